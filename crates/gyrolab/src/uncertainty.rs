//! Measurement uncertainty of the calibration figures, stated as an accredited calibration
//! states it: budgets of standard uncertainties, combined and expanded.
//!
//! Sources: JCGM 100:2008 (GUM) = JJF 1059.1-2012: clause 4.2 (type A evaluation), 4.3 (type B
//! evaluation; 4.3.7 rectangular distribution u = a/√3), 5.1.2 (law of propagation of
//! uncertainty for uncorrelated input quantities), 5.2.2 (correlated input quantities, eq. 16),
//! 6.2-6.3 (expanded uncertainty U = k u_c), Annex G.4 (effective degrees of freedom by the
//! Welch-Satterthwaite formula, eq. G.2b, and k_p = t_p(ν_eff), ν_eff truncated to an integer),
//! Annex E.4.3 (the standard deviation of an experimental standard deviation ≈ s/√(2(n-1)),
//! normal theory); JJF 1535 for the gyro figures. The standard errors of a least-squares line
//! are the textbook ones (Draper & Smith, Applied Regression Analysis, 3rd ed., section 1.4;
//! GUM Annex H.3). The uncertainty of a mean of correlated noise from the Allan deviation: IEEE
//! Std 952-1997 Annex C (the Allan variance at τ is the variance of τ-averages for white rate
//! noise). Every formula with its units is in docs/METHODS.md, "Measurement uncertainty".

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// How a component's standard uncertainty was evaluated (GUM 4.2 and 4.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum EvaluationType {
    /// Type A: statistical analysis of the data (GUM 4.2).
    #[serde(rename = "A")]
    A,
    /// Type B: other information, here the plan's stated accuracies (GUM 4.3).
    #[serde(rename = "B")]
    B,
}

/// The distribution a type-B accuracy is stated with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Distribution {
    /// The value is the half-width a of a rectangular distribution: u = a/√3 (GUM 4.3.7).
    Rectangular,
    /// The value already is a standard uncertainty (one standard deviation of a normal
    /// distribution): u = value.
    Normal,
}

impl Distribution {
    /// Parses `rectangular` or `normal`.
    pub fn parse(s: &str) -> Option<Distribution> {
        match s.trim() {
            "rectangular" => Some(Distribution::Rectangular),
            "normal" => Some(Distribution::Normal),
            _ => None,
        }
    }

    /// The standard uncertainty of a stated accuracy (GUM 4.3.7 for the rectangular case).
    pub fn standard_uncertainty(self, value: f64) -> f64 {
        match self {
            Distribution::Rectangular => value / 3f64.sqrt(),
            Distribution::Normal => value,
        }
    }
}

/// One line of an uncertainty budget.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Component {
    /// What the input quantity is.
    pub name: String,
    /// Type A or type B.
    pub kind: EvaluationType,
    /// Standard uncertainty u(x_i) of the input quantity, in `unit`.
    pub standard_uncertainty: f64,
    /// Unit of the input quantity's standard uncertainty.
    pub unit: String,
    /// Sensitivity coefficient c_i = ∂y/∂x_i, in (budget unit) / `unit` (GUM 5.1.3).
    pub sensitivity: f64,
    /// Contribution u_i(y) = |c_i| u(x_i), in the budget's unit.
    pub contribution: f64,
    /// Degrees of freedom ν_i of u(x_i) (GUM G.3, G.4.2): n − 1 for a mean or standard deviation
    /// of n values, m − 2 for a straight line through m points, the equivalent degrees of freedom
    /// of an Allan deviation; `None` is infinite (a type-B accuracy taken as exactly known).
    #[serde(default)]
    pub dof: Option<f64>,
}

impl Component {
    /// A component with its contribution |c| u.
    pub fn new(name: impl Into<String>, kind: EvaluationType, u: f64, unit: impl Into<String>, c: f64) -> Self {
        Component {
            name: name.into(),
            kind,
            standard_uncertainty: u,
            unit: unit.into(),
            sensitivity: c,
            contribution: (c * u).abs(),
            dof: None,
        }
    }

