//! Evaluation of a TOML test plan ([`gyrolab_io::test_plan`], keys in docs/PLAN.md) into a
//! report folder: the rate-table records per axis (long, wide or raw logs), a three-axis set,
//! then the static (bias) and Allan part of every `[static.<axis>]` table, then the g-sensitivity
//! of every `[g_sensitivity.<axis>]` table.

pub mod g_sensitivity;
pub mod power_ups;
pub mod static_part;
pub mod temperature;
pub mod threshold;
pub mod uncertainty;

use crate::report_folder::{assemble_report, ReportFolder, ReportInputs};
use gyrolab::format::sig;
use gyrolab::limits::Limit;
use gyrolab::triad::TableAxis;
use gyrolab_eval::error::EvalResult;
use gyrolab_eval::progress::Progress;
use gyrolab_eval::rate::raw_log::{evaluate_channels, segment_file, SegmentationRequest, SegmentedLog};
use gyrolab_eval::rate::{evaluate_record, is_raw_log, EvaluatedAxis, RateSettings};
use gyrolab_eval::triad::{evaluate_triad, TriadRequest};
use gyrolab_eval::EvalError;
use gyrolab_io::rate_table::read_rate_table;
use gyrolab_io::test_plan::{read_plan, SegmentationPlan, TestPlan};
use gyrolab_io::DataError;
use gyrolab_report::html::{DataTable, ReportHeader, ReportSection};
use gyrolab_report::results::{DeviceJson, InputJson, IntegrityJson};
use gyrolab_report::segments::SegmentationJson;
use gyrolab_report::triad::triad_json;
use std::path::{Path, PathBuf};

/// The name of the plan's copy in a report folder.
pub const PLAN_COPY: &str = "plan_copy.toml";

/// Reads and checks a plan file ([`gyrolab_io::test_plan::read_plan`]: limit names are checked
/// against the figure catalogue; a limit on a figure that cannot carry one is refused with the
/// reason, naming the plan's line).
pub fn read_test_plan(path: &Path) -> EvalResult<TestPlan> {
    Ok(read_plan(path)?)
}

/// Rate-test settings of a plan.
pub fn plan_settings(plan: &TestPlan) -> RateSettings {
    RateSettings {
        coverage: plan.options.coverage,
        half_hysteresis: plan.options.half_hysteresis,
        order: plan.options.order as i64,
        nonlinearity_limit_pct: plan.options.nonlinearity_limit_pct,
    }
}

/// The segmentation request of a plan's raw-log keys.
pub fn segmentation_request(p: &SegmentationPlan) -> SegmentationRequest {
    SegmentationRequest {
        table_rate_column: p.table_rate_column.clone(),
        steady_tolerance_dps: p.steady_tolerance_dps,
        min_plateau_s: p.min_plateau_s,
        settling_s: p.settling_s,
        rest_tolerance_dps: p.rest_tolerance_dps,
        manual_segments: p.segments.clone(),
    }
}

/// Number of progress steps of a plan's evaluation.
pub fn progress_steps(plan: &TestPlan) -> u64 {
    2 * plan.rate.len() as u64
        + 6
        + 2 * static_part::progress_steps(&plan.static_tests)
        + plan.triad.is_some() as u64
        + temperature::progress_steps(&plan.temperature)
        + threshold::progress_steps(&plan.threshold, &plan.resolution)
        + power_ups::progress_steps(plan)
        + g_sensitivity::progress_steps(&plan.g_sensitivity)
}

/// The rate-table part of a plan: the evaluated axes in device axis order, and the raw logs they
/// came from as (axis, segmented log).
pub type PlanRates = (Vec<EvaluatedAxis>, Vec<(String, SegmentedLog)>);

