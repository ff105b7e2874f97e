//! Generalized Method of Wavelet Moments (GMWM) on the Haar wavelet variance, and the
//! overbounding of filter noise parameters (docs/METHODS.md, "GMWM" and "Overbound").
//!
//! Sources: S. Guerrier, J. Skaloud, Y. Stebler, M.-P. Victoria-Feser, "Wavelet-variance-based
//! estimation for composite stochastic processes", JASA 108(503), 2013 (the estimator
//! theta = argmin (nu_hat - nu(theta))' Omega (nu_hat - nu(theta))); D. B. Percival and A. T.
//! Walden, *Wavelet Methods for Time Series Analysis*, 2000, section 8.4 (the Haar wavelet
//! variance nu^2(tau) = AVAR(tau) / 2 and the chi-squared approximation of its estimate);
//! IEEE Std 952-1997 annex C (the Allan variance of each process, which fixes its wavelet
//! variance through nu^2 = AVAR / 2).
//!
//! Scope of this implementation (stated in METHODS): the processes whose wavelet variance is
//! linear in a parameter (white noise N, quantization Q, the flicker floor of bias instability B,
//! random walk K, drift R) and up to two first-order Gauss-Markov processes (sigma, correlation
//! time T; module `gauss_markov`). For a fixed weight matrix and fixed correlation times the GMWM
//! objective is a non-negative weighted least-squares problem solved exactly (every subset of
//! processes, the best feasible one); the correlation times are profiled out (a grid of one per
//! octave over the scales, then golden-section refinement of each ln T). Omega is the inverse of
//! the diagonal of the estimates' covariance under the fitted model (module `covariance`: the
//! large-sample spectral variance of Percival and Walden 2000, ch. 8, plus a drift's cross term),
//! re-evaluated at the fitted model a few times, starting from the chi-squared approximation 2
//! nu_hat^4_j / edf_j at the estimates; the intervals use the full covariance across scales in a
//! sandwich with the model's Jacobian; the model is chosen by a wavelet information criterion, the
//! objective plus its estimated optimism (module `select`), and the linear processes' intervals
//! are averaged over the candidate models by their criterion weights, the candidates that a
//! simpler nested candidate matches or beats on the criterion dropped (module `average`).

mod average;
mod covariance;
mod gauss_markov;
mod overbound;
mod select;

pub use average::model_weights;
pub use covariance::{wavelet_variance_covariance, CovarianceGrid, ShapeIntegrals};
pub use gauss_markov::{
    gauss_markov_filter_bound, gauss_markov_spectral_density, gauss_markov_wavelet_variance, MarkovBound,
};
pub use overbound::{overbound_factors, OverboundFactors};
pub use select::{gmwm, select_model, select_model_with_gauss_markov, MAX_GAUSS_MARKOV};

use crate::allan::chi_squared_quantile;
use crate::allan::{AllanCurve, DeviationKind};
use serde::Serialize;

/// sqrt(2 ln 2 / pi): the Allan deviation of the flicker floor per unit bias instability B.
const FLICKER: f64 = crate::noise::BIAS_INSTABILITY_FACTOR;

/// A process of the composite model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Process {
    /// Quantization noise Q (angle; AVAR = 3 Q^2 / tau^2).
    Quantization,
    /// White rate noise N (angle random walk; AVAR = N^2 / tau).
    White,
    /// Flicker floor of bias instability B (AVAR = (2 ln 2 / pi) B^2, its plateau).
    Flicker,
    /// Rate random walk K (AVAR = K^2 tau / 3).
    RandomWalk,
    /// Drift (rate ramp) R (AVAR = R^2 tau^2 / 2).
    Drift,
    /// First-order Gauss-Markov process: stationary standard deviation sigma and correlation time
    /// T (autocovariance sigma^2 exp(-|t| / T)), sampled every tau0 (module `gauss_markov`).
    GaussMarkov,
}

