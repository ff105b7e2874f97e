//! The threshold and resolution part of a test plan: evaluates the `[threshold.<axis>]` and
//! `[resolution.<axis>]` records with [`gyrolab::threshold`] and returns the report section
//! "Threshold and resolution", the summary figures `threshold_dps` / `resolution_dps`, the
//! results.json sections `threshold` and `resolution` (keyed by axis) and a CSV of the rates tried.

use gyrolab::figures::AxisFigures;
use gyrolab::limits::Limit;
use gyrolab::threshold::{self as core, ThresholdError};
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::progress::Progress;
use gyrolab_eval::rate::EvaluatedAxis;
use gyrolab_io::calibration::read_calibration;
use gyrolab_io::test_plan::{NominalScaleFactor, StepTestPlan};
use gyrolab_io::threshold_record::{read_step_record, StepRecord};
use gyrolab_io::DataError;
use gyrolab_report::html::ReportSection;
use gyrolab_report::threshold::{step_figures, step_section, StepKind, StepReport};
use std::collections::BTreeMap;
use std::path::Path;

/// What the threshold and resolution part adds to a report folder.
#[derive(Default)]
pub struct ThresholdParts {
    /// The section "Threshold and resolution" (none without tests).
    pub sections: Vec<ReportSection>,
    /// Summary figures, one entry per test.
    pub figures: Vec<AxisFigures>,
    /// results.json sections `threshold` and `resolution`, each keyed by axis.
    pub json: BTreeMap<String, serde_json::Value>,
    /// CSV files (name, content).
    pub files: Vec<(String, Vec<u8>)>,
    /// Uncertainty inputs of the figures for the `[uncertainty]` part.
    pub uncertainty_inputs: Vec<super::uncertainty::FigureInput>,
}

/// An error about the plan's table `plan_key` (`threshold.x.base_rate_dps`), at its line.
fn plan_error(plan_file: &Path, t: &StepTestPlan, key: &str, msg: impl std::fmt::Display) -> EvalError {
    EvalError::Data(DataError::new(plan_file, format!("{}.{key}: {msg}", t.key)).at_line(t.line))
}

/// K and where it came from, in the record's output unit.
fn nominal_scale_factor(
    plan_file: &Path,
    t: &StepTestPlan,
    record: &StepRecord,
    rate_axes: &[EvaluatedAxis],
) -> EvalResult<(f64, String)> {
    let unit = record.output_unit;
    let (k, k_unit, source) = match &t.scale_factor {
        NominalScaleFactor::Given(k) => return Ok((*k, format!("the plan ({}.scale_factor)", t.key))),
        NominalScaleFactor::RateTable => {
            let a = rate_axes.iter().find(|a| a.name == t.axis).ok_or_else(|| {
                plan_error(plan_file, t, "scale_factor", format!("no rate-table evaluation of axis {}", t.axis))
            })?;
            let c = a.calibration();
            (
                c.scale_factor,
                c.output_unit,
                format!("this plan's rate-table evaluation of axis {} ({})", t.axis, a.file),
            )
        }
        NominalScaleFactor::CalibrationFile(path) => {
            let cal = read_calibration(path)?;
            let c = cal.axis(Some(&t.axis)).map_err(|m| {
                plan_error(
                    plan_file,
                    t,
                    "scale_factor",
                    format!("not given, and the calibration file {}: {m}", path.display()),
                )
            })?;
            (c.scale_factor, c.output_unit, format!("the calibration file {} (axis {})", path.display(), t.axis))
        }
    };
    if k_unit != unit {
        return Err(plan_error(
            plan_file,
            t,
            "scale_factor",
            format!(
                "K from {source} is in {}/(deg/s) but {} is in {}: give {}.scale_factor in {}/(deg/s) or {}.output_unit",
                k_unit.symbol(),
                t.file_as_written,
                unit.symbol(),
                t.key,
                unit.symbol(),
                t.key
            ),
        ));
    }
    Ok((k, source))
}

/// The core's error as a located error: in the plan (a missing base rate) or in the record.
fn located(plan_file: &Path, t: &StepTestPlan, record: &StepRecord, e: ThresholdError) -> EvalError {
    let line_of = |rate: f64| {
        record.groups.iter().position(|g| g.rate_dps == rate).and_then(|i| record.first_lines.get(i).copied())
    };
    match e {
        ThresholdError::NoReference { rate_dps } if t.base_rate_dps.is_some() => plan_error(
            plan_file,
            t,
            "base_rate_dps",
            format!(
                "{rate_dps} deg/s is not among the rates of {} ({}): the base rate must be one of the file's rates",
                t.file_as_written,
                rates_text(record)
            ),
        ),
        ThresholdError::NoReference { .. } => EvalError::Data(DataError::new(
            &t.file,
            format!(
                "{}.file: no 0 deg/s rows (rates found: {}): the threshold is measured from the zero-rate output",
                t.key,
                rates_text(record)
            ),
        )),
        ThresholdError::TooFewSamples { rate_dps, .. } => {
            let mut d = DataError::new(&t.file, format!("{}.file: {e}", t.key));
            if let Some(l) = line_of(rate_dps) {
                d = d.at_line(l);
            }
            EvalError::Data(d)
        }
        ThresholdError::BadScaleFactor(_) => plan_error(plan_file, t, "scale_factor", e),
        other => EvalError::Data(DataError::new(&t.file, format!("{}.file: {other}", t.key))),
    }
}

