//! Threshold and resolution of a rate gyro from small-rate plateaus and rate steps on a rate
//! table.
//!
//! Sources: GJB 2426A-2004 (光纤陀螺仪测试方法; 阈值 threshold and 分辨率 resolution: the smallest
//! input rate, and the smallest input-rate increment at a stated input rate, whose output change
//! is at least 50 % of the output the nominal scale factor predicts) and IEEE Std 528
//! (inertial sensor terminology: threshold, the largest absolute value of the minimum input that
//! produces an output equal to at least 50 % of the output expected using the nominal scale
//! factor; resolution, the same for an input change at a stated input). The standards define the
//! figures; the estimator over a set of tried rates is ours (docs/METHODS.md, "Threshold and
//! resolution"):
//!
//! - the samples are grouped by commanded rate; each group's mean ȳ and the standard error of
//!   the mean s = sd(n − 1) / √n;
//! - threshold: the reference is the zero-rate group (ȳ_0); for each tried rate Ω, the output
//!   change Δ = ȳ_Ω − ȳ_0, the expected change E = K Ω, the ratio Δ / E; the rate passes when
//!   the ratio is at least 0.5;
//! - resolution: the reference is the group at the base rate Ω_b; each other rate is a step
//!   δ = Ω − Ω_b, with Δ = ȳ_Ω − ȳ_b and E = K δ;
//! - a magnitude |Ω| (or |δ|) passes when both of its directions were tried and pass;
//!   the figure is the smallest tried magnitude such that it and every larger tried magnitude
//!   pass ([`Support::Value`]); when the smallest tried passes this is only an upper bound
//!   ([`Support::UpperBound`], "at most the smallest tried"); when the largest tried fails there
//!   is no value, only a lower bound ([`Support::LowerBound`], "above the largest tried");
//! - the noise: the standard error of Δ is √(s_Ω² + s_ref²); a pass or fail is marginal when
//!   |Δ − 0.5 E| < 2 √(s_Ω² + s_ref²), i.e. decided within two standard errors of the 50 % line.

use thiserror::Error;

/// The fraction of the expected output change a tried rate must reach (50 %).
pub const PASS_FRACTION: f64 = 0.5;
/// A decision within this many standard errors of the 50 % line is marginal.
pub const MARGINAL_STANDARD_ERRORS: f64 = 2.0;

/// The output samples recorded at one commanded rate.
#[derive(Debug, Clone, PartialEq)]
pub struct RateSamples {
    /// Commanded table rate, deg/s.
    pub rate_dps: f64,
    /// Output samples, output units.
    pub outputs: Vec<f64>,
}

/// Groups (rate, output) pairs by commanded rate (exactly equal rates), in order of first
/// appearance.
pub fn group_by_rate(rates_dps: &[f64], outputs: &[f64]) -> Vec<RateSamples> {
    let mut groups: Vec<RateSamples> = Vec::new();
    for (&r, &y) in rates_dps.iter().zip(outputs) {
        match groups.iter_mut().find(|g| g.rate_dps == r) {
            Some(g) => g.outputs.push(y),
            None => groups.push(RateSamples { rate_dps: r, outputs: vec![y] }),
        }
    }
    groups
}

