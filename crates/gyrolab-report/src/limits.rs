//! Spec limits: each limit of a test plan checked against every axis's figures, with the
//! verdict PASS, FAIL or NOT EVALUATED (the figure is not available for that axis).

use crate::figures::{known_figure, AxisFigures};
use crate::format::short;
use serde::Serialize;

/// A spec limit on one figure: the value must lie within [min, max] (either bound optional).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Limit {
    /// Figure key (a JSON key with its unit, e.g. `nonlinearity_pct`).
    pub figure: String,
    /// Lower bound, inclusive.
    pub min: Option<f64>,
    /// Upper bound, inclusive.
    pub max: Option<f64>,
}

impl Limit {
    /// The limit as text, e.g. `≤ 0.1`, `≥ 7`, `7 … 8`.
    pub fn text(&self) -> String {
        match (self.min, self.max) {
            (Some(lo), Some(hi)) => format!("{} … {}", short(lo, 6), short(hi, 6)),
            (Some(lo), None) => format!("≥ {}", short(lo, 6)),
            (None, Some(hi)) => format!("≤ {}", short(hi, 6)),
            (None, None) => "none".into(),
        }
    }

    /// Whether a value satisfies the limit (bounds inclusive).
    pub fn admits(&self, value: f64) -> bool {
        value.is_finite() && self.min.is_none_or(|lo| value >= lo) && self.max.is_none_or(|hi| value <= hi)
    }
}

/// Outcome of one limit on one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Verdict {
    /// The value is within the limit.
    Pass,
    /// The value is outside the limit.
    Fail,
    /// The figure is not available for this axis (not measured or not computable).
    NotEvaluated,
}

impl Verdict {
    /// Text shown in reports: `PASS`, `FAIL`, `NOT EVALUATED`.
    pub fn text(self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
            Verdict::NotEvaluated => "NOT EVALUATED",
        }
    }
}

/// One limit checked on one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitCheck {
    /// Axis name.
    pub axis: String,
    /// Figure key.
    pub figure: String,
    /// Unit of the value and the limit.
    pub unit: String,
    /// The figure's value, when available.
    pub value: Option<f64>,
    /// Lower bound.
    pub min: Option<f64>,
    /// Upper bound.
    pub max: Option<f64>,
    /// The verdict.
    pub verdict: Verdict,
}

/// Checks every limit on every axis (axis order, then limit order).
pub fn check_limits(limits: &[Limit], axes: &[AxisFigures]) -> Vec<LimitCheck> {
    let mut out = Vec::new();
    for a in axes {
        for l in limits {
            let value = a.get(&l.figure);
            let verdict = match value {
                None => Verdict::NotEvaluated,
                Some(v) if l.admits(v) => Verdict::Pass,
                Some(_) => Verdict::Fail,
            };
            out.push(LimitCheck {
                axis: a.axis.clone(),
                figure: l.figure.clone(),
                unit: a.unit_of(&l.figure),
                value,
                min: l.min,
                max: l.max,
                verdict,
            });
        }
    }
    out
}

/// Overall verdict: FAIL if any check fails, else PASS if any passed, else NOT EVALUATED.
pub fn overall(checks: &[LimitCheck]) -> Verdict {
    if checks.iter().any(|c| c.verdict == Verdict::Fail) {
        Verdict::Fail
    } else if checks.iter().any(|c| c.verdict == Verdict::Pass) {
        Verdict::Pass
    } else {
        Verdict::NotEvaluated
    }
}

/// Whether the figure name is one a limit may use.
pub fn is_limitable(figure: &str) -> bool {
    known_figure(figure).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(name: &str, values: &[(&str, f64)]) -> AxisFigures {
        let mut a = AxisFigures { axis: name.into(), output_unit: "V".into(), ..Default::default() };
        for (k, v) in values {
            a.set(*k, *v);
        }
        a
    }

    fn limit(figure: &str, min: Option<f64>, max: Option<f64>) -> Limit {
        Limit { figure: figure.into(), min, max }
    }

    #[test]
    fn pass_fail_and_not_evaluated_by_hand() {
        let axes = [
            axis("x", &[("nonlinearity_pct", 0.05), ("scale_factor", 0.0076)]),
            axis("y", &[("nonlinearity_pct", 0.2)]),
        ];
        let limits = [
            limit("nonlinearity_pct", None, Some(0.1)),
            limit("scale_factor", Some(0.007), Some(0.008)),
            limit("bias_stability_dph_10s", None, Some(20.0)),
        ];
        let c = check_limits(&limits, &axes);
        let v: Vec<(&str, &str, Verdict)> = c.iter().map(|c| (c.axis.as_str(), c.figure.as_str(), c.verdict)).collect();
        assert_eq!(
            v,
            [
                ("x", "nonlinearity_pct", Verdict::Pass),
                ("x", "scale_factor", Verdict::Pass),
                ("x", "bias_stability_dph_10s", Verdict::NotEvaluated),
                ("y", "nonlinearity_pct", Verdict::Fail),
                ("y", "scale_factor", Verdict::NotEvaluated),
                ("y", "bias_stability_dph_10s", Verdict::NotEvaluated),
            ]
        );
        assert_eq!(c[1].unit, "V/(deg/s)");
        assert_eq!(c[2].unit, "deg/h");
        assert_eq!(overall(&c), Verdict::Fail);
        assert_eq!(overall(&c[..3]), Verdict::Pass);
        assert_eq!(overall(&c[2..3]), Verdict::NotEvaluated);
        assert_eq!(overall(&[]), Verdict::NotEvaluated);
    }

    #[test]
    fn bounds_are_inclusive_and_texts() {
        let l = limit("linearity_pct", Some(1.0), Some(2.0));
        assert!(l.admits(1.0) && l.admits(2.0) && l.admits(1.5));
        assert!(!l.admits(0.999) && !l.admits(2.001) && !l.admits(f64::NAN));
        assert_eq!(l.text(), "1 … 2");
        assert_eq!(limit("a", None, Some(0.1)).text(), "≤ 0.1");
        assert_eq!(limit("a", Some(-3.0), None).text(), "≥ -3");
        assert!(limit("a", Some(-3.0), None).admits(1e9));
        assert_eq!(Verdict::NotEvaluated.text(), "NOT EVALUATED");
        assert_eq!(serde_json::to_string(&Verdict::NotEvaluated).unwrap(), "\"NOT_EVALUATED\"");
        assert!(is_limitable("arw_deg_rt_h") && !is_limitable("arw"));
    }
}
