//! The sampling interval of a record from its time stamps, and the samples missing from it:
//! the one estimator every command, the static test and the Allan analysis use.
//!
//! Rule (docs/METHODS.md, "Sampling interval"):
//! - a first interval: the span over the count, `(t[n-1] - t[0]) / (n - 1)`, unless it differs
//!   by more than 5 % from the median of the mean intervals of blocks of [`BLOCK`] intervals
//!   (then a long gap stretches the span, and the block median is taken); block means are
//!   insensitive to jitter and to the bursts of host-stamped logs (a PC stamping an MPU6050
//!   read over USB: intervals of 0.9 ms, then long ones, about 100 Hz on average);
//! - a gap (missing samples) is a persistent shift of the time line, not one long interval: at
//!   every interval longer than 1.5 intervals, the floor (minimum) of the lateness
//!   `e_j = t_j - j dt` over [`WINDOW`] samples after it is compared with the floor over the
//!   [`WINDOW`] samples before it (back to the previous gap); a shift of k intervals (rounded,
//!   k >= 1) is a gap of k missing samples. A late stamp followed by a short interval (jitter, a
//!   burst) leaves the floor where it was: no gap;
//! - the estimate is the span over the count of intervals including the missing samples,
//!   `(t[n-1] - t[0]) / (n - 1 + missing)`, found again once with that interval (exact for
//!   uniform stamps, whatever their rounding; the mean rate of jittered or bursty stamps);
//! - a stamp that does not increase (repeated, reversed, not finite) is irregular: counted and
//!   the first one reported; it is no gap.
//!
//! The mean rather than the median: stamps written with a few decimals or by a host clock
//! jitter around the true interval; their median is one of the jittered values (0.9 ms for the
//! MPU6050 log, 1125 Hz), their mean over the span converges on the true one.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Intervals per block of the robust first interval.
pub const BLOCK: usize = 64;

/// Samples on each side of a long interval over which the floor of the lateness is taken.
pub const WINDOW: usize = 32;

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

/// Samples missing before one sample (a gap in the time stamps).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gap {
    /// Index of the first sample after the gap.
    pub index: usize,
    /// Number of samples missing before it.
    pub missing: usize,
    /// The interval that holds the gap, s.
    pub interval_s: f64,
}

