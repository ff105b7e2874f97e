//! Static (bias) test figures for one output channel, accumulated block by block in bounded
//! memory: zero-rate output mean, bias, bias stability for smoothing times, drift, temperature
//! sensitivity, bias repeatability across tests, and data-quality findings.
//!
//! Sources: the paper (Cheng et al. 2014) eq. 10 (bias B0 = F / K), eq. 11 (bias stability
//! B_s = std(F_i, n-1) / K) and eq. 12 (repeatability B_r = std(B0_i, n-1)); GJB 2426A-2004 for
//! the smoothing (non-overlapping window means of T seconds) and the earth-rate subtraction with
//! the input axis vertical; IEEE Std 952-1997 for the definitions of bias, drift and temperature
//! sensitivity. The temperature-model details (fit of window means, compensated stability) were
//! recalled, not read from the standard's text: `docs/METHODS.md` marks them unverified.
//!
//! Precision: every sum is taken of deviations from the first valid sample (and time from the
//! first valid time stamp); moments of each block are computed in two passes and merged with the
//! pairwise update of Chan, Golub & LeVeque (1983), so a 2.5 V null with 1e-4 V noise over 1e8
//! samples loses no significant digit.
//!
//! Memory: constant per channel, except the temperature fit, which keeps one (temperature,
//! output) pair of window means per `temperature_window_s` seconds of record (16 bytes each:
//! 1.6 MB for a 10^5-window record), and the sample-rate probe (the first 4097 samples when no
//! sample rate is given).

use crate::fit::{self, FitError};
use crate::sampling::SampleRateSource;
use crate::units::{self, OutputUnit};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// How many first positions each data-quality finding keeps.
pub const FIRST_POSITIONS: usize = 10;
/// Samples buffered to estimate the sample rate from time stamps when none is given.
pub const RATE_PROBE_SAMPLES: usize = 4097;

/// A block of consecutive samples of one channel (the slices have equal length).
#[derive(Debug, Clone, Copy)]
pub struct SampleBlock<'a> {
    /// Output samples, in the channel's output unit.
    pub output: &'a [f64],
    /// Time stamps in seconds, when the record has a time column.
    pub time_s: Option<&'a [f64]>,
    /// Temperature in degC, when the record has a temperature column.
    pub temperature_c: Option<&'a [f64]>,
    /// Source line of each sample, when the samples come from a file (for reporting positions).
    pub lines: Option<&'a [u64]>,
}

impl<'a> SampleBlock<'a> {
    /// A block of output samples only.
    pub fn output_only(output: &'a [f64]) -> Self {
        SampleBlock { output, time_s: None, temperature_c: None, lines: None }
    }
}

/// Why a static test could not be evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StaticTestError {
    /// An option is out of range.
    #[error("invalid static-test option: {0}")]
    InvalidOption(String),
    /// The record has no time stamps and no sample rate was given.
    #[error("the record has no time column and no sample rate was given: give sample_rate_hz")]
    NoSampleRate,
    /// The time stamps do not allow a sample rate to be estimated.
    #[error("cannot estimate the sample rate: {0}")]
    SampleRateUnknown(String),
    /// Slices of one block differ in length.
    #[error("block slices differ in length: {what} has {found} values, output has {expected}")]
    LengthMismatch {
        /// Which slice.
        what: &'static str,
        /// Output length.
        expected: usize,
        /// The slice's length.
        found: usize,
    },
    /// A block lacks a column the earlier blocks had, or the reverse.
    #[error("block {0} column presence differs from the first block")]
    InconsistentBlocks(&'static str),
    /// Too few valid samples.
    #[error("the record has {found} valid samples, at least {needed} are needed")]
    TooFewSamples {
        /// Valid samples found.
        found: u64,
        /// Samples needed.
        needed: u64,
    },
    /// Too few tests for a repeatability.
    #[error("bias repeatability needs at least 2 tests with {what}, found {found}")]
    TooFewTests {
        /// What each test must provide.
        what: &'static str,
        /// Tests that provide it.
        found: usize,
    },
    /// A fit failed.
    #[error(transparent)]
    Fit(#[from] FitError),
}

/// Options of a static test for one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticTestConfig {
    /// Channel name, copied into the result.
    pub channel: String,
    /// Unit of the output samples.
    pub output_unit: OutputUnit,
    /// Sample rate in Hz; when `None` it is estimated from the time stamps (median interval).
    pub sample_rate_hz: Option<f64>,
    /// Scale factor K in output units per deg/s (defaults to the native factor of deg/s and
    /// rad/s outputs; required for deg/h figures of V, mV and LSB outputs).
    pub scale_factor: Option<f64>,
    /// Zero-rate output reference F_null in output units (defaults to 0 for rate outputs).
    pub null_output: Option<f64>,
    /// Latitude in degrees (input axis vertical, pointing up): subtract the earth rate when given.
    pub latitude_deg: Option<f64>,
    /// Report the bias stability of raw samples (smoothing time one sample interval).
    pub include_one_sample: bool,
    /// Smoothing times T in seconds for the bias stability.
    pub smoothing_times_s: Vec<f64>,
    /// A smoothing time is reported only when at least this many whole windows fit.
    pub min_windows: u64,
    /// Window length in seconds of the window means used for the temperature fit.
    pub temperature_window_s: f64,
    /// Also fit a quadratic temperature model (and compensate with it).
    pub temperature_quadratic: bool,
    /// Time gap rule: an interval longer than this factor times the nominal interval.
    pub gap_factor: f64,
    /// Rail rule: at least this many consecutive identical samples at the record's min or max.
    pub rail_run_samples: u64,
    /// Outlier rule: |x - drift line| > k * residual std of the drift line.
    pub outlier_k_sigma: f64,
    /// Remove outliers (second pass) before computing the figures; otherwise they are only counted.
    pub drop_outliers: bool,
}

impl Default for StaticTestConfig {
    fn default() -> Self {
        StaticTestConfig {
            channel: "output".into(),
            output_unit: OutputUnit::Volt,
            sample_rate_hz: None,
            scale_factor: None,
            null_output: None,
            latitude_deg: None,
            include_one_sample: true,
            smoothing_times_s: vec![1.0, 10.0, 100.0],
            min_windows: 10,
            temperature_window_s: 10.0,
            temperature_quadratic: false,
            gap_factor: 1.5,
            rail_run_samples: 10,
            outlier_k_sigma: 6.0,
            drop_outliers: false,
        }
    }
}

impl StaticTestConfig {
    fn validate(&self) -> Result<(), StaticTestError> {
        let bad = |m: String| Err(StaticTestError::InvalidOption(m));
        if let Some(f) = self.sample_rate_hz {
            if !(f.is_finite() && f > 0.0) {
                return bad(format!("sample_rate_hz = {f}, expected a positive number"));
            }
        }
        if let Some(k) = self.scale_factor {
            if !(k.is_finite() && k != 0.0) {
                return bad(format!("scale_factor = {k}, expected a non-zero number"));
            }
        }
        if let Some(n) = self.null_output {
            if !n.is_finite() {
                return bad(format!("null_output = {n}, expected a number"));
            }
        }
        if let Some(l) = self.latitude_deg {
            if !(-90.0..=90.0).contains(&l) {
                return bad(format!("latitude_deg = {l}, expected -90..90"));
            }
        }
        if let Some(t) = self.smoothing_times_s.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
            return bad(format!("smoothing time {t} s, expected a positive number"));
        }
        if self.min_windows < 2 {
            return bad(format!("min_windows = {}, expected at least 2", self.min_windows));
        }
        if !(self.temperature_window_s.is_finite() && self.temperature_window_s > 0.0) {
            return bad(format!("temperature_window_s = {}, expected a positive number", self.temperature_window_s));
        }
        if !(self.gap_factor.is_finite() && self.gap_factor > 1.0) {
            return bad(format!("gap_factor = {}, expected a number above 1", self.gap_factor));
        }
        if self.rail_run_samples < 2 {
            return bad(format!("rail_run_samples = {}, expected at least 2", self.rail_run_samples));
        }
        if !(self.outlier_k_sigma.is_finite() && self.outlier_k_sigma > 0.0) {
            return bad(format!("outlier_k_sigma = {}, expected a positive number", self.outlier_k_sigma));
        }
        Ok(())
    }

    /// The scale factor in use: the given one or the output unit's native one.
    pub fn effective_scale_factor(&self) -> Option<f64> {
        self.scale_factor.or(self.output_unit.native_scale_factor_per_dps())
    }

    /// The zero-rate reference in use: the given one, or 0 for outputs that are already rates.
    pub fn effective_null_output(&self) -> Option<f64> {
        self.null_output.or(self.output_unit.native_scale_factor_per_dps().map(|_| 0.0))
    }
}

