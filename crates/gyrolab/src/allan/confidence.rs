//! Noise identification, equivalent degrees of freedom and chi-squared confidence intervals.
//!
//! Sources:
//! - W. J. Riley, C. A. Greenhall, "Power law noise identification using the lag 1
//!   autocorrelation", EFTF 2004: lag-1 ACF r1, differencing until delta = r1/(1+r1) < 0.25,
//!   alpha = -round(2 delta) - 2d for frequency data. Applied, as Stable32 does (read off its
//!   result files, see `docs/METHODS.md`), to the m-sample frequency averages with a linear trend
//!   removed, when there are at least 30 of them; alpha capped at 2.
//! - NIST SP 1065 section 5.6 (B1 ratio of Barnes, R(n) = Mod AVAR / AVAR) for the larger
//!   averaging factors (Stable32's fallback), with Barnes' B1(N, mu) evaluated at N = the
//!   estimator's number of terms, as Stable32's results require.
//! - C. A. Greenhall, W. J. Riley, "Uncertainty of stability variances based on finite
//!   differences", 35th PTTI, 2003/2004: EDF algorithm (eq. 7-10 and tables 1-3), the same one
//!   allantools' `edf_greenhall` implements. Case 4 (white PM, unmodified) is evaluated here by
//!   its exact finite sum, which equals the paper's a0 - a1/r when ceil(r) > d.
//! - NIST SP 1065 section 5.2.11 table 11 (recalled as `b T/tau - c`) for TOTDEV's EDF.
//! - NIST SP 1065 eq. (45): chi-squared bounds var*edf/chi2(p, edf), quantiles from `chi2`
//!   (valid at every edf; statrs' `ChiSquared::inverse_cdf` fails above edf ~ 3e5).

use super::chi2::chi_squared_quantile;

/// Fewest m-sample frequency averages for which the lag-1 autocorrelation is used (Riley &
/// Greenhall's 30; Stable32 counts averages: on Cs5071A it switches to B1 between 30 and 29).
pub(crate) const LAG1_MIN_AVERAGES: usize = 30;

/// Fewest "independent terms" for the B1 fallback: the number of terms of a non-overlapping
/// estimator, terms / m of an overlapping one. Below it the previous tau's alpha is kept.
/// Read off Stable32's result files (phasedat, Keysight, gps, Cs5071A; see `docs/METHODS.md`).
pub(crate) const B1_MIN_TERMS: f64 = 8.0;

/// Lag-1 autocorrelation r1 of a series (Riley & Greenhall eq. 2); `None` if it has no spread.
#[cfg(test)]
pub(super) fn lag1_acf(z: &[f64]) -> Option<f64> {
    if z.len() < 3 {
        return None;
    }
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    let den: f64 = z.iter().map(|v| (v - mean) * (v - mean)).sum();
    if den <= 0.0 || !den.is_finite() {
        return None;
    }
    let num: f64 = z.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    Some(num / den)
}

/// Removes the least-squares straight line from equally spaced values, in place, by projection
/// on the orthogonal polynomials 1 and t - c: no matrix, exact to rounding.
#[cfg(test)]
pub(super) fn detrend_linear(z: &mut [f64]) {
    let n = z.len();
    if n < 2 {
        return;
    }
    let c = (n as f64 - 1.0) / 2.0;
    let (mut s0, mut s1, mut n1) = (0.0, 0.0, 0.0);
    for (t, &v) in z.iter().enumerate() {
        s0 += v;
        s1 += v * (t as f64 - c);
        n1 += (t as f64 - c) * (t as f64 - c);
    }
    let (a0, a1) = (s0 / n as f64, s1 / n1);
    for (t, v) in z.iter_mut().enumerate() {
        *v -= a0 + a1 * (t as f64 - c);
    }
}