/// The estimated sampling interval of a record.
#[derive(Debug, Clone, PartialEq)]
pub struct IntervalEstimate {
    /// The estimate: the mean interval (see the module's rule), s.
    pub interval_s: f64,
    /// The first interval of the rule (span over count, or the median block mean), s.
    pub nominal_s: f64,
    /// The first irregular interval (a gap or a stamp that does not increase), if any.
    pub first_irregular: Option<IrregularInterval>,
    /// Number of irregular intervals (gaps and stamps that do not increase).
    pub irregular: usize,
    /// The gaps, in order.
    pub gaps: Vec<Gap>,
    /// Samples missing in all gaps.
    pub missing: usize,
    /// The first stamp that does not increase (repeated, reversed or not finite), if any.
    pub first_non_increasing: Option<IrregularInterval>,
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

/// Estimates the sampling interval from time stamps in seconds and finds the gaps (see the
/// module's rule).
///
/// ```
/// use gyrolab::sampling::estimate_interval;
/// let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
/// let e = estimate_interval(&t).unwrap();
/// assert!((e.interval_s - 0.01).abs() < 1e-15);
/// assert!(e.first_irregular.is_none());
/// // Samples 500 and 501 missing: one gap of two samples before index 500.
/// let t: Vec<f64> = (0..1000).filter(|&i| i != 500 && i != 501).map(|i| i as f64 * 0.01).collect();
/// let e = estimate_interval(&t).unwrap();
/// assert_eq!((e.gaps[0].index, e.gaps[0].missing, e.missing), (500, 2, 2));
/// assert!((e.interval_s - 0.01).abs() < 1e-15);
/// ```
pub fn estimate_interval(t: &[f64]) -> Result<IntervalEstimate, SamplingError> {
    let n = t.len();
    if n < 2 {
        return Err(SamplingError::TooShort);
    }
    let increasing = |d: f64| d.is_finite() && d > 0.0;
    // Stamps that do not increase.
    let mut first_non_increasing = None;
    let mut non_increasing = 0usize;
    for (i, w) in t.windows(2).enumerate() {
        if !increasing(w[1] - w[0]) {
            non_increasing += 1;
            first_non_increasing.get_or_insert(IrregularInterval { index: i + 1, interval_s: w[1] - w[0] });
        }
    }
    // First interval: the span over the count, or the median block mean when a long gap
    // stretches the span.
    let (first, last) = (t.iter().position(|v| v.is_finite()), t.iter().rposition(|v| v.is_finite()));
    let (Some(first), Some(last)) = (first, last) else { return Err(SamplingError::NotIncreasing) };
    let span = t[last] - t[first];
    if span.is_nan() || span <= 0.0 || last == first {
        return Err(SamplingError::NotIncreasing);
    }
    let span_dt = span / (last - first) as f64;
    let block = BLOCK.min(n - 1);
    let mut blocks: Vec<f64> = (0..(n - 1) / block)
        .map(|k| (t[(k + 1) * block] - t[k * block]) / block as f64)
        .filter(|d| increasing(*d))
        .collect();
    let nominal = if n - 1 < 4 * BLOCK {
        // Too few blocks: the median interval.
        let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).filter(|d| increasing(*d)).collect();
        if d.is_empty() {
            return Err(SamplingError::NotIncreasing);
        }
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    } else if blocks.is_empty() {
        span_dt
    } else {
        blocks.sort_by(f64::total_cmp);
        let median = blocks[blocks.len() / 2];
        if (span_dt / median - 1.0).abs() <= 0.05 {
            span_dt
        } else {
            median
        }
    };
    let mut gaps = find_gaps(t, nominal);
    let mut missing: usize = gaps.iter().map(|g| g.missing).sum();
    let mut interval_s = span / ((last - first) + missing) as f64;
    // Again with the interval that counts the missing samples, until the count holds.
    for _ in 0..3 {
        if missing == 0 {
            break;
        }
        let again = find_gaps(t, interval_s);
        let m: usize = again.iter().map(|g| g.missing).sum();
        gaps = again;
        interval_s = span / ((last - first) + m) as f64;
        if m == missing {
            break;
        }
        missing = m;
    }
    missing = gaps.iter().map(|g| g.missing).sum();
    let gap_irregular = gaps.first().map(|g| IrregularInterval { index: g.index, interval_s: g.interval_s });
    let first_irregular = match (gap_irregular, first_non_increasing) {
        (Some(a), Some(b)) => Some(if a.index <= b.index { a } else { b }),
        (a, b) => a.or(b),
    };
    Ok(IntervalEstimate {
        interval_s,
        nominal_s: nominal,
        first_irregular,
        irregular: gaps.len() + non_increasing,
        gaps,
        missing,
        first_non_increasing,
    })
}

