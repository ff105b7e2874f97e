//! Rendering of threshold and resolution tests: the report section "Threshold and resolution"
//! (a table of the rates tried per axis and test), the summary figures `threshold_dps` and
//! `resolution_dps`, and the results.json objects `sections.threshold.<axis>` and
//! `sections.resolution.<axis>` (docs/JSON.md). Definitions: docs/METHODS.md, "Threshold and
//! resolution" (GJB 2426A-2004, IEEE Std 528).

use crate::html::{DataTable, FigureRow, ReportSection};
use gyrolab::figures::AxisFigures;
use gyrolab::format::{short, sig};
use gyrolab::limits::{check_limits, Limit};
use gyrolab::threshold::{StepEstimate, Support, MARGINAL_STANDARD_ERRORS, PASS_FRACTION};
use serde_json::json;

/// Which test an estimate comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepKind {
    /// Threshold (steps from 0 deg/s).
    Threshold,
    /// Resolution (steps from a base rate).
    Resolution,
}

impl StepKind {
    /// The figure key (`threshold_dps`, `resolution_dps`).
    pub fn figure(self) -> &'static str {
        match self {
            StepKind::Threshold => "threshold_dps",
            StepKind::Resolution => "resolution_dps",
        }
    }

    /// The word (`threshold`, `resolution`), also the results.json section name.
    pub fn word(self) -> &'static str {
        match self {
            StepKind::Threshold => "threshold",
            StepKind::Resolution => "resolution",
        }
    }
}

/// One evaluated threshold or resolution test of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport {
    /// Which test.
    pub kind: StepKind,
    /// Axis name.
    pub axis: String,
    /// The record as named in the plan.
    pub file: String,
    /// Output unit symbol.
    pub output_unit: String,
    /// Where K came from, in words (`this plan's rate-table evaluation of axis x`).
    pub scale_factor_source: String,
    /// The estimate.
    pub estimate: StepEstimate,
    /// Simulated data: what was simulated; `None` for measured data.
    pub simulated: Option<String>,
}

impl StepReport {
    /// The figure's text: `0.05 deg/s`, `at most 0.01 deg/s`, `above the largest tried, 0.2 deg/s`.
    pub fn value_text(&self) -> String {
        let e = &self.estimate;
        match (e.support, e.value_dps, e.above_dps) {
            (Support::Value, Some(v), _) => format!("{} deg/s", short(v, 6)),
            (Support::UpperBound, Some(v), _) => format!("at most {} deg/s (the smallest tried)", short(v, 6)),
            (Support::LowerBound, _, Some(a)) => format!("above the largest tried, {} deg/s (no value)", short(a, 6)),
            _ => "n/a".into(),
        }
    }

    /// The summary figure: the value, or the upper bound (a `max` limit on it is then still a
    /// sound check); none for a lower bound.
    pub fn figure_value(&self) -> Option<f64> {
        match self.estimate.support {
            Support::Value | Support::UpperBound => self.estimate.value_dps,
            Support::LowerBound => None,
        }
    }

    /// The results.json object of this test.
    pub fn json(&self) -> serde_json::Value {
        let e = &self.estimate;
        let rows: Vec<serde_json::Value> = e
            .tried
            .iter()
            .map(|t| {
                json!({
                    "rate_dps": t.rate_dps,
                    "step_dps": t.step_dps,
                    "samples": t.samples,
                    "mean_output": t.mean_output,
                    "mean_output_std_error": t.std_error,
                    "output_change": t.output_change,
                    "expected_change": t.expected_change,
                    "ratio": t.ratio,
                    "ratio_std_error": t.ratio_std_error,
                    "pass": t.pass,
                    "marginal": t.marginal,
                })
            })
            .collect();
        let mut o = serde_json::Map::new();
        o.insert(self.kind.figure().into(), json!(e.value_dps));
        o.insert(format!("{}_support", self.kind.word()), json!(e.support.key()));
        o.insert("above_dps".into(), json!(e.above_dps));
        o.insert("marginal".into(), json!(e.marginal));
        if self.kind == StepKind::Resolution {
            o.insert("base_rate_dps".into(), json!(e.reference_rate_dps));
        }
        o.insert("reference_rate_dps".into(), json!(e.reference_rate_dps));
        o.insert("reference_samples".into(), json!(e.reference_samples));
        o.insert("reference_mean_output".into(), json!(e.reference_mean));
        o.insert("reference_mean_output_std_error".into(), json!(e.reference_std_error));
        o.insert("scale_factor".into(), json!(e.scale_factor));
        o.insert("scale_factor_source".into(), json!(self.scale_factor_source));
        o.insert("output_unit".into(), json!(self.output_unit));
        o.insert("pass_fraction".into(), json!(PASS_FRACTION));
        o.insert("file".into(), json!(self.file));
        o.insert("rates_tried".into(), serde_json::Value::Array(rows));
        o.insert("simulated".into(), json!(self.simulated));
        serde_json::Value::Object(o)
    }

