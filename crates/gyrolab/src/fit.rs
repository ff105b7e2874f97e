//! Least-squares fits: the straight line of the paper (eq. 2-3) and polynomials by QR.
//!
//! Sources: the paper's eq. 2-3 (closed-form least-squares line, evaluated here in centred form,
//! which is algebraically identical and loses less precision); polynomials are solved by a
//! Householder QR factorisation of the Vandermonde matrix in a scaled variable
//! u = (x - c) / h (Golub & Van Loan, Matrix Computations, section 5.3), never by normal equations.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FitError {
    /// x and y have different lengths.
    #[error("x has {x} values but y has {y}")]
    LengthMismatch {
        /// Number of x values.
        x: usize,
        /// Number of y values.
        y: usize,
    },
    /// Too few distinct x values for the requested model.
    #[error("a fit of order {order} needs at least {needed} distinct input values, found {found}")]
    TooFewPoints {
        /// Polynomial order requested.
        order: usize,
        /// Distinct x values needed.
        needed: usize,
        /// Distinct x values found.
        found: usize,
    },
    /// A value is NaN or infinite.
    #[error("a value to fit is not finite")]
    NonFinite,
}

/// A least-squares straight line y = slope * x + intercept.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineFit {
    /// Slope (the scale factor K when x is the input rate).
    pub slope: f64,
    /// Intercept (the zero offset F0 when x is the input rate).
    pub intercept: f64,
}

impl LineFit {
    /// Value of the line at x.
    pub fn eval(&self, x: f64) -> f64 {
        self.slope * x + self.intercept
    }
}

fn distinct_count(x: &[f64]) -> usize {
    let mut v: Vec<f64> = x.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v.len()
}

/// Fits y = K x + F0 by least squares (paper eq. 2-3, centred form).
pub fn fit_line(x: &[f64], y: &[f64]) -> Result<LineFit, FitError> {
    if x.len() != y.len() {
        return Err(FitError::LengthMismatch { x: x.len(), y: y.len() });
    }
    if x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(FitError::NonFinite);
    }
    let found = distinct_count(x);
    if found < 2 {
        return Err(FitError::TooFewPoints { order: 1, needed: 2, found });
    }
    let m = x.len() as f64;
    let mx = x.iter().sum::<f64>() / m;
    let my = y.iter().sum::<f64>() / m;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (&xi, &yi) in x.iter().zip(y) {
        sxy += (xi - mx) * (yi - my);
        sxx += (xi - mx) * (xi - mx);
    }
    let slope = sxy / sxx;
    Ok(LineFit { slope, intercept: my - slope * mx })
}

/// A least-squares polynomial y = sum_k c_k x^k with its residuals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PolynomialFit {
    /// Coefficients in ascending powers of x: c_0, c_1, ..., c_order.
    pub coefficients: Vec<f64>,
    /// Residuals y_i - p(x_i), in the order of the input points.
    pub residuals: Vec<f64>,
    /// Root-mean-square of the residuals.
    pub rms_residual: f64,
    /// Centre c of the scaled variable u = (x - c) / h used for the solve.
    pub centre: f64,
    /// Half-range h of the scaled variable.
    pub half_range: f64,
    /// Coefficients in ascending powers of u (better conditioned; used for evaluation).
    pub scaled_coefficients: Vec<f64>,
}

impl PolynomialFit {
    /// Order of the polynomial.
    pub fn order(&self) -> usize {
        self.coefficients.len().saturating_sub(1)
    }

    /// Value of the polynomial at x (evaluated in the scaled variable, Horner's rule).
    pub fn eval(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.half_range;
        self.scaled_coefficients.iter().rev().fold(0.0, |acc, &c| acc * u + c)
    }

    /// Derivative dp/dx at x.
    pub fn derivative(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.half_range;
        let n = self.scaled_coefficients.len();
        let mut acc = 0.0;
        for k in (1..n).rev() {
            acc = acc * u + k as f64 * self.scaled_coefficients[k];
        }
        acc / self.half_range
    }