/// Evaluates the `[rate.<axis>]` records of a plan, in device axis order.
pub fn evaluate_plan_rates(plan: &TestPlan, progress: &dyn Progress) -> EvalResult<PlanRates> {
    let options = plan_settings(plan).options()?;
    let mut axes = Vec::new();
    let mut logs = Vec::new();
    for r in &plan.rate {
        progress.message(&format!("evaluating axis {}", r.axis));
        if is_raw_log(&r.file, r.raw)? {
            let request = segmentation_request(&r.segmentation);
            let seg_options = request.options()?;
            let log = segment_file(&r.file, &request, &seg_options, r.columns.output.as_deref())?;
            if log.log.header.channels.len() != 1 {
                let names: Vec<&str> = log.log.header.channels.iter().map(|c| c.name.as_str()).collect();
                return Err(EvalError::Data(DataError::new(
                    &r.file,
                    format!(
                        "rate.{}: the raw log has {} output columns ({}): name the one of this axis with \
                         rate.{}.output_column",
                        r.axis,
                        names.len(),
                        names.join(", "),
                        r.axis
                    ),
                )));
            }
            let mut name = Some(r.axis.clone());
            let mut evaluated = evaluate_channels(&log, &options, &seg_options, &mut || name.take())?;
            for a in &mut evaluated {
                a.file = r.file_as_written.clone();
            }
            axes.extend(evaluated);
            logs.push((r.axis.clone(), log));
        } else {
            let record = read_rate_table(&r.file, &r.columns)?;
            axes.push(evaluate_record(r.axis.clone(), r.file_as_written.clone(), record, &options)?);
        }
        progress.advance(1);
    }
    Ok((axes, logs))
}

/// The HTML section of a three-axis calibration.
fn triad_section(t: &gyrolab_eval::outcome::triad::TriadReport<'_>) -> ReportSection {
    let c = &t.fit.calibration;
    let u = t.output_unit.symbol();
    let mut rows = Vec::new();
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        let mut row = vec![axis.to_string()];
        row.extend((0..3).map(|j| sig(c.matrix[i][j], 7)));
        row.push(sig(c.bias[i], 7));
        rows.push(row);
    }
    ReportSection {
        title: "Three-axis calibration (scale factors, misalignments, biases)".into(),
        paragraphs: vec![format!(
            "Output = M · rate + b, fitted by least squares over the steady plateaus of the rotations about the \
             table axes ({}). M in {u}/(deg/s), b in {u}; docs/METHODS.md, three-axis calibration.",
            t.files.iter().map(|(a, f)| format!("{a}: {f}")).collect::<Vec<_>>().join(", ")
        )],
        tables: vec![DataTable {
            caption: format!("Scale-factor and misalignment matrix M ({u}/(deg/s)) and bias b ({u})"),
            header: ["gyro", "M · x", "M · y", "M · z", "b"].map(String::from).to_vec(),
            rows,
        }],
        ..Default::default()
    }
}

/// Evaluates a plan into a report folder (nothing is written).
///
/// ```
/// use gyrolab_eval::progress::Silent;
/// use gyrolab_lab::test_plan::{read_test_plan, evaluate_test_plan};
/// let plan = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paper_plan.toml");
/// let folder = evaluate_test_plan(&read_test_plan(&plan)?, &plan.display().to_string(), &Silent)?;
/// assert!(folder.outputs.iter().any(|o| o.name == "results.json"));
/// assert_eq!(folder.verdict, Some(gyrolab::limits::Overall::Fail)); // the paper's own claims fail
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn evaluate_test_plan(plan: &TestPlan, plan_file: &str, progress: &dyn Progress) -> EvalResult<ReportFolder> {
    // Simulated from the records themselves: a plan without `[device] simulated` whose records
    // include one gyrolab's simulator wrote (its first line says so) is marked as a simulated
    // plan, every figure and table, whatever the plan says (a mixed plan is marked whole).
    if plan.device.simulated.is_none() {
        let simulated: Vec<String> = plan
            .input_files()
            .into_iter()
            .filter(|f| gyrolab_io::provenance::is_gyrolab_simulation(f))
            .map(|f| f.file_name().map_or_else(|| f.display().to_string(), |n| n.to_string_lossy().into_owned()))
            .collect();
        if !simulated.is_empty() {
            let mut marked = plan.clone();
            marked.device.simulated = Some(format!(
                "the records {} were written by gyrolab's simulator (their first line says so), though the plan does not say it is simulated",
                simulated.join(", ")
            ));
            return evaluate_marked(&marked, plan_file, progress);
        }
    }
    evaluate_marked(plan, plan_file, progress)
}

