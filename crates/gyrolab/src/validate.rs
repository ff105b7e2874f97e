//! Validators of option values: the one place each rule on an option's domain is written.
//!
//! An error names the request *field* (`coverage`, `sample_rate_hz`, ...), never a front end's
//! spelling of it: the command line maps the field to its flag (`--coverage`), a test plan to
//! its key (`options.coverage`), the Python package to its keyword. The message completes the
//! sentence that starts with that name: `"{name} {message}"`.

use thiserror::Error;

/// An option value outside its domain.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{field} {message}")]
pub struct InvalidOption {
    /// The request field, in snake case (`coverage`).
    pub field: &'static str,
    /// The rest of the sentence: `must be a positive number, got -1`.
    pub message: String,
}

impl InvalidOption {
    /// An error on `field` with the rest of the sentence.
    pub fn new(field: &'static str, message: impl Into<String>) -> Self {
        InvalidOption { field, message: message.into() }
    }

    /// The sentence with the field spelled as a front end spells it (`--coverage must ...`).
    pub fn render(&self, name: &str) -> String {
        format!("{name} {}", self.message)
    }
}

/// Result of a validator.
pub type Valid<T> = Result<T, InvalidOption>;

/// Largest magnitude of a numeric option: 1e100. Figures multiply options by data (up to 1e150)
/// and square them; beyond this bound they overflow to infinity. No real option comes near.
pub const MAX_OPTION_MAGNITUDE: f64 = 1e100;

/// Smallest magnitude of a non-zero numeric option: 1e-100 (subnormal or absurdly small values
/// make quotients overflow).
pub const MIN_OPTION_MAGNITUDE: f64 = 1e-100;

/// `Ok(v)` when `v` is zero or its magnitude lies within [`MIN_OPTION_MAGNITUDE`] to
/// [`MAX_OPTION_MAGNITUDE`] (NaN and infinity are left to the caller's own rule).
fn sane_magnitude(field: &'static str, v: f64) -> Valid<f64> {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 || (MIN_OPTION_MAGNITUDE..=MAX_OPTION_MAGNITUDE).contains(&a) {
        Ok(v)
    } else {
        Err(InvalidOption::new(
            field,
            format!(
                "must have a magnitude from {MIN_OPTION_MAGNITUDE:e} to {MAX_OPTION_MAGNITUDE:e} (the figures would \
                 overflow or lose all precision), got {v:e}"
            ),
        ))
    }
}

/// A finite number above zero.
///
/// ```
/// use gyrolab::validate::positive;
/// assert_eq!(positive("coverage", 2.0), Ok(2.0));
/// assert_eq!(positive("coverage", 0.0).unwrap_err().to_string(), "coverage must be a positive number, got 0");
/// ```
pub fn positive(field: &'static str, v: f64) -> Valid<f64> {
    sane_magnitude(field, v)?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must be a positive number, got {v}")))
    }
}

/// A finite number at or above zero.
pub fn non_negative(field: &'static str, v: f64) -> Valid<f64> {
    sane_magnitude(field, v)?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must be a non-negative number, got {v}")))
    }
}

/// A finite, positive percentage.
pub fn positive_percentage(field: &'static str, v: f64) -> Valid<f64> {
    sane_magnitude(field, v)?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must be a positive percentage, got {v}")))
    }
}

/// A latitude in degrees, -90 to 90.
pub fn latitude_deg(field: &'static str, v: f64) -> Valid<f64> {
    if v.is_finite() && v.abs() <= 90.0 {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must be within -90..90 degrees, got {v}")))
    }
}

/// A probability strictly between 0 and 1 (a confidence level).
pub fn confidence(field: &'static str, v: f64) -> Valid<f64> {
    if v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must lie strictly between 0 and 1, got {v}")))
    }
}

/// The order of a polynomial model, 1 to 9.
pub fn polynomial_order(field: &'static str, n: i64) -> Valid<usize> {
    if (1..=9).contains(&n) {
        Ok(n as usize) // ok: 1..=9
    } else {
        Err(InvalidOption::new(field, format!("must be 1 to 9, got {n}")))
    }
}

/// Smoothing (averaging) times: each a positive number of seconds.
pub fn smoothing_times(field: &'static str, times: &[f64]) -> Valid<()> {
    for &t in times {
        sane_magnitude(field, t)?;
    }
    match times.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        Some(t) => Err(InvalidOption::new(field, format!("must be positive seconds, got {t}"))),
        None => Ok(()),
    }
}

