//! Overbounding of a filter's noise model (white noise N and random walk K) on a measured Allan
//! curve: per parameter, the smallest factor (at least 1) such that the Allan deviation of the
//! inflated model lies on or above the curve's upper confidence bound at every tau used. The idea
//! of overbounding the measured Allan variance follows the navigation-integrity literature cited in
//! issue 36 (Lethander and Taylor, NAVIGATION 2023); the rule below is gyrolab's own and is stated
//! in docs/METHODS.md ("Overbound").

use crate::allan::AllanCurve;
use serde::Serialize;

/// The factors each parameter of the model needed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OverboundFactors {
    /// Factor applied to N (None when the model has no white noise).
    pub white: Option<f64>,
    /// Factor applied to K (None when the model has no random walk).
    pub random_walk: Option<f64>,
    /// Taus with an upper bound that were checked.
    pub taus_checked: usize,
    /// Confidence level of the curve's two-sided intervals whose upper ends were overbounded
    /// (each upper end is a one-sided bound at (1 + confidence) / 2).
    pub confidence: Option<f64>,
}

/// The overbound factors of the model AVAR(tau) = N^2 / tau + K^2 tau / 3 (N, K in the curve's
/// coefficient units) against the upper ends of the curve's intervals within `tau_range_s`
/// (default: every point). The taus are split at the crossing tau_c = sqrt(3) N / K of the two
/// terms: N's factor is the smallest f >= 1 with f^2 N^2 / tau + K^2 tau / 3 >= U(tau)^2 at every
/// tau <= tau_c, K's the smallest with N^2 / tau + f^2 K^2 tau / 3 >= U(tau)^2 above it; since
/// neither factor is below 1, the model with both factors lies on or above U everywhere. `None`
/// when neither parameter is given or no point has an upper bound.
pub fn overbound_factors(
    curve: &AllanCurve,
    white: Option<f64>,
    random_walk: Option<f64>,
    tau_range_s: Option<(f64, f64)>,
) -> Option<OverboundFactors> {
    let n = white.filter(|v| v.is_finite() && *v > 0.0);
    let k = random_walk.filter(|v| v.is_finite() && *v > 0.0);
    if n.is_none() && k.is_none() {
        return None;
    }
    let crossing = match (n, k) {
        (Some(n), Some(k)) => 3f64.sqrt() * n / k,
        (Some(_), None) => f64::INFINITY,
        _ => 0.0,
    };
    let (mut need_n, mut need_k) = (1.0f64, 1.0f64);
    let mut checked = 0;
    for p in &curve.points {
        let Some(u) = p.upper.filter(|u| u.is_finite()) else { continue };
        if let Some((lo, hi)) = tau_range_s {
            if p.tau_s < lo || p.tau_s > hi {
                continue;
            }
        }
        checked += 1;
        let t = p.tau_s;
        let wn = n.map_or(0.0, |n| n * n / t);
        let rw = k.map_or(0.0, |k| k * k * t / 3.0);
        let u2 = u * u;
        if t <= crossing {
            if wn > 0.0 && u2 > wn + rw {
                need_n = need_n.max(((u2 - rw) / wn).sqrt());
            }
        } else if rw > 0.0 && u2 > wn + rw {
            need_k = need_k.max(((u2 - wn) / rw).sqrt());
        }
    }
    (checked > 0).then_some(OverboundFactors {
        white: n.map(|_| need_n),
        random_walk: k.map(|_| need_k),
        taus_checked: checked,
        confidence: curve.confidence,
    })
}
