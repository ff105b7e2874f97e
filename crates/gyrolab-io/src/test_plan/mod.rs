//! Test plans (TOML) for `gyrolab eval`: the device, the rate-table and static records per
//! axis, evaluation options and spec limits. Every key is documented in docs/PLAN.md.
//!
//! Errors name the plan file, the line and column, and the key (`rate.x.output_unit`): unknown
//! keys (`deny_unknown_fields`), missing files, bad units, limits on unknown figures, axes not
//! listed in `[device] axes`. Relative paths are relative to the plan's folder.

use crate::calibration::line_col;
use crate::rate_table::RateColumns;
use crate::DataError;
use gyrolab::conformity::DecisionRule;
use gyrolab::triad::TableAxis;
use gyrolab::units::{OutputUnit, RateUnit};
use gyrolab::validate::{self, InvalidOption};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod g_sensitivity;
mod power_ups;
pub mod temperature;
mod threshold;
pub mod uncertainty;
pub use g_sensitivity::{GRecordPlan, GSensitivityAxisPlan};
pub use power_ups::{PowerUpsPlan, WarmupPlan, DEFAULT_WARMUP_WINDOW_S};
pub use threshold::{NominalScaleFactor, StepTestPlan};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlan {
    device: RawDevice,
    #[serde(default)]
    options: RawOptions,
    #[serde(default)]
    rate: BTreeMap<String, Spanned<RawRate>>,
    #[serde(default, rename = "static")]
    static_tests: BTreeMap<String, Spanned<RawStatic>>,
    #[serde(default)]
    limits: BTreeMap<String, Spanned<RawLimit>>,
    #[serde(default)]
    triad: Option<Spanned<RawTriad>>,
    #[serde(default)]
    test: RawTest,
    #[serde(default)]
    equipment: Vec<Spanned<RawEquipment>>,
    #[serde(default)]
    temperature: BTreeMap<String, Spanned<temperature::RawTemperature>>,
    uncertainty: Option<uncertainty::RawUncertainty>,
    #[serde(default)]
    threshold: BTreeMap<String, Spanned<threshold::RawThreshold>>,
    #[serde(default)]
    resolution: BTreeMap<String, Spanned<threshold::RawResolution>>,
    #[serde(default)]
    power_ups: BTreeMap<String, Spanned<power_ups::RawPowerUps>>,
    #[serde(default)]
    warmup: BTreeMap<String, Spanned<power_ups::RawWarmup>>,
    #[serde(default)]
    g_sensitivity: BTreeMap<String, Spanned<g_sensitivity::RawGSensitivity>>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTest {
    operator: Option<String>,
    approver: Option<String>,
    date: Option<Spanned<String>>,
    site: Option<String>,
    procedure: Option<String>,
    ambient_temperature_c: Option<Spanned<f64>>,
    ambient_humidity_pct: Option<Spanned<f64>>,
    report_number: Option<Spanned<String>>,
    issue_date: Option<Spanned<String>>,
    customer: Option<String>,
    item_condition: Option<String>,
    receipt_date: Option<Spanned<String>>,
    deviations: Option<String>,
    date_end: Option<Spanned<String>>,
    laboratory: Option<String>,
    laboratory_address: Option<String>,
    customer_contact: Option<String>,
    sampling: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEquipment {
    name: String,
    id: String,
    model: Option<String>,
    calibration_due: Option<Spanned<String>>,
}

/// Raw-log keys, shared by `[rate.<axis>]` and `[triad]` (written out in both, because toml's
/// spans do not survive serde's `flatten`).
struct RawSegmentation<'a> {
    table_rate_column: &'a Option<String>,
    steady_tolerance_dps: &'a Option<Spanned<f64>>,
    min_plateau_s: &'a Option<Spanned<f64>>,
    settling_s: &'a Option<Spanned<f64>>,
    rest_tolerance_dps: &'a Option<Spanned<f64>>,
}

macro_rules! raw_segmentation {
    ($r:expr) => {
        RawSegmentation {
            table_rate_column: &$r.table_rate_column,
            steady_tolerance_dps: &$r.steady_tolerance_dps,
            min_plateau_s: &$r.min_plateau_s,
            settling_s: &$r.settling_s,
            rest_tolerance_dps: &$r.rest_tolerance_dps,
        }
    };
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTriad {
    x: Spanned<String>,
    y: Spanned<String>,
    z: Spanned<String>,
    #[serde(default)]
    gyro_columns: Option<Spanned<Vec<String>>>,
    table_rate_column: Option<String>,
    steady_tolerance_dps: Option<Spanned<f64>>,
    min_plateau_s: Option<Spanned<f64>>,
    settling_s: Option<Spanned<f64>>,
    rest_tolerance_dps: Option<Spanned<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDevice {
    model: String,
    serial: String,
    axes: Spanned<Vec<String>>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    simulated: Option<String>,
    #[serde(default)]
    lot: Option<String>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOptions {
    coverage: Option<Spanned<f64>>,
    half_hysteresis: Option<bool>,
    order: Option<Spanned<i64>>,
    nonlinearity_limit_pct: Option<Spanned<f64>>,
    calibration: Option<Spanned<String>>,
    exports: Option<Spanned<Vec<String>>>,
    decision_rule: Option<Spanned<String>>,
    nominal_null: Option<Spanned<toml::Value>>,
    expired_calibration: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRate {
    file: Spanned<String>,
    rate_column: Option<String>,
    run_column: Option<String>,
    stroke_column: Option<String>,
    output_column: Option<String>,
    rate_unit: Option<Spanned<String>>,
    output_unit: Option<Spanned<String>>,
    raw: Option<bool>,
    segments: Option<Spanned<String>>,
    table_rate_column: Option<String>,
    steady_tolerance_dps: Option<Spanned<f64>>,
    min_plateau_s: Option<Spanned<f64>>,
    settling_s: Option<Spanned<f64>>,
    rest_tolerance_dps: Option<Spanned<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStatic {
    files: Spanned<Vec<String>>,
    sample_rate_hz: Spanned<f64>,
    channel: Option<String>,
    output_unit: Option<Spanned<String>>,
    temperature_channel: Option<String>,
    latitude_deg: Option<Spanned<f64>>,
    allan_file: Option<Spanned<String>>,
    allow_motion: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLimit {
    min: Option<f64>,
    max: Option<f64>,
    rule: Option<Spanned<String>>,
    axes: Option<Spanned<Vec<String>>>,
}

/// The device under test.
#[derive(Debug, Clone, PartialEq)]
pub struct DevicePlan {
    /// Model.
    pub model: String,
    /// Serial number.
    pub serial: String,
    /// Axis names in report order.
    pub axes: Vec<String>,
    /// Free description.
    pub description: Option<String>,
    /// The plan's records are SIMULATED: how they were made (every section, table and summary row
    /// of the report is then labelled SIMULATED with it).
    pub simulated: Option<String>,
    /// Production lot (`lot`), the key of the records store's lot statistics.
    pub lot: Option<String>,
}

/// Who tested, where, under which conditions and to which procedure (`[test]`), for the
/// report's header and sign-off block.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TestInfo {
    /// Who ran the test.
    pub operator: Option<String>,
    /// Who approves the report.
    pub approver: Option<String>,
    /// Date of the test, `YYYY-MM-DD`.
    pub date: Option<String>,
    /// Laboratory or site.
    pub site: Option<String>,
    /// Procedure or standard followed (`GJB 2426A-2004 5.3`).
    pub procedure: Option<String>,
    /// Ambient temperature, degC.
    pub ambient_temperature_c: Option<f64>,
    /// Ambient relative humidity, %.
    pub ambient_humidity_pct: Option<f64>,
    /// The report's number (ISO/IEC 17025:2017 7.8.2.1 b); `None`: gyrolab generates one.
    pub report_number: Option<String>,
    /// The report's issue date, `YYYY-MM-DD`; `None`: the evaluation date.
    pub issue_date: Option<String>,
    /// The customer (7.8.2.1 e).
    pub customer: Option<String>,
    /// The condition of the item when received (7.8.2.1 g).
    pub item_condition: Option<String>,
    /// The date the item was received, `YYYY-MM-DD` (7.8.2.1 h).
    pub receipt_date: Option<String>,
    /// Deviations from, additions to or exclusions from the method (7.8.2.1 l; 7.8.3.1 a).
    pub deviations: Option<String>,
    /// The last date of the test when it took several days, `YYYY-MM-DD`, not before `date`
    /// (7.8.2.1 h: the dates of performance).
    pub date_end: Option<String>,
    /// The laboratory's name (7.8.2.1 a).
    pub laboratory: Option<String>,
    /// The laboratory's address (7.8.2.1 a).
    pub laboratory_address: Option<String>,
    /// The customer's contact information (7.8.2.1 e).
    pub customer_contact: Option<String>,
    /// Reference to the sampling plan and method, where the item was sampled (7.8.2.1 i,
    /// 7.8.5).
    pub sampling: Option<String>,
}

/// One piece of test equipment (`[[equipment]]`): rate table, chamber, data acquisition.
#[derive(Debug, Clone, PartialEq)]
pub struct Equipment {
    /// What it is (`rate table`).
    pub name: String,
    /// Asset number or serial.
    pub id: String,
    /// Make and model.
    pub model: Option<String>,
    /// Calibration due date, `YYYY-MM-DD`.
    pub calibration_due: Option<String>,
    /// 1-based line in the plan.
    pub line: u64,
}

/// A date `YYYY-MM-DD` (Gregorian, years 1900 to 2999) as (year, month, day).
pub fn parse_date(text: &str) -> Option<(u32, u32, u32)> {
    let b = text.as_bytes();
    if b.len() != 10 || b[4] != b'-' || b[7] != b'-' {
        return None;
    }
    let num = |r: std::ops::Range<usize>| text.get(r)?.parse::<u32>().ok();
    let (y, m, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days = match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => return None,
    };
    ((1900..3000).contains(&y) && (1..=days).contains(&d)).then_some((y, m, d))
}

/// Evaluation options (`[options]`).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Coverage factor k of the repeatability (default 3).
    pub coverage: f64,
    /// Quote half the largest forward-reverse difference as hysteresis (default false).
    pub half_hysteresis: bool,
    /// Order of the polynomial model (default 1).
    pub order: usize,
    /// Nonlinearity limit for the linear input range, percent.
    pub nonlinearity_limit_pct: Option<f64>,
    /// An existing calibration file for the static sections (resolved path).
    pub calibration: Option<PathBuf>,
    /// Filter stacks whose noise-parameter files the report folder gets from the static axes'
    /// Allan analyses (`exports = ["kalibr", "px4"]`; docs/EXPORTS.md).
    pub exports: Vec<crate::noise_export::Stack>,
    /// The decision rule of every limit that names none (`decision_rule = "guarded_acceptance"`;
    /// default simple acceptance; docs/PLAN.md, METHODS "Decision rules").
    pub decision_rule: DecisionRule,
    /// The nominal null of each axis, in its output unit (`nominal_null = 2.5` for every axis or
    /// `nominal_null = { x = 2.5, y = 0 }`; 0 for a digital output's zero code): the bias of those
    /// axes is the absolute bias against it. Axes without one keep the bias shift against the
    /// rate test's rest output (docs/PLAN.md, METHODS "Bias").
    pub nominal_null: BTreeMap<String, f64>,
    /// What an item of equipment whose calibration was due before the test date does to the
    /// verdicts (`expired_calibration`; default [`ExpiredCalibration::NotEvaluated`]).
    pub expired_calibration: ExpiredCalibration,
}

/// The plan's rule for equipment used past its calibration due date (`[options]
/// expired_calibration`; ISO/IEC 17025:2017 6.4.7, 6.5: results traceable through equipment in
/// calibration).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExpiredCalibration {
    /// Every limit check is NOT EVALUATED, the reason naming the item (the overall verdict is
    /// then INCOMPLETE): `"not_evaluated"`, the default.
    #[default]
    NotEvaluated,
    /// The verdicts stand; the report states the expired item (a deviation the lab has
    /// assessed and records): `"stated"`.
    Stated,
}

impl ExpiredCalibration {
    /// The plan's spelling.
    pub fn key(self) -> &'static str {
        match self {
            ExpiredCalibration::NotEvaluated => "not_evaluated",
            ExpiredCalibration::Stated => "stated",
        }
    }
}

/// The rate-table record of one axis (`[rate.<axis>]`).
#[derive(Debug, Clone, PartialEq)]
pub struct RateAxisPlan {
    /// Axis name.
    pub axis: String,
    /// The record, resolved against the plan's folder.
    pub file: PathBuf,
    /// The path as written in the plan.
    pub file_as_written: String,
    /// Column names and units, as for `gyrolab rate`.
    pub columns: RateColumns,
    /// Read the file as a raw log even if its header does not say so (`raw = true`).
    pub raw: bool,
    /// Segmentation of a raw log.
    pub segmentation: SegmentationPlan,
}

/// How a raw log (time, table rate, outputs) is segmented: the keys of `gyrolab rate`'s
/// options of the same names; `None` keeps the default.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SegmentationPlan {
    /// Name of the table-rate column.
    pub table_rate_column: Option<String>,
    /// Steadiness tolerance, deg/s.
    pub steady_tolerance_dps: Option<f64>,
    /// Shortest plateau, s.
    pub min_plateau_s: Option<f64>,
    /// Settling time dropped at each plateau's start, s.
    pub settling_s: Option<f64>,
    /// Rest tolerance, deg/s.
    pub rest_tolerance_dps: Option<f64>,
    /// A manual segment file (resolved), instead of finding the segments.
    pub segments: Option<PathBuf>,
}

/// A three-axis calibration set (`[triad]`): raw logs of rotations about the table's x, y and z.
#[derive(Debug, Clone, PartialEq)]
pub struct TriadPlan {
    /// The logs, resolved, in the order x, y, z.
    pub files: [PathBuf; 3],
    /// The paths as written in the plan.
    pub files_as_written: [String; 3],
    /// The gyro output columns x, y, z (empty: the files' three outputs).
    pub gyro_columns: Vec<String>,
    /// Segmentation.
    pub segmentation: SegmentationPlan,
}

/// The static records of one axis (`[static.<axis>]`), evaluated by the static and Allan sections.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticAxisPlan {
    /// Axis name.
    pub axis: String,
    /// Records, one per static test, resolved against the plan's folder.
    pub files: Vec<PathBuf>,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Name of the output column.
    pub channel: Option<String>,
    /// Output unit, overriding the column suffix.
    pub output_unit: Option<OutputUnit>,
    /// Name of the temperature column.
    pub temperature_channel: Option<String>,
    /// Latitude of the test site, degrees (for the earth-rate correction).
    pub latitude_deg: Option<f64>,
    /// Record for the Allan analysis (resolved); `None`: the longest of `files`.
    pub allan_file: Option<PathBuf>,
    /// Evaluate a record of `files` or the Allan record even when the stillness check finds
    /// motion (`allow_motion = true`; the section then says it moved and the Allan analysis is
    /// marked); by default such a record is refused.
    pub allow_motion: bool,
}

/// One spec limit (`[limits] figure = { min = .., max = .. }`).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanLimit {
    /// Figure key (a JSON key with its unit suffix).
    pub figure: String,
    /// Lower bound, inclusive.
    pub min: Option<f64>,
    /// Upper bound, inclusive.
    pub max: Option<f64>,
    /// The decision rule of this limit (`rule = ".."`), else the plan's
    /// [`PlanOptions::decision_rule`].
    pub rule: DecisionRule,
    /// The axes the limit applies to (`axes = ["x"]`); `None`: every axis of the device (each
    /// is then a required check).
    pub axes: Option<Vec<String>>,
    /// 1-based line in the plan.
    pub line: u64,
}