/// The five processes whose wavelet variance is linear in their squared coefficient, in the
/// order of the parameter vector (the Gauss-Markov processes come after them).
pub const PROCESSES: [Process; 5] =
    [Process::Quantization, Process::White, Process::Flicker, Process::RandomWalk, Process::Drift];

impl Process {
    /// `quantization`, `white`, `flicker`, `random_walk`, `drift`, `gauss_markov`.
    pub fn name(self) -> &'static str {
        match self {
            Process::Quantization => "quantization",
            Process::White => "white",
            Process::Flicker => "flicker",
            Process::RandomWalk => "random_walk",
            Process::Drift => "drift",
            Process::GaussMarkov => "gauss_markov",
        }
    }

    /// The Haar wavelet variance at `tau_s` per unit squared coefficient (nu^2 = AVAR / 2); NaN for
    /// [`Process::GaussMarkov`], whose shape depends on its correlation time ([`Shape::unit`]).
    pub fn unit_wavelet_variance(self, tau_s: f64) -> f64 {
        0.5 * match self {
            Process::Quantization => 3.0 / (tau_s * tau_s),
            Process::White => 1.0 / tau_s,
            Process::Flicker => FLICKER * FLICKER,
            Process::RandomWalk => tau_s / 3.0,
            Process::Drift => tau_s * tau_s / 2.0,
            Process::GaussMarkov => f64::NAN,
        }
    }
}

/// A term of a model with everything fixed but its weight: one of the five linear processes, or
/// a first-order Gauss-Markov process of a given correlation time (weight: its variance sigma^2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A process whose wavelet variance is linear in its squared coefficient (not
    /// [`Process::GaussMarkov`]).
    Linear(Process),
    /// A first-order Gauss-Markov process of correlation time T, s.
    GaussMarkov(f64),
}

impl Shape {
    /// The process of the term.
    pub fn process(self) -> Process {
        match self {
            Shape::Linear(p) => p,
            Shape::GaussMarkov(_) => Process::GaussMarkov,
        }
    }

    /// The Haar wavelet variance at the scale of `w` per unit weight.
    pub fn unit(self, w: &WaveletVariance) -> f64 {
        match self {
            Shape::Linear(p) => p.unit_wavelet_variance(w.tau_s),
            Shape::GaussMarkov(t) => gauss_markov_wavelet_variance(t, w.tau_s / w.m as f64, w.m as f64),
        }
    }
}

/// One Haar wavelet variance estimate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WaveletVariance {
    /// Scale tau_j = 2^j tau0, s.
    pub tau_s: f64,
    /// The estimate nu_hat^2 = OAVAR(tau) / 2, (curve unit)^2.
    pub nu2: f64,
    /// Equivalent degrees of freedom of the estimate (the curve's).
    pub edf: f64,
    /// Averaging factor m (tau_s = m tau0).
    pub m: u64,
    /// Terms (wavelet coefficients) averaged in the estimate.
    pub terms: u64,
}

/// Why a GMWM fit could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GmwmError {
    /// The curve is not an octave overlapping Allan deviation with confidence intervals.
    #[error("GMWM needs the octave overlapping Allan deviation with its degrees of freedom (kind oadev, taus octave, a confidence level): {0}")]
    Curve(String),
    /// Too few scales for the model.
    #[error("GMWM: {scales} scale(s) for {parameters} parameter(s): a longer record is needed")]
    TooFewScales {
        /// Scales available.
        scales: usize,
        /// Parameters of the model.
        parameters: usize,
    },
    /// The confidence level is not in (0, 1).
    #[error("GMWM: confidence {0} is not in (0, 1)")]
    Confidence(f64),
}

