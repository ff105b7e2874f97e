//! The static (bias) and Allan part of a test plan (and of the paper's report): evaluates the
//! `[static.<axis>]` records (the same code path for both) and returns the report sections,
//! summary figures, results.json sections and CSV files.

use gyrolab::allan::{AllanOptions, DeviationKind};
use gyrolab::figures::{name_matches, AxisFigures};
use gyrolab::limits::Limit;
use gyrolab::rate_test::RestReferenceSource;
use gyrolab::static_test::{bias_repeatability, smoothing_key, StaticTestConfig};
use gyrolab_eval::allan::{analyse_channel, ChannelSetup};
use gyrolab_eval::error::{EvalError, EvalResult};
use gyrolab_eval::outcome::allan::ChannelAnalysis;
use gyrolab_eval::outcome::static_test::TestReport;
use gyrolab_eval::progress::Progress;
use gyrolab_eval::rate::EvaluatedAxis;
use gyrolab_eval::reference::Reference;
use gyrolab_eval::static_test::window_means_file;
use gyrolab_eval::static_test::{evaluate_file, stillness_of_file};
use gyrolab_io::calibration::read_calibration;
use gyrolab_io::series::{read_series_all, SeriesOptions};
use gyrolab_io::test_plan::StaticAxisPlan;
use gyrolab_io::DataError;
use gyrolab_report::html::ReportSection;
use gyrolab_report::static_report::{
    allan_axis_csv, allan_section, bias_tests_csv, bias_windows_csv, static_section, ReferenceJson, StaticAxisReport,
    TestWindows,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Default smoothing times of the bias stability, s (one sample is added by the core).
pub const DEFAULT_SMOOTHING_S: [f64; 3] = [1.0, 10.0, 100.0];

/// What the static part adds to a report folder.
#[derive(Default)]
pub struct StaticParts {
    /// Static and Allan sections, per axis.
    pub sections: Vec<ReportSection>,
    /// Summary figures per axis.
    pub figures: Vec<AxisFigures>,
    /// results.json sections: `static` and `allan`, each keyed by axis.
    pub json: BTreeMap<String, serde_json::Value>,
    /// CSV files (name, content).
    pub files: Vec<(String, Vec<u8>)>,
    /// The evaluated axes (their numbers feed the measurement-uncertainty budgets).
    pub reports: Vec<StaticAxisReport>,
    /// Uncertainty inputs of further figures (power-ups, warm-up) for the `[uncertainty]` part.
    pub uncertainty_inputs: Vec<super::uncertainty::FigureInput>,
}

/// Inputs of the static part besides the plan's `[static.*]` tables.
pub struct StaticContext<'a> {
    /// This plan's rate-table evaluations (their K and F0 are the first choice of reference).
    pub rate_axes: &'a [EvaluatedAxis],
    /// The plan's `[options] calibration` file (second choice).
    pub calibration: Option<&'a Path>,
    /// The plan's limits (their `bias_stability_dph_<T>s` names add smoothing times).
    pub limits: &'a [Limit],
    /// File names are shown relative to this folder.
    pub base: &'a Path,
    /// Simulated data: the description shown with every section, table and JSON object.
    pub simulated: Option<&'a dyn Fn(&str) -> String>,
    /// Filter stacks whose noise-parameter files are written from the axes' Allan analyses
    /// (the plan's `[options] exports`).
    pub exports: &'a [gyrolab_io::noise_export::Stack],
    /// The plan says its records are simulated (`[device] simulated`): the exports say so.
    pub records_simulated: bool,
    /// The plan's nominal nulls by axis (`[options] nominal_null`): those axes' bias is the
    /// absolute bias against it; the others' the bias shift against the rest output.
    pub nominal_nulls: &'a BTreeMap<String, f64>,
}

pub(crate) fn shown(path: &Path, base: &Path) -> String {
    path.strip_prefix(base).unwrap_or(path).display().to_string()
}