/// [`evaluate_test_plan`] of a plan whose simulated records are declared.
fn evaluate_marked(plan: &TestPlan, plan_file: &str, progress: &dyn Progress) -> EvalResult<ReportFolder> {
    progress.begin(progress_steps(plan));
    // The integrity record is of the bytes evaluated: every input hashed before it is read,
    // with the identity of the file hashed, and checked again once every figure is computed
    // (a file replaced or written while the plan was evaluated is refused, never reported
    // under a hash of other bytes).
    progress.message("hashing the inputs");
    let mut hashed = Vec::new();
    for f in plan.input_files() {
        let (sha256, size_bytes, identity) = gyrolab_io::input_file::sha256_file_identified(&f)?;
        hashed.push((f, sha256, size_bytes, identity));
    }
    let (axes, logs) = evaluate_plan_rates(plan, progress)?;
    let triad = match &plan.triad {
        None => None,
        Some(t) => {
            progress.message("three-axis calibration");
            let request = TriadRequest {
                files: TableAxis::ALL.into_iter().zip(t.files.iter().cloned()).collect(),
                gyro_columns: t.gyro_columns.clone(),
                segmentation: segmentation_request(&t.segmentation),
            };
            let mut result = evaluate_triad(&request)?;
            for ((_, shown), written) in result.files.iter_mut().zip(&t.files_as_written) {
                *shown = written.clone();
            }
            progress.advance(1);
            Some(result)
        }
    };
    let mut notes = Vec::new();
    if let Some(l) = plan.options.nonlinearity_limit_pct {
        notes.push(format!("Linear input range searched with a nonlinearity limit of {} %.", sig(l, 4)));
    }
    let limits: Vec<Limit> = plan
        .limits
        .iter()
        .map(|l| Limit { figure: l.figure.clone(), min: l.min, max: l.max, rule: l.rule, axes: l.axes.clone() })
        .collect();
    let base = match plan.file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let ctx = static_part::StaticContext {
        rate_axes: &axes,
        calibration: plan.options.calibration.as_deref(),
        limits: &limits,
        base: &base,
        simulated: None,
        exports: &plan.options.exports,
        records_simulated: plan.device.simulated.is_some(),
        nominal_nulls: &plan.options.nominal_null,
    };
    let mut parts = static_part::evaluate_static(&plan.static_tests, &ctx, progress)?;
    let more = power_ups::evaluate_power_ups(plan, &ctx, progress)?;
    parts.sections.extend(more.sections);
    parts.figures.extend(more.figures);
    parts.json.extend(more.json);
    parts.files.extend(more.files);
    parts.uncertainty_inputs.extend(more.uncertainty_inputs);
    let steps = threshold::evaluate_threshold(&plan.file, &plan.threshold, &plan.resolution, &axes, &limits, progress)?;
    parts.sections.extend(steps.sections);
    parts.figures.extend(steps.figures);
    parts.json.extend(steps.json);
    parts.files.extend(steps.files);
    parts.uncertainty_inputs.extend(steps.uncertainty_inputs);
    let thermal =
        temperature::evaluate_temperature(&plan.temperature, &plan_settings(plan).options()?, &ctx, progress)?;
    if !thermal.reports.is_empty() {
        let plot_err = |e: gyrolab_report::plot::PlotError| EvalError::Output(e.to_string());
        let mut json = serde_json::Map::new();
        for r in &thermal.reports {
            parts.sections.push(gyrolab_report::thermal::temperature_section(r, &limits).map_err(plot_err)?);
            parts.figures.push(r.figures());
            parts.uncertainty_inputs.extend(uncertainty::temperature_inputs(r));
            json.insert(r.axis.clone(), r.json());
        }
        parts.json.insert("temperature".into(), serde_json::Value::Object(json));
        parts.files.push((
            "temperature_points.csv".into(),
            gyrolab_report::thermal::temperature_points_csv(&thermal.reports).into_bytes(),
        ));
    }
    let g = g_sensitivity::evaluate_g_sensitivity(&plan.g_sensitivity, &ctx, &plan.file, progress)?;
    parts.sections.extend(g.sections);
    parts.figures.extend(g.figures);
    parts.files.extend(g.files);
    parts.uncertainty_inputs.extend(g.uncertainty_inputs);
    if let Some(j) = g.json {
        parts.json.insert("g_sensitivity".into(), j);
    }
    if let Some(u) = &plan.uncertainty {
        let un = uncertainty::evaluate_uncertainty(u, &axes, &parts.reports, &parts.uncertainty_inputs);
        parts.sections.extend(un.sections);
        parts.figures.extend(un.figures);
        parts.json.insert("uncertainty".into(), un.json);
    }
    if !logs.is_empty() {
        let mut seg = serde_json::Map::new();
        for (axis, log) in &logs {
            let value = serde_json::to_value(SegmentationJson::new(&log.report()))
                .map_err(|e| EvalError::Output(e.to_string()))?;
            seg.insert(axis.clone(), value);
            parts.files.push((format!("segments_{axis}.csv"), log.segments_csv().into_bytes()));
        }
        parts.json.insert("segmentation".into(), serde_json::Value::Object(seg));
    }
    if let Some(text) = &plan.device.simulated {
        // Every section, figure and table of a simulated plan is labelled so.
        let label = format!("SIMULATED: {text}");
        for s in &mut parts.sections {
            s.simulated = true;
            if !s.paragraphs.iter().any(|p| p.starts_with("SIMULATED")) {
                s.paragraphs.insert(0, label.clone());
            }
        }
        for f in &mut parts.figures {
            f.simulated = f.values.iter().map(|(k, _)| k.clone()).collect();
        }
        notes.insert(0, format!("{label}. Every figure of this report comes from simulated records."));
    }
    let triad_report = triad.as_ref().map(|t| t.report());
    if let Some(t) = &triad_report {
        parts.sections.insert(0, triad_section(t));
        let value = serde_json::to_value(triad_json(t)).map_err(|e| EvalError::Output(e.to_string()))?;
        parts.json.insert("triad".into(), value);
    }
    let created = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let (test, equipment) = conditions(&plan.test, &plan.equipment, &created);
    // The integrity record: the plan (hashed, and copied into the folder) and every input with
    // its SHA-256 (docs/PLAN.md, `gyrolab verify`).
    let plan_bytes = plan.text.as_bytes().to_vec();
    let plan_sha256 = gyrolab_io::input_file::sha256_hex(&plan_bytes);
    let plan_dir = plan.file.parent().unwrap_or(Path::new("."));
    let mut inputs_json = Vec::new();
    for (f, sha256, size_bytes, identity) in hashed {
        if gyrolab_io::input_file::FileIdentity::at(&f).ok() != Some(identity) {
            return Err(EvalError::Data(gyrolab_io::DataError::new(
                &f,
                "the input changed (replaced, written or removed) while the plan was evaluated: its figures and its hash could be of different bytes; evaluate again once it is settled",
            )));
        }
        // As the plan names it (a re-evaluation reads the store's copies from elsewhere).
        let named = plan.named_input(&f);
        let file = named.strip_prefix(plan_dir).unwrap_or(named).display().to_string();
        inputs_json.push(InputJson { file, sha256, size_bytes });
    }
    parts.files.push((PLAN_COPY.into(), plan_bytes));
    let integrity = IntegrityJson {
        plan_sha256: Some(plan_sha256.clone()),
        plan_copy: Some(PLAN_COPY.into()),
        inputs: inputs_json,
    };
    let report_number = plan
        .test
        .report_number
        .clone()
        .unwrap_or_else(|| crate::report_folder::generated_report_number(&created, &plan_sha256));
    let issue_date = plan.test.issue_date.clone().unwrap_or_else(|| created.get(..10).unwrap_or_default().to_string());
    let mut header = ReportHeader {
        report_number,
        issue_date,
        integrity,
        title: "Gyro test report".into(),
        test,
        equipment,
        model: plan.device.model.clone(),
        serial: plan.device.serial.clone(),
        axes: plan.device.axes.clone(),
        date: created,
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        plan_file: plan_file.to_string(),
        notes,
    };
    // Equipment used past its calibration due date: every verdict withheld under the plan's
    // default rule (ISO/IEC 17025:2017 6.4.7), stated either way.
    let expired: Vec<String> = header
        .equipment
        .iter()
        .filter(|e| e.status == gyrolab_report::results::CalibrationStatus::Expired)
        .map(|e| format!("{} ({}, due {})", e.name, e.id, e.calibration_due.as_deref().unwrap_or("?")))
        .collect();
    let withheld = (!expired.is_empty()
        && plan.options.expired_calibration == gyrolab_io::test_plan::ExpiredCalibration::NotEvaluated)
        .then(|| {
            let ids: Vec<&str> = header
                .equipment
                .iter()
                .filter(|e| e.status == gyrolab_report::results::CalibrationStatus::Expired)
                .map(|e| e.id.as_str())
                .collect();
            format!("equipment used past its calibration due date ({})", ids.join(", "))
        });
    if !expired.is_empty() {
        header.notes.push(format!(
            "CALIBRATION EXPIRED on the test date: {}; {}",
            expired.join("; "),
            match plan.options.expired_calibration {
                gyrolab_io::test_plan::ExpiredCalibration::NotEvaluated =>
                    "every limit check is NOT EVALUATED (expired_calibration = \"not_evaluated\", the default)",
                gyrolab_io::test_plan::ExpiredCalibration::Stated =>
                    "the verdicts stand as the plan's rule expired_calibration = \"stated\" says (a deviation the lab has assessed)",
            }
        ));
    }
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
        triad: triad_report,
        temperature_models: thermal.compensation,
        simulated_rate: plan.device.simulated.clone(),
        withheld,
    };
    let mut folder = assemble_report(inputs, progress)?;
    folder.inputs = std::iter::once(plan.file.clone()).chain(plan.input_files()).collect();
    Ok(folder)
}