/// The Haar wavelet variance at dyadic scales from an octave overlapping Allan curve:
/// nu^2_j = OAVAR(tau_j) / 2 (Percival and Walden 2000, eq. 8.4 with the Haar filter), each
/// with the curve's equivalent degrees of freedom.
pub fn wavelet_variance(curve: &AllanCurve) -> Result<Vec<WaveletVariance>, GmwmError> {
    if !matches!(curve.kind, DeviationKind::Oadev | DeviationKind::Adev) {
        return Err(GmwmError::Curve(format!("the curve is {}", curve.kind.name())));
    }
    let mut out = Vec::with_capacity(curve.points.len());
    for p in &curve.points {
        if !p.m.is_power_of_two() {
            return Err(GmwmError::Curve(format!("averaging factor {} is not a power of two", p.m)));
        }
        let Some(edf) = p.edf.filter(|e| e.is_finite() && *e > 0.0) else {
            return Err(GmwmError::Curve(format!("no degrees of freedom at tau {} s", p.tau_s)));
        };
        if p.deviation.is_finite() && p.deviation > 0.0 {
            out.push(WaveletVariance {
                tau_s: p.tau_s,
                nu2: 0.5 * p.deviation * p.deviation,
                edf,
                m: p.m as u64,
                terms: p.terms as u64,
            });
        }
    }
    Ok(out)
}

/// The correlation time of a Gauss-Markov parameter with its interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CorrelationTime {
    /// The estimate T, s.
    pub value_s: f64,
    /// Lower end of the two-sided interval, s (exp of the interval on ln T).
    pub lower_s: f64,
    /// Upper end of the two-sided interval, s.
    pub upper_s: f64,
    /// True when T sits at an end of the range searched (the first and last scales): the record
    /// does not resolve it, and the interval is not meaningful.
    pub at_search_edge: bool,
}

/// One estimated parameter of a GMWM fit, in the curve's coefficient units (for a gyro in deg/s:
/// Q deg, N deg/sqrt(s), B deg/s, K deg/s/sqrt(s), R deg/s^2, a Gauss-Markov sigma deg/s).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GmwmParameter {
    /// The process.
    pub process: Process,
    /// The coefficient (square root of the fitted wavelet-variance weight; for a Gauss-Markov
    /// process its stationary standard deviation sigma).
    pub value: f64,
    /// Lower end of the two-sided interval at `confidence` (0 when the interval reaches zero).
    pub lower: f64,
    /// Upper end of the two-sided interval.
    pub upper: f64,
    /// The correlation time of a Gauss-Markov process (None for the other processes).
    pub correlation_time: Option<CorrelationTime>,
    /// The summed weight of the candidate models holding this process (for a Gauss-Markov
    /// process: holding one), exp(-criterion / 2) normalised over the candidates the nesting rule
    /// leaves (module `average`); 1 for the fit of a single model ([`fit_processes`]).
    pub model_weight: f64,
}

/// A linear process the chosen model leaves out, bounded given that it is there (the mixture of
/// the candidate models holding it, their weights renormalised): its coefficient lies below
/// `upper` at the one-sided level 1 - (1 - confidence) / 2 (84.15 % for 68.3 %), the same as the
/// upper end of the two-sided intervals.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GmwmBound {
    /// The process.
    pub process: Process,
    /// The upper bound of its coefficient, in the units of [`GmwmParameter::value`].
    pub upper: f64,
    /// The summed weight of the candidate models holding it, with the plain weights (every
    /// candidate, the nesting rule not applied: those the bound was made with), so it is not
    /// on the same footing as [`GmwmParameter::model_weight`].
    pub model_weight: f64,
}

