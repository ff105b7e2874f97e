//! The paper's worked example (Cheng et al. 2014): its rate tables evaluated, its printed
//! Tables 2, 5 and 6 compared with the recomputation, and its report folder with static and
//! Allan sections on SIMULATED records of the same gyro family (the paper did not publish its
//! raw static records).

use crate::paper;
use crate::report_folder::{assemble_report, ReportFolder, ReportInputs};
use crate::test_plan::static_part::{evaluate_static, static_null_of, StaticContext, StaticParts};
use gyrolab::format::sig;
use gyrolab::rate_test::{RateEvaluation, RateTestOptions};
use gyrolab::sim::{Preset, SensorModel, StaticSpec, TemperatureProfile};
use gyrolab::validate::InvalidOption;
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::progress::Progress;
use gyrolab_eval::rate::{evaluate_text, EvaluatedAxis};
use gyrolab_io::sim_csv::{write_static_csv, SimCsvOptions};
use gyrolab_io::test_plan::StaticAxisPlan;
use gyrolab_report::html::ReportHeader;
use gyrolab_report::paper::{compare_table2, compare_table6, paper_section, ClaimVerdict, ClaimedTable6};
use gyrolab_report::paper::{PrintedTable5Row, Table2Comparison};
use gyrolab_report::results::DeviceJson;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The paper's rate tables evaluated and its printed tables compared.
///
/// ```
/// let demo = gyrolab_lab::demo::evaluate_paper()?;
/// assert_eq!(demo.axes.len(), 3);
/// // Rows 11 and 14 of the printed Table 2 do not reproduce from Table 1 (docs/METHODS.md).
/// let slips: Vec<usize> = demo.table2.iter().filter(|r| !r.differs.is_empty()).map(|r| r.point).collect();
/// assert_eq!(slips, [11, 14]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct PaperDemo {
    /// The three axes, evaluated with the default options.
    pub axes: Vec<EvaluatedAxis>,
    /// Table 2 (axis x) recomputed beside the printed values.
    pub table2: Vec<Table2Comparison>,
    /// Table 5 as printed.
    pub table5: Vec<PrintedTable5Row>,
    /// Table 6 as printed (the paper's claims).
    pub table6_claims: Vec<ClaimedTable6>,
    /// Table 6's claims beside the figures computed from the data.
    pub table6: Vec<ClaimVerdict>,
}

impl PaperDemo {
    /// (axis, evaluation) pairs.
    pub fn evaluations(&self) -> Vec<(&str, &RateEvaluation)> {
        self.axes.iter().map(|a| (a.name.as_str(), &a.evaluation)).collect()
    }
}

/// Evaluates the paper's data (built in).
pub fn evaluate_paper() -> EvalResult<PaperDemo> {
    let options = RateTestOptions::default();
    let mut axes = Vec::new();
    for (axis, name, text) in paper::RATE_TABLES {
        axes.push(evaluate_text(axis, name, text, &options)?);
    }
    let t2 = paper::table2()?;
    let t5 = paper::table5()?;
    let t6 = paper::table6()?;
    let table2 = compare_table2(&t2, &axes[0].evaluation);
    let zero_bias: Vec<(&str, f64)> =
        t5.iter().map(|r| (r.axis.as_str(), gyrolab::fit::mean(&r.tests_v).unwrap_or(f64::NAN))).collect();
    let evals: Vec<(&str, &RateEvaluation)> = axes.iter().map(|a| (a.name.as_str(), &a.evaluation)).collect();
    let table6 = compare_table6(&t6, &evals, &zero_bias);
    Ok(PaperDemo { table2, table5: t5, table6_claims: t6, table6, axes })
}

/// The lengths of the simulated records of the paper's report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperReportRequest {
    /// Length of each simulated static test, s (4 per axis, 100 Hz), 60 to 86 400.
    pub sim_static_s: f64,
    /// Length of the simulated record of each axis's Allan section, s (100 Hz), 60 to 86 400.
    pub sim_allan_s: f64,
}

impl Default for PaperReportRequest {
    fn default() -> Self {
        PaperReportRequest { sim_static_s: 1200.0, sim_allan_s: 7200.0 }
    }
}

/// Sample rate of the simulated static records, Hz.
const SIM_RATE_HZ: f64 = 100.0;
/// Simulated static tests per axis (the paper's Table 5 has four).
const SIM_TESTS: usize = 4;
/// Base of the fixed seeds: axis i, test j (1..=4) uses BASE + 10 i + j; the Allan record j = 9.
const SIM_SEED_BASE: u64 = 201_400;

/// A temporary folder removed when dropped.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn sim_error(path: &Path, e: impl std::fmt::Display) -> EvalError {
    EvalError::Output(format!("{}: cannot write the simulated record: {e}", path.display()))
}

