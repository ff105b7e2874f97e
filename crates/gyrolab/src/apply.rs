//! Calibrations applied to output samples: output to rate, sample by sample or block by block
//! (no I/O, no state between blocks, so a reader can stream a file of any length through it).
//!
//! Sources: the inverse of the paper's line (Cheng et al. 2014, eq. 1): rate = (u - F0) / K; the
//! inverse of the polynomial model (`fit.rs`) by bisection-safeguarded Newton iteration within
//! the calibrated range; the three-axis inverse omega = S^-1 (u - b) (`triad.rs`, the form
//! omega = T K (u - b) of Tedaldi et al. 2014). Outside the calibrated range nothing is
//! extrapolated silently: the rate is continued along the tangent line at the nearer end of the
//! range (first order, never the polynomial's own growth) and the sample is flagged.

use crate::fit::PolynomialFit;
use crate::triad::TriadCalibration;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Relative margin of the calibrated range (of its span; of the limit for a triad) within which a
/// rate still counts as inside, so that the calibration's own end plateaus are not flagged for
/// their noise.
pub const RANGE_MARGIN: f64 = 1e-3;

/// Where a calibrated rate lies relative to the calibrated range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RangeStatus {
    /// Inside the calibrated range.
    Inside,
    /// Below the lowest calibrated rate (continued along the end tangent).
    Below,
    /// Above the highest calibrated rate (continued along the end tangent); for a triad, some
    /// |rate| beyond the calibrated limit.
    Above,
    /// The output sample is not a finite number (the rate is NaN).
    NotFinite,
}

/// One calibrated rate and its range status.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AppliedRate {
    /// Rate, deg/s.
    pub rate_dps: f64,
    /// Range status.
    pub status: RangeStatus,
}

/// Why a calibration cannot be applied.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ApplyError {
    /// The scale factor is zero or not finite.
    #[error("the scale factor must be a non-zero number, got {0}")]
    BadScaleFactor(f64),
    /// The rate range is empty or not finite.
    #[error("the calibrated rate range {min} .. {max} deg/s is not a valid interval")]
    BadRange {
        /// Lower end, deg/s.
        min: f64,
        /// Upper end, deg/s.
        max: f64,
    },
    /// A polynomial without coefficients, or with a non-finite one.
    #[error("the polynomial model needs finite coefficients (order 1 or more)")]
    BadPolynomial,
    /// The polynomial turns back inside the range, so an output does not give one rate.
    #[error("the polynomial model is not monotonic in the calibrated range: its slope changes sign near {rate_dps:.3} deg/s")]
    NotMonotonic {
        /// Where the slope changes sign, deg/s.
        rate_dps: f64,
    },
    /// The three-axis matrix cannot be inverted.
    #[error("the three-axis scale-factor matrix is singular: it cannot be inverted")]
    SingularMatrix,
    /// Blocks of different lengths.
    #[error("output blocks of different lengths: {0:?}")]
    LengthMismatch([usize; 3]),
}

/// The output model of one axis.
#[derive(Debug, Clone, PartialEq)]
enum Model {
    Line { scale_factor: f64, zero_offset: f64 },
    Polynomial(PolynomialFit),
}

/// A single-axis calibration ready to apply: the line or the polynomial, and the calibrated range.
#[derive(Debug, Clone, PartialEq)]
pub struct SingleAxisCalibration {
    model: Model,
    rate_min_dps: f64,
    rate_max_dps: f64,
}

fn check_range(min: f64, max: f64) -> Result<(), ApplyError> {
    if min.is_finite() && max.is_finite() && min < max {
        Ok(())
    } else {
        Err(ApplyError::BadRange { min, max })
    }
}

impl SingleAxisCalibration {
    /// The line output = K * rate + F0 (K output units per deg/s, F0 output units), valid on
    /// [rate_min_dps, rate_max_dps].
    pub fn line(scale_factor: f64, zero_offset: f64, rate_min_dps: f64, rate_max_dps: f64) -> Result<Self, ApplyError> {
        if !(scale_factor.is_finite() && scale_factor != 0.0) {
            return Err(ApplyError::BadScaleFactor(scale_factor));
        }
        if !zero_offset.is_finite() {
            return Err(ApplyError::BadPolynomial);
        }
        check_range(rate_min_dps, rate_max_dps)?;
        Ok(SingleAxisCalibration { model: Model::Line { scale_factor, zero_offset }, rate_min_dps, rate_max_dps })
    }

