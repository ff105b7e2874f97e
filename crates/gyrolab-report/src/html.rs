//! The self-contained HTML report: inline CSS and SVG, no script, no external URL, no web font;
//! prints to A4 (each axis section starts on a new page, plots never split or clip).
//!
//! A report is a [`Report`]: a device header, the summary table of every figure with its limit
//! and verdict ([`SummaryTable`]), a list of [`ReportSection`]s and the methods appendix built
//! from the figure catalogue ([`gyrolab::figures::FIGURES`]). A section is generic (title, a
//! simulated-data flag, a figure table, data tables, plots), so the static-bias and Allan
//! sections are added by building more `ReportSection`s: the page template does not change.

use crate::plot::PlotError;
use crate::rate_plots::{calibration_plot, hysteresis_plot, scale_factor_plot};
use crate::results::{CalibrationStatus, EquipmentRow, TestConditions};
use gyrolab::figures::{known_figure, AxisFigures, FigureGroup, FIGURES};
use gyrolab::format::{sig, sig_opt};
use gyrolab::limits::{check_limits, overall, DecisionRule, Limit, LimitCheck, Overall, Support, Verdict};
use gyrolab::units::{ratio_to_pct, ratio_to_ppm};
use gyrolab_eval::outcome::rate::AxisReport;
use std::fmt::Write;

/// Escapes text for HTML element content and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The report's header: what was tested, when, by which program, from which plan.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportHeader {
    /// Report title.
    pub title: String,
    /// Device model.
    pub model: String,
    /// Device serial number.
    pub serial: String,
    /// Axes, in plan order.
    pub axes: Vec<String>,
    /// Date and time of the evaluation (RFC 3339).
    pub date: String,
    /// gyrolab version.
    pub gyrolab_version: String,
    /// The plan file (or a description of the built-in data).
    pub plan_file: String,
    /// Further lines shown under the header (plain text).
    pub notes: Vec<String>,
    /// Who, where, when, under which conditions (the plan's `[test]`).
    pub test: TestConditions,
    /// The equipment used, with its calibration status on the test date.
    pub equipment: Vec<EquipmentRow>,
    /// The report's number (ISO/IEC 17025:2017 7.8.2.1 b): on the header and every printed page.
    pub report_number: String,
    /// The issue date, `YYYY-MM-DD`.
    pub issue_date: String,
    /// The plan and the inputs with their SHA-256 (empty for built-in data).
    pub integrity: crate::results::IntegrityJson,
}

/// One row of a section's figure table.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureRow {
    /// Figure name (human).
    pub label: String,
    /// Catalogue key, linking to the methods appendix; empty for none.
    pub key: String,
    /// Value as text.
    pub value: String,
    /// Unit.
    pub unit: String,
    /// Limit as text (empty for none).
    pub limit: String,
    /// Verdict when a limit applies.
    pub verdict: Option<Verdict>,
    /// The axis whose figure the row shows, when its value is in the figure's catalogue unit
    /// (the report then prints it rounded to its expanded uncertainty).
    pub axis: Option<String>,
    /// The axis whose limit check gives the row's verdict: [`apply_checks`] sets it from the
    /// report's one list of checks (the summary's and results.json's), so that a section never
    /// shows another verdict for the same check.
    pub check_axis: Option<String>,
}

impl FigureRow {
    /// The row of figure `key` of one axis, checked against the limits that apply to the axis:
    /// the value (or bound, "at most"/"above") to four significant digits or as many more as keep
    /// it from contradicting the verdict; `None` when the axis has no such figure.
    pub fn checked(figs: &AxisFigures, limits: &[Limit], key: &str, label: &str) -> Option<FigureRow> {
        let k = figs.known(key)?;
        let limit = limits.iter().find(|l| l.figure == key && l.applies_to(&figs.axis));
        let check = limit.and_then(|l| check_limits(std::slice::from_ref(l), std::slice::from_ref(figs)).pop());
        let value = match (&check, k.support) {
            (Some(c), _) => c.value_text(4),
            (None, Support::Value) => sig(k.value, 4),
            (None, Support::UpperBound) => format!("at most {}", sig(k.value, 4)),
            (None, Support::LowerBound) => format!("above {}", sig(k.value, 4)),
        };
        Some(FigureRow {
            label: label.to_string(),
            key: key.to_string(),
            value,
            unit: figs.unit_of(key),
            limit: limit.map_or_else(String::new, Limit::text),
            verdict: check.map(|c| c.verdict),
            axis: Some(figs.axis.clone()),
            check_axis: Some(figs.axis.clone()),
        })
    }
}

/// The text of figure `key` of an axis as the report prints it: with a limit check, as many
/// digits as keep value and limit from contradicting the verdict; a bound says which side it is
/// ("at most", "above"); with an expanded uncertainty U the value rounded to U's second
/// significant digit followed by "± U" (GUM 7.2.6); `None` when the axis has no such figure.
pub fn value_cell(a: &AxisFigures, key: &str, check: Option<&LimitCheck>, digits: usize) -> Option<String> {
    let k = a.known(key)?;
    let u = k.expanded_uncertainty.filter(|u| *u > 0.0);
    let text = match (check, k.support) {
        (Some(c), _) => c.value_text(digits),
        (None, Support::Value) => u
            .and_then(|u| gyrolab::format::rounded_to_uncertainty(k.value, u))
            .map_or_else(|| sig(k.value, digits), |(v, _)| v),
        (None, Support::UpperBound) => format!("at most {}", sig(k.value, digits)),
        (None, Support::LowerBound) => format!("above {}", sig(k.value, digits)),
    };
    Some(match u.and_then(|u| gyrolab::format::rounded_to_uncertainty(1.0, u)) {
        Some((_, u_text)) => format!("{text} ± {u_text}"),
        None => text,
    })
}

