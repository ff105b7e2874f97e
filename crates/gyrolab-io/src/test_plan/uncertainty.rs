//! The `[uncertainty]` table of a test plan: the coverage factor and the type-B inputs of the
//! measurement-uncertainty budgets (docs/PLAN.md, "Measurement uncertainty"). Errors name the
//! key and its line.

use crate::DataError;
use gyrolab::uncertainty::Distribution;
use serde::Deserialize;
use toml::Spanned;

/// The `[uncertainty]` table as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawUncertainty {
    coverage_factor: Option<Spanned<f64>>,
    rate_accuracy_ppm: Option<Spanned<f64>>,
    rate_accuracy_distribution: Option<Spanned<String>>,
    output_accuracy: Option<Spanned<f64>>,
    output_accuracy_distribution: Option<Spanned<String>>,
}

/// The checked `[uncertainty]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct UncertaintyPlan {
    /// Coverage factor k of the expanded uncertainties (default 2).
    pub coverage_factor: f64,
    /// The rate table's rate accuracy, relative, ppm, when stated.
    pub rate_accuracy_ppm: Option<f64>,
    /// How `rate_accuracy_ppm` is stated (default rectangular half-width).
    pub rate_accuracy_distribution: Distribution,
    /// The data acquisition's output accuracy, in each axis's output unit, when stated.
    pub output_accuracy: Option<f64>,
    /// How `output_accuracy` is stated (default rectangular half-width).
    pub output_accuracy_distribution: Distribution,
}

impl UncertaintyPlan {
    /// Standard uncertainty of the table rate, relative (ratio), when stated.
    pub fn rate_standard_uncertainty_rel(&self) -> Option<f64> {
        self.rate_accuracy_ppm
            .map(|a| gyrolab::units::ppm_to_ratio(self.rate_accuracy_distribution.standard_uncertainty(a)))
    }

    /// Standard uncertainty of an output reading, output units, when stated.
    pub fn output_standard_uncertainty(&self) -> Option<f64> {
        self.output_accuracy.map(|a| self.output_accuracy_distribution.standard_uncertainty(a))
    }
}

/// Checks the raw table; `err(span, key, message)` builds an error located at the key's line.
pub(crate) fn parse_uncertainty(
    raw: &RawUncertainty,
    err: &dyn Fn(std::ops::Range<usize>, &str, String) -> DataError,
) -> Result<UncertaintyPlan, DataError> {
    let coverage_factor = match &raw.coverage_factor {
        Some(k) => {
            let v = *k.get_ref();
            if !(v.is_finite() && v > 0.0) {
                return Err(err(
                    k.span(),
                    "uncertainty.coverage_factor",
                    format!("must be a positive number (2 for about 95 % coverage), got {v}"),
                ));
            }
            v
        }
        None => 2.0,
    };
    let non_negative = |v: &Option<Spanned<f64>>, key: &str| -> Result<Option<f64>, DataError> {
        match v {
            Some(a) if !(a.get_ref().is_finite() && *a.get_ref() >= 0.0) => {
                Err(err(a.span(), key, format!("must be a non-negative number (an accuracy), got {}", a.get_ref())))
            }
            Some(a) => Ok(Some(*a.get_ref())),
            None => Ok(None),
        }
    };
    let distribution = |v: &Option<Spanned<String>>, key: &str| -> Result<Distribution, DataError> {
        match v {
            Some(s) => Distribution::parse(s.get_ref()).ok_or_else(|| {
                err(
                    s.span(),
                    key,
                    format!(
                        "unknown distribution '{}': expected \"rectangular\" (the value is a half-width a, u = a/√3) \
                         or \"normal\" (the value is a standard uncertainty)",
                        s.get_ref()
                    ),
                )
            }),
            None => Ok(Distribution::Rectangular),
        }
    };
    Ok(UncertaintyPlan {
        coverage_factor,
        rate_accuracy_ppm: non_negative(&raw.rate_accuracy_ppm, "uncertainty.rate_accuracy_ppm")?,
        rate_accuracy_distribution: distribution(
            &raw.rate_accuracy_distribution,
            "uncertainty.rate_accuracy_distribution",
        )?,
        output_accuracy: non_negative(&raw.output_accuracy, "uncertainty.output_accuracy")?,
        output_accuracy_distribution: distribution(
            &raw.output_accuracy_distribution,
            "uncertainty.output_accuracy_distribution",
        )?,
    })
}