/// A GMWM fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GmwmFit {
    /// The processes of the chosen model with their coefficients and intervals (the linear
    /// processes first, then the Gauss-Markov processes by increasing correlation time).
    pub parameters: Vec<GmwmParameter>,
    /// Two-sided confidence level of the intervals.
    pub confidence: f64,
    /// Scales used.
    pub scales: usize,
    /// The objective at the estimate, (nu_hat - nu)' Omega (nu_hat - nu).
    pub objective: f64,
    /// The estimated optimism of the objective, 2 tr(Omega H Sigma) (H the fit's hat matrix,
    /// Sigma the wavelet variances' covariance under the fitted model); 2 x parameters when Omega
    /// = Sigma^-1. Infinite (the model not eligible) when the covariance cannot be made.
    pub optimism: f64,
    /// The model-choice criterion (wavelet information criterion): objective + optimism (smaller
    /// is better).
    pub criterion: f64,
    /// The weighted RMS residual sqrt(objective / scales) (about 1 when the model and the
    /// weights are right).
    pub weighted_rms_residual: f64,
    /// Poor when the weighted RMS residual exceeds [`crate::noise::FIT_RMS_LIMIT`] (the limit of
    /// the five-term fit): no model of the processes searched describes the curve, and its values
    /// are not to be used.
    pub quality: crate::noise::FitQuality,
    /// The linear processes the chosen model leaves out that some candidate model of non-zero
    /// weight holds, each with its upper bound given that it is there when that bound is above
    /// zero (module `average`); empty when one candidate holds all the weight.
    pub left_out: Vec<GmwmBound>,
}

impl GmwmFit {
    /// The coefficient of a process, when the model holds it (the first Gauss-Markov process for
    /// [`Process::GaussMarkov`]).
    pub fn value(&self, process: Process) -> Option<f64> {
        self.parameter(process).map(|p| p.value)
    }

    /// The parameter of a process, when the model holds it (the first Gauss-Markov process for
    /// [`Process::GaussMarkov`]).
    pub fn parameter(&self, process: Process) -> Option<GmwmParameter> {
        self.parameters.iter().find(|p| p.process == process).copied()
    }

    /// The Gauss-Markov parameters, by increasing correlation time.
    pub fn gauss_markov(&self) -> Vec<GmwmParameter> {
        self.parameters.iter().filter(|p| p.process == Process::GaussMarkov).copied().collect()
    }

    /// The terms of the model with their weights (squared coefficients, or sigma^2).
    pub fn shapes(&self) -> Vec<(Shape, f64)> {
        self.parameters
            .iter()
            .map(|p| {
                let shape = match p.correlation_time {
                    Some(t) => Shape::GaussMarkov(t.value_s),
                    None => Shape::Linear(p.process),
                };
                (shape, p.value * p.value)
            })
            .collect()
    }

    /// The model's wavelet variance at the scale of `w` (its tau and averaging factor).
    pub fn wavelet_variance(&self, w: &WaveletVariance) -> f64 {
        self.shapes().iter().map(|(s, t)| t * s.unit(w)).sum()
    }
}

/// A fitted model: each term with its weight (squared coefficient, or a Gauss-Markov sigma^2).
type Model = Vec<(Shape, f64)>;

/// Reweighting rounds: Omega from the estimates (chi-squared), then from the fitted model's variances.
const ROUNDS: usize = 4;

/// GMWM fit of a given set of linear processes (at least one; not [`Process::GaussMarkov`]) to
/// the wavelet variance: non-negative weighted least squares in the squared coefficients with
/// Omega = diag(1 / var(nu_hat^2_j)), the variances under the fitted model
/// ([`CovarianceGrid::variances`]; in the first round the chi-squared 2 nu_hat_j^4 / edf_j at the
/// estimates). Processes whose weight is zero at the optimum are left out of the result.
/// Intervals: theta +- z sqrt(var), var from the sandwich covariance with the wavelet variances'
/// covariance across scales under the fitted model ([`wavelet_variance_covariance`] and a drift's
/// cross term), clipped at zero, then square-rooted; two-sided at `confidence`.
pub fn fit_processes(wv: &[WaveletVariance], processes: &[Process], confidence: f64) -> Result<GmwmFit, GmwmError> {
    let shapes: Vec<Shape> =
        processes.iter().filter(|p| **p != Process::GaussMarkov).map(|&p| Shape::Linear(p)).collect();
    let grid = CovarianceGrid::new(wv);
    let (model, sigma2) = fit_estimate(wv, &grid, &shapes, confidence)?;
    let integrals = ShapeIntegrals::new(&grid, &shapes);
    Ok(finish(wv, &integrals, &model, &sigma2, confidence, (0.0, f64::INFINITY)).0)
}

