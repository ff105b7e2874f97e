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
//! Scope of this implementation (stated in METHODS): the processes are those whose wavelet
//! variance is linear in a parameter (white noise N, quantization Q, the flicker floor of bias
//! instability B, random walk K, drift R), so for a fixed weight matrix the GMWM objective is a
//! non-negative weighted least-squares problem solved exactly (every subset of processes, the
//! best feasible one); Omega is the inverse of a diagonal estimate of the wavelet-variance
//! covariance, var(nu_hat^2_j) = 2 nu^4_j / edf_j (the chi-squared approximation with the
//! curve's equivalent degrees of freedom), re-evaluated at the fitted nu(theta) a few times; the
//! intervals use the full covariance across scales (module `covariance`, Percival and Walden
//! 2000, ch. 8) in a sandwich. First-order Gauss-Markov processes are not included.

mod covariance;
mod overbound;

pub use covariance::wavelet_variance_covariance;
pub use overbound::{overbound_factors, OverboundFactors};

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
}

/// Every process, in the order of the parameter vector.
pub const PROCESSES: [Process; 5] =
    [Process::Quantization, Process::White, Process::Flicker, Process::RandomWalk, Process::Drift];

impl Process {
    /// `quantization`, `white`, `flicker`, `random_walk`, `drift`.
    pub fn name(self) -> &'static str {
        match self {
            Process::Quantization => "quantization",
            Process::White => "white",
            Process::Flicker => "flicker",
            Process::RandomWalk => "random_walk",
            Process::Drift => "drift",
        }
    }

    /// The Haar wavelet variance at `tau_s` per unit squared coefficient (nu^2 = AVAR / 2).
    pub fn unit_wavelet_variance(self, tau_s: f64) -> f64 {
        0.5 * match self {
            Process::Quantization => 3.0 / (tau_s * tau_s),
            Process::White => 1.0 / tau_s,
            Process::Flicker => FLICKER * FLICKER,
            Process::RandomWalk => tau_s / 3.0,
            Process::Drift => tau_s * tau_s / 2.0,
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

/// One estimated parameter of a GMWM fit, in the curve's coefficient units (for a gyro in deg/s:
/// Q deg, N deg/sqrt(s), B deg/s, K deg/s/sqrt(s), R deg/s^2).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GmwmParameter {
    /// The process.
    pub process: Process,
    /// The coefficient (square root of the fitted wavelet-variance weight).
    pub value: f64,
    /// Lower end of the two-sided interval at `confidence` (0 when the interval reaches zero).
    pub lower: f64,
    /// Upper end of the two-sided interval.
    pub upper: f64,
}

/// A GMWM fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GmwmFit {
    /// The processes of the chosen model with their coefficients and intervals.
    pub parameters: Vec<GmwmParameter>,
    /// Two-sided confidence level of the intervals.
    pub confidence: f64,
    /// Scales used.
    pub scales: usize,
    /// The objective at the estimate, (nu_hat - nu)' Omega (nu_hat - nu).
    pub objective: f64,
    /// The model-choice criterion: objective + 2 x number of parameters (smaller is better).
    pub criterion: f64,
}

impl GmwmFit {
    /// The coefficient of a process, when the model holds it.
    pub fn value(&self, process: Process) -> Option<f64> {
        self.parameter(process).map(|p| p.value)
    }

    /// The parameter of a process, when the model holds it.
    pub fn parameter(&self, process: Process) -> Option<GmwmParameter> {
        self.parameters.iter().find(|p| p.process == process).copied()
    }

    /// The model's wavelet variance at `tau_s`.
    pub fn wavelet_variance(&self, tau_s: f64) -> f64 {
        self.parameters.iter().map(|p| p.value * p.value * p.process.unit_wavelet_variance(tau_s)).sum()
    }
}

/// Reweighting rounds: Omega evaluated at nu_hat, then at the fitted nu(theta).
const ROUNDS: usize = 4;

/// GMWM fit of a given set of processes (at least one) to the wavelet variance: non-negative
/// weighted least squares in the squared coefficients with Omega = diag(edf_j / (2 nu_j^4)), nu_j
/// the fitted wavelet variance (the estimate in the first round). Processes whose weight is zero
/// at the optimum are left out of the result. Intervals: theta +- z sqrt(var), var from the
/// sandwich covariance with the wavelet variances' covariance across scales under the fitted
/// model ([`wavelet_variance_covariance`]), clipped at zero, then square-rooted; two-sided at
/// `confidence`.
pub fn fit_processes(wv: &[WaveletVariance], processes: &[Process], confidence: f64) -> Result<GmwmFit, GmwmError> {
    let (fit, sigma2) = fit_estimate(wv, processes, confidence)?;
    Ok(with_intervals(fit, wv, &sigma2))
}

