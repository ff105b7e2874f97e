//! The `fill` gap policy: isolated missing samples of a rate record (NaN on the record's
//! uniform grid) filled by linear interpolation between their valid neighbours, so that the
//! terms around them are kept and the long taus with them.
//!
//! Rule (docs/METHODS.md, "Gap policies"): a run of at most [`MAX_FILLED_RUN`] missing samples
//! with a valid sample on both sides gets the values of the straight line between those two
//! samples; longer runs, and runs at either end of the record, stay missing (analysed by the
//! gap rule of [`super::deviation_from_rate_with_gaps`]).
//!
//! Effect on the deviation: an interpolated sample of white rate noise has the variance
//! (1 + 1) / 4 = 1/2 of a true one (a run of k: at least 1/2), and it correlates with its
//! neighbours; with a share p of samples filled, the Allan variance at tau0 moves by at most
//! about p (relative) and by less at longer taus, where the average over m samples holds the
//! filled values at their mean. Checked by a test against the same seed without drops (every
//! tau within [`FILL_TOLERANCE`] relative for p <= 1 %).
//!
//! Source: the rule is this module's own (linear interpolation, stated above); NIST SP 1065
//! (Riley 2008) section 8.7 discusses gaps in a record, and the gap rule left for longer runs
//! follows it.

/// Longest run of missing samples filled.
pub const MAX_FILLED_RUN: usize = 3;

/// Largest share of a record's samples the fill rule is checked for (1 %): a record with more
/// samples filled gets a warning that its short-tau deviations and N are biased.
pub const MAX_FILLED_SHARE: f64 = 0.01;

/// Largest relative change of a deviation point that filling a share of at most 1 % of the
/// samples may cause (the bound the test checks, at every tau).
pub const FILL_TOLERANCE: f64 = 0.02;

/// What [`fill_isolated`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FillCount {
    /// Samples filled.
    pub filled: usize,
    /// Runs filled.
    pub runs: usize,
    /// Samples left missing (longer runs, or runs at an end of the record).
    pub left: usize,
}

/// Fills every run of at most [`MAX_FILLED_RUN`] NaN samples that has a finite sample on both
/// sides by linear interpolation between those two; returns the counts.
///
/// ```
/// use gyrolab::allan::gap_fill::fill_isolated;
/// let mut y = vec![1.0, f64::NAN, 3.0, 4.0, f64::NAN, f64::NAN, 7.0, f64::NAN];
/// let c = fill_isolated(&mut y);
/// assert_eq!(&y[..7], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
/// assert!(y[7].is_nan()); // at the end: no neighbour after it
/// assert_eq!((c.filled, c.runs, c.left), (3, 2, 1));
/// ```
pub fn fill_isolated(rate: &mut [f64]) -> FillCount {
    let mut count = FillCount::default();
    let n = rate.len();
    let mut i = 0;
    while i < n {
        if !rate[i].is_nan() {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && rate[i].is_nan() {
            i += 1;
        }
        let run = i - start;
        let bounded = start > 0 && i < n && rate[start - 1].is_finite() && rate[i].is_finite();
        if bounded && run <= MAX_FILLED_RUN {
            let (a, b) = (rate[start - 1], rate[i]);
            for (k, v) in rate[start..i].iter_mut().enumerate() {
                let w = (k + 1) as f64 / (run + 1) as f64;
                *v = a + (b - a) * w;
            }
            count.filled += run;
            count.runs += 1;
        } else {
            count.left += run;
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{deviation_from_rate, deviation_from_rate_with_gaps, AllanOptions, DeviationKind};

    /// splitmix64, uniform in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// White noise plus a random walk (Box-Muller normals), the two noises of a gyro record.
    fn record(seed: u64, n: usize) -> Vec<f64> {
        let mut st = seed;
        let mut walk = 0.0;
        (0..n)
            .map(|_| {
                let (u1, u2) = (uniform(&mut st).max(1e-300), uniform(&mut st));
                let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
                let (u3, u4) = (uniform(&mut st).max(1e-300), uniform(&mut st));
                walk += 2e-3 * (-2.0 * u3.ln()).sqrt() * (std::f64::consts::TAU * u4).cos();
                z + walk
            })
            .collect()
    }

    #[test]
    fn filled_drops_move_every_tau_by_less_than_the_tolerance() {
        // 20 min at 250 Hz; one sample in 150 dropped (runs of 1, and a few of 2 and 3), as a
        // host-stamped ROS bag has them. The curve of the filled record against the curve of
        // the same seed without drops, at every octave tau, over four seeds.
        let opts = AllanOptions::new(DeviationKind::Oadev).with_confidence(None);
        for seed in [1u64, 2, 3, 4] {
            let n = 300_000;
            let full = record(seed, n);
            let mut st = seed ^ 0xABCD;
            let mut dropped = full.clone();
            let mut i = 10;
            while i < n - 10 {
                if uniform(&mut st) < 1.0 / 150.0 {
                    let run = 1 + usize::from(uniform(&mut st) < 0.1) + usize::from(uniform(&mut st) < 0.05);
                    dropped[i..i + run].fill(f64::NAN);
                    i += run + 1;
                }
                i += 1;
            }
            let truth = deviation_from_rate(full, 0.004, &opts).unwrap();
            let gapped = deviation_from_rate_with_gaps(dropped.clone(), 0.004, &opts).unwrap();
            let c = fill_isolated(&mut dropped);
            assert_eq!(c.left, 0);
            assert!(c.filled as f64 / n as f64 <= 0.01, "{c:?}");
            let filled = deviation_from_rate(dropped, 0.004, &opts).unwrap();
            // Filling keeps every tau of the complete record; the gap rule loses the long ones.
            assert_eq!(filled.points.len(), truth.points.len());
            assert!(gapped.points.len() < truth.points.len(), "seed {seed}");
            for (f, t) in filled.points.iter().zip(&truth.points) {
                assert_eq!(f.m, t.m);
                let rel = (f.deviation / t.deviation - 1.0).abs();
                assert!(rel <= FILL_TOLERANCE, "seed {seed}, m {}: {rel}", f.m);
            }
        }
    }

    #[test]
    fn long_runs_and_ends_stay_missing() {
        let mut y = [f64::NAN, 1.0, f64::NAN, f64::NAN, f64::NAN, f64::NAN, 2.0, f64::NAN, 3.0];
        let c = fill_isolated(&mut y);
        assert!(y[0].is_nan() && y[2..6].iter().all(|v| v.is_nan()));
        assert_eq!(y[7], 2.5);
        assert_eq!((c.filled, c.runs, c.left), (1, 1, 5));
        // A neighbour that is infinite is not valid: the run stays missing.
        let mut z = [1.0, f64::NAN, f64::INFINITY];
        assert_eq!(fill_isolated(&mut z).filled, 0);
    }
}