/// Lag-1 autocorrelation noise identification at averaging factor m, on the phase `s` (sample
/// units), as Stable32 does it: the n = (L-1)/m non-overlapping m-sample frequency averages
/// w_j = s[(j+1) m] - s[j m] (the factor 1/m does not change r1), linear trend removed, then
/// differenced (at most `dmax` - 1 times, `dmax` the estimator's difference order) until
/// delta = r1/(1+r1) < 0.25; alpha = -round(2 delta) - 2d, capped at 2 (white PM).
///
/// Returns `None` when fewer than [`LAG1_MIN_AVERAGES`] averages exist or the series is constant.
///
/// Streaming, without a copy of the averages: one pass gives the line's coefficients
/// (orthogonal polynomials, as [`detrend_linear`]), a second pass forms the residual r_j and its
/// differences of every order up to `dmax` - 1 on the fly and sums, per order, w, w^2 and
/// w_t w_{t+1}; r1 = (S11 - mu (S1 - w_last + S1 - w_first) + (n-1) mu^2) / (S2 - n mu^2).
/// The residual has zero mean and its differences a mean of order (spread) / n, so the expanded
/// sums lose nothing against the centred ones.
pub(crate) fn lag1_noise_id(s: &[f64], m: usize, dmax: usize) -> Option<i32> {
    const ORDERS: usize = 3;
    if s.len() < 2 || m == 0 {
        return None;
    }
    let n = (s.len() - 1) / m;
    if n < LAG1_MIN_AVERAGES {
        return None;
    }
    let dmax = dmax.saturating_sub(1).min(ORDERS - 1);
    let averages = || (0..n).map(|j| s[(j + 1) * m] - s[j * m]);
    let c = (n as f64 - 1.0) / 2.0;
    let (mut s0, mut s1, mut n1) = (0.0, 0.0, 0.0);
    for (t, v) in averages().enumerate() {
        let p1 = t as f64 - c;
        s0 += v;
        s1 += v * p1;
        n1 += p1 * p1;
    }
    let (a0, a1) = (s0 / n as f64, s1 / n1);
    // Order 0 alone first: most series stop there (delta < 0.25), and this loop has no
    // per-order branches. Its sums are the ones the general loop below forms for d = 0, in the
    // same order, so the result does not depend on which loop ran.
    {
        let (mut sum1, mut sum2, mut sum11, mut first, mut prev) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for (t, v) in averages().enumerate() {
            let cur = v - (a0 + a1 * (t as f64 - c));
            if t == 0 {
                first = cur;
            } else {
                sum11 += prev * cur;
            }
            sum1 += cur;
            sum2 += cur * cur;
            prev = cur;
        }
        let lf = n as f64;
        if n < 3 {
            return None;
        }
        let mu = sum1 / lf;
        let den = sum2 - lf * mu * mu;
        if den <= 0.0 || !den.is_finite() {
            return None;
        }
        let num = sum11 - mu * ((sum1 - prev) + (sum1 - first)) + (lf - 1.0) * mu * mu;
        let r1 = num / den;
        let delta = r1 / (1.0 + r1);
        if delta < 0.25 || dmax == 0 {
            return Some(lag1_alpha(delta, 0));
        }
    }
    // per order d: sum w, sum w^2, sum w_t w_{t+1}, first w, last w
    let mut sum1 = [0.0f64; ORDERS];
    let mut sum2 = [0.0f64; ORDERS];
    let mut sum11 = [0.0f64; ORDERS];
    let mut first = [0.0f64; ORDERS];
    let mut last = [0.0f64; ORDERS];
    // prev[d]: the order-d value at t - 1 (defined once t - 1 >= d)
    let mut prev = [0.0f64; ORDERS];
    for (t, v) in averages().enumerate() {
        let mut cur = [0.0f64; ORDERS];
        cur[0] = v - (a0 + a1 * (t as f64 - c));
        let top = dmax.min(t);
        for d in 1..=top {
            cur[d] = cur[d - 1] - prev[d - 1];
        }
        for d in 0..=top {
            if t == d {
                first[d] = cur[d];
            } else {
                sum11[d] += prev[d] * cur[d];
            }
            sum1[d] += cur[d];
            sum2[d] += cur[d] * cur[d];
        }
        prev[..=top].copy_from_slice(&cur[..=top]);
    }
    last.copy_from_slice(&prev);
    let mut d = 0usize;
    loop {
        let len = n - d;
        if len < 3 {
            return None;
        }
        let lf = len as f64;
        let mu = sum1[d] / lf;
        let den = sum2[d] - lf * mu * mu;
        if den <= 0.0 || !den.is_finite() {
            return None;
        }
        let num = sum11[d] - mu * ((sum1[d] - last[d]) + (sum1[d] - first[d])) + (lf - 1.0) * mu * mu;
        let r1 = num / den;
        let delta = r1 / (1.0 + r1);
        if delta < 0.25 || d >= dmax {
            return Some(lag1_alpha(delta, d));
        }
        d += 1;
    }
}

