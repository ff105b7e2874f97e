//! `gyrolab eval PLAN.toml --out DIR`: evaluate a test plan and write the report folder
//! (report.html, results.json, calibration.toml, CSV tables). Exit code 3 when a limit fails.
//!
//! The rate-table part per axis, then the static (bias) and Allan part of every
//! `[static.<axis>]` table ([`crate::cmd::static_eval`], shared with `gyrolab demo --out`).

use crate::cmd::rate::{calibration_file, evaluate_record, EvaluatedAxis};
use crate::cmd::static_eval;
use crate::error::{CliError, CliResult};
use crate::output::{print, to_json, write_file};
use clap::Args;
use gyrolab::rate_test::RateTestOptions;
use gyrolab_io::plan::{read_plan, TestPlan};
use gyrolab_io::rate_table::read_rate_table;
use gyrolab_report::figures::{known_figure, rate_figures, AxisFigures};
use gyrolab_report::format::sig;
use gyrolab_report::html::{rate_section, render_html, Report, ReportHeader, ReportSection, SummaryTable};
use gyrolab_report::limits::{Limit, Verdict};
use gyrolab_report::rate::{AxisJson, AxisReport};
use gyrolab_report::results::{DeviceJson, LimitJson, ResultsJson};
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Options of `gyrolab eval`.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// The test plan (TOML; keys in docs/PLAN.md).
    #[arg(value_name = "PLAN.toml")]
    pub plan: PathBuf,
    /// Folder to write report.html, results.json, calibration.toml and the CSV tables into
    /// (created if missing; existing files of the same names are replaced).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// No progress bar and no summary on standard output (errors still go to stderr).
    #[arg(long, short)]
    pub quiet: bool,
}

/// A progress bar on stderr, shown only when stderr is a terminal and not `--quiet`.
pub fn progress(quiet: bool, steps: u64) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(steps);
    if let Ok(style) = ProgressStyle::with_template("{spinner} [{bar:30}] {pos}/{len} {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// Everything a report folder is written from.
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
    /// Further results.json sections by key (`static`, `allan`, `paper`).
    pub extra_json: BTreeMap<String, serde_json::Value>,
    /// Further files (name in DIR, content): the static and Allan CSV tables.
    pub extra_files: Vec<(String, Vec<u8>)>,
}

/// What was written.
pub struct Written {
    /// The files, in writing order.
    pub files: Vec<PathBuf>,
    /// Overall verdict of the limits; `None` without limits.
    pub verdict: Option<Verdict>,
    /// One line per failed check.
    pub failures: Vec<String>,
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |x| x.to_string())
}

/// The per-point CSV of one axis (Table 2 with residuals).
pub fn points_csv(a: &AxisJson) -> String {
    let u = &a.output_unit;
    let mut s = format!(
        "# gyrolab: axis {} rate-table points; output-valued columns in {u}\n\
         rate_dps,fwd_mean,rev_mean,mean,fwd_std,rev_std,line_output,line_residual,nonlinearity_pct,polynomial_residual\n",
        a.name
    );
    for p in &a.points {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            p.rate_dps,
            p.fwd_mean,
            p.rev_mean,
            p.mean,
            opt(p.fwd_std),
            opt(p.rev_std),
            p.line_output,
            p.line_residual,
            p.nonlinearity_pct,
            p.polynomial_residual
        ));
    }
    s
}

/// The per-run scale factors of every axis.
pub fn runs_csv(axes: &[AxisJson]) -> String {
    let mut s = String::from(
        "# gyrolab: scale factor K of each run (both strokes), output units per deg/s\naxis,run,scale_factor,unit\n",
    );
    for a in axes {
        for r in &a.scale_factor_per_run {
            s.push_str(&format!(
                "{},{},{},{}\n",
                csv_field(&a.name),
                r.run,
                r.scale_factor,
                csv_field(&a.scale_factor_unit)
            ));
        }
    }
    s
}

