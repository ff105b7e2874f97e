//! Temperature tests at soaked temperature points (thermal chamber): scale factor K(T), null
//! and bias against temperature, their temperature sensitivities, thermal hysteresis between
//! heating and cooling, and the compensation model applied to outputs.
//!
//! Sources:
//! - IEEE Std 952-1997, annex B and IEEE Std 1431-2004, annex B (model equations: the
//!   temperature-sensitive terms of bias and scale factor, coefficients per degC about a
//!   reference temperature); GJB 2426A-2004 (bias and scale-factor temperature tests at soaked
//!   points; 零偏温度灵敏度, 标度因数温度灵敏度);
//! - least squares by [`crate::fit`] (Householder QR), the standard error of a fitted slope as in
//!   any regression text (Draper & Smith, Applied Regression Analysis, 3rd ed., section 1.4):
//!   se(b) = s / sqrt(sum (T_i - mean T)^2), s^2 = sum r_i^2 / (n - 2).
//!
//! Rules (docs/METHODS.md, "Temperature tests"):
//! - models in the temperature offset x = T - T_ref: y(T) = sum_k c_k x^k, order chosen by the
//!   plan, fitted to the points' values (K_i from each point's rate-table test, the null from each
//!   point's static mean, bias B_i in deg/h);
//! - sensitivities are the least-squares straight-line slope over the points (a coefficient, as
//!   IEEE 952's model defines it): scale factor in ppm/degC relative to K(T_ref) of the line, bias
//!   in (deg/h)/degC; they need at least two distinct temperatures spanning [`MIN_SPAN_C`];
//! - thermal hysteresis: where a temperature was visited both heating and cooling (within
//!   [`SAME_TEMPERATURE_C`]), the largest |value_heating - value_cooling| over such pairs.

use crate::fit::{fit_line, fit_polynomial, FitError};
use serde::{Deserialize, Serialize};

/// Smallest temperature span over which a temperature sensitivity is quoted, degC. Below it the
/// slope is dominated by the noise of the points and by drift (a sensor held at one temperature).
pub const MIN_SPAN_C: f64 = 5.0;

/// Smallest span of a static record's own temperature column over which its within-record bias
/// temperature slope is quoted, degC (a record held near one temperature measures drift, not a
/// temperature coefficient: 0.04 degC of span once gave 1 790 (deg/h)/degC).
pub const MIN_WITHIN_RECORD_SPAN_C: f64 = 1.0;

/// Two points within this many degC are the same temperature (for thermal hysteresis).
pub const SAME_TEMPERATURE_C: f64 = 1.0;

/// How the chamber reached a temperature point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Reached from below (temperature rising).
    Heating,
    /// Reached from above (temperature falling).
    Cooling,
    /// Not stated.
    Unstated,
}

impl Phase {
    /// The plan's word: `heating`, `cooling`, or `unstated`.
    pub fn word(self) -> &'static str {
        match self {
            Phase::Heating => "heating",
            Phase::Cooling => "cooling",
            Phase::Unstated => "unstated",
        }
    }
}

/// A polynomial in the temperature offset: y(T) = sum_k c_k (T - T_ref)^k.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TemperatureModel {
    /// Reference temperature T_ref, degC.
    pub reference_temp_c: f64,
    /// Coefficients c_0..c_n in ascending powers of (T - T_ref) (units: y per degC^k).
    pub coefficients: Vec<f64>,
    /// Lowest temperature of the points it was fitted to, degC.
    pub temp_min_c: f64,
    /// Highest temperature of the points, degC.
    pub temp_max_c: f64,
    /// RMS of the residuals at the points (0 when the model passes through every point).
    pub rms_residual: f64,
    /// Residual degrees of freedom (points minus coefficients).
    pub residual_dof: usize,
}

impl TemperatureModel {
    /// The model's value at `temp_c` (no clamping: see [`TemperatureModel::clamped`]).
    pub fn eval(&self, temp_c: f64) -> f64 {
        let x = temp_c - self.reference_temp_c;
        self.coefficients.iter().rev().fold(0.0, |acc, &c| acc * x + c)
    }