/// alpha = -round(2 delta) - 2d for frequency data, capped at 2 (Stable32 never reports more;
/// r1 < -5/9 on a short white-PM series would otherwise give 3).
pub(crate) fn lag1_alpha(delta: f64, d: usize) -> i32 {
    (-(2.0 * delta).round() as i32 - 2 * d as i32).min(2)
}

/// Allan-variance tau exponent mu for a power-law alpha (SP1065 table 4): mu = -alpha - 1, capped at -2.
fn mu_of_alpha(alpha: i32) -> i32 {
    (-alpha - 1).max(-2)
}

/// Barnes' B1 bias function for n averages and exponent mu (SP1065 eq. 62, limits for mu = -2..2).
fn b1_theory(n: f64, mu: i32) -> f64 {
    match mu {
        2 => n * (n + 1.0) / 6.0,
        1 => n / 2.0,
        0 => n * n.ln() / (2.0 * (n - 1.0) * std::f64::consts::LN_2),
        -1 => 1.0,
        -2 => (n * n - 1.0) / (1.5 * n * (n - 1.0)),
        _ => {
            let mu = mu as f64;
            n * (1.0 - n.powf(mu)) / (2.0 * (n - 1.0) * (1.0 - 2f64.powf(mu)))
        }
    }
}

/// R(n) = Mod AVAR / AVAR expected for white PM (alpha = 2) and flicker PM (alpha = 1), SP1065 5.6.
/// The flicker value assumes the measurement bandwidth f_h = 1/(2 tau0) (recalled, as allantools).
fn rn_theory(m: f64, alpha: i32) -> f64 {
    if alpha == 2 {
        1.0 / m
    } else {
        let pi2 = std::f64::consts::PI * std::f64::consts::PI;
        let avar = (1.038 + 3.0 * (std::f64::consts::PI * m).ln()) / (4.0 * pi2);
        let mvar = 3.0 * (256.0f64 / 27.0).ln() / (8.0 * pi2);
        mvar / avar
    }
}

/// B1-ratio noise identification (with R(n) to split white from flicker PM), SP1065 section 5.6.
///
/// `averages` are the non-overlapping m-sample means of the rate (the measured B1 is their sample
/// variance over their Allan variance); `terms` is the estimator's number of terms, the N at
/// which Barnes' B1(N, mu) is evaluated (Stable32 does so: with N = the number of averages the
/// overlapping estimators of Cs5071A would get alpha -1 where Stable32 has 0); `mod_over_allan`
/// the measured ratio Mod AVAR / AVAR at this m (used only when B1 points to PM noise).
pub(crate) fn b1_noise_id(
    averages: &[f64],
    m: usize,
    terms: usize,
    mod_over_allan: impl FnOnce() -> Option<f64>,
) -> Option<i32> {
    let n = averages.len();
    if n < 3 || terms < 2 {
        return None;
    }
    let mean = averages.iter().sum::<f64>() / n as f64;
    let var = averages.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n as f64 - 1.0);
    let avar = averages.windows(2).map(|w| (w[1] - w[0]) * (w[1] - w[0])).sum::<f64>() / (2.0 * (n as f64 - 1.0));
    if avar <= 0.0 || !avar.is_finite() {
        return None;
    }
    let b1 = var / avar;
    let nf = terms as f64;
    // candidate alphas from random-walk FM up to PM; boundaries are geometric means
    let mut alpha = -2;
    for candidate in [-1, 0, 1] {
        let lo = b1_theory(nf, mu_of_alpha(candidate - 1));
        let hi = b1_theory(nf, mu_of_alpha(candidate));
        let boundary = (lo * hi).sqrt();
        if b1 < boundary {
            alpha = candidate;
        } else {
            break;
        }
    }
    if alpha == 1 {
        if let Some(rn) = mod_over_allan() {
            let boundary = (rn_theory(m as f64, 2) * rn_theory(m as f64, 1)).sqrt();
            if rn < boundary {
                alpha = 2;
            }
        }
    }
    Some(alpha)
}