    /// The polynomial output = sum_k c_k rate^k (ascending powers, as in the calibration file),
    /// valid on [rate_min_dps, rate_max_dps]; it must be monotonic there.
    pub fn polynomial(coefficients: &[f64], rate_min_dps: f64, rate_max_dps: f64) -> Result<Self, ApplyError> {
        check_range(rate_min_dps, rate_max_dps)?;
        if coefficients.len() < 2 || coefficients.iter().any(|c| !c.is_finite()) {
            return Err(ApplyError::BadPolynomial);
        }
        if coefficients.len() == 2 {
            return Self::line(coefficients[1], coefficients[0], rate_min_dps, rate_max_dps);
        }
        let p = PolynomialFit {
            coefficients: coefficients.to_vec(),
            residuals: Vec::new(),
            rms_residual: 0.0,
            centre: 0.0,
            half_range: 1.0,
            scaled_coefficients: coefficients.to_vec(),
        };
        // Monotonic on the range: the slope keeps its sign on a fine grid (the slope of an order-n
        // polynomial has at most n - 1 roots, so 4096 intervals resolve any practical case).
        const STEPS: usize = 4096;
        let at = |k: usize| rate_min_dps + (rate_max_dps - rate_min_dps) * k as f64 / STEPS as f64;
        let sign = p.derivative(at(0)).signum();
        for k in 0..=STEPS {
            let d = p.derivative(at(k));
            if d == 0.0 || d.signum() != sign {
                return Err(ApplyError::NotMonotonic { rate_dps: at(k) });
            }
        }
        Ok(SingleAxisCalibration { model: Model::Polynomial(p), rate_min_dps, rate_max_dps })
    }

    /// Calibrated range, deg/s.
    pub fn range_dps(&self) -> (f64, f64) {
        (self.rate_min_dps, self.rate_max_dps)
    }

    /// The rate that produces output `u`, with its range status.
    pub fn rate(&self, u: f64) -> AppliedRate {
        if !u.is_finite() {
            return AppliedRate { rate_dps: f64::NAN, status: RangeStatus::NotFinite };
        }
        let (lo, hi) = (self.rate_min_dps, self.rate_max_dps);
        let margin = RANGE_MARGIN * (hi - lo);
        let status_of = |r: f64| {
            if r < lo - margin {
                RangeStatus::Below
            } else if r > hi + margin {
                RangeStatus::Above
            } else {
                RangeStatus::Inside
            }
        };
        match &self.model {
            Model::Line { scale_factor, zero_offset } => {
                let r = (u - zero_offset) / scale_factor;
                AppliedRate { rate_dps: r, status: status_of(r) }
            }
            Model::Polynomial(p) => {
                if let Some(r) = p.invert(u, lo, hi) {
                    return AppliedRate { rate_dps: r, status: RangeStatus::Inside };
                }
                // Outside [p(lo), p(hi)]: continue along the tangent at the nearer end.
                let (plo, phi) = (p.eval(lo), p.eval(hi));
                let end = if (u - plo).abs() < (u - phi).abs() { lo } else { hi };
                let r = end + (u - p.eval(end)) / p.derivative(end);
                AppliedRate { rate_dps: r, status: status_of(r) }
            }
        }
    }

    /// Applies the calibration to a block of outputs; `out` is cleared and filled, one per sample.
    pub fn apply_block(&self, outputs: &[f64], out: &mut Vec<AppliedRate>) {
        out.clear();
        out.extend(outputs.iter().map(|&u| self.rate(u)));
    }
}

/// A three-axis rate vector and its range status.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AppliedTriad {
    /// Rates about x, y, z, deg/s.
    pub rates_dps: [f64; 3],
    /// `Above` when some |rate| exceeds the calibrated limit, `NotFinite` for a bad sample.
    pub status: RangeStatus,
}

/// A three-axis calibration ready to apply: omega = S^-1 (u - b).
#[derive(Debug, Clone, PartialEq)]
pub struct TriadApplier {
    inverse: [[f64; 3]; 3],
    bias: [f64; 3],
    rate_limit_dps: f64,
}