/// A parsed and checked test plan.
#[derive(Debug, Clone, PartialEq)]
pub struct TestPlan {
    /// The plan file.
    pub file: PathBuf,
    /// The plan's text as parsed: the bytes a report hashes and copies (never the file read
    /// again, which may have changed since).
    pub text: String,
    /// The device.
    pub device: DevicePlan,
    /// Options.
    pub options: PlanOptions,
    /// Rate-table records in device axis order.
    pub rate: Vec<RateAxisPlan>,
    /// Static records in device axis order.
    pub static_tests: Vec<StaticAxisPlan>,
    /// Spec limits, by figure name.
    pub limits: Vec<PlanLimit>,
    /// A three-axis calibration set.
    pub triad: Option<TriadPlan>,
    /// Who, where, when, under which conditions (`[test]`).
    pub test: TestInfo,
    /// The equipment used (`[[equipment]]`), in plan order.
    pub equipment: Vec<Equipment>,
    /// Temperature tests at soaked points (`[temperature.<axis>]`), in device axis order.
    pub temperature: Vec<temperature::TemperaturePlan>,
    /// Measurement-uncertainty inputs (`[uncertainty]`); `None`: no uncertainty budgets.
    pub uncertainty: Option<uncertainty::UncertaintyPlan>,
    /// Threshold tests (`[threshold.<axis>]`) in device axis order.
    pub threshold: Vec<StepTestPlan>,
    /// Resolution tests (`[resolution.<axis>]`) in device axis order.
    pub resolution: Vec<StepTestPlan>,
    /// Records of repeated power-ups (`[power_ups.<axis>]`), in device axis order.
    pub power_ups: Vec<PowerUpsPlan>,
    /// Warm-up records from power-on (`[warmup.<axis>]`), in device axis order.
    pub warmup: Vec<WarmupPlan>,
    /// g-sensitivity records (`[g_sensitivity.<axis>]`) in device axis order.
    pub g_sensitivity: Vec<GSensitivityAxisPlan>,
    /// Inputs read from elsewhere than the plan names ([`parse_plan_reading_moved`]): (where
    /// they are read, as the plan names them). Empty for a plan as parsed.
    pub moved_inputs: Vec<(PathBuf, PathBuf)>,
}