fn greenhall_sw(t: f64, alpha: i32) -> f64 {
    let ln_term = |p: i32| if t == 0.0 { 0.0 } else { t.powi(p) * t.abs().ln() };
    match alpha {
        2 => -t.abs(),
        1 => ln_term(2),
        0 => t.abs().powi(3),
        -1 => ln_term(4),
        -2 => t.abs().powi(5),
        -3 => ln_term(6),
        _ => t.abs().powi(7),
    }
}

/// Greenhall's s_x(t); `f == None` stands for F = infinity.
fn greenhall_sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        None => greenhall_sw(t, alpha + 2),
        Some(f) => {
            f * f * (2.0 * greenhall_sw(t, alpha) - greenhall_sw(t - 1.0 / f, alpha) - greenhall_sw(t + 1.0 / f, alpha))
        }
    }
}

fn greenhall_sz(t: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let sx = |u: f64| greenhall_sx(u, f, alpha);
    match d {
        1 => 2.0 * sx(t) - sx(t - 1.0) - sx(t + 1.0),
        2 => 6.0 * sx(t) - 4.0 * (sx(t - 1.0) + sx(t + 1.0)) + sx(t - 2.0) + sx(t + 2.0),
        _ => {
            20.0 * sx(t) - 15.0 * (sx(t - 1.0) + sx(t + 1.0)) + 6.0 * (sx(t - 2.0) + sx(t + 2.0))
                - sx(t - 3.0)
                - sx(t + 3.0)
        }
    }
}

fn greenhall_basic_sum(j: f64, mm: f64, s: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let first = greenhall_sz(0.0, f, alpha, d).powi(2);
    let second = (1.0 - j / mm) * greenhall_sz(j / s, f, alpha, d).powi(2);
    let third: f64 =
        (1..j as usize).map(|jj| 2.0 * (1.0 - jj as f64 / mm) * greenhall_sz(jj as f64 / s, f, alpha, d).powi(2)).sum();
    first + second + third
}

fn table1(alpha: i32, d: u32) -> (f64, f64) {
    let t: [[(f64, f64); 3]; 7] = [
        [(2.0 / 3.0, 1.0 / 3.0), (7.0 / 9.0, 0.5), (22.0 / 25.0, 2.0 / 3.0)],
        [(0.840, 0.345), (0.997, 0.616), (1.141, 0.843)],
        [(1.079, 0.368), (1.033, 0.607), (1.184, 0.848)],
        [(f64::NAN, f64::NAN), (1.048, 0.534), (1.180, 0.816)],
        [(f64::NAN, f64::NAN), (1.302, 0.535), (1.175, 0.777)],
        [(f64::NAN, f64::NAN), (f64::NAN, f64::NAN), (1.194, 0.703)],
        [(f64::NAN, f64::NAN), (f64::NAN, f64::NAN), (1.489, 0.702)],
    ];
    t[(2 - alpha) as usize][(d - 1) as usize]
}

