//! `gyrolab demo`: the paper's worked example from data built into the binary.

use crate::cmd::eval::{finish, progress, write_report, ReportInputs};
use crate::cmd::rate::{evaluate_record, EvaluatedAxis};
use crate::cmd::static_eval::{evaluate_static, StaticContext, StaticParts};
use crate::error::{CliError, CliResult};
use crate::output::{print, to_json};
use crate::paper_data;
use clap::Args;
use gyrolab::rate_test::RateTestOptions;
use gyrolab::sim::{Preset, SensorModel, StaticSpec, TemperatureProfile};
use gyrolab_io::plan::StaticAxisPlan;
use gyrolab_io::rate_table::{parse_rate_table, RateColumns};
use gyrolab_io::sim_csv::{write_static_csv, SimCsvOptions};
use gyrolab_report::format::sig;
use gyrolab_report::html::{DataTable, ReportHeader, ReportSection};
use gyrolab_report::paper::{compare_table2, compare_table6, table2_text, table5_text, table6_text};
use gyrolab_report::paper::{ClaimVerdict, Table2Comparison};
use gyrolab_report::rate::{rate_json, rate_summary_table, AxisReport};
use gyrolab_report::results::DeviceJson;
use indicatif::ProgressBar;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Options of `gyrolab demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Print the demo's figures and comparisons as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the paper's report folder (report.html, results.json, calibration.toml, CSV) here.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: no progress bar and no summary on standard output.
    #[arg(long, short, requires = "out")]
    pub quiet: bool,
    /// With --out: length of each simulated static test, s (4 per axis, 100 Hz).
    #[arg(long, value_name = "S", default_value_t = 1200.0, requires = "out")]
    pub sim_static_s: f64,
    /// With --out: length of the simulated record of each axis's Allan section, s (100 Hz);
    /// shorter records run faster but end the Allan curve at a quarter of their length.
    #[arg(long, value_name = "S", default_value_t = 7200.0, requires = "out")]
    pub sim_allan_s: f64,
}

#[derive(Serialize)]
struct DemoJson<'a> {
    rate: gyrolab_report::rate::RateJson,
    table2_x: Vec<gyrolab_report::paper::Table2Comparison>,
    table6: Vec<gyrolab_report::paper::ClaimVerdict>,
    #[serde(skip)]
    _p: std::marker::PhantomData<&'a ()>,
}

/// Runs `gyrolab demo`.
pub fn run(args: &DemoArgs) -> CliResult {
    let options = RateTestOptions::default();
    let mut axes: Vec<EvaluatedAxis> = Vec::new();
    for (axis, name, text) in paper_data::RATE_TABLES {
        let record = parse_rate_table(Path::new(name), text, &RateColumns::default())?;
        axes.push(evaluate_record(axis.into(), name.into(), record, &options)?);
    }
    let reports: Vec<AxisReport<'_>> = axes.iter().map(EvaluatedAxis::report).collect();
    let evals: Vec<(&str, &gyrolab::rate_test::RateEvaluation)> =
        axes.iter().map(|a| (a.name.as_str(), &a.evaluation)).collect();
    let t2 = paper_data::table2()?;
    let t5 = paper_data::table5()?;
    let t6 = paper_data::table6()?;
    let table2 = compare_table2(&t2, &axes[0].evaluation);
    let zero_bias: Vec<(&str, f64)> =
        t5.iter().map(|r| (r.axis.as_str(), gyrolab::fit::mean(&r.tests_v).unwrap_or(f64::NAN))).collect();
    let verdicts = compare_table6(&t6, &evals, &zero_bias);
    if let Some(out) = &args.out {
        return write_paper_report(out, args, &axes, &table2, &verdicts);
    }
    if args.json {
        return print(&to_json(&DemoJson {
            rate: rate_json(&reports),
            table2_x: table2,
            table6: verdicts,
            _p: std::marker::PhantomData,
        })?);
    }
    let mut s = String::new();
    s.push_str("gyrolab demo: the paper's worked example (Cheng et al. 2014, MEMS gyro of the ADXRS family,\n");
    s.push_str("three axes on a rate table, 14 rates, 4 runs of forward and reverse strokes). Data built in.\n\n");
    s.push_str("1. Table 2 (axis x): stroke means recomputed from Table 1 beside the printed values\n");
    s.push_str(&table2_text(&table2));
    let bad: Vec<String> = table2
        .iter()
        .filter(|r| !r.differs.is_empty())
        .map(|r| format!("{} ({} deg/s)", r.point, r.rate_dps))
        .collect();
    if bad.is_empty() {
        s.push_str("\nEvery row agrees with the printed values at their printed precision.\n");
    } else {
        s.push_str(&format!(
            "\nRows {} do not reproduce from Table 1: the printed value differs from the mean of the printed\n\
             Table 1 entries (a slip in the paper). gyrolab uses the means of Table 1.\n",
            bad.join(", ")
        ));
    }
    s.push_str("\n2. Table 5: zero-rate output of the four static tests per axis, means recomputed\n");
    let (t5_text, t5_ok) = table5_text(&t5);
    s.push_str(&t5_text);
    s.push_str(if t5_ok {
        "\nEvery printed mean agrees at its printed precision. (The raw static records were not published.)\n"
    } else {
        "\nSome printed means do not agree with the mean of the printed tests.\n"
    });
    s.push_str("\n3. Rate-table figures computed by gyrolab (definitions in docs/METHODS.md)\n");
    s.push_str(&rate_summary_table(&reports));
    s.push_str("\n\n4. Table 6: the paper's claims beside the figures computed from its own data\n");
    s.push_str(&table6_text(&verdicts, &t6, &evals));
    print(&s)
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

fn sim_error(path: &Path, e: impl std::fmt::Display) -> CliError {
    CliError::Output(format!("{}: cannot write the simulated record: {e}", path.display()))
}

/// Writes one simulated static record.
fn write_sim(path: &Path, model: &SensorModel, spec: &StaticSpec, seed: u64) -> CliResult {
    let f = std::fs::File::create(path).map_err(|e| sim_error(path, e))?;
    let opts = SimCsvOptions {
        comments: vec!["SIMULATED: gyrolab demo, preset adxrs646 (the paper's gyro family)".into()],
        ..SimCsvOptions::default()
    };
    write_static_csv(std::io::BufWriter::new(f), model, spec, seed, &opts).map_err(|e| sim_error(path, e))?;
    Ok(())
}

/// The static and Allan part of the demo: simulated records of the paper's gyro family
/// (ADXRS646 preset; K and null set to each axis's rate-table K and F0), written to a temporary
/// folder with fixed seeds and evaluated by the same code as `gyrolab eval` (`static_eval`).
fn simulated_static_and_allan(args: &DemoArgs, axes: &[EvaluatedAxis], bar: &ProgressBar) -> CliResult<StaticParts> {
    for (name, v) in [("--sim-static-s", args.sim_static_s), ("--sim-allan-s", args.sim_allan_s)] {
        if !(v.is_finite() && (60.0..=86_400.0).contains(&v)) {
            return Err(CliError::Usage(format!("{name} must be 60 to 86400 seconds, got {v}")));
        }
    }
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.subsec_nanos());
    let dir = TempDir(std::env::temp_dir().join(format!("gyrolab-demo-{}-{nanos}", std::process::id())));
    std::fs::create_dir_all(&dir.0).map_err(|e| sim_error(&dir.0, e))?;
    let temperature = TemperatureProfile::Ramp { start_c: 25.0, rate_c_per_h: 15.0 };
    let test_spec = StaticSpec {
        sample_rate_hz: SIM_RATE_HZ,
        duration_s: args.sim_static_s,
        temperature: temperature.clone(),
        latitude_deg: None,
        record_temperature: true,
    };
    let allan_spec = StaticSpec { duration_s: args.sim_allan_s, ..test_spec.clone() };
    let mut plans = Vec::new();
    let mut texts = BTreeMap::new();
    for (i, a) in axes.iter().enumerate() {
        let cal = a.calibration();
        let model = SensorModel {
            scale_factor_per_dps: cal.scale_factor,
            null: cal.zero_offset,
            ..SensorModel::preset(Preset::Adxrs646)
        };
        let seed0 = SIM_SEED_BASE + 10 * i as u64;
        let mut files = Vec::new();
        for j in 1..=SIM_TESTS {
            bar.set_message(format!("simulating axis {} static test {j}", a.name));
            let path = dir.0.join(format!("static_{}_{j}.csv", a.name));
            write_sim(&path, &model, &test_spec, seed0 + j as u64)?;
            files.push(path);
        }
        bar.set_message(format!("simulating axis {} Allan record", a.name));
        let allan_path = dir.0.join(format!("allan_{}.csv", a.name));
        write_sim(&allan_path, &model, &allan_spec, seed0 + 9)?;
        texts.insert(
            a.name.clone(),
            format!(
                "the records of this section were generated by gyrolab's simulator (preset adxrs646, the paper's gyro \
                 family: ARW 0.6 deg/√h, bias instability 12 deg/h over 10..10000 s, no rate random walk, no bias \
                 temperature coefficient, no earth rate), with K = {} V/(deg/s) and null = {} V set to axis {}'s \
                 rate-table K and F0: {SIM_TESTS} static tests of {} s at {} Hz (seeds {}..{}) and one {} s record at \
                 {} Hz for the Allan analysis (seed {}), temperature ramp 25 degC + 15 degC/h. The paper sampled its \
                 static tests once a second (too coarse for the Allan curve below 2 s) and did not publish its raw \
                 static records; these figures show the evaluation on records of the same gyro class, not the paper's gyros.",
                sig(cal.scale_factor, 6),
                sig(cal.zero_offset, 7),
                a.name,
                sig(args.sim_static_s, 6),
                sig(SIM_RATE_HZ, 4),
                seed0 + 1,
                seed0 + SIM_TESTS as u64,
                sig(args.sim_allan_s, 6),
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
        });
    }
    let describe = |axis: &str| texts.get(axis).cloned().unwrap_or_default();
    let ctx =
        StaticContext { rate_axes: axes, calibration: None, limits: &[], base: &dir.0, simulated: Some(&describe) };
    evaluate_static(&plans, &ctx, bar)
}

/// The paper's comparison section: Table 2 recomputed and Table 6's claims beside the data.
fn paper_section(table2: &[Table2Comparison], verdicts: &[ClaimVerdict]) -> ReportSection {
    let t2 = DataTable {
        caption: "Table 2 (axis x): stroke means recomputed from Table 1 beside the printed values (V)".into(),
        header: [
            "rate (deg/s)",
            "fwd computed",
            "fwd printed",
            "rev computed",
            "rev printed",
            "mean computed",
            "mean printed",
            "agrees",
        ]
        .map(String::from)
        .to_vec(),
        rows: table2
            .iter()
            .map(|r| {
                let mut row = vec![sig(r.rate_dps, 6)];
                for k in 0..3 {
                    row.push(format!("{:.8}", r.computed_v[k]));
                    row.push(r.printed[k].clone());
                }
                row.push(if r.differs.is_empty() { "yes".into() } else { format!("NO: {}", r.differs.join(", ")) });
                row
            })
            .collect(),
    };
    let t6 = DataTable {
        caption: "Table 6: the paper's claims beside the figures computed from its own data".into(),
        header: ["axis", "figure", "unit", "computed", "paper claims", "supported by the data"]
            .map(String::from)
            .to_vec(),
        rows: verdicts
            .iter()
            .map(|v| {
                vec![
                    v.axis.clone(),
                    v.figure.to_string(),
                    v.unit.to_string(),
                    if v.unit == "V" { format!("{:.8}", v.computed) } else { sig(v.computed, 5) },
                    v.claimed.clone(),
                    if v.supported { "yes".into() } else { "NO".into() },
                ]
            })
            .collect(),
    };
    ReportSection {
        title: "The paper's printed tables beside the recomputation".into(),
        simulated: false,
        paragraphs: vec![
            "Rows 11 (135 deg/s) and 14 (300 deg/s) of Table 2 do not reproduce from Table 1 (a slip in the paper); \
             gyrolab uses the means of Table 1."
                .into(),
            "The printed linearity, hysteresis, repeatability and accuracy are not supported by the data: the output \
             saturates above about 230 deg/s, so no straight line fits the data to 0.01 %. See docs/METHODS.md section 1."
                .into(),
        ],
        tables: vec![t2, t6],
        page_break_before: true,
        ..Default::default()
    }
}

/// Writes the paper's report folder (`gyrolab demo --out DIR`).
fn write_paper_report(
    out: &Path,
    args: &DemoArgs,
    axes: &[EvaluatedAxis],
    table2: &[Table2Comparison],
    verdicts: &[ClaimVerdict],
) -> CliResult {
    let quiet = args.quiet;
    let bar = progress(quiet, axes.len() as u64 + 7 + 2 * (SIM_TESTS as u64 + 1) * axes.len() as u64);
    let parts = simulated_static_and_allan(args, axes, &bar)?;
    let (mut sections, figures, mut json) = (parts.sections, parts.figures, parts.json);
    sections.insert(0, paper_section(table2, verdicts));
    json.insert("paper".into(), serde_json::json!({ "table2_x": table2, "table6": verdicts }));
    let created = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let header = ReportHeader {
        title: "Gyro test report: the paper's worked example".into(),
        model: "MEMS rate gyro, ADXRS family (Cheng et al. 2014)".into(),
        serial: "the paper's three units (axes x, y, z)".into(),
        axes: names.clone(),
        date: created,
        gyrolab_version: env!("CARGO_PKG_VERSION").into(),
        plan_file: "built-in: the paper's Tables 1, 3, 4 (data/paper/*.csv)".into(),
        notes: vec![
            "Rate-table part: the paper's published data. Static (bias) and Allan sections: SIMULATED records of the \
             paper's gyro family (ADXRS646 preset), because the paper did not publish its raw static records; every \
             such section, table and summary row is labelled SIMULATED."
                .into(),
        ],
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
    };
    let written = write_report(out, inputs, &bar)?;
    bar.finish_and_clear();
    finish(out, &written, quiet)
}
