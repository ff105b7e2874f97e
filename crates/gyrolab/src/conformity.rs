//! Statements of conformity to a specification limit: decision rules, guard bands, verdicts, and
//! the rounding of printed values so that they never contradict the verdict.
//!
//! Sources:
//! - ILAC-G8:09/2019 "Guidelines on Decision Rules and Statements of Conformity", 4.2.1 (simple
//!   acceptance, w = 0), 4.2.2 (guarded acceptance, acceptance limit AL = TL − w), 4.2.3
//!   (non-binary statements: conditional pass / conditional fail inside the guard band), 4.2.4
//!   (guarded rejection, AL = TL + w); the guard band w = U, the expanded uncertainty (k = 2).
//! - JCGM 106:2012 "The role of measurement uncertainty in conformity assessment", 8.2 (guarded
//!   acceptance), 8.3 (guarded rejection), 8.3.2 (w = U).
//! - ISO/IEC 17025:2017 7.8.6 (the decision rule is stated with the statement of conformity),
//!   7.1.3 (the rule is agreed with the customer: the test plan states it).
//! - JCGM 100:2008 (GUM) 7.2.6 (U to at most two significant digits, the value to the same
//!   decimal place).
//!
//! A figure may be known only as a bound (a threshold "above the largest rate tried", an Allan
//! term "at most" its value where the curve does not resolve it): a bound decides where it can
//! (an upper bound under an upper limit passes; a lower bound over an upper limit fails) and the
//! verdict is NOT EVALUATED, with the reason, where it cannot.

use serde::Serialize;

/// How a figure is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    /// An estimate of the value.
    Value,
    /// The true value is at most this (`x ≤ b`).
    UpperBound,
    /// The true value is above this (`x > b`).
    LowerBound,
}

impl Support {
    /// The JSON spelling (`value`, `upper_bound`, `lower_bound`).
    pub fn key(self) -> &'static str {
        match self {
            Support::Value => "value",
            Support::UpperBound => "upper_bound",
            Support::LowerBound => "lower_bound",
        }
    }
}

/// A decision rule (ILAC-G8:09/2019 4.2, JCGM 106:2012 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DecisionRule {
    /// Simple acceptance (ILAC-G8 4.2.1, w = 0): PASS inside the limit, FAIL outside, the
    /// uncertainty not taken into account beyond being stated.
    #[default]
    SimpleAcceptance,
    /// Guarded acceptance (ILAC-G8 4.2.2/4.2.3, JCGM 106 8.2): PASS only when the value is inside
    /// the limit by more than w = U; CONDITIONAL (conditional pass) within w inside the limit;
    /// FAIL outside the limit.
    GuardedAcceptance,
    /// Guarded rejection (ILAC-G8 4.2.3/4.2.4, JCGM 106 8.3): FAIL only when the value is outside
    /// the limit by more than w = U; CONDITIONAL (conditional fail) within w outside the limit;
    /// PASS inside the limit.
    GuardedRejection,
}

impl DecisionRule {
    /// Every rule, in the order of [`DecisionRule::key`].
    pub const ALL: [DecisionRule; 3] =
        [DecisionRule::SimpleAcceptance, DecisionRule::GuardedAcceptance, DecisionRule::GuardedRejection];

    /// The plan and JSON spelling: `simple_acceptance`, `guarded_acceptance`, `guarded_rejection`.
    pub fn key(self) -> &'static str {
        match self {
            DecisionRule::SimpleAcceptance => "simple_acceptance",
            DecisionRule::GuardedAcceptance => "guarded_acceptance",
            DecisionRule::GuardedRejection => "guarded_rejection",
        }
    }

    /// The rule from its plan spelling.
    pub fn parse(s: &str) -> Option<DecisionRule> {
        DecisionRule::ALL.into_iter().find(|r| r.key() == s)
    }

    /// The rule as the report states it, with its source.
    pub fn statement(self) -> &'static str {
        match self {
            DecisionRule::SimpleAcceptance => {
                "simple acceptance (ILAC-G8:09/2019 4.2.1, guard band w = 0): PASS when the measured value \
                 is within the limit, FAIL otherwise; the expanded uncertainty is stated but not subtracted"
            }
            DecisionRule::GuardedAcceptance => {
                "guarded acceptance (ILAC-G8:09/2019 4.2.2 and 4.2.3, JCGM 106:2012 8.2, guard band w = U): \
                 PASS when the value is inside the limit by more than U, CONDITIONAL (conditional pass) \
                 within U inside the limit, FAIL outside the limit"
            }
            DecisionRule::GuardedRejection => {
                "guarded rejection (ILAC-G8:09/2019 4.2.3 and 4.2.4, JCGM 106:2012 8.3, guard band w = U): \
                 PASS inside the limit, CONDITIONAL (conditional fail) within U outside the limit, FAIL \
                 when outside the limit by more than U"
            }
        }
    }
}