    /// The input x in [lo, hi] at which p(x) = y (the inverse model, output to rate), found by
    /// bisection safeguarded Newton iteration; `None` when p is not monotonic enough on the
    /// interval to bracket y.
    pub fn invert(&self, y: f64, lo: f64, hi: f64) -> Option<f64> {
        let (mut a, mut b) = (lo, hi);
        let (mut fa, fb) = (self.eval(a) - y, self.eval(b) - y);
        if fa == 0.0 {
            return Some(a);
        }
        if fb == 0.0 {
            return Some(b);
        }
        if fa.signum() == fb.signum() || !fa.is_finite() || !fb.is_finite() {
            return None;
        }
        let mut x = 0.5 * (a + b);
        for _ in 0..200 {
            let fx = self.eval(x) - y;
            if fx == 0.0 {
                return Some(x);
            }
            if fx.signum() == fa.signum() {
                a = x;
                fa = fx;
            } else {
                b = x;
            }
            let d = self.derivative(x);
            let newton = x - fx / d;
            x = if d != 0.0 && newton > a.min(b) && newton < a.max(b) { newton } else { 0.5 * (a + b) };
            if (b - a).abs() <= 1e-15 * (1.0 + x.abs()) {
                break;
            }
        }
        Some(x)
    }
}

/// Fits a polynomial of the given order to (x, y) by least squares (Householder QR).
pub fn fit_polynomial(x: &[f64], y: &[f64], order: usize) -> Result<PolynomialFit, FitError> {
    if x.len() != y.len() {
        return Err(FitError::LengthMismatch { x: x.len(), y: y.len() });
    }
    if x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(FitError::NonFinite);
    }
    let found = distinct_count(x);
    if found < order + 1 || order == 0 && found < 1 {
        return Err(FitError::TooFewPoints { order, needed: order + 1, found });
    }
    let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    let centre = 0.5 * (lo + hi);
    let half_range = if hi > lo { 0.5 * (hi - lo) } else { 1.0 };
    let n = x.len();
    let cols = order + 1;
    let a = DMatrix::from_fn(n, cols, |i, k| ((x[i] - centre) / half_range).powi(k as i32));
    let b = DVector::from_column_slice(y);
    let qr = a.qr();
    let q = qr.q();
    let r = qr.r();
    let qtb = q.transpose() * &b;
    let scaled = r.solve_upper_triangular(&qtb).ok_or(FitError::TooFewPoints { order, needed: order + 1, found })?;
    let scaled_coefficients: Vec<f64> = scaled.iter().copied().collect();
    // Expand sum_k a_k ((x - c)/h)^k into powers of x.
    let mut coefficients = vec![0.0; cols];
    for (k, &ak) in scaled_coefficients.iter().enumerate() {
        let scale = ak / half_range.powi(k as i32);
        let mut binom = 1.0;
        for (j, coefficient) in coefficients.iter_mut().enumerate().take(k + 1) {
            // term: binom(k, j) x^j (-c)^(k-j)
            *coefficient += scale * binom * (-centre).powi((k - j) as i32);
            binom = binom * (k - j) as f64 / (j + 1) as f64;
        }
    }
    let mut fit = PolynomialFit {
        coefficients,
        residuals: Vec::new(),
        rms_residual: 0.0,
        centre,
        half_range,
        scaled_coefficients,
    };
    fit.residuals = x.iter().zip(y).map(|(&xi, &yi)| yi - fit.eval(xi)).collect();
    fit.rms_residual = (fit.residuals.iter().map(|r| r * r).sum::<f64>() / n as f64).sqrt();
    Ok(fit)
}

/// Arithmetic mean; `None` for an empty slice.
pub fn mean(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        None
    } else {
        Some(v.iter().sum::<f64>() / v.len() as f64)
    }
}