/// Smoothing times: the defaults plus every T named by a `bias_stability_dph_<T>s` limit.
pub fn smoothing_times(limits: &[Limit]) -> Vec<f64> {
    let mut t: Vec<f64> = DEFAULT_SMOOTHING_S.to_vec();
    for l in limits {
        if name_matches("bias_stability_dph_<T>s", &l.figure) {
            let v = l.figure.trim_start_matches("bias_stability_dph_").trim_end_matches('s').parse::<f64>();
            if let Ok(v) = v {
                if !t.iter().any(|x| smoothing_key(*x) == smoothing_key(v)) {
                    t.push(v);
                }
            }
        }
    }
    t.sort_by(f64::total_cmp);
    t
}

/// The static null of an axis: the best measured zero-rate output of its rate test, the rest
/// reference F_r (rest records at start and end, else the 0 deg/s point, paper eq. 5); the
/// fitted intercept F0 only where neither was recorded (it is pulled by saturated end points).
/// Both were measured on the table at rest on the same mounting, so they contain the earth-rate
/// component a vertical input axis sees.
fn static_null(
    rest_reference: f64,
    source: Option<RestReferenceSource>,
    zero_offset: f64,
) -> (f64, &'static str, &'static str) {
    match source {
        Some(RestReferenceSource::RestRecords) => {
            (rest_reference, "rest_records", "the rest reference F_r (rest records)")
        }
        Some(RestReferenceSource::ZeroRatePoint) => {
            (rest_reference, "zero_rate_point", "the rest reference F_r (the 0 deg/s point)")
        }
        Some(RestReferenceSource::FitZeroOffset) => (zero_offset, "line_intercept", "the fitted zero offset F0"),
        // A calibration file stores F_r but not where it came from.
        None => (rest_reference, "rest_reference", "the rest reference F_r"),
    }
}

/// The static null of an evaluated rate-table axis (see `static_null`).
pub fn static_null_of(axis: &EvaluatedAxis) -> f64 {
    let c = axis.calibration();
    static_null(c.rest_reference, Some(axis.evaluation.rest_reference_source), c.zero_offset).0
}

/// The output-to-rate reference of an axis: this plan's rate-table K and static null, else the
/// plan's calibration file, else none (output units only).
pub(crate) fn reference_of(axis: &str, ctx: &StaticContext<'_>) -> EvalResult<(Reference, ReferenceJson)> {
    let sig = gyrolab::format::sig;
    let found = match ctx.rate_axes.iter().find(|a| a.name == axis) {
        Some(r) => {
            let c = r.calibration();
            let (null, key, words) =
                static_null(c.rest_reference, Some(r.evaluation.rest_reference_source), c.zero_offset);
            Some((
                c,
                null,
                key,
                words,
                "rate_table",
                format!("this plan's rate-table evaluation of axis {axis} ({})", r.file),
            ))
        }
        None => match ctx.calibration {
            Some(path) => {
                let cal = read_calibration(path)?;
                cal.axis(Some(axis)).ok().map(|c| {
                    let (null, key, words) = static_null(c.rest_reference, None, c.zero_offset);
                    let from = format!("the calibration file {} (axis {axis})", shown(path, ctx.base));
                    (c.clone(), null, key, words, "calibration_file", from)
                })
            }
            None => None,
        },
    };
    let Some((c, measured_null, key, words, source, from)) = found else {
        return Ok((
            Reference::None,
            ReferenceJson {
                source: "none".into(),
                scale_factor: None,
                null_output: None,
                null_source: None,
                null_contains_earth_rate: false,
                output_unit: None,
                text: format!(
                    "none: axis {axis} has no rate-table record in this plan and no entry in a calibration file, so \
                     figures are in output units only (outputs already in deg/s or rad/s are rates)."
                ),
            },
        ));
    };
    let u = c.output_unit.symbol();
    if let Some(&nominal) = ctx.nominal_nulls.get(axis) {
        return Ok((
            Reference::Calibrated { scale_factor: c.scale_factor, null: nominal, unit: c.output_unit },
            ReferenceJson {
                source: source.into(),
                scale_factor: Some(c.scale_factor),
                null_output: Some(nominal),
                null_source: Some(gyrolab_report::static_report::NOMINAL_NULL.into()),
                null_contains_earth_rate: false,
                output_unit: Some(u.into()),
                text: format!(
                    "K = {} {u}/(deg/s) from {from}; null = the plan's nominal null {} {u} (options.nominal_null). \
                     B0 = (static mean - nominal null) / K is the absolute bias: the gyro's zero-rate output against \
                     its nominal null, with the earth-rate component of the input axis removed only where a \
                     latitude is given. (The rate test's {words}, {} {u}, is not used as the null.)",
                    sig(c.scale_factor, 6),
                    sig(nominal, 7),
                    sig(measured_null, 7),
                ),
            },
        ));
    }
    let null = measured_null;
    Ok((
        Reference::Calibrated { scale_factor: c.scale_factor, null, unit: c.output_unit },
        ReferenceJson {
            source: source.into(),
            scale_factor: Some(c.scale_factor),
            null_output: Some(null),
            null_source: Some(key.into()),
            null_contains_earth_rate: true,
            output_unit: Some(u.into()),
            text: format!(
                "K = {} {u}/(deg/s) and null = {} {u} ({words}; F0 = {} {u}) from {from}. The null was measured at \
                 rest on the rate table, so it already contains the earth-rate component of a vertical input axis: \
                 a latitude does not subtract it again. It also contains the gyro's own bias at that time, so B0 = \
                 (static mean - null) / K is a bias shift (the change of the zero-rate output between the rate-table \
                 and the static tests), not the absolute bias against a nominal null (options.nominal_null gives \
                 that).",
                sig(c.scale_factor, 6),
                sig(null, 7),
                sig(c.zero_offset, 7),
            ),
        },
    ))
}

