//! Test planning: how long a static record must be to measure a noise term from the overlapping
//! Allan deviation to a stated precision at a stated confidence.
//!
//! Sources: equivalent degrees of freedom of the overlapping Allan deviation by Greenhall &
//! Riley (2004) as in [`crate::allan::equivalent_dof`]; chi-squared confidence intervals
//! (NIST SP 1065 section 5.3); the noise types at which each term is read (IEEE Std 952-1997
//! annex C: angle random walk on white rate noise, alpha = 0; bias instability on flicker rate
//! noise, alpha = -1).

use crate::allan::{deviation_bounds, equivalent_dof, DeviationKind};
use crate::noise::{flat_run_record_s, flat_start_tau_s, BIAS_INSTABILITY_FACTOR, FLAT_MIN_SEGMENTS};
use crate::units::{arw_deg_rt_h_to_deg_rt_s, dph_to_dps};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The noise term a static test is planned for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseTerm {
    /// Bias instability B, read on the flat (flicker, alpha = -1) part of the curve.
    BiasInstability,
    /// Angle random walk N, read on the white-noise (alpha = 0) part.
    AngleRandomWalk,
}

impl NoiseTerm {
    /// Noise type alpha (power-law exponent of the rate noise) at which the term is read.
    pub fn alpha(self) -> i32 {
        match self {
            NoiseTerm::BiasInstability => -1,
            NoiseTerm::AngleRandomWalk => 0,
        }
    }

    /// Parses `bias-instability` / `b` or `arw` / `angle-random-walk` / `n`.
    pub fn parse(s: &str) -> Option<NoiseTerm> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "bias-instability" | "b" | "bi" => Some(NoiseTerm::BiasInstability),
            "arw" | "angle-random-walk" | "n" => Some(NoiseTerm::AngleRandomWalk),
            _ => None,
        }
    }
}

/// What to plan for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordLengthRequest {
    /// The term to measure.
    pub term: NoiseTerm,
    /// Wanted half-width of the interval relative to the value (0.1 = plus or minus 10 %).
    pub relative_precision: f64,
    /// Two-sided confidence level (0.95).
    pub confidence: f64,
    /// Sample rate of the record, Hz.
    pub sample_rate_hz: f64,
    /// Averaging time at which the term is read, s.
    pub tau_s: f64,
}

/// The plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordLength {
    /// The request.
    pub request: RecordLengthRequest,
    /// Noise type alpha assumed at tau.
    pub alpha: i32,
    /// Averaging factor m = tau * f_s.
    pub m: usize,
    /// Degrees of freedom needed.
    pub required_edf: f64,
    /// Samples needed.
    pub samples: u64,
    /// Record length needed, s.
    pub duration_s: f64,
    /// Record length needed, h.
    pub duration_h: f64,
    /// The interval such a record gives, relative to the value: (low, high) such as (0.9, 1.08).
    pub relative_interval: (f64, f64),
    /// For bias instability: the record the slope lines need to read B on a flat run beginning
    /// at tau ([`flat_run_record_s`]: its octave points to 8 tau, within a quarter of the
    /// record), s; the plan's length is at least this (`gyrolab allan` says a shorter record is
    /// too short by the same rule).
    #[serde(default)]
    pub flat_run_record_s: Option<f64>,
}

/// Why a plan cannot be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RecordLengthError {
    /// A parameter is out of range.
    #[error("{parameter} = {value} is out of range: expected {expected}")]
    OutOfRange {
        /// Parameter name.
        parameter: &'static str,
        /// Value given.
        value: f64,
        /// What is allowed.
        expected: &'static str,
    },
    /// No record shorter than the search limit reaches the precision.
    #[error("no record of up to {0} samples reaches that precision")]
    Unreachable(u64),
}

/// The averaging time at which bias instability is read for a gyro with angle random walk
/// `arw_deg_rt_h` and bias instability `bias_instability_dph`: where the white-noise line has
/// fallen to half the flicker floor, N / sqrt(tau) = 0.5 * 0.6643 B.
pub fn bias_instability_tau_s(arw_deg_rt_h: f64, bias_instability_dph: f64) -> f64 {
    let n = arw_deg_rt_h_to_deg_rt_s(arw_deg_rt_h);
    let floor = BIAS_INSTABILITY_FACTOR * dph_to_dps(bias_instability_dph);
    flat_start_tau_s(n, floor)
}

/// Relative interval (low, high) of a deviation with `edf` degrees of freedom.
fn relative_interval(edf: f64, confidence: f64) -> Option<(f64, f64)> {
    deviation_bounds(1.0, edf, confidence)
}