/// The summary CSV: every figure of every axis with its unit, limit and verdict.
pub fn summary_csv(summary: &SummaryTable, figures: &[AxisFigures], limits: &[Limit]) -> String {
    let mut s = String::from("axis,figure,unit,value,limit_min,limit_max,verdict\n");
    for a in figures {
        for row in &summary.rows {
            let l = limits.iter().find(|l| l.figure == row.key);
            let verdict = summary
                .checks
                .iter()
                .find(|c| c.axis == a.axis && c.figure == row.key)
                .map_or("", |c| c.verdict.text());
            s.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                csv_field(&a.axis),
                row.key,
                csv_field(&a.unit_of(&row.key)),
                opt(a.get(&row.key)),
                opt(l.and_then(|l| l.min)),
                opt(l.and_then(|l| l.max)),
                verdict
            ));
        }
    }
    s
}

/// Evaluates nothing: assembles and writes the report folder from evaluated inputs.
pub fn write_report(out: &Path, inputs: ReportInputs<'_>, bar: &ProgressBar) -> CliResult<Written> {
    std::fs::create_dir_all(out)
        .map_err(|e| CliError::Output(format!("{}: cannot create the output folder: {e}", out.display())))?;
    let reports: Vec<AxisReport<'_>> = inputs.axes.iter().map(EvaluatedAxis::report).collect();
    let axis_json: Vec<AxisJson> = reports.iter().map(AxisJson::new).collect();
    let mut figures: Vec<AxisFigures> = axis_json.iter().map(rate_figures).collect();
    for extra in inputs.extra_figures {
        match figures.iter_mut().find(|f| f.axis == extra.axis) {
            Some(f) => {
                extra.values.into_iter().for_each(|(k, v)| f.set(k, v));
                f.simulated.extend(extra.simulated);
            }
            None => figures.push(extra),
        }
    }
    let summary = SummaryTable::build(&figures, &inputs.limits);
    bar.set_message("drawing plots");
    let mut sections = Vec::new();
    for r in &reports {
        sections.push(rate_section(r, &inputs.limits).map_err(|e| CliError::Output(e.to_string()))?);
        bar.inc(1);
    }
    sections.extend(inputs.extra_sections);
    let verdict = if inputs.limits.is_empty() { None } else { Some(summary.overall()) };
    let failures: Vec<String> = summary
        .checks
        .iter()
        .filter(|c| c.verdict == Verdict::Fail)
        .map(|c| {
            let l = Limit { figure: c.figure.clone(), min: c.min, max: c.max };
            format!(
                "axis {}: {} = {} {} (limit {})",
                c.axis,
                c.figure,
                sig(c.value.unwrap_or(f64::NAN), 4),
                c.unit,
                l.text()
            )
        })
        .collect();
    let results = ResultsJson {
        gyrolab_version: inputs.header.gyrolab_version.clone(),
        created: inputs.header.date.clone(),
        plan_file: inputs.header.plan_file.clone(),
        device: inputs.device,
        rate_axes: axis_json.clone(),
        sections: inputs.extra_json,
        limits: inputs.limits.iter().map(|l| LimitJson { figure: l.figure.clone(), min: l.min, max: l.max }).collect(),
        limit_checks: summary.checks.clone(),
        verdict,
    };
    let html = render_html(&Report { header: inputs.header, summary: summary.clone(), sections });
    bar.set_message("writing files");
    let mut files: Vec<(PathBuf, Vec<u8>)> =
        vec![(out.join("report.html"), html.into_bytes()), (out.join("results.json"), to_json(&results)?.into_bytes())];
    if !inputs.axes.is_empty() {
        let cal = calibration_file(inputs.axes)
            .to_toml()
            .map_err(|e| CliError::Output(format!("cannot serialise the calibration: {e}")))?;
        files.push((out.join("calibration.toml"), cal.into_bytes()));
    }
    files.push((out.join("summary.csv"), summary_csv(&summary, &figures, &inputs.limits).into_bytes()));
    for a in &axis_json {
        files.push((out.join(format!("points_{}.csv", a.name)), points_csv(a).into_bytes()));
    }
    if axis_json.iter().any(|a| !a.scale_factor_per_run.is_empty()) {
        files.push((out.join("scale_factor_runs.csv"), runs_csv(&axis_json).into_bytes()));
    }
    files.extend(inputs.extra_files.into_iter().map(|(name, bytes)| (out.join(name), bytes)));
    for (path, bytes) in &files {
        write_file(path, bytes)?;
        bar.inc(1);
    }
    Ok(Written { files: files.into_iter().map(|(p, _)| p).collect(), verdict, failures })
}