    /// `temp_c` limited to the fitted range, and whether it had to be limited.
    pub fn clamped(&self, temp_c: f64) -> (f64, bool) {
        let t = temp_c.clamp(self.temp_min_c, self.temp_max_c);
        (t, t != temp_c)
    }

    /// Polynomial order.
    pub fn order(&self) -> usize {
        self.coefficients.len().saturating_sub(1)
    }
}

/// Why a temperature figure has no value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "reason")]
pub enum NotResolved {
    /// Fewer points (distinct temperatures) than the figure needs.
    TooFewPoints {
        /// Distinct temperatures found.
        found: usize,
        /// Needed.
        needed: usize,
    },
    /// The points span less than [`MIN_SPAN_C`].
    SpanTooSmall {
        /// Span of the points, degC.
        span_c: f64,
    },
    /// No temperature was visited both heating and cooling.
    NoHeatingCoolingPair,
}

impl NotResolved {
    /// The reason in words.
    pub fn text(&self) -> String {
        match self {
            NotResolved::TooFewPoints { found, needed } => {
                format!("{found} distinct temperature(s), {needed} needed")
            }
            NotResolved::SpanTooSmall { span_c } => {
                format!("the points span {span_c:.3} degC, less than the {MIN_SPAN_C} degC a sensitivity needs")
            }
            NotResolved::NoHeatingCoolingPair => {
                "no temperature was visited both heating and cooling (phase = \"heating\" / \"cooling\")".into()
            }
        }
    }
}

/// A temperature sensitivity: the least-squares slope over the points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sensitivity {
    /// Slope, in the figure's unit per degC.
    pub value: f64,
    /// Standard error of the slope (`None` with only two distinct temperatures).
    pub standard_error: Option<f64>,
    /// Span of the points, degC.
    pub span_c: f64,
    /// The largest single-point figure |y_i - y_ref| / |T_i - T_ref| over the points, with the
    /// reference point the one nearest T_ref (GJB-style worst point), same unit as `value`.
    pub worst_point: Option<f64>,
}

/// Thermal hysteresis: the largest heating-cooling difference at one temperature.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Hysteresis {
    /// |value_heating - value_cooling|, the figure's unit.
    pub value: f64,
    /// Temperature of that pair (mean of the two), degC.
    pub temperature_c: f64,
    /// Pairs compared.
    pub pairs: usize,
}

/// Values at the temperature points, one series (scale factor, null or bias).
#[derive(Debug, Clone, PartialEq)]
pub struct PointSeries<'a> {
    /// Temperatures, degC.
    pub temps_c: &'a [f64],
    /// Phases, one per point.
    pub phases: &'a [Phase],
    /// Values, one per point.
    pub values: &'a [f64],
}

fn distinct(t: &[f64]) -> usize {
    let mut v = t.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    v.len()
}

fn span(t: &[f64]) -> f64 {
    let (lo, hi) = t.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    if lo.is_finite() {
        hi - lo
    } else {
        0.0
    }
}

/// Fits the polynomial model of `order` about `reference_temp_c` (see the module rules).
pub fn fit_model(
    temps_c: &[f64],
    values: &[f64],
    order: usize,
    reference_temp_c: f64,
) -> Result<TemperatureModel, NotResolved> {
    let x: Vec<f64> = temps_c.iter().map(|t| t - reference_temp_c).collect();
    let fit = fit_polynomial(&x, values, order).map_err(|e| match e {
        FitError::TooFewPoints { found, needed, .. } => NotResolved::TooFewPoints { found, needed },
        _ => NotResolved::TooFewPoints { found: distinct(temps_c), needed: order + 1 },
    })?;
    let (lo, hi) = temps_c.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    Ok(TemperatureModel {
        reference_temp_c,
        coefficients: fit.coefficients,
        temp_min_c: lo,
        temp_max_c: hi,
        rms_residual: fit.rms_residual,
        residual_dof: temps_c.len().saturating_sub(order + 1),
    })
}

