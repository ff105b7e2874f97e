//! Spec limits: each limit of a test plan checked against every axis's figures under the plan's
//! decision rule, with the verdict PASS, FAIL, CONDITIONAL or NOT EVALUATED and its reason. The
//! rules, the bounds that decide and the rounding that never contradicts a verdict are those of
//! [`crate::conformity`] (ILAC-G8:09/2019 4.2, JCGM 106:2012 8, ISO/IEC 17025:2017 7.8.6); this
//! module only pairs limits with figures.

use crate::conformity::{consistent_digits, decide};
pub use crate::conformity::{DecisionRule, Known, Overall, Support, Verdict};
use crate::figures::{known_figure, AxisFigures};
use crate::format::{short, sig};
use serde::Serialize;

/// A spec limit on one figure: the value must lie within [min, max] (either bound optional),
/// decided by `rule`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Limit {
    /// Figure key (a JSON key with its unit, e.g. `nonlinearity_pct`).
    pub figure: String,
    /// Lower bound, inclusive.
    pub min: Option<f64>,
    /// Upper bound, inclusive.
    pub max: Option<f64>,
    /// The decision rule.
    pub rule: DecisionRule,
    /// The axes it applies to; `None`: every axis.
    pub axes: Option<Vec<String>>,
}

impl Limit {
    /// A limit on every axis under simple acceptance.
    pub fn new(figure: impl Into<String>, min: Option<f64>, max: Option<f64>) -> Limit {
        Limit { figure: figure.into(), min, max, rule: DecisionRule::SimpleAcceptance, axes: None }
    }

    /// Whether the limit applies to `axis`.
    pub fn applies_to(&self, axis: &str) -> bool {
        self.axes.as_ref().is_none_or(|a| a.iter().any(|x| x == axis))
    }

    /// The limit as text, e.g. `≤ 0.1`, `≥ 7`, `7 … 8` (up to 15 significant digits: the
    /// limit as the plan wrote it).
    pub fn text(&self) -> String {
        match (self.min, self.max) {
            (Some(lo), Some(hi)) => format!("{} … {}", short(lo, 15), short(hi, 15)),
            (Some(lo), None) => format!("≥ {}", short(lo, 15)),
            (None, Some(hi)) => format!("≤ {}", short(hi, 15)),
            (None, None) => "none".into(),
        }
    }

    /// The limit's ends.
    pub fn ends(&self) -> Vec<f64> {
        self.min.into_iter().chain(self.max).collect()
    }

    /// The significant digits at which `value` prints without contradicting its comparison with
    /// this limit ([`consistent_digits`]), at least `min_digits`.
    pub fn digits_for(&self, value: f64, min_digits: usize) -> usize {
        if value.is_finite() {
            consistent_digits(value, &self.ends(), min_digits)
        } else {
            min_digits
        }
    }

    /// Whether a value satisfies the limit (bounds inclusive).
    pub fn admits(&self, value: f64) -> bool {
        value.is_finite() && self.min.is_none_or(|lo| value >= lo) && self.max.is_none_or(|hi| value <= hi)
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
    /// The figure's value or bound, when available.
    pub value: Option<f64>,
    /// What `value` is: `value`, `upper_bound` (the figure is at most it) or `lower_bound` (the
    /// figure is above it); null when the figure is not available.
    pub support: Option<Support>,
    /// The figure's expanded uncertainty U (same unit), when computed.
    pub expanded_uncertainty: Option<f64>,
    /// Lower bound.
    pub min: Option<f64>,
    /// Upper bound.
    pub max: Option<f64>,
    /// The decision rule applied.
    pub rule: DecisionRule,
    /// Guard band w applied (0 for simple acceptance and for bounds; null when no rule could be
    /// applied).
    pub guard_band: Option<f64>,
    /// The verdict.
    pub verdict: Verdict,
    /// Why the verdict is NOT EVALUATED or CONDITIONAL, or how a bound decided.
    pub reason: Option<String>,
}

impl LimitCheck {
    /// The value as printed beside its limit: rounded to its expanded uncertainty (the decimal of
    /// U's second significant digit) when it has one, else at least `min_digits` significant
    /// digits, and as many more as keep the printed value and limit from contradicting the
    /// verdict; a bound printed `at most ..` or `above ..`; `n/a` without a value.
    pub fn value_text(&self, min_digits: usize) -> String {
        let Some(v) = self.value else { return "n/a".into() };
        let n = self.limit().digits_for(v, min_digits);
        // Rounded to U (tens included) where the printed number falls on the same side of the
        // limit as the value; else the digits that keep them apart.
        let estimate = !matches!(self.support, Some(Support::UpperBound | Support::LowerBound));
        if let (Some(u), true) = (self.expanded_uncertainty, estimate) {
            if let Some((text, _)) = crate::format::rounded_to_uncertainty(v, u) {
                let limit = self.limit();
                if text.parse::<f64>().is_ok_and(|p| limit.admits(p) == limit.admits(v)) {
                    return text;
                }
            }
        }
        match self.support {
            Some(Support::UpperBound) => format!("at most {}", sig(v, n)),
            Some(Support::LowerBound) => format!("above {}", sig(v, n)),
            _ => sig(v, n),
        }
    }