/// Prints the per-axis figure rows of every section as the summary prints them wherever the
/// figure has an expanded uncertainty (the sections are drawn before the uncertainty part has
/// run): value rounded to U and "± U", the digits a limit needs kept. Rows without an axis, or
/// whose figure has no U, keep their own digits.
pub fn round_rows_to_uncertainty(sections: &mut [ReportSection], figures: &[AxisFigures], limits: &[Limit]) {
    for row in sections.iter_mut().flat_map(|s| s.figures.iter_mut()) {
        let (Some(axis), false) = (row.axis.as_deref(), row.key.is_empty()) else { continue };
        let Some(a) = figures.iter().find(|f| f.axis == axis) else { continue };
        if a.known(&row.key).and_then(|k| k.expanded_uncertainty).is_none_or(|u| u <= 0.0) {
            continue;
        }
        let applicable: Vec<Limit> =
            limits.iter().filter(|l| l.figure == row.key && l.applies_to(axis)).cloned().collect();
        let check = check_limits(&applicable, std::slice::from_ref(a)).pop();
        if let Some(text) = value_cell(a, &row.key, check.as_ref(), 4) {
            row.value = text;
        }
    }
}

/// Sets the verdict of every section row that shows a limit check from `checks`, the report's
/// one list (the summary's, results.json's `limit_checks`): a section is drawn before the
/// uncertainty part has run, so its own check of a guarded rule would lack the guard band U
/// and say NOT EVALUATED where the summary says PASS (issue 53: one verdict per check).
pub fn apply_checks(sections: &mut [ReportSection], checks: &[LimitCheck]) {
    for row in sections.iter_mut().flat_map(|s| s.figures.iter_mut()) {
        let (Some(axis), false) = (row.check_axis.as_deref(), row.key.is_empty()) else { continue };
        if let Some(c) = checks.iter().find(|c| c.axis == axis && c.figure == row.key) {
            row.verdict = Some(c.verdict);
        }
    }
}

/// A table of data (points, runs...).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DataTable {
    /// Caption.
    pub caption: String,
    /// Column headers (with units).
    pub header: Vec<String>,
    /// Rows of cells.
    pub rows: Vec<Vec<String>>,
}

/// A plot with its caption.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotBlock {
    /// Caption under the plot.
    pub caption: String,
    /// Inline SVG from [`crate::plot::Figure::to_svg`].
    pub svg: String,
}

/// A report section (one axis's rate-table test, its static test, its Allan analysis...).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportSection {
    /// Section title.
    pub title: String,
    /// Whether the section's data are simulated (shown as a prominent label).
    pub simulated: bool,
    /// Introductory paragraphs (plain text).
    pub paragraphs: Vec<String>,
    /// The figure table.
    pub figures: Vec<FigureRow>,
    /// Plots.
    pub plots: Vec<PlotBlock>,
    /// Data tables, after the plots.
    pub tables: Vec<DataTable>,
    /// Start the section on a new printed page.
    pub page_break_before: bool,
}

/// One row of the summary: a figure, its unit, its limit and the value and verdict per axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryRow {
    /// Catalogue key.
    pub key: String,
    /// Human name.
    pub label: String,
    /// Unit (the first axis's, for output-valued figures).
    pub unit: String,
    /// Limit text, empty for none.
    pub limit: String,
    /// Per axis: value text and verdict (None when no limit applies).
    pub cells: Vec<(String, Option<Verdict>)>,
    /// Whether the figure comes from simulated data on some axis (marked SIMULATED).
    pub simulated: bool,
}

/// The summary table of every figure.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SummaryTable {
    /// Axis names (columns).
    pub axes: Vec<String>,
    /// Rows in catalogue order.
    pub rows: Vec<SummaryRow>,
    /// Every limit check.
    pub checks: Vec<LimitCheck>,
}

impl SummaryTable {
    /// Withholds every verdict: each check becomes NOT EVALUATED with `reason` (an expired
    /// equipment calibration under the plan's default rule), every cell's verdict with it.
    pub fn withhold(&mut self, reason: &str) {
        for c in &mut self.checks {
            c.verdict = Verdict::NotEvaluated;
            c.reason = Some(match &c.reason {
                Some(r) => format!("{reason} (else: {r})"),
                None => reason.to_string(),
            });
        }
        for cell in self.rows.iter_mut().flat_map(|r| r.cells.iter_mut()) {
            if cell.1.is_some() {
                cell.1 = Some(Verdict::NotEvaluated);
            }
        }
    }