impl TestPlan {
    /// Every input file the plan names, resolved against its folder, in plan order, without
    /// repeats (the files a report's integrity record hashes).
    pub fn input_files(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = Vec::new();
        // One traversal of the plan's inputs ([`TestPlan::visit_inputs`]), on a copy.
        let mut copy = TestPlan { text: String::new(), ..self.clone() };
        copy.visit_inputs(&mut |p| {
            if !out.iter().any(|q| q == p) {
                out.push(p.clone());
            }
        });
        out
    }

    /// Calls `f` on every input path of the plan, in plan order (repeats included): the one
    /// list of the fields that name a record file.
    fn visit_inputs(&mut self, f: &mut dyn FnMut(&mut PathBuf)) {
        if let Some(c) = &mut self.options.calibration {
            f(c);
        }
        for r in &mut self.rate {
            f(&mut r.file);
            if let Some(s) = &mut r.segmentation.segments {
                f(s);
            }
        }
        if let Some(t) = &mut self.triad {
            t.files.iter_mut().for_each(&mut *f);
            if let Some(s) = &mut t.segmentation.segments {
                f(s);
            }
        }
        for s in &mut self.static_tests {
            s.files.iter_mut().for_each(&mut *f);
            if let Some(a) = &mut s.allan_file {
                f(a);
            }
        }
        for t in &mut self.temperature {
            for p in &mut t.points {
                p.rate_file.iter_mut().chain(&mut p.static_file).for_each(&mut *f);
            }
        }
        self.threshold.iter_mut().chain(&mut self.resolution).for_each(|s| f(&mut s.file));
        for p in &mut self.power_ups {
            p.rate_files.iter_mut().chain(&mut p.static_files).for_each(|(file, _)| f(file));
        }
        self.warmup.iter_mut().for_each(|w| f(&mut w.file));
        for g in &mut self.g_sensitivity {
            g.records.iter_mut().for_each(|r| f(&mut r.file));
        }
    }

    /// The name of input `path` as the plan names it: the path it was read in place of (a plan
    /// parsed by [`parse_plan_reading_moved`]), else `path`.
    pub fn named_input<'a>(&'a self, path: &'a Path) -> &'a Path {
        self.moved_inputs.iter().find(|(now, _)| now == path).map_or(path, |(_, was)| was.as_path())
    }
}