impl TriadApplier {
    /// Inverts S once; fails when S is singular.
    pub fn new(calibration: &TriadCalibration) -> Result<Self, ApplyError> {
        let inverse = calibration.inverse_matrix().ok_or(ApplyError::SingularMatrix)?;
        if calibration.bias.iter().any(|b| !b.is_finite()) {
            return Err(ApplyError::SingularMatrix);
        }
        Ok(TriadApplier { inverse, bias: calibration.bias, rate_limit_dps: calibration.rate_limit_dps })
    }

    /// The rate vector that produces outputs `u` (gyros x, y, z).
    pub fn rates(&self, u: [f64; 3]) -> AppliedTriad {
        if u.iter().any(|v| !v.is_finite()) {
            return AppliedTriad { rates_dps: [f64::NAN; 3], status: RangeStatus::NotFinite };
        }
        let d = [u[0] - self.bias[0], u[1] - self.bias[1], u[2] - self.bias[2]];
        let rates_dps = self.inverse.map(|row| row[0] * d[0] + row[1] * d[1] + row[2] * d[2]);
        let limit = self.rate_limit_dps * (1.0 + RANGE_MARGIN);
        let status = if rates_dps.iter().any(|r| r.abs() > limit) { RangeStatus::Above } else { RangeStatus::Inside };
        AppliedTriad { rates_dps, status }
    }