/// The outcome of one limit on one figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Verdict {
    /// Conforms under the decision rule.
    Pass,
    /// Does not conform under the decision rule.
    Fail,
    /// Inside the guard band: neither pass nor fail can be stated at the rule's risk.
    Conditional,
    /// Not decided (figure missing, a bound that cannot decide, no uncertainty for a guarded
    /// rule); the check carries the reason.
    NotEvaluated,
}

impl Verdict {
    /// Text shown in reports: `PASS`, `FAIL`, `CONDITIONAL`, `NOT EVALUATED`.
    pub fn text(self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
            Verdict::Conditional => "CONDITIONAL",
            Verdict::NotEvaluated => "NOT EVALUATED",
        }
    }

    /// CSS class / JSON spelling: `PASS`, `FAIL`, `CONDITIONAL`, `NOT_EVALUATED`.
    pub fn class(self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
            Verdict::Conditional => "CONDITIONAL",
            Verdict::NotEvaluated => "NOT_EVALUATED",
        }
    }
}

/// The overall result of a set of required checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Overall {
    /// Every check passed.
    Pass,
    /// At least one check failed.
    Fail,
    /// No check failed, at least one is CONDITIONAL, every check was evaluated.
    Conditional,
    /// No check failed, at least one required check is NOT EVALUATED (or there were none).
    Incomplete,
}

impl Overall {
    /// Text shown in reports.
    pub fn text(self) -> &'static str {
        match self {
            Overall::Pass => "PASS",
            Overall::Fail => "FAIL",
            Overall::Conditional => "CONDITIONAL",
            Overall::Incomplete => "INCOMPLETE",
        }
    }
}

/// Overall result: FAIL if any check failed; else INCOMPLETE if any is NOT EVALUATED (or there
/// are no checks); else CONDITIONAL if any is CONDITIONAL; else PASS. A check not evaluated
/// never counts as passed.
pub fn overall(verdicts: &[Verdict]) -> Overall {
    if verdicts.contains(&Verdict::Fail) {
        Overall::Fail
    } else if verdicts.is_empty() || verdicts.contains(&Verdict::NotEvaluated) {
        Overall::Incomplete
    } else if verdicts.contains(&Verdict::Conditional) {
        Overall::Conditional
    } else {
        Overall::Pass
    }
}

/// A figure as known: value or bound, and its expanded uncertainty when one is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Known {
    /// The value, or the bound.
    pub value: f64,
    /// What `value` is.
    pub support: Support,
    /// Expanded uncertainty U of the value (same unit), when computed.
    pub expanded_uncertainty: Option<f64>,
}

impl Known {
    /// An estimate without a computed uncertainty.
    pub fn value(value: f64) -> Known {
        Known { value, support: Support::Value, expanded_uncertainty: None }
    }
}

/// The decision on one limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Decision {
    /// The verdict.
    pub verdict: Verdict,
    /// Guard band w applied (0 for simple acceptance; `None` when no rule could be applied).
    pub guard_band: Option<f64>,
    /// Why the verdict is NOT EVALUATED or CONDITIONAL, or how a bound decided.
    pub reason: Option<String>,
}

fn decision(verdict: Verdict, guard_band: Option<f64>, reason: Option<String>) -> Decision {
    Decision { verdict, guard_band, reason }
}

