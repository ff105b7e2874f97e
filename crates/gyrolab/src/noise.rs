//! Gyro noise terms from an Allan deviation curve (rate in deg/s, tau in s).
//!
//! Source: IEEE Std 952-1997 annex C (Allan variance noise model of a single-axis gyro):
//!   sigma^2(tau) = 3 Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2
//! with Q quantization (deg), N angle random walk (deg/sqrt(s)), B bias instability (deg/s),
//! K rate random walk (deg/s/sqrt(s)), R rate ramp (deg/s^2). Two extractions:
//! - slope lines (IEEE 952 annex C.2; the MathWorks "Inertial sensor noise analysis using Allan
//!   variance" example): the log-log segment whose slope is nearest -1, -1/2 (left of the
//!   minimum), +1/2, +1 (right of it) fixes a line of that exact slope, read at tau = 1 s for N,
//!   tau = 3 s for K, and through the point itself for Q and R; B = sigma_min / sqrt(2 ln2/pi)
//!   = sigma_min / 0.6643 at an interior minimum;
//! - a weighted least-squares fit of the five-term model to sigma^2 with non-negative
//!   coefficients (Lawson & Hanson, "Solving Least Squares Problems", 1974, ch. 23, NNLS), each
//!   point weighted by the inverse half-width of its confidence interval on the variance.
//!
//! Kalibr's IMU noise model (ethz-asl/kalibr wiki, "IMU Noise Model"): gyroscope_noise_density
//! = N in rad/s/sqrt(Hz), gyroscope_random_walk = K in rad/s^2/sqrt(Hz).

use crate::allan::{AllanCurve, AllanPoint, DeviationKind};
use crate::units;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// sqrt(2 ln 2 / pi) = 0.6643: the flat-region Allan deviation per unit bias instability.
pub const BIAS_INSTABILITY_FACTOR: f64 = 0.664_282_410_551_185_4;

/// Largest |local slope - target| accepted as "that slope is present" in the slope-line method.
pub const SLOPE_TOLERANCE: f64 = 0.15;

/// Why noise terms could not be extracted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NoiseError {
    /// The curve is not an Allan-type deviation (ADEV, OADEV or TOTDEV).
    #[error("noise terms need an Allan-type deviation curve, got {0}")]
    WrongKind(&'static str),
    /// Fewer usable points (positive deviation, inside the tau range) than needed.
    #[error("{found} usable points, at least {needed} needed")]
    TooFewPoints {
        /// Points needed.
        needed: usize,
        /// Points found.
        found: usize,
    },
}

/// The five IEEE 952 noise coefficients in engineering and SI-like units; `None` where absent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NoiseCoefficients {
    /// Quantization noise Q in deg.
    pub quantization_deg: Option<f64>,
    /// Angle random walk N in deg/sqrt(s) (equal to the noise density in deg/s/sqrt(Hz)).
    pub arw_deg_rt_s: Option<f64>,
    /// Angle random walk N in deg/sqrt(h).
    pub arw_deg_rt_h: Option<f64>,
    /// Bias instability B in deg/s.
    pub bias_instability_dps: Option<f64>,
    /// Bias instability B in deg/h.
    pub bias_instability_dph: Option<f64>,
    /// Rate random walk K in deg/s/sqrt(s).
    pub rrw_deg_s_rt_s: Option<f64>,
    /// Rate random walk K in deg/h/sqrt(h).
    pub rrw_deg_h_rt_h: Option<f64>,
    /// Rate ramp R in deg/s per s.
    pub rate_ramp_dps_per_s: Option<f64>,
    /// Rate ramp R in deg/h per h.
    pub rate_ramp_dph_per_h: Option<f64>,
}

impl NoiseCoefficients {
    /// Builds the coefficients from Q (deg), N (deg/sqrt(s)), B (deg/s), K (deg/s/sqrt(s)), R (deg/s^2).
    pub fn from_base_units(q: Option<f64>, n: Option<f64>, b: Option<f64>, k: Option<f64>, r: Option<f64>) -> Self {
        NoiseCoefficients {
            quantization_deg: q,
            arw_deg_rt_s: n,
            arw_deg_rt_h: n.map(units::arw_deg_rt_s_to_deg_rt_h),
            bias_instability_dps: b,
            bias_instability_dph: b.map(units::bias_dps_to_dph),
            rrw_deg_s_rt_s: k,
            rrw_deg_h_rt_h: k.map(units::rrw_dps_rt_s_to_dph_rt_h),
            rate_ramp_dps_per_s: r,
            rate_ramp_dph_per_h: r.map(units::rate_ramp_dps_per_s_to_dph_per_h),
        }
    }