/// Where a sample is: 0-based sample index in the record, and its source line when known.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Position {
    /// 0-based index of the sample in the record.
    pub sample: u64,
    /// 1-based source line, when the record came from a file.
    pub line: Option<u64>,
}

/// A counted data-quality finding with its first positions.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct QualityIssue {
    /// How many samples (or intervals) have it.
    pub count: u64,
    /// The first positions (at most [`FIRST_POSITIONS`]).
    pub first: Vec<Position>,
}

impl QualityIssue {
    fn note(&mut self, p: Position) {
        self.count += 1;
        if self.first.len() < FIRST_POSITIONS {
            self.first.push(p);
        }
    }
}

/// Runs of identical samples at a rail (the record's min or max).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RailRuns {
    /// The rail value (output units), when runs were found.
    pub value: Option<f64>,
    /// Number of runs.
    pub runs: u64,
    /// Samples in those runs.
    pub samples: u64,
    /// First sample of the first runs.
    pub first: Vec<Position>,
}

/// Outliers found in the second pass.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutlierReport {
    /// The k of the rule |x - drift line| > k * sigma.
    pub k_sigma: f64,
    /// Sigma: residual standard deviation of the samples about the drift line (output units).
    pub residual_std_output: f64,
    /// Outliers found.
    pub outliers: QualityIssue,
    /// Whether they were removed before computing the figures.
    pub dropped: bool,
}

/// Data-quality findings: reported, never repaired.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DataQuality {
    /// Samples whose output or time is NaN, infinite or missing (excluded from every figure).
    pub missing: QualityIssue,
    /// Nominal sample interval in seconds (1 / sample rate).
    pub nominal_interval_s: f64,
    /// Intervals longer than gap_factor times the nominal interval (position: the sample after).
    pub time_gaps: QualityIssue,
    /// Longest interval between valid time stamps, seconds.
    pub largest_interval_s: Option<f64>,
    /// Time stamps equal to the previous one.
    pub repeated_time: QualityIssue,
    /// Time stamps below the previous one.
    pub decreasing_time: QualityIssue,
    /// Runs stuck at the record's minimum.
    pub stuck_at_min: RailRuns,
    /// Runs stuck at the record's maximum.
    pub stuck_at_max: RailRuns,
    /// Outliers (`None` when the second pass was not run).
    pub outliers: Option<OutlierReport>,
}

/// A smoothing time that was not reported, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedSmoothing {
    /// Smoothing time in seconds.
    pub smoothing_s: f64,
    /// Whole windows that fit.
    pub windows: u64,
    /// Why it was skipped.
    pub reason: String,
}

/// The least-squares drift line output = output_at_t0 + slope * (t - t0).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriftLine {
    /// Time of the first valid sample, seconds (0 when the record has no time column).
    pub t0_s: f64,
    /// Line value at t0, output units.
    pub output_at_t0: f64,
    /// Slope, output units per second.
    pub slope_output_per_s: f64,
    /// Residual standard deviation about the line (n-2), output units.
    pub residual_std_output: f64,
}

impl DriftLine {
    /// Line value at time t (seconds).
    pub fn eval(&self, t_s: f64) -> f64 {
        self.output_at_t0 + self.slope_output_per_s * (t_s - self.t0_s)
    }
}

/// Bias against temperature, fitted on window means.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TemperatureResult {
    /// Window length of the means fitted, seconds.
    pub window_s: f64,
    /// Window means fitted.
    pub windows: u64,
    /// Lowest window-mean temperature, degC.
    pub temp_min_c: f64,
    /// Highest window-mean temperature, degC.
    pub temp_max_c: f64,
    /// Linear model slope, output units per degC.
    pub slope_output_per_c: f64,
    /// Linear model output at 0 degC, output units.
    pub intercept_output: f64,
    /// Temperature sensitivity of the bias, (deg/h)/degC (when calibrated).
    pub temp_sensitivity_dph_per_c: Option<f64>,
    /// Quadratic model c0 + c1 T + c2 T^2 (output units, T in degC), when requested.
    pub quadratic_output: Option<[f64; 3]>,
    /// Model used for compensation: "linear" or "quadratic".
    pub compensation_model: String,
    /// Std of the window means before compensation (n-1), output units.
    pub window_std_output: f64,
    /// Residual std of the window means after compensation (n - parameters), output units.
    pub compensated_stability_output: f64,
    /// The same in deg/h (when calibrated).
    pub compensated_stability_dph: Option<f64>,
}

/// Static-test figures of one channel of one test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticTestResult {
    /// Channel name.
    pub channel: String,
    /// Output unit of the figures named `*_output`.
    pub output_unit: OutputUnit,
    /// Samples seen (valid or not).
    pub samples: u64,
    /// Samples used (finite and not dropped).
    pub valid_samples: u64,
    /// Sample rate used, Hz.
    pub sample_rate_hz: f64,
    /// Where the sample rate came from.
    pub sample_rate_source: SampleRateSource,
    /// Span of the record, seconds (last minus first valid time).
    pub duration_s: f64,
    /// Zero-rate output mean F (paper Table 5), output units.
    pub mean_output: f64,
    /// Sample standard deviation (n-1) of the output, output units.
    pub std_output: f64,
    /// Scale factor K used, output units per deg/s.
    pub scale_factor_output_per_dps: Option<f64>,
    /// Zero-rate reference F_null used, output units.
    pub null_output: Option<f64>,
    /// Bias B0 = (F - F_null) / K (earth rate removed when `earth_rate_subtracted`), deg/s.
    pub bias_dps: Option<f64>,
    /// The same in deg/h.
    pub bias_dph: Option<f64>,
    /// Earth-rate component Omega_e sin(latitude), deg/h, when a latitude was given.
    pub earth_rate_component_dph: Option<f64>,
    /// Whether the earth-rate component was subtracted from the bias.
    pub earth_rate_subtracted: bool,
    /// Bias stability per reported smoothing time, in increasing smoothing time (one entry per
    /// [`smoothing_key`]). In JSON: three objects keyed by [`smoothing_key`]
    /// (`bias_stability_output`, `bias_stability_dph`, `bias_stability_windows`).
    #[serde(flatten, with = "stability_json")]
    pub bias_stability: Vec<BiasStability>,
    /// The smoothing time quoted as "the" bias stability (10 s, else 1 s, else one sample), s;
    /// always one of `bias_stability`'s. In JSON: its [`smoothing_key`] string.
    #[serde(with = "quoted_json")]
    pub bias_stability_quoted_s: Option<f64>,
    /// Smoothing times not reported, with reasons.
    pub bias_stability_skipped: Vec<SkippedSmoothing>,
    /// Drift: least-squares slope of output vs time, output units per hour.
    pub drift_output_per_h: Option<f64>,
    /// Drift in (deg/h) per hour (when calibrated).
    pub drift_dph_per_h: Option<f64>,
    /// The fitted drift line.
    pub drift_line: Option<DriftLine>,
    /// Temperature model (when a temperature channel exists and varies).
    pub temperature: Option<TemperatureResult>,
    /// Data-quality findings.
    pub quality: DataQuality,
    /// Notes: figures not computed and why.
    pub notes: Vec<String>,
}

/// Bias stability at one smoothing time T (paper eq. 11).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BiasStability {
    /// Smoothing time T, seconds.
    pub smoothing_s: f64,
    /// Std (n-1) of the consecutive T-second window means, output units.
    pub output: f64,
    /// The same in deg/h (when calibrated).
    pub dph: Option<f64>,
    /// Whole windows used.
    pub windows: u64,
}