/// Decides one limit `[min, max]` (inclusive, either side optional) on a figure.
///
/// Comparisons use the unrounded numbers. A bound decides with w = 0 (the bound is itself the
/// conservative statement); a value is decided by `rule`, whose guard band is the figure's
/// expanded uncertainty (a guarded rule on a figure without one is NOT EVALUATED).
pub fn decide(known: Option<&Known>, min: Option<f64>, max: Option<f64>, rule: DecisionRule) -> Decision {
    let Some(k) = known.filter(|k| k.value.is_finite()) else {
        return decision(Verdict::NotEvaluated, None, Some("the figure is not available".into()));
    };
    let inside = |x: f64| min.is_none_or(|lo| x >= lo) && max.is_none_or(|hi| x <= hi);
    match k.support {
        Support::UpperBound => {
            // x <= b.
            let b = k.value;
            if min.is_some_and(|lo| b < lo) {
                decision(Verdict::Fail, Some(0.0), Some(format!("the figure is at most {b}, below the lower limit")))
            } else if min.is_none() && max.is_some_and(|hi| b <= hi) {
                decision(Verdict::Pass, Some(0.0), Some(format!("the figure is at most {b}, within the upper limit")))
            } else {
                decision(
                    Verdict::NotEvaluated,
                    None,
                    Some(format!("the figure is known only as an upper bound ({b}), which cannot decide this limit")),
                )
            }
        }
        Support::LowerBound => {
            // x > b.
            let b = k.value;
            if max.is_some_and(|hi| b >= hi) {
                decision(Verdict::Fail, Some(0.0), Some(format!("the figure is above {b}, beyond the upper limit")))
            } else if max.is_none() && min.is_some_and(|lo| b >= lo) {
                decision(Verdict::Pass, Some(0.0), Some(format!("the figure is above {b}, within the lower limit")))
            } else {
                decision(
                    Verdict::NotEvaluated,
                    None,
                    Some(format!("the figure is known only as a lower bound ({b}), which cannot decide this limit")),
                )
            }
        }
        Support::Value => {
            let v = k.value;
            if rule == DecisionRule::SimpleAcceptance {
                let verdict = if inside(v) { Verdict::Pass } else { Verdict::Fail };
                return decision(verdict, Some(0.0), None);
            }
            let Some(w) = k.expanded_uncertainty.filter(|u| u.is_finite() && *u >= 0.0) else {
                return decision(
                    Verdict::NotEvaluated,
                    None,
                    Some(format!(
                        "the decision rule {} needs the figure's expanded uncertainty as guard band; none is \
                         computed for this figure",
                        rule.key()
                    )),
                );
            };
            let inside_by_w = min.is_none_or(|lo| v >= lo + w) && max.is_none_or(|hi| v <= hi - w);
            let outside_by_w = min.is_some_and(|lo| v < lo - w) || max.is_some_and(|hi| v > hi + w);
            match rule {
                DecisionRule::GuardedAcceptance if inside_by_w && inside(v) => decision(Verdict::Pass, Some(w), None),
                DecisionRule::GuardedAcceptance if inside(v) => decision(
                    Verdict::Conditional,
                    Some(w),
                    Some(format!("conditional pass: within the limit but within the guard band U = {w} of it")),
                ),
                DecisionRule::GuardedRejection if inside(v) => decision(Verdict::Pass, Some(w), None),
                DecisionRule::GuardedRejection if !outside_by_w => decision(
                    Verdict::Conditional,
                    Some(w),
                    Some(format!("conditional fail: outside the limit but within the guard band U = {w} of it")),
                ),
                _ => decision(Verdict::Fail, Some(w), None),
            }
        }
    }
}

/// `x` rounded to `n` significant digits (n ≥ 1).
pub fn round_significant(x: f64, n: usize) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    format!("{:.*e}", n.max(1) - 1, x).parse().unwrap_or(x) // ok: Rust's own exponent format parses back
}

/// The smallest number of significant digits, at least `min_digits` (at most 17), at which the
/// value and every limit, each rounded to that many significant digits, compare as the
/// unrounded numbers do (less, equal, greater): printed so, value and limit never contradict a
/// verdict taken on the unrounded value (a value 7.499894 beside a limit 7.49989 prints as
/// 7.499894, not as 7.49989).
pub fn consistent_digits(value: f64, limits: &[f64], min_digits: usize) -> usize {
    let mut n = min_digits.max(1);
    while n < 17 {
        let rv = round_significant(value, n);
        let ok = limits.iter().all(|&l| {
            let rl = round_significant(l, n);
            value.partial_cmp(&l) == rv.partial_cmp(&rl)
        });
        if ok {
            return n;
        }
        n += 1;
    }
    17
}

/// The decimal exponent of the last digit kept when `u` is given to two significant digits
/// (GUM 7.2.6): U = 0.0123 → -3 (0.012), U = 112 → 1 (110).
pub fn uncertainty_last_digit(u: f64) -> Option<i32> {
    (u.is_finite() && u > 0.0).then(|| u.abs().log10().floor() as i32 - 1)
}