    /// The limit checked.
    pub fn limit(&self) -> Limit {
        Limit { figure: self.figure.clone(), min: self.min, max: self.max, rule: self.rule, axes: None }
    }

    /// One line for messages: `axis x: nonlinearity_pct = 0.2 % (limit ≤ 0.1; simple_acceptance)`,
    /// with the reason when there is one.
    pub fn line(&self) -> String {
        let mut s = format!(
            "axis {}: {} = {} {} (limit {}; {})",
            self.axis,
            self.figure,
            self.value_text(4),
            self.unit,
            self.limit().text(),
            self.rule.key()
        );
        if let Some(r) = &self.reason {
            s.push_str(&format!(": {r}"));
        }
        s
    }
}

/// Checks every limit on every axis it applies to (axis order, then limit order) under each
/// limit's rule.
pub fn check_limits(limits: &[Limit], axes: &[AxisFigures]) -> Vec<LimitCheck> {
    let mut out = Vec::new();
    for a in axes {
        for l in limits.iter().filter(|l| l.applies_to(&a.axis)) {
            let known = a.known(&l.figure);
            let d = decide(known.as_ref(), l.min, l.max, l.rule);
            out.push(LimitCheck {
                axis: a.axis.clone(),
                figure: l.figure.clone(),
                unit: a.unit_of(&l.figure),
                value: known.map(|k| k.value),
                support: known.map(|k| k.support),
                expanded_uncertainty: known.and_then(|k| k.expanded_uncertainty),
                min: l.min,
                max: l.max,
                rule: l.rule,
                guard_band: d.guard_band,
                verdict: d.verdict,
                reason: d.reason,
            });
        }
    }
    out
}

/// The overall result ([`crate::conformity::overall`]): FAIL if any check failed, else
/// INCOMPLETE if any is NOT EVALUATED (or there are none), else CONDITIONAL if any is, else PASS.
pub fn overall(checks: &[LimitCheck]) -> Overall {
    crate::conformity::overall(&checks.iter().map(|c| c.verdict).collect::<Vec<_>>())
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
        Limit::new(figure, min, max)
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
        assert_eq!(c[2].reason.as_deref(), Some("the figure is not available"));
        assert_eq!(overall(&c), Overall::Fail);
        // A check not evaluated never counts as passed: two PASS and one NOT EVALUATED is INCOMPLETE.
        assert_eq!(overall(&c[..3]), Overall::Incomplete);
        assert_eq!(overall(&c[..2]), Overall::Pass);
        assert_eq!(overall(&[]), Overall::Incomplete);
    }

    #[test]
    fn bounds_and_uncertainties_reach_the_decision() {
        // The cases: an Allan term known only as "< 8.3 deg/h" against <= 100 passes; a
        // threshold above the largest rate tried (0.5 deg/s) against <= 0.2 fails; bias thermal
        // hysteresis 7.2 +- 6.4 (k = 2) against <= 10 under guarded acceptance is CONDITIONAL.
        let mut a = axis("x", &[("bias_thermal_hysteresis_dph", 7.2)]);
        a.set_bound("bias_instability_dph", 8.3, Support::UpperBound);
        a.set_bound("threshold_dps", 0.5, Support::LowerBound);
        a.set_uncertainty("bias_thermal_hysteresis_dph", 6.4);
        let limits = [
            limit("bias_instability_dph", None, Some(100.0)),
            limit("threshold_dps", None, Some(0.2)),
            Limit { rule: DecisionRule::GuardedAcceptance, ..limit("bias_thermal_hysteresis_dph", None, Some(10.0)) },
            limit("bias_thermal_hysteresis_dph", None, Some(10.0)),
        ];
        let c = check_limits(&limits, &[a]);
        let v: Vec<Verdict> = c.iter().map(|c| c.verdict).collect();
        assert_eq!(v, [Verdict::Pass, Verdict::Fail, Verdict::Conditional, Verdict::Pass]);
        assert_eq!(c[0].value_text(4), "at most 8.300");
        assert_eq!(c[1].value_text(4), "above 0.5000");
        assert_eq!((c[2].guard_band, c[2].expanded_uncertainty), (Some(6.4), Some(6.4)));
        assert_eq!(c[3].guard_band, Some(0.0));
        assert_eq!(overall(&c), Overall::Fail);
        assert_eq!(overall(&c[2..]), Overall::Conditional);
        // The plain value replaces a bound and its uncertainty is kept apart.
        let mut b = axis("y", &[]);
        b.set_bound("threshold_dps", 0.5, Support::LowerBound);
        b.set("threshold_dps", 0.1);
        assert_eq!(b.known("threshold_dps").unwrap().support, Support::Value);
        assert_eq!(b.get("threshold_dps"), Some(0.1));
    }