    /// Allan deviation (deg/s) the model predicts at tau (absent terms count as zero).
    pub fn model_deviation(&self, tau_s: f64) -> f64 {
        let q = self.quantization_deg.unwrap_or(0.0);
        let n = self.arw_deg_rt_s.unwrap_or(0.0);
        let b = self.bias_instability_dps.unwrap_or(0.0);
        let k = self.rrw_deg_s_rt_s.unwrap_or(0.0);
        let r = self.rate_ramp_dps_per_s.unwrap_or(0.0);
        let basis = model_basis(tau_s);
        (basis[0] * q * q + basis[1] * n * n + basis[2] * b * b + basis[3] * k * k + basis[4] * r * r).sqrt()
    }
}

/// Where a slope-line coefficient was read.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeReading {
    /// Averaging time of the reading (geometric mid-point of the segment, or the minimum), s.
    pub tau_s: f64,
    /// Taus of the segment's two points (for B: the minimum's neighbours), s.
    pub tau_range_s: (f64, f64),
    /// Local log-log slope found there.
    pub local_slope: f64,
}

/// Result of the slope-line method.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeLineResult {
    /// The coefficients found.
    pub coefficients: NoiseCoefficients,
    /// Where Q was read (slope -1).
    pub quantization: Option<SlopeReading>,
    /// Where N was read (slope -1/2, line read at tau = 1 s).
    pub arw: Option<SlopeReading>,
    /// Where B was read (the median level of the flat region, else an interior minimum).
    pub bias_instability: Option<SlopeReading>,
    /// Where K was read (slope +1/2, line read at tau = 3 s).
    pub rrw: Option<SlopeReading>,
    /// Where R was read (slope +1).
    pub rate_ramp: Option<SlopeReading>,
}

/// Result of the weighted least-squares fit of the five-term model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFitResult {
    /// The coefficients (`None` for a term the non-negative fit set to zero).
    pub coefficients: NoiseCoefficients,
    /// Smallest and largest tau of the points fitted, s.
    pub tau_range_s: (f64, f64),
    /// Number of points fitted.
    pub points_used: usize,
    /// Root mean square of the weighted residuals (about 1 when the weights are right).
    pub weighted_rms_residual: f64,
}

/// Kalibr `imu.yaml` gyroscope entries.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KalibrGyroscope {
    /// N in rad/s/sqrt(Hz).
    pub gyroscope_noise_density: Option<f64>,
    /// K in rad/s^2/sqrt(Hz).
    pub gyroscope_random_walk: Option<f64>,
}

/// Kalibr's gyroscope entries from noise coefficients.
pub fn kalibr_gyroscope(c: &NoiseCoefficients) -> KalibrGyroscope {
    KalibrGyroscope {
        gyroscope_noise_density: c.arw_deg_rt_s.map(units::arw_deg_rt_s_to_rad_s_rt_hz),
        gyroscope_random_walk: c.rrw_deg_s_rt_s.map(units::rrw_dps_rt_s_to_rad_s2_rt_hz),
    }
}

/// Allan variance of each model term per unit coefficient squared: [3/tau^2, 1/tau, 2ln2/pi, tau/3, tau^2/2].
fn model_basis(tau: f64) -> [f64; 5] {
    [3.0 / (tau * tau), 1.0 / tau, BIAS_INSTABILITY_FACTOR * BIAS_INSTABILITY_FACTOR, tau / 3.0, tau * tau / 2.0]
}