    /// The same component with ν_i degrees of freedom (non-finite or non-positive: infinite).
    pub fn with_dof(mut self, dof: f64) -> Self {
        self.dof = (dof.is_finite() && dof > 0.0).then_some(dof);
        self
    }

    /// The signed contribution c_i u(x_i) (the correlated law of propagation needs the sign).
    pub fn signed_contribution(&self) -> f64 {
        self.sensitivity * self.standard_uncertainty
    }
}

/// How a budget's expanded uncertainty is obtained (GUM 6.2-6.3, Annex G).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coverage {
    /// One coverage factor k for every budget (the report's k); the coverage probability it
    /// gives at each budget's ν_eff is stated beside it.
    Factor(f64),
    /// A coverage probability p: each budget's k_p = t_p(ν_eff) (GUM G.4.1, G.3.4).
    Probability(f64),
}

/// A correlation coefficient r(x_i, x_j) between two components of a budget, with the reason it
/// is stated (GUM 5.2.2, 5.2.4: e.g. both read with the same instrument).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Correlation {
    /// Index of the first component.
    pub first: usize,
    /// Index of the second component.
    pub second: usize,
    /// r(x_i, x_j), in [-1, 1].
    pub coefficient: f64,
    /// Why the two inputs are correlated, as the report states it.
    pub reason: String,
}

/// An uncertainty budget of one figure: components, combined standard uncertainty and expanded
/// uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Budget {
    /// The figure (measurand).
    pub quantity: String,
    /// Its value, in `unit`.
    pub value: f64,
    /// Unit of the value, the contributions, combined and expanded uncertainties.
    pub unit: String,
    /// The components.
    pub components: Vec<Component>,
    /// Correlations between components (none: uncorrelated inputs).
    #[serde(default)]
    pub correlations: Vec<Correlation>,
    /// Combined standard uncertainty u_c: √(Σ u_i²) for uncorrelated inputs (GUM 5.1.2), with
    /// the terms 2 Σ c_i c_j u_i u_j r_ij of the correlated ones (GUM 5.2.2, eq. 16).
    pub combined: f64,
    /// Effective degrees of freedom ν_eff = u_c⁴ / Σ (u_i⁴ / ν_i) (Welch-Satterthwaite, GUM
    /// G.4.1 eq. G.2b); `None` is infinite (every component has infinite ν).
    #[serde(default)]
    pub effective_dof: Option<f64>,
    /// Coverage factor k (GUM 6.2.1).
    pub coverage_factor: f64,
    /// Coverage probability p of U = k u_c at ν_eff (Student's t; the normal distribution for
    /// infinite ν_eff).
    #[serde(default)]
    pub coverage_probability: f64,
    /// Expanded uncertainty U = k u_c (GUM 6.2.1).
    pub expanded: f64,
}

impl Budget {
    /// Combines the components as uncorrelated (GUM 5.1.2) and expands with k (GUM 6.2.1).
    pub fn new(
        quantity: impl Into<String>,
        value: f64,
        unit: impl Into<String>,
        components: Vec<Component>,
        k: f64,
    ) -> Self {
        Budget::correlated(quantity, value, unit, components, Vec::new(), Coverage::Factor(k))
    }

    /// Combines the components with their correlations (GUM 5.2.2) and expands them as
    /// `coverage` says: with one k, or with k_p = t_p(ν_eff) (GUM G.4). Correlations naming a
    /// component that does not exist are ignored; coefficients are clamped to [-1, 1].
    pub fn correlated(
        quantity: impl Into<String>,
        value: f64,
        unit: impl Into<String>,
        components: Vec<Component>,
        correlations: Vec<Correlation>,
        coverage: Coverage,
    ) -> Self {
        let correlations: Vec<Correlation> = correlations
            .into_iter()
            .filter(|c| c.first < components.len() && c.second < components.len() && c.first != c.second)
            .map(|c| Correlation { coefficient: c.coefficient.clamp(-1.0, 1.0), ..c })
            .collect();
        let combined = combine_correlated(&components, &correlations);
        let effective_dof = welch_satterthwaite(combined, &components);
        let (coverage_factor, coverage_probability) = match coverage {
            Coverage::Factor(k) => (k, coverage_probability_of(k, effective_dof)),
            Coverage::Probability(p) => (coverage_factor_for(p, effective_dof), p),
        };
        Budget {
            quantity: quantity.into(),
            value,
            unit: unit.into(),
            components,
            correlations,
            combined,
            effective_dof,
            coverage_factor,
            coverage_probability,
            expanded: coverage_factor * combined,
        }
    }

