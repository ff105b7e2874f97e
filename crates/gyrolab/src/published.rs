//! Comparison of computed figures with values printed in a publication, at the printed precision.
//!
//! A printed value with d decimals stands for every number within half a unit of its last digit;
//! a computed value agrees with it when it lies in that interval (a hair of tolerance covers the
//! binary representation of exact halves such as 2.5141515).

use serde::{Deserialize, Serialize};

/// A number as printed, with the count of decimals it was printed with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrintedValue {
    /// The text as printed.
    pub text: String,
    /// Its value.
    pub value: f64,
    /// Decimals after the point.
    pub decimals: usize,
}

impl PrintedValue {
    /// Parses a printed decimal number; `None` when the text is not one.
    pub fn parse(text: &str) -> Option<PrintedValue> {
        let t = text.trim();
        let value: f64 = t.parse().ok()?;
        if !value.is_finite() || t.contains(['e', 'E']) {
            return None;
        }
        let decimals = t.split_once('.').map_or(0, |(_, d)| d.len());
        Some(PrintedValue { text: t.to_string(), value, decimals })
    }

    /// Half a unit of the last printed digit.
    pub fn half_unit(&self) -> f64 {
        0.5 * 10f64.powi(-(self.decimals as i32))
    }

    /// Whether `computed` rounds to this printed value.
    pub fn agrees_with(&self, computed: f64) -> bool {
        let slack = self.half_unit() * (1.0 + 1e-9) + 1e-15 * self.value.abs();
        (computed - self.value).abs() <= slack
    }

    /// The computed value rounded to the printed number of decimals, as text.
    pub fn format_like(&self, computed: f64) -> String {
        format!("{:.*}", self.decimals, computed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agreement_at_printed_precision() {
        let p = PrintedValue::parse("2.514152").unwrap();
        assert_eq!(p.decimals, 6);
        assert!(p.agrees_with(2.5141515)); // an exact half rounds either way
        assert!(p.agrees_with(2.5141524));
        assert!(!p.agrees_with(2.5141526));
        let k = PrintedValue::parse("7.5").unwrap();
        assert!(!k.agrees_with(7.5756));
        assert!(PrintedValue::parse("7.6").unwrap().agrees_with(7.5616));
        assert!(PrintedValue::parse("abc").is_none());
    }
}