/// Value and U as printed (GUM 7.2.6): U to two significant digits, the value to the same
/// decimal place. Without a usable U, `None`.
pub fn round_to_uncertainty(value: f64, u: f64) -> Option<(String, String)> {
    let last = uncertainty_last_digit(u)?;
    if !value.is_finite() {
        return None;
    }
    let decimals = (-last).max(0) as usize;
    let scale = 10f64.powi(last);
    let (rv, ru) = if last > 0 { ((value / scale).round() * scale, (u / scale).round() * scale) } else { (value, u) };
    Some((format!("{rv:.decimals$}"), format!("{ru:.decimals$}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn val(v: f64, u: Option<f64>) -> Known {
        Known { value: v, support: Support::Value, expanded_uncertainty: u }
    }
    fn bound(v: f64, support: Support) -> Known {
        Known { value: v, support, expanded_uncertainty: None }
    }
    use DecisionRule::*;
    use Verdict::*;

    #[test]
    fn simple_acceptance_by_hand() {
        // limit <= 10: 7.2 passes whatever its U; 10 passes (inclusive); 10.01 fails.
        assert_eq!(decide(Some(&val(7.2, Some(6.4))), None, Some(10.0), SimpleAcceptance).verdict, Pass);
        assert_eq!(decide(Some(&val(10.0, None)), None, Some(10.0), SimpleAcceptance).verdict, Pass);
        assert_eq!(decide(Some(&val(10.01, None)), None, Some(10.0), SimpleAcceptance).verdict, Fail);
        assert_eq!(decide(Some(&val(0.9, None)), Some(1.0), Some(2.0), SimpleAcceptance).verdict, Fail);
        assert_eq!(decide(Some(&val(1.0, None)), Some(1.0), Some(2.0), SimpleAcceptance).guard_band, Some(0.0));
    }

    #[test]
    fn guarded_acceptance_by_hand() {
        // The bias thermal hysteresis: 7.2 deg/h, scatter 3.2 deg/h (k = 2: U = 6.4),
        // limit <= 10: acceptance limit 10 - 6.4 = 3.6 < 7.2 <= 10, so CONDITIONAL (conditional pass).
        let d = decide(Some(&val(7.2, Some(6.4))), None, Some(10.0), GuardedAcceptance);
        assert_eq!((d.verdict, d.guard_band), (Conditional, Some(6.4)));
        assert!(d.reason.unwrap().starts_with("conditional pass"));
        // 3.6 is exactly on the acceptance limit: PASS; 3.61 CONDITIONAL; 10.5 FAIL.
        assert_eq!(decide(Some(&val(3.5, Some(6.5))), None, Some(10.0), GuardedAcceptance).verdict, Pass);
        assert_eq!(decide(Some(&val(3.61, Some(6.4))), None, Some(10.0), GuardedAcceptance).verdict, Conditional);
        assert_eq!(decide(Some(&val(10.5, Some(6.4))), None, Some(10.0), GuardedAcceptance).verdict, Fail);
        // Two-sided limit [1, 2], U = 0.2: acceptance zone [1.2, 1.8].
        assert_eq!(decide(Some(&val(1.5, Some(0.2))), Some(1.0), Some(2.0), GuardedAcceptance).verdict, Pass);
        assert_eq!(decide(Some(&val(1.1, Some(0.2))), Some(1.0), Some(2.0), GuardedAcceptance).verdict, Conditional);
        assert_eq!(decide(Some(&val(1.9, Some(0.2))), Some(1.0), Some(2.0), GuardedAcceptance).verdict, Conditional);
        // U wider than half the tolerance: no acceptance zone, the middle is CONDITIONAL too.
        assert_eq!(decide(Some(&val(1.5, Some(0.6))), Some(1.0), Some(2.0), GuardedAcceptance).verdict, Conditional);
        // No U: a guarded rule cannot be applied.
        let d = decide(Some(&val(7.2, None)), None, Some(10.0), GuardedAcceptance);
        assert_eq!((d.verdict, d.guard_band), (NotEvaluated, None));
        assert!(d.reason.unwrap().contains("guarded_acceptance needs the figure's expanded uncertainty"));
    }

    #[test]
    fn guarded_rejection_by_hand() {
        // limit <= 10, U = 0.5: 10 PASS, 10.4 CONDITIONAL (conditional fail), 10.5 CONDITIONAL
        // (on the rejection limit), 10.6 FAIL.
        let d = |v: f64| decide(Some(&val(v, Some(0.5))), None, Some(10.0), GuardedRejection).verdict;
        assert_eq!([d(10.0), d(10.4), d(10.5), d(10.6), d(-50.0)], [Pass, Conditional, Conditional, Fail, Pass]);
        let d = |v: f64| decide(Some(&val(v, Some(0.5))), Some(1.0), None, GuardedRejection).verdict;
        assert_eq!([d(1.0), d(0.6), d(0.4)], [Pass, Conditional, Fail]);
    }

    #[test]
    fn bounds_decide_where_they_can() {
        // Allan term < 8.3 deg/h against <= 100: PASS.
        assert_eq!(decide(Some(&bound(8.3, Support::UpperBound)), None, Some(100.0), GuardedAcceptance).verdict, Pass);
        // Upper bound 0.1 against <= 0.05: cannot decide.
        let d = decide(Some(&bound(0.1, Support::UpperBound)), None, Some(0.05), SimpleAcceptance);
        assert_eq!(d.verdict, NotEvaluated);
        assert!(d.reason.unwrap().contains("upper bound"));
        // Upper bound below a lower limit: FAIL; within a two-sided limit: cannot decide.
        assert_eq!(decide(Some(&bound(0.5, Support::UpperBound)), Some(1.0), None, SimpleAcceptance).verdict, Fail);
        assert_eq!(
            decide(Some(&bound(1.5, Support::UpperBound)), Some(1.0), Some(2.0), SimpleAcceptance).verdict,
            NotEvaluated
        );
        // The threshold: no response even at 0.5 deg/s against <= 0.2 deg/s: FAIL.
        assert_eq!(decide(Some(&bound(0.5, Support::LowerBound)), None, Some(0.2), SimpleAcceptance).verdict, Fail);
        // x > 0.2 against <= 0.2: FAIL (strict bound on the limit).
        assert_eq!(decide(Some(&bound(0.2, Support::LowerBound)), None, Some(0.2), SimpleAcceptance).verdict, Fail);
        // Lower bound 0.1 against <= 0.2: cannot decide; against >= 0.05: PASS.
        assert_eq!(
            decide(Some(&bound(0.1, Support::LowerBound)), None, Some(0.2), SimpleAcceptance).verdict,
            NotEvaluated
        );
        assert_eq!(decide(Some(&bound(0.1, Support::LowerBound)), Some(0.05), None, SimpleAcceptance).verdict, Pass);
        // Missing or non-finite figure.
        assert_eq!(decide(None, None, Some(1.0), SimpleAcceptance).verdict, NotEvaluated);
        assert_eq!(decide(Some(&val(f64::NAN, None)), None, Some(1.0), SimpleAcceptance).verdict, NotEvaluated);
    }

    #[test]
    fn overall_by_hand() {
        assert_eq!(overall(&[Pass, Pass]), Overall::Pass);
        assert_eq!(overall(&[Pass, NotEvaluated]), Overall::Incomplete);
        assert_eq!(overall(&[Conditional, NotEvaluated]), Overall::Incomplete);
        assert_eq!(overall(&[Pass, Conditional]), Overall::Conditional);
        assert_eq!(overall(&[Fail, NotEvaluated, Conditional]), Overall::Fail);
        assert_eq!(overall(&[]), Overall::Incomplete);
        assert_eq!(serde_json::to_string(&Overall::Incomplete).unwrap(), "\"INCOMPLETE\"");
        assert_eq!(serde_json::to_string(&NotEvaluated).unwrap(), "\"NOT_EVALUATED\"");
        assert_eq!(serde_json::to_string(&GuardedRejection).unwrap(), "\"guarded_rejection\"");
        assert!(DecisionRule::ALL.iter().all(|r| DecisionRule::parse(r.key()) == Some(*r)));
    }

    #[test]
    fn printed_digits_never_contradict_the_comparison() {
        // The case: 7.499894 against <= 7.49989 fails; at 6 digits both print 7.49989.
        assert_eq!(consistent_digits(7.499894, &[7.49989], 4), 7);
        assert_eq!(round_significant(7.499894, 7), 7.499894);
        // 0.0075004 against <= 0.0075 fails; 4 digits print 0.007500 (equal): 5 digits needed.
        assert_eq!(consistent_digits(0.0075004, &[0.0075], 4), 5);
        // Equal values stay equal; distant values keep the minimum.
        assert_eq!(consistent_digits(0.0075, &[0.0075], 4), 4);
        assert_eq!(consistent_digits(1.234, &[10.0, 0.5], 3), 3);
        // A value just under the limit: 9.99996 vs 10 rounds to 10.000 at 5 digits.
        assert_eq!(consistent_digits(9.99996, &[10.0], 4), 6);
    }

    #[test]
    fn rounding_to_two_digits_of_u_gum_7_2_6() {
        assert_eq!(round_to_uncertainty(1.864, 112.0), Some(("0".into(), "110".into())));
        assert_eq!(round_to_uncertainty(100.02147, 0.00035), Some(("100.02147".into(), "0.00035".into())));
        assert_eq!(round_to_uncertainty(7.2, 6.4), Some(("7.2".into(), "6.4".into())));
        assert_eq!(round_to_uncertainty(0.0076543, 0.000123), Some(("0.00765".into(), "0.00012".into())));
        assert_eq!(round_to_uncertainty(1.0, 0.0), None);
        assert_eq!(uncertainty_last_digit(0.0123), Some(-3));
    }
}