fn check(wv: &[WaveletVariance], parameters: usize, confidence: f64) -> Result<(), GmwmError> {
    if confidence.is_nan() || confidence <= 0.0 || confidence >= 1.0 {
        return Err(GmwmError::Confidence(confidence));
    }
    if wv.len() <= parameters || parameters == 0 {
        return Err(GmwmError::TooFewScales { scales: wv.len(), parameters });
    }
    Ok(())
}

/// The variances of Omega: the chi-squared variances 2 nu_hat^4 / edf at the estimates for the
/// first round (no model yet), then the variances of the estimates under the fitted model
/// ([`CovarianceGrid::variances`]; the chi-squared value where that is not positive).
fn omega_variances(wv: &[WaveletVariance], grid: &CovarianceGrid, model: &[(Shape, f64)]) -> Vec<f64> {
    let chi2 = |w: &WaveletVariance| 2.0 * w.nu2 * w.nu2 / w.edf;
    if model.is_empty() {
        return wv.iter().map(chi2).collect();
    }
    grid.variances(wv, model)
        .into_iter()
        .zip(wv)
        .map(|(v, w)| if v.is_finite() && v > 0.0 { v } else { chi2(w) })
        .collect()
}

/// The weights of fixed shapes by reweighted non-negative least squares (zero weights dropped),
/// with the final Omega's variances.
fn fit_estimate(
    wv: &[WaveletVariance],
    grid: &CovarianceGrid,
    shapes: &[Shape],
    confidence: f64,
) -> Result<(Model, Vec<f64>), GmwmError> {
    check(wv, shapes.len(), confidence)?;
    let x = design(wv, shapes);
    let nu: Vec<f64> = wv.iter().map(|w| w.nu2).collect();
    let mut sigma2 = omega_variances(wv, grid, &[]);
    let mut best = Vec::new();
    for round in 0..ROUNDS {
        if round > 0 {
            sigma2 = omega_variances(wv, grid, &best);
        }
        let (kept, theta, _) = nnls(&x, &nu, &sigma2);
        best = kept.iter().zip(theta).map(|(&c, t)| (shapes[c], t)).collect();
    }
    Ok((best, sigma2))
}

/// The design matrix x[j][c]: the unit wavelet variance of shape c at scale j.
fn design(wv: &[WaveletVariance], shapes: &[Shape]) -> Vec<Vec<f64>> {
    wv.iter().map(|w| shapes.iter().map(|s| s.unit(w)).collect()).collect()
}

/// The exact non-negative least-squares optimum over every subset of the columns of `x`: the
/// unconstrained weighted fit of each subset, kept when all its weights are positive, the one with
/// the smallest objective chosen (the KKT solution is among them). Returns the kept columns, their
/// weights and the objective (empty and infinite when no subset is feasible).
fn nnls(x: &[Vec<f64>], nu: &[f64], sigma2: &[f64]) -> (Vec<usize>, Vec<f64>, f64) {
    let p = x.first().map_or(0, Vec::len);
    let mut best: (Vec<usize>, Vec<f64>, f64) = (Vec::new(), Vec::new(), f64::INFINITY);
    // The normal equations of all columns, once; each subset's are a sub-block.
    let Some(g) = information(x, sigma2) else { return best };
    let mut rhs = vec![0.0; p];
    for ((row, n), s2) in x.iter().zip(nu).zip(sigma2) {
        for (r, v) in rhs.iter_mut().zip(row) {
            *r += v * n / s2;
        }
    }
    for mask in 1u32..(1u32 << p) {
        let cols: Vec<usize> = (0..p).filter(|c| mask & (1 << c) != 0).collect();
        let sub: Vec<Vec<f64>> = cols.iter().map(|&r| cols.iter().map(|&c| g[r][c]).collect()).collect();
        let Some(inv) = invert(&sub) else { continue };
        let theta: Vec<f64> = inv.iter().map(|row| row.iter().zip(&cols).map(|(a, &c)| a * rhs[c]).sum()).collect();
        if theta.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
            continue;
        }
        let j = objective(x, nu, sigma2, &cols, &theta);
        if j < best.2 {
            best = (cols, theta, j);
        }
    }
    best
}