/// The straight-line temperature sensitivity of `values`, divided by `per` (1 for bias; K at the
/// reference temperature / 1e6 for ppm of the scale factor).
pub fn sensitivity(
    temps_c: &[f64],
    values: &[f64],
    reference_temp_c: f64,
    per: f64,
) -> Result<Sensitivity, NotResolved> {
    let found = distinct(temps_c);
    if found < 2 {
        return Err(NotResolved::TooFewPoints { found, needed: 2 });
    }
    let s = span(temps_c);
    if s < MIN_SPAN_C {
        return Err(NotResolved::SpanTooSmall { span_c: s });
    }
    let line = fit_line(temps_c, values).map_err(|_| NotResolved::TooFewPoints { found, needed: 2 })?;
    let n = temps_c.len();
    let standard_error = (n > 2 && found > 2).then(|| {
        let mt = temps_c.iter().sum::<f64>() / n as f64;
        let sxx: f64 = temps_c.iter().map(|t| (t - mt) * (t - mt)).sum();
        let ss: f64 = temps_c.iter().zip(values).map(|(t, y)| (y - line.eval(*t)).powi(2)).sum();
        (ss / (n - 2) as f64 / sxx).sqrt() / per.abs()
    });
    // Worst single point against the point nearest the reference temperature.
    let r =
        (0..n).min_by(|&a, &b| (temps_c[a] - reference_temp_c).abs().total_cmp(&(temps_c[b] - reference_temp_c).abs()));
    let worst_point = r.and_then(|r| {
        (0..n)
            .filter(|&i| (temps_c[i] - temps_c[r]).abs() >= SAME_TEMPERATURE_C)
            .map(|i| (values[i] - values[r]).abs() / (temps_c[i] - temps_c[r]).abs() / per.abs())
            .max_by(f64::total_cmp)
    });
    Ok(Sensitivity { value: line.slope / per, standard_error, span_c: s, worst_point })
}

/// Thermal hysteresis of a series: heating and cooling points within [`SAME_TEMPERATURE_C`] are
/// paired; the largest |difference| (divided by `per`) over the pairs.
pub fn hysteresis(series: &PointSeries<'_>, per: f64) -> Result<Hysteresis, NotResolved> {
    let mut best: Option<Hysteresis> = None;
    let mut pairs = 0;
    for (i, (&ti, &pi)) in series.temps_c.iter().zip(series.phases).enumerate() {
        if pi != Phase::Heating {
            continue;
        }
        for (j, (&tj, &pj)) in series.temps_c.iter().zip(series.phases).enumerate() {
            if pj != Phase::Cooling || (ti - tj).abs() > SAME_TEMPERATURE_C {
                continue;
            }
            pairs += 1;
            let d = (series.values[i] - series.values[j]).abs() / per.abs();
            if best.is_none_or(|b| d > b.value) {
                best = Some(Hysteresis { value: d, temperature_c: 0.5 * (ti + tj), pairs: 0 });
            }
        }
    }
    best.map(|b| Hysteresis { pairs, ..b }).ok_or(NotResolved::NoHeatingCoolingPair)
}

/// Temperature compensation of one axis's outputs: the output at temperature T is brought to the
/// reference temperature, u_ref = (u - F(T)) K(T_ref) / K(T) + F(T_ref), and then converted by
/// the axis's rate model at the reference temperature. F is the null (zero-rate output) model, K
/// the scale-factor model; T outside the fitted range is limited to it (and counted).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Compensation {
    /// Scale factor K(T), output units per deg/s.
    pub scale_factor: TemperatureModel,
    /// Null F(T), output units.
    pub null: TemperatureModel,
}

/// Why a compensation model cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompensationError {
    /// A coefficient or range is not finite, or the range is reversed.
    #[error("the temperature model needs finite coefficients and a temperature range min <= max")]
    NotFinite,
    /// K(T) is zero or changes sign inside the range.
    #[error("the scale-factor model K(T) reaches zero or changes sign near {temp_c:.2} degC")]
    ScaleFactorCrossesZero {
        /// Where, degC.
        temp_c: f64,
    },
}