/// Reads and checks a plan file: every `[limits]` name must be in the figure catalogue
/// ([`gyrolab::figures`]) and able to carry a limit (a refusal names the reason and the line).
pub fn read_plan(path: &Path) -> Result<TestPlan, DataError> {
    let text = crate::text::read_text_file(path, crate::text::MAX_CONFIG_BYTES, "a test plan (TOML)")?;
    parse_plan(path, &text)
}

/// Parses and checks a plan's text (as [`read_plan`]; `path` names the file in errors and
/// resolves its relative paths).
pub fn parse_plan(path: &Path, text: &str) -> Result<TestPlan, DataError> {
    parse_plan_reading_moved(path, text, &[])
}

/// [`parse_plan`], each input the plan names at a path of `moved` (as the plan resolves it)
/// read from the path paired with it: a re-evaluation of records kept elsewhere (the records
/// store's copies of inputs named by an absolute path). The report still names them as the plan
/// does ([`TestPlan::named_input`]).
pub fn parse_plan_reading_moved(path: &Path, text: &str, moved: &[(PathBuf, PathBuf)]) -> Result<TestPlan, DataError> {
    let mut plan = parse_plan_with(path, text, &|n| gyrolab::figures::known_figure(n).is_some(), moved)?;
    plan.moved_inputs = moved.iter().map(|(was, now)| (now.clone(), was.clone())).collect();
    for l in &plan.limits {
        if let Some(why) = gyrolab::figures::limit_refusal(&l.figure) {
            return Err(DataError::new(path, format!("limits.{}: {why}", l.figure)).at_line(l.line));
        }
    }
    Ok(plan)
}

pub(crate) struct Ctx<'a> {
    pub(crate) path: &'a Path,
    pub(crate) text: &'a str,
    pub(crate) base: PathBuf,
    /// Inputs read from elsewhere: (as the plan resolves it, where it is read).
    pub(crate) moved: &'a [(PathBuf, PathBuf)],
}

impl Ctx<'_> {
    pub(crate) fn err(&self, span: std::ops::Range<usize>, key: &str, msg: impl std::fmt::Display) -> DataError {
        let (line, col) = line_col(self.text, span.start);
        DataError::new(self.path, format!("{key}: {msg}")).at_line(line).at_column(col, None)
    }

    pub(crate) fn existing_file(&self, key: &str, value: &Spanned<String>) -> Result<PathBuf, DataError> {
        let p = self.base.join(value.get_ref());
        if let Some((_, now)) = self.moved.iter().find(|(was, _)| *was == p) {
            return Ok(now.clone());
        }
        if p.is_file() {
            Ok(p)
        } else {
            Err(self.err(
                value.span(),
                key,
                format!(
                    "file '{}' not found (looked for {}; relative paths start at the plan's folder){}",
                    value.get_ref(),
                    p.display(),
                    // The example test program's plan names the command that writes its records.
                    if self.text.contains("gyrolab simulate test-program") {
                        let dir = if self.base.as_os_str().is_empty() { Path::new(".") } else { &self.base };
                        format!("; write the records with `gyrolab simulate test-program {}`", dir.display())
                    } else {
                        String::new()
                    }
                ),
            ))
        }
    }

    /// Checks a value with a core validator; the error names `key` and its line.
    pub(crate) fn check<T>(
        &self,
        span: std::ops::Range<usize>,
        key: &str,
        r: Result<T, InvalidOption>,
    ) -> Result<T, DataError> {
        r.map_err(|e| self.err(span, key, e.message))
    }

    fn segmentation(
        &self,
        prefix: &str,
        r: &RawSegmentation<'_>,
        segments: Option<&Spanned<String>>,
    ) -> Result<SegmentationPlan, DataError> {
        let key = |k: &str| format!("{prefix}.{k}");
        let num = |v: &Option<Spanned<f64>>, k: &'static str, zero_ok: bool| -> Result<Option<f64>, DataError> {
            v.as_ref()
                .map(|x| {
                    let f = if zero_ok { validate::non_negative } else { validate::positive };
                    self.check(x.span(), &key(k), f(k, *x.get_ref()))
                })
                .transpose()
        };
        Ok(SegmentationPlan {
            table_rate_column: r.table_rate_column.clone(),
            steady_tolerance_dps: num(r.steady_tolerance_dps, "steady_tolerance_dps", false)?,
            min_plateau_s: num(r.min_plateau_s, "min_plateau_s", false)?,
            settling_s: num(r.settling_s, "settling_s", true)?,
            rest_tolerance_dps: num(r.rest_tolerance_dps, "rest_tolerance_dps", true)?,
            segments: segments.map(|f| self.existing_file(&key("segments"), f)).transpose()?,
        })
    }

    pub(crate) fn output_unit(&self, key: &str, v: &Option<Spanned<String>>) -> Result<Option<OutputUnit>, DataError> {
        v.as_ref()
            .map(|s| {
                OutputUnit::parse(s.get_ref()).ok_or_else(|| {
                    self.err(
                        s.span(),
                        key,
                        format!(
                            "unknown output unit '{}': expected v, mv, lsb, dps or rad_s",
                            crate::text::excerpt(s.get_ref())
                        ),
                    )
                })
            })
            .transpose()
    }
}