/// Rate-test options from a plan.
pub fn plan_options(plan: &TestPlan) -> RateTestOptions {
    RateTestOptions {
        coverage: plan.options.coverage,
        half_hysteresis: plan.options.half_hysteresis,
        order: plan.options.order,
        nonlinearity_limit: plan.options.nonlinearity_limit_pct.map(|p| p / 100.0),
    }
}

/// Ends a run: prints what was written (unless quiet) and turns a failed limit into exit code 3.
pub fn finish(out: &Path, written: &Written, quiet: bool) -> CliResult {
    if !quiet {
        let mut s = format!("Wrote {} files to {}:\n", written.files.len(), out.display());
        for f in &written.files {
            s.push_str(&format!(
                "  {}\n",
                f.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned())
            ));
        }
        match written.verdict {
            Some(v) => s.push_str(&format!("Spec limits: {}\n", v.text())),
            None => s.push_str("Spec limits: none in the plan\n"),
        }
        for f in &written.failures {
            s.push_str(&format!("  FAIL {f}\n"));
        }
        print(&s)?;
    }
    if written.verdict == Some(Verdict::Fail) {
        return Err(CliError::LimitFailed(format!(
            "{} spec limit check(s) failed (report written to {}): {}",
            written.failures.len(),
            out.display(),
            written.failures.join("; ")
        )));
    }
    Ok(())
}

/// Runs `gyrolab eval`.
pub fn run(args: &EvalArgs) -> CliResult {
    let plan = read_plan(&args.plan, &|n| known_figure(n).is_some())?;
    let options = plan_options(&plan);
    let steps = 2 * plan.rate.len() as u64 + 6 + 2 * static_eval::progress_steps(&plan.static_tests);
    let bar = progress(args.quiet, steps);
    let mut axes = Vec::new();
    for r in &plan.rate {
        bar.set_message(format!("evaluating axis {}", r.axis));
        let record = read_rate_table(&r.file, &r.columns)?;
        axes.push(evaluate_record(r.axis.clone(), r.file_as_written.clone(), record, &options)?);
        bar.inc(1);
    }
    let mut notes = Vec::new();
    if let Some(l) = plan.options.nonlinearity_limit_pct {
        notes.push(format!("Linear input range searched with a nonlinearity limit of {} %.", sig(l, 4)));
    }
    let limits: Vec<Limit> =
        plan.limits.iter().map(|l| Limit { figure: l.figure.clone(), min: l.min, max: l.max }).collect();
    let base = match plan.file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let ctx = static_eval::StaticContext {
        rate_axes: &axes,
        calibration: plan.options.calibration.as_deref(),
        limits: &limits,
        base: &base,
        simulated: None,
    };
    let parts = static_eval::evaluate_static(&plan.static_tests, &ctx, &bar)?;
    let created = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let header = ReportHeader {
        title: format!("Gyro test report: {} {}", plan.device.model, plan.device.serial),
        model: plan.device.model.clone(),
        serial: plan.device.serial.clone(),
        axes: plan.device.axes.clone(),
        date: created,
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        plan_file: args.plan.display().to_string(),
        notes,
    };
    let inputs = ReportInputs {
        header,
        device: DeviceJson {
            model: plan.device.model.clone(),
            serial: plan.device.serial.clone(),
            axes: plan.device.axes.clone(),
            description: plan.device.description.clone(),
        },
        axes: &axes,
        limits,
        extra_figures: parts.figures,
        extra_sections: parts.sections,
        extra_json: parts.json,
        extra_files: parts.files,
    };
    let written = write_report(&args.out, inputs, &bar)?;
    bar.finish_and_clear();
    finish(&args.out, &written, args.quiet)
}
