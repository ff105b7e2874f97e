//! Measurement uncertainty of the calibration figures, stated as an accredited calibration
//! states it: budgets of standard uncertainties, combined and expanded.
//!
//! Sources: JCGM 100:2008 (GUM) = JJF 1059.1-2012: clause 4.2 (type A evaluation), 4.3 (type B
//! evaluation; 4.3.7 rectangular distribution u = a/√3), 5.1.2 (law of propagation of
//! uncertainty for uncorrelated input quantities), 6.2-6.3 (expanded uncertainty U = k u_c),
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
        }
    }
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
    /// Combined standard uncertainty u_c = √(Σ u_i²) (uncorrelated inputs, GUM 5.1.2).
    pub combined: f64,
    /// Coverage factor k (GUM 6.2.1).
    pub coverage_factor: f64,
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
        let combined = combine(&components);
        Budget {
            quantity: quantity.into(),
            value,
            unit: unit.into(),
            components,
            combined,
            coverage_factor: k,
            expanded: k * combined,
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