/// (nu_hat - X theta)' W (nu_hat - X theta) over the columns `cols`.
fn objective(x: &[Vec<f64>], nu: &[f64], sigma2: &[f64], cols: &[usize], theta: &[f64]) -> f64 {
    x.iter()
        .zip(nu)
        .zip(sigma2)
        .map(|((row, n), s2)| {
            let model: f64 = cols.iter().zip(theta).map(|(&c, t)| t * row[c]).sum();
            (n - model).powi(2) / s2
        })
        .sum()
}

/// D' W D with W = diag(1 / sigma2), D given by rows (one per scale).
fn information(d: &[Vec<f64>], sigma2: &[f64]) -> Option<Vec<Vec<f64>>> {
    let p = d.first().map_or(0, Vec::len);
    let mut m = vec![vec![0.0; p]; p];
    for (row, s2) in d.iter().zip(sigma2) {
        if s2.is_nan() || *s2 <= 0.0 {
            return None;
        }
        for (out, a) in m.iter_mut().zip(row) {
            for (cell, b) in out.iter_mut().zip(row) {
                *cell += a * b / s2;
            }
        }
    }
    Some(m)
}

/// Step of the central difference of a Gauss-Markov column in ln T.
const LN_T_STEP: f64 = 1e-4;

/// The Jacobian of the model's wavelet variance by rows (one per scale) in the parameters: the
/// weight of each shape, and for a Gauss-Markov process also ln T (sigma^2 times the central
/// difference of its unit column).
fn jacobian(wv: &[WaveletVariance], model: &[(Shape, f64)]) -> Vec<Vec<f64>> {
    wv.iter()
        .map(|w| {
            let mut row = Vec::with_capacity(model.len() + 2);
            for &(s, t) in model {
                row.push(s.unit(w));
                if let Shape::GaussMarkov(tc) = s {
                    let up = Shape::GaussMarkov(tc * LN_T_STEP.exp()).unit(w);
                    let down = Shape::GaussMarkov(tc * (-LN_T_STEP).exp()).unit(w);
                    row.push(t * (up - down) / (2.0 * LN_T_STEP));
                }
            }
            row
        })
        .collect()
}

/// The covariance of the wavelet-variance estimates across scales under a fitted model,
/// (curve unit)^4: the large-sample spectral covariance S ([`wavelet_variance_covariance`]) plus
/// a drift's cross terms C ([`ShapeIntegrals::drift_cross_variance`]) correlated as the spectral
/// part is: Sigma_jk = S_jk + rho_jk sqrt(C_j C_k), rho_jk = S_jk / sqrt(S_jj S_kk) (a sum of two
/// positive semi-definite matrices; the correlation of the coefficients' means across scales
/// equals the spectral one for white noise). The diagonal is checked against the variance of the
/// estimates over simulated records (test `scale_covariance_equals_the_spread_over_simulated_
/// records`, with and without a drift). The large-sample formula drops the (1 - |lag| / M)
/// weighting of the coefficients' autocovariance, so it overstates the variance where a scale has
/// few coefficients per filter width: by about 1 / 0.75 at the last scale of a white-noise record
/// (M = 2m + 1), 1 / 0.92 one octave below (conservative; not corrected). The chi-squared variance
/// 2 nu^4 / edf is not used here: with the curve's equivalent degrees of freedom it overstated the
/// variance up to 1.5 times at middle scales, and without bound at scales a drift dominates.
/// `None` when a shape is not among `integrals`.
pub(crate) fn scale_covariance(
    wv: &[WaveletVariance],
    integrals: &ShapeIntegrals,
    model: &[(Shape, f64)],
) -> Option<Vec<Vec<f64>>> {
    let spectral = integrals.covariance(model)?;
    let cross = integrals.drift_cross_variance(wv, model)?;
    let n = wv.len();
    let mut sigma = vec![vec![0.0; n]; n];
    for j in 0..n {
        for k in 0..n {
            let (sj, sk) = (spectral[j][j], spectral[k][k]);
            sigma[j][k] = if j == k {
                sj + cross[j]
            } else if sj > 0.0 && sk > 0.0 {
                spectral[j][k] * (1.0 + (cross[j] * cross[k]).sqrt() / (sj * sk).sqrt())
            } else {
                0.0
            };
        }
    }
    Some(sigma)
}