fn rates_text(record: &StepRecord) -> String {
    let shown: Vec<String> = record.groups.iter().take(12).map(|g| format!("{}", g.rate_dps)).collect();
    let more = if record.groups.len() > 12 { ", ..." } else { "" };
    format!("{}{more} deg/s", shown.join(", "))
}

/// Evaluates one test.
fn evaluate_one(
    plan_file: &Path,
    t: &StepTestPlan,
    kind: StepKind,
    rate_axes: &[EvaluatedAxis],
) -> EvalResult<StepReport> {
    let record = read_step_record(&t.file, &t.columns)?;
    let (k, source) = nominal_scale_factor(plan_file, t, &record, rate_axes)?;
    let estimate = match t.base_rate_dps {
        Some(b) => core::resolution(&record.groups, b, k),
        None => core::threshold(&record.groups, k),
    }
    .map_err(|e| located(plan_file, t, &record, e))?;
    let simulated = record
        .comments
        .first()
        .filter(|c| c.starts_with(gyrolab_io::provenance::SIMULATOR_MARK.trim_start_matches("# ")))
        .map(|_| {
            let truth: Vec<&str> =
                record.comments.iter().filter(|c| c.starts_with("truth.")).map(String::as_str).collect();
            format!("{} ({})", t.file_as_written, if truth.is_empty() { "simulator".into() } else { truth.join("; ") })
        });
    Ok(StepReport {
        kind,
        axis: t.axis.clone(),
        file: t.file_as_written.clone(),
        output_unit: record.output_unit.symbol().to_string(),
        scale_factor_source: source,
        estimate,
        simulated,
    })
}

/// The CSV of every rate tried (one row per rate and test).
fn rates_csv(reports: &[StepReport]) -> String {
    // Rows from simulated records say so on the first line (issue 33), as the other CSVs do.
    let mut s = match reports.iter().find_map(|r| r.simulated.as_deref()) {
        Some(how) => format!("{}: {}\n", gyrolab_io::provenance::SIMULATED_DATA_MARK, how.replace('\n', " ")),
        None => String::new(),
    };
    s.push_str(
        "axis,test,rate_dps,step_dps,samples,mean_output,mean_output_std_error,output_change,expected_change,ratio,ratio_std_error,pass,marginal,output_unit\n",
    );
    for r in reports {
        let e = &r.estimate;
        for t in &e.tried {
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                r.axis,
                r.kind.word(),
                t.rate_dps,
                t.step_dps,
                t.samples,
                t.mean_output,
                t.std_error,
                t.output_change,
                t.expected_change,
                t.ratio,
                t.ratio_std_error,
                t.pass,
                t.marginal,
                r.output_unit
            ));
        }
    }
    s
}

/// Number of progress steps of this part.
pub fn progress_steps(threshold: &[StepTestPlan], resolution: &[StepTestPlan]) -> u64 {
    (threshold.len() + resolution.len()) as u64
}

/// Evaluates every threshold and resolution test of a plan.
pub fn evaluate_threshold(
    plan_file: &Path,
    threshold: &[StepTestPlan],
    resolution: &[StepTestPlan],
    rate_axes: &[EvaluatedAxis],
    limits: &[Limit],
    progress: &dyn Progress,
) -> EvalResult<ThresholdParts> {
    let mut parts = ThresholdParts::default();
    let mut reports = Vec::new();
    for (tests, kind) in [(threshold, StepKind::Threshold), (resolution, StepKind::Resolution)] {
        for t in tests {
            progress.message(&format!("axis {}: {} test", t.axis, kind.word()));
            reports.push(evaluate_one(plan_file, t, kind, rate_axes)?);
            progress.advance(1);
        }
    }
    if reports.is_empty() {
        return Ok(parts);
    }
    parts.sections.push(step_section(&reports, limits));
    parts.figures = step_figures(&reports);
    parts.uncertainty_inputs = reports.iter().filter_map(super::uncertainty::step_inputs).collect();
    for kind in [StepKind::Threshold, StepKind::Resolution] {
        let mut m = serde_json::Map::new();
        for r in reports.iter().filter(|r| r.kind == kind) {
            m.insert(r.axis.clone(), r.json());
        }
        if !m.is_empty() {
            parts.json.insert(kind.word().into(), serde_json::Value::Object(m));
        }
    }
    parts.files.push(("threshold_resolution.csv".into(), rates_csv(&reports).into_bytes()));
    Ok(parts)
}