    /// The table of rates tried.
    fn table(&self) -> DataTable {
        let e = &self.estimate;
        let u = &self.output_unit;
        let step_head = match self.kind {
            StepKind::Threshold => "rate (deg/s)".to_string(),
            StepKind::Resolution => "step from base (deg/s)".to_string(),
        };
        let mut rows = vec![vec![
            short(e.reference_rate_dps, 6),
            "reference".into(),
            e.reference_samples.to_string(),
            sig(e.reference_mean, 7),
            sig(e.reference_std_error, 3),
            String::new(),
            String::new(),
            String::new(),
            String::new(),
        ]];
        for t in &e.tried {
            rows.push(vec![
                short(t.rate_dps, 6),
                short(t.step_dps, 6),
                t.samples.to_string(),
                sig(t.mean_output, 7),
                sig(t.std_error, 3),
                sig(t.output_change, 4),
                sig(t.expected_change, 4),
                format!("{} ± {}", sig(t.ratio, 3), sig(t.ratio_std_error, 2)),
                format!("{}{}", if t.pass { "pass" } else { "FAIL" }, if t.marginal { " (marginal)" } else { "" }),
            ]);
        }
        DataTable {
            caption: format!(
                "Axis {}: {} test, rates tried ({}{})",
                self.axis,
                self.kind.word(),
                self.file,
                if self.simulated.is_some() { ", SIMULATED" } else { "" }
            ),
            header: vec![
                "rate (deg/s)".into(),
                step_head,
                "samples".into(),
                format!("mean output ({u})"),
                format!("std error ({u})"),
                format!("output change ({u})"),
                format!("expected K·Δrate ({u})"),
                "ratio ± s.e.".into(),
                "50 % test".into(),
            ],
            rows,
        }
    }
}

/// The summary figures of the tests, one [`AxisFigures`] per test (the report merges them by axis).
pub fn step_figures(reports: &[StepReport]) -> Vec<AxisFigures> {
    reports
        .iter()
        .map(|r| {
            let mut f = AxisFigures { axis: r.axis.clone(), output_unit: r.output_unit.clone(), ..Default::default() };
            // The value, or the bound on its side: "at most the smallest tried" or "above the
            // largest tried" (a limit decides on the bound where it can).
            let e = &r.estimate;
            let known = match e.support {
                Support::Value | Support::UpperBound => e.value_dps,
                Support::LowerBound => e.above_dps,
            };
            if let Some(v) = known {
                f.set_bound(r.kind.figure(), v, e.support);
                if r.simulated.is_some() {
                    f.simulated.push(r.kind.figure().into());
                }
            }
            f
        })
        .collect()
}

