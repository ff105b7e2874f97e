//! The temperature of a static record (a `temp_c` column beside the rate channels): its mean,
//! range and drift, and whether it moved enough to matter for the noise terms read from the
//! record. An Allan analysis assumes a sensor at one temperature (IEEE Std 952-1997, annex C:
//! the test is made at a stabilised temperature); a drifting temperature adds a ramp and a
//! slow wander that read as rate random walk or rate ramp.
//!
//! Rules (docs/METHODS.md, "Record temperature"): finite samples only (at least two); the drift
//! is the least-squares straight-line slope of temperature against time (the sample times on
//! the record's grid, sample i at i tau0), in degC/h; the temperature **moved** when its range
//! (max - min) exceeds [`MOVED_SPAN_C`].

use serde::{Deserialize, Serialize};

/// Range of a record's temperature above which it moved (1 degC): beyond the stability a
/// thermal chamber holds at a soaked point, and enough to move a MEMS gyro's bias by tens of
/// deg/h (typical bias sensitivities are 0.01 to 0.1 deg/s per degC).
pub const MOVED_SPAN_C: f64 = 1.0;

/// The temperature of a record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordTemperature {
    /// The column it was read from.
    pub column: String,
    /// Finite samples.
    pub samples: usize,
    /// Mean, degC.
    pub mean_c: f64,
    /// Lowest, degC.
    pub min_c: f64,
    /// Highest, degC.
    pub max_c: f64,
    /// Range max - min, degC.
    pub span_c: f64,
    /// Least-squares drift, degC/h.
    pub slope_c_per_h: f64,
    /// Whether the range exceeds [`MOVED_SPAN_C`].
    pub moved: bool,
}

/// The temperature summary of samples `temp_c` (NaN skipped) taken every `tau0_s` seconds;
/// `None` with fewer than two finite samples or a non-positive `tau0_s`.
///
/// ```
/// use gyrolab::record_temperature::record_temperature;
/// // 25 degC rising 0.5 degC over one hour at 1 Hz.
/// let t: Vec<f64> = (0..3601).map(|i| 25.0 + 0.5 * i as f64 / 3600.0).collect();
/// let s = record_temperature("temp_c", &t, 1.0).unwrap(); // ok: two finite samples at least
/// assert!((s.slope_c_per_h - 0.5).abs() < 1e-9 && (s.span_c - 0.5).abs() < 1e-12 && !s.moved);
/// ```
pub fn record_temperature(column: &str, temp_c: &[f64], tau0_s: f64) -> Option<RecordTemperature> {
    if tau0_s.is_nan() || tau0_s <= 0.0 {
        return None;
    }
    let (mut n, mut sum, mut min, mut max) = (0usize, 0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    let mut sum_t = 0.0f64;
    for (i, &v) in temp_c.iter().enumerate() {
        if v.is_finite() {
            n += 1;
            sum += v;
            sum_t += i as f64;
            min = min.min(v);
            max = max.max(v);
        }
    }
    if n < 2 {
        return None;
    }
    let (mean, mean_i) = (sum / n as f64, sum_t / n as f64);
    // Slope by centred sums (sample index as time, then per hour).
    let (mut sxy, mut sxx) = (0.0f64, 0.0f64);
    for (i, &v) in temp_c.iter().enumerate() {
        if v.is_finite() {
            let dx = i as f64 - mean_i;
            sxy += dx * (v - mean);
            sxx += dx * dx;
        }
    }
    let per_sample = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let span = max - min;
    Some(RecordTemperature {
        column: column.to_string(),
        samples: n,
        mean_c: mean,
        min_c: min,
        max_c: max,
        span_c: span,
        slope_c_per_h: per_sample / tau0_s * 3600.0,
        moved: span > MOVED_SPAN_C,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against numpy's polyfit slope and plain statistics, by hand: a ramp of 2 degC/h with a
    /// missing sample and a step.
    #[test]
    fn ramp_with_gaps_matches_a_hand_fit() {
        // 0.1 s samples: i -> 20 + 2 * (i * 0.1 / 3600); sample 5 missing.
        let mut t: Vec<f64> = (0..100).map(|i| 20.0 + 2.0 * (i as f64 * 0.1 / 3600.0)).collect();
        t[5] = f64::NAN;
        let s = record_temperature("temp_c", &t, 0.1).unwrap();
        assert_eq!(s.samples, 99);
        assert!((s.slope_c_per_h - 2.0).abs() < 1e-9, "{}", s.slope_c_per_h);
        assert!((s.min_c - 20.0).abs() < 1e-12 && (s.max_c - (20.0 + 2.0 * 9.9 / 3600.0)).abs() < 1e-12);
        assert!(!s.moved);
        // A step of 1.5 degC: moved.
        let step: Vec<f64> = (0..10).map(|i| if i < 5 { 20.0 } else { 21.5 }).collect();
        let s = record_temperature("t", &step, 1.0).unwrap();
        assert!(s.moved && (s.span_c - 1.5).abs() < 1e-12 && (s.mean_c - 20.75).abs() < 1e-12);
        // slope of the step by hand: sxy / sxx = (sum (i - 4.5)(y - 20.75)) / 82.5 = 18.75 / 82.5 per sample
        assert!((s.slope_c_per_h / 3600.0 - 18.75 / 82.5).abs() < 1e-12, "{}", s.slope_c_per_h);
        assert!(record_temperature("t", &[f64::NAN, 1.0], 1.0).is_none());
        assert!(record_temperature("t", &[1.0, 2.0], 0.0).is_none());
    }
}