impl Compensation {
    /// Checks the models (finite, K(T) of one sign over the range).
    pub fn new(scale_factor: TemperatureModel, null: TemperatureModel) -> Result<Self, CompensationError> {
        for m in [&scale_factor, &null] {
            let ok = m.coefficients.iter().all(|c| c.is_finite())
                && !m.coefficients.is_empty()
                && m.reference_temp_c.is_finite()
                && m.temp_min_c.is_finite()
                && m.temp_max_c.is_finite()
                && m.temp_min_c <= m.temp_max_c;
            if !ok {
                return Err(CompensationError::NotFinite);
            }
        }
        const STEPS: usize = 1000;
        let (lo, hi) = (scale_factor.temp_min_c, scale_factor.temp_max_c);
        let k_ref = scale_factor.eval(scale_factor.reference_temp_c);
        for i in 0..=STEPS {
            let t = lo + (hi - lo) * i as f64 / STEPS as f64;
            let k = scale_factor.eval(t);
            if k == 0.0 || k.signum() != k_ref.signum() || !k.is_finite() {
                return Err(CompensationError::ScaleFactorCrossesZero { temp_c: t });
            }
        }
        Ok(Compensation { scale_factor, null })
    }

    /// The output `u` at `temp_c` brought to the reference temperature, and whether the
    /// temperature lay outside the fitted range (then the range's end is used).
    pub fn to_reference(&self, u: f64, temp_c: f64) -> (f64, bool) {
        let (tk, out_k) = self.scale_factor.clamped(temp_c);
        let (tf, out_f) = self.null.clamped(temp_c);
        let k_ref = self.scale_factor.eval(self.scale_factor.reference_temp_c);
        let f_ref = self.null.eval(self.null.reference_temp_c);
        ((u - self.null.eval(tf)) * k_ref / self.scale_factor.eval(tk) + f_ref, out_k || out_f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn model_through_hand_points() {
        // K = 7.5e-3 (1 + 100e-6 (T - 25)) at -40, 25, 85: a line in x = T - 25 with
        // c0 = 7.5e-3, c1 = 7.5e-7.
        let t = [-40.0, 25.0, 85.0];
        let k: Vec<f64> = t.iter().map(|t| 7.5e-3 * (1.0 + 100e-6 * (t - 25.0))).collect();
        let m = fit_model(&t, &k, 1, 25.0).unwrap();
        assert_relative_eq!(m.coefficients[0], 7.5e-3, max_relative = 1e-12);
        assert_relative_eq!(m.coefficients[1], 7.5e-7, max_relative = 1e-9);
        assert_eq!((m.temp_min_c, m.temp_max_c, m.residual_dof), (-40.0, 85.0, 1));
        assert_relative_eq!(m.eval(60.0), 7.5e-3 * (1.0 + 100e-6 * 35.0), max_relative = 1e-12);
        let s = sensitivity(&t, &k, 25.0, m.coefficients[0] / 1e6).unwrap();
        assert_relative_eq!(s.value, 100.0, max_relative = 1e-9);
        assert!(s.standard_error.unwrap() < 1e-6);
        assert_relative_eq!(s.worst_point.unwrap(), 100.0, max_relative = 1e-9);
        // Quadratic bias: B = 2 + 0.1 x + 0.01 x^2, order 2 through four points.
        let t = [-20.0, 0.0, 25.0, 60.0];
        let b: Vec<f64> = t
            .iter()
            .map(|t| {
                let x = t - 25.0;
                2.0 + 0.1 * x + 0.01 * x * x
            })
            .collect();
        let m = fit_model(&t, &b, 2, 25.0).unwrap();
        for (got, want) in m.coefficients.iter().zip([2.0, 0.1, 0.01]) {
            assert_relative_eq!(*got, want, epsilon = 1e-9);
        }
    }

    #[test]
    fn slope_standard_error_by_hand() {
        // T = 0, 10, 20, 30; y = 1, 3, 4, 8: mean T 15, Sxx = 500, Sxy = (-15)(-3) + (-5)(-1)
        // + 5 (0) + 15 (4) = 110 -> slope 0.22, intercept 4 - 3.3 = 0.7; residuals 0.3, 0.1,
        // -1.1, 0.7 -> SS = 0.09 + 0.01 + 1.21 + 0.49 = 1.8; s^2 = 0.9; se = sqrt(0.9 / 500).
        let s = sensitivity(&[0.0, 10.0, 20.0, 30.0], &[1.0, 3.0, 4.0, 8.0], 0.0, 1.0).unwrap();
        assert_relative_eq!(s.value, 0.22, max_relative = 1e-12);
        assert_relative_eq!(s.standard_error.unwrap(), (0.9f64 / 500.0).sqrt(), max_relative = 1e-12);
        // Worst point against T = 0: |8 - 1| / 30, |4 - 1| / 20, |3 - 1| / 10 -> 0.2333.
        assert_relative_eq!(s.worst_point.unwrap(), 7.0 / 30.0, max_relative = 1e-12);
    }

    #[test]
    fn unsupported_figures_say_why() {
        assert_eq!(
            sensitivity(&[25.0, 25.0], &[1.0, 2.0], 25.0, 1.0),
            Err(NotResolved::TooFewPoints { found: 1, needed: 2 })
        );
        match sensitivity(&[25.0, 25.02, 25.04], &[1.0, 2.0, 3.0], 25.0, 1.0) {
            Err(NotResolved::SpanTooSmall { span_c }) => assert!((span_c - 0.04).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            fit_model(&[0.0, 10.0], &[1.0, 2.0], 2, 0.0),
            Err(NotResolved::TooFewPoints { found: 2, needed: 3 })
        ));
    }

    #[test]
    fn hysteresis_pairs_heating_and_cooling() {
        let t = [-40.0, 25.0, 85.0, 25.3, -40.0];
        let p = [Phase::Heating, Phase::Heating, Phase::Heating, Phase::Cooling, Phase::Cooling];
        let v = [1.0, 2.0, 3.0, 2.5, 0.8];
        let h = hysteresis(&PointSeries { temps_c: &t, phases: &p, values: &v }, 1.0).unwrap();
        assert_relative_eq!(h.value, 0.5, max_relative = 1e-12);
        assert_relative_eq!(h.temperature_c, 25.15, max_relative = 1e-12);
        assert_eq!(h.pairs, 2);
        let p = [Phase::Heating; 5];
        assert_eq!(
            hysteresis(&PointSeries { temps_c: &t, phases: &p, values: &v }, 1.0),
            Err(NotResolved::NoHeatingCoolingPair)
        );
    }

    #[test]
    fn compensation_undoes_a_known_temperature_model() {
        // Output u = F(T) + K(T) w with K(T) = 7.5e-3 (1 + 200e-6 x), F(T) = 2.5 + 1e-4 x,
        // x = T - 25: brought to 25 degC it is 2.5 + 7.5e-3 w for every T in range.
        let model = |c: Vec<f64>| TemperatureModel {
            reference_temp_c: 25.0,
            coefficients: c,
            temp_min_c: -40.0,
            temp_max_c: 85.0,
            rms_residual: 0.0,
            residual_dof: 0,
        };
        let c = Compensation::new(model(vec![7.5e-3, 7.5e-3 * 200e-6]), model(vec![2.5, 1e-4])).unwrap();
        for t in [-40.0, 0.0, 25.0, 70.0, 85.0] {
            for w in [-300.0, -1.0, 0.0, 50.0] {
                let x: f64 = t - 25.0;
                let u = 2.5 + 1e-4 * x + 7.5e-3 * (1.0 + 200e-6 * x) * w;
                let (r, out) = c.to_reference(u, t);
                assert!(!out);
                assert_relative_eq!(r, 2.5 + 7.5e-3 * w, epsilon = 1e-12);
            }
        }
        assert!(c.to_reference(2.5, 100.0).1, "outside the fitted range is counted");
        // A K(T) that crosses zero inside the range is refused.
        assert!(matches!(
            Compensation::new(model(vec![1e-3, 1e-4]), model(vec![0.0])),
            Err(CompensationError::ScaleFactorCrossesZero { .. })
        ));
    }
}