/// Plans a static record: the shortest record whose overlapping Allan deviation at tau has a
/// confidence interval within plus or minus the requested precision.
pub fn static_record_length(req: &RecordLengthRequest) -> Result<RecordLength, RecordLengthError> {
    let bad = |parameter, value, expected| Err(RecordLengthError::OutOfRange { parameter, value, expected });
    if !(req.relative_precision > 0.0 && req.relative_precision < 1.0) {
        return bad("relative precision", req.relative_precision, "between 0 and 1 (0.1 = 10 %)");
    }
    if !(req.confidence > 0.0 && req.confidence < 1.0) {
        return bad("confidence", req.confidence, "between 0 and 1");
    }
    if !(req.sample_rate_hz.is_finite() && req.sample_rate_hz > 0.0) {
        return bad("sample rate (Hz)", req.sample_rate_hz, "a positive number");
    }
    if !(req.tau_s.is_finite() && req.tau_s * req.sample_rate_hz >= 1.0) {
        return bad("tau (s)", req.tau_s, "at least one sample interval");
    }
    let m = (req.tau_s * req.sample_rate_hz).round().max(1.0) as usize;
    let alpha = req.term.alpha();
    let x = req.relative_precision;
    let good = |n: u64| {
        let edf = equivalent_dof(DeviationKind::Oadev, alpha, m, n as usize + 1);
        relative_interval(edf, req.confidence).is_some_and(|(lo, hi)| lo >= 1.0 - x && hi <= 1.0 + x)
    };
    // Stable32's stop limit for OADEV: m <= N / 4; for bias instability, the flat run the slope
    // lines read (its last point at 2^FLAT_MIN_SEGMENTS m, within the same limit).
    let mut lo = match req.term {
        NoiseTerm::BiasInstability => (4 * m as u64) << FLAT_MIN_SEGMENTS,
        NoiseTerm::AngleRandomWalk => 4 * m as u64,
    };
    if good(lo) {
        return finish(req, alpha, m, lo);
    }
    const LIMIT: u64 = 1 << 40;
    let mut hi = lo;
    while !good(hi) {
        lo = hi;
        hi = hi.saturating_mul(2);
        if hi > LIMIT {
            return Err(RecordLengthError::Unreachable(LIMIT));
        }
    }
    while hi - lo > 1.max(lo / 100_000) {
        let mid = lo + (hi - lo) / 2;
        if good(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    finish(req, alpha, m, hi)
}

fn finish(req: &RecordLengthRequest, alpha: i32, m: usize, n: u64) -> Result<RecordLength, RecordLengthError> {
    let edf = equivalent_dof(DeviationKind::Oadev, alpha, m, n as usize + 1);
    let interval = relative_interval(edf, req.confidence).unwrap_or((f64::NAN, f64::NAN));
    let duration_s = n as f64 / req.sample_rate_hz;
    Ok(RecordLength {
        request: req.clone(),
        alpha,
        m,
        required_edf: edf,
        samples: n,
        duration_s,
        duration_h: duration_s / 3600.0,
        relative_interval: interval,
        // At the tau read, m sample intervals.
        flat_run_record_s: (req.term == NoiseTerm::BiasInstability)
            .then(|| flat_run_record_s(m as f64 / req.sample_rate_hz)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{deviation_from_rate, AllanOptions, TauList};
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    #[test]
    fn planned_white_noise_record_meets_its_precision_in_simulation() {
        // Plan ARW to +-10 % at 90 % confidence, tau = 1 s at 10 Hz; then simulate many records
        // of that length and count how often the measured ADEV(1 s) lies within +-10 % of the
        // true sigma / sqrt(m): the fraction must be close to 90 % (binomial standard error of
        // 300 trials is 1.7 %; allow 6 %).
        let req = RecordLengthRequest {
            term: NoiseTerm::AngleRandomWalk,
            relative_precision: 0.10,
            confidence: 0.90,
            sample_rate_hz: 10.0,
            tau_s: 1.0,
        };
        let plan = static_record_length(&req).unwrap();
        assert!(plan.relative_interval.0 >= 0.9 && plan.relative_interval.1 <= 1.1);
        let n = plan.samples as usize;
        assert!(n > 100 && n < 100_000, "{n}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let truth = 1.0 / (10f64).sqrt();
        let trials = 300;
        let mut inside = 0;
        for _ in 0..trials {
            let v: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut rng)).collect();
            let c = deviation_from_rate(
                v,
                0.1,
                &AllanOptions::default().with_taus(TauList::Factors(vec![10])).with_confidence(None),
            )
            .unwrap();
            if (c.points[0].deviation / truth - 1.0).abs() <= 0.10 {
                inside += 1;
            }
        }
        let frac = inside as f64 / trials as f64;
        assert!((frac - 0.90).abs() < 0.06, "fraction within +-10 %: {frac}");
    }

    #[test]
    fn tighter_precision_needs_a_longer_record() {
        let mut req = RecordLengthRequest {
            term: NoiseTerm::BiasInstability,
            relative_precision: 0.25,
            confidence: 0.683,
            sample_rate_hz: 100.0,
            tau_s: bias_instability_tau_s(0.6, 12.0),
        };
        // +-25 % at 68.3 %: the flat run the slope lines read decides (32 tau = 2611 s).
        let loose = static_record_length(&req).unwrap();
        assert_eq!(loose.flat_run_record_s, Some(32.0 * loose.m as f64 / 100.0));
        assert!((loose.duration_s / (32.0 * req.tau_s) - 1.0).abs() < 1e-3, "{}", loose.duration_s);
        req.relative_precision = 0.10;
        let a = static_record_length(&req).unwrap();
        req.relative_precision = 0.03;
        let b = static_record_length(&req).unwrap();
        assert!(a.duration_s > loose.duration_s, "{} vs {}", a.duration_s, loose.duration_s);
        assert!(b.duration_s > 3.0 * a.duration_s, "{} vs {}", b.duration_s, a.duration_s);
        // tau for N = 0.6 deg/sqrt(h), B = 12 deg/h: (2 * 0.01 / (0.6643 * 12 / 3600))^2 = 81.6 s.
        assert!((req.tau_s - 81.6).abs() < 0.2, "{}", req.tau_s);
    }

    /// One rule for the plan and the reading (issue 55): on records of white noise and flicker
    /// (N 0.6 deg/sqrt(h), B 12 deg/h) shorter than the flat run the plan asks for, the slope
    /// lines call B's record too short and name a length between a quarter and twice the plan's
    /// (the reading places the flat at the upper bound of the curve's minimum, a lower limit; the
    /// plan at 0.6643 B) wherever the curve has not turned (3 of these 5 seeds); on records as
    /// long as the plan's, they never do.
    #[test]
    fn the_reading_and_the_plan_need_the_same_record_for_bias_instability() {
        use crate::noise::{slope_line_terms, Reading, Unresolved};
        use crate::sim::{SensorModel, StaticBlock, StaticGenerator, StaticSpec};
        let plan = static_record_length(&RecordLengthRequest {
            term: NoiseTerm::BiasInstability,
            relative_precision: 0.25,
            confidence: 0.683,
            sample_rate_hz: 50.0,
            tau_s: bias_instability_tau_s(0.6, 12.0),
        })
        .unwrap();
        let flat = plan.flat_run_record_s.unwrap();
        let model = SensorModel {
            arw_deg_rt_h: 0.6,
            bias_instability_dph: 12.0,
            flicker_tau_min_s: 0.2,
            flicker_tau_max_s: 1e5,
            ..SensorModel::default()
        };
        let mut too_short = 0;
        for (duration, seeds) in [(0.3 * flat, 1..6u64), (plan.duration_s, 6..11)] {
            for seed in seeds {
                let spec = StaticSpec { sample_rate_hz: 50.0, duration_s: duration, ..StaticSpec::default() };
                let mut g = StaticGenerator::new(&model, &spec, seed).unwrap();
                let (mut x, mut block) = (Vec::new(), StaticBlock::default());
                while g.next_block(&mut block, 1 << 16) > 0 {
                    x.extend_from_slice(&block.output);
                }
                let opts = AllanOptions {
                    kind: DeviationKind::Oadev,
                    taus: TauList::Octave,
                    confidence: Some(0.683),
                    max_factor: None,
                };
                let curve = deviation_from_rate(x, 0.02, &opts).unwrap();
                let b = slope_line_terms(&curve).unwrap().bias_instability;
                match b {
                    Reading::UpperBound { reason: Unresolved::RecordTooShort { needed_record_s }, .. } => {
                        assert!(duration < flat, "seed {seed}: {duration} s called too short");
                        assert!(
                            (0.25..2.0).contains(&(needed_record_s / flat)),
                            "seed {seed}: {needed_record_s} vs {flat}"
                        );
                        too_short += 1;
                    }
                    other => assert!(duration >= flat || other.value().is_none(), "seed {seed}: {other:?}"),
                }
            }
        }
        // The others' curves turned up at a noisy last point by chance: `no_supported_region`.
        assert!(too_short >= 3, "{too_short} of 5 short records called too short");
    }

    #[test]
    fn bad_requests() {
        let ok = RecordLengthRequest {
            term: NoiseTerm::BiasInstability,
            relative_precision: 0.2,
            confidence: 0.95,
            sample_rate_hz: 100.0,
            tau_s: 100.0,
        };
        assert!(static_record_length(&RecordLengthRequest { relative_precision: 0.0, ..ok.clone() }).is_err());
        assert!(static_record_length(&RecordLengthRequest { confidence: 1.0, ..ok.clone() }).is_err());
        assert!(static_record_length(&RecordLengthRequest { sample_rate_hz: 0.0, ..ok.clone() }).is_err());
        assert!(static_record_length(&RecordLengthRequest { tau_s: 0.001, ..ok.clone() }).is_err());
        assert!(static_record_length(&RecordLengthRequest { relative_precision: 1e-6, ..ok }).is_err());
    }
}
