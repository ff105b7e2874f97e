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