/// Sample standard deviation with n - 1 in the denominator; `None` for fewer than two values.
pub fn sample_std(v: &[f64]) -> Option<f64> {
    if v.len() < 2 {
        return None;
    }
    let m = mean(v)?;
    let ss: f64 = v.iter().map(|x| (x - m) * (x - m)).sum();
    Some((ss / (v.len() - 1) as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn line_through_hand_points() {
        // x = 0, 1, 2; y = 1, 3, 7: slope = sum (x-1)(y-11/3) / 2 = (-1*-8/3 + 1*10/3)/2 = 3,
        // intercept = 11/3 - 3 = 2/3.
        let f = fit_line(&[0.0, 1.0, 2.0], &[1.0, 3.0, 7.0]).unwrap();
        assert_relative_eq!(f.slope, 3.0, epsilon = 1e-12);
        assert_relative_eq!(f.intercept, 2.0 / 3.0, epsilon = 1e-12);
    }

    #[test]
    fn line_matches_paper_equation_form() {
        // Paper eq. 2-3 in their raw-sum form, evaluated independently.
        let x = [-300.0, -60.0, 0.0, 25.0, 135.0, 300.0];
        let y = [0.25, 2.18, 2.51, 2.72, 3.53, 4.69];
        let m = x.len() as f64;
        let sx: f64 = x.iter().sum();
        let sy: f64 = y.iter().sum();
        let sxy: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        let sxx: f64 = x.iter().map(|a| a * a).sum();
        let k = (sxy - sx * sy / m) / (sxx - sx * sx / m);
        let f0 = sy / m - k * sx / m;
        let f = fit_line(&x, &y).unwrap();
        assert_relative_eq!(f.slope, k, max_relative = 1e-12);
        assert_relative_eq!(f.intercept, f0, max_relative = 1e-12);
    }

    #[test]
    fn polynomial_recovers_exact_cubic() {
        let x: Vec<f64> = (-10..=10).map(|i| i as f64 * 30.0).collect();
        let c = [2.5, 7.5e-3, -1e-7, 3e-10];
        let y: Vec<f64> = x.iter().map(|&v| c[0] + c[1] * v + c[2] * v * v + c[3] * v * v * v).collect();
        let f = fit_polynomial(&x, &y, 3).unwrap();
        for (got, want) in f.coefficients.iter().zip(c) {
            assert_relative_eq!(*got, want, max_relative = 1e-7);
        }
        assert!(f.rms_residual < 1e-12);
        let r = f.invert(f.eval(123.0), -300.0, 300.0).unwrap();
        assert_relative_eq!(r, 123.0, epsilon = 1e-9);
    }

    #[test]
    fn order_one_polynomial_equals_line() {
        let x = [-2.0, -1.0, 0.0, 1.0, 5.0];
        let y = [1.0, 2.5, 2.9, 4.2, 9.0];
        let l = fit_line(&x, &y).unwrap();
        let p = fit_polynomial(&x, &y, 1).unwrap();
        assert_relative_eq!(p.coefficients[1], l.slope, max_relative = 1e-12);
        assert_relative_eq!(p.coefficients[0], l.intercept, max_relative = 1e-12);
    }

    #[test]
    fn too_few_points_is_an_error() {
        assert!(matches!(fit_line(&[1.0, 1.0], &[2.0, 3.0]), Err(FitError::TooFewPoints { .. })));
        assert!(fit_polynomial(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], 3).is_err());
        assert!(matches!(fit_line(&[1.0, f64::NAN], &[2.0, 3.0]), Err(FitError::NonFinite)));
    }

    #[test]
    fn std_of_hand_values() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, sum of squares 32, sample variance 32/7.
        let v = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0];
        assert_relative_eq!(sample_std(&v).unwrap(), (32.0f64 / 7.0).sqrt());
        assert_eq!(sample_std(&[1.0]), None);
    }
}