/// The gaps of `t` at interval `dt` (see the module's rule).
fn find_gaps(t: &[f64], dt: f64) -> Vec<Gap> {
    let n = t.len();
    let t0 = t[0];
    let lateness = |j: usize| t[j] - t0 - j as f64 * dt;
    let floor =
        |from: usize, to: usize| (from..to).map(lateness).filter(|e| e.is_finite()).fold(f64::INFINITY, f64::min);
    let mut gaps = Vec::new();
    let mut previous = 0usize;
    let mut i = 1;
    while i < n {
        let d = t[i] - t[i - 1];
        if d.is_finite() && d > 1.5 * dt {
            let before = floor(previous.max(i.saturating_sub(WINDOW)), i);
            let after = floor(i, (i + WINDOW).min(n));
            let shift = (after - before) / dt;
            if shift.is_finite() && shift >= 0.5 {
                let missing = shift.round() as usize;
                // The gap sits at the longest interval among the next few (a host stamp may
                // hold the delay over a burst).
                let end = (i + WINDOW / 2).min(n);
                let at = (i..end)
                    .max_by(|&a, &b| (t[a] - t[a - 1]).total_cmp(&(t[b] - t[b - 1])).then(b.cmp(&a)))
                    .unwrap_or(i);
                gaps.push(Gap { index: at, missing, interval_s: t[at] - t[at - 1] });
                previous = at;
                i = at + 1;
                continue;
            }
        }
        i += 1;
    }
    gaps
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
        assert_eq!((e.gaps[0].index, e.gaps[0].missing), (600, 20));
        assert!((e.interval_s - 0.5).abs() < 1e-12);
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
        assert!((e.nominal_s - 0.01).abs() < 1e-12, "{}", e.nominal_s);
    }

    /// A small deterministic generator (splitmix64) for jitter: uniform in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn bursty_host_stamps_give_the_true_rate() {
        // An MPU6050 at 100.3 Hz read by a PC: samples reach the host in USB frames every 20 ms
        // (plus 0 to 5 ms of scheduling delay) and are stamped on arrival, 0.9 ms apart within a
        // frame. The median interval is 0.9 ms (1125 Hz); the true rate is 100.3 Hz.
        let rate = 100.3;
        let mut st = 7u64;
        let mut t = Vec::new();
        let mut last = f64::NEG_INFINITY;
        for i in 0..60_000 {
            let true_t = i as f64 / rate;
            let frame = (true_t / 0.02).ceil() * 0.02 + 0.005 * uniform(&mut st);
            let stamp = frame.max(last + 0.0009);
            t.push(stamp);
            last = stamp;
        }
        let e = estimate_interval(&t).unwrap();
        assert!((e.rate_hz() / rate - 1.0).abs() < 0.005, "{} Hz", e.rate_hz());
        assert_eq!(e.missing, 0, "{:?}", &e.gaps[..e.gaps.len().min(5)]);
    }

    #[test]
    fn a_dozen_dropped_samples_in_jittered_stamps_are_found() {
        // 2 h at 200 Hz, stamps jittered uniformly by +-30 % of the interval, a clock 50 ppm
        // fast; 12 single and double drops at known places.
        let (rate, n) = (200.0 * (1.0 + 50e-6), 1_440_000usize);
        let drops: Vec<(usize, usize)> = (0..12).map(|k| (50_000 + k * 113_000, 1 + k % 2)).collect();
        let mut st = 11u64;
        let mut t = Vec::with_capacity(n);
        let mut expected = Vec::new();
        let mut i = 0usize;
        let mut d = 0;
        while i < n {
            if d < drops.len() && i == drops[d].0 {
                expected.push((t.len(), drops[d].1));
                i += drops[d].1;
                d += 1;
                continue;
            }
            t.push((i as f64 + 0.6 * (uniform(&mut st) - 0.5)) / rate);
            i += 1;
        }
        let e = estimate_interval(&t).unwrap();
        let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(found, expected);
        assert_eq!(e.missing, 18);
        assert!((e.rate_hz() / rate - 1.0).abs() < 1e-6, "{}", e.rate_hz());
    }

    #[test]
    fn long_gaps_are_counted() {
        // 1 h at 100 Hz with a 10 s and a 600 s gap: 1000 and 60 000 samples missing.
        let t: Vec<f64> = (0..360_000usize)
            .filter(|&i| !(100_000..101_000).contains(&i) && !(200_000..260_000).contains(&i))
            .map(|i| i as f64 * 0.01)
            .collect();
        let e = estimate_interval(&t).unwrap();
        let found: Vec<(usize, usize)> = e.gaps.iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(found, vec![(100_000, 1000), (199_000, 60_000)]);
        assert!((e.interval_s - 0.01).abs() < 1e-12);
    }

    #[test]
    fn too_short_and_not_increasing_are_errors() {
        assert_eq!(estimate_interval(&[1.0]), Err(SamplingError::TooShort));
        assert_eq!(estimate_interval(&[1.0, 1.0, 0.5]), Err(SamplingError::NotIncreasing));
        assert_eq!(estimate_interval(&[f64::NAN, f64::NAN]), Err(SamplingError::NotIncreasing));
    }
}
