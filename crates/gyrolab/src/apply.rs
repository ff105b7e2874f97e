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
    pub fn line(
        scale_factor: f64,
        zero_offset: f64,
        rate_min_dps: f64,
        rate_max_dps: f64,
    ) -> Result<Self, ApplyError> {
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