/// Writes one simulated static record.
fn write_sim(path: &Path, model: &SensorModel, spec: &StaticSpec, seed: u64) -> EvalResult {
    let f = std::fs::File::create(path).map_err(|e| sim_error(path, e))?;
    let opts = SimCsvOptions {
        comments: vec!["SIMULATED: gyrolab demo, preset adxrs646 (the paper's gyro family)".into()],
        ..SimCsvOptions::default()
    };
    write_static_csv(std::io::BufWriter::new(f), model, spec, seed, &opts).map_err(|e| sim_error(path, e))?;
    Ok(())
}

/// The static and Allan part of the demo: simulated records of the paper's gyro family
/// (ADXRS646 preset; K and null set to each axis's rate-table K and static null), written to a temporary
/// folder with fixed seeds and evaluated by the same code as `gyrolab eval` (`static_eval`).
fn simulated_static_and_allan(
    request: &PaperReportRequest,
    axes: &[EvaluatedAxis],
    progress: &dyn Progress,
) -> EvalResult<StaticParts> {
    for (field, v) in [("sim_static_s", request.sim_static_s), ("sim_allan_s", request.sim_allan_s)] {
        if !(v.is_finite() && (60.0..=86_400.0).contains(&v)) {
            return Err(InvalidOption::new(field, format!("must be 60 to 86400 seconds, got {v}")).into());
        }
    }
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.subsec_nanos());
    let dir = TempDir(std::env::temp_dir().join(format!("gyrolab-demo-{}-{nanos}", std::process::id())));
    std::fs::create_dir_all(&dir.0).map_err(|e| sim_error(&dir.0, e))?;
    let temperature = TemperatureProfile::Ramp { start_c: 25.0, rate_c_per_h: 15.0 };
    let test_spec = StaticSpec {
        sample_rate_hz: SIM_RATE_HZ,
        duration_s: request.sim_static_s,
        temperature: temperature.clone(),
        latitude_deg: None,
        record_temperature: true,
        ..StaticSpec::default()
    };
    let allan_spec = StaticSpec { duration_s: request.sim_allan_s, ..test_spec.clone() };
    let mut plans = Vec::new();
    let mut texts = BTreeMap::new();
    for (i, a) in axes.iter().enumerate() {
        let cal = a.calibration();
        let model = SensorModel {
            scale_factor_per_dps: cal.scale_factor,
            null: static_null_of(a),
            ..SensorModel::preset(Preset::Adxrs646)
        };
        let seed0 = SIM_SEED_BASE + 10 * i as u64;
        let mut files = Vec::new();
        for j in 1..=SIM_TESTS {
            progress.message(&format!("simulating axis {} static test {j}", a.name));
            let path = dir.0.join(format!("static_{}_{j}.csv", a.name));
            write_sim(&path, &model, &test_spec, seed0 + j as u64)?;
            files.push(path);
        }
        progress.message(&format!("simulating axis {} Allan record", a.name));
        let allan_path = dir.0.join(format!("allan_{}.csv", a.name));
        write_sim(&allan_path, &model, &allan_spec, seed0 + 9)?;
        texts.insert(
            a.name.clone(),
            format!(
                "the records of this section were generated by gyrolab's simulator (preset adxrs646, the paper's gyro \
                 family: ARW 0.6 deg/√h, bias instability 12 deg/h over 10..10000 s, no rate random walk, no bias \
                 temperature coefficient, no earth rate), with K = {} V/(deg/s) and null = {} V set to axis {}'s \
                 rate-table K and static null: {SIM_TESTS} static tests of {} s at {} Hz (seeds {}..{}) and one {} s record at \
                 {} Hz for the Allan analysis (seed {}), temperature ramp 25 degC + 15 degC/h. The paper sampled its \
                 static tests once a second (too coarse for the Allan curve below 2 s) and did not publish its raw \
                 static records; these figures show the evaluation on records of the same gyro class, not the paper's gyros.",
                sig(cal.scale_factor, 6),
                sig(static_null_of(a), 7),
                a.name,
                sig(request.sim_static_s, 6),
                sig(SIM_RATE_HZ, 4),
                seed0 + 1,
                seed0 + SIM_TESTS as u64,
                sig(request.sim_allan_s, 6),
                sig(SIM_RATE_HZ, 4),
                seed0 + 9
            ),
        );
        plans.push(StaticAxisPlan {
            axis: a.name.clone(),
            files,
            sample_rate_hz: SIM_RATE_HZ,
            channel: Some("output_v".into()),
            output_unit: None,
            temperature_channel: Some("temp_c".into()),
            latitude_deg: None,
            allan_file: Some(allan_path),
            allow_motion: false,
        });
    }
    let describe = |axis: &str| texts.get(axis).cloned().unwrap_or_default();
    let ctx = StaticContext {
        rate_axes: axes,
        calibration: None,
        limits: &[],
        base: &dir.0,
        simulated: Some(&describe),
        exports: &[],
        records_simulated: true,
        nominal_nulls: &std::collections::BTreeMap::new(),
    };
    evaluate_static(&plans, &ctx, progress)
}