fn usable_points(curve: &AllanCurve) -> Result<Vec<AllanPoint>, NoiseError> {
    if !matches!(curve.kind, DeviationKind::Oadev | DeviationKind::Adev | DeviationKind::Totdev) {
        return Err(NoiseError::WrongKind(curve.kind.name()));
    }
    let mut pts: Vec<AllanPoint> = curve
        .points
        .iter()
        .copied()
        .filter(|p| p.deviation > 0.0 && p.deviation.is_finite() && p.tau_s > 0.0)
        .collect();
    pts.sort_by(|a, b| a.tau_s.total_cmp(&b.tau_s));
    Ok(pts)
}

/// Slope-line method on an Allan deviation curve of a rate in deg/s.
pub fn slope_line_terms(curve: &AllanCurve) -> Result<SlopeLineResult, NoiseError> {
    let pts = usable_points(curve)?;
    if pts.len() < 2 {
        return Err(NoiseError::TooFewPoints { needed: 2, found: pts.len() });
    }
    let i_min = pts.iter().enumerate().min_by(|a, b| a.1.deviation.total_cmp(&b.1.deviation)).map_or(0, |(i, _)| i);
    // segment i joins points i and i+1
    let segments: Vec<(usize, f64, f64, f64)> = pts
        .windows(2)
        .enumerate()
        .map(|(i, w)| {
            let slope = (w[1].deviation / w[0].deviation).ln() / (w[1].tau_s / w[0].tau_s).ln();
            let tau_mid = (w[0].tau_s * w[1].tau_s).sqrt();
            let dev_mid = (w[0].deviation * w[1].deviation).sqrt();
            (i, slope, tau_mid, dev_mid)
        })
        .collect();
    // A term on the rising side (K, R) sits where the curve has the fewest terms and the widest
    // bounds; one segment there is weak evidence, so it must have a neighbouring segment whose
    // slope is also near the target (within twice the tolerance).
    let supported = |i: usize, target: f64, left: bool| {
        left || [i.wrapping_sub(1), i + 1]
            .iter()
            .filter_map(|&j| segments.get(j))
            .any(|n| n.0 >= i_min && (n.1 - target).abs() <= 2.0 * SLOPE_TOLERANCE)
    };
    let find = |target: f64, left: bool| {
        segments
            .iter()
            .filter(|s| if left { s.0 < i_min } else { s.0 >= i_min })
            .filter(|s| (s.1 - target).abs() <= SLOPE_TOLERANCE && supported(s.0, target, left))
            .min_by(|a, b| (a.1 - target).abs().total_cmp(&(b.1 - target).abs()))
            .map(|&(i, slope, tau, dev)| {
                (dev, SlopeReading { tau_s: tau, tau_range_s: (pts[i].tau_s, pts[i + 1].tau_s), local_slope: slope })
            })
    };
    let quantization = find(-1.0, true);
    let arw = find(-0.5, true);
    let rrw = find(0.5, false);
    let rate_ramp = find(1.0, false);
    let q = quantization.map(|(dev, r)| dev * r.tau_s / 3f64.sqrt());
    let n = arw.map(|(dev, r)| dev * r.tau_s.sqrt()); // line sigma = N / sqrt(tau), read at 1 s
    let k = rrw.map(|(dev, r)| dev * (3.0 / r.tau_s).sqrt()); // line sigma = K sqrt(tau/3), read at 3 s
    let r = rate_ramp.map(|(dev, r)| dev * 2f64.sqrt() / r.tau_s);
    // B: the median level of the flat region (segments with slope near 0; the median, not the
    // lowest, because single long-tau points of one record scatter widely), else an interior
    // minimum of the curve. A minimum at either end of the curve is not a flat region.
    let mut flats: Vec<&(usize, f64, f64, f64)> = segments.iter().filter(|s| s.1.abs() <= SLOPE_TOLERANCE).collect();
    flats.sort_by(|a, b| a.3.total_cmp(&b.3));
    let flat = (!flats.is_empty()).then(|| {
        let median = if flats.len() % 2 == 1 {
            flats[flats.len() / 2].3
        } else {
            (flats[flats.len() / 2 - 1].3 * flats[flats.len() / 2].3).sqrt()
        };
        let near = flats.iter().min_by(|a, b| (a.3 / median).ln().abs().total_cmp(&(b.3 / median).ln().abs()));
        let lo = flats.iter().map(|s| pts[s.0].tau_s).fold(f64::INFINITY, f64::min);
        let hi = flats.iter().map(|s| pts[s.0 + 1].tau_s).fold(0.0, f64::max);
        let (tau, slope) = near.map_or((lo, 0.0), |s| (s.2, s.1));
        (median, SlopeReading { tau_s: tau, tau_range_s: (lo, hi), local_slope: slope })
    });
    let interior_min = (i_min > 0 && i_min + 1 < pts.len()).then(|| {
        (
            pts[i_min].deviation,
            SlopeReading {
                tau_s: pts[i_min].tau_s,
                tau_range_s: (pts[i_min - 1].tau_s, pts[i_min + 1].tau_s),
                local_slope: 0.5 * (segments[i_min - 1].1 + segments[i_min].1),
            },
        )
    });
    let floor = flat.or(interior_min);
    let bias_instability = floor.map(|f| f.1);
    let b = floor.map(|f| f.0 / BIAS_INSTABILITY_FACTOR);
    Ok(SlopeLineResult {
        coefficients: NoiseCoefficients::from_base_units(q, n, b, k, r),
        quantization: quantization.map(|x| x.1),
        arw: arw.map(|x| x.1),
        bias_instability,
        rrw: rrw.map(|x| x.1),
        rate_ramp: rate_ramp.map(|x| x.1),
    })
}