/// Samples at the start of each static record whose time stamps are checked against the plan's
/// sample rate.
const RATE_CHECK_ROWS: usize = 10_000;

/// Evaluates one axis's static records: every test, their repeatability, window means and the
/// Allan analysis of the Allan record (the plan's `allan_file`, else the longest test).
fn evaluate_axis(s: &StaticAxisPlan, ctx: &StaticContext<'_>, progress: &dyn Progress) -> EvalResult<StaticAxisReport> {
    let axis = &s.axis;
    let (reference, reference_json) = reference_of(axis, ctx)?;
    if s.output_unit.is_some() && s.channel.is_none() {
        return Err(EvalError::conflict(format!(
            "{}: static.{axis}.output_unit needs static.{axis}.channel (the column it applies to)",
            ctx.base.display()
        )));
    }
    let options = SeriesOptions {
        sample_rate_hz: Some(s.sample_rate_hz),
        channels: s.channel.clone().map(|c| vec![c]),
        column_units: match (&s.channel, s.output_unit) {
            (Some(c), Some(u)) => vec![(c.clone(), u)],
            _ => Vec::new(),
        },
        ..SeriesOptions::default()
    };
    let smoothing = smoothing_times(ctx.limits);
    let mut tests = Vec::new();
    let mut notes = Vec::new();
    let mut samples = Vec::new();
    for (i, path) in s.files.iter().enumerate() {
        progress.message(&format!("axis {axis}: static test {}", shown(path, ctx.base)));
        let config = StaticTestConfig {
            latitude_deg: s.latitude_deg,
            null_contains_earth_rate: reference_json.null_contains_earth_rate,
            smoothing_times_s: smoothing.clone(),
            ..StaticTestConfig::default()
        };
        if let Some(t) = gyrolab_eval::allan::first_times(path, &options, RATE_CHECK_ROWS)? {
            let key = format!("static.{axis}.sample_rate_hz");
            if let Some(msg) = gyrolab_eval::allan::rate_disagreement(&t, s.sample_rate_hz, &key, path) {
                return Err(EvalError::conflict(msg));
            }
        }
        let (results, summary) = evaluate_file(path, &options, &reference, &config)?;
        if let Some(want) = &s.temperature_channel {
            let found = summary
                .header
                .temperature_column
                .and_then(|c| summary.header.columns.get(c - 1))
                .map(|c| c.name.clone());
            if !found.as_deref().is_some_and(|f| f.eq_ignore_ascii_case(want)) {
                return Err(EvalError::Data(DataError::new(
                    path,
                    format!(
                        "static.{axis}.temperature_channel = '{want}': the file's temperature column is {} \
                         (the temperature column must be named temp_c or temperature_c)",
                        found.map_or("missing".to_string(), |f| format!("'{f}'"))
                    ),
                )));
            }
        }
        if results.len() > 1 {
            notes.push(format!(
                "{}: {} output columns; the first, '{}', is evaluated (name one with static.{axis}.channel).",
                shown(path, ctx.base),
                results.len(),
                results[0].channel
            ));
        }
        let Some(result) = results.into_iter().next() else {
            return Err(EvalError::Data(DataError::new(path, "no output channel to evaluate")));
        };
        // The Allan record is checked again with its curve.
        let record_key = format!("files[{i}]");
        let motion = ("static", record_key.as_str(), s.sample_rate_hz, s.allow_motion);
        notes.extend(motion_of_static_record(path, &options, &reference, axis, motion, ctx.base)?);
        samples.push(summary.rows);
        tests.push(TestReport { file: shown(path, ctx.base), result });
        progress.advance(1);
    }
    let window_s = tests.first().and_then(|t| t.result.bias_stability_quoted_s).unwrap_or(10.0);
    let mut windows = Vec::new();
    for (path, t) in s.files.iter().zip(&tests) {
        progress.message(&format!("axis {axis}: window means of {}", t.file));
        windows.push(TestWindows { file: t.file.clone(), windows: window_means_file(path, &options, 0, window_s)? });
    }
    let repeatability = if tests.len() >= 2 {
        let results: Vec<_> = tests.iter().map(|t| t.result.clone()).collect();
        bias_repeatability(&results).ok()
    } else {
        None
    };
    let allan_path: PathBuf = match &s.allan_file {
        Some(p) => p.clone(),
        None => {
            let longest =
                samples.iter().enumerate().max_by_key(|(i, n)| (**n, std::cmp::Reverse(*i))).map_or(0, |x| x.0);
            s.files[longest].clone() // ok: the plan has at least one file per [static] table
        }
    };
    progress.message(&format!("axis {axis}: Allan deviation of {}", shown(&allan_path, ctx.base)));
    let allan = allan_of(axis, &allan_path, &options, &reference, s, ctx.base)?;
    progress.advance(1);
    let simulated = ctx.simulated.map(|f| f(axis));
    Ok(StaticAxisReport {
        axis: axis.clone(),
        reference: reference_json,
        tests,
        repeatability,
        window_s,
        windows,
        allan: Some(allan),
        simulated,
        notes,
    })
}