    /// The combined standard uncertainty relative to |value| (ratio); `None` when the value is 0.
    pub fn relative_combined(&self) -> Option<f64> {
        (self.value != 0.0).then(|| self.combined / self.value.abs())
    }

    /// The expanded uncertainty relative to |value| (ratio); `None` when the value is 0.
    pub fn relative_expanded(&self) -> Option<f64> {
        (self.value != 0.0).then(|| self.expanded / self.value.abs())
    }
}

/// Combined standard uncertainty of uncorrelated components: √(Σ (c_i u_i)²) (GUM eq. 10).
pub fn combine(components: &[Component]) -> f64 {
    components.iter().map(|c| c.contribution * c.contribution).sum::<f64>().sqrt()
}

/// Combined standard uncertainty with correlations: u_c² = Σ (c_i u_i)² + 2 Σ_{i<j} c_i u_i c_j
/// u_j r_ij (GUM 5.2.2, eq. 16). A fully correlated pair read with opposite sensitivities cancels.
pub fn combine_correlated(components: &[Component], correlations: &[Correlation]) -> f64 {
    let mut v: f64 = components.iter().map(|c| c.contribution * c.contribution).sum();
    for r in correlations {
        if let (Some(a), Some(b)) = (components.get(r.first), components.get(r.second)) {
            v += 2.0 * a.signed_contribution() * b.signed_contribution() * r.coefficient;
        }
    }
    v.max(0.0).sqrt()
}

/// Effective degrees of freedom ν_eff = u_c⁴ / Σ (u_i⁴ / ν_i) (Welch-Satterthwaite, GUM G.4.1,
/// eq. G.2b); components of infinite ν add nothing to the denominator. `None` (infinite) when
/// every component has infinite ν or u_c is 0.
///
/// ```
/// use gyrolab::uncertainty::{welch_satterthwaite, Component, EvaluationType::A};
/// // GUM G.4.1, example 1: relative uncertainties 0.25 %, 0.57 %, 0.82 % from 10, 5 and 15
/// // observations (ν = 9, 4, 14) combine to 1.03 % with ν_eff = 19.0.
/// let c = [
///     Component::new("x1", A, 0.25, "%", 1.0).with_dof(9.0),
///     Component::new("x2", A, 0.57, "%", 1.0).with_dof(4.0),
///     Component::new("x3", A, 0.82, "%", 1.0).with_dof(14.0),
/// ];
/// let uc = gyrolab::uncertainty::combine(&c);
/// assert!((uc - 1.03).abs() < 0.005);
/// assert!((welch_satterthwaite(uc, &c).unwrap() - 19.0).abs() < 0.05); // ok: doctest, valid inputs
/// ```
pub fn welch_satterthwaite(combined: f64, components: &[Component]) -> Option<f64> {
    let denominator: f64 = components.iter().filter_map(|c| c.dof.map(|nu| c.contribution.powi(4) / nu)).sum();
    (denominator > 0.0 && combined > 0.0).then(|| combined.powi(4) / denominator)
}

/// ν_eff truncated to the next lower integer, at least 1 (GUM G.4.1 b: the conservative choice
/// for a table of t_p).
fn truncated_dof(nu: f64) -> f64 {
    nu.floor().max(1.0)
}