/// Parses and checks plan text; `path` names it in errors and its folder anchors relative paths.
fn parse_plan_with(
    path: &Path,
    text: &str,
    known_figure: &dyn Fn(&str) -> bool,
    moved: &[(PathBuf, PathBuf)],
) -> Result<TestPlan, DataError> {
    let raw: RawPlan = toml::from_str(text).map_err(|e| {
        let mut d = DataError::new(path, format!("not a valid test plan: {}", crate::text::short_message(e.message())));
        if let Some(span) = e.span() {
            let (line, col) = line_col(text, span.start);
            d = d.at_line(line).at_column(col, None);
        }
        d
    })?;
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let cx = Ctx { path, text, base, moved };

    let axes = raw.device.axes.get_ref().clone();
    if axes.is_empty() {
        return Err(cx.err(
            raw.device.axes.span(),
            "device.axes",
            "no axis: expected a list such as [\"x\", \"y\", \"z\"]",
        ));
    }
    for (i, a) in axes.iter().enumerate() {
        if a.trim().is_empty() || axes[..i].contains(a) {
            return Err(cx.err(raw.device.axes.span(), "device.axes", format!("axis name '{a}' is empty or repeated")));
        }
        if let Err(e) = gyrolab::validate::axis_name("device.axes", a) {
            return Err(cx.err(raw.device.axes.span(), "device.axes", e.message));
        }
    }
    for (table, keys) in [
        ("rate", raw.rate.iter().map(|(k, v)| (k, v.span())).collect::<Vec<_>>()),
        ("static", raw.static_tests.iter().map(|(k, v)| (k, v.span())).collect()),
        ("temperature", raw.temperature.iter().map(|(k, v)| (k, v.span())).collect()),
        ("threshold", raw.threshold.iter().map(|(k, v)| (k, v.span())).collect()),
        ("resolution", raw.resolution.iter().map(|(k, v)| (k, v.span())).collect()),
        ("g_sensitivity", raw.g_sensitivity.iter().map(|(k, v)| (k, v.span())).collect()),
    ] {
        for (k, span) in keys {
            if !axes.contains(k) {
                return Err(cx.err(
                    span,
                    &format!("{table}.{k}"),
                    format!("axis '{k}' is not in device.axes ({})", axes.join(", ")),
                ));
            }
        }
    }
    for a in &axes {
        let step_test = raw.threshold.contains_key(a) || raw.resolution.contains_key(a);
        if !raw.rate.contains_key(a)
            && !raw.static_tests.contains_key(a)
            && !raw.temperature.contains_key(a)
            && !raw.power_ups.contains_key(a)
            && !raw.warmup.contains_key(a)
            && !raw.g_sensitivity.contains_key(a)
            && raw.triad.is_none()
            && !step_test
        {
            return Err(cx.err(
                raw.device.axes.span(),
                "device.axes",
                format!(
                    "axis '{a}' has neither a [rate.{a}] nor a [static.{a}] table (nor [temperature.{a}], \
                     [threshold.{a}], [resolution.{a}], [power_ups.{a}], [warmup.{a}], [g_sensitivity.{a}] or a [triad])"
                ),
            ));
        }
    }

    let o = &raw.options;
    let coverage = match &o.coverage {
        Some(c) => cx.check(c.span(), "options.coverage", validate::positive("coverage", *c.get_ref()))?,
        None => 3.0,
    };
    let order = match &o.order {
        Some(n) => cx.check(n.span(), "options.order", validate::polynomial_order("order", *n.get_ref()))?,
        None => 1,
    };
    if let Some(l) = &o.nonlinearity_limit_pct {
        cx.check(
            l.span(),
            "options.nonlinearity_limit_pct",
            validate::positive_percentage("nonlinearity_limit_pct", *l.get_ref()),
        )?;
    }
    let calibration = o.calibration.as_ref().map(|c| cx.existing_file("options.calibration", c)).transpose()?;
    let mut exports = Vec::new();
    if let Some(list) = &o.exports {
        for name in list.get_ref() {
            let stack = crate::noise_export::Stack::parse(name).ok_or_else(|| {
                let names: Vec<&str> = crate::noise_export::STACKS.iter().map(|s| s.name()).collect();
                cx.err(
                    list.span(),
                    "options.exports",
                    format!("unknown filter stack '{}': expected {}", crate::text::excerpt(name), names.join(", ")),
                )
            })?;
            if !exports.contains(&stack) {
                exports.push(stack);
            }
        }
    }
    let rule_of = |v: &Spanned<String>, key: &str| {
        DecisionRule::parse(v.get_ref()).ok_or_else(|| {
            let names: Vec<&str> = DecisionRule::ALL.iter().map(|r| r.key()).collect();
            cx.err(
                v.span(),
                key,
                format!("unknown decision rule '{}': expected {}", crate::text::excerpt(v.get_ref()), names.join(", ")),
            )
        })
    };
    let decision_rule =
        o.decision_rule.as_ref().map(|r| rule_of(r, "options.decision_rule")).transpose()?.unwrap_or_default();
    let expired_calibration = match &o.expired_calibration {
        None => ExpiredCalibration::default(),
        Some(v) => [ExpiredCalibration::NotEvaluated, ExpiredCalibration::Stated]
            .into_iter()
            .find(|r| r.key() == v.get_ref())
            .ok_or_else(|| {
                cx.err(
                    v.span(),
                    "options.expired_calibration",
                    format!("unknown rule '{}': expected not_evaluated or stated", crate::text::excerpt(v.get_ref())),
                )
            })?,
    };
    let mut nominal_null = BTreeMap::new();
    if let Some(v) = &o.nominal_null {
        let number = |x: &toml::Value, key: &str| -> Result<f64, DataError> {
            let f = x.as_float().or_else(|| x.as_integer().map(|i| i as f64));
            match f {
                Some(f) if f.is_finite() => Ok(f),
                _ => Err(cx.err(
                    v.span(),
                    key,
                    format!(
                        "must be a number in the axis's output unit (the datasheet null voltage, 0 for a digital \
                         output's zero code), got {}",
                        crate::text::excerpt(&x.to_string())
                    ),
                )),
            }
        };
        match v.get_ref() {
            toml::Value::Table(t) => {
                for (axis, x) in t {
                    let key = format!("options.nominal_null.{axis}");
                    if !axes.contains(axis) {
                        return Err(cx.err(
                            v.span(),
                            &key,
                            format!("axis '{axis}' is not in device.axes ({})", axes.join(", ")),
                        ));
                    }
                    nominal_null.insert(axis.clone(), number(x, &key)?);
                }
            }
            x => {
                let f = number(x, "options.nominal_null")?;
                nominal_null.extend(axes.iter().map(|a| (a.clone(), f)));
            }
        }
    }
    let options = PlanOptions {
        nominal_null,
        coverage,
        half_hysteresis: o.half_hysteresis.unwrap_or(false),
        order,
        nonlinearity_limit_pct: o.nonlinearity_limit_pct.as_ref().map(|l| *l.get_ref()),
        calibration,
        exports,
        decision_rule,
        expired_calibration,
    };

    let mut rate = Vec::new();
    let mut static_tests = Vec::new();
    for axis in &axes {
        if let Some(r) = raw.rate.get(axis) {
            let r = r.get_ref();
            let key = |k: &str| format!("rate.{axis}.{k}");
            let rate_unit = r
                .rate_unit
                .as_ref()
                .map(|s| {
                    RateUnit::parse(s.get_ref()).ok_or_else(|| {
                        cx.err(
                            s.span(),
                            &key("rate_unit"),
                            format!("unknown rate unit '{}': expected dps, rad_s or dph", s.get_ref()),
                        )
                    })
                })
                .transpose()?;
            rate.push(RateAxisPlan {
                axis: axis.clone(),
                file: cx.existing_file(&key("file"), &r.file)?,
                file_as_written: r.file.get_ref().clone(),
                columns: RateColumns {
                    rate: r.rate_column.clone(),
                    run: r.run_column.clone(),
                    stroke: r.stroke_column.clone(),
                    output: r.output_column.clone(),
                    rate_unit,
                    output_unit: cx.output_unit(&key("output_unit"), &r.output_unit)?,
                },
                raw: r.raw.unwrap_or(false),
                segmentation: cx.segmentation(&format!("rate.{axis}"), &raw_segmentation!(r), r.segments.as_ref())?,
            });
        }
        if let Some(s) = raw.static_tests.get(axis) {
            let span = s.span();
            let s = s.get_ref();
            let key = |k: &str| format!("static.{axis}.{k}");
            if s.files.get_ref().is_empty() {
                return Err(cx.err(span, &key("files"), "no file: expected one record per static test"));
            }
            let files = s
                .files
                .get_ref()
                .iter()
                .enumerate()
                .map(|(i, f)| {
                    cx.existing_file(&format!("{}[{i}]", key("files")), &Spanned::new(s.files.span(), f.clone()))
                })
                .collect::<Result<Vec<_>, _>>()?;
            let fs = cx.check(
                s.sample_rate_hz.span(),
                &key("sample_rate_hz"),
                validate::positive("sample_rate_hz", *s.sample_rate_hz.get_ref()),
            )?;
            if let Some(l) = &s.latitude_deg {
                cx.check(l.span(), &key("latitude_deg"), validate::latitude_deg("latitude_deg", *l.get_ref()))?;
            }
            if let (Some(u), None) = (&s.output_unit, &s.channel) {
                return Err(cx.err(
                    u.span(),
                    &key("output_unit"),
                    format!("needs {} (the column it applies to)", key("channel")),
                ));
            }
            static_tests.push(StaticAxisPlan {
                axis: axis.clone(),
                files,
                sample_rate_hz: fs,
                channel: s.channel.clone(),
                output_unit: cx.output_unit(&key("output_unit"), &s.output_unit)?,
                temperature_channel: s.temperature_channel.clone(),
                latitude_deg: s.latitude_deg.as_ref().map(|l| *l.get_ref()),
                allan_file: s.allan_file.as_ref().map(|f| cx.existing_file(&key("allan_file"), f)).transpose()?,
                allow_motion: s.allow_motion.unwrap_or(false),
            });
        }
    }

    let mut limits = Vec::new();
    for (name, l) in &raw.limits {
        let key = format!("limits.{name}");
        if !known_figure(name) {
            return Err(cx.err(
                l.span(),
                &key,
                format!("'{name}' is not a figure gyrolab reports: limit names are the JSON keys with their unit, such as nonlinearity_pct or bias_stability_dph_10s (docs/PLAN.md lists them)"),
            ));
        }
        let v = l.get_ref();
        let bad = |x: Option<f64>| x.is_some_and(|x| !x.is_finite());
        if (v.min.is_none() && v.max.is_none()) || bad(v.min) || bad(v.max) {
            return Err(cx.err(l.span(), &key, "expected { min = NUMBER } or { max = NUMBER } or both"));
        }
        if let (Some(lo), Some(hi)) = (v.min, v.max) {
            if lo > hi {
                return Err(cx.err(l.span(), &key, format!("min {lo} is above max {hi}")));
            }
        }
        let rule = v.rule.as_ref().map(|r| rule_of(r, &format!("{key}.rule"))).transpose()?.unwrap_or(decision_rule);
        if let Some(list) = &v.axes {
            if list.get_ref().is_empty() {
                return Err(cx.err(
                    list.span(),
                    &format!("{key}.axes"),
                    "an empty list: name at least one axis, or leave `axes` out for every axis",
                ));
            }
            if let Some(a) = list.get_ref().iter().find(|a| !raw.device.axes.get_ref().contains(a)) {
                return Err(cx.err(
                    list.span(),
                    &format!("{key}.axes"),
                    format!(
                        "axis '{}' is not one of the device's axes ({})",
                        crate::text::excerpt(a),
                        raw.device.axes.get_ref().join(", ")
                    ),
                ));
            }
        }
        limits.push(PlanLimit {
            figure: name.clone(),
            min: v.min,
            max: v.max,
            rule,
            axes: v.axes.as_ref().map(|a| a.get_ref().clone()),
            line: line_col(text, l.span().start).0,
        });
    }
    limits.sort_by_key(|l| l.line);

    let date = |v: &Spanned<String>, key: &str| -> Result<String, DataError> {
        parse_date(v.get_ref()).map(|_| v.get_ref().clone()).ok_or_else(|| {
            cx.err(v.span(), key, format!("'{}': expected a date YYYY-MM-DD", crate::text::excerpt(v.get_ref())))
        })
    };
    let t = &raw.test;
    if let Some(c) = &t.ambient_temperature_c {
        let v = *c.get_ref();
        if !(-60.0..=100.0).contains(&v) {
            return Err(cx.err(c.span(), "test.ambient_temperature_c", format!("{v} degC: expected -60 to 100")));
        }
    }
    if let Some(h) = &t.ambient_humidity_pct {
        let v = *h.get_ref();
        if !(0.0..=100.0).contains(&v) {
            return Err(cx.err(h.span(), "test.ambient_humidity_pct", format!("{v} %: expected 0 to 100")));
        }
    }
    let test = TestInfo {
        operator: t.operator.clone(),
        approver: t.approver.clone(),
        date: t.date.as_ref().map(|d| date(d, "test.date")).transpose()?,
        site: t.site.clone(),
        procedure: t.procedure.clone(),
        ambient_temperature_c: t.ambient_temperature_c.as_ref().map(|v| *v.get_ref()),
        ambient_humidity_pct: t.ambient_humidity_pct.as_ref().map(|v| *v.get_ref()),
        report_number: t
            .report_number
            .as_ref()
            .map(|n| {
                let v = n.get_ref().trim();
                if v.is_empty() || v.len() > 64 || v.chars().any(|c| c.is_control()) {
                    Err(cx.err(n.span(), "test.report_number", "expected 1 to 64 printable characters"))
                } else {
                    Ok(v.to_string())
                }
            })
            .transpose()?,
        issue_date: t.issue_date.as_ref().map(|d| date(d, "test.issue_date")).transpose()?,
        customer: t.customer.clone(),
        item_condition: t.item_condition.clone(),
        receipt_date: t.receipt_date.as_ref().map(|d| date(d, "test.receipt_date")).transpose()?,
        deviations: t.deviations.clone(),
        date_end: match (&t.date_end, &t.date) {
            (None, _) => None,
            (Some(e), None) => {
                return Err(cx.err(e.span(), "test.date_end", "needs test.date, the first day of the test"))
            }
            (Some(e), Some(d)) => {
                let (end, first) = (date(e, "test.date_end")?, date(d, "test.date")?);
                if parse_date(&end) < parse_date(&first) {
                    return Err(cx.err(e.span(), "test.date_end", format!("{end} is before test.date {first}")));
                }
                Some(end)
            }
        },
        laboratory: t.laboratory.clone(),
        laboratory_address: t.laboratory_address.clone(),
        customer_contact: t.customer_contact.clone(),
        sampling: t.sampling.clone(),
    };
    let mut equipment = Vec::with_capacity(raw.equipment.len());
    for (i, e) in raw.equipment.iter().enumerate() {
        let line = line_col(text, e.span().start).0;
        let e = e.get_ref();
        if e.name.trim().is_empty() || e.id.trim().is_empty() {
            return Err(cx.err(
                raw.equipment[i].span(),
                &format!("equipment[{i}]"),
                "name and id must not be empty (what it is, and its asset number or serial)",
            ));
        }
        equipment.push(Equipment {
            name: e.name.clone(),
            id: e.id.clone(),
            model: e.model.clone(),
            calibration_due: e
                .calibration_due
                .as_ref()
                .map(|d| date(d, &format!("equipment[{i}].calibration_due")))
                .transpose()?,
            line,
        });
    }

    let mut temperature = Vec::new();
    for axis in &axes {
        if let Some(t) = raw.temperature.get(axis) {
            temperature.push(temperature::parse(&cx, axis, t)?);
        }
    }

    let triad = match &raw.triad {
        None => None,
        Some(t) => {
            let span = t.span();
            let t = t.get_ref();
            let files = [&t.x, &t.y, &t.z];
            let mut resolved = Vec::with_capacity(3);
            for (axis, f) in TableAxis::ALL.into_iter().zip(files) {
                resolved.push(cx.existing_file(&format!("triad.{axis}"), f)?);
            }
            let gyro_columns = match &t.gyro_columns {
                Some(g) if g.get_ref().len() != 3 => {
                    return Err(cx.err(
                        g.span(),
                        "triad.gyro_columns",
                        format!("expected three names (gyros x, y, z), got {}", g.get_ref().len()),
                    ))
                }
                Some(g) => g.get_ref().clone(),
                None => Vec::new(),
            };
            let _ = span;
            Some(TriadPlan {
                files: [resolved[0].clone(), resolved[1].clone(), resolved[2].clone()],
                files_as_written: files.map(|f| f.get_ref().clone()),
                gyro_columns,
                segmentation: cx.segmentation("triad", &raw_segmentation!(t), None)?,
            })
        }
    };

    let uncertainty = raw
        .uncertainty
        .as_ref()
        .map(|u| uncertainty::parse_uncertainty(u, &|span, key, msg| cx.err(span, key, msg)))
        .transpose()?;
    let (threshold, resolution) = threshold::parse_step_tests(
        &cx,
        &axes,
        &threshold::RawStepTables { threshold: &raw.threshold, resolution: &raw.resolution },
        &|a| raw.rate.contains_key(a),
        options.calibration.as_ref(),
    )?;

    let power_ups = power_ups::power_ups(&cx, &raw.power_ups, &axes)?;
    let warmup = power_ups::warmups(&cx, &raw.warmup, &axes)?;
    let g_sensitivity = g_sensitivity::parse_g_sensitivity(&cx, &raw.g_sensitivity, &axes)?;
    Ok(TestPlan {
        file: path.to_path_buf(),
        text: text.to_string(),
        device: DevicePlan {
            model: raw.device.model,
            serial: raw.device.serial,
            axes,
            description: raw.device.description,
            simulated: raw.device.simulated,
            lot: raw.device.lot,
        },
        options,
        rate,
        static_tests,
        limits,
        triad,
        test,
        equipment,
        temperature,
        uncertainty,
        threshold,
        resolution,
        power_ups,
        warmup,
        g_sensitivity,
        moved_inputs: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder with two record files and a plan around them.
    fn setup(plan: &str) -> (tempfile::TempDir, Result<TestPlan, DataError>) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("x.csv"), "rate_dps,run,stroke,output_v\n").unwrap();
        std::fs::write(dir.path().join("s1.csv"), "t,v\n").unwrap();
        let p = dir.path().join("plan.toml");
        std::fs::write(&p, plan).unwrap();
        let r = read_plan(&p);
        (dir, r)
    }

    const GOOD: &str = r#"# a plan
[device]
model = "ADXRS646"
serial = "SN1"
axes = ["x"]

[options]
coverage = 2
order = 3

[rate.x]
file = "x.csv"
output_unit = "v"

[static.x]
files = ["s1.csv"]
sample_rate_hz = 1.0

[limits]
nonlinearity_pct = { max = 0.1 }
bias_stability_dph_10s = { max = 20 }
"#;

    #[test]
    fn decision_rules_and_limit_axes() {
        // The plan's rule applies to every limit that names none; a limit's own rule wins.
        let text = GOOD.replace("order = 3", "order = 3\ndecision_rule = \"guarded_acceptance\"").replace(
            "bias_stability_dph_10s = { max = 20 }",
            "bias_stability_dph_10s = { max = 20, rule = \"simple_acceptance\", axes = [\"x\"] }",
        );
        let (_dir, r) = setup(&text);
        let p = r.unwrap();
        assert_eq!(p.options.decision_rule, DecisionRule::GuardedAcceptance);
        assert_eq!((p.limits[0].rule, p.limits[0].axes.clone()), (DecisionRule::GuardedAcceptance, None));
        assert_eq!(
            (p.limits[1].rule, p.limits[1].axes.clone()),
            (DecisionRule::SimpleAcceptance, Some(vec!["x".into()]))
        );
        // Without a key: simple acceptance.
        assert_eq!(setup(GOOD).1.unwrap().limits[0].rule, DecisionRule::SimpleAcceptance);
        // Errors name the key and the line.
        let bad = GOOD.replace("order = 3", "order = 3\ndecision_rule = \"lenient\"");
        let e = setup(&bad).1.unwrap_err().to_string();
        assert!(e.contains("options.decision_rule") && e.contains("unknown decision rule 'lenient'"), "{e}");
        assert!(e.contains("guarded_acceptance"), "{e}");
        let bad = GOOD.replace("{ max = 20 }", "{ max = 20, axes = [\"q\"] }");
        let e = setup(&bad).1.unwrap_err().to_string();
        assert!(
            e.contains("limits.bias_stability_dph_10s.axes")
                && e.contains("axis 'q' is not one of the device's axes (x)"),
            "{e}"
        );
        let bad = GOOD.replace("{ max = 20 }", "{ max = 20, axes = [] }");
        assert!(setup(&bad).1.unwrap_err().to_string().contains("an empty list"));
        let bad = GOOD.replace("{ max = 20 }", "{ max = 20, rule = \"guarded\" }");
        let e = setup(&bad).1.unwrap_err();
        assert_eq!(e.line, Some(21), "{e}");
        assert!(e.to_string().contains("limits.bias_stability_dph_10s.rule"), "{e}");
    }

    #[test]
    fn good_plan() {
        let (dir, r) = setup(GOOD);
        let p = r.unwrap();
        assert_eq!(p.device.axes, ["x"]);
        assert_eq!(p.options.coverage, 2.0);
        assert_eq!(p.options.order, 3);
        assert_eq!(p.rate[0].file, dir.path().join("x.csv"));
        assert_eq!(p.rate[0].columns.output_unit, Some(OutputUnit::Volt));
        assert_eq!(p.static_tests[0].files, [dir.path().join("s1.csv")]);
        assert_eq!(p.limits.len(), 2);
        assert_eq!(
            (p.limits[0].figure.as_str(), p.limits[0].max, p.limits[0].line),
            ("nonlinearity_pct", Some(0.1), 20)
        );
    }

    fn error(plan: &str) -> DataError {
        let (_d, r) = setup(plan);
        r.unwrap_err()
    }

    const TEST_AND_EQUIPMENT: &str = r#"
[test]
operator = "A. Operator"
approver = "B. Approver"
date = "2026-11-20"
procedure = "GJB 2426A-2004"
ambient_temperature_c = 23.5
ambient_humidity_pct = 41

[[equipment]]
name = "rate table"
id = "RT-7"
calibration_due = "2027-01-31"

[[equipment]]
name = "DAQ"
id = "DAQ-2"
"#;

    #[test]
    fn test_conditions_and_equipment_are_read_and_checked() {
        let p = setup(&format!("{GOOD}{TEST_AND_EQUIPMENT}")).1.unwrap();
        assert_eq!(p.test.operator.as_deref(), Some("A. Operator"));
        assert_eq!(p.test.date.as_deref(), Some("2026-11-20"));
        assert_eq!((p.test.ambient_temperature_c, p.test.ambient_humidity_pct), (Some(23.5), Some(41.0)));
        assert_eq!(p.equipment.len(), 2);
        assert_eq!(
            (p.equipment[0].id.as_str(), p.equipment[0].calibration_due.as_deref()),
            ("RT-7", Some("2027-01-31"))
        );
        assert_eq!(p.equipment[1].calibration_due, None);
        // Lines: GOOD ends with line 21, a blank line, [test] on 23, its date on 26.
        let e = error(&format!("{GOOD}{}", TEST_AND_EQUIPMENT.replace("2026-11-20", "20.11.2026")));
        assert_eq!(e.line, Some(26), "{e}");
        assert!(e.to_string().contains("test.date: '20.11.2026': expected a date YYYY-MM-DD"), "{e}");
        let e = error(&format!("{GOOD}{}", TEST_AND_EQUIPMENT.replace("2027-01-31", "2027-02-30")));
        assert!(e.to_string().contains("equipment[0].calibration_due"), "{e}");
        let e = error(&format!("{GOOD}{}", TEST_AND_EQUIPMENT.replace("= 41", "= 141")));
        assert!(e.to_string().contains("test.ambient_humidity_pct: 141 %: expected 0 to 100"), "{e}");
        let e = error(&format!("{GOOD}{}", TEST_AND_EQUIPMENT.replace("operator =", "operater =")));
        assert!(e.to_string().contains("operater"), "{e}");
        let e = error(&format!("{GOOD}{}", TEST_AND_EQUIPMENT.replace("id = \"DAQ-2\"", "id = \" \"")));
        assert!(e.to_string().contains("equipment[1]: name and id must not be empty"), "{e}");
    }

    #[test]
    fn dates_follow_the_calendar() {
        assert_eq!(parse_date("2024-02-29"), Some((2024, 2, 29)));
        assert_eq!(parse_date("2023-02-29"), None);
        assert_eq!(parse_date("1900-02-29"), None);
        assert_eq!(parse_date("2000-02-29"), Some((2000, 2, 29)));
        for bad in ["2024-13-01", "2024-04-31", "2024-1-01", "24-01-01", "2024/01/01", ""] {
            assert_eq!(parse_date(bad), None, "{bad}");
        }
    }

    #[test]
    fn unknown_key_names_key_and_line() {
        let e = error(&GOOD.replace("output_unit = \"v\"", "output_unt = \"v\""));
        assert_eq!(e.line, Some(13), "{e}");
        assert!(e.to_string().contains("output_unt"), "{e}");
        let e = error(&GOOD.replace("[options]", "[optons]"));
        assert_eq!(e.line, Some(7), "{e}");
        assert!(e.to_string().contains("optons"), "{e}");
    }

    #[test]
    fn missing_file_names_key_line_and_path() {
        let e = error(&GOOD.replace("file = \"x.csv\"", "file = \"nope.csv\""));
        assert_eq!(e.line, Some(12), "{e}");
        let s = e.to_string();
        assert!(s.contains("rate.x.file") && s.contains("nope.csv") && s.contains("not found"), "{s}");
        let e = error(&GOOD.replace("[\"s1.csv\"]", "[\"s1.csv\", \"s2.csv\"]"));
        assert!(e.to_string().contains("static.x.files[1]") && e.to_string().contains("s2.csv"), "{e}");
        assert_eq!(e.line, Some(16));
    }

    #[test]
    fn bad_unit_names_key_and_line() {
        let e = error(&GOOD.replace("output_unit = \"v\"", "output_unit = \"volt-ish\""));
        assert_eq!(e.line, Some(13), "{e}");
        assert!(e.to_string().contains("rate.x.output_unit: unknown output unit 'volt-ish'"), "{e}");
    }

    #[test]
    fn limit_on_unknown_figure_names_key_and_line() {
        let e = error(&GOOD.replace("nonlinearity_pct = { max = 0.1 }", "nonlinearity = { max = 0.1 }"));
        assert_eq!(e.line, Some(20), "{e}");
        assert!(e.to_string().contains("limits.nonlinearity: 'nonlinearity' is not a figure"), "{e}");
        let e = error(&GOOD.replace("{ max = 0.1 }", "{ }"));
        assert!(e.to_string().contains("limits.nonlinearity_pct: expected"), "{e}");
        let e = error(&GOOD.replace("{ max = 0.1 }", "{ min = 2, max = 1 }"));
        assert!(e.to_string().contains("min 2 is above max 1"), "{e}");
    }

    #[test]
    fn axis_consistency_and_options() {
        let e = error(&GOOD.replace("axes = [\"x\"]", "axes = [\"y\"]"));
        assert!(e.to_string().contains("rate.x: axis 'x' is not in device.axes (y)"), "{e}");
        let e = error(&GOOD.replace("axes = [\"x\"]", "axes = [\"x\", \"z\"]"));
        assert!(e.to_string().contains("axis 'z' has neither"), "{e}");
        assert_eq!(e.line, Some(5));
        let e = error(&GOOD.replace("order = 3", "order = 0"));
        assert!(e.to_string().contains("options.order: must be 1 to 9"), "{e}");
        assert_eq!(e.line, Some(9));
        let e = error(&GOOD.replace("sample_rate_hz = 1.0", "sample_rate_hz = -1"));
        assert!(e.to_string().contains("static.x.sample_rate_hz"), "{e}");
        let e = error(&GOOD.replace("serial = \"SN1\"\n", ""));
        assert!(e.to_string().contains("serial"), "{e}");
    }
}