/// The paper's report folder (`gyrolab demo --out DIR`): the paper's comparison, its rate-table
/// evaluation, and static and Allan sections on SIMULATED records of its gyro family.
pub fn paper_report_folder(request: &PaperReportRequest, progress: &dyn Progress) -> EvalResult<ReportFolder> {
    let demo = evaluate_paper()?;
    let axes = &demo.axes[..];
    progress.begin(axes.len() as u64 + 7 + 2 * (SIM_TESTS as u64 + 1) * axes.len() as u64);
    let (table2, verdicts) = (&demo.table2, &demo.table6);
    let parts = simulated_static_and_allan(request, axes, progress)?;
    let (mut sections, figures, mut json) = (parts.sections, parts.figures, parts.json);
    sections.insert(0, paper_section(table2, verdicts));
    json.insert("paper".into(), serde_json::json!({ "table2_x": table2, "table6": verdicts }));
    let created = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let header = ReportHeader {
        report_number: crate::report_folder::generated_report_number(&created, "demo"),
        issue_date: created.get(..10).unwrap_or_default().to_string(),
        title: "Gyro test report: the paper's worked example".into(),
        model: "MEMS rate gyro, ADXRS family (Cheng et al. 2014)".into(),
        serial: "the paper's three units (axes x, y, z)".into(),
        axes: names.clone(),
        date: created,
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        plan_file: "built-in: the paper's Tables 1, 3, 4 (data/paper/*.csv)".into(),
        notes: vec![
            "The whole test program of a lab (temperature points, repeated power-ups, warm-up, threshold and \
             resolution, g-sensitivity, measurement uncertainty) is shown on SIMULATED records of this gyro class in \
             program_report.html beside this report (its plan: program_plan.toml; results: program_results.json)."
                .into(),
            "Rate-table part: the paper's published data. Static (bias) and Allan sections: SIMULATED records of the \
             paper's gyro family (ADXRS646 preset), because the paper did not publish its raw static records; every \
             such section, table and summary row is labelled SIMULATED."
                .into(),
        ],
        ..Default::default()
    };
    let inputs = ReportInputs {
        header,
        device: DeviceJson {
            model: "MEMS rate gyro, ADXRS family (Cheng et al. 2014)".into(),
            serial: "paper".into(),
            axes: names,
            description: Some("the paper's worked example".into()),
        },
        axes,
        limits: Vec::new(),
        extra_figures: figures,
        extra_sections: sections,
        extra_json: json,
        extra_files: parts.files,
        triad: None,
        temperature_models: Vec::new(),
        simulated_rate: None,
        withheld: None,
    };
    let mut folder = assemble_report(inputs, progress)?;
    folder.outputs.extend(program_outputs(progress)?);
    Ok(folder)
}

/// Seed of the demo's simulated test program (the example's: examples/test_program).
const PROGRAM_SEED: u64 = 2026;

/// The whole test program of a lab on SIMULATED records ([`gyrolab_eval::program_sim`]): its plan and
/// records written to a temporary folder, evaluated as `gyrolab eval` does, and its report folder's
/// files named `program_<file>` (the plan itself as `program_plan.toml`).
fn program_outputs(progress: &dyn Progress) -> EvalResult<Vec<gyrolab_io::provenance::NamedOutput>> {
    progress.message("simulating and evaluating a whole test program");
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.subsec_nanos());
    let dir = TempDir(std::env::temp_dir().join(format!("gyrolab-program-{}-{nanos}", std::process::id())));
    std::fs::create_dir_all(&dir.0).map_err(|e| sim_error(&dir.0, e))?;
    let plan_text = gyrolab_eval::program_sim::write_test_program(&dir.0, PROGRAM_SEED)?;
    let plan = crate::test_plan::read_test_plan(&dir.0.join("plan.toml"))?;
    let folder = crate::test_plan::evaluate_test_plan(&plan, "program_plan.toml", &gyrolab_eval::progress::Silent)?;
    let mut outputs =
        vec![gyrolab_io::provenance::NamedOutput { name: "program_plan.toml".into(), bytes: plan_text.into_bytes() }];
    outputs.extend(
        folder
            .outputs
            .into_iter()
            .map(|o| gyrolab_io::provenance::NamedOutput { name: format!("program_{}", o.name), bytes: o.bytes }),
    );
    Ok(outputs)
}
