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
    coverage_probability: Option<Spanned<f64>>,
    output_accuracy_correlation: Option<Spanned<f64>>,
    temperature_accuracy_c: Option<Spanned<f64>>,
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
    /// A coverage probability instead of one k: each budget's k_p = t_p(ν_eff) (GUM G.4); `None`
    /// uses `coverage_factor` for every budget of the report.
    pub coverage_probability: Option<f64>,
    /// Correlation coefficient r of the output-accuracy errors of two readings of one axis by the
    /// same data acquisition at nearly the same level (the static mean and the rate test's zero-rate
    /// output; default 1: the same instrument's offset error, which cancels in their difference).
    pub output_accuracy_correlation: f64,
    /// The chamber's temperature accuracy, degC (rectangular half-width, u = a/√3): a type-B term
    /// of the temperature sensitivities, taken as independent between the soaked points (u of a
    /// slope = |slope| u_T / √S_TT; an offset common to every point does not change a slope).
    pub temperature_accuracy_c: Option<f64>,
}

impl UncertaintyPlan {
    /// How every budget of the report is expanded: one k, or k_p from each ν_eff.
    pub fn coverage(&self) -> gyrolab::uncertainty::Coverage {
        match self.coverage_probability {
            Some(p) => gyrolab::uncertainty::Coverage::Probability(p),
            None => gyrolab::uncertainty::Coverage::Factor(self.coverage_factor),
        }
    }

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
    let coverage_probability = match &raw.coverage_probability {
        Some(p) => {
            let v = *p.get_ref();
            if raw.coverage_factor.is_some() {
                return Err(err(
                    p.span(),
                    "uncertainty.coverage_probability",
                    "give coverage_factor (one k for the whole report) or coverage_probability (k_p = t_p(ν_eff) \
                     per budget), not both"
                        .into(),
                ));
            }
            if !(v.is_finite() && v > 0.5 && v < 1.0) {
                return Err(err(
                    p.span(),
                    "uncertainty.coverage_probability",
                    format!("must be a probability between 0.5 and 1 (0.95 for 95 %), got {v}"),
                ));
            }
            Some(v)
        }
        None => None,
    };
    let output_accuracy_correlation = match &raw.output_accuracy_correlation {
        Some(r) => {
            let v = *r.get_ref();
            if !(v.is_finite() && (-1.0..=1.0).contains(&v)) {
                return Err(err(
                    r.span(),
                    "uncertainty.output_accuracy_correlation",
                    format!("must be a correlation coefficient between -1 and 1, got {v}"),
                ));
            }
            v
        }
        None => 1.0,
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
        coverage_probability,
        output_accuracy_correlation,
        temperature_accuracy_c: non_negative(&raw.temperature_accuracy_c, "uncertainty.temperature_accuracy_c")?,
    })
}
