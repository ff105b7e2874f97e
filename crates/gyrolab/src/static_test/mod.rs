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

mod accumulator;
mod config;
mod extremes;
mod outlier;
mod rail;
mod result;

pub use accumulator::StaticTestAccumulator;
pub use config::{SampleBlock, StaticTestConfig, StaticTestError, FIRST_POSITIONS, RATE_PROBE_SAMPLES};
pub use outlier::OutlierScan;
pub use result::{
    bias_repeatability, reported_smoothing_times, smoothing_key, BiasRepeatability, BiasStability, DataQuality,
    DriftLine, FirstPass, OutlierReport, Position, QualityIssue, RailRuns, SkippedSmoothing, StaticTestResult,
    TemperatureResult,
};

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
