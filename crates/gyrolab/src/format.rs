//! Number formatting shared by the text reports.

/// Formats a value with `digits` significant digits, without exponent for ordinary magnitudes.
pub fn sig(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-5..=8).contains(&mag) {
        return format!("{:.*e}", digits.saturating_sub(1), v);
    }
    let decimals = (digits as i32 - 1 - mag).max(0) as usize;
    format!("{v:.decimals$}")
}

/// The significant digits of `v` that end at the decimal of the second significant digit of its
/// expanded uncertainty `u` (U stated to two significant digits and the value rounded to match,
/// GUM 7.2.6); at least 1. `None` without a positive finite U or for a zero value.
///
/// ```
/// use gyrolab::format::{digits_to_uncertainty, sig};
/// // 7.21834 with U = 3.2: to 0.1 -> "7.2"; 0.0012345 with U = 0.000051 -> "0.001234" (4 digits).
/// assert_eq!(sig(7.21834, digits_to_uncertainty(7.21834, 3.2).unwrap()), "7.2"); // ok: doctest, valid inputs
/// assert_eq!(digits_to_uncertainty(0.0012345, 0.000051), Some(4));
/// assert_eq!(digits_to_uncertainty(5.0, 0.0), None);
/// ```
pub fn digits_to_uncertainty(v: f64, u: f64) -> Option<usize> {
    if !(v.is_finite() && u.is_finite() && u > 0.0) || v == 0.0 {
        return None;
    }
    let mv = v.abs().log10().floor() as i32;
    let mu = u.log10().floor() as i32;
    Some((mv - mu + 2).max(1) as usize)
}

/// A value and its expanded uncertainty as printed: U rounded to two significant digits and the
/// value rounded to the same decimal, tens and hundreds included (GUM 7.2.6); `None` without a
/// positive finite U or a finite value. Very large or small magnitudes use [`sig`]'s exponent form.
///
/// ```
/// use gyrolab::format::rounded_to_uncertainty;
/// assert_eq!(rounded_to_uncertainty(581.29, 367.6), Some(("580".into(), "370".into())));
/// assert_eq!(rounded_to_uncertainty(7.21834, 3.2), Some(("7.2".into(), "3.2".into())));
/// assert_eq!(rounded_to_uncertainty(0.0075000198, 8.754e-6), Some(("0.0075000".into(), "0.0000088".into())));
/// assert_eq!(rounded_to_uncertainty(1.0, 0.0), None);
/// // U = 0.0996 rounds up to 0.10; a negative value that rounds to zero prints 0.
/// assert_eq!(rounded_to_uncertainty(1.046, 0.0996), Some(("1.05".into(), "0.10".into())));
/// assert_eq!(rounded_to_uncertainty(-0.03, 3.2), Some(("0.0".into(), "3.2".into())));
/// ```
pub fn rounded_to_uncertainty(v: f64, u: f64) -> Option<(String, String)> {
    if !(v.is_finite() && u.is_finite() && u > 0.0) {
        return None;
    }
    let mag = u.log10().floor() as i32;
    // Rounding U may carry into the next decade (9.96 -> 10): take the exponent after rounding.
    let step = 10f64.powi(mag - 1);
    let u_r = (u / step).round() * step;
    let mag = u_r.log10().floor() as i32;
    let step = 10f64.powi(mag - 1);
    if !(-6..=8).contains(&mag) {
        return Some((sig(v, digits_to_uncertainty(v, u_r).unwrap_or(2)), sig(u_r, 2)));
    }
    let decimals = (1 - mag).max(0) as usize;
    // A value that rounds to zero prints 0, not -0.
    let v_r = (v / step).round() * step + 0.0;
    let v_r = if v_r == 0.0 { 0.0 } else { v_r };
    Some((format!("{v_r:.decimals$}"), format!("{u_r:.decimals$}")))
}

/// Formats a value with up to `digits` significant digits, trailing zeros removed.
pub fn short(v: f64, digits: usize) -> String {
    let s = sig(v, digits);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Formats an optional value, `n/a` when absent.
pub fn sig_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "n/a".into(), |x| sig(x, digits))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(7.561_634, 5), "7.5616");
        assert_eq!(sig(0.010_478, 3), "0.0105");
        assert_eq!(sig(2522.6, 3), "2523");
        assert_eq!(sig(1.5e-9, 3), "1.50e-9");
        assert_eq!(sig(0.0, 3), "0");
        assert_eq!(sig_opt(None, 3), "n/a");
        assert_eq!(short(5.000000000000001, 4), "5");
        assert_eq!(short(185.0, 4), "185");
        assert_eq!(short(0.0125, 4), "0.0125");
    }
}