/// The stillness check of a static record (its first selected channel, [`stillness_of_file`]):
/// a record that moved gives no still sensor's bias, so it is refused naming the plan key that
/// allows it, `<table>.<axis>.allow_motion`; when allowed, the note its section prints
/// (`MOTION: ...`). `motion`: the plan table's name, the key of the record in it (such as
/// `files[1]`), the sample rate and `allow_motion`.
pub(crate) fn motion_of_static_record(
    path: &Path,
    options: &SeriesOptions,
    reference: &Reference,
    axis: &str,
    (table, record_key, sample_rate_hz, allow_motion): (&str, &str, f64, bool),
    base: &Path,
) -> EvalResult<Option<String>> {
    let Some((channel, check)) = stillness_of_file(path, options, reference, sample_rate_hz)? else {
        return Ok(None);
    };
    let Some(summary) = check.motion_summary() else { return Ok(None) };
    let summary = format!("channel '{}' {summary}", gyrolab_io::text::excerpt(&channel));
    let key = format!("{table}.{axis}.allow_motion");
    if !allow_motion {
        return Err(EvalError::conflict(format!(
            "{}: {table}.{axis}.{record_key}: the record is not static, so its bias figures would not be a still \
             sensor's: {summary}; record the sensor at rest, or set {key} = true to evaluate it anyway \
             (the report then says it moved)",
            path.display()
        )));
    }
    Ok(Some(format!("MOTION: {}: {summary}; evaluated because {key} = true.", shown(path, base))))
}