/// The sandwich covariance B D' W Sigma W D B (B = (D' W D)^-1, W = diag(1 / sigma2)) of the
/// parameters of [`jacobian`], with Sigma the covariance of the wavelet variances under the
/// fitted model ([`scale_covariance`]); and the optimism 2 tr(B meat) = 2 tr(W H Sigma). `None`
/// when the information matrix is singular.
fn sandwich(
    wv: &[WaveletVariance],
    integrals: &ShapeIntegrals,
    model: &[(Shape, f64)],
    sigma2: &[f64],
) -> Option<(Vec<Vec<f64>>, f64)> {
    let d = jacobian(wv, model);
    let bread = information(&d, sigma2).and_then(|m| invert(&m))?;
    let sigma = scale_covariance(wv, integrals, model)?;
    let p = bread.len();
    // A = W D (n x p); meat = A' Sigma A.
    let a: Vec<Vec<f64>> = d.iter().zip(sigma2).map(|(row, s2)| row.iter().map(|v| v / s2).collect()).collect();
    let mut meat = vec![vec![0.0; p]; p];
    for (j, row_j) in sigma.iter().enumerate() {
        for (k, &c) in row_j.iter().enumerate() {
            if c == 0.0 {
                continue;
            }
            for (r, row) in meat.iter_mut().enumerate() {
                for (q, cell) in row.iter_mut().enumerate() {
                    *cell += a[j][r] * c * a[k][q];
                }
            }
        }
    }
    let mul = |x: &[Vec<f64>], y: &[Vec<f64>]| -> Vec<Vec<f64>> {
        (0..p).map(|r| (0..p).map(|q| (0..p).map(|t| x[r][t] * y[t][q]).sum()).collect()).collect()
    };
    let optimism = 2.0 * (0..p).map(|r| (0..p).map(|q| bread[r][q] * meat[q][r]).sum::<f64>()).sum::<f64>();
    Some((mul(&mul(&bread, &meat), &bread), optimism))
}