/// Coverage factor k_p = t_p(ν) of a two-sided interval of coverage probability p (Student's t
/// with ν truncated to an integer, GUM G.3.2-G.4.1; the normal quantile for infinite ν).
///
/// ```
/// use gyrolab::uncertainty::coverage_factor_for;
/// // GUM Table G.2: t_95(19) = 2.09 (2.093), t_95.45(∞) = 2.00, t_95(∞) = 1.96.
/// assert!((coverage_factor_for(0.95, Some(19.0)) - 2.093).abs() < 5e-4);
/// assert!((coverage_factor_for(0.9545, None) - 2.0).abs() < 1e-3);
/// assert!((coverage_factor_for(0.95, None) - 1.95996).abs() < 1e-4);
/// ```
pub fn coverage_factor_for(p: f64, effective_dof: Option<f64>) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
    let q = (1.0 + p.clamp(0.0, 1.0 - 1e-15)) / 2.0;
    let t = effective_dof.and_then(|nu| StudentsT::new(0.0, 1.0, truncated_dof(nu)).ok());
    match t {
        Some(t) => t.inverse_cdf(q),
        None => Normal::new(0.0, 1.0).map(|n| n.inverse_cdf(q)).unwrap_or(f64::NAN),
    }
}

/// The coverage probability of U = k u_c at ν_eff: 2 F_t(k; ν) − 1 (the normal distribution for
/// infinite ν). k = 2 gives 95.45 % at infinite ν and 91.95 % at ν = 8.
pub fn coverage_probability_of(k: f64, effective_dof: Option<f64>) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal, StudentsT};
    let cdf = match effective_dof.and_then(|nu| StudentsT::new(0.0, 1.0, truncated_dof(nu)).ok()) {
        Some(t) => t.cdf(k),
        None => Normal::new(0.0, 1.0).map(|n| n.cdf(k)).unwrap_or(f64::NAN),
    };
    2.0 * cdf - 1.0
}

/// Why an uncertainty cannot be stated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UncertaintyError {
    /// A straight line through fewer than three points has no residual degree of freedom.
    #[error("the line has {0} point(s): its standard errors need at least 3 (m - 2 residual degrees of freedom)")]
    TooFewPoints(usize),
    /// The rates do not span anything (all equal).
    #[error("the rates do not vary: no slope")]
    NoSpan,
    /// A value is not finite.
    #[error("a value is not finite")]
    NonFinite,
    /// A record is too short for a supported Allan point at a quarter of its length.
    #[error("no Allan deviation point at or below a quarter of the record")]
    NoAllanPoint,
    /// A sample standard deviation from fewer than two values.
    #[error("fewer than two values: no standard deviation")]
    TooFewValues,
}

/// Standard errors of a least-squares line y = K x + F0 (type A, GUM 4.2 and Annex H.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineUncertainty {
    /// Residual standard deviation s = √(Σ r_j² / (m - 2)), y units.
    pub residual_std: f64,
    /// Standard error of the slope s / √Sxx, y units per x unit.
    pub slope: f64,
    /// Standard error of the intercept s √(1/m + x̄²/Sxx), y units.
    pub intercept: f64,
    /// Covariance of slope and intercept -x̄ s² / Sxx.
    pub covariance: f64,
    /// Residual degrees of freedom m - 2.
    pub dof: usize,
}

/// The standard errors of the least-squares slope and intercept of y on x (the textbook
/// formulas; Draper & Smith section 1.4).
pub fn line_standard_errors(x: &[f64], y: &[f64]) -> Result<LineUncertainty, UncertaintyError> {
    let m = x.len();
    if m != y.len() || m < 3 {
        return Err(UncertaintyError::TooFewPoints(m.min(y.len())));
    }
    if x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(UncertaintyError::NonFinite);
    }
    let mf = m as f64;
    let mx = x.iter().sum::<f64>() / mf;
    let my = y.iter().sum::<f64>() / mf;
    let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
    if sxx <= 0.0 {
        return Err(UncertaintyError::NoSpan);
    }
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let k = sxy / sxx;
    let f0 = my - k * mx;
    let ss: f64 = x.iter().zip(y).map(|(a, b)| (b - (k * a + f0)).powi(2)).sum();
    let s2 = ss / (mf - 2.0);
    Ok(LineUncertainty {
        residual_std: s2.sqrt(),
        slope: (s2 / sxx).sqrt(),
        intercept: (s2 * (1.0 / mf + mx * mx / sxx)).sqrt(),
        covariance: -mx * s2 / sxx,
        dof: m - 2,
    })
}