/// Standard uncertainty of a point's variance: half the width of its confidence interval on
/// sigma^2, else sigma^2 sqrt(2/edf), else sigma^2 itself (equal relative weights).
fn variance_uncertainty(p: &AllanPoint) -> f64 {
    let var = p.deviation * p.deviation;
    match (p.lower, p.upper, p.edf) {
        (Some(lo), Some(hi), _) if hi > lo => 0.5 * (hi * hi - lo * lo),
        (_, _, Some(edf)) if edf > 0.0 => var * (2.0 / edf).sqrt(),
        _ => var,
    }
}

/// Weighted least-squares fit of the five-term IEEE 952 model to sigma^2 over an optional tau
/// range (inclusive, s), with non-negative coefficients.
pub fn fit_noise_model(curve: &AllanCurve, tau_range_s: Option<(f64, f64)>) -> Result<ModelFitResult, NoiseError> {
    let pts: Vec<AllanPoint> = usable_points(curve)?
        .into_iter()
        .filter(|p| tau_range_s.is_none_or(|(lo, hi)| p.tau_s >= lo && p.tau_s <= hi))
        .collect();
    if pts.len() < 2 {
        return Err(NoiseError::TooFewPoints { needed: 2, found: pts.len() });
    }
    let rows = pts.len();
    let mut a = DMatrix::<f64>::zeros(rows, 5);
    let mut b = DVector::<f64>::zeros(rows);
    for (i, p) in pts.iter().enumerate() {
        let u = variance_uncertainty(p);
        let basis = model_basis(p.tau_s);
        for j in 0..5 {
            a[(i, j)] = basis[j] / u;
        }
        b[i] = p.deviation * p.deviation / u;
    }
    // scale columns to unit norm for conditioning (taus span decades)
    let scales: Vec<f64> = (0..5).map(|j| a.column(j).norm()).collect();
    for (j, &s) in scales.iter().enumerate() {
        if s > 0.0 {
            a.column_mut(j).scale_mut(1.0 / s);
        }
    }
    let x = nnls(&a, &b);
    let residual = &b - &a * &x;
    let coef: Vec<Option<f64>> =
        (0..5).map(|j| if x[j] > 0.0 && scales[j] > 0.0 { Some((x[j] / scales[j]).sqrt()) } else { None }).collect();
    Ok(ModelFitResult {
        coefficients: NoiseCoefficients::from_base_units(coef[0], coef[1], coef[2], coef[3], coef[4]),
        tau_range_s: (pts[0].tau_s, pts[rows - 1].tau_s),
        points_used: rows,
        weighted_rms_residual: (residual.norm_squared() / rows as f64).sqrt(),
    })
}

