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
//! curve's equivalent degrees of freedom), re-evaluated at the fitted nu(theta) a few times.
//! First-order Gauss-Markov processes are not included.

mod overbound;

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
            out.push(WaveletVariance { tau_s: p.tau_s, nu2: 0.5 * p.deviation * p.deviation, edf });
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
/// at the optimum are left out of the result. Intervals: theta +- z sqrt(diag((X' Omega X)^-1))
/// (the asymptotic covariance of the GMWM estimator with Omega the inverse of the estimate's
/// covariance), clipped at zero, then square-rooted; two-sided at `confidence`.
pub fn fit_processes(wv: &[WaveletVariance], processes: &[Process], confidence: f64) -> Result<GmwmFit, GmwmError> {
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
    let cov = information(wv, &chosen, &sigma2).and_then(|m| invert(&m)).unwrap_or_default();
    let z = chi_squared_quantile(confidence, 1.0).map_or(f64::NAN, f64::sqrt);
    let parameters = chosen
        .iter()
        .zip(&theta)
        .enumerate()
        .map(|(i, (&process, &t))| {
            let se = cov.get(i).and_then(|r| r.get(i)).map_or(f64::NAN, |v| v.max(0.0).sqrt());
            GmwmParameter {
                process,
                value: t.sqrt(),
                lower: (t - z * se).max(0.0).sqrt(),
                upper: (t + z * se).max(0.0).sqrt(),
            }
        })
        .collect();
    Ok(GmwmFit { parameters, confidence, scales: wv.len(), objective, criterion: objective + 2.0 * p as f64 })
}

/// The GMWM fit with the model chosen by the criterion J + 2 p over every non-empty subset of
/// `candidates` (a simplified wavelet information criterion: the objective is approximately
/// chi-squared with (scales - p) degrees of freedom when the model holds, so 2 p is the AIC
/// penalty; Guerrier et al.'s WIC estimates the optimism instead).
pub fn select_model(wv: &[WaveletVariance], candidates: &[Process], confidence: f64) -> Result<GmwmFit, GmwmError> {
    let mut best: Option<GmwmFit> = None;
    let mut last_err = None;
    for mask in 1u32..(1u32 << candidates.len()) {
        let set: Vec<Process> =
            candidates.iter().enumerate().filter(|(i, _)| mask & (1 << i) != 0).map(|(_, &p)| p).collect();
        match fit_processes(wv, &set, confidence) {
            Ok(mut f) => {
                // The penalty counts the processes the model keeps.
                f.criterion = f.objective + 2.0 * f.parameters.len() as f64;
                if best.as_ref().is_none_or(|b| f.criterion < b.criterion - 1e-12) {
                    best = Some(f);
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    match (best, last_err) {
        (Some(b), _) => Ok(b),
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