/// Type-A standard uncertainty of the mean of a record of length `record_s` from the Allan
/// deviation `adev` at the averaging time `tau_s`: u = σ_A(τ) √(τ / T).
///
/// For white rate noise σ_A²(τ) is the variance of a τ-average (IEEE 952 Annex C), so the mean of
/// T/τ such averages has variance σ_A²(τ) τ / T. When the noise is correlated over times shorter
/// than τ the curve falls more slowly than τ^-1/2, and σ_A(τ)√τ grows with τ: the longest
/// supported τ gives the largest, least optimistic value the record supports. Noise correlated
/// over times longer than τ is not seen.
pub fn mean_uncertainty_from_allan(adev: f64, tau_s: f64, record_s: f64) -> Result<f64, UncertaintyError> {
    if !(adev.is_finite() && tau_s.is_finite() && record_s.is_finite()) || tau_s <= 0.0 || record_s <= 0.0 {
        return Err(UncertaintyError::NonFinite);
    }
    Ok(adev * (tau_s / record_s).sqrt())
}

/// The point of an Allan curve used for the uncertainty of a record mean: the longest τ not
/// above a quarter of the record (at least four independent τ-averages). Returns (τ, σ).
pub fn longest_supported_point(taus_s: &[f64], adevs: &[f64], record_s: f64) -> Result<(f64, f64), UncertaintyError> {
    taus_s
        .iter()
        .zip(adevs)
        .filter(|(t, d)| t.is_finite() && d.is_finite() && **t <= record_s / 4.0 * (1.0 + 1e-9))
        .max_by(|a, b| a.0.total_cmp(b.0))
        .map(|(t, d)| (*t, *d))
        .ok_or(UncertaintyError::NoAllanPoint)
}

/// Standard uncertainty of a sample standard deviation s of n values: s / √(2(n - 1)) (normal
/// theory; GUM Annex E.4.3, the approximation of its Table E.1).
pub fn std_of_sample_std(s: f64, n: usize) -> Result<f64, UncertaintyError> {
    if n < 2 {
        return Err(UncertaintyError::TooFewValues);
    }
    if !s.is_finite() {
        return Err(UncertaintyError::NonFinite);
    }
    Ok(s / (2.0 * (n as f64 - 1.0)).sqrt())
}