/// The estimate of [`fit_processes`] with its objective, intervals not yet made (NaN), and the
/// final weights' variances sigma2.
fn fit_estimate(
    wv: &[WaveletVariance],
    processes: &[Process],
    confidence: f64,
) -> Result<(GmwmFit, Vec<f64>), GmwmError> {
    if confidence.is_nan() || confidence <= 0.0 || confidence >= 1.0 {
        return Err(GmwmError::Confidence(confidence));
    }
    let p = processes.len();
    if wv.len() <= p || p == 0 {
        return Err(GmwmError::TooFewScales { scales: wv.len(), parameters: p });
    }
    let mut sigma2: Vec<f64> = wv.iter().map(|w| 2.0 * w.nu2 * w.nu2 / w.edf).collect();
    let mut best = nnls_subsets(wv, processes, &sigma2);
    for _ in 1..ROUNDS {
        sigma2 = wv
            .iter()
            .map(|w| {
                let model: f64 = best.iter().map(|&(pr, t)| t * pr.unit_wavelet_variance(w.tau_s)).sum();
                let nu = if model > 0.0 { model } else { w.nu2 };
                2.0 * nu * nu / w.edf
            })
            .collect();
        best = nnls_subsets(wv, processes, &sigma2);
    }
    let chosen: Vec<Process> = best.iter().map(|x| x.0).collect();
    let theta: Vec<f64> = best.iter().map(|x| x.1).collect();
    let objective = objective(wv, &chosen, &theta, &sigma2);
    let parameters = chosen
        .iter()
        .zip(&theta)
        .map(|(&process, &t)| GmwmParameter { process, value: t.sqrt(), lower: f64::NAN, upper: f64::NAN })
        .collect();
    let fit = GmwmFit { parameters, confidence, scales: wv.len(), objective, criterion: objective + 2.0 * p as f64 };
    Ok((fit, sigma2))
}

/// The fit with its two-sided intervals: theta +- z sqrt(var) on the squared coefficients
/// ([`estimate_covariance`]), clipped at 0, square-rooted.
fn with_intervals(mut fit: GmwmFit, wv: &[WaveletVariance], sigma2: &[f64]) -> GmwmFit {
    let chosen: Vec<Process> = fit.parameters.iter().map(|p| p.process).collect();
    let theta: Vec<f64> = fit.parameters.iter().map(|p| p.value * p.value).collect();
    let cov = estimate_covariance(wv, &chosen, &theta, sigma2);
    let z = chi_squared_quantile(fit.confidence, 1.0).map_or(f64::NAN, f64::sqrt);
    for (i, (par, &t)) in fit.parameters.iter_mut().zip(&theta).enumerate() {
        let se = cov.get(i).and_then(|r| r.get(i)).map_or(f64::NAN, |v| v.max(0.0).sqrt());
        par.lower = (t - z * se).max(0.0).sqrt();
        par.upper = (t + z * se).max(0.0).sqrt();
    }
    fit
}

