//! Options of a static test, the sample blocks it reads, and its errors.

use crate::fit::FitError;
use crate::units::OutputUnit;
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
    /// Latitude in degrees (input axis vertical, pointing up): subtract the earth rate when given
    /// (unless `null_contains_earth_rate`).
    pub latitude_deg: Option<f64>,
    /// The null was measured at rest on the same mounting (a rate test's rest reference or
    /// intercept), so it already contains the earth-rate component: it is reported, not
    /// subtracted again.
    pub null_contains_earth_rate: bool,
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
            null_contains_earth_rate: false,
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
    pub(super) fn validate(&self) -> Result<(), StaticTestError> {
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
