//! Chi-squared distribution function and quantiles for any degrees of freedom (1 to 1e9 and more).
//!
//! Sources:
//! - chi2(nu) is the gamma distribution with shape a = nu/2 and scale 2, so
//!   P(chi2 <= q) = P(a, q/2), the regularized lower incomplete gamma function (Abramowitz & Stegun
//!   26.4.19).
//! - P(a, x) by its power series, P = x^a e^-x / Gamma(a+1) * sum_n x^n / ((a+1)...(a+n))
//!   (A&S 6.5.29), for x < a + 1; Q(a, x) = 1 - P(a, x) by Legendre's continued fraction
//!   (A&S 6.5.31) evaluated with the modified Lentz method (Numerical Recipes, 3rd ed., 5.2 and 6.2)
//!   for x >= a + 1. The smaller tail is always the one summed, so both tails keep full relative
//!   accuracy.
//! - The common factor x^a e^-x / Gamma(a+1) is formed, for a >= 10, as
//!   exp(a (ln(1+t) - t) - ln(2 pi a)/2 - s(a)) with t = (x - a)/a and s(a) the Stirling series of
//!   ln Gamma(a+1) - (a ln a - a + ln(2 pi a)/2) (A&S 6.1.41); ln(1+t) - t by its atanh series near
//!   t = 0. This is the form Temme (1979) and DiDonato & Morris (ACM TOMS 12, 1986) use for large a:
//!   the naive a ln x - x - ln Gamma(a+1) subtracts numbers of size a ln a and loses about
//!   log10(a ln a) digits (statrs' `gamma_lr`/`ChiSquared::inverse_cdf` fail that way near
//!   dof 3e5 and above). For a < 10, ln Gamma comes from statrs (Lanczos).
//! - Quantile: Wilson & Hilferty (1931) cube-root start, q = nu (1 - 2/(9 nu) + z sqrt(2/(9 nu)))^3,
//!   then safeguarded Newton steps on ln P (lower half) or ln Q (upper half) inside a bracket that
//!   every evaluation narrows.

use statrs::function::erf::erfc_inv;
use statrs::function::gamma::ln_gamma;

/// Shapes below this use statrs' ln Gamma in the prefix; above it the Stirling form.
const STIRLING_MIN_SHAPE: f64 = 10.0;

/// ln(1 + t) - t, accurate to a few ulps for t > -1.
fn log1pmx(t: f64) -> f64 {
    if t.abs() < 0.5 {
        // ln(1+t) = 2 atanh(y), y = t/(2+t); 2y - t = -t^2/(2+t)
        let y = t / (2.0 + t);
        let y2 = y * y;
        let mut power = y * y2;
        let mut series = 0.0;
        let mut k = 3.0;
        while k < 80.0 {
            let term = power / k;
            series += term;
            if term.abs() <= 1e-18 * series.abs() {
                break;
            }
            power *= y2;
            k += 2.0;
        }
        -t * t / (2.0 + t) + 2.0 * series
    } else {
        t.ln_1p() - t
    }
}

/// Stirling series s(a) = ln Gamma(a+1) - (a ln a - a + ln(2 pi a)/2) for a >= 10 (A&S 6.1.41).
fn stirling_correction(a: f64) -> f64 {
    let r = 1.0 / a;
    let r2 = r * r;
    r * (1.0 / 12.0
        + r2 * (-1.0 / 360.0
            + r2 * (1.0 / 1260.0
                + r2 * (-1.0 / 1680.0 + r2 * (1.0 / 1188.0 + r2 * (-691.0 / 360_360.0 + r2 / 156.0))))))
}

/// ln(x^a e^-x / Gamma(a+1)) for a > 0, x > 0.
fn ln_prefix(a: f64, x: f64) -> f64 {
    if a < STIRLING_MIN_SHAPE {
        a * x.ln() - x - ln_gamma(a + 1.0)
    } else {
        let t = (x - a) / a;
        a * log1pmx(t) - 0.5 * (2.0 * std::f64::consts::PI * a).ln() - stirling_correction(a)
    }
}

/// Power series of P(a, x) / prefix (A&S 6.5.29).
fn lower_series(a: f64, x: f64) -> f64 {
    let mut sum = 1.0;
    let mut term = 1.0;
    let mut n = 1.0;
    loop {
        term *= x / (a + n);
        sum += term;
        if term <= f64::EPSILON * 0.25 * sum || n > 1e9 {
            return sum;
        }
        n += 1.0;
    }
}

