//! A report folder as named outputs: report.html, results.json, calibration.toml, summary and
//! per-axis CSV tables, assembled from evaluated parts. Nothing is written here: the caller
//! writes the outputs (the command line with `gyrolab_io::atomic::write_folder`, whole or not
//! at all).

use gyrolab::figures::AxisFigures;
use gyrolab::limits::{Limit, Overall, Verdict};
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::outcome::rate::AxisReport;
use gyrolab_eval::outcome::triad::TriadReport;
use gyrolab_eval::progress::Progress;
use gyrolab_eval::rate::{calibration_file, EvaluatedAxis};
use gyrolab_io::provenance::{manifest_json, NamedOutput, MANIFEST};
use gyrolab_report::html::{rate_section, render_html, Report, ReportHeader, ReportSection, SummaryTable};
use gyrolab_report::rate::rate_figures;
use gyrolab_report::rate::AxisJson;
use gyrolab_report::results::{DecisionRuleJson, DeviceJson, LimitJson, ResultsJson};
use gyrolab_report::tables_csv::{points_csv, runs_csv, summary_csv};
use std::collections::BTreeMap;

/// An assembled report folder.
#[derive(Debug, Clone)]
pub struct ReportFolder {
    /// The outputs, in writing order.
    pub outputs: Vec<NamedOutput>,
    /// Overall result of the limits; `None` without limits.
    pub verdict: Option<Overall>,
    /// One line per failed check.
    pub failures: Vec<String>,
    /// One line per check that is CONDITIONAL or NOT EVALUATED, with its reason.
    pub undecided: Vec<String>,
    /// Some results come from simulated records (results.json `simulated`).
    pub simulated: bool,
    /// The files the evaluation read (the plan and its inputs), which no output may overwrite.
    pub inputs: Vec<std::path::PathBuf>,
}

/// The mark a CSV of a report folder with simulated inputs starts with, unless the file's own
/// rows are simulated (it then starts with `# SIMULATED DATA: ...`).
pub const SIMULATED_INPUTS_LINE: &str = "# SIMULATED INPUTS: some results of this report folder come from simulated \
     records (results.json `simulated`; summary.csv column `simulated`); the rows of this file come from records not \
     marked simulated\n";

/// Marks every CSV of a folder with simulated inputs (summary.csv has its `simulated` column):
/// files whose rows come from simulated records already start with `# SIMULATED`; when every
/// record is simulated (`simulated_device`: the plan's `[device] simulated`, also the rate-table
/// records) the others get `# SIMULATED DATA: <how>`, else [`SIMULATED_INPUTS_LINE`].
fn mark_simulated_csvs(outputs: &mut [NamedOutput], simulated_device: Option<&str>) {
    for o in outputs.iter_mut().filter(|o| o.name.ends_with(".csv") && o.name != "summary.csv") {
        if o.bytes.starts_with(b"# SIMULATED") {
            continue;
        }
        let line = match simulated_device {
            Some(how) => format!("{}: {}\n", gyrolab_io::provenance::SIMULATED_DATA_MARK, how.replace('\n', " ")),
            None => SIMULATED_INPUTS_LINE.to_string(),
        };
        o.bytes.splice(0..0, line.into_bytes());
    }
}

/// Everything a report folder is assembled from.
pub struct ReportInputs<'a> {
    /// Report header (device, date, version, plan).
    pub header: ReportHeader,
    /// Device block of results.json.
    pub device: DeviceJson,
    /// Evaluated rate-table axes.
    pub axes: &'a [EvaluatedAxis],
    /// Spec limits.
    pub limits: Vec<Limit>,
    /// Further figures per axis (static bias, Allan), merged into the summary and the limits.
    pub extra_figures: Vec<AxisFigures>,
    /// Sections after the rate-table sections (static bias, Allan; demo: the paper comparison).
    pub extra_sections: Vec<ReportSection>,
    /// Further results.json sections by key (`static`, `allan`, `paper`, `triad`).
    pub extra_json: BTreeMap<String, serde_json::Value>,
    /// Further files (name, content): the static and Allan CSV tables.
    pub extra_files: Vec<(String, Vec<u8>)>,
    /// A three-axis calibration, written into calibration.toml's `[triad]`.
    pub triad: Option<TriadReport<'a>>,
    /// Temperature compensation per axis, written into calibration.toml's `[axis.temperature]`.
    pub temperature_models: Vec<(String, gyrolab_io::calibration::TemperatureSection)>,
    /// The rate-table records are SIMULATED: how (their sections and summary rows say so).
    pub simulated_rate: Option<String>,
    /// Why every limit check is withheld (NOT EVALUATED), when it is: equipment used past its
    /// calibration due date under the plan's default rule.
    pub withheld: Option<String>,
}