    /// Builds the summary from each axis's figures and the plan's limits.
    pub fn build(axes: &[AxisFigures], limits: &[Limit]) -> SummaryTable {
        let checks = check_limits(limits, axes);
        let mut keys: Vec<String> = Vec::new();
        for def in FIGURES {
            for a in axes {
                for (k, _) in &a.values {
                    if gyrolab::figures::name_matches(def.key, k) && !keys.contains(k) {
                        keys.push(k.clone());
                    }
                }
            }
            for l in limits {
                if gyrolab::figures::name_matches(def.key, &l.figure) && !keys.contains(&l.figure) {
                    keys.push(l.figure.clone());
                }
            }
        }
        let rows = keys
            .into_iter()
            .map(|key| {
                let def = known_figure(&key);
                let limit = limits.iter().find(|l| l.figure == key);
                let digits = if key == "scale_factor" || key == "zero_offset" { 6 } else { 4 };
                let cells = axes
                    .iter()
                    .map(|a| {
                        let check = checks.iter().find(|c| c.axis == a.axis && c.figure == key);
                        let text = value_cell(a, &key, check, digits).unwrap_or_else(|| "n/a".into());
                        let verdict = limit
                            .filter(|l| l.applies_to(&a.axis))
                            .map(|_| check.map_or(Verdict::NotEvaluated, |c| c.verdict));
                        (text, verdict)
                    })
                    .collect();
                SummaryRow {
                    simulated: axes.iter().any(|a| a.simulated.contains(&key)),
                    label: {
                        let mut labels: Vec<String> = Vec::new();
                        for l in axes.iter().map(|a| a.label_of(&key)) {
                            if !labels.contains(&l) {
                                labels.push(l);
                            }
                        }
                        if labels.is_empty() {
                            def.map_or_else(|| key.clone(), |d| d.label.to_string())
                        } else {
                            labels.join(" / ")
                        }
                    },
                    unit: axes.first().map_or_else(String::new, |a| a.unit_of(&key)),
                    limit: limit.map_or_else(String::new, Limit::text),
                    key,
                    cells,
                }
            })
            .collect();
        SummaryTable { axes: axes.iter().map(|a| a.axis.clone()).collect(), rows, checks }
    }

    /// The overall result of the limits.
    pub fn overall(&self) -> Overall {
        overall(&self.checks)
    }

    /// The decision rules the checks used, each once.
    pub fn rules(&self) -> Vec<DecisionRule> {
        DecisionRule::ALL.into_iter().filter(|r| self.checks.iter().any(|c| c.rule == *r)).collect()
    }
}

/// The whole report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    /// Header.
    pub header: ReportHeader,
    /// Summary of every figure.
    pub summary: SummaryTable,
    /// Sections in order (rate-table per axis, then static and Allan when present).
    pub sections: Vec<ReportSection>,
}

impl Report {
    /// Whether any section or summary figure comes from simulated records: the report then
    /// carries a SIMULATED mark on every printed page and beside its overall result.
    pub fn simulated(&self) -> bool {
        self.sections.iter().any(|s| s.simulated) || self.summary.rows.iter().any(|r| r.simulated)
    }
}