/// Why the threshold or resolution cannot be estimated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ThresholdError {
    /// The nominal scale factor is zero or not finite.
    #[error("the nominal scale factor K = {0} must be finite and non-zero")]
    BadScaleFactor(f64),
    /// No group at the reference rate (0 deg/s for the threshold, the base rate for the resolution).
    #[error("no samples at the reference rate {rate_dps} deg/s: the output change is measured from it")]
    NoReference {
        /// The reference rate, deg/s.
        rate_dps: f64,
    },
    /// A group has fewer than two samples (no standard error).
    #[error("{samples} sample(s) at {rate_dps} deg/s: each rate needs at least 2 samples (for the standard error of its mean)")]
    TooFewSamples {
        /// The rate, deg/s.
        rate_dps: f64,
        /// Samples found.
        samples: usize,
    },
    /// Nothing but the reference rate was tried.
    #[error("only the reference rate was tried: expected rates (or steps) in both directions")]
    NoSteps,
    /// A magnitude was tried in one direction only.
    #[error("{magnitude_dps} deg/s was tried only in the {direction} direction: the definition needs both directions (+ and -)")]
    OneDirection {
        /// The magnitude, deg/s (of the rate, or of the step from the base rate).
        magnitude_dps: f64,
        /// `positive` or `negative`: the direction that was tried.
        direction: &'static str,
    },
    /// A sample or rate is not finite.
    #[error("a rate or output is not finite")]
    NotFinite,
}

/// What the data support about the figure (the conformity module's [`Support`]: a value, "at
/// most" the smallest tried magnitude when even that one passes, or "above" the largest tried
/// when even that one fails, with no value).
pub use crate::conformity::Support;

/// One tried rate (or step) against its reference.
#[derive(Debug, Clone, PartialEq)]
pub struct TriedRate {
    /// Commanded rate, deg/s.
    pub rate_dps: f64,
    /// Input change from the reference rate, deg/s (the rate itself for the threshold).
    pub step_dps: f64,
    /// Samples at this rate.
    pub samples: usize,
    /// Mean output, output units.
    pub mean_output: f64,
    /// Standard error of the mean output, output units.
    pub std_error: f64,
    /// Output change from the reference mean, output units.
    pub output_change: f64,
    /// Expected change K step, output units.
    pub expected_change: f64,
    /// output_change / expected_change.
    pub ratio: f64,
    /// Standard error of the ratio: √(s² + s_ref²) / |E|.
    pub ratio_std_error: f64,
    /// ratio >= 0.5.
    pub pass: bool,
    /// The decision lies within two standard errors of the 50 % line.
    pub marginal: bool,
}

/// A threshold or resolution estimate with its table of tried rates.
#[derive(Debug, Clone, PartialEq)]
pub struct StepEstimate {
    /// Reference rate, deg/s (0 for the threshold, the base rate for the resolution).
    pub reference_rate_dps: f64,
    /// Samples at the reference rate.
    pub reference_samples: usize,
    /// Mean output at the reference rate, output units.
    pub reference_mean: f64,
    /// Its standard error, output units.
    pub reference_std_error: f64,
    /// Nominal scale factor K used, output units per deg/s.
    pub scale_factor: f64,
    /// Every tried rate other than the reference, ordered by magnitude of the step, negative first.
    pub tried: Vec<TriedRate>,
    /// Distinct step magnitudes tried, ascending, deg/s, with whether both directions pass.
    pub magnitudes: Vec<(f64, bool)>,
    /// What the data support.
    pub support: Support,
    /// The figure, deg/s: the value ([`Support::Value`]) or the upper bound (the smallest
    /// tried, [`Support::UpperBound`]); `None` for a lower bound.
    pub value_dps: Option<f64>,
    /// The largest tried magnitude that fails, deg/s: the figure lies above it (for
    /// [`Support::LowerBound`], the lower bound itself); `None` when every magnitude passes.
    pub above_dps: Option<f64>,
    /// A row at a deciding magnitude (the value and the failing magnitude just below it, or the
    /// bound) is marginal.
    pub marginal: bool,
}

/// Mean and standard error of the mean (sd with n − 1, over √n).
fn mean_and_std_error(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Whether two step magnitudes are the same tried magnitude (rounding of Ω − Ω_b).
fn same_magnitude(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-12)
}

/// Threshold: the smallest input rate whose output change from the zero-rate output is at least
/// 50 % of K × rate, in both directions (module doc). `groups` must contain the 0 deg/s group.
pub fn threshold(groups: &[RateSamples], scale_factor: f64) -> Result<StepEstimate, ThresholdError> {
    estimate(groups, 0.0, scale_factor)
}