fn json<T: serde::Serialize>(value: &T) -> EvalResult<String> {
    serde_json::to_string_pretty(value)
        .map(|s| s + "\n")
        .map_err(|e| EvalError::Output(format!("cannot serialise JSON: {e}")))
}

/// A report number for a plan that gives none: `GYR-<YYYYMMDD>-<8 hex digits>`, the digits from
/// the SHA-256 of the evaluation time and `seed` (the plan's SHA-256), so two evaluations never
/// share one in practice.
///
/// ```
/// let n = gyrolab_lab::report_folder::generated_report_number("2026-11-29T03:10:00Z", "ab");
/// assert!(n.starts_with("GYR-20261129-") && n.len() == 21, "{n}");
/// ```
pub fn generated_report_number(created: &str, seed: &str) -> String {
    let day: String = created.chars().take(10).filter(char::is_ascii_digit).collect();
    let h = gyrolab_io::input_file::sha256_hex(format!("{created}\n{seed}").as_bytes());
    format!("GYR-{day}-{}", &h[..8])
}

/// Assembles the report folder from evaluated inputs.
pub fn assemble_report(inputs: ReportInputs<'_>, progress: &dyn Progress) -> EvalResult<ReportFolder> {
    let reports: Vec<AxisReport<'_>> = inputs.axes.iter().map(EvaluatedAxis::report).collect();
    let axis_json: Vec<AxisJson> = reports.iter().map(AxisJson::new).collect();
    let mut figures: Vec<AxisFigures> = axis_json.iter().map(rate_figures).collect();
    if inputs.simulated_rate.is_some() {
        for f in &mut figures {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
    }
    for extra in inputs.extra_figures {
        match figures.iter_mut().find(|f| f.axis == extra.axis) {
            Some(f) => f.merge(extra),
            None => figures.push(extra),
        }
    }
    let mut summary = SummaryTable::build(&figures, &inputs.limits);
    if let Some(reason) = &inputs.withheld {
        summary.withhold(reason);
    }
    progress.message("drawing plots");
    let mut sections = Vec::new();
    for r in &reports {
        let mut s = rate_section(r, &inputs.limits).map_err(|e| EvalError::Output(e.to_string()))?;
        if let Some(text) = &inputs.simulated_rate {
            s.simulated = true;
            s.paragraphs.insert(0, format!("SIMULATED: {text}"));
        }
        sections.push(s);
        progress.advance(1);
    }
    sections.extend(inputs.extra_sections);
    gyrolab_report::html::round_rows_to_uncertainty(&mut sections, &figures, &inputs.limits);
    gyrolab_report::html::apply_checks(&mut sections, &summary.checks);
    let verdict = if inputs.limits.is_empty() { None } else { Some(summary.overall()) };
    let lines = |keep: &dyn Fn(Verdict) -> bool| -> Vec<String> {
        summary.checks.iter().filter(|c| keep(c.verdict)).map(|c| c.line()).collect()
    };
    let failures = lines(&|v| v == Verdict::Fail);
    let undecided = lines(&|v| matches!(v, Verdict::Conditional | Verdict::NotEvaluated));
    let simulated = inputs.simulated_rate.is_some()
        || figures.iter().any(|f| !f.simulated.is_empty())
        || sections.iter().any(|s| s.simulated);
    let results = ResultsJson {
        simulated,
        report_number: inputs.header.report_number.clone(),
        issue_date: inputs.header.issue_date.clone(),
        integrity: inputs.header.integrity.clone(),
        gyrolab_version: inputs.header.gyrolab_version.clone(),
        created: inputs.header.date.clone(),
        plan_file: inputs.header.plan_file.clone(),
        device: inputs.device,
        test: inputs.header.test.clone(),
        equipment: inputs.header.equipment.clone(),
        rate_axes: axis_json.clone(),
        sections: inputs.extra_json,
        limits: inputs.limits.iter().map(LimitJson::new).collect(),
        limit_checks: summary.checks.clone(),
        decision_rules: DecisionRuleJson::used(&inputs.limits),
        verdict,
    };
    let html = render_html(&Report { header: inputs.header, summary: summary.clone(), sections });
    let mut outputs = vec![
        NamedOutput { name: "report.html".into(), bytes: html.into_bytes() },
        NamedOutput { name: "results.json".into(), bytes: json(&results)?.into_bytes() },
    ];
    if !inputs.axes.is_empty() || inputs.triad.is_some() {
        let mut cal = calibration_file(inputs.axes);
        // Any simulated part marks the calibration (its K, F0 or temperature model may rest on it).
        if simulated {
            cal.simulated = Some(
                inputs.simulated_rate.clone().unwrap_or_else(|| "some of the report's records are simulated".into()),
            );
        }
        for (axis, model) in &inputs.temperature_models {
            if let Some(a) = cal.axes.iter_mut().find(|a| a.name == *axis) {
                a.temperature = Some(model.clone());
            }
        }
        if let Some(t) = &inputs.triad {
            cal.triad = Some(gyrolab_io::calibration::TriadSection::from_calibration(
                &t.fit.calibration,
                ["x".into(), "y".into(), "z".into()],
                t.files.iter().map(|(_, f)| f.clone()).collect(),
                t.output_unit,
            ));
        }
        let text = cal.to_toml().map_err(|e| EvalError::Output(format!("cannot serialise the calibration: {e}")))?;
        outputs.push(NamedOutput { name: "calibration.toml".into(), bytes: text.into_bytes() });
    }
    outputs.push(NamedOutput {
        name: "summary.csv".into(),
        bytes: summary_csv(&summary, &figures, &inputs.limits).into_bytes(),
    });
    for a in &axis_json {
        outputs.push(NamedOutput { name: format!("points_{}.csv", a.name), bytes: points_csv(a).into_bytes() });
    }
    if axis_json.iter().any(|a| !a.scale_factor_per_run.is_empty()) {
        outputs.push(NamedOutput { name: "scale_factor_runs.csv".into(), bytes: runs_csv(&axis_json).into_bytes() });
    }
    outputs.extend(inputs.extra_files.into_iter().map(|(name, bytes)| NamedOutput { name, bytes }));
    if simulated {
        mark_simulated_csvs(&mut outputs, inputs.simulated_rate.as_deref());
    }
    let manifest = manifest_json(&outputs).map_err(|e| EvalError::Output(format!("cannot serialise JSON: {e}")))?;
    outputs.push(NamedOutput { name: MANIFEST.into(), bytes: manifest.into_bytes() });
    Ok(ReportFolder { outputs, verdict, failures, undecided, simulated, inputs: Vec::new() })
}

/// What writing a report folder printed: the files written to `out` and the verdict of the spec
/// limits (on SIMULATED data when it is), each failed and undecided check on a line.
pub fn written_text(out: &std::path::Path, files: &[std::path::PathBuf], folder: &ReportFolder) -> String {
    let mut s = format!("Wrote {} files to {}:\n", files.len(), out.display());
    for f in files {
        s.push_str(&format!("  {}\n", f.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned())));
    }
    match folder.verdict {
        Some(v) if folder.simulated => s.push_str(&format!("Spec limits: {} (on SIMULATED data)\n", v.text())),
        Some(v) => s.push_str(&format!("Spec limits: {}\n", v.text())),
        None => s.push_str("Spec limits: none in the plan\n"),
    }
    for f in &folder.failures {
        s.push_str(&format!("  FAIL {f}\n"));
    }
    for f in &folder.undecided {
        s.push_str(&format!("  {f}\n"));
    }
    s
}

/// Prints the folder's report.html to report.pdf (headless Chromium): the line saying so, or
/// the message of why not (an older report.pdf, which showed an earlier report, removed; the
/// failed spec limits named too).
pub fn print_pdf(out: &std::path::Path, folder: &ReportFolder) -> Result<String, String> {
    match gyrolab_report::pdf::print_report(out) {
        Ok((path, size)) => Ok(format!("Printed report.html to {} ({} kB)\n", path.display(), size.div_ceil(1024))),
        Err(e) => {
            let mut message = e.message(out);
            let stale = out.join("report.pdf");
            if stale.exists() && std::fs::remove_file(&stale).is_ok() {
                message
                    .push_str(" (The older report.pdf of this folder, which showed an earlier report, was removed.)");
            }
            if folder.verdict == Some(Overall::Fail) {
                message.push_str(&format!(
                    " Also {} spec limit check(s) failed: {}",
                    folder.failures.len(),
                    folder.failures.join("; ")
                ));
            }
            Err(message)
        }
    }
}