/// A scale factor: finite and not zero (its sign is the gyro's sense).
pub fn scale_factor(field: &'static str, v: f64) -> Valid<f64> {
    sane_magnitude(field, v)?;
    if v.is_finite() && v != 0.0 {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must be a non-zero number, got {v}")))
    }
}

/// Any finite number (a null, an offset).
pub fn finite(field: &'static str, v: f64) -> Valid<f64> {
    sane_magnitude(field, v)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(InvalidOption::new(field, format!("must be a number, got {v}")))
    }
}

/// An axis name: it names files in report folders and keys in results, so it must be a plain
/// file name: not empty, at most 64 characters, no `/`, `\`, `:`, control characters, and not
/// `.` or `..`.
///
/// ```
/// use gyrolab::validate::axis_name;
/// assert!(axis_name("axis_names", "x").is_ok());
/// assert!(axis_name("axis_names", "x/y").unwrap_err().message.contains("'/'"));
/// ```
pub fn axis_name<'a>(field: &'static str, name: &'a str) -> Valid<&'a str> {
    let bad = |why: String| Err(InvalidOption::new(field, format!("axis name '{}': {why}", name.escape_debug())));
    if name.trim().is_empty() {
        return bad("empty".into());
    }
    if name.chars().count() > 64 {
        return bad("longer than 64 characters".into());
    }
    if name == "." || name == ".." {
        return bad("not a file name".into());
    }
    if let Some(c) = name.chars().find(|c| matches!(c, '/' | '\\' | ':') || c.is_control()) {
        return bad(format!(
            "'{}' cannot be part of a file name: expected letters, digits, '-' or '_'",
            c.escape_debug()
        ));
    }
    Ok(name)
}

/// A range of two increasing positive values (`LOW,HIGH`).
pub fn increasing_pair(field: &'static str, values: &[f64]) -> Valid<Option<(f64, f64)>> {
    for &t in values {
        sane_magnitude(field, t)?;
    }
    match values {
        [] => Ok(None),
        [a, b] if a.is_finite() && b.is_finite() && *a > 0.0 && b > a => Ok(Some((*a, *b))),
        _ => Err(InvalidOption::new(field, "needs two increasing positive taus in seconds: LOW,HIGH")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_validator_accepts_its_domain_and_names_the_field() {
        assert!(non_negative("settling_s", 0.0).is_ok());
        assert_eq!(non_negative("settling_s", -1.0).unwrap_err().field, "settling_s");
        assert!(latitude_deg("latitude_deg", -90.0).is_ok());
        assert!(latitude_deg("latitude_deg", 90.5).is_err());
        assert!(latitude_deg("latitude_deg", f64::NAN).is_err());
        assert!(confidence("confidence", 0.683).is_ok());
        assert!(confidence("confidence", 1.0).is_err());
        assert_eq!(polynomial_order("order", 3), Ok(3));
        assert!(polynomial_order("order", 0).is_err());
        assert!(polynomial_order("order", 10).is_err());
        assert!(smoothing_times("smoothing_s", &[1.0, 10.0]).is_ok());
        assert!(smoothing_times("smoothing_s", &[1.0, -1.0]).is_err());
        assert!(scale_factor("scale_factor", -0.0075).is_ok());
        assert!(scale_factor("scale_factor", 0.0).is_err());
        assert!(positive_percentage("nonlinearity_limit_pct", f64::INFINITY).is_err());
        assert_eq!(increasing_pair("fit_range_s", &[0.1, 1000.0]), Ok(Some((0.1, 1000.0))));
        assert!(increasing_pair("fit_range_s", &[10.0, 1.0]).is_err());
        assert_eq!(
            positive("sample_rate_hz", -1.0).unwrap_err().render("--sample-rate-hz"),
            "--sample-rate-hz must be a positive number, got -1"
        );
    }

    #[test]
    fn absurd_magnitudes_are_refused_with_the_field() {
        let e = positive("coverage", 1e308).unwrap_err();
        assert_eq!(e.field, "coverage");
        assert!(e.message.contains("magnitude") && e.message.contains("1e308"), "{e}");
        assert!(scale_factor("scale_factor", 1e-320).unwrap_err().message.contains("1e-320"));
        assert!(finite("null", -1e200).is_err());
        assert_eq!(finite("null", 0.0), Ok(0.0));
        assert_eq!(non_negative("x", 0.0), Ok(0.0));
        assert!(smoothing_times("tau", &[1.0, 1e300]).is_err());
        assert!(increasing_pair("fit", &[1e-200, 1.0]).is_err());
        assert_eq!(positive("coverage", 2.0), Ok(2.0));
    }
}