fn table2(alpha: i32, d: u32) -> (f64, f64) {
    let t: [[(f64, f64); 3]; 7] = [
        [(1.5, 0.5), (35.0 / 18.0, 1.0), (231.0 / 100.0, 1.5)],
        [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
        [(2.0 / 3.0, 1.0 / 6.0), (2.0 / 3.0, 1.0 / 3.0), (7.0 / 9.0, 0.5)],
        [(f64::NAN, f64::NAN), (0.852, 0.375), (0.997, 0.617)],
        [(f64::NAN, f64::NAN), (1.079, 0.368), (1.033, 0.607)],
        [(f64::NAN, f64::NAN), (f64::NAN, f64::NAN), (1.053, 0.553)],
        [(f64::NAN, f64::NAN), (f64::NAN, f64::NAN), (1.302, 0.535)],
    ];
    t[(2 - alpha) as usize][(d - 1) as usize]
}

fn table3(d: u32) -> (f64, f64) {
    [(6.0, 4.0), (15.23, 12.0), (47.8, 40.0)][(d - 1) as usize]
}

fn binomial(n: u32, k: u32) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// Equivalent degrees of freedom by Greenhall & Riley's algorithm.
///
/// `alpha` noise exponent (clamped to the valid range alpha + 2d > 1, alpha <= 2), `d` the
/// difference order (2 Allan, 3 Hadamard), `m` averaging factor, `n_phase` number of phase
/// points, `overlapping` and `modified` select the estimator.
pub(crate) fn edf_greenhall(alpha: i32, d: u32, m: usize, n_phase: usize, overlapping: bool, modified: bool) -> f64 {
    let alpha = alpha.clamp(2 - 2 * d as i32, 2);
    let mf = m as f64;
    let f = if modified { 1.0 } else { mf };
    let s = if overlapping { mf } else { 1.0 };
    let l = mf / f + mf * d as f64;
    let big_m = 1.0 + (s * (n_phase as f64 - l) / mf).floor();
    let j = big_m.min((d as f64 + 1.0) * s);
    let j_max = 100.0;
    let r = big_m / s;
    let inv = if modified {
        if j <= j_max {
            greenhall_basic_sum(j, big_m, s, Some(1.0), alpha, d)
                / (greenhall_sz(0.0, Some(1.0), alpha, d).powi(2) * big_m)
        } else if r > d as f64 + 1.0 {
            let (a0, a1) = table1(alpha, d);
            (a0 - a1 / r) / r
        } else {
            let m_prime = j_max / r;
            greenhall_basic_sum(j_max, j_max, m_prime, Some(1.0), alpha, d)
                / (greenhall_sz(0.0, Some(1.0), alpha, d).powi(2) * j_max)
        }
    } else if alpha <= 0 {
        if j <= j_max {
            let fp = if mf * (d as f64 + 1.0) <= j_max { Some(mf) } else { None };
            greenhall_basic_sum(j, big_m, s, fp, alpha, d) / (greenhall_sz(0.0, fp, alpha, d).powi(2) * big_m)
        } else if r > d as f64 + 1.0 {
            let (a0, a1) = table2(alpha, d);
            (a0 - a1 / r) / r
        } else {
            let m_prime = j_max / r;
            greenhall_basic_sum(j_max, j_max, m_prime, None, alpha, d)
                / (greenhall_sz(0.0, None, alpha, d).powi(2) * j_max)
        }
    } else if alpha == 1 {
        if j <= j_max {
            greenhall_basic_sum(j, big_m, s, Some(mf), 1, d) / (greenhall_sz(0.0, Some(mf), 1, d).powi(2) * big_m)
        } else if r > d as f64 + 1.0 {
            let (a0, a1) = table2(1, d);
            let (b0, b1) = table3(d);
            (a0 - a1 / r) / ((b0 + b1 * mf.ln()).powi(2) * r)
        } else {
            let m_prime = j_max / r;
            let (b0, b1) = table3(d);
            greenhall_basic_sum(j_max, j_max, m_prime, Some(m_prime), 1, d) / ((b0 + b1 * mf.ln()).powi(2) * j_max)
        }
    } else {
        // white PM, unmodified: only lags that are multiples of m correlate; exact finite sum
        let k = r.ceil() as i64;
        let norm = binomial(2 * d, d).powi(2);
        let lmax = (k - 1).min(d as i64);
        let mut sum = 1.0;
        for lag in 1..=lmax {
            sum += 2.0 * (1.0 - lag as f64 / r) * binomial(2 * d, d + lag as u32).powi(2) / norm;
        }
        sum / big_m
    };
    1.0 / inv
}

/// SP1065 simple EDF formulas (table 5, from Stein 1985) for the overlapping Allan variance.
pub(crate) fn edf_simple(n_phase: usize, m: usize, alpha: i32) -> f64 {
    let n = n_phase as f64;
    let m = m as f64;
    match alpha {
        2 => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        1 => {
            let a = (n - 1.0) / (2.0 * m);
            let b = (2.0 * m + 1.0) * (n - 1.0) / 4.0;
            (a.ln() * b.ln()).sqrt().exp()
        }
        0 => (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * (4.0 * m * m / (4.0 * m * m + 5.0)),
        -1 => {
            if m == 1.0 {
                2.0 * (n - 2.0) / (2.3 * n - 4.9)
            } else {
                5.0 * n * n / (4.0 * m * (n + 3.0 * m))
            }
        }
        _ => (n - 2.0) / (m * (n - 3.0).powi(2)) * ((n - 1.0).powi(2) - 3.0 * m * (n - 1.0) + 4.0 * m * m),
    }
}

/// EDF of the total deviation: b T/tau - c (SP1065 table 11) for alpha in {0, -1, -2};
/// other noise types fall back to the simple overlapping-Allan formulas.
pub(crate) fn edf_total(n_phase: usize, m: usize, alpha: i32) -> f64 {
    let ratio = (n_phase - 1) as f64 / m as f64;
    match alpha {
        0 => 1.50 * ratio,
        -1 => 1.17 * ratio - 0.22,
        a if a <= -2 => 0.93 * ratio - 0.36,
        _ => edf_simple(n_phase, m, alpha),
    }
}

/// Bounds (dev_lo, dev_hi) from chi-squared quantiles at confidence c (SP1065 eq. 45).
pub(crate) fn chi2_bounds(dev: f64, edf: f64, confidence: f64) -> Option<(f64, f64)> {
    if !(edf.is_finite() && edf > 0.0) {
        return None;
    }
    if dev == 0.0 {
        return Some((0.0, 0.0));
    }
    let tail = (1.0 - confidence) / 2.0;
    let hi_q = chi_squared_quantile(1.0 - tail, edf)?;
    let lo_q = chi_squared_quantile(tail, edf)?;
    if !(lo_q > 0.0 && hi_q.is_finite()) {
        return None;
    }
    let var = dev * dev;
    let lo = (edf * var / hi_q).sqrt();
    let hi = (edf * var / lo_q).sqrt();
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// The copying reference implementation of [`lag1_noise_id`] (average, detrend, difference).
#[cfg(test)]
fn lag1_noise_id_copy(s: &[f64], m: usize, dmax: usize) -> Option<i32> {
    let z: Vec<f64> = s.iter().step_by(m).copied().collect();
    let mut w: Vec<f64> = z.windows(2).map(|p| (p[1] - p[0]) / m as f64).collect();
    if w.len() < LAG1_MIN_AVERAGES {
        return None;
    }
    detrend_linear(&mut w);
    let dmax = dmax - 1;
    let mut d = 0usize;
    loop {
        let r1 = lag1_acf(&w)?;
        let delta = r1 / (1.0 + r1);
        if delta < 0.25 || d >= dmax {
            return Some(lag1_alpha(delta, d));
        }
        for i in 0..w.len() - 1 {
            w[i] = w[i + 1] - w[i];
        }
        w.pop();
        d += 1;
    }
}

#[cfg(test)]
mod streaming_tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    #[test]
    fn streaming_noise_id_equals_the_copying_one() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let white: Vec<f64> = (0..5000).map(|_| StandardNormal.sample(&mut rng)).collect();
        let mut walk = white.clone();
        for i in 1..walk.len() {
            walk[i] += walk[i - 1];
        }
        let mut walk2 = walk.clone();
        for i in 1..walk2.len() {
            walk2[i] += walk2[i - 1];
        }
        let mut count = 0;
        for series in [&white, &walk, &walk2] {
            for m in [1, 2, 3, 7, 16, 100, 166] {
                for dmax in [2, 3] {
                    assert_eq!(lag1_noise_id(series, m, dmax), lag1_noise_id_copy(series, m, dmax), "m={m}");
                    count += usize::from(lag1_noise_id(series, m, dmax).is_some());
                }
            }
        }
        assert!(count > 30);
        assert_eq!(lag1_noise_id(&[1.0; 100], 1, 2), None);
    }
}