/// The section "Threshold and resolution": figures with their support, and the tables of rates
/// tried, for every test.
pub fn step_section(reports: &[StepReport], limits: &[Limit]) -> ReportSection {
    let mut paragraphs = vec![format!(
        "Threshold (GJB 2426A-2004, IEEE Std 528): the smallest input rate whose output change from the zero-rate \
         output is at least {} % of K × rate, in both directions. Resolution: at a stated base rate, the smallest \
         rate step whose output change is at least {} % of K × step, for both signs. Each tried magnitude passes \
         when both directions pass; the figure is the smallest tried magnitude from which on every larger tried \
         magnitude passes. When the smallest tried passes the figure is an upper bound (at most the smallest \
         tried; it passes an upper limit at or above it); when the largest tried fails it is a lower bound with no \
         value (above the largest tried; it fails an upper limit at or below it). A decision within {} standard errors of the {} % line is marked marginal. \
         docs/METHODS.md, threshold and resolution.",
        PASS_FRACTION * 100.0,
        PASS_FRACTION * 100.0,
        MARGINAL_STANDARD_ERRORS,
        PASS_FRACTION * 100.0
    )];
    let mut figures = Vec::new();
    let mut tables = Vec::new();
    for r in reports {
        if let Some(s) = &r.simulated {
            paragraphs.push(format!("SIMULATED ({} {}): {s}", r.axis, r.kind.word()));
        }
        let e = &r.estimate;
        paragraphs.push(format!(
            "Axis {}, {}: {}{}; K = {} {}/(deg/s) from {}{}.",
            r.axis,
            r.kind.word(),
            r.value_text(),
            if e.marginal { " (MARGINAL: a deciding rate is within two standard errors of the 50 % line)" } else { "" },
            sig(e.scale_factor, 6),
            r.output_unit,
            r.scale_factor_source,
            match r.kind {
                StepKind::Resolution => format!("; base rate {} deg/s", short(e.reference_rate_dps, 6)),
                StepKind::Threshold => String::new(),
            }
        ));
        let key = r.kind.figure();
        let figs = step_figures(std::slice::from_ref(r));
        let checks = check_limits(limits, &figs);
        let limit = limits.iter().find(|l| l.figure == key && l.applies_to(&r.axis));
        figures.push(FigureRow {
            label: format!("{} {}", r.axis, r.kind.word()),
            key: key.into(),
            value: r.value_text(),
            unit: "deg/s".into(),
            limit: limit.map_or_else(String::new, Limit::text),
            verdict: limit.and_then(|_| checks.iter().find(|c| c.figure == key).map(|c| c.verdict)),
            axis: Some(r.axis.clone()),
            check_axis: Some(r.axis.clone()),
        });
        tables.push(r.table());
    }
    ReportSection {
        title: "Threshold and resolution".into(),
        simulated: reports.iter().any(|r| r.simulated.is_some()),
        paragraphs,
        figures,
        tables,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrolab::threshold::{threshold, RateSamples};

    fn report(groups: Vec<RateSamples>) -> StepReport {
        StepReport {
            kind: StepKind::Threshold,
            axis: "x".into(),
            file: "t.csv".into(),
            output_unit: "V".into(),
            scale_factor_source: "the plan".into(),
            estimate: threshold(&groups, 1.0).unwrap(),
            simulated: None,
        }
    }

    fn g(rate: f64, y: f64) -> RateSamples {
        RateSamples { rate_dps: rate, outputs: vec![y, y] }
    }

    #[test]
    fn lower_bound_has_no_figure_and_says_so() {
        let r = report(vec![g(0.0, 0.0), g(0.1, 0.0), g(-0.1, 0.0)]);
        assert_eq!(r.figure_value(), None);
        let f = &step_figures(std::slice::from_ref(&r))[0];
        assert_eq!(f.known("threshold_dps").map(|k| (k.value, k.support)), Some((0.1, Support::LowerBound)));
        assert!(r.value_text().starts_with("above the largest tried, 0.1"), "{}", r.value_text());
        let j = r.json();
        assert_eq!(j["threshold_dps"], serde_json::Value::Null);
        assert_eq!(j["threshold_support"], "lower_bound");
        assert_eq!(j["above_dps"], 0.1);
        // Above 0.1 against <= 0.05: FAIL (the "no response even at 0.5 against <= 0.2");
        // against <= 0.5 the bound cannot decide.
        let s = step_section(std::slice::from_ref(&r), &[Limit::new("threshold_dps", None, Some(0.05))]);
        assert_eq!(s.figures[0].verdict, Some(gyrolab::limits::Verdict::Fail));
        assert_eq!(s.tables[0].rows.len(), 3);
        let s = step_section(std::slice::from_ref(&r), &[Limit::new("threshold_dps", None, Some(0.5))]);
        assert_eq!(s.figures[0].verdict, Some(gyrolab::limits::Verdict::NotEvaluated));
    }

    #[test]
    fn upper_bound_is_the_figure_and_checked() {
        let r = report(vec![g(0.0, 0.0), g(0.1, 0.1), g(-0.1, -0.1)]);
        assert_eq!(r.figure_value(), Some(0.1));
        let j = r.json();
        assert_eq!(j["threshold_support"], "upper_bound");
        assert_eq!(j["rates_tried"][0]["rate_dps"], -0.1);
        assert_eq!(j["rates_tried"][0]["pass"], true);
        // At most 0.1 against <= 0.05 cannot be decided; against <= 0.2 it passes.
        let s = step_section(std::slice::from_ref(&r), &[Limit::new("threshold_dps", None, Some(0.05))]);
        assert_eq!(s.figures[0].verdict, Some(gyrolab::limits::Verdict::NotEvaluated));
        assert!(s.figures[0].value.starts_with("at most 0.1"));
        let s = step_section(std::slice::from_ref(&r), &[Limit::new("threshold_dps", None, Some(0.2))]);
        assert_eq!(s.figures[0].verdict, Some(gyrolab::limits::Verdict::Pass));
    }
}