/// OADEV (octave taus, 68.3 % bounds) of one record's first selected channel, converted to deg/s
/// with the reference (or the unit's native factor), with slope-line and five-term noise terms.
fn allan_of(
    axis: &str,
    path: &Path,
    options: &SeriesOptions,
    reference: &Reference,
    plan: &StaticAxisPlan,
    base: &Path,
) -> EvalResult<ChannelAnalysis> {
    let sample_rate_hz = plan.sample_rate_hz;
    let mut data = read_series_all(path, options)?;
    if let Some(t) = &data.time {
        let key = format!("static.{axis}.sample_rate_hz");
        if let Some(msg) = gyrolab_eval::allan::rate_disagreement(t, sample_rate_hz, &key, path) {
            return Err(EvalError::conflict(msg));
        }
    }
    // Gaps in the stamps are missing samples (computed over, as `gyrolab allan` does); a stamp
    // that does not increase is an error naming its line.
    let (gaps, missing) = match data.time.as_deref().map(gyrolab::sampling::estimate_interval) {
        Some(Ok(e)) => {
            if let Some(g) = e.first_non_increasing {
                let line = data.lines.get(g.index).unwrap_or(0);
                return Err(EvalError::Data(
                    DataError::new(
                        path,
                        "the time stamp does not increase: the Allan variance needs increasing time stamps",
                    )
                    .at_line(line),
                ));
            }
            (e.gaps, e.missing)
        }
        _ => (Vec::new(), 0),
    };
    data.time = None;
    data.temperature = None;
    let Some(info) = data.header.channels.first().cloned() else {
        return Err(EvalError::Data(DataError::new(path, "no output channel to analyse")));
    };
    let lines = std::mem::take(&mut data.lines);
    let values = std::mem::take(&mut data.channels).into_iter().next().unwrap_or_default();
    let opts = AllanOptions::new(DeviationKind::Oadev);
    let setup = ChannelSetup {
        path,
        shown: shown(path, base),
        topic: None,
        lines: &lines,
        tau0_s: 1.0 / sample_rate_hz,
        options: &opts,
        reference,
        fit_range_s: None,
        uncalibrated_hint: "give the axis a rate-table record or a calibration file",
        allow_motion: plan.allow_motion,
    };
    let analysis = analyse_channel(&setup, &info, gyrolab_eval::allan::on_grid(values, &gaps, missing))?;
    // A static record that moved is not a still sensor's: refused, naming the plan key that
    // allows it (then every output of the analysis is marked).
    if let Some(summary) = analysis.stillness.as_ref().and_then(|c| c.motion_summary()).filter(|_| !plan.allow_motion) {
        return Err(EvalError::conflict(format!(
            "{}: static.{axis}: the Allan record is not static, so its noise terms and bias figures would not be \
             a still sensor's: channel '{}' {summary}; record the sensor at rest, or set \
             static.{axis}.allow_motion = true to analyse it anyway (its outputs are then marked)",
            path.display(),
            gyrolab_io::text::excerpt(&analysis.channel)
        )));
    }
    Ok(analysis)
}

/// Number of progress steps of the static part.
pub fn progress_steps(plans: &[StaticAxisPlan]) -> u64 {
    plans.iter().map(|s| s.files.len() as u64 + 1).sum()
}

