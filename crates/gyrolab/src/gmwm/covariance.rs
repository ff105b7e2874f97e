//! The covariance of the Haar wavelet-variance estimates of a fitted composite model, across
//! scales, for the GMWM's intervals (docs/METHODS.md 3.1, "GMWM").
//!
//! Source: D. B. Percival and A. T. Walden, *Wavelet Methods for Time Series Analysis*, 2000,
//! section 8.3-8.4: for a Gaussian process with spectral density S(f) (f in cycles per sample),
//! the MODWT wavelet-variance estimate at level j from M_j coefficients has the large-sample
//! variance 2 A_j / M_j, A_j = integral over [-1/2, 1/2] of |H_j(f)|^4 S(f)^2 df; the same
//! argument gives cov(nu_hat^2_j, nu_hat^2_k) = 2 / M integral |H_j(f)|^2 |H_k(f)|^2 S(f)^2 df
//! (M = min(M_j, M_k) here). The Haar squared gain at averaging factor m (width 2m) is
//! |H(f)|^2 = sin^4(pi f m) / (m^2 sin^2(pi f)), so that nu^2 = integral |H|^2 S = AVAR(m tau0) / 2.
//! Spectral densities per sample of each process, from the one-sided continuous power-law
//! coefficients h_alpha of IEEE Std 1139 / NIST SP 1065 (S_d(f) = S_y(f / tau0) / (2 tau0)):
//! white N: N^2 / tau0; quantization Q: 4 Q^2 sin^2(pi f) / tau0^2 (differenced white angle noise);
//! flicker floor B: B^2 / (2 pi |f|); random walk K: K^2 tau0 / (4 sin^2(pi f)); drift: none
//! (deterministic). Each reproduces its AVAR of IEEE 952 annex C at long averaging times.

use super::{Process, WaveletVariance};

/// The model's spectral density per sample at frequency `f` (cycles per sample, 0 < f <= 1/2),
/// (curve unit)^2 per cycle per sample; `model` holds (process, squared coefficient).
fn spectral_density(model: &[(Process, f64)], tau0_s: f64, f: f64) -> f64 {
    let s = (std::f64::consts::PI * f).sin();
    model
        .iter()
        .map(|&(p, t)| match p {
            Process::White => t / tau0_s,
            Process::Quantization => 4.0 * t * s * s / (tau0_s * tau0_s),
            Process::Flicker => t / (2.0 * std::f64::consts::PI * f),
            Process::RandomWalk => t * tau0_s / (4.0 * s * s),
            Process::Drift => 0.0,
        })
        .sum()
}

/// The Haar squared gain at averaging factor `m`; `averaged` replaces sin^4(pi f m) by its mean
/// 3/8 (where the grid does not resolve its oscillation and the rest of the integrand is smooth).
fn haar_gain(m: f64, f: f64, averaged: bool) -> f64 {
    let s = (std::f64::consts::PI * f).sin();
    let num = if averaged { 0.375 } else { (std::f64::consts::PI * f * m).sin().powi(4) };
    num / (m * m * s * s)
}

/// Midpoint-rule integral of the product of the two scales' gains and S^2 over (a, b] in `n`
/// steps (uniform, or uniform in log f when `log`).
#[allow(clippy::too_many_arguments)]
fn integrate(
    model: &[(Process, f64)],
    tau0_s: f64,
    (m_lo, avg_lo): (f64, bool),
    (m_hi, avg_hi): (f64, bool),
    a: f64,
    b: f64,
    n: usize,
    log: bool,
) -> f64 {
    if b <= a {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..n {
        let u = (i as f64 + 0.5) / n as f64;
        let (f, w) = if log {
            let f = a * (b / a).powf(u);
            (f, f * (b / a).ln() / n as f64)
        } else {
            (a + u * (b - a), (b - a) / n as f64)
        };
        let s = spectral_density(model, tau0_s, f);
        sum += w * haar_gain(m_lo, f, avg_lo) * haar_gain(m_hi, f, avg_hi) * s * s;
    }
    sum
}

/// Covariance matrix of the wavelet-variance estimates `wv` under the model (process, squared
/// coefficient): entries (curve unit)^4. The integral over [-1/2, 1/2] is twice that over
/// (0, 1/2], in three parts: up to 32 / m_hi exactly (512 steps), then with the larger scale's
/// oscillation averaged up to 32 / m_lo (512 steps), then both averaged (256 log steps).
pub fn wavelet_variance_covariance(wv: &[WaveletVariance], model: &[(Process, f64)]) -> Vec<Vec<f64>> {
    let n = wv.len();
    let mut cov = vec![vec![0.0; n]; n];
    for j in 0..n {
        for k in j..n {
            let (a, b) = (&wv[j], &wv[k]);
            let tau0 = a.tau_s / a.m as f64;
            let (m_lo, m_hi) = ((a.m.min(b.m)) as f64, (a.m.max(b.m)) as f64);
            let f1 = (32.0 / m_hi).min(0.5);
            let f2 = (32.0 / m_lo).min(0.5);
            let exact = integrate(model, tau0, (m_lo, false), (m_hi, false), 0.0, f1, 512, false);
            let middle = integrate(model, tau0, (m_lo, false), (m_hi, true), f1, f2, 512, false);
            let tail = integrate(model, tau0, (m_lo, true), (m_hi, true), f2, 0.5, 256, true);
            let terms = a.terms.min(b.terms).max(1) as f64;
            let c = 2.0 / terms * 2.0 * (exact + middle + tail);
            cov[j][k] = c;
            cov[k][j] = c;
        }
    }
    cov
}
