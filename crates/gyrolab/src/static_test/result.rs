//! The figures of a static test (with their JSON form), bias repeatability across tests, and
//! the smoothing-time keys.

use super::config::{StaticTestError, FIRST_POSITIONS};
use crate::fit;
use crate::sampling::SampleRateSource;
use crate::units::{self, OutputUnit};
use serde::{Deserialize, Serialize};

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
    pub(super) fn note(&mut self, p: Position) {
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

/// The first pass's figures, before the outlier pass
/// ([`StaticTestAccumulator::finish`](super::StaticTestAccumulator::finish)).
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
    /// Bias repeatability std(B0_i, n-1), deg/h, whenever every test has a scale factor: the
    /// null cancels (B0_i = F_i / K - F_null / K), so it is std(F_i / K_i) without a null.
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
        bias_repeatability_dph: match biases {
            Some(b) => fit::sample_std(&b),
            None => {
                // B0_i = (F_i - F_null) / K_i: with one K and one null for every test the null
                // cancels in the spread, so the repeatability needs K only.
                let k: Option<Vec<f64>> = results.iter().map(|r| r.scale_factor_output_per_dps).collect();
                let same_k = k.as_ref().is_some_and(|k| k.iter().all(|x| *x == k[0]));
                let nulls_agree = results.windows(2).all(|w| w[0].null_output == w[1].null_output);
                match k {
                    Some(k) if same_k && nulls_agree => {
                        let b0: Vec<f64> = means.iter().map(|f| units::dps_to_dph(f / k[0])).collect();
                        fit::sample_std(&b0)
                    }
                    _ => None,
                }
            }
        },
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