/// The covariance of the squared coefficients: the sandwich (X' W X)^-1 X' W Sigma W X (X' W
/// X)^-1 of the weighted fit (W = diag(1 / sigma2)) with Sigma the covariance of the wavelet
/// variances across scales under the fitted model ([`wavelet_variance_covariance`]); its
/// diagonal is raised to the chi-squared variance 2 nu^4 / edf where that is larger (the
/// large-sample formula understates the variance at scales with few independent terms), the
/// correlations kept. Empty when the information matrix is singular.
fn estimate_covariance(wv: &[WaveletVariance], set: &[Process], theta: &[f64], sigma2: &[f64]) -> Vec<Vec<f64>> {
    let Some(bread) = information(wv, set, sigma2).and_then(|m| invert(&m)) else { return Vec::new() };
    let model: Vec<(Process, f64)> = set.iter().copied().zip(theta.iter().copied()).collect();
    let spectral = wavelet_variance_covariance(wv, &model);
    let n = wv.len();
    let diag: Vec<f64> = (0..n).map(|j| spectral[j][j].max(sigma2[j])).collect();
    let p = set.len();
    // A = W X (n x p); meat = A' Sigma A.
    let a: Vec<Vec<f64>> = wv
        .iter()
        .zip(sigma2)
        .map(|(w, s2)| set.iter().map(|pr| pr.unit_wavelet_variance(w.tau_s) / s2).collect())
        .collect();
    let sigma = |j: usize, k: usize| -> f64 {
        if j == k {
            return diag[j];
        }
        let (sj, sk) = (spectral[j][j], spectral[k][k]);
        if sj > 0.0 && sk > 0.0 {
            spectral[j][k] / (sj * sk).sqrt() * (diag[j] * diag[k]).sqrt()
        } else {
            0.0
        }
    };
    let mut meat = vec![vec![0.0; p]; p];
    for j in 0..n {
        for k in 0..n {
            let c = sigma(j, k);
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
    mul(&mul(&bread, &meat), &bread)
}

/// The GMWM fit with the model chosen by the criterion J + 2 p over every non-empty subset of
/// `candidates` (a simplified wavelet information criterion: the objective is approximately
/// chi-squared with (scales - p) degrees of freedom when the model holds, so 2 p is the AIC
/// penalty; Guerrier et al.'s WIC estimates the optimism instead).
pub fn select_model(wv: &[WaveletVariance], candidates: &[Process], confidence: f64) -> Result<GmwmFit, GmwmError> {
    let mut best: Option<(GmwmFit, Vec<f64>)> = None;
    let mut last_err = None;
    for mask in 1u32..(1u32 << candidates.len()) {
        let set: Vec<Process> =
            candidates.iter().enumerate().filter(|(i, _)| mask & (1 << i) != 0).map(|(_, &p)| p).collect();
        match fit_estimate(wv, &set, confidence) {
            Ok((mut f, sigma2)) => {
                // The penalty counts the processes the model keeps.
                f.criterion = f.objective + 2.0 * f.parameters.len() as f64;
                if best.as_ref().is_none_or(|b| f.criterion < b.0.criterion - 1e-12) {
                    best = Some((f, sigma2));
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    match (best, last_err) {
        // Intervals for the chosen model only.
        (Some((b, sigma2)), _) => Ok(with_intervals(b, wv, &sigma2)),
        (None, Some(e)) => Err(e),
        (None, None) => Err(GmwmError::TooFewScales { scales: wv.len(), parameters: 0 }),
    }
}

/// GMWM of an octave Allan curve with the model chosen over every process ([`PROCESSES`]).
pub fn gmwm(curve: &AllanCurve, confidence: f64) -> Result<GmwmFit, GmwmError> {
    let wv = wavelet_variance(curve)?;
    select_model(&wv, &PROCESSES, confidence)
}

/// The exact non-negative least-squares optimum over every subset of `processes`: the
/// unconstrained weighted fit of each subset, kept when all its weights are positive, the one
/// with the smallest objective chosen (the KKT solution is among them).
fn nnls_subsets(wv: &[WaveletVariance], processes: &[Process], sigma2: &[f64]) -> Vec<(Process, f64)> {
    let mut best: Option<(f64, Vec<(Process, f64)>)> = None;
    for mask in 1u32..(1u32 << processes.len()) {
        let set: Vec<Process> =
            processes.iter().enumerate().filter(|(i, _)| mask & (1 << i) != 0).map(|(_, &p)| p).collect();
        let Some(theta) = weighted_fit(wv, &set, sigma2) else { continue };
        if theta.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
            continue;
        }
        let j = objective(wv, &set, &theta, sigma2);
        if best.as_ref().is_none_or(|b| j < b.0) {
            best = Some((j, set.into_iter().zip(theta).collect()));
        }
    }
    best.map(|b| b.1).unwrap_or_default()
}

fn objective(wv: &[WaveletVariance], set: &[Process], theta: &[f64], sigma2: &[f64]) -> f64 {
    wv.iter()
        .zip(sigma2)
        .map(|(w, s2)| {
            let model: f64 = set.iter().zip(theta).map(|(p, t)| t * p.unit_wavelet_variance(w.tau_s)).sum();
            (w.nu2 - model).powi(2) / s2
        })
        .sum()
}

/// X' Omega X with Omega = diag(1 / sigma2).
fn information(wv: &[WaveletVariance], set: &[Process], sigma2: &[f64]) -> Option<Vec<Vec<f64>>> {
    let p = set.len();
    let mut m = vec![vec![0.0; p]; p];
    for (w, s2) in wv.iter().zip(sigma2) {
        if s2.is_nan() || *s2 <= 0.0 {
            return None;
        }
        let x: Vec<f64> = set.iter().map(|pr| pr.unit_wavelet_variance(w.tau_s)).collect();
        for (row, xa) in m.iter_mut().zip(&x) {
            for (cell, xb) in row.iter_mut().zip(&x) {
                *cell += xa * xb / s2;
            }
        }
    }
    Some(m)
}

/// The weighted least-squares weights of `set` (normal equations, columns scaled to unit
/// diagonal for conditioning).
fn weighted_fit(wv: &[WaveletVariance], set: &[Process], sigma2: &[f64]) -> Option<Vec<f64>> {
    let m = information(wv, set, sigma2)?;
    let mut rhs = vec![0.0; set.len()];
    for (w, s2) in wv.iter().zip(sigma2) {
        for (r, pr) in rhs.iter_mut().zip(set) {
            *r += pr.unit_wavelet_variance(w.tau_s) * w.nu2 / s2;
        }
    }
    let inv = invert(&m)?;
    Some(inv.iter().map(|row| row.iter().zip(&rhs).map(|(a, b)| a * b).sum()).collect())
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