impl BiasStability {
    /// The smoothing time as the JSON and report key ([`smoothing_key`]: "0.01", "10").
    pub fn key(&self) -> String {
        smoothing_key(self.smoothing_s)
    }
}

impl StaticTestResult {
    /// The bias stability at a smoothing time, matched by [`smoothing_key`] (to 9 decimals).
    pub fn stability_at(&self, smoothing_s: f64) -> Option<&BiasStability> {
        let key = smoothing_key(smoothing_s);
        self.bias_stability.iter().find(|b| b.key() == key)
    }

    /// The bias stability quoted as "the" figure (at `bias_stability_quoted_s`).
    pub fn quoted_stability(&self) -> Option<&BiasStability> {
        self.bias_stability_quoted_s.and_then(|t| self.stability_at(t))
    }
}

/// The smoothing times reported by any of the results (one per [`smoothing_key`], the first
/// seen), in increasing order: the columns of a table of several tests.
pub fn reported_smoothing_times<'a>(results: impl IntoIterator<Item = &'a StaticTestResult>) -> Vec<f64> {
    let mut times: Vec<f64> = Vec::new();
    for r in results {
        for b in &r.bias_stability {
            let key = b.key();
            if !times.iter().any(|t| smoothing_key(*t) == key) {
                times.push(b.smoothing_s);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    times
}

/// JSON form of [`StaticTestResult::bias_stability`]: three objects keyed by [`smoothing_key`],
/// keys in string order (as the earlier `BTreeMap<String, _>` fields wrote them).
mod stability_json {
    use super::{smoothing_key, BiasStability};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    use std::collections::BTreeMap;

    #[derive(Serialize, Deserialize)]
    struct Maps {
        bias_stability_output: BTreeMap<String, f64>,
        bias_stability_dph: BTreeMap<String, f64>,
        bias_stability_windows: BTreeMap<String, u64>,
    }

    pub fn serialize<S: Serializer>(v: &[BiasStability], s: S) -> Result<S::Ok, S::Error> {
        let mut m = Maps {
            bias_stability_output: BTreeMap::new(),
            bias_stability_dph: BTreeMap::new(),
            bias_stability_windows: BTreeMap::new(),
        };
        for b in v {
            let key = smoothing_key(b.smoothing_s);
            m.bias_stability_output.insert(key.clone(), b.output);
            if let Some(d) = b.dph {
                m.bias_stability_dph.insert(key.clone(), d);
            }
            m.bias_stability_windows.insert(key, b.windows);
        }
        m.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<BiasStability>, D::Error> {
        let m = Maps::deserialize(d)?;
        let mut v = Vec::with_capacity(m.bias_stability_output.len());
        for (key, output) in m.bias_stability_output {
            let smoothing_s = key
                .parse::<f64>()
                .map_err(|_| serde::de::Error::custom(format!("smoothing time '{key}' is not a number")))?;
            let windows = m.bias_stability_windows.get(&key).copied().ok_or_else(|| {
                serde::de::Error::custom(format!("bias_stability_windows has no entry for smoothing time '{key}'"))
            })?;
            v.push(BiasStability { smoothing_s, output, dph: m.bias_stability_dph.get(&key).copied(), windows });
        }
        v.sort_by(|a, b| a.smoothing_s.total_cmp(&b.smoothing_s));
        Ok(v)
    }
}

/// JSON form of [`StaticTestResult::bias_stability_quoted_s`]: its [`smoothing_key`] string.
mod quoted_json {
    use super::smoothing_key;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        v.map(smoothing_key).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        Option::<String>::deserialize(d)?
            .map(|k| {
                k.parse::<f64>().map_err(|_| serde::de::Error::custom(format!("smoothing time '{k}' is not a number")))
            })
            .transpose()
    }
}

/// The first pass's figures, before the outlier pass ([`StaticTestAccumulator::finish`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FirstPass {
    /// The figures, without an outlier report.
    pub result: StaticTestResult,
    /// Whether the outlier pass could find anything: `false` when the first pass's per-chunk
    /// extremes prove that no sample lies beyond the rule (the pass can then be skipped, see
    /// [`FirstPass::with_no_outliers`]).
    pub outlier_scan_needed: bool,
}

/// Bias repeatability over Q static tests (paper eq. 12).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BiasRepeatability {
    /// Number of tests Q.
    pub tests: usize,
    /// Mean of the zero-rate output means, output units (paper Table 5 "mean").
    pub mean_output: f64,
    /// Std (n-1) of the zero-rate output means, output units.
    pub output_repeatability: f64,
    /// Mean bias, deg/h (when every test is calibrated).
    pub mean_bias_dph: Option<f64>,
    /// Bias repeatability std(B0_i, n-1), deg/h (when every test is calibrated).
    pub bias_repeatability_dph: Option<f64>,
}

/// Bias repeatability across tests: std (n-1) of the per-test biases (paper eq. 12, GJB 2426A).
pub fn bias_repeatability(results: &[StaticTestResult]) -> Result<BiasRepeatability, StaticTestError> {
    if results.len() < 2 {
        return Err(StaticTestError::TooFewTests { what: "a mean output", found: results.len() });
    }
    let means: Vec<f64> = results.iter().map(|r| r.mean_output).collect();
    let biases: Option<Vec<f64>> = results.iter().map(|r| r.bias_dph).collect();
    Ok(BiasRepeatability {
        tests: results.len(),
        mean_output: fit::mean(&means).unwrap_or(f64::NAN), // ok: len >= 2
        output_repeatability: fit::sample_std(&means).unwrap_or(f64::NAN), // ok: len >= 2
        mean_bias_dph: biases.as_deref().and_then(fit::mean),
        bias_repeatability_dph: biases.as_deref().and_then(fit::sample_std),
    })
}

/// Formats a smoothing time as a map key: up to 9 decimals, trailing zeros removed ("0.01", "10").
pub fn smoothing_key(t_s: f64) -> String {
    let s = format!("{t_s:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() {
        "0".into()
    } else {
        s.to_string()
    }
}

/// Moments of (t, d) pairs: count, means, centred cross sums (merged pairwise).
#[derive(Debug, Clone, Copy, Default)]
struct Moments {
    n: f64,
    mean_t: f64,
    mean_d: f64,
    ctt: f64,
    cdd: f64,
    ctd: f64,
}

impl Moments {
    fn of(t: &[f64], d: &[f64]) -> Moments {
        let n = d.len() as f64;
        if d.is_empty() {
            return Moments::default();
        }
        let mean_t = t.iter().sum::<f64>() / n;
        let mean_d = d.iter().sum::<f64>() / n;
        let (mut ctt, mut cdd, mut ctd) = (0.0, 0.0, 0.0);
        for (&ti, &di) in t.iter().zip(d) {
            let (a, b) = (ti - mean_t, di - mean_d);
            ctt += a * a;
            cdd += b * b;
            ctd += a * b;
        }
        Moments { n, mean_t, mean_d, ctt, cdd, ctd }
    }

    fn of_shifted(t: &[f64], t0: f64, x: &[f64], x0: f64) -> Moments {
        let n = x.len() as f64;
        if x.is_empty() {
            return Moments::default();
        }
        let mean_t = lane_sum(t, t0) / n;
        let mean_d = lane_sum(x, x0) / n;
        let (mut ctt, mut cdd, mut ctd) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        let (tc, xc) = (t.chunks_exact(4), x.chunks_exact(4));
        let (tr, xr) = (tc.remainder(), xc.remainder());
        for (tq, xq) in tc.zip(xc) {
            for l in 0..4 {
                let (a, b) = (tq[l] - t0 - mean_t, xq[l] - x0 - mean_d);
                ctt[l] += a * a;
                cdd[l] += b * b;
                ctd[l] += a * b;
            }
        }
        for (&ti, &xi) in tr.iter().zip(xr) {
            let (a, b) = (ti - t0 - mean_t, xi - x0 - mean_d);
            ctt[0] += a * a;
            cdd[0] += b * b;
            ctd[0] += a * b;
        }
        let s = |v: [f64; 4]| (v[0] + v[1]) + (v[2] + v[3]);
        Moments { n, mean_t, mean_d, ctt: s(ctt), cdd: s(cdd), ctd: s(ctd) }
    }

    fn of_indexed(i0: u64, fs: f64, t0: f64, x: &[f64], x0: f64) -> Moments {
        // Times i / fs; their centred sums are exact closed forms of the index.
        let n = x.len() as f64;
        if x.is_empty() {
            return Moments::default();
        }
        let mean_i = (n - 1.0) / 2.0;
        let mean_t = (i0 as f64 + mean_i) / fs - t0;
        let mean_d = lane_sum(x, x0) / n;
        let (mut cdd, mut cid) = ([0.0; 4], [0.0; 4]);
        let xc = x.chunks_exact(4);
        let rest = xc.remainder();
        for (q, xq) in xc.enumerate() {
            for l in 0..4 {
                let a = (q * 4 + l) as f64 - mean_i;
                let b = xq[l] - x0 - mean_d;
                cdd[l] += b * b;
                cid[l] += a * b;
            }
        }
        let base = x.len() - rest.len();
        for (j, &xi) in rest.iter().enumerate() {
            let (a, b) = ((base + j) as f64 - mean_i, xi - x0 - mean_d);
            cdd[0] += b * b;
            cid[0] += a * b;
        }
        let s = |v: [f64; 4]| (v[0] + v[1]) + (v[2] + v[3]);
        let cii = n * (n * n - 1.0) / 12.0;
        Moments { n, mean_t, mean_d, ctt: cii / (fs * fs), cdd: s(cdd), ctd: s(cid) / fs }
    }

    fn merge(&mut self, o: &Moments) {
        if o.n == 0.0 {
            return;
        }
        if self.n == 0.0 {
            *self = *o;
            return;
        }
        let n = self.n + o.n;
        let (dt, dd) = (o.mean_t - self.mean_t, o.mean_d - self.mean_d);
        let f = self.n * o.n / n;
        self.ctt += o.ctt + dt * dt * f;
        self.cdd += o.cdd + dd * dd * f;
        self.ctd += o.ctd + dt * dd * f;
        self.mean_t += dt * o.n / n;
        self.mean_d += dd * o.n / n;
        self.n = n;
    }
}

/// Sum of (v - shift) over a slice, in four lanes (vectorisable).
fn lane_sum(v: &[f64], shift: f64) -> f64 {
    let mut acc = [0.0; 4];
    let c = v.chunks_exact(4);
    let rest = c.remainder();
    for q in c {
        for l in 0..4 {
            acc[l] += q[l] - shift;
        }
    }
    let tail: f64 = rest.iter().map(|x| x - shift).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Welford accumulation of window means.
#[derive(Debug, Clone, Copy, Default)]
struct Welford {
    n: u64,
    mean: f64,
    m2: f64,
}

impl Welford {
    fn add(&mut self, x: f64) {
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
    }

    fn std(&self) -> Option<f64> {
        (self.n >= 2).then(|| (self.m2 / (self.n - 1) as f64).sqrt())
    }
}

/// Non-overlapping windows of m samples; a window's mean is over its valid samples.
#[derive(Debug, Clone)]
struct Windows {
    smoothing_s: f64,
    m: u64,
    filled: u64,
    valid: u64,
    sum: f64,
    means: Welford,
    with_missing: u64,
    empty: u64,
}

impl Windows {
    /// Adds a slice of valid samples (deviations x - shift).
    fn add_slice(&mut self, x: &[f64], shift: f64) {
        let mut i = 0;
        while i < x.len() {
            let take = ((self.m - self.filled) as usize).min(x.len() - i);
            self.sum += lane_sum(&x[i..i + take], shift);
            self.filled += take as u64;
            self.valid += take as u64;
            i += take;
            if self.filled == self.m {
                self.close();
            }
        }
    }

    fn close(&mut self) {
        if self.valid == 0 {
            self.empty += 1;
        } else {
            if self.valid < self.m {
                self.with_missing += 1;
            }
            self.means.add(self.sum / self.valid as f64);
        }
        self.filled = 0;
        self.valid = 0;
        self.sum = 0.0;
    }

    #[inline]
    fn add(&mut self, d: Option<f64>) {
        self.filled += 1;
        if let Some(d) = d {
            self.sum += d;
            self.valid += 1;
        }
        if self.filled == self.m {
            self.close();
        }
    }
}

/// Window means of temperature and output for the temperature fit.
#[derive(Debug, Clone, Default)]
struct TempWindows {
    m: u64,
    filled: u64,
    valid: u64,
    sum_d: f64,
    sum_c: f64,
    points: Vec<(f64, f64)>,
}

/// Candidate runs at the running min or max.
#[derive(Debug, Clone, Default)]
struct RailTracker {
    run_value: f64,
    run_len: u64,
    run_start: Option<Position>,
    at_min: RailRuns,
    at_max: RailRuns,
}

/// An exclusion rule applied in a second pass (outliers).
#[derive(Debug, Clone, Copy)]
struct OutlierRule {
    line: DriftLine,
    limit: f64,
}

/// Owned copies of the first samples, kept until the sample rate is known.
#[derive(Debug, Clone, Default)]
struct Probe {
    output: Vec<f64>,
    time: Vec<f64>,
    temp: Vec<f64>,
    lines: Vec<u64>,
}

/// Streaming accumulator of the static-test figures of one channel (bounded memory).
#[derive(Debug, Clone)]
pub struct StaticTestAccumulator {
    config: StaticTestConfig,
    fs: Option<f64>,
    fs_given: bool,
    probe: Option<Probe>,
    has_time: Option<bool>,
    has_temp: Option<bool>,
    has_lines: Option<bool>,
    samples: u64,
    reference: Option<(f64, f64)>,
    prev_time: Option<f64>,
    last_time: f64,
    min: f64,
    max: f64,
    moments: Moments,
    windows: Vec<Windows>,
    skipped: Vec<SkippedSmoothing>,
    temp: TempWindows,
    rail: RailTracker,
    quality: DataQuality,
    rule: Option<OutlierRule>,
    outliers: QualityIssue,
    scratch_t: Vec<f64>,
    scratch_d: Vec<f64>,
    extremes: Vec<ChunkExtremes>,
    chunk_slope: ChunkSlope,
}

/// Extremes of the valid samples of a run of consecutive samples (at most [`EXTREMES_CHUNK`]),
/// kept so the outlier pass can be skipped when it cannot find anything. The extremes are of
/// y = x - s t with a provisional slope s (the fit of the previous chunks' means), so that the
/// residuals about the final drift line can be bounded tightly.
#[derive(Debug, Clone, Copy)]
struct ChunkExtremes {
    samples: u64,
    slope: f64,
    t_min: f64,
    t_max: f64,
    y_min: f64,
    y_max: f64,
    valid: u64,
    t_sum: f64,
    x_sum: f64,
}

/// Samples per [`ChunkExtremes`] entry (memory: 72 bytes per 1024 samples, 7 MB per 1e8).
const EXTREMES_CHUNK: u64 = 1024;
/// Samples per entry for the first [`EXTREMES_SHORT_CHUNKS`] entries, while the provisional
/// slope is still poorly known.
const EXTREMES_SHORT_CHUNK: u64 = 128;
/// Number of short entries at the start of a record.
const EXTREMES_SHORT_CHUNKS: usize = 16;

/// Running least-squares slope of the chunk means (values relative to the first chunk's mean).
#[derive(Debug, Clone, Copy, Default)]
struct ChunkSlope {
    reference: Option<(f64, f64)>,
    n: f64,
    st: f64,
    sx: f64,
    stt: f64,
    stx: f64,
}

impl ChunkSlope {
    fn add(&mut self, t: f64, x: f64) {
        let (t0, x0) = *self.reference.get_or_insert((t, x));
        let (t, x) = (t - t0, x - x0);
        self.n += 1.0;
        self.st += t;
        self.sx += x;
        self.stt += t * t;
        self.stx += t * x;
    }

    fn slope(&self) -> f64 {
        let d = self.n * self.stt - self.st * self.st;
        if self.n >= 2.0 && d > 0.0 {
            (self.n * self.stx - self.st * self.sx) / d
        } else {
            0.0
        }
    }
}

impl StaticTestAccumulator {
    /// A new accumulator; fails when an option is out of range.
    pub fn new(config: StaticTestConfig) -> Result<Self, StaticTestError> {
        config.validate()?;
        let mut acc = StaticTestAccumulator {
            fs: None,
            fs_given: config.sample_rate_hz.is_some(),
            probe: None,
            has_time: None,
            has_temp: None,
            has_lines: None,
            samples: 0,
            reference: None,
            prev_time: None,
            last_time: 0.0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            moments: Moments::default(),
            windows: Vec::new(),
            skipped: Vec::new(),
            temp: TempWindows::default(),
            rail: RailTracker::default(),
            quality: DataQuality::default(),
            rule: None,
            outliers: QualityIssue::default(),
            scratch_t: Vec::new(),
            scratch_d: Vec::new(),
            extremes: Vec::new(),
            chunk_slope: ChunkSlope::default(),
            config,
        };
        match acc.config.sample_rate_hz {
            Some(fs) => acc.set_rate(fs),
            None => acc.probe = Some(Probe::default()),
        }
        Ok(acc)
    }

    fn set_rate(&mut self, fs: f64) {
        self.fs = Some(fs);
        self.quality.nominal_interval_s = 1.0 / fs;
        let mut times: Vec<f64> = Vec::new();
        if self.config.include_one_sample {
            times.push(1.0 / fs);
        }
        times.extend(self.config.smoothing_times_s.iter().copied());
        for t in times {
            let m = (t * fs).round();
            if m < 1.0 {
                self.skipped.push(SkippedSmoothing {
                    smoothing_s: t,
                    windows: 0,
                    reason: format!("shorter than one sample interval ({} s)", 1.0 / fs),
                });
                continue;
            }
            self.windows.push(Windows {
                smoothing_s: t,
                m: m as u64,
                filled: 0,
                valid: 0,
                sum: 0.0,
                means: Welford::default(),
                with_missing: 0,
                empty: 0,
            });
        }
        self.temp.m = ((self.config.temperature_window_s * fs).round() as u64).max(1);
    }

    fn check_block(&mut self, b: &SampleBlock) -> Result<(), StaticTestError> {
        let n = b.output.len();
        let check = |what, s: Option<usize>| match s {
            Some(found) if found != n => Err(StaticTestError::LengthMismatch { what, expected: n, found }),
            _ => Ok(()),
        };
        check("time_s", b.time_s.map(<[f64]>::len))?;
        check("temperature_c", b.temperature_c.map(<[f64]>::len))?;
        check("lines", b.lines.map(<[u64]>::len))?;
        for (slot, present, what) in [
            (&mut self.has_time, b.time_s.is_some(), "time"),
            (&mut self.has_temp, b.temperature_c.is_some(), "temperature"),
            (&mut self.has_lines, b.lines.is_some(), "line-number"),
        ] {
            match *slot {
                None => *slot = Some(present),
                Some(p) if p != present => return Err(StaticTestError::InconsistentBlocks(what)),
                _ => {}
            }
        }
        if self.fs.is_none() && !b.output.is_empty() && b.time_s.is_none() {
            return Err(StaticTestError::NoSampleRate);
        }
        Ok(())
    }

    /// Adds a block of consecutive samples.
    pub fn push(&mut self, block: &SampleBlock) -> Result<(), StaticTestError> {
        self.check_block(block)?;
        if let Some(probe) = self.probe.as_mut() {
            probe.output.extend_from_slice(block.output);
            if let Some(t) = block.time_s {
                probe.time.extend_from_slice(t);
            }
            if let Some(c) = block.temperature_c {
                probe.temp.extend_from_slice(c);
            }
            if let Some(l) = block.lines {
                probe.lines.extend_from_slice(l);
            }
            if probe.output.len() >= RATE_PROBE_SAMPLES {
                self.end_probe()?;
            }
            return Ok(());
        }
        self.process(block);
        Ok(())
    }

    fn end_probe(&mut self) -> Result<(), StaticTestError> {
        let Some(p) = self.probe.take() else { return Ok(()) };
        if p.output.is_empty() {
            return Ok(());
        }
        let estimate = crate::sampling::estimate_interval(&p.time).map_err(|_| {
            StaticTestError::SampleRateUnknown(format!(
                "no increasing time stamps among the first {} samples; give sample_rate_hz",
                p.output.len()
            ))
        })?;
        self.set_rate(estimate.rate_hz());
        let block = SampleBlock {
            output: &p.output,
            time_s: Some(&p.time),
            temperature_c: (!p.temp.is_empty()).then_some(&p.temp[..]),
            lines: (!p.lines.is_empty()).then_some(&p.lines[..]),
        };
        self.process(&block);
        Ok(())
    }

    fn process(&mut self, b: &SampleBlock) {
        let clean = self.block_is_clean(b);
        self.track_extremes(b, clean);
        if clean {
            self.process_clean(b);
        } else {
            self.process_each(b);
        }
    }

    /// Records the extremes of the block's valid samples, chunk by chunk (`clean`: every sample
    /// is valid, see [`Self::block_is_clean`]).
    fn track_extremes(&mut self, b: &SampleBlock, clean: bool) {
        let fs = self.fs.unwrap_or(1.0); // ok: process runs only once the rate is set
        let i0 = self.samples;
        let n = b.output.len();
        let mut i = 0;
        while i < n {
            let size = if self.extremes.len() <= EXTREMES_SHORT_CHUNKS { EXTREMES_SHORT_CHUNK } else { EXTREMES_CHUNK };
            if self.extremes.last().is_none_or(|c| c.samples >= size) {
                if let Some(c) = self.extremes.last() {
                    if c.valid > 0 {
                        self.chunk_slope.add(c.t_sum / c.valid as f64, c.x_sum / c.valid as f64);
                    }
                }
                self.extremes.push(ChunkExtremes {
                    samples: 0,
                    slope: self.chunk_slope.slope(),
                    t_min: f64::INFINITY,
                    t_max: f64::NEG_INFINITY,
                    y_min: f64::INFINITY,
                    y_max: f64::NEG_INFINITY,
                    valid: 0,
                    t_sum: 0.0,
                    x_sum: 0.0,
                });
            }
            let size = if self.extremes.len() <= EXTREMES_SHORT_CHUNKS { EXTREMES_SHORT_CHUNK } else { EXTREMES_CHUNK };
            let Some(c) = self.extremes.last_mut() else { return };
            let take = ((size - c.samples) as usize).min(n - i);
            if let (true, Some(ts)) = (clean, b.time_s) {
                // Every sample valid: the same sums without a test per sample.
                let slope = c.slope;
                for (&x, &t) in b.output[i..i + take].iter().zip(&ts[i..i + take]) {
                    let y = x - slope * t;
                    c.y_min = c.y_min.min(y);
                    c.y_max = c.y_max.max(y);
                    c.t_min = c.t_min.min(t);
                    c.t_max = c.t_max.max(t);
                    c.t_sum += t;
                    c.x_sum += x;
                }
                c.valid += take as u64;
                c.samples += take as u64;
                i += take;
                continue;
            }
            for j in i..i + take {
                let x = b.output[j];
                let t = b.time_s.map_or((i0 + j as u64) as f64 / fs, |ts| ts[j]);
                if x.is_finite() && t.is_finite() {
                    let y = x - c.slope * t;
                    c.y_min = c.y_min.min(y);
                    c.y_max = c.y_max.max(y);
                    c.t_min = c.t_min.min(t);
                    c.t_max = c.t_max.max(t);
                    c.valid += 1;
                    c.t_sum += t;
                    c.x_sum += x;
                }
            }
            c.samples += take as u64;
            i += take;
        }
    }

    /// Whether any chunk could hold a sample beyond `limit` from `line` (a conservative bound:
    /// r = x - A - b t = y - A - (b - s) t with y = x - s t).
    fn outliers_possible(&self, line: &DriftLine, limit: f64) -> bool {
        let limit = limit * (1.0 - 1e-9);
        let intercept = line.output_at_t0 - line.slope_output_per_s * line.t0_s;
        self.extremes.iter().any(|c| {
            if c.valid == 0 {
                return false;
            }
            let d = line.slope_output_per_s - c.slope;
            let (p, q) = (d * c.t_min, d * c.t_max);
            let upper = c.y_max - intercept - p.min(q);
            let lower = c.y_min - intercept - p.max(q);
            upper > limit || lower < -limit
        })
    }

    /// Whether every sample is finite and inside the outlier rule (then the slice loops apply).
    fn block_is_clean(&self, b: &SampleBlock) -> bool {
        if b.output.is_empty() {
            return false;
        }
        let finite = |v: &[f64]| v.iter().fold(true, |a, x| a & x.is_finite());
        if !finite(b.output) || !b.time_s.is_none_or(finite) {
            return false;
        }
        match (self.rule, b.time_s) {
            (None, _) => true,
            (Some(r), Some(ts)) => {
                b.output.iter().zip(ts).fold(true, |a, (&x, &t)| a & ((x - r.line.eval(t)).abs() <= r.limit))
            }
            (Some(r), None) => {
                let fs = self.fs.unwrap_or(1.0); // ok: set before processing
                let i0 = self.samples;
                b.output
                    .iter()
                    .enumerate()
                    .fold(true, |a, (i, &x)| a & ((x - r.line.eval((i0 + i as u64) as f64 / fs)).abs() <= r.limit))
            }
        }
    }

    /// The fast path: a block of finite samples, processed slice by slice.
    fn process_clean(&mut self, b: &SampleBlock) {
        let fs = self.fs.unwrap_or(1.0); // ok: process runs only once the rate is set
        let x = b.output;
        let n = x.len();
        let i0 = self.samples;
        let pos = |i: usize| Position { sample: i0 + i as u64, line: b.lines.map(|l| l[i]) };
        let t_first = b.time_s.map_or(i0 as f64 / fs, |t| t[0]);
        let (x0, t0) = *self.reference.get_or_insert((x[0], t_first));
        // Time checks.
        if let Some(ts) = b.time_s {
            let gap_limit = self.config.gap_factor / fs;
            let mut prev = self.prev_time.unwrap_or(ts[0]);
            let mut largest = self.quality.largest_interval_s.unwrap_or(f64::NEG_INFINITY);
            let start = usize::from(self.prev_time.is_none());
            // The smallest and largest interval first (no branch per sample): only when one is out
            // of bounds are the intervals looked at one by one.
            let first = if start == 0 { (ts[0] - prev, ts[0] - prev) } else { (f64::INFINITY, f64::NEG_INFINITY) };
            let (smallest, widest) = ts.windows(2).fold(first, |(lo, hi), w| {
                let dt = w[1] - w[0];
                (lo.min(dt), hi.max(dt))
            });
            let all_regular = smallest > 0.0 && widest <= gap_limit;
            if all_regular {
                largest = largest.max(widest);
                prev = ts[n - 1];
            }
            for (i, &t) in ts.iter().enumerate().skip(if all_regular { n } else { start }) {
                let dt = t - prev;
                if dt <= 0.0 || dt > gap_limit {
                    if dt == 0.0 {
                        self.quality.repeated_time.note(pos(i));
                    } else if dt < 0.0 {
                        self.quality.decreasing_time.note(pos(i));
                    } else {
                        self.quality.time_gaps.note(pos(i));
                    }
                }
                largest = largest.max(dt);
                prev = t;
            }
            if n > start {
                self.quality.largest_interval_s = Some(largest);
            }
            self.prev_time = Some(prev);
            self.last_time = prev;
        } else {
            self.last_time = (i0 + n as u64 - 1) as f64 / fs;
        }
        // Min, max and rail runs.
        let (lo, hi) = x.iter().fold((self.min, self.max), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        // Runs of equal samples, in pieces of RAIL_PIECE samples. Without two equal neighbours in a
        // piece every run inside it has one sample, shorter than any rail run
        // (rail_run_samples >= 2): only its first two samples can end a longer run (the one
        // carried in), and its last one starts the run carried out.
        const RAIL_PIECE: usize = 64;
        let mut start = 0;
        while start < n {
            let piece = &x[start..(start + RAIL_PIECE).min(n)];
            let repeats = piece.windows(2).fold(false, |a, w| a | (w[0] == w[1]));
            let stepped = if repeats { piece.len() } else { piece.len().min(2) };
            for (k, &v) in piece.iter().enumerate().take(stepped) {
                self.rail_step(v, pos(start + k));
            }
            if stepped < piece.len() {
                let (lo, hi) =
                    piece[stepped..].iter().fold((self.min, self.max), |(lo, hi), &v| (lo.min(v), hi.max(v)));
                self.min = lo;
                self.max = hi;
                let last = start + piece.len() - 1;
                self.rail.run_value = x[last];
                self.rail.run_len = 1;
                self.rail.run_start = Some(pos(last));
            }
            start += piece.len();
        }
        self.min = lo;
        self.max = hi;
        // Moments of (t - t0, x - x0).
        let m = match b.time_s {
            Some(ts) => Moments::of_shifted(ts, t0, x, x0),
            None => Moments::of_indexed(i0, fs, t0, x, x0),
        };
        self.moments.merge(&m);
        self.samples += n as u64;
        // Windows.
        for w in &mut self.windows {
            if w.m > 1 {
                w.add_slice(x, x0);
            }
        }
        if let Some(c) = b.temperature_c {
            for (i, &v) in x.iter().enumerate() {
                self.add_temp(Some(v - x0), Some(c[i]));
            }
        }
    }

    /// The general path: sample by sample, with missing samples and the outlier rule.
    fn process_each(&mut self, b: &SampleBlock) {
        let fs = self.fs.unwrap_or(1.0); // ok: process runs only once the rate is set
        let gap_limit = self.config.gap_factor / fs;
        self.scratch_t.clear();
        self.scratch_d.clear();
        for i in 0..b.output.len() {
            let idx = self.samples;
            self.samples += 1;
            let pos = Position { sample: idx, line: b.lines.map(|l| l[i]) };
            let x = b.output[i];
            let t = match b.time_s {
                Some(ts) => ts[i],
                None => idx as f64 / fs,
            };
            // Time stamps are checked whenever they are finite, even if the output is missing.
            if b.time_s.is_some() && t.is_finite() {
                if let Some(prev) = self.prev_time {
                    let dt = t - prev;
                    if dt == 0.0 {
                        self.quality.repeated_time.note(pos);
                    } else if dt < 0.0 {
                        self.quality.decreasing_time.note(pos);
                    } else if dt > gap_limit {
                        self.quality.time_gaps.note(pos);
                    }
                    if self.quality.largest_interval_s.is_none_or(|m| dt > m) {
                        self.quality.largest_interval_s = Some(dt);
                    }
                }
                self.prev_time = Some(t);
            }
            let mut ok = x.is_finite() && t.is_finite();
            if !ok {
                self.quality.missing.note(pos);
            } else if let Some(rule) = self.rule {
                if (x - rule.line.eval(t)).abs() > rule.limit {
                    self.outliers.note(pos);
                    ok = false;
                }
            }
            let temp_c = b.temperature_c.map(|c| c[i]);
            if !ok {
                self.end_run();
                for w in &mut self.windows {
                    w.add(None);
                }
                self.add_temp(None, None);
                continue;
            }
            let (x0, t0) = *self.reference.get_or_insert((x, t));
            let d = x - x0;
            self.last_time = t;
            self.scratch_t.push(t - t0);
            self.scratch_d.push(d);
            self.min = self.min.min(x);
            self.max = self.max.max(x);
            if self.rail.run_len > 0 && x == self.rail.run_value {
                self.rail.run_len += 1;
            } else {
                self.end_run();
                self.rail.run_value = x;
                self.rail.run_len = 1;
                self.rail.run_start = Some(pos);
            }
            for w in &mut self.windows {
                if w.m > 1 {
                    w.add(Some(d));
                }
            }
            self.add_temp(Some(d), temp_c);
        }
        let m = Moments::of(&self.scratch_t, &self.scratch_d);
        self.moments.merge(&m);
    }

    /// One sample of the rail-run tracking: it continues the current run or ends it (the running
    /// min and max, as of this sample, decide whether the ending run is at a rail).
    #[inline]
    fn rail_step(&mut self, v: f64, p: Position) {
        if self.rail.run_len > 0 && v == self.rail.run_value {
            self.rail.run_len += 1;
        } else {
            self.min = self.min.min(v);
            self.max = self.max.max(v);
            self.end_run();
            self.rail.run_value = v;
            self.rail.run_len = 1;
            self.rail.run_start = Some(p);
        }
    }

    #[inline]
    fn add_temp(&mut self, d: Option<f64>, c: Option<f64>) {
        let Some(c) = c else { return };
        let tw = &mut self.temp;
        tw.filled += 1;
        if let Some(d) = d {
            if c.is_finite() {
                tw.sum_d += d;
                tw.sum_c += c;
                tw.valid += 1;
            }
        }
        if tw.filled == tw.m {
            if tw.valid > 0 {
                let v = tw.valid as f64;
                tw.points.push((tw.sum_c / v, tw.sum_d / v));
            }
            tw.filled = 0;
            tw.valid = 0;
            tw.sum_c = 0.0;
            tw.sum_d = 0.0;
        }
    }

    fn end_run(&mut self) {
        let r = &mut self.rail;
        if r.run_len >= self.config.rail_run_samples {
            let v = r.run_value;
            for (rails, at) in [(&mut r.at_min, v == self.min), (&mut r.at_max, v == self.max)] {
                if !at {
                    continue;
                }
                if rails.value != Some(v) {
                    *rails = RailRuns { value: Some(v), ..RailRuns::default() };
                }
                rails.runs += 1;
                rails.samples += r.run_len;
                if rails.first.len() < FIRST_POSITIONS {
                    if let Some(p) = r.run_start {
                        rails.first.push(p);
                    }
                }
            }
        }
        r.run_len = 0;
    }

    /// Finishes the record and computes the figures (no outlier pass; see [`OutlierScan`]).
    pub fn finish(mut self) -> Result<FirstPass, StaticTestError> {
        if self.probe.is_some() {
            if self.has_time == Some(false) {
                return Err(StaticTestError::NoSampleRate);
            }
            self.end_probe()?;
        }
        self.end_run();
        let valid = self.moments.n as u64;
        if valid < 2 {
            return Err(StaticTestError::TooFewSamples { found: valid, needed: 2 });
        }
        let fs = self.fs.unwrap_or(1.0); // ok: set once samples exist
        let cfg = &self.config;
        let mut notes = Vec::new();
        let (x0, t0) = self.reference.unwrap_or((0.0, 0.0)); // ok: valid >= 2
        let mo = self.moments;
        let mean_output = x0 + mo.mean_d;
        let std_output = (mo.cdd / (mo.n - 1.0)).sqrt();
        let k = cfg.effective_scale_factor();
        let null = cfg.effective_null_output();
        let earth = cfg.latitude_deg.map(units::earth_rate_vertical_dph);
        let (bias_dps, bias_dph, earth_done) = match (k, null) {
            (Some(k), Some(f0)) => {
                let raw_dph = units::dps_to_dph((mean_output - f0) / k);
                let dph = raw_dph - earth.unwrap_or(0.0);
                (Some(units::dph_to_dps(dph)), Some(dph), earth.is_some())
            }
            _ => {
                notes.push(match k {
                    None => "bias in deg/s not computed: no scale factor given".to_string(),
                    Some(_) => "bias in deg/s not computed: no zero-rate reference (null_output) given".to_string(),
                });
                (None, None, false)
            }
        };
        if earth.is_some() && !earth_done {
            notes.push("earth rate not subtracted: the bias could not be computed".into());
        }
        let to_dph = |v_out: f64| k.map(|k| units::dps_to_dph(v_out / k.abs()));

        let mut stability: Vec<BiasStability> = Vec::new();
        let mut skipped = self.skipped.clone();
        for w in &self.windows {
            let (n, std) = if w.m == 1 { (valid, Some(std_output)) } else { (w.means.n, w.means.std()) };
            if n < cfg.min_windows {
                skipped.push(SkippedSmoothing {
                    smoothing_s: w.smoothing_s,
                    windows: n,
                    reason: format!("{n} whole windows of {} samples fit, at least {} needed", w.m, cfg.min_windows),
                });
                continue;
            }
            let Some(std) = std else { continue };
            let entry = BiasStability { smoothing_s: w.smoothing_s, output: std, dph: to_dph(std), windows: n };
            // One entry per key: a later smoothing time with the same key replaces the earlier one.
            let key = entry.key();
            match stability.iter_mut().find(|b| b.key() == key) {
                Some(b) => *b = entry,
                None => stability.push(entry),
            }
            if w.with_missing > 0 || w.empty > 0 {
                notes.push(format!(
                    "smoothing {} s: {} windows had missing samples (mean over the valid ones), {} had none and were dropped",
                    w.smoothing_s, w.with_missing, w.empty
                ));
            }
        }
        stability.sort_by(|a, b| a.smoothing_s.total_cmp(&b.smoothing_s));
        let find = |t: f64| stability.iter().find(|b| b.key() == smoothing_key(t)).map(|b| b.smoothing_s);
        let quoted = find(10.0).or_else(|| find(1.0)).or_else(|| {
            if self.config.include_one_sample {
                find(1.0 / fs)
            } else {
                None
            }
        });

        let (drift_out, drift_dph, drift_line) = if mo.ctt > 0.0 {
            let slope = mo.ctd / mo.ctt;
            let ssr = (mo.cdd - slope * mo.ctd).max(0.0);
            let resid = if mo.n > 2.0 { (ssr / (mo.n - 2.0)).sqrt() } else { 0.0 };
            let line = DriftLine {
                t0_s: t0,
                output_at_t0: x0 + mo.mean_d - slope * mo.mean_t,
                slope_output_per_s: slope,
                residual_std_output: resid,
            };
            (Some(units::per_s_to_per_h(slope)), k.map(|k| units::dps_per_s_to_dph_per_h(slope / k)), Some(line))
        } else {
            notes.push("drift not computed: all time stamps are equal".into());
            (None, None, None)
        };

        let temperature = if self.has_temp == Some(true) {
            match temperature_fit(&self.temp.points, x0, cfg, k) {
                Ok(t) => Some(t),
                Err(why) => {
                    notes.push(format!("temperature model not computed: {why}"));
                    None
                }
            }
        } else {
            None
        };

        let rule_line = drift_line.unwrap_or(DriftLine {
            t0_s: 0.0,
            output_at_t0: mean_output,
            slope_output_per_s: 0.0,
            residual_std_output: std_output,
        });
        let outlier_scan_needed = rule_line.residual_std_output > 0.0
            && self.outliers_possible(&rule_line, self.config.outlier_k_sigma * rule_line.residual_std_output);
        let mut quality = self.quality;
        quality.stuck_at_min =
            if self.rail.at_min.value == Some(self.min) { self.rail.at_min } else { RailRuns::default() };
        quality.stuck_at_max =
            if self.rail.at_max.value == Some(self.max) { self.rail.at_max } else { RailRuns::default() };
        let result = StaticTestResult {
            channel: self.config.channel.clone(),
            output_unit: self.config.output_unit,
            samples: self.samples,
            valid_samples: valid,
            sample_rate_hz: fs,
            sample_rate_source: if self.fs_given { SampleRateSource::Given } else { SampleRateSource::TimeStamps },
            duration_s: self.last_time - t0,
            mean_output,
            std_output,
            scale_factor_output_per_dps: k,
            null_output: null,
            bias_dps,
            bias_dph,
            earth_rate_component_dph: earth,
            earth_rate_subtracted: earth_done,
            bias_stability: stability,
            bias_stability_quoted_s: quoted,
            bias_stability_skipped: skipped,
            drift_output_per_h: drift_out,
            drift_dph_per_h: drift_dph,
            drift_line,
            temperature,
            quality,
            notes,
        };
        Ok(FirstPass { result, outlier_scan_needed })
    }
}

fn temperature_fit(
    points: &[(f64, f64)],
    x0: f64,
    cfg: &StaticTestConfig,
    k: Option<f64>,
) -> Result<TemperatureResult, String> {
    let needed = if cfg.temperature_quadratic { 4 } else { 3 };
    if points.len() < needed {
        return Err(format!(
            "{} windows of {} s with temperature, at least {needed} needed",
            points.len(),
            cfg.temperature_window_s
        ));
    }
    let temps: Vec<f64> = points.iter().map(|p| p.0).collect();
    let outs: Vec<f64> = points.iter().map(|p| p.1).collect();
    let line = fit::fit_line(&temps, &outs).map_err(|e| e.to_string())?;
    let n = points.len() as f64;
    let window_std = fit::sample_std(&outs).unwrap_or(0.0); // ok: len >= 3
    let ssr_line: f64 = points.iter().map(|&(c, d)| (d - line.eval(c)).powi(2)).sum();
    let (quadratic, model, ssr, params) = if cfg.temperature_quadratic {
        let q = fit::fit_polynomial(&temps, &outs, 2).map_err(|e| e.to_string())?;
        let c = &q.coefficients;
        let ssr: f64 = q.residuals.iter().map(|r| r * r).sum();
        (Some([c[0] + x0, c[1], c[2]]), "quadratic", ssr, 3.0)
    } else {
        (None, "linear", ssr_line, 2.0)
    };
    let comp = (ssr / (n - params)).sqrt();
    let to_dph = |v: f64| k.map(|k| units::dps_to_dph(v / k));
    Ok(TemperatureResult {
        window_s: cfg.temperature_window_s,
        windows: points.len() as u64,
        temp_min_c: temps.iter().copied().fold(f64::INFINITY, f64::min),
        temp_max_c: temps.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        slope_output_per_c: line.slope,
        intercept_output: line.intercept + x0,
        temp_sensitivity_dph_per_c: k.map(|k| units::dps_per_c_to_dph_per_c(line.slope / k)),
        quadratic_output: quadratic,
        compensation_model: model.into(),
        window_std_output: window_std,
        compensated_stability_output: comp,
        compensated_stability_dph: to_dph(comp).map(f64::abs),
    })
}

/// Second pass over the same record: finds outliers by the rule |x - drift line| > k sigma
/// (sigma the residual std about the first pass's drift line) and, with `drop_outliers`,
/// recomputes every figure without them.
#[derive(Debug, Clone)]
pub struct OutlierScan {
    inner: StaticTestAccumulator,
    line: DriftLine,
}

impl OutlierScan {
    /// Prepares the second pass from the first pass's result.
    pub fn new(first: &FirstPass, config: &StaticTestConfig) -> Result<Self, StaticTestError> {
        let first = &first.result;
        let mut cfg = config.clone();
        // The second pass reuses the rate the first pass used, so windows line up.
        cfg.sample_rate_hz = Some(first.sample_rate_hz);
        let mut inner = StaticTestAccumulator::new(cfg)?;
        inner.fs_given = config.sample_rate_hz.is_some();
        let line = first.drift_line.unwrap_or(DriftLine {
            t0_s: 0.0,
            output_at_t0: first.mean_output,
            slope_output_per_s: 0.0,
            residual_std_output: first.std_output,
        });
        // A record that lies exactly on its drift line has sigma 0: no sample is an outlier by this rule.
        if line.residual_std_output > 0.0 {
            inner.rule = Some(OutlierRule { line, limit: config.outlier_k_sigma * line.residual_std_output });
        }
        Ok(OutlierScan { inner, line })
    }

    /// Adds a block of the same record, in the same order as the first pass.
    pub fn push(&mut self, block: &SampleBlock) -> Result<(), StaticTestError> {
        self.inner.push(block)
    }

    /// The final result: the first pass's figures with the outlier report, or, with
    /// `drop_outliers`, the figures recomputed without the outliers.
    pub fn finish(mut self, first: FirstPass) -> Result<StaticTestResult, StaticTestError> {
        let drop = self.inner.config.drop_outliers;
        let report = OutlierReport {
            k_sigma: self.inner.config.outlier_k_sigma,
            residual_std_output: self.line.residual_std_output,
            outliers: std::mem::take(&mut self.inner.outliers),
            dropped: drop,
        };
        let mut out = if drop && report.outliers.count > 0 { self.inner.finish()?.result } else { first.result };
        out.quality.outliers = Some(report);
        Ok(out)
    }
}

impl FirstPass {
    /// The result of an outlier pass that found nothing, for a first pass whose extremes prove
    /// that none exists (`outlier_scan_needed` is false): the same report the pass would give.
    pub fn with_no_outliers(self, config: &StaticTestConfig) -> StaticTestResult {
        let mut out = self.result;
        let sigma = out.drift_line.map_or(out.std_output, |l| l.residual_std_output);
        out.quality.outliers = Some(OutlierReport {
            k_sigma: config.outlier_k_sigma,
            residual_std_output: sigma,
            outliers: QualityIssue::default(),
            dropped: config.drop_outliers,
        });
        out
    }
}

/// Evaluates a record held in memory: first pass, then the outlier pass when it can find any.
pub fn evaluate_static(block: &SampleBlock, config: &StaticTestConfig) -> Result<StaticTestResult, StaticTestError> {
    let mut acc = StaticTestAccumulator::new(config.clone())?;
    acc.push(block)?;
    let first = acc.finish()?;
    if !first.outlier_scan_needed {
        return Ok(first.with_no_outliers(config));
    }
    let mut scan = OutlierScan::new(&first, config)?;
    scan.push(block)?;
    scan.finish(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Feeds blocks through the sample-by-sample path only (the reference for the block path).
    fn each_path(config: &StaticTestConfig, blocks: &[SampleBlock]) -> StaticTestResult {
        let mut acc = StaticTestAccumulator::new(config.clone()).unwrap();
        for b in blocks {
            acc.check_block(b).unwrap();
            acc.track_extremes(b, false);
            acc.process_each(b);
        }
        acc.finish().unwrap().result
    }

    proptest! {
        /// The block path (slice loops, rail runs by pieces, interval extremes first) finds the same
        /// quality findings and figures as the sample-by-sample path, on records with long runs at
        /// the rails, repeated values and irregular time stamps, split into random blocks.
        #[test]
        fn block_path_equals_sample_path(
            runs in prop::collection::vec((0u8..6, 1usize..30), 2..40),
            stamps in prop::collection::vec((0u8..40, 0usize..2000), 0..6),
            split in 1usize..300,
        ) {
            let x: Vec<f64> = runs.iter().flat_map(|&(v, len)| std::iter::repeat_n(2.0 + 0.25 * f64::from(v), len)).collect();
            let n = x.len();
            let mut t: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
            for &(kind, at) in &stamps {
                if at > 0 && at < n {
                    // A repeated stamp, a decreasing one, a gap; each followed by regular stamps.
                    let shift = match kind {
                        0 => -0.5,
                        1 => -0.6,
                        2 => 3.0,
                        _ => 0.0,
                    };
                    t.iter_mut().skip(at).for_each(|v| *v += shift);
                }
            }
            let lines: Vec<u64> = (1..=n as u64).collect();
            let config = StaticTestConfig { sample_rate_hz: Some(2.0), smoothing_times_s: vec![1.0, 3.0], min_windows: 2, rail_run_samples: 4, ..StaticTestConfig::default() };
            let blocks: Vec<SampleBlock> = x
                .chunks(split)
                .zip(t.chunks(split))
                .zip(lines.chunks(split))
                .map(|((o, ts), l)| SampleBlock { output: o, time_s: Some(ts), temperature_c: None, lines: Some(l) })
                .collect();
            let mut acc = StaticTestAccumulator::new(config.clone()).unwrap();
            for b in &blocks {
                acc.push(b).unwrap();
            }
            let fast = acc.finish().unwrap().result;
            let reference = each_path(&config, &blocks);
            prop_assert_eq!(&fast.quality, &reference.quality);
            prop_assert_eq!(fast.valid_samples, reference.valid_samples);
            prop_assert!((fast.mean_output - reference.mean_output).abs() < 1e-12);
            prop_assert_eq!(fast.bias_stability.len(), reference.bias_stability.len());
            for (f, r) in fast.bias_stability.iter().zip(&reference.bias_stability) {
                prop_assert_eq!(f.smoothing_s, r.smoothing_s);
                prop_assert!((f.output - r.output).abs() < 1e-12 * (1.0 + r.output.abs()));
            }
        }
    }
}