    #[test]
    fn a_limit_on_named_axes_is_checked_only_there() {
        let axes = [axis("x", &[("threshold_dps", 0.1)]), axis("y", &[])];
        let on_x = Limit { axes: Some(vec!["x".into()]), ..limit("threshold_dps", None, Some(0.2)) };
        let c = check_limits(std::slice::from_ref(&on_x), &axes);
        assert_eq!(c.len(), 1);
        assert_eq!(overall(&c), Overall::Pass);
        // On every axis, y's missing figure makes the result INCOMPLETE.
        let c = check_limits(&[limit("threshold_dps", None, Some(0.2))], &axes);
        assert_eq!(overall(&c), Overall::Incomplete);
    }

    #[test]
    fn printed_values_never_contradict_the_verdict() {
        // The case: 7.499894 against <= 7.49989 fails and must not print as 7.49989.
        let c = check_limits(&[limit("bias_dph", None, Some(7.49989))], &[axis("x", &[("bias_dph", 7.499894)])]);
        assert_eq!(c[0].verdict, Verdict::Fail);
        assert_eq!(c[0].value_text(4), "7.499894");
        assert_eq!(c[0].limit().text(), "≤ 7.49989");
        assert!(
            c[0].line().contains("bias_dph = 7.499894 deg/h (limit ≤ 7.49989; simple_acceptance)"),
            "{}",
            c[0].line()
        );
        // 0.0075004 against <= 0.0075: five digits, not 0.007500.
        let c =
            check_limits(&[limit("scale_factor", None, Some(0.0075))], &[axis("x", &[("scale_factor", 0.0075004)])]);
        assert_eq!(c[0].value_text(4), "0.0075004");
    }

    #[test]
    fn values_with_an_uncertainty_are_rounded_to_it_unless_that_contradicts_the_verdict() {
        let with_u = |v: f64, u: f64| {
            let mut a = axis("x", &[("nonlinearity_pct", v)]);
            a.set_uncertainty("nonlinearity_pct", u);
            a
        };
        // 0.09751 ± 0.015 against <= 0.1: U to two digits is 0.015, the value to 0.001: 0.098.
        let c = check_limits(&[limit("nonlinearity_pct", None, Some(0.1))], &[with_u(0.09751, 0.015)]);
        assert_eq!((c[0].verdict, c[0].value_text(4)), (Verdict::Pass, "0.098".to_string()));
        // 0.09994 ± 0.015 against <= 0.09995 passes, but 0.100 would print above the limit: the
        // digits that keep value and limit apart instead.
        let c = check_limits(&[limit("nonlinearity_pct", None, Some(0.09995))], &[with_u(0.09994, 0.015)]);
        assert_eq!(c[0].verdict, Verdict::Pass);
        assert_eq!(c[0].value_text(4), "0.09994");
        // Tens: 581.29 ± 367.6 prints 580 (U 370).
        let c = check_limits(&[limit("nonlinearity_pct", None, Some(1000.0))], &[with_u(581.29, 367.6)]);
        assert_eq!(c[0].value_text(4), "580");
        // U = 0.0996 rounds up a decade to 0.10: 1.046 prints 1.05, above a limit <= 1.049 it
        // passes, so the digits that keep it below instead.
        let c = check_limits(&[limit("nonlinearity_pct", None, Some(1.049))], &[with_u(1.046, 0.0996)]);
        assert_eq!((c[0].verdict, c[0].value_text(4)), (Verdict::Pass, "1.046".to_string()));
        // |v| far below U: 0.04 ± 1.2 fails [-0.02, 0.02]; "0.0" would sit inside, so not that.
        let c = check_limits(&[limit("nonlinearity_pct", Some(-0.02), Some(0.02))], &[with_u(0.04, 1.2)]);
        assert_eq!(c[0].verdict, Verdict::Fail);
        assert_eq!(c[0].value_text(4), "0.04000");
    }

    #[test]
    fn bounds_are_inclusive_and_texts() {
        let l = limit("linearity_pct", Some(1.0), Some(2.0));
        assert!(l.admits(1.0) && l.admits(2.0) && l.admits(1.5));
        assert!(!l.admits(0.999) && !l.admits(2.001) && !l.admits(f64::NAN));
        assert_eq!(l.text(), "1 … 2");
        assert_eq!(limit("a", None, Some(0.1)).text(), "≤ 0.1");
        assert_eq!(limit("a", Some(-3.0), None).text(), "≥ -3");
        assert_eq!(limit("a", None, Some(7.49989)).text(), "≤ 7.49989");
        assert!(limit("a", Some(-3.0), None).admits(1e9));
        assert_eq!(Verdict::NotEvaluated.text(), "NOT EVALUATED");
        assert_eq!(serde_json::to_string(&Verdict::NotEvaluated).unwrap(), "\"NOT_EVALUATED\"");
        assert!(is_limitable("arw_deg_rt_h") && !is_limitable("arw"));
    }
}