const CSS: &str = r#"
:root { --pass: #1b7f3a; --pass-bg: #dff3e4; --fail: #b00020; --fail-bg: #fde2e4; --ne: #6b6b6b; --ne-bg: #eeeeee; --cond: #8a5a00; --cond-bg: #fff0cc; }
* { box-sizing: border-box; }
body { font-family: sans-serif; font-size: 11pt; color: #111; margin: 0 auto; padding: 16px 24px; max-width: 1100px; line-height: 1.35; }
h1 { font-size: 20pt; margin: 0 0 8px; }
h2 { font-size: 15pt; margin: 24px 0 8px; border-bottom: 2px solid #333; padding-bottom: 2px; }
h3 { font-size: 12pt; margin: 16px 0 6px; }
table { border-collapse: collapse; margin: 6px 0 12px; font-size: 10pt; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: right; vertical-align: top; }
th { background: #f0f0f0; }
caption { text-align: left; font-weight: bold; padding: 2px 0; white-space: nowrap; }
td.name, th.name { text-align: left; }
table.header td { text-align: left; border: none; padding: 1px 10px 1px 0; }
.verdict { font-weight: bold; white-space: nowrap; padding: 0 4px; border-radius: 3px; }
.PASS { color: var(--pass); background: var(--pass-bg); }
.FAIL { color: var(--fail); background: var(--fail-bg); }
.NOT_EVALUATED, .INCOMPLETE { color: var(--ne); background: var(--ne-bg); }
.CONDITIONAL { color: var(--cond); background: var(--cond-bg); }
.overall { font-size: 13pt; padding: 4px 10px; display: inline-block; margin: 4px 0; }
.simulated { display: inline-block; background: #fff3cd; color: #7a5a00; border: 2px solid #e0b000; font-weight: bold; padding: 2px 10px; margin: 4px 0; }
.sim-page { display: block; background: #fff3cd; color: #7a5a00; border: 2px solid #e0b000; font-weight: bold; padding: 2px 10px; margin: 4px 0; }
.sim-tag { font-size: 8.5pt; font-weight: bold; color: #7a5a00; background: #fff3cd; border: 1px solid #e0b000; padding: 0 4px; }
figure.plot { margin: 10px 0 16px; break-inside: avoid; page-break-inside: avoid; }
figure.plot svg { display: block; width: 100%; max-width: 760px; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 9.5pt; color: #333; margin-top: 3px; }
.note { font-size: 9.5pt; color: #333; }
p.end { text-align: center; font-weight: bold; margin-top: 24px; }
section.page-break { break-before: page; page-break-before: always; }
table.conditions, table.equipment { margin-top: 8px; }
table.sign-off td.sign { min-width: 180px; height: 40px; }
table.conditions td { min-width: 260px; }
table.methods { width: 100%; }
table.sign-off td:nth-child(2) { min-width: 160px; }
section.sign-off { break-inside: avoid; page-break-inside: avoid; }
tr { break-inside: avoid; page-break-inside: avoid; }
@page { size: A4; margin: 14mm 12mm; }
/* No ligatures: report numbers, hashes and identifiers copy out of the PDF as typed ("ff", not
   the single glyph U+FB00). */
html { font-variant-ligatures: none; font-feature-settings: "liga" 0, "clig" 0; }
@media print {
  body { max-width: none; padding: 0; font-size: 10pt; }
  * { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
  figure.plot svg { max-width: 165mm; max-height: 240mm; }
  .sim-page { position: fixed; bottom: 0; right: 0; margin: 0; padding: 0 6px; font-size: 8pt; }
  h2, h3 { break-after: avoid; page-break-after: avoid; }
}
"#;

fn verdict_span(v: Verdict) -> String {
    format!("<span class=\"verdict {}\">{}</span>", v.class(), v.text())
}

fn anchor(key: &str) -> String {
    let pattern = known_figure(key).map_or(key, |d| d.key);
    let id: String = pattern.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '-' }).collect();
    format!("def-{id}")
}

fn figure_link(key: &str, label: &str) -> String {
    if key.is_empty() || known_figure(key).is_none() {
        escape(label)
    } else {
        format!("<a href=\"#{}\">{}</a>", anchor(key), escape(label))
    }
}

fn write_table(h: &mut String, t: &DataTable) {
    let _ = write!(h, "<table><caption>{}</caption><thead><tr>", escape(&t.caption));
    for (i, c) in t.header.iter().enumerate() {
        let class = if i == 0 { " class=\"name\"" } else { "" };
        let _ = write!(h, "<th{class}>{}</th>", escape(c));
    }
    h.push_str("</tr></thead><tbody>\n");
    for r in &t.rows {
        h.push_str("<tr>");
        for (i, c) in r.iter().enumerate() {
            let class = if i == 0 { " class=\"name\"" } else { "" };
            let _ = write!(h, "<td{class}>{}</td>", escape(c));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table>\n");
}

fn write_section(h: &mut String, s: &ReportSection) {
    let class = if s.page_break_before { " class=\"page-break\"" } else { "" };
    let _ = write!(h, "<section{class}>\n<h2>{}</h2>\n", escape(&s.title));
    if s.simulated {
        h.push_str(
            "<p class=\"simulated\">SIMULATED DATA: the records of this section were generated by gyrolab's \
             simulator, not measured.</p>\n",
        );
    }
    for p in &s.paragraphs {
        let _ = writeln!(h, "<p>{}</p>", escape(p));
    }
    if !s.figures.is_empty() {
        h.push_str(
            "<table><thead><tr><th class=\"name\">figure</th><th>value</th><th class=\"name\">unit</th>\
             <th>limit</th><th>verdict</th></tr></thead><tbody>\n",
        );
        for f in &s.figures {
            let _ = writeln!(
                h,
                "<tr><td class=\"name\">{}</td><td>{}</td><td class=\"name\">{}</td><td>{}</td><td>{}</td></tr>",
                figure_link(&f.key, &f.label),
                escape(&f.value),
                escape(&f.unit),
                escape(&f.limit),
                f.verdict.map_or_else(String::new, verdict_span)
            );
        }
        h.push_str("</tbody></table>\n");
    }
    for p in &s.plots {
        let _ = writeln!(h, "<figure class=\"plot\">{}<figcaption>{}</figcaption></figure>", p.svg, escape(&p.caption));
    }
    for t in &s.tables {
        write_table(h, t);
    }
    h.push_str("</section>\n");
}

fn write_summary(h: &mut String, s: &SummaryTable, simulated: bool) {
    h.push_str("<section>\n<h2>Summary</h2>\n");
    if !s.checks.is_empty() {
        let o = s.overall();
        let count = |v: Verdict| s.checks.iter().filter(|c| c.verdict == v).count();
        let _ = writeln!(
            h,
            "<p>Overall: <span class=\"verdict overall {}\">{}</span>{} ({} limit check(s): {} passed, {} failed, {} \
             conditional, {} not evaluated)</p>",
            o.text(),
            o.text(),
            if simulated { " <span class=\"sim-tag\">ON SIMULATED DATA</span>" } else { "" },
            s.checks.len(),
            count(Verdict::Pass),
            count(Verdict::Fail),
            count(Verdict::Conditional),
            count(Verdict::NotEvaluated)
        );
        if o == Overall::Incomplete {
            h.push_str(
                "<p class=\"note\">INCOMPLETE: no check failed, but at least one required check could not be \
                 evaluated (reasons below); a check not evaluated never counts as passed.</p>\n",
            );
        }
        for r in s.rules() {
            let _ = writeln!(h, "<p class=\"note\">Decision rule: {}.</p>", escape(r.statement()));
        }
        let undecided: Vec<&LimitCheck> = s
            .checks
            .iter()
            .filter(|c| {
                matches!(c.verdict, Verdict::NotEvaluated | Verdict::Conditional)
                    || c.support.is_some_and(|x| x != Support::Value)
            })
            .collect();
        if !undecided.is_empty() {
            h.push_str("<ul class=\"note\">\n");
            for c in undecided {
                let _ = writeln!(
                    h,
                    "<li>axis {}, {}: {} ({})</li>",
                    escape(&c.axis),
                    escape(&c.figure),
                    c.verdict.text(),
                    escape(c.reason.as_deref().unwrap_or(""))
                );
            }
            h.push_str("</ul>\n");
        }
    } else {
        h.push_str("<p class=\"note\">The plan sets no spec limits: figures are reported without verdicts.</p>\n");
    }
    h.push_str(
        "<table class=\"summary\"><thead><tr><th class=\"name\">figure</th><th class=\"name\">unit</th><th>limit</th>",
    );
    for a in &s.axes {
        let _ = write!(h, "<th>axis {}</th>", escape(a));
    }
    h.push_str("</tr></thead><tbody>\n");
    for r in &s.rows {
        let _ = write!(
            h,
            "<tr><td class=\"name\">{}{} <small>({})</small></td><td class=\"name\">{}</td><td>{}</td>",
            figure_link(&r.key, &r.label),
            if r.simulated { " <span class=\"sim-tag\">SIMULATED</span>" } else { "" },
            escape(&r.key),
            escape(&r.unit),
            escape(&r.limit)
        );
        for (v, verdict) in &r.cells {
            let _ = write!(
                h,
                "<td>{}{}</td>",
                escape(v),
                verdict.map_or_else(String::new, |x| format!(" {}", verdict_span(x)))
            );
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table>\n</section>\n");
}

fn write_methods(h: &mut String, summary: &SummaryTable) {
    h.push_str("<section class=\"page-break\">\n<h2>Appendix: methods</h2>\n<p class=\"note\">Each figure with its formula, unit and source. \
        Notation: Ω_j table rates (deg/s), ȳ_j point means, ȳ_j,fwd and ȳ_j,rev stroke means, K scale factor, \
        F0 zero offset, F_r rest reference, Y_FS full-scale output. Sources: [P] Cheng et al. 2014 (the paper), \
        [GJB] GJB 2426A-2004 / JJF 1535-2015, [IEEE] IEEE Std 952-1997 / 528, [SP1065] NIST SP 1065, [GUM] JCGM 100:2008 = JJF 1059.1-2012, [GB/T 18459] GB/T 18459-2001 (methods for calculating the main static performance specifications of transducers: Y_FS, linearity, hysteresis, repeatability). \
        Full definitions: docs/METHODS.md of gyrolab.</p>\n");
    // Every group in catalogue order.
    let mut groups: Vec<FigureGroup> = Vec::new();
    for d in FIGURES {
        if !groups.contains(&d.group) {
            groups.push(d.group);
        }
    }
    for group in groups {
        let _ = writeln!(h, "<h3>{}</h3>", group.title());
        h.push_str("<table class=\"methods\"><thead><tr><th class=\"name\">figure</th><th class=\"name\">key</th><th class=\"name\">formula</th><th class=\"name\">unit</th><th class=\"name\">source</th></tr></thead><tbody>\n");
        for d in FIGURES.iter().filter(|d| d.group == group) {
            // The report's own name of the figure where its axes gave it one (the bias is
            // absolute against a plan's nominal null, not a shift): the appendix agrees with the
            // tables it explains.
            let label = summary.rows.iter().find(|r| r.key == d.key).map_or(d.label, |r| r.label.as_str());
            let _ = writeln!(
                h,
                "<tr id=\"{}\"><td class=\"name\">{}</td><td class=\"name\">{}</td><td class=\"name\">{}</td><td class=\"name\">{}</td><td class=\"name\">{}</td></tr>",
                anchor(d.key),
                escape(label),
                escape(d.key),
                escape(d.formula),
                escape(d.unit),
                escape(d.source)
            );
        }
        h.push_str("</tbody></table>\n");
    }
    h.push_str("</section>\n");
}

/// The test conditions and the equipment table of the header (blank cells where the plan gives
/// nothing, so that a printed report can be completed by hand).
fn write_conditions(h: &mut String, t: &TestConditions, equipment: &[EquipmentRow]) {
    let text = |v: &Option<String>| v.as_deref().map_or(String::new(), escape);
    let num =
        |v: Option<f64>, unit: &str| v.map_or(String::new(), |x| format!("{} {unit}", gyrolab::format::short(x, 4)));
    h.push_str("<table class=\"conditions\"><caption>Test conditions</caption><tbody>\n");
    let test_dates = match (&t.test_date, &t.test_date_end) {
        (Some(a), Some(b)) if a != b => format!("{} to {}", escape(a), escape(b)),
        _ => text(&t.test_date),
    };
    let rows = [
        ("laboratory", text(&t.laboratory)),
        ("laboratory address", text(&t.laboratory_address)),
        ("customer", text(&t.customer)),
        ("customer contact", text(&t.customer_contact)),
        ("item condition on receipt", text(&t.item_condition)),
        ("receipt date", text(&t.receipt_date)),
        ("sampling", text(&t.sampling)),
        ("test date", test_dates),
        ("site", text(&t.site)),
        ("procedure", text(&t.procedure)),
        ("ambient temperature", num(t.ambient_temperature_c, "degC")),
        ("ambient relative humidity", num(t.ambient_humidity_pct, "%")),
        ("operator", text(&t.operator)),
    ];
    for (k, v) in rows {
        let _ = writeln!(h, "<tr><th class=\"name\">{k}</th><td class=\"name\">{v}</td></tr>");
    }
    h.push_str("</tbody></table>\n");
    let _ = writeln!(
        h,
        "<p class=\"note\"><b>Deviations from the method:</b> {}</p>",
        t.deviations.as_deref().map_or_else(|| "none stated in the plan ([test] deviations).".to_string(), escape)
    );
    h.push_str("<table class=\"equipment\"><caption>Equipment</caption><thead><tr><th class=\"name\">equipment</th><th class=\"name\">model</th><th class=\"name\">identifier</th><th class=\"name\">calibration due</th><th class=\"name\">status on the test date</th></tr></thead><tbody>\n");
    if equipment.is_empty() {
        h.push_str("<tr><td class=\"name\" colspan=\"5\">none listed in the plan ([[equipment]])</td></tr>\n");
    }
    for e in equipment {
        let (cls, status) = match e.status {
            CalibrationStatus::Valid => ("PASS", "within calibration"),
            CalibrationStatus::Expired => ("FAIL", "CALIBRATION EXPIRED"),
            CalibrationStatus::NotStated => ("NOT_EVALUATED", "due date not stated"),
        };
        let _ = writeln!(
            h,
            "<tr><td class=\"name\">{}</td><td class=\"name\">{}</td><td class=\"name\">{}</td><td class=\"name\">{}</td><td class=\"name\"><span class=\"verdict {cls}\">{status}</span></td></tr>",
            escape(&e.name),
            text(&e.model),
            escape(&e.id),
            text(&e.calibration_due)
        );
    }
    h.push_str("</tbody></table>\n");
}

/// The comment lines around the sign-off block: `gyrolab store issue` replaces everything
/// between them (both included) with the issued report's signature block (crate gyrolab-store,
/// `issue`).
pub const SIGNATURE_BLOCK_BEGIN: &str = "<!-- gyrolab:signature-block:begin -->";
/// See [`SIGNATURE_BLOCK_BEGIN`].
pub const SIGNATURE_BLOCK_END: &str = "<!-- gyrolab:signature-block:end -->";

/// The sign-off block: who tested and who approves, each with a signature and a date to fill
/// in by hand, marked DRAFT (a report is issued, numbered and signed by `gyrolab store issue`,
/// which replaces this block between its markers).
fn write_sign_off(h: &mut String, t: &TestConditions) {
    let name = |v: &Option<String>| v.as_deref().map_or(String::new(), escape);
    h.push_str(SIGNATURE_BLOCK_BEGIN);
    h.push('\n');
    h.push_str("<section class=\"sign-off\">\n<h2>Sign-off</h2>\n<p class=\"note\"><b>DRAFT: not issued.</b> An issued report carries its report number, issue date and electronic signature here (gyrolab store issue).</p>\n<table class=\"sign-off\"><thead><tr><th class=\"name\">role</th><th class=\"name\">name</th><th class=\"name\">signature</th><th class=\"name\">date</th></tr></thead><tbody>\n");
    for (role, who) in [("tested by", &t.operator), ("approved by", &t.approver)] {
        let _ = writeln!(
            h,
            "<tr><td class=\"name\">{role}</td><td class=\"name\">{}</td><td class=\"sign\"></td><td class=\"sign\"></td></tr>",
            name(who)
        );
    }
    h.push_str("</tbody></table>\n</section>\n");
    h.push_str(SIGNATURE_BLOCK_END);
    h.push('\n');
}

/// The printed page's margin boxes: the report number at the foot of every page and "page x of
/// y" beside it (CSS Paged Media margin boxes, printed by Chromium 131 and later).
fn page_style(report_number: &str) -> String {
    // A CSS string: only printable characters, quotes and backslashes escaped.
    let number: String = report_number
        .chars()
        .filter(|c| !c.is_control())
        .flat_map(|c| match c {
            '"' | '\\' | '<' | '>' => format!("\\{:x} ", c as u32).chars().collect::<Vec<_>>(),
            c => vec![c],
        })
        .collect();
    format!(
        "\n@page {{ @bottom-left {{ content: \"Report {number}\"; font-size: 8pt; color: #333; font-variant-ligatures: none; }} \
         @bottom-right {{ content: \"page \" counter(page) \" of \" counter(pages); font-size: 8pt; color: #333; }} }}\n"
    )
}

/// The inputs of the report with their SHA-256 (`gyrolab verify DIR` recomputes them).
fn write_inputs(h: &mut String, integrity: &crate::results::IntegrityJson) {
    if integrity.inputs.is_empty() && integrity.plan_sha256.is_none() {
        return;
    }
    h.push_str(
        "<section class=\"inputs\">\n<h2>Inputs and their SHA-256</h2>\n<p class=\"note\">Each input as hashed when it \
         was evaluated; <code>gyrolab verify</code> on this folder recomputes the hashes and names any input that changed.</p>\n\
         <table><thead><tr><th class=\"name\">file</th><th>bytes</th><th class=\"name\">SHA-256</th></tr></thead><tbody>\n",
    );
    if let (Some(sha), Some(copy)) = (&integrity.plan_sha256, &integrity.plan_copy) {
        let _ = writeln!(
            h,
            "<tr><td class=\"name\">plan (copy: {})</td><td></td><td class=\"name\"><code>{}</code></td></tr>",
            escape(copy),
            escape(sha)
        );
    }
    for i in &integrity.inputs {
        let _ = writeln!(
            h,
            "<tr><td class=\"name\">{}</td><td>{}</td><td class=\"name\"><code>{}</code></td></tr>",
            escape(&i.file),
            i.size_bytes,
            escape(&i.sha256)
        );
    }
    h.push_str("</tbody></table>\n</section>\n");
}

/// Renders the whole report as one self-contained HTML document.
pub fn render_html(r: &Report) -> String {
    let hd = &r.header;
    let mut h = String::with_capacity(256 * 1024);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{CSS}{}</style>\n</head>\n<body>\n",
        escape(&hd.title),
        page_style(&hd.report_number)
    );
    let simulated = r.simulated();
    if simulated {
        // Fixed in print: Chromium repeats it at the foot of every printed page.
        h.push_str(
            "<div class=\"sim-page\">SIMULATED DATA: some results of this report come from simulated records, \
             not measurements (sections and summary rows marked SIMULATED)</div>\n",
        );
    }
    let _ = write!(h, "<header>\n<h1>{}</h1>\n<table class=\"header\">\n", escape(&hd.title));
    let rows = [
        ("report number", &hd.report_number),
        ("issued", &hd.issue_date),
        ("model", &hd.model),
        ("serial", &hd.serial),
        ("axes", &hd.axes.join(", ")),
        ("evaluated", &hd.date),
        ("gyrolab", &hd.gyrolab_version),
        ("plan", &hd.plan_file),
    ];
    for (k, v) in rows {
        let _ = writeln!(h, "<tr><td><b>{k}</b></td><td>{}</td></tr>", escape(v));
    }
    h.push_str("</table>\n");
    h.push_str(
        "<p class=\"note\">The results relate only to the items tested, as received. This report shall not be \
         reproduced except in full.</p>\n",
    );
    write_conditions(&mut h, &hd.test, &hd.equipment);
    for n in &hd.notes {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(n));
    }
    h.push_str("</header>\n");
    write_summary(&mut h, &r.summary, simulated);
    for s in &r.sections {
        write_section(&mut h, s);
    }
    write_sign_off(&mut h, &hd.test);
    write_inputs(&mut h, &hd.integrity);
    write_methods(&mut h, &r.summary);
    let _ = writeln!(h, "<p class=\"end\">End of report {}</p>", escape(&hd.report_number));
    h.push_str("</body>\n</html>\n");
    h
}

/// The rate-table section of one axis: Table-6-style figures with limits and verdicts, the
/// calibration, hysteresis and scale-factor plots, and the Table-2-style point table.
pub fn rate_section(a: &AxisReport<'_>, limits: &[Limit]) -> Result<ReportSection, PlotError> {
    let e = a.evaluation;
    let u = a.output_unit.symbol();
    let (du, df) = a.output_unit.scale_factor_display();
    let figs = crate::rate::rate_figures(&crate::rate::AxisJson::new(a));
    let checks = check_limits(limits, std::slice::from_ref(&figs));
    let row = |key: &str, label: &str, value: String, unit: String| {
        let c = checks.iter().find(|c| c.figure == key);
        FigureRow {
            label: label.into(),
            key: key.into(),
            value,
            unit,
            limit: limits.iter().find(|l| l.figure == key).map_or_else(String::new, Limit::text),
            verdict: c.map(|c| c.verdict),
            // K is shown in a display unit (mV/(deg/s)) of its own.
            axis: (key != "scale_factor").then(|| figs.axis.clone()),
            check_axis: Some(figs.axis.clone()),
        }
    };
    let hyst = if e.options.half_hysteresis { "hysteresis δ_H (half)" } else { "hysteresis δ_H" };
    let mut figures = vec![
        row("scale_factor", "scale factor K", sig(e.scale_factor() * df, 6), format!("{du}/(deg/s)")),
        row("zero_offset", "zero offset F0", sig(e.zero_offset(), 7), u.into()),
        row("", "rest reference F_r", sig(e.rest_reference, 7), u.into()),
        row("", "full-scale output Y_FS", sig(e.full_scale_output, 5), u.into()),
        row("nonlinearity_pct", "nonlinearity K_a", sig(ratio_to_pct(e.nonlinearity), 4), "%".into()),
        row("nonlinearity_ppm", "nonlinearity K_a", sig(ratio_to_ppm(e.nonlinearity), 4), "ppm".into()),
        row("linearity_pct", "linearity δ_L", sig(ratio_to_pct(e.linearity), 4), "% FS".into()),
        row("hysteresis_pct", hyst, sig(ratio_to_pct(e.hysteresis), 4), "% FS".into()),
        row(
            "repeatability_pct",
            &format!("repeatability δ_R (k = {})", e.options.coverage),
            sig_opt(e.repeatability.map(ratio_to_pct), 4),
            "% FS".into(),
        ),
        row("accuracy_pct", "accuracy (sum)", sig_opt(e.accuracy_sum.map(ratio_to_pct), 4), "% FS".into()),
        row("accuracy_rss_pct", "accuracy (RSS)", sig_opt(e.accuracy_rss.map(ratio_to_pct), 4), "% FS".into()),
        row("asymmetry_pct", "asymmetry K_as", sig_opt(e.asymmetry.map(|s| ratio_to_pct(s.asymmetry)), 4), "%".into()),
        row(
            "scale_factor_repeatability_ppm",
            "scale-factor repeatability K_r",
            sig_opt(e.scale_factor_repeatability.as_ref().map(|s| ratio_to_ppm(s.repeatability)), 4),
            "ppm".into(),
        ),
    ];
    // A value printed beside a limit gets the digits that keep the two from contradicting the
    // verdict (the comparison is on the unrounded value).
    for f in figures.iter_mut() {
        let Some(c) = checks.iter().find(|c| c.figure == f.key) else { continue };
        let (Some(v), Some(Support::Value)) = (c.value, c.support) else { continue };
        let (base, factor) = match f.key.as_str() {
            "scale_factor" => (6, df),
            "zero_offset" => (7, 1.0),
            _ => (4, 1.0),
        };
        let n = c.limit().digits_for(v, base);
        if n > base {
            f.value = sig(v * factor, n);
        }
    }
    // A limit on scale_factor is given in output units per deg/s (the JSON key's unit): shown
    // in the row's display unit (mV/(deg/s) for volt outputs), so value and limit share a unit.
    if let Some(l) = limits.iter().find(|l| l.figure == "scale_factor") {
        let shown = Limit { min: l.min.map(|x| x * df), max: l.max.map(|x| x * df), ..l.clone() };
        if let Some(f) = figures.iter_mut().find(|f| f.key == "scale_factor") {
            f.limit = shown.text();
        }
    }
    let mut plots = vec![
        PlotBlock {
            caption: format!(
                "Calibration curve of axis {}: forward (●) and reverse (×) stroke means with the least-squares line; \
                 below, the residuals from the line (the paper's Figures 1 to 3).",
                a.name
            ),
            svg: calibration_plot(a)?,
        },
        PlotBlock {
            caption: format!(
                "Hysteresis of axis {}: forward and reverse stroke means minus the line at each rate.",
                a.name
            ),
            svg: hysteresis_plot(a)?,
        },
    ];
    if let Some(svg) = scale_factor_plot(a) {
        plots.push(PlotBlock {
            caption: format!("Scale factor of each run of axis {} (both strokes), against K from all runs.", a.name),
            svg: svg?,
        });
    }
    let points = DataTable {
        caption: format!("Axis {}: stroke means per rate (as the paper's Table 2) and residuals", a.name),
        header: vec![
            "rate (deg/s)".into(),
            format!("fwd mean ({u})"),
            format!("rev mean ({u})"),
            format!("mean ({u})"),
            format!("line residual ({u})"),
            "a_j (%)".into(),
            format!("fwd std ({u})"),
            format!("rev std ({u})"),
        ],
        rows: e
            .points
            .iter()
            .map(|p| {
                vec![
                    gyrolab::format::short(p.rate_dps, 6),
                    format!("{:.8}", p.forward_mean),
                    format!("{:.8}", p.reverse_mean),
                    format!("{:.8}", p.mean),
                    sig(p.line_residual, 4),
                    sig(ratio_to_pct(p.nonlinearity), 4),
                    sig_opt(p.forward_std, 3),
                    sig_opt(p.reverse_std, 3),
                ]
            })
            .collect(),
    };
    let mut tables = vec![points];
    if let Some(s) = &e.scale_factor_repeatability {
        tables.push(DataTable {
            caption: format!("Axis {}: scale factor per run", a.name),
            header: vec!["run".into(), format!("K ({du}/(deg/s))")],
            rows: s.per_run.iter().map(|(r, k)| vec![r.to_string(), sig(k * df, 6)]).collect(),
        });
    }
    Ok(ReportSection {
        title: format!("Axis {}: rate-table test", a.name),
        simulated: false,
        paragraphs: vec![format!(
            "Record {} ({} layout, {} samples, {} runs × {} rates, output in {u}). Rest reference from {}.",
            a.file,
            a.layout,
            a.samples,
            e.runs,
            e.points.len(),
            match e.rest_reference_source {
                gyrolab::rate_test::RestReferenceSource::RestRecords => "the rest records at start and end",
                gyrolab::rate_test::RestReferenceSource::ZeroRatePoint => "the 0 deg/s point",
                gyrolab::rate_test::RestReferenceSource::FitZeroOffset => "the fitted zero offset (no rest data)",
            }
        )],
        figures,
        plots,
        tables,
        page_break_before: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_anchors() {
        assert_eq!(escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
        assert_eq!(anchor("bias_stability_dph_10s"), "def-bias_stability_dph_-T-s");
        assert_eq!(anchor("nonlinearity_pct"), "def-nonlinearity_pct");
    }

    #[test]
    fn generic_section_renders_simulated_label_and_verdicts() {
        let s = ReportSection {
            title: "Axis x: static test".into(),
            simulated: true,
            figures: vec![FigureRow {
                label: "bias stability".into(),
                key: "bias_stability_dph_10s".into(),
                value: "12".into(),
                unit: "deg/h".into(),
                limit: "≤ 20".into(),
                verdict: Some(Verdict::Pass),
                axis: None,
                check_axis: None,
            }],
            ..Default::default()
        };
        let r = Report { sections: vec![s], ..Default::default() };
        let h = render_html(&r);
        assert!(h.contains("SIMULATED DATA"));
        assert!(h.contains("<span class=\"verdict PASS\">PASS</span>"));
        assert!(
            h.contains("href=\"#def-bias_stability_dph_-T-s\"") && h.contains("id=\"def-bias_stability_dph_-T-s\"")
        );
        assert!(!h.contains("<script"));
        // No ligatures anywhere, the page margins included: "dba4ebff" copies out of the PDF as
        // typed (pypdf read Chromium's "ff" ligature as U+FB00 and the report number failed to
        // match; crates/gyrolab-cli/tests/integration/pdf.rs).
        assert!(h.contains("html { font-variant-ligatures: none;"));
        assert!(page_style("GYR-1-ff")
            .contains("Report GYR-1-ff\"; font-size: 8pt; color: #333; font-variant-ligatures: none;"));
    }
}
