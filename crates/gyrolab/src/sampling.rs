//! The sampling interval of a record from its time stamps: the one estimator every command,
//! the static test and the Allan analysis use.
//!
//! Rule (docs/METHODS.md, "Sampling interval"):
//! - the nominal interval is the median of the finite, positive intervals among the first
//!   [`MEDIAN_INTERVALS`] (robust to a few gaps, repeated or reversed stamps);
//! - an interval is regular when it lies within ±50 % of the nominal interval; the first one
//!   that does not is reported (a gap, a repeated or reversed stamp, a non-finite stamp);
//! - the estimate is the mean interval: `(t[n-1] - t[0]) / (n - 1)` when every interval is
//!   regular (exact for uniform stamps, whatever their rounding), else the mean of the regular
//!   intervals (gaps do not stretch it).
//!
//! The mean rather than the median, because stamps written with a few decimals or by a host
//! clock jitter around the true interval: their median is one of the jittered values, their
//! mean converges on the true one.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Intervals examined for the median (nominal) interval.
pub const MEDIAN_INTERVALS: usize = 100_000;

/// Where the sample rate of a record came from (serialized as [`SampleRateSource::text`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleRateSource {
    /// Given by the user (option or plan).
    Given,
    /// Estimated from the time stamps by [`estimate_interval`].
    TimeStamps,
}

impl SampleRateSource {
    /// The description used in reports and JSON.
    pub fn text(self) -> &'static str {
        match self {
            SampleRateSource::Given => "given",
            SampleRateSource::TimeStamps => "estimated from the time stamps (mean interval)",
        }
    }
}

impl Serialize for SampleRateSource {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.text())
    }
}

impl<'de> Deserialize<'de> for SampleRateSource {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        [SampleRateSource::Given, SampleRateSource::TimeStamps]
            .into_iter()
            .find(|s| s.text() == text)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown sample-rate source '{text}'")))
    }
}

/// The first interval outside ±50 % of the nominal one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrregularInterval {
    /// Index of the sample that ends the interval (the interval is `t[index] - t[index - 1]`).
    pub index: usize,
    /// The interval, s (may be negative or not finite).
    pub interval_s: f64,
}

/// The estimated sampling interval of a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalEstimate {
    /// The estimate: the mean interval (see the module's rule), s.
    pub interval_s: f64,
    /// The nominal interval: the median of the first finite positive intervals, s.
    pub nominal_s: f64,
    /// The first irregular interval, if any.
    pub first_irregular: Option<IrregularInterval>,
    /// Number of irregular intervals.
    pub irregular: usize,
}

impl IntervalEstimate {
    /// The sample rate, Hz.
    pub fn rate_hz(&self) -> f64 {
        1.0 / self.interval_s
    }
}

/// Why no interval could be estimated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SamplingError {
    /// Fewer than two stamps.
    #[error("fewer than two samples: no sampling interval")]
    TooShort,
    /// No finite, increasing pair of stamps.
    #[error("the time stamps do not increase: expected increasing time stamps")]
    NotIncreasing,
}

/// Estimates the sampling interval from time stamps in seconds (see the module's rule).
///
/// ```
/// use gyrolab::sampling::estimate_interval;
/// let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
/// let e = estimate_interval(&t).unwrap();
/// assert!((e.interval_s - 0.01).abs() < 1e-15);
/// assert!(e.first_irregular.is_none());
/// ```
pub fn estimate_interval(t: &[f64]) -> Result<IntervalEstimate, SamplingError> {
    if t.len() < 2 {
        return Err(SamplingError::TooShort);
    }
    let mut head: Vec<f64> =
        t.windows(2).take(MEDIAN_INTERVALS).map(|w| w[1] - w[0]).filter(|d| d.is_finite() && *d > 0.0).collect();
    if head.is_empty() {
        return Err(SamplingError::NotIncreasing);
    }
    head.sort_by(f64::total_cmp);
    let nominal = head[head.len() / 2];
    let regular = |d: f64| d.is_finite() && (d - nominal).abs() <= 0.5 * nominal;
    let (mut first_irregular, mut irregular, mut sum, mut count) = (None, 0usize, 0.0, 0u64);
    for (i, w) in t.windows(2).enumerate() {
        let d = w[1] - w[0];
        if regular(d) {
            sum += d;
            count += 1;
        } else {
            irregular += 1;
            first_irregular.get_or_insert(IrregularInterval { index: i + 1, interval_s: d });
        }
    }
    let interval_s = if irregular == 0 { (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64 } else { sum / count as f64 };
    Ok(IntervalEstimate { interval_s, nominal_s: nominal, first_irregular, irregular })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_stamps_give_the_span_over_the_count() {
        // Stamps rounded to 3 decimals, as a logger writes them: the hand value is 1/100 Hz.
        let t: Vec<f64> = (0..50_001).map(|i| ((i as f64) * 0.01 * 1000.0).round() / 1000.0).collect();
        let e = estimate_interval(&t).unwrap();
        assert_eq!(e.interval_s, (t[50_000] - t[0]) / 50_000.0);
        assert!((e.rate_hz() - 100.0).abs() < 1e-9);
        assert_eq!(e.irregular, 0);
    }

    #[test]
    fn a_gap_is_reported_and_does_not_stretch_the_mean() {
        let mut t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.5).collect();
        for v in t.iter_mut().skip(600) {
            *v += 10.0; // a 10 s gap before sample 600
        }
        let e = estimate_interval(&t).unwrap();
        assert_eq!(e.first_irregular.map(|g| g.index), Some(600));
        assert_eq!(e.irregular, 1);
        assert!((e.interval_s - 0.5).abs() < 1e-12);
        assert_eq!(e.nominal_s, 0.5);
    }

    #[test]
    fn jittered_stamps_give_the_true_mean_interval() {
        // Alternating +-20 % jitter around 0.01 s: the median is one of the jittered values
        // (0.008 or 0.012); the mean is the true 0.01.
        let mut t = vec![0.0];
        for i in 1..2001 {
            let d = if i % 2 == 0 { 0.012 } else { 0.008 };
            t.push(t[i - 1] + d);
        }
        let e = estimate_interval(&t).unwrap();
        assert!((e.interval_s - 0.01).abs() < 1e-12, "{}", e.interval_s);
        assert!(e.nominal_s == 0.008 || (e.nominal_s - 0.012).abs() < 1e-12);
    }

    #[test]
    fn too_short_and_not_increasing_are_errors() {
        assert_eq!(estimate_interval(&[1.0]), Err(SamplingError::TooShort));
        assert_eq!(estimate_interval(&[1.0, 1.0, 0.5]), Err(SamplingError::NotIncreasing));
        assert_eq!(estimate_interval(&[f64::NAN, f64::NAN]), Err(SamplingError::NotIncreasing));
    }
}