/// Resolution at base rate `base_rate_dps`: the smallest rate step from the base whose output
/// change is at least 50 % of K × step, for both signs (module doc). `groups` must contain the
/// base-rate group; every other group is a step from it.
pub fn resolution(
    groups: &[RateSamples],
    base_rate_dps: f64,
    scale_factor: f64,
) -> Result<StepEstimate, ThresholdError> {
    estimate(groups, base_rate_dps, scale_factor)
}

/// Index of the group at the reference rate (within rounding).
pub fn find_rate(groups: &[RateSamples], rate_dps: f64) -> Option<usize> {
    groups.iter().position(|g| g.rate_dps == rate_dps || same_magnitude(g.rate_dps, rate_dps))
}

fn estimate(groups: &[RateSamples], reference: f64, k: f64) -> Result<StepEstimate, ThresholdError> {
    if !k.is_finite() || k == 0.0 {
        return Err(ThresholdError::BadScaleFactor(k));
    }
    if !reference.is_finite()
        || groups.iter().any(|g| !g.rate_dps.is_finite() || g.outputs.iter().any(|y| !y.is_finite()))
    {
        return Err(ThresholdError::NotFinite);
    }
    if let Some(g) = groups.iter().find(|g| g.outputs.len() < 2) {
        return Err(ThresholdError::TooFewSamples { rate_dps: g.rate_dps, samples: g.outputs.len() });
    }
    let r = find_rate(groups, reference).ok_or(ThresholdError::NoReference { rate_dps: reference })?;
    let (ref_mean, ref_se) = mean_and_std_error(&groups[r].outputs);
    let mut tried: Vec<TriedRate> = groups
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != r)
        .map(|(_, g)| {
            let (mean, se) = mean_and_std_error(&g.outputs);
            // Steps from a base rate are rounded to 1e-12 deg/s (1.05 - 1 is 0.05, not 0.050000000000000044).
            let step = if reference == 0.0 { g.rate_dps } else { ((g.rate_dps - reference) * 1e12).round() / 1e12 };
            let change = mean - ref_mean;
            let expected = k * step;
            let se_change = (se * se + ref_se * ref_se).sqrt();
            TriedRate {
                rate_dps: g.rate_dps,
                step_dps: step,
                samples: g.outputs.len(),
                mean_output: mean,
                std_error: se,
                output_change: change,
                expected_change: expected,
                ratio: change / expected,
                ratio_std_error: se_change / expected.abs(),
                pass: change / expected >= PASS_FRACTION,
                marginal: (change - PASS_FRACTION * expected).abs() < MARGINAL_STANDARD_ERRORS * se_change,
            }
        })
        .collect();
    if tried.is_empty() {
        return Err(ThresholdError::NoSteps);
    }
    tried.sort_by(|a, b| a.step_dps.abs().total_cmp(&b.step_dps.abs()).then(a.step_dps.total_cmp(&b.step_dps)));
    // Distinct magnitudes, each with its rows (both directions required).
    let mut mags: Vec<(f64, Vec<usize>)> = Vec::new();
    for (i, t) in tried.iter().enumerate() {
        let m = t.step_dps.abs();
        match mags.last_mut() {
            Some((last, rows)) if same_magnitude(*last, m) => rows.push(i),
            _ => mags.push((m, vec![i])),
        }
    }
    for (m, rows) in &mags {
        let pos = rows.iter().any(|&i| tried[i].step_dps > 0.0);
        let neg = rows.iter().any(|&i| tried[i].step_dps < 0.0);
        if !(pos && neg) {
            return Err(ThresholdError::OneDirection {
                magnitude_dps: *m,
                direction: if pos { "positive" } else { "negative" },
            });
        }
    }
    let magnitudes: Vec<(f64, bool)> = mags.iter().map(|(m, rows)| (*m, rows.iter().all(|&i| tried[i].pass))).collect();
    // First index from which every magnitude passes (len when the largest fails).
    let first = magnitudes.iter().rposition(|(_, p)| !p).map_or(0, |i| i + 1);
    let n = magnitudes.len();
    let (support, value, deciding): (Support, Option<f64>, Vec<usize>) = if first == n {
        (Support::LowerBound, None, vec![n - 1])
    } else if first == 0 {
        (Support::UpperBound, Some(magnitudes[0].0), vec![0])
    } else {
        (Support::Value, Some(magnitudes[first].0), vec![first - 1, first])
    };
    let above = first.checked_sub(1).map(|i| magnitudes[i].0);
    let marginal = deciding.iter().any(|&j| mags[j].1.iter().any(|&i| tried[i].marginal));
    Ok(StepEstimate {
        reference_rate_dps: groups[r].rate_dps,
        reference_samples: groups[r].outputs.len(),
        reference_mean: ref_mean,
        reference_std_error: ref_se,
        scale_factor: k,
        tried,
        magnitudes,
        support,
        value_dps: value,
        above_dps: above,
        marginal,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(rate: f64, outputs: &[f64]) -> RateSamples {
        RateSamples { rate_dps: rate, outputs: outputs.to_vec() }
    }

    /// K = 2 output/(deg/s), zero-rate outputs {0.9, 1.1} (mean 1, sd 0.1414, se 0.1).
    fn zero() -> RateSamples {
        g(0.0, &[0.9, 1.1])
    }

    #[test]
    fn hand_worked_threshold_value() {
        // Rates ±0.1, ±0.2, ±0.5 deg/s; K = 2. Expected changes ±0.2, ±0.4, ±1.0.
        // ±0.1: means 1.05 / 0.95 -> changes ±0.05, ratio 0.25: fail.
        // ±0.2: means 1.3 / 0.7 -> changes ±0.3, ratio 0.75: pass.
        // ±0.5: means 2.0 / 0.0 -> ratio 1: pass. Threshold 0.2, above 0.1.
        let groups = vec![
            zero(),
            g(0.1, &[1.04, 1.06]),
            g(-0.1, &[0.94, 0.96]),
            g(0.2, &[1.29, 1.31]),
            g(-0.2, &[0.69, 0.71]),
            g(0.5, &[1.99, 2.01]),
            g(-0.5, &[-0.01, 0.01]),
        ];
        let e = threshold(&groups, 2.0).unwrap();
        assert_eq!(e.support, Support::Value);
        assert_eq!(e.value_dps, Some(0.2));
        assert_eq!(e.above_dps, Some(0.1));
        assert!((e.reference_mean - 1.0).abs() < 1e-12);
        // se of {0.9, 1.1}: sd = sqrt(0.02 / 1) = 0.141421, / sqrt(2) = 0.1.
        assert!((e.reference_std_error - 0.1).abs() < 1e-12);
        let r = e.tried.iter().find(|t| t.rate_dps == 0.2).unwrap();
        assert!((r.output_change - 0.3).abs() < 1e-12);
        assert!((r.expected_change - 0.4).abs() < 1e-12);
        assert!((r.ratio - 0.75).abs() < 1e-12);
        // se of {1.29, 1.31} = 0.01; se of change = sqrt(0.01^2 + 0.1^2) = 0.100499;
        // |0.3 - 0.2| = 0.1 < 2 x 0.1005: marginal.
        assert!(r.pass && r.marginal);
        assert!((r.ratio_std_error - (0.0001f64 + 0.01).sqrt() / 0.4).abs() < 1e-12);
        assert!(e.marginal);
        // Order: by magnitude, negative first.
        let order: Vec<f64> = e.tried.iter().map(|t| t.rate_dps).collect();
        assert_eq!(order, [-0.1, 0.1, -0.2, 0.2, -0.5, 0.5]);
        assert_eq!(e.magnitudes, [(0.1, false), (0.2, true), (0.5, true)]);
    }

    #[test]
    fn both_directions_and_every_larger_magnitude_must_pass() {
        let z = g(0.0, &[0.0, 0.0]);
        // K = 1. +0.1 passes, -0.1 fails (no change); ±0.2 pass; +0.3 fails: the threshold is
        // above the largest tried (a lower bound, no value).
        let groups = vec![
            z.clone(),
            g(0.1, &[0.1, 0.1]),
            g(-0.1, &[0.0, 0.0]),
            g(0.2, &[0.2, 0.2]),
            g(-0.2, &[-0.2, -0.2]),
            g(0.3, &[0.1, 0.1]),
            g(-0.3, &[-0.3, -0.3]),
        ];
        let e = threshold(&groups, 1.0).unwrap();
        assert_eq!(e.magnitudes, [(0.1, false), (0.2, true), (0.3, false)]);
        assert_eq!((e.support, e.value_dps, e.above_dps), (Support::LowerBound, None, Some(0.3)));
        // Noise-free: no standard error, no marginal decision (0.1/0.3 = 0.33 is 0.17 from 0.5).
        assert!(!e.marginal);
        // Every magnitude passes: an upper bound, the smallest tried.
        let groups = vec![z, g(0.1, &[0.06, 0.06]), g(-0.1, &[-0.05, -0.05])];
        let e = threshold(&groups, 1.0).unwrap();
        assert_eq!((e.support, e.value_dps, e.above_dps), (Support::UpperBound, Some(0.1), None));
        assert!(e.tried.iter().all(|t| t.pass));
    }

    #[test]
    fn negative_scale_factor_and_resolution_at_a_base_rate() {
        // K = -0.5; base 10 deg/s, mean output -5. Steps ±0.01: changes ∓0.001 (ratio 0.2,
        // fails); steps ±0.02: changes ∓0.006 vs expected ∓0.01 (ratio 0.6, passes).
        let groups = vec![
            g(10.0, &[-5.0, -5.0]),
            g(10.01, &[-5.001, -5.001]),
            g(9.99, &[-4.999, -4.999]),
            g(10.02, &[-5.006, -5.006]),
            g(9.98, &[-4.994, -4.994]),
        ];
        let e = resolution(&groups, 10.0, -0.5).unwrap();
        assert_eq!(e.magnitudes.len(), 2, "{:?}", e.magnitudes);
        assert_eq!(e.support, Support::Value);
        assert!((e.value_dps.unwrap() - 0.02).abs() < 1e-12);
        assert!((e.above_dps.unwrap() - 0.01).abs() < 1e-12);
        let t = &e.tried[0];
        assert!((t.step_dps + 0.01).abs() < 1e-12 && (t.ratio - 0.2).abs() < 1e-9, "{t:?}");
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        let z = g(0.0, &[0.0, 0.0]);
        assert_eq!(threshold(std::slice::from_ref(&z), 1.0).unwrap_err(), ThresholdError::NoSteps);
        assert_eq!(
            threshold(&[g(0.1, &[0.1, 0.1]), g(-0.1, &[0.0, 0.0])], 1.0).unwrap_err(),
            ThresholdError::NoReference { rate_dps: 0.0 }
        );
        assert_eq!(
            threshold(&[z.clone(), g(0.1, &[0.1, 0.1])], 1.0).unwrap_err(),
            ThresholdError::OneDirection { magnitude_dps: 0.1, direction: "positive" }
        );
        assert_eq!(
            threshold(&[z.clone(), g(0.1, &[0.1])], 1.0).unwrap_err(),
            ThresholdError::TooFewSamples { rate_dps: 0.1, samples: 1 }
        );
        assert_eq!(threshold(std::slice::from_ref(&z), 0.0).unwrap_err(), ThresholdError::BadScaleFactor(0.0));
        assert_eq!(threshold(&[z, g(0.1, &[f64::NAN, 0.0])], 1.0).unwrap_err(), ThresholdError::NotFinite);
        assert_eq!(
            resolution(&[g(1.0, &[1.0, 1.0])], 2.0, 1.0).unwrap_err(),
            ThresholdError::NoReference { rate_dps: 2.0 }
        );
    }

    #[test]
    fn grouping_keeps_first_appearance_order() {
        let g = group_by_rate(&[0.0, 0.1, 0.0, -0.1, 0.1], &[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(g.len(), 3);
        assert_eq!((g[0].rate_dps, g[0].outputs.clone()), (0.0, vec![1.0, 3.0]));
        assert_eq!((g[1].rate_dps, g[1].outputs.clone()), (0.1, vec![2.0, 5.0]));
    }

    /// The simulator's dead zone (`SensorModel::dead_zone_dps`): rates below it give the null,
    /// rates at or above it the full K rate; with white noise the threshold is the smallest
    /// tried rate at or above the dead zone.
    #[test]
    fn simulated_dead_zone() {
        use crate::sim::{RateTableGenerator, RateTableSpec, SensorModel};
        let tried = [0.05, 0.15, 0.25, 0.5];
        let mut rates = vec![0.0];
        tried.iter().for_each(|&r| rates.extend([r, -r]));
        let spec = RateTableSpec {
            rates_dps: rates,
            runs: 1,
            rest_samples: 0,
            samples_per_plateau: 500,
            ..Default::default()
        };
        let k = 0.01;
        let ideal = SensorModel { scale_factor_per_dps: k, null: 1.0, dead_zone_dps: 0.2, ..SensorModel::default() };
        let noisy = SensorModel { arw_deg_rt_h: 0.6, ..ideal.clone() };
        for (model, seed) in [(ideal, 1), (noisy, 2)] {
            let samples: Vec<_> = RateTableGenerator::new(&model, &spec, seed).unwrap().collect();
            let (r, y): (Vec<f64>, Vec<f64>) = samples.iter().map(|s| (s.rate_dps, s.output)).unzip();
            let groups = group_by_rate(&r, &y);
            if model.arw_deg_rt_h == 0.0 {
                // Inside the dead zone the output is the null exactly; outside, null + K rate.
                let at = |rate: f64| groups.iter().find(|g| g.rate_dps == rate).unwrap().outputs[0];
                assert_eq!(at(0.15), 1.0);
                assert!((at(0.25) - (1.0 + k * 0.25)).abs() < 1e-12);
            }
            let e = threshold(&groups, k).unwrap();
            assert_eq!((e.support, e.value_dps, e.above_dps), (Support::Value, Some(0.25), Some(0.15)), "{e:?}");
        }
    }

    /// A gap dead zone d (output K w for |w| >= d, none below), noise-free: the threshold is the
    /// smallest tried magnitude >= d, with the largest tried magnitude below d under it.
    mod dead_zone {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #[test]
            fn recovers_the_bracket(d in 0.001f64..1.0, k in prop_oneof![0.001f64..10.0, -10.0f64..-0.001], null in -5.0f64..5.0) {
                let tried = [0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0];
                let out = |w: f64| null + if w.abs() >= d { k * w } else { 0.0 };
                let mut groups = vec![g(0.0, &[out(0.0), out(0.0)])];
                for r in tried {
                    groups.push(g(r, &[out(r), out(r)]));
                    groups.push(g(-r, &[out(-r), out(-r)]));
                }
                let e = threshold(&groups, k).unwrap();
                let want = tried.iter().copied().find(|&r| r >= d).unwrap();
                let below = tried.iter().copied().rfind(|&r| r < d);
                match below {
                    Some(b) => {
                        prop_assert_eq!(e.support, Support::Value);
                        prop_assert_eq!(e.above_dps, Some(b));
                    }
                    None => prop_assert_eq!(e.support, Support::UpperBound),
                }
                prop_assert_eq!(e.value_dps, Some(want));
            }
        }
    }
}