/// Standard uncertainty of a deviation from its confidence interval [lower, upper] at 68.3 %:
/// the larger of the two one-sided widths (the chi-square interval is asymmetric, wider above;
/// the larger side is used, the conservative choice). `None` when a bound is missing.
pub fn deviation_uncertainty(deviation: f64, lower: Option<f64>, upper: Option<f64>) -> Option<f64> {
    let (lo, hi) = (lower?, upper?);
    let u = (hi - deviation).max(deviation - lo);
    (u.is_finite() && u >= 0.0).then_some(u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution as _, Normal};

    #[test]
    fn rectangular_and_normal_conversions() {
        // a = 30 ppm rectangular: u = 30/sqrt(3) = 17.3205...
        assert_relative_eq!(Distribution::Rectangular.standard_uncertainty(30.0), 30.0 / 3f64.sqrt());
        assert_relative_eq!(Distribution::Rectangular.standard_uncertainty(3.0), 1.7320508075688772, epsilon = 1e-15);
        assert_eq!(Distribution::Normal.standard_uncertainty(7.0), 7.0);
        assert_eq!(Distribution::parse("normal"), Some(Distribution::Normal));
        assert_eq!(Distribution::parse("uniform"), None);
    }

    #[test]
    fn budget_combines_root_sum_square_and_expands() {
        // 3-4-5: contributions |2 * 1.5| = 3 and |-0.5 * 8| = 4 combine to 5; k = 2 gives 10.
        let b = Budget::new(
            "y",
            20.0,
            "u",
            vec![
                Component::new("a", EvaluationType::A, 1.5, "u", 2.0),
                Component::new("b", EvaluationType::B, 8.0, "u", -0.5),
            ],
            2.0,
        );
        assert_relative_eq!(b.components[0].contribution, 3.0);
        assert_relative_eq!(b.components[1].contribution, 4.0);
        assert_relative_eq!(b.combined, 5.0);
        assert_relative_eq!(b.expanded, 10.0);
        assert_relative_eq!(b.relative_expanded().unwrap(), 0.5);
    }

    #[test]
    fn welch_satterthwaite_on_the_gum_example() {
        // JCGM 100:2008 G.4.1, example 1: u_i/x_i = 0.25, 0.57, 0.82 % from n = 10, 5, 15
        // observations: u_c/y = 1.03 %, ν_eff = 1.03⁴ / (0.25⁴/9 + 0.57⁴/4 + 0.82⁴/14) = 19.0,
        // t_95(19) = 2.09, U_95 = 2.2 %. scipy: ν_eff = 18.99874, t.ppf(0.975, 19) = 2.0930240.
        let c = vec![
            Component::new("x1", EvaluationType::A, 0.25, "%", 1.0).with_dof(9.0),
            Component::new("x2", EvaluationType::A, 0.57, "%", 1.0).with_dof(4.0),
            Component::new("x3", EvaluationType::A, 0.82, "%", 1.0).with_dof(14.0),
        ];
        let b = Budget::correlated("y", 100.0, "%", c, Vec::new(), Coverage::Probability(0.95));
        assert_relative_eq!(b.combined, 1.0294658809304948, max_relative = 1e-12);
        assert_relative_eq!(b.effective_dof.unwrap(), 18.998742314267954, max_relative = 1e-9);
        // ν_eff truncated to 18 (GUM G.4.1 b): t_95(18) = 2.100922 (scipy), U = 2.16 %.
        assert_relative_eq!(b.coverage_factor, 2.1009220402410382, max_relative = 1e-7);
        assert!((b.expanded - 2.2).abs() < 0.05);
        // With one k = 2 for the report the stated probability follows ν_eff: scipy
        // 2 t.cdf(2, 18) − 1 = 0.9391785.
        let fixed = Budget::new("y", 100.0, "%", b.components.clone(), 2.0);
        assert_relative_eq!(fixed.coverage_probability, 0.9391785343306676, max_relative = 1e-7);
        // Infinite ν everywhere: the normal distribution (95.45 % for k = 2).
        let b = Budget::new("y", 1.0, "u", vec![Component::new("b", EvaluationType::B, 1.0, "u", 1.0)], 2.0);
        assert_eq!(b.effective_dof, None);
        assert_relative_eq!(b.coverage_probability, 0.9544997361036416, max_relative = 1e-9);
        // t_p(ν) against scipy: t.ppf(0.975, 4) = 2.7764451; 2 t.cdf(2, 8) − 1 = 0.9194838.
        assert_relative_eq!(coverage_factor_for(0.95, Some(4.7)), 2.7764451051977934, max_relative = 1e-7);
        assert_relative_eq!(coverage_probability_of(2.0, Some(8.0)), 0.9194837620427374, max_relative = 1e-7);
    }

    #[test]
    fn correlated_readings_of_one_instrument_cancel_to_the_stated_degree() {
        // y = x1 − x2, both read by one instrument with u = 3 (the same offset error): r = 1
        // cancels it; r = 0 adds in quadrature (3√2); r = 0.5 gives √(9 + 9 − 9) = 3.
        let c = || {
            vec![
                Component::new("reading 1", EvaluationType::B, 3.0, "V", 1.0),
                Component::new("reading 2", EvaluationType::B, 3.0, "V", -1.0),
                Component::new("scatter", EvaluationType::A, 4.0, "V", 1.0).with_dof(10.0),
            ]
        };
        let r =
            |coefficient: f64| vec![Correlation { first: 0, second: 1, coefficient, reason: "same instrument".into() }];
        let full = Budget::correlated("y", 0.0, "V", c(), r(1.0), Coverage::Factor(2.0));
        assert_relative_eq!(full.combined, 4.0, max_relative = 1e-12);
        let none = Budget::correlated("y", 0.0, "V", c(), r(0.0), Coverage::Factor(2.0));
        assert_relative_eq!(none.combined, (16.0f64 + 18.0).sqrt(), max_relative = 1e-12);
        let half = Budget::correlated("y", 0.0, "V", c(), r(0.5), Coverage::Factor(2.0));
        assert_relative_eq!(half.combined, 5.0, max_relative = 1e-12);
        // Same sign: a correlated pair adds linearly (3 + 3 = 6 with r = 1).
        let mut same = c();
        same[1].sensitivity = 1.0;
        let b = Budget::correlated("y", 0.0, "V", same, r(1.0), Coverage::Factor(2.0));
        assert_relative_eq!(b.combined, (36.0f64 + 16.0).sqrt(), max_relative = 1e-12);
        // ν_eff only from the type-A scatter: u_c⁴ / (4⁴/10) with u_c = 4 gives 10.
        assert_relative_eq!(full.effective_dof.unwrap(), 10.0, max_relative = 1e-12);
    }

    #[test]
    fn line_standard_errors_by_hand() {
        // x = 0, 1, 2, 3; y = 1, 3, 4, 8: x̄ = 1.5, Sxx = 5, ȳ = 4, Sxy = (-1.5)(-3) + (-0.5)(-1)
        // + 0.5*0 + 1.5*4 = 11, K = 2.2, F0 = 4 - 3.3 = 0.7; residuals 0.3, 0.1, -1.1, 0.7,
        // SS = 0.09 + 0.01 + 1.21 + 0.49 = 1.8, s² = 0.9.
        let u = line_standard_errors(&[0.0, 1.0, 2.0, 3.0], &[1.0, 3.0, 4.0, 8.0]).unwrap();
        assert_relative_eq!(u.residual_std, 0.9f64.sqrt(), max_relative = 1e-12);
        assert_relative_eq!(u.slope, (0.9f64 / 5.0).sqrt(), max_relative = 1e-12);
        assert_relative_eq!(u.intercept, (0.9f64 * (0.25 + 2.25 / 5.0)).sqrt(), max_relative = 1e-12);
        assert_relative_eq!(u.covariance, -1.5 * 0.9 / 5.0, max_relative = 1e-12);
        assert_eq!(u.dof, 2);
        assert_eq!(line_standard_errors(&[0.0, 1.0], &[1.0, 2.0]), Err(UncertaintyError::TooFewPoints(2)));
        assert_eq!(line_standard_errors(&[1.0; 3], &[1.0, 2.0, 3.0]), Err(UncertaintyError::NoSpan));
    }

    #[test]
    fn slope_standard_error_matches_scatter_of_simulated_rate_tables() {
        // 11 rates, K = 0.01 V/(deg/s), point means with white noise of 2 mV: the std of K over
        // 400 simulated tables is the truth the stated u_A(K) must match (within 20 %).
        let rates: Vec<f64> = (-5..=5).map(|i| 60.0 * i as f64).collect();
        let noise = Normal::new(0.0, 2e-3).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(19);
        let (mut ks, mut us) = (Vec::new(), Vec::new());
        for _ in 0..400 {
            let y: Vec<f64> = rates.iter().map(|w| 0.01 * w + 2.5 + noise.sample(&mut rng)).collect();
            ks.push(crate::fit::fit_line(&rates, &y).unwrap().slope);
            us.push(line_standard_errors(&rates, &y).unwrap().slope);
        }
        let scatter = crate::fit::sample_std(&ks).unwrap();
        let stated = crate::fit::mean(&us).unwrap();
        assert!((scatter / stated - 1.0).abs() < 0.2, "std of K {scatter} vs mean u_A(K) {stated}");
        // And the truth of the textbook formula: sigma / sqrt(Sxx).
        let sxx: f64 = rates.iter().map(|w| w * w).sum();
        assert!((stated / (2e-3 / sxx.sqrt()) - 1.0).abs() < 0.1);
    }

    /// A record of white noise plus a first-order Gauss-Markov process (correlation time
    /// `corr` samples): correlated noise on which s/√n is too optimistic.
    fn correlated_record(rng: &mut ChaCha8Rng, n: usize, corr: f64) -> Vec<f64> {
        let white = Normal::new(0.0, 1.0).unwrap();
        let phi = (-1.0 / corr).exp();
        let drive = (1.0 - phi * phi).sqrt() * 2.0; // stationary std 2
        let mut g = 0.0;
        (0..n)
            .map(|_| {
                g = phi * g + drive * white.sample(rng);
                g + white.sample(rng)
            })
            .collect()
    }

    #[test]
    fn mean_uncertainty_from_allan_matches_scatter_of_simulated_means() {
        use crate::allan::{deviation_from_rate_slice, AllanOptions, DeviationKind};
        let (n, corr) = (20_000usize, 25.0);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut means, mut stated, mut naive) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..60 {
            let x = correlated_record(&mut rng, n, corr);
            means.push(crate::fit::mean(&x).unwrap());
            let curve = deviation_from_rate_slice(&x, 1.0, &AllanOptions::new(DeviationKind::Oadev)).unwrap();
            let taus: Vec<f64> = curve.points.iter().map(|p| p.tau_s).collect();
            let devs: Vec<f64> = curve.points.iter().map(|p| p.deviation).collect();
            let (tau, dev) = longest_supported_point(&taus, &devs, n as f64).unwrap();
            assert!(tau <= n as f64 / 4.0);
            stated.push(mean_uncertainty_from_allan(dev, tau, n as f64).unwrap());
            naive.push(crate::fit::sample_std(&x).unwrap() / (n as f64).sqrt());
        }
        // Truth: the std of the record mean over seeds; analytically, the mean's variance is
        // 1/n + 4 (1+phi)/(1-phi) / n (white plus Gauss-Markov, long record).
        let scatter = crate::fit::sample_std(&means).unwrap();
        let phi = (-1.0f64 / corr).exp();
        let truth = ((1.0 + 4.0 * (1.0 + phi) / (1.0 - phi)) / n as f64).sqrt();
        assert!((scatter / truth - 1.0).abs() < 0.25, "simulation {scatter} vs analytic {truth}");
        let u = crate::fit::mean(&stated).unwrap();
        assert!((u / truth - 1.0).abs() < 0.2, "stated {u} vs truth {truth}");
        // The naive s/sqrt(n) is far too small on this correlated noise.
        assert!(crate::fit::mean(&naive).unwrap() < 0.5 * truth);
    }

    #[test]
    fn std_of_sample_std_by_hand() {
        // s = 0.6 from n = 9 values: 0.6 / sqrt(16) = 0.15.
        assert_relative_eq!(std_of_sample_std(0.6, 9).unwrap(), 0.15);
        assert_eq!(std_of_sample_std(0.6, 1), Err(UncertaintyError::TooFewValues));
    }

    #[test]
    fn std_of_sample_std_matches_simulation() {
        // n = 11 normal values of sigma 1: the std of s over many sets is about 1/sqrt(20).
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let white = Normal::new(0.0, 1.0).unwrap();
        let s: Vec<f64> = (0..3000)
            .map(|_| crate::fit::sample_std(&(0..11).map(|_| white.sample(&mut rng)).collect::<Vec<_>>()).unwrap())
            .collect();
        let scatter = crate::fit::sample_std(&s).unwrap();
        let stated = std_of_sample_std(crate::fit::mean(&s).unwrap(), 11).unwrap();
        assert!((scatter / stated - 1.0).abs() < 0.1, "{scatter} vs {stated}");
    }

    #[test]
    fn deviation_uncertainty_uses_the_wider_side() {
        // 1.0 within [0.8, 1.3]: sides 0.2 and 0.3, the wider 0.3.
        assert_relative_eq!(deviation_uncertainty(1.0, Some(0.8), Some(1.3)).unwrap(), 0.3, epsilon = 1e-15);
        assert_eq!(deviation_uncertainty(1.0, None, Some(1.3)), None);
    }

    #[test]
    fn longest_point_at_most_a_quarter() {
        let (t, d) = longest_supported_point(&[1.0, 2.0, 4.0, 8.0], &[4.0, 3.0, 2.0, 1.0], 20.0).unwrap();
        assert_eq!((t, d), (4.0, 2.0));
        assert_relative_eq!(mean_uncertainty_from_allan(2.0, 4.0, 16.0).unwrap(), 1.0);
        assert!(longest_supported_point(&[8.0], &[1.0], 20.0).is_err());
    }
}