    /// Applies the calibration to blocks of the three outputs (equal lengths); `out` is cleared
    /// and filled, one per sample.
    pub fn apply_block(&self, x: &[f64], y: &[f64], z: &[f64], out: &mut Vec<AppliedTriad>) -> Result<(), ApplyError> {
        if x.len() != y.len() || x.len() != z.len() {
            return Err(ApplyError::LengthMismatch([x.len(), y.len(), z.len()]));
        }
        out.clear();
        out.extend((0..x.len()).map(|k| self.rates([x[k], y[k], z[k]])));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rate_test::{evaluate, RateTable, RateTestOptions};
    use crate::segment::{rate_observations, segment_log, PlateauReduction, SegmentKind, SegmentOptions};
    use crate::sim::{raw_log_setpoints, simulate_raw_log, RawLogProfile};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    const RATES: [f64; 7] = [-300.0, -100.0, -30.0, 0.0, 30.0, 100.0, 300.0];

    /// A single-axis gyro with a small quadratic term (5e-8 V/(deg/s)^2: 4.5 mV, 0.6 deg/s at
    /// 300 deg/s, far above the noise of a plateau mean), calibrated by order 1 and order 2 through
    /// the segmentation and `rate_test::evaluate`, then applied to the calibration's own plateaus.
    /// A plateau mean's rate error is sigma / sqrt(n) / K with n >= 425 samples: 0.013 deg/s.
    #[test]
    fn applying_a_calibration_to_its_own_plateaus_returns_the_table_rates() {
        let (k, f0, c2, sigma) = (0.0075, 2.5, 5e-8, 0.002);
        let sim = simulate_raw_log(&raw_log_setpoints(&RATES, 2, true, true), &RawLogProfile::default(), 21).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(22);
        let noise = Normal::new(0.0, sigma).unwrap();
        let out: Vec<f64> = sim.true_rate.iter().map(|w| f0 + k * w + c2 * w * w + noise.sample(&mut rng)).collect();
        let o = SegmentOptions::default();
        let seg = segment_log(&sim.time, &sim.logged_rate, &o).unwrap();
        let (obs, rest) = rate_observations(&seg, &sim.time, &out, PlateauReduction::Mean, o.rest).unwrap();
        let table = RateTable::from_observations(&obs, rest).unwrap();
        let quad = evaluate(&table, &RateTestOptions { order: 2, ..Default::default() }).unwrap();
        let cal = SingleAxisCalibration::polynomial(&quad.polynomial.coefficients, -300.0, 300.0).unwrap();
        let line = SingleAxisCalibration::line(quad.scale_factor(), quad.zero_offset(), -300.0, 300.0).unwrap();
        let tol = 5.0 * sigma / 425f64.sqrt() / k + 5.0 * 0.01 / 425f64.sqrt();
        let mut worst_line: f64 = 0.0;
        for s in seg.iter().filter(|s| matches!(s.kind, SegmentKind::Plateau { .. })) {
            let u = out[s.start_index..s.end_index].iter().sum::<f64>() / s.samples() as f64;
            let got = cal.rate(u);
            assert_eq!(got.status, RangeStatus::Inside, "{s:?}");
            assert!((got.rate_dps - s.rate_dps).abs() < tol, "{} vs {} (tol {tol})", got.rate_dps, s.rate_dps);
            worst_line = worst_line.max((line.rate(u).rate_dps - s.rate_dps).abs());
        }
        // The straight line cannot follow the quadratic term: the test can tell the models apart.
        assert!(worst_line > 3.0 * tol, "{worst_line}");
        let mut block = Vec::new();
        cal.apply_block(&out[..100], &mut block);
        assert_eq!(block.len(), 100);
    }

    #[test]
    fn outside_the_range_is_flagged_and_continued_along_the_end_tangent() {
        let c = [2.5, 0.0075, 2e-8];
        let p = |w: f64| c[0] + c[1] * w + c[2] * w * w;
        let cal = SingleAxisCalibration::polynomial(&c, -300.0, 300.0).unwrap();
        // Inside: exact inverse.
        let r = cal.rate(p(123.0));
        assert_eq!(r.status, RangeStatus::Inside);
        assert!((r.rate_dps - 123.0).abs() < 1e-9);
        // Above: 300 + (u - p(300)) / p'(300), by hand.
        let u = p(400.0);
        let r = cal.rate(u);
        assert_eq!(r.status, RangeStatus::Above);
        let by_hand = 300.0 + (u - p(300.0)) / (c[1] + 2.0 * c[2] * 300.0);
        assert!((r.rate_dps - by_hand).abs() < 1e-9, "{} vs {by_hand}", r.rate_dps);
        let r = cal.rate(p(-400.0));
        assert_eq!(r.status, RangeStatus::Below);
        // Within the margin: inside.
        assert_eq!(cal.rate(p(300.3)).status, RangeStatus::Inside);
        // Line: (u - F0) / K.
        let line = SingleAxisCalibration::line(0.0075, 2.5, -300.0, 300.0).unwrap();
        assert!((line.rate(2.5 + 0.0075 * 77.0).rate_dps - 77.0).abs() < 1e-12);
        assert_eq!(line.rate(2.5 + 0.0075 * 350.0).status, RangeStatus::Above);
        assert_eq!(line.rate(f64::NAN).status, RangeStatus::NotFinite);
    }

    #[test]
    fn bad_calibrations_are_errors() {
        // Slope 1 + 0.02 x vanishes at -50 deg/s, inside the range.
        assert!(matches!(
            SingleAxisCalibration::polynomial(&[0.0, 1.0, 0.01], -100.0, 100.0),
            Err(ApplyError::NotMonotonic { .. })
        ));
        assert!(SingleAxisCalibration::polynomial(&[0.0, 1.0, 0.01], 0.0, 100.0).is_ok());
        assert!(matches!(SingleAxisCalibration::line(0.0, 2.5, -1.0, 1.0), Err(ApplyError::BadScaleFactor(_))));
        assert!(matches!(SingleAxisCalibration::line(1.0, 2.5, 1.0, -1.0), Err(ApplyError::BadRange { .. })));
        let singular = TriadCalibration {
            matrix: [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            bias: [0.0; 3],
            rate_limit_dps: 1.0,
        };
        assert_eq!(TriadApplier::new(&singular), Err(ApplyError::SingularMatrix));
        let ok = TriadCalibration {
            matrix: [[2.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 5.0]],
            bias: [1.0; 3],
            rate_limit_dps: 10.0,
        };
        let a = TriadApplier::new(&ok).unwrap();
        let r = a.rates([3.0, 5.0, 6.0]);
        assert_eq!(r.rates_dps, [1.0, 1.0, 1.0]);
        assert_eq!(a.rates([41.0, 1.0, 1.0]).status, RangeStatus::Above);
        let mut out = Vec::new();
        assert!(matches!(a.apply_block(&[1.0], &[1.0, 2.0], &[1.0], &mut out), Err(ApplyError::LengthMismatch(_))));
    }
}