/// The report's test conditions and equipment rows: each piece of equipment's calibration status
/// on the test date (the plan's `test.date`, else the evaluation date `created`, RFC 3339).
fn conditions(
    test: &gyrolab_io::test_plan::TestInfo,
    equipment: &[gyrolab_io::test_plan::Equipment],
    created: &str,
) -> (gyrolab_report::results::TestConditions, Vec<gyrolab_report::results::EquipmentRow>) {
    use gyrolab_io::test_plan::parse_date;
    use gyrolab_report::results::{CalibrationStatus, EquipmentRow, TestConditions};
    // In calibration through the test's last day (its range's end where it took several days).
    let on = test
        .date_end
        .as_deref()
        .or(test.date.as_deref())
        .and_then(parse_date)
        .or_else(|| created.get(..10).and_then(parse_date));
    let rows = equipment
        .iter()
        .map(|e| {
            let due = e.calibration_due.as_deref().and_then(parse_date);
            let status = match (due, on) {
                (Some(d), Some(t)) if d < t => CalibrationStatus::Expired,
                (Some(_), _) => CalibrationStatus::Valid,
                (None, _) => CalibrationStatus::NotStated,
            };
            EquipmentRow {
                name: e.name.clone(),
                model: e.model.clone(),
                id: e.id.clone(),
                calibration_due: e.calibration_due.clone(),
                status,
            }
        })
        .collect();
    let conditions = TestConditions {
        operator: test.operator.clone(),
        approver: test.approver.clone(),
        test_date: test.date.clone(),
        site: test.site.clone(),
        procedure: test.procedure.clone(),
        ambient_temperature_c: test.ambient_temperature_c,
        ambient_humidity_pct: test.ambient_humidity_pct,
        customer: test.customer.clone(),
        item_condition: test.item_condition.clone(),
        receipt_date: test.receipt_date.clone(),
        deviations: test.deviations.clone(),
        test_date_end: test.date_end.clone(),
        laboratory: test.laboratory.clone(),
        laboratory_address: test.laboratory_address.clone(),
        customer_contact: test.customer_contact.clone(),
        sampling: test.sampling.clone(),
    };
    (conditions, rows)
}