/// The fit of a model (linear processes and Gauss-Markov processes with their weights) with its
/// objective, intervals and criterion, and each linear process's weight with its standard error
/// (the inputs of the model averaging, module `average`). `search` is the range of correlation
/// times searched (an estimate at either end is flagged).
fn finish(
    wv: &[WaveletVariance],
    integrals: &ShapeIntegrals,
    model: &[(Shape, f64)],
    sigma2: &[f64],
    confidence: f64,
    search: (f64, f64),
) -> (GmwmFit, Vec<average::Moment>) {
    let mut model: Vec<(Shape, f64)> = model.to_vec();
    model.sort_by(|a, b| {
        let key = |s: &Shape| match s {
            Shape::Linear(p) => (0, PROCESSES.iter().position(|q| q == p).unwrap_or(0) as f64),
            Shape::GaussMarkov(t) => (1, *t),
        };
        let (ka, kb) = (key(&a.0), key(&b.0));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let shapes: Vec<Shape> = model.iter().map(|m| m.0).collect();
    let theta: Vec<f64> = model.iter().map(|m| m.1).collect();
    let x = design(wv, &shapes);
    let nu: Vec<f64> = wv.iter().map(|w| w.nu2).collect();
    let cols: Vec<usize> = (0..shapes.len()).collect();
    let objective = objective(&x, &nu, sigma2, &cols, &theta);
    let (cov, optimism) = sandwich(wv, integrals, &model, sigma2).unwrap_or((Vec::new(), f64::NAN));
    let z = chi_squared_quantile(confidence, 1.0).map_or(f64::NAN, f64::sqrt);
    let se = |i: usize| cov.get(i).and_then(|r| r.get(i)).map_or(f64::NAN, |v| v.max(0.0).sqrt());
    let mut parameters = Vec::with_capacity(model.len());
    let mut moments = Vec::with_capacity(model.len());
    let mut i = 0;
    for &(shape, t) in &model {
        let s = se(i);
        let mut par = GmwmParameter {
            process: shape.process(),
            value: t.sqrt(),
            lower: (t - z * s).max(0.0).sqrt(),
            upper: (t + z * s).max(0.0).sqrt(),
            correlation_time: None,
            model_weight: 1.0,
        };
        if let Shape::Linear(p) = shape {
            moments.push(average::Moment { process: p, weight: t, se: s });
        }
        i += 1;
        if let Shape::GaussMarkov(tc) = shape {
            let s = se(i);
            i += 1;
            // Within 1e-4 in ln T of an end of the range searched (golden-section steps stop
            // short of the ends by a few 1e-6).
            let edge = |b: f64| b.is_finite() && (tc / b).ln().abs() < 1e-4;
            par.correlation_time = Some(CorrelationTime {
                value_s: tc,
                lower_s: tc * (-z * s).exp(),
                upper_s: tc * (z * s).exp(),
                at_search_edge: edge(search.0) || edge(search.1),
            });
        }
        parameters.push(par);
    }
    // A model whose covariance could not be made (a singular information matrix: a correlation
    // time collinear with another term) is not eligible: no optimism, an infinite criterion.
    let optimism = if optimism.is_finite() && optimism >= 0.0 { optimism } else { f64::INFINITY };
    let weighted_rms_residual = (objective / wv.len() as f64).sqrt();
    let quality = if weighted_rms_residual > crate::noise::FIT_RMS_LIMIT {
        crate::noise::FitQuality::Poor
    } else {
        crate::noise::FitQuality::Acceptable
    };
    let fit = GmwmFit {
        parameters,
        confidence,
        scales: wv.len(),
        objective,
        optimism,
        criterion: objective + optimism,
        weighted_rms_residual,
        quality,
        left_out: Vec::new(),
    };
    (fit, moments)
}

/// Inverse of a small symmetric positive matrix (scaled to unit diagonal, Gauss-Jordan with
/// partial pivoting); `None` when singular.
fn invert(m: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let p = m.len();
    let d: Vec<f64> = (0..p).map(|i| m[i][i].sqrt()).collect();
    if d.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return None;
    }
    let mut a: Vec<Vec<f64>> = (0..p)
        .map(|i| {
            let mut row: Vec<f64> = (0..p).map(|j| m[i][j] / (d[i] * d[j])).collect();
            row.extend((0..p).map(|j| if i == j { 1.0 } else { 0.0 }));
            row
        })
        .collect();
    for c in 0..p {
        let piv = (c..p).max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))?;
        if a[piv][c].abs() < 1e-13 {
            return None;
        }
        a.swap(c, piv);
        let v = a[c][c];
        for x in a[c].iter_mut() {
            *x /= v;
        }
        let pivot_row = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            let f = row[c];
            if r != c && f != 0.0 {
                for (x, y) in row.iter_mut().zip(&pivot_row) {
                    *x -= f * y;
                }
            }
        }
    }
    Some((0..p).map(|i| (0..p).map(|j| a[i][p + j] / (d[i] * d[j])).collect()).collect())
}

#[cfg(test)]
mod tests;