/// Continued fraction of Q(a, x) / (x^a e^-x / Gamma(a)) (A&S 6.5.31), modified Lentz.
fn upper_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    let mut i = 1.0;
    loop {
        let an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + an / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() <= f64::EPSILON * 0.5 || i > 1e9 {
            return h;
        }
        i += 1.0;
    }
}

/// Regularized incomplete gamma functions (P(a, x), Q(a, x)), the smaller one summed directly.
fn gamma_pq(a: f64, x: f64) -> (f64, f64) {
    if x <= 0.0 {
        return (0.0, 1.0);
    }
    if x.is_infinite() {
        return (1.0, 0.0);
    }
    let pre = ln_prefix(a, x).exp();
    if x < a + 1.0 {
        let p = (pre * lower_series(a, x)).min(1.0);
        (p, 1.0 - p)
    } else {
        let q = (pre * a * upper_fraction(a, x)).min(1.0);
        (1.0 - q, q)
    }
}

/// Gamma density in x: x^(a-1) e^-x / Gamma(a) = prefix * a / x.
fn gamma_density(a: f64, x: f64) -> f64 {
    (ln_prefix(a, x).exp()) * a / x
}

/// Distribution function of chi-squared with `dof` degrees of freedom: (P(chi2 <= q), P(chi2 > q)).
///
/// Both values carry full relative accuracy (about 1e-13 and better), whichever is small.
/// `None` when `dof` is not a positive finite number or `q` is NaN.
pub fn chi_squared_cdf(q: f64, dof: f64) -> Option<(f64, f64)> {
    if !(dof.is_finite() && dof > 0.0) || q.is_nan() {
        return None;
    }
    Some(gamma_pq(0.5 * dof, 0.5 * q))
}

/// Standard normal quantile (start value only).
fn normal_quantile(p: f64) -> f64 {
    -std::f64::consts::SQRT_2 * erfc_inv(2.0 * p)
}

/// Quantile q with P(chi2(dof) <= q) = p, for any dof > 0 (tested from 1 to 1e9) and 0 <= p <= 1.
///
/// p = 0 gives 0, p = 1 infinity. Relative accuracy about 1e-14 (checked against scipy's
/// `chi2.ppf` to 1e-9 by `scripts/check_chi2_scipy.py`, and CDF(quantile(p)) = p to 1e-12 by the
/// unit tests). `None` when `dof` is not a positive finite number or p is outside [0, 1].
///
/// Each (p, dof) is solved once per process and kept (a small table shared by every thread,
/// emptied when full): the same curves ask for the same quantiles again and again (a batch of
/// records of one length, a notebook's repeated calls, the stillness check's windows), and a
/// solve costs microseconds where a look-up costs nanoseconds (issue 56). The kept value is the
/// solved one, bit for bit.
pub fn chi_squared_quantile(p: f64, dof: f64) -> Option<f64> {
    use std::collections::HashMap;
    use std::sync::Mutex;
    /// Most (p, dof) pairs kept.
    const KEPT: usize = 1 << 14;
    /// Solved quantiles by the bits of (p, dof).
    type Table = HashMap<(u64, u64), Option<f64>>;
    static SOLVED: Mutex<Option<Table>> = Mutex::new(None);
    let key = (p.to_bits(), dof.to_bits());
    if let Some(v) = SOLVED.lock().ok().and_then(|t| t.as_ref().and_then(|t| t.get(&key).copied())) {
        return v;
    }
    let v = solve_quantile(p, dof);
    if let Ok(mut table) = SOLVED.lock() {
        let table = table.get_or_insert_with(HashMap::new);
        if table.len() >= KEPT {
            table.clear();
        }
        table.insert(key, v);
    }
    v
}