/// The noise-parameter files of the plan's `[options] exports` (`noise_<stack>.<ext>`): every
/// axis's Allan analysis combined as `gyrolab allan --export` combines channels (slope
/// readings, the largest value per entry), SIMULATED when the plan's data are.
fn filter_exports(reports: &[StaticAxisReport], ctx: &StaticContext<'_>) -> EvalResult<Vec<(String, Vec<u8>)>> {
    use gyrolab_eval::filter_export::{channel_filter_terms, combine_terms, ExportRecord, ExportRequest};
    if ctx.exports.is_empty() {
        return Ok(Vec::new());
    }
    let analyses: Vec<&ChannelAnalysis> = reports.iter().filter_map(|r| r.allan.as_ref()).collect();
    let Some(first) = analyses.first() else {
        return Err(EvalError::conflict(
            "options.exports: no [static.<axis>] table has an Allan analysis to export noise parameters from",
        ));
    };
    let tau0 = first.curve.tau0_s;
    if let Some(other) = analyses.iter().find(|a| (a.curve.tau0_s / tau0 - 1.0).abs() > 1e-9) {
        return Err(EvalError::conflict(
            format!(
                "options.exports: the Allan records have different sample intervals ({} s in {}, {} s in {}): one filter file holds one rate",
                tau0, first.file, other.curve.tau0_s, other.file
            ),
        ));
    }
    let channels: Vec<_> = analyses.iter().filter_map(|a| channel_filter_terms(a)).collect();
    let mut files: Vec<&str> = analyses.iter().map(|a| a.file.as_str()).collect();
    files.dedup();
    let record = ExportRecord {
        record: format!("test plan, static axes' Allan records: {}", files.join(", ")),
        rate_hz: 1.0 / tau0,
        simulated: ctx.simulated.is_some() || ctx.records_simulated,
        rostopic: None,
        motion: analyses.iter().filter_map(|a| a.motion_line()).collect(),
    };
    let request = ExportRequest {
        targets: Vec::new(),
        estimator: gyrolab_eval::filter_export::Estimator::Slopes,
        inflate: 1.0,
        overbound: false,
        allow_poor_fit: false,
    };
    let (export, _warnings) = combine_terms(&record, &channels, &request)
        .map_err(|e| EvalError::conflict(format!("options.exports: {e}")))?;
    Ok(ctx
        .exports
        .iter()
        .map(|s| (format!("noise_{}.{}", s.name(), s.file_extension()), export.render(*s).into_bytes()))
        .collect())
}

/// Evaluates every `[static.<axis>]` table and builds the sections, figures, JSON and CSV files.
pub fn evaluate_static(
    plans: &[StaticAxisPlan],
    ctx: &StaticContext<'_>,
    progress: &dyn Progress,
) -> EvalResult<StaticParts> {
    let mut parts = StaticParts::default();
    if plans.is_empty() {
        return Ok(parts);
    }
    let mut reports = Vec::new();
    for s in plans {
        reports.push(evaluate_axis(s, ctx, progress)?);
    }
    let plot_err = |e: gyrolab_report::plot::PlotError| EvalError::Output(e.to_string());
    let mut static_json = serde_json::Map::new();
    let mut allan_json = serde_json::Map::new();
    for r in &reports {
        parts.sections.push(static_section(r, ctx.limits).map_err(plot_err)?);
        if let Some(s) = allan_section(r, ctx.limits) {
            parts.sections.push(s.map_err(plot_err)?);
        }
        parts.figures.push(r.figures());
        static_json.insert(r.axis.clone(), r.static_json());
        if let Some(a) = r.allan_json() {
            allan_json.insert(r.axis.clone(), a);
        }
        parts.files.push((format!("bias_windows_{}.csv", r.axis), bias_windows_csv(r).into_bytes()));
        if let Some(csv) = allan_axis_csv(r) {
            parts.files.push((format!("allan_{}.csv", r.axis), csv.into_bytes()));
        }
    }
    parts.files.insert(0, ("bias_tests.csv".into(), bias_tests_csv(&reports).into_bytes()));
    parts.files.extend(filter_exports(&reports, ctx)?);
    parts.json.insert("static".into(), serde_json::Value::Object(static_json));
    if !allan_json.is_empty() {
        parts.json.insert("allan".into(), serde_json::Value::Object(allan_json));
    }
    parts.reports = reports;
    Ok(parts)
}