/// Least squares restricted to the columns in `passive` (SVD solve); zeros elsewhere.
fn solve_on(a: &DMatrix<f64>, b: &DVector<f64>, passive: &[bool]) -> DVector<f64> {
    let cols: Vec<usize> = (0..a.ncols()).filter(|&j| passive[j]).collect();
    let mut z = DVector::zeros(a.ncols());
    if cols.is_empty() {
        return z;
    }
    let sub = a.select_columns(cols.iter());
    let svd = sub.svd(true, true);
    if let Ok(sol) = svd.solve(b, 1e-12) {
        for (k, &j) in cols.iter().enumerate() {
            z[j] = sol[k];
        }
    }
    z
}

/// Non-negative least squares min |A x - b|, x >= 0 (Lawson & Hanson's active-set algorithm).
fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let tol = 1e-12 * a.norm() * b.norm().max(1e-300);
    for _ in 0..(3 * n + 10) {
        let w = a.transpose() * (b - a * &x);
        let candidate = (0..n).filter(|&j| !passive[j] && w[j] > tol).max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = candidate else { break };
        passive[j] = true;
        for _ in 0..(3 * n + 10) {
            let z = solve_on(a, b, &passive);
            if (0..n).all(|k| !passive[k] || z[k] > 0.0) {
                x = z;
                break;
            }
            let mut step = 1.0f64;
            for k in 0..n {
                if passive[k] && z[k] <= 0.0 {
                    let denom = x[k] - z[k];
                    if denom > 0.0 {
                        step = step.min(x[k] / denom);
                    }
                }
            }
            x = &x + (z - &x) * step;
            for k in 0..n {
                if passive[k] && x[k] <= tol.max(0.0) {
                    passive[k] = false;
                    x[k] = 0.0;
                }
            }
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{deviation_from_rate, AllanOptions};
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// White rate noise of density N plus a rate random walk of strength K, tau0 = 0.1 s.
    fn simulated_record(n_arw: f64, k_rrw: f64, samples: usize, seed: u64) -> Vec<f64> {
        let tau0: f64 = 0.1;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut walk = 0.0;
        let mut v = Vec::with_capacity(samples + 1);
        for _ in 0..samples {
            let w: f64 = StandardNormal.sample(&mut rng);
            let r: f64 = StandardNormal.sample(&mut rng);
            walk += k_rrw * tau0.sqrt() * r;
            v.push(1.0 + n_arw / tau0.sqrt() * w + walk);
        }
        v
    }

    #[test]
    fn recovers_arw_and_rrw_of_a_simulated_record() {
        // N = 1e-3 deg/sqrt(s) (0.06 deg/sqrt(h)), K = 5e-5 deg/s/sqrt(s) (10.8 deg/h/sqrt(h)),
        // 1e6 samples at 10 Hz (27.8 h): the two lines cross at tau = sqrt(3) N/K = 35 s.
        let (n_true, k_true) = (1e-3, 5e-5);
        let curve =
            deviation_from_rate(simulated_record(n_true, k_true, 1_000_000, 3), 0.1, &AllanOptions::default()).unwrap();
        let slope = slope_line_terms(&curve).unwrap();
        let c = slope.coefficients;
        let n = c.arw_deg_rt_s.unwrap();
        let k = c.rrw_deg_s_rt_s.unwrap();
        assert!((n / n_true - 1.0).abs() < 0.05, "slope-line N {n} vs {n_true}");
        assert!((k / k_true - 1.0).abs() < 0.25, "slope-line K {k} vs {k_true}");
        assert!(slope.arw.unwrap().tau_s < 35.0 && slope.rrw.unwrap().tau_s > 35.0);
        assert!(slope.quantization.is_none() && slope.rate_ramp.is_none());
        assert!((c.arw_deg_rt_h.unwrap() - 60.0 * n).abs() < 1e-12);
        let fit = fit_noise_model(&curve, None).unwrap();
        let f = fit.coefficients;
        let n = f.arw_deg_rt_s.unwrap();
        let k = f.rrw_deg_s_rt_s.unwrap();
        assert!((n / n_true - 1.0).abs() < 0.05, "fit N {n} vs {n_true}");
        assert!((k / k_true - 1.0).abs() < 0.25, "fit K {k} vs {k_true}");
        assert!(f.quantization_deg.is_none_or(|q| q < 0.1 * n_true * 0.1f64.sqrt()));
        let kal = kalibr_gyroscope(&f);
        assert!((kal.gyroscope_noise_density.unwrap() - n.to_radians()).abs() < 1e-15);
        assert!((kal.gyroscope_random_walk.unwrap() - k.to_radians()).abs() < 1e-15);
    }

    #[test]
    fn slope_lines_on_an_exact_model_curve() {
        // Curve sampled from the model itself: each coefficient must come back (to the bias of
        // reading a line where neighbouring terms still contribute).
        let truth = NoiseCoefficients::from_base_units(None, Some(2e-3), Some(1e-4), Some(1e-6), None);
        let points = (0..30)
            .map(|i| {
                let tau = 0.01 * 2f64.powi(i);
                AllanPoint {
                    m: 1 << i,
                    tau_s: tau,
                    deviation: truth.model_deviation(tau),
                    terms: 100,
                    alpha: None,
                    noise_id: None,
                    edf: None,
                    lower: None,
                    upper: None,
                }
            })
            .collect();
        let curve = AllanCurve { kind: DeviationKind::Oadev, tau0_s: 0.01, n_rate: 1 << 32, confidence: None, points };
        let s = slope_line_terms(&curve).unwrap().coefficients;
        let n = s.arw_deg_rt_s.unwrap();
        assert!((n / 2e-3 - 1.0).abs() < 0.05, "N {n}");
        // B from the minimum overestimates when the N and K lines still contribute there
        let b = s.bias_instability_dps.unwrap();
        assert!((b / 1e-4 - 1.0).abs() < 0.3, "B {b}");
        let fit = fit_noise_model(&curve, None).unwrap().coefficients;
        assert!((fit.arw_deg_rt_s.unwrap() / 2e-3 - 1.0).abs() < 1e-6);
        assert!((fit.bias_instability_dps.unwrap() / 1e-4 - 1.0).abs() < 1e-6);
        assert!((fit.rrw_deg_s_rt_s.unwrap() / 1e-6 - 1.0).abs() < 1e-6);
        assert!((fit.bias_instability_dph.unwrap() - 0.36).abs() < 1e-6);
    }

    #[test]
    fn rejects_curves_that_are_not_allan_type() {
        let curve = AllanCurve { kind: DeviationKind::Tdev, tau0_s: 1.0, n_rate: 10, confidence: None, points: vec![] };
        assert_eq!(slope_line_terms(&curve), Err(NoiseError::WrongKind("tdev")));
        let curve = AllanCurve { kind: DeviationKind::Oadev, ..curve };
        assert!(matches!(fit_noise_model(&curve, None), Err(NoiseError::TooFewPoints { .. })));
    }

    fn curve_from(taus: &[f64], devs: &[f64]) -> AllanCurve {
        let points = taus
            .iter()
            .zip(devs)
            .map(|(&tau_s, &deviation)| AllanPoint {
                m: tau_s as usize,
                tau_s,
                deviation,
                terms: 100,
                alpha: None,
                noise_id: None,
                edf: None,
                lower: None,
                upper: None,
            })
            .collect();
        AllanCurve { kind: DeviationKind::Oadev, tau0_s: 1.0, n_rate: 1 << 20, confidence: None, points }
    }

    #[test]
    fn a_single_rising_segment_at_the_end_is_not_rate_random_walk() {
        // A flat (flicker) curve whose last octave rises with slope +1/2 by chance.
        let mut taus = Vec::new();
        let mut devs = Vec::new();
        for k in 0..12 {
            let tau = 2f64.powi(k);
            taus.push(tau);
            devs.push(if k < 11 { 1e-3 } else { 1e-3 * 2f64.sqrt() });
        }
        let curve = curve_from(&taus, &devs);
        let r = slope_line_terms(&curve).unwrap();
        assert!(r.rrw.is_none(), "{:?}", r.rrw);
        // Two rising octaves are accepted.
        devs[10] = 1e-3 * 2f64.sqrt();
        devs[11] = 2e-3;
        devs[9] = 1e-3;
        let r = slope_line_terms(&curve_from(&taus, &devs)).unwrap();
        assert!(r.rrw.is_some());
    }
}