/// [`chi_squared_quantile`] solved (no table).
fn solve_quantile(p: f64, dof: f64) -> Option<f64> {
    if !(dof.is_finite() && dof > 0.0 && (0.0..=1.0).contains(&p)) {
        return None;
    }
    if p == 0.0 {
        return Some(0.0);
    }
    if p == 1.0 {
        return Some(f64::INFINITY);
    }
    let a = 0.5 * dof;
    // solve in the half whose tail probability is the smaller one
    let lower = p < 0.5;
    let target = if lower { p } else { 1.0 - p };
    let ln_target = target.ln();
    // Wilson-Hilferty start, else the small-x form P ~ x^a / Gamma(a+1)
    let z = normal_quantile(p);
    let h = 2.0 / (9.0 * dof);
    let base = 1.0 - h + z * h.sqrt();
    let mut x = if base > 0.0 { 0.5 * dof * base.powi(3) } else { 0.0 };
    if lower && (a < 1.0 || !(x.is_finite() && x > 0.0)) {
        let small = ((p.ln() + ln_gamma(a + 1.0)) / a).exp();
        if small.is_finite() && small > 0.0 {
            x = small;
        }
    }
    if !(x.is_finite() && x > 0.0) {
        x = a.max(1.0);
    }
    let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
    for _ in 0..400 {
        let (pl, pu) = gamma_pq(a, x);
        let tail = if lower { pl } else { pu };
        // below the root the lower tail is too small and the upper tail too large
        let below = if lower { tail < target } else { tail > target };
        if tail == target {
            return Some(2.0 * x);
        }
        if below {
            lo = lo.max(x);
        } else {
            hi = hi.min(x);
        }
        let density = gamma_density(a, x);
        // Newton on g(x) = ln(tail) - ln(target); g' = +-density / tail
        let slope = if lower { density / tail } else { -density / tail };
        let mut next = x - (tail.ln() - ln_target) / slope;
        if !(next.is_finite() && next > lo && next < hi) {
            next = if hi.is_finite() {
                if lo > 0.0 {
                    (lo * hi).sqrt()
                } else {
                    0.5 * hi
                }
            } else {
                2.0 * x.max(lo)
            };
        }
        if (next - x).abs() <= 2.0 * f64::EPSILON * x || (hi - lo) <= 2.0 * f64::EPSILON * lo {
            return Some(2.0 * next);
        }
        x = next;
    }
    Some(2.0 * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_quantile_is_the_solved_one_bit_for_bit() {
        for &dof in &[1.0, 7.5, 123.25, 59_999.0, 2.5e6] {
            for &p in &[1e-9, 0.1585, 0.5, 0.8415, 1.0 - 1e-9] {
                let solved = solve_quantile(p, dof).map(f64::to_bits);
                // the first call solves and keeps, the second reads the table
                assert_eq!(chi_squared_quantile(p, dof).map(f64::to_bits), solved);
                assert_eq!(chi_squared_quantile(p, dof).map(f64::to_bits), solved);
            }
        }
        assert_eq!(chi_squared_quantile(0.5, -1.0), None);
        assert_eq!(chi_squared_quantile(0.5, -1.0), None);
    }

    const PS: [f64; 7] = [0.0005, 0.025, 0.1587, 0.5, 0.8413, 0.975, 0.9995];
    const DOFS: [f64; 12] = [1.0, 2.0, 3.7, 10.0, 100.0, 1e3, 1e4, 2.709e5, 1e6, 1e7, 1e8, 1e9];

    /// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n; Golub & Welsch would do too).
    fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
                let mut dp = 1.0;
                for _ in 0..100 {
                    let (mut p0, mut p1) = (1.0, x);
                    for k in 2..=n {
                        let k = k as f64;
                        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                        p0 = p1;
                        p1 = p2;
                    }
                    dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                    let dx = p1 / dp;
                    x -= dx;
                    if dx.abs() < 1e-16 {
                        break;
                    }
                }
                (x, 2.0 / ((1.0 - x * x) * dp * dp))
            })
            .collect()
    }

    /// Tail probability of chi2(dof) below (`lower`) or above q by composite Gauss-Legendre
    /// integration of the density: an evaluation independent of the series, the continued fraction
    /// and the solver (it shares only the density's closed form). Shapes a < 10 integrate in
    /// u = sqrt(x) (smooth at 0 for a = 1/2); larger shapes in x itself, so the boundary is q exactly.
    fn tail_by_quadrature(q: f64, dof: f64, lower: bool) -> f64 {
        let a = 0.5 * dof;
        let x0 = 0.5 * q;
        let in_u = a < 10.0;
        let (start, span) = if in_u { (x0.sqrt(), 40.0) } else { (x0, 40.0 * a.sqrt()) };
        let (from, to) = if lower { ((start - span).max(0.0), start) } else { (start, start + span) };
        let nodes = gauss_legendre(20);
        let panels = 800;
        let width = (to - from) / panels as f64;
        let (mut sum, mut carry) = (0.0f64, 0.0f64);
        for k in 0..panels {
            let mid = from + (k as f64 + 0.5) * width;
            for &(t, w) in &nodes {
                let v: f64 = mid + 0.5 * width * t;
                if v <= 0.0 {
                    continue;
                }
                // in u: density of x at u^2 times dx/du = 2u
                let f = if in_u { gamma_density(a, v * v) * 2.0 * v } else { gamma_density(a, v) };
                let y = 0.5 * width * w * f - carry;
                let s = sum + y;
                carry = (s - sum) - y;
                sum = s;
            }
        }
        sum
    }

    #[test]
    fn cdf_of_the_quantile_returns_p() {
        for &dof in &DOFS {
            for &p in &PS {
                let q = chi_squared_quantile(p, dof).unwrap();
                assert!(q.is_finite() && q > 0.0, "dof {dof} p {p}: {q}");
                let (lo, hi) = chi_squared_cdf(q, dof).unwrap();
                let (tail, want) = if p < 0.5 { (lo, p) } else { (hi, 1.0 - p) };
                // A double q cannot do better than one ulp: at dof 1e9 one ulp of q moves the
                // tail by ~1e-11 relative. The tolerance is 1e-12 plus what 2 ulps of q change.
                let ulp_effect = 2.0 * f64::EPSILON * q * 0.5 * gamma_density(0.5 * dof, 0.5 * q) / want;
                let tol = 1e-12 + ulp_effect;
                assert!((tail / want - 1.0).abs() < tol, "dof {dof} p {p}: own CDF {tail} vs {want} (tol {tol:e})");
                let independent = tail_by_quadrature(q, dof, p < 0.5);
                let rel = (independent / want - 1.0).abs();
                assert!(rel < tol, "dof {dof} p {p}: quadrature {independent:e} vs {want:e} ({rel:e}, tol {tol:e})");
            }
        }
    }

    #[test]
    fn prefix_agrees_with_the_plain_formula_where_that_is_accurate() {
        // a ln x - x - ln Gamma(a+1) is accurate to ~1e-15 absolute for small a
        for &a in &[10.0, 12.5, 30.0, 100.0] {
            for &f in &[0.5, 0.9, 1.0, 1.1, 2.0] {
                let x: f64 = a * f;
                let plain = a * x.ln() - x - ln_gamma(a + 1.0);
                let ours = ln_prefix(a, x);
                assert!((plain - ours).abs() < 1e-12 * (1.0 + plain.abs()), "a {a} x {x}: {plain} vs {ours}");
            }
        }
    }

    #[test]
    fn quantiles_increase_with_p() {
        for &dof in &DOFS {
            let mut previous = 0.0;
            for i in 1..200 {
                let p = i as f64 / 200.0;
                let q = chi_squared_quantile(p, dof).unwrap();
                assert!(q > previous, "dof {dof}: q({p}) = {q} <= {previous}");
                previous = q;
            }
        }
    }

    #[test]
    fn large_dof_tends_to_the_normal_limit() {
        // (q - nu) / sqrt(2 nu) -> z with error (z^2 - 1) sqrt(2) / (3 sqrt(nu)) + O(1/nu)
        for &dof in &[1e6, 1e8, 1e9] {
            for &p in &PS {
                let z = normal_quantile(p);
                let q = chi_squared_quantile(p, dof).unwrap();
                let scaled = (q - dof) / (2.0 * dof).sqrt();
                let first = (z * z - 1.0) * std::f64::consts::SQRT_2 / (3.0 * dof.sqrt());
                assert!((scaled - z - first).abs() < 10.0 / dof, "dof {dof} p {p}: {scaled} vs {z} + {first}");
            }
        }
    }

    #[test]
    fn known_small_dof_values() {
        // closed forms: chi2(2) is exponential with mean 2, q = -2 ln(1 - p);
        // chi2(1): q = (z_{(1+p)/2})^2, with z from the median 0.4549364231195724 (p = 1/2).
        for &p in &PS {
            let q = chi_squared_quantile(p, 2.0).unwrap();
            let exact = -2.0 * (-p).ln_1p();
            assert!((q / exact - 1.0).abs() < 1e-14, "p {p}: {q} vs {exact}");
        }
        let median = chi_squared_quantile(0.5, 1.0).unwrap();
        assert!((median / 0.454_936_423_119_572_4 - 1.0).abs() < 1e-14, "{median}");
        assert_eq!(chi_squared_quantile(0.0, 3.0), Some(0.0));
        assert_eq!(chi_squared_quantile(1.0, 3.0), Some(f64::INFINITY));
        assert_eq!(chi_squared_quantile(0.5, 0.0), None);
        assert_eq!(chi_squared_quantile(1.5, 3.0), None);
    }
}
