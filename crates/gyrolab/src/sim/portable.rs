//! Elementary functions built from + - * / only, so that the simulator's set-up values are
//! bit-identical on every IEEE-754 platform (the platform's libm `exp`/`sin` may differ in the last
//! bit between systems). Rust never fuses a multiply and an add unless asked, so each operation
//! below is one correctly rounded IEEE-754 operation.
//!
//! Sources: Cody & Waite argument reduction with the fdlibm split of ln 2 (`e_exp.c`); Taylor
//! series evaluated by Horner's rule.

/// ln 2, high part (its last 11 bits are zero, so `k * LN2_HI` is exact for |k| < 2^11).
const LN2_HI: f64 = 6.931_471_803_691_238e-1;
/// ln 2, low part: ln 2 - LN2_HI.
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;

/// 2^k for an integer k in [-1022, 1023], built from its bit pattern.
fn pow2(k: i64) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// e^x to within about 2 ulp, from + - * / only (portable across platforms).
pub(crate) fn exp(x: f64) -> f64 {
    if x.is_nan() {
        return x;
    }
    if x > 709.7 {
        return f64::INFINITY;
    }
    if x < -745.2 {
        return 0.0;
    }
    // x = k ln2 + r, |r| <= ln2 / 2.
    let k = (x / std::f64::consts::LN_2).round();
    let r = (x - k * LN2_HI) - k * LN2_LO;
    // Taylor series of e^r to r^18 / 18!: truncation error < 1e-23 for |r| <= 0.35.
    let mut sum = 1.0;
    let mut n = 18.0;
    while n >= 1.0 {
        sum = 1.0 + r * sum / n;
        n -= 1.0;
    }
    let k = k as i64;
    // Two steps keep 2^k representable in the subnormal range.
    if k < -1000 {
        sum * pow2(k + 1000) * pow2(-1000)
    } else if k > 1000 {
        sum * pow2(k - 1000) * pow2(1000)
    } else {
        sum * pow2(k)
    }
}

/// sin of an angle in degrees, from + - * / and the exact remainder only (portable).
pub(crate) fn sin_deg(x_deg: f64) -> f64 {
    if !x_deg.is_finite() {
        return f64::NAN;
    }
    // Exact reductions: fmod is exact; 180 - r is exact by Sterbenz' lemma for r in [90, 180].
    let mut r = x_deg % 360.0;
    if r > 180.0 {
        r -= 360.0;
    } else if r < -180.0 {
        r += 360.0;
    }
    if r > 90.0 {
        r = 180.0 - r;
    } else if r < -90.0 {
        r = -180.0 - r;
    }
    let x = r * (std::f64::consts::PI / 180.0);
    let x2 = x * x;
    // Taylor series to x^25 / 25!: truncation error < 1e-20 for |x| <= pi / 2.
    let mut sum = 1.0;
    let mut n = 25.0;
    while n >= 3.0 {
        sum = 1.0 - x2 * sum / (n * (n - 1.0));
        n -= 2.0;
    }
    x * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_matches_libm_closely() {
        for &x in &[-700.0, -50.0, -10.0, -1.0, -1e-3, 0.0, 1e-9, 0.5, 1.0, 3.7, 20.0, 700.0] {
            let (a, b): (f64, f64) = (exp(x), x.exp());
            assert!(((a - b) / b).abs() < 1e-15, "exp({x}) = {a}, libm {b}");
        }
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-1000.0), 0.0);
    }

    #[test]
    fn sin_deg_matches_known_values() {
        assert_eq!(sin_deg(0.0), 0.0);
        assert!((sin_deg(30.0) - 0.5).abs() < 3e-16);
        assert!((sin_deg(90.0) - 1.0).abs() < 3e-16);
        assert!((sin_deg(-90.0) + 1.0).abs() < 3e-16);
        assert!((sin_deg(150.0) - 0.5).abs() < 1e-15);
        assert!((sin_deg(390.0) - 0.5).abs() < 1e-15);
        for i in -400..400 {
            let d = i as f64 * 0.9;
            assert!((sin_deg(d) - d.to_radians().sin()).abs() < 1e-15, "sin({d} deg)");
        }
    }
}
