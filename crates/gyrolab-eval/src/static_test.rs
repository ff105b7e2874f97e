//! Static tests (the gyro at rest): per file and output channel the bias and its figures
//! ([`gyrolab::static_test`]: paper eq. 10-12, IEEE 952, GJB 2426A), and the bias repeatability
//! across the files (docs/METHODS.md section 2). "Static" names the test, "bias" its main figure.

use crate::error::{EvalError, EvalResult};
use crate::outcome::static_test::{ChannelRepeatability, TestReport};
use crate::reference::{Reference, ReferenceRequest};
use gyrolab::dropout::{DropoutTally, DropoutVerdict};
use gyrolab::static_test::{bias_repeatability, StaticTestConfig, StaticTestResult};
use gyrolab::units::OutputUnit;
use gyrolab::validate;
use gyrolab_io::series::{ReaderQuality, SeriesOptions, SeriesSummary};
use std::path::{Path, PathBuf};

mod streamed;
pub use streamed::{evaluate_static_data, evaluate_static_file, window_means_file};

/// Static tests, one file per test.
///
/// ```
/// use gyrolab_eval::static_test::{evaluate_static_tests, StaticTestRequest};
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let mut files = Vec::new();
/// for (k, level) in [2.5001, 2.5003].into_iter().enumerate() {
///     let path = dir.path().join(format!("s{k}.csv"));
///     let mut text = String::from("time_s,output_v\n");
///     for i in 0..2000 {
///         text.push_str(&format!("{},{}\n", i as f64 * 0.1, level + if i % 2 == 0 { 1e-4 } else { -1e-4 }));
///     }
///     std::fs::write(&path, text)?;
///     files.push(path);
/// }
/// let mut request = StaticTestRequest::new(files);
/// request.reference.scale_factor = Some(0.0075);
/// request.reference.null = Some(2.5);
/// let outcome = evaluate_static_tests(&request)?;
/// // B0 = (F - F0) / K: 0.0001 V / 0.0075 V/(deg/s) = 0.01333 deg/s = 48 deg/h.
/// let bias = outcome.tests[0].result.bias_dph.ok_or("no bias")?;
/// assert!((bias - 48.0).abs() < 1e-6);
/// let r = outcome.repeatability[0].repeatability.bias_repeatability_dph.ok_or("no repeatability")?;
/// assert!((r - 96.0 / 2f64.sqrt()).abs() < 1e-6); // std (n-1) of 48 and 144 deg/h
/// # Ok(())
/// # }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct StaticTestRequest {
    /// Records, one file per test.
    pub files: Vec<PathBuf>,
    /// Output columns to evaluate (default: every output column).
    pub columns: Vec<String>,
    /// Unit of `columns` whose names carry no unit suffix.
    pub output_unit: Option<OutputUnit>,
    /// Sample rate, Hz (default: from the time column).
    pub sample_rate_hz: Option<f64>,
    /// Output-to-rate reference.
    pub reference: ReferenceRequest,
    /// Latitude, degrees (input axis vertical, up): the earth rate is subtracted from the bias.
    pub latitude_deg: Option<f64>,
    /// Smoothing times of the bias stability, s (default 1, 10, 100, plus one sample).
    pub smoothing_s: Vec<f64>,
    /// Fit a quadratic bias-temperature model as well as the linear one.
    pub temperature_quadratic: bool,
    /// Remove outliers (beyond 6 sigma of the drift line) before computing the figures.
    pub drop_outliers: bool,
    /// Accept NaN and empty cells (reported, excluded) instead of stopping.
    pub tolerant: bool,
    /// Units, time column and names of the files, as the user gives them.
    pub layout: crate::layout::LogLayout,
    /// Topics of recordings (MCAP, ROS 1 bag, ULog) to evaluate (default: every IMU topic).
    pub topics: Vec<String>,
    /// Also evaluate the warm-up of each record (records that start at power-on).
    pub warmup: Option<gyrolab::warmup::WarmupConfig>,
    /// The part of each record evaluated: seconds from its first sample, `[start, end)`
    /// (each topic of a recording from its own first sample); read whole then.
    pub window_s: (Option<f64>, Option<f64>),
}

impl StaticTestRequest {
    /// The default evaluation of `files`.
    pub fn new(files: Vec<PathBuf>) -> Self {
        StaticTestRequest {
            files,
            columns: Vec::new(),
            output_unit: None,
            sample_rate_hz: None,
            reference: ReferenceRequest::default(),
            latitude_deg: None,
            smoothing_s: Vec::new(),
            temperature_quadratic: false,
            drop_outliers: false,
            tolerant: false,
            layout: crate::layout::LogLayout::default(),
            topics: Vec::new(),
            warmup: None,
            window_s: (None, None),
        }
    }
}

/// What the reader passed on as missing in one file (tolerant mode).
#[derive(Debug, Clone)]
pub struct FileQuality {
    /// The file, as given.
    pub file: String,
    /// Its missing cells.
    pub quality: ReaderQuality,
}

/// The evaluated static tests.
#[derive(Debug, Clone)]
pub struct StaticOutcome {
    /// One per file and channel, in file order.
    pub tests: Vec<TestReport>,
    /// Bias repeatability per channel present in two or more files.
    pub repeatability: Vec<ChannelRepeatability>,
    /// Missing cells per file (tolerant mode).
    pub files: Vec<FileQuality>,
    /// The reference used.
    pub reference: Reference,
    /// Warm-up figures per file and channel (when asked for).
    pub warmup: Vec<crate::outcome::static_test::WarmupReport>,
    /// What the reader decided per file (the part of the record analysed), with the file
    /// (and topic) shown.
    pub notes: Vec<(String, crate::allan::ReadNote)>,
}

/// Evaluates every file of the request and the repeatability across them.
pub fn evaluate_static_tests(request: &StaticTestRequest) -> EvalResult<StaticOutcome> {
    if let Some(f) = request.sample_rate_hz {
        validate::positive("sample_rate_hz", f)?;
    }
    if let Some(l) = request.latitude_deg {
        validate::latitude_deg("latitude_deg", l)?;
    }
    validate::smoothing_times("smoothing_s", &request.smoothing_s)?;
    if request.output_unit.is_some() && request.columns.is_empty() {
        return Err(EvalError::conflict_on(&["output_unit", "columns"], "{output_unit} needs {columns}"));
    }
    if request.warmup.is_some() && (request.window_s.0.is_some() || request.window_s.1.is_some()) {
        return Err(EvalError::conflict_on(
            &["warmup_band_dph", "start_s", "end_s"],
            "the warm-up ({warmup_band_dph}) is read from power-on, the record's first sample: not with {start_s} or {end_s}",
        ));
    }
    let reference = request.reference.resolve()?;
    let options = request.layout.apply(SeriesOptions {
        sample_rate_hz: request.sample_rate_hz,
        channels: if request.columns.is_empty() { None } else { Some(request.columns.clone()) },
        column_units: request
            .output_unit
            .map(|u| request.columns.iter().map(|c| (c.clone(), u)).collect())
            .unwrap_or_default(),
        tolerant: request.tolerant,
        ..SeriesOptions::default()
    })?;
    let mut tests: Vec<TestReport> = Vec::new();
    let mut files = Vec::new();
    let mut notes = Vec::new();
    for path in &request.files {
        let mut config = StaticTestConfig {
            latitude_deg: request.latitude_deg,
            temperature_quadratic: request.temperature_quadratic,
            drop_outliers: request.drop_outliers,
            ..StaticTestConfig::default()
        };
        if !request.smoothing_s.is_empty() {
            config.smoothing_times_s = request.smoothing_s.clone();
        }
        if let Some(f) = request.sample_rate_hz {
            // A given rate must agree with the time stamps (as for the Allan analysis).
            if let Some(t) = crate::allan::first_times(path, &options, 4097)? {
                if let Some(msg) = crate::allan::rate_disagreement(&t, f, "{sample_rate_hz}", path) {
                    return Err(EvalError::conflict_on(&["sample_rate_hz"], msg));
                }
            }
        }
        let format = gyrolab_io::recording::sniff_format(path)?;
        let window = request.window_s.0.is_some() || request.window_s.1.is_some();
        if format == gyrolab_io::recording::FileFormat::Text && !window {
            if !request.topics.is_empty() {
                return Err(EvalError::conflict_on(
                    &["topics"],
                    format!("{}: {{topics}} applies to recordings (MCAP, ROS 1 bag, PX4 ULog); this is a delimited text file", path.display()),
                ));
            }
            let (results, summary) = evaluate_file(path, &options, &reference, &config)?;
            files.push(FileQuality { file: path.display().to_string(), quality: summary.quality });
            for result in results {
                tests.push(TestReport { file: path.display().to_string(), result });
            }
            continue;
        }
        // Parquet tables, the IMU topics of recordings, and a part of any record
        // ({start_s}, {end_s}), read whole.
        if format == gyrolab_io::recording::FileFormat::Text && !request.topics.is_empty() {
            return Err(EvalError::conflict_on(
                &["topics"],
                format!(
                    "{}: {{topics}} applies to recordings (MCAP, ROS 1 bag, PX4 ULog); this is a delimited text file",
                    path.display()
                ),
            ));
        }
        let records = gyrolab_io::recording::read_records(path, &options, &request.topics)?;
        for record in records.records {
            let rows = record.data.header.rows;
            let topic = record.topic;
            let shown = match &topic {
                Some(t) => format!("{} {}", path.display(), t.topic),
                None => path.display().to_string(),
            };
            let mut data = record.data;
            if let Some(note) = crate::allan::trim_to_window(&mut data, path, request.window_s, request.sample_rate_hz)?
            {
                notes.push((shown.clone(), note));
            }
            let (results, summary) = evaluate_record(data, &reference, &config)
                .map_err(|e| crate::allan::located_in(e, rows, topic.as_ref()))?;
            files.push(FileQuality { file: shown.clone(), quality: summary.quality });
            for mut result in results {
                if let Some(t) = &topic {
                    result.channel = format!("{}/{}", t.topic.trim_end_matches('/'), result.channel);
                }
                tests.push(TestReport { file: shown.clone(), result });
            }
        }
    }
    let repeatability = repeatability_by_channel(&tests);
    let mut warmup = Vec::new();
    if let Some(w) = &request.warmup {
        for path in &request.files {
            warmup.extend(evaluate_warmups(path, &options, &request.topics, &reference, request, w)?);
        }
    }
    Ok(StaticOutcome { tests, repeatability, files, reference, warmup, notes })
}

/// The warm-up of every channel of every record of `path` (a record must start at power-on):
/// outputs turned into bias in deg/h by the reference (the earth rate subtracted as for the
/// static figures), then [`gyrolab::warmup::evaluate_warmup`].
fn evaluate_warmups(
    path: &Path,
    options: &SeriesOptions,
    topics: &[String],
    reference: &Reference,
    request: &StaticTestRequest,
    config: &gyrolab::warmup::WarmupConfig,
) -> EvalResult<Vec<crate::outcome::static_test::WarmupReport>> {
    let records = gyrolab_io::recording::read_records(path, options, topics)?;
    let mut out = Vec::new();
    for record in records.records {
        let data = record.data;
        let shown = match &record.topic {
            Some(t) => format!("{} {}", path.display(), t.topic),
            None => path.display().to_string(),
        };
        let n = data.lines.len();
        let time: Vec<f64> = match (&data.time, request.sample_rate_hz.or(data.header.sample_rate_hz)) {
            (Some(t), _) => t.clone(),
            (None, Some(f)) => (0..n).map(|i| i as f64 / f).collect(),
            (None, None) => {
                return Err(EvalError::conflict_on(
                    &["sample_rate_hz"],
                    format!("{}: no time column: give {{sample_rate_hz}} for the warm-up", path.display()),
                ))
            }
        };
        for (info, values) in data.header.channels.iter().zip(&data.channels) {
            let mut cfg = StaticTestConfig { latitude_deg: request.latitude_deg, ..StaticTestConfig::default() };
            reference.configure(&mut cfg, &info.name, info.unit).map_err(EvalError::conflict)?;
            // Outputs that are already rates (deg/s, rad/s, ...) need no reference: null 0.
            let native = info.unit.native_scale_factor_per_dps();
            let k = cfg.scale_factor.or(native);
            let null = cfg.null_output.or(native.map(|_| 0.0));
            let (Some(k), Some(null)) = (k, null) else {
                return Err(EvalError::conflict_on(
                    &["scale_factor"],
                    format!(
                        "{shown} ({}): the warm-up needs the bias in deg/h: give a calibration or {{scale_factor}}",
                        gyrolab_io::text::excerpt(&info.name)
                    ),
                ));
            };
            let earth = match request.latitude_deg {
                Some(l) if !cfg.null_contains_earth_rate => gyrolab::units::earth_rate_vertical_dph(l),
                _ => 0.0,
            };
            let bias: Vec<f64> = values.iter().map(|&f| gyrolab::units::dps_to_dph((f - null) / k) - earth).collect();
            let result = gyrolab::warmup::evaluate_warmup(&time, &bias, config).map_err(|e| {
                EvalError::Data(gyrolab_io::DataError::new(
                    path,
                    format!("channel '{}': warm-up: {e}", gyrolab_io::text::excerpt(&info.name)),
                ))
            })?;
            out.push(crate::outcome::static_test::WarmupReport {
                file: shown.clone(),
                channel: info.name.clone(),
                result,
            });
        }
    }
    Ok(out)
}

/// Evaluates every channel of one file with `config`, its scale factor and null set from the
/// reference for each channel's unit (a unit the reference cannot convert is a conflict).
pub fn evaluate_file(
    path: &Path,
    options: &SeriesOptions,
    reference: &Reference,
    config: &StaticTestConfig,
) -> EvalResult<(Vec<StaticTestResult>, SeriesSummary)> {
    let mut options = options.clone();
    let verdict = dropout_verdict(path, &options)?;
    options.zero_rows_missing = verdict.all_zero;
    options.repeated_rows_missing = verdict.repeated;
    with_reference(path, reference, config, |config_for| evaluate_static_file(path, &options, config_for))
}

/// Runs a static evaluation whose channel options come from `config` and the reference for each
/// channel's unit; a unit the reference cannot convert is a conflict naming `path`.
fn with_reference<T>(
    path: &Path,
    reference: &Reference,
    config: &StaticTestConfig,
    run: impl FnOnce(
        &mut dyn FnMut(&gyrolab_io::series::ChannelInfo) -> StaticTestConfig,
    ) -> Result<T, gyrolab_io::DataError>,
) -> EvalResult<T> {
    let mut mismatch = None;
    let evaluated = run(&mut |ch| {
        let mut cfg = config.clone();
        if let Err(m) = reference.configure(&mut cfg, &ch.name, ch.unit) {
            mismatch = Some(m);
        }
        cfg
    })?;
    match mismatch {
        Some(m) => Err(EvalError::conflict(format!("{}: {m}", path.display()))),
        None => Ok(evaluated),
    }
}

/// Evaluates every channel of one record held in memory (a Parquet table, a recording's topic),
/// as [`evaluate_file`] does for a text file.
pub fn evaluate_record(
    mut data: gyrolab_io::series::SeriesData,
    reference: &Reference,
    config: &StaticTestConfig,
) -> EvalResult<(Vec<StaticTestResult>, SeriesSummary)> {
    let path = data.header.file.clone();
    let mut tally = DropoutTally::new(data.channels.len());
    tally.push_block(&data.channels.iter().map(|c| &c[..]).collect::<Vec<_>>());
    let verdict = tally.verdict();
    with_reference(&path, reference, config, |config_for| evaluate_static_data(&mut data, verdict, config_for))
}

/// The stillness check ([`gyrolab::stillness`]) of a static record's first selected channel,
/// converted to deg/s (or m/s^2) with `reference`, streaming the file once (memory per window).
/// The samples are placed on the grid of `sample_rate_hz` as the Allan record's are: a gap in the
/// time stamps is that many missing samples (rounded), dropout rows (found as [`evaluate_file`]
/// finds them) are missing samples, and a stamp that does not increase adds none. The channel's
/// name and its check;
/// `None` when no rule applies (a channel the reference leaves in volts or counts) or the
/// record has no channel.
pub fn stillness_of_file(
    path: &Path,
    options: &SeriesOptions,
    reference: &Reference,
    sample_rate_hz: f64,
) -> EvalResult<Option<(String, gyrolab::stillness::StillnessCheck)>> {
    use gyrolab::stillness::{StillnessAccumulator, StillnessRule};
    let mut options = options.clone();
    let verdict = dropout_verdict(path, &options)?;
    options.zero_rows_missing = verdict.all_zero;
    options.repeated_rows_missing = verdict.repeated;
    let mut r = gyrolab_io::series::SeriesReader::open(path, &options)?;
    let Some(info) = r.header().channels.first().cloned() else { return Ok(None) };
    let (quantity, conversion) = reference.physical_conversion(info.unit).map_err(|m| {
        EvalError::conflict(format!("{}: channel '{}': {m}", path.display(), gyrolab_io::text::excerpt(&info.name)))
    })?;
    let Some(mut acc) =
        StillnessRule::for_quantity(quantity).and_then(|rule| StillnessAccumulator::new(rule, 1.0 / sample_rate_hz))
    else {
        return Ok(None);
    };
    let tau0 = 1.0 / sample_rate_hz;
    let mut buffer = Vec::new();
    let mut last_stamp: Option<f64> = None;
    while let Some(block) = r.next_block()? {
        buffer.clear();
        buffer.extend_from_slice(block.channels.first().map_or(&[][..], |c| &c[..]));
        conversion.apply(&mut buffer);
        let Some(time) = block.time else {
            acc.push(&buffer);
            continue;
        };
        let mut run_start = 0;
        for (i, &t) in time.iter().enumerate() {
            let missing = last_stamp.map_or(0.0, |last| ((t - last) / tau0).round() - 1.0);
            if missing >= 1.0 && missing.is_finite() {
                acc.push(&buffer[run_start..i]);
                acc.skip(missing as u64);
                run_start = i;
            }
            if t.is_finite() {
                last_stamp = Some(last_stamp.map_or(t, |l: f64| l.max(t)));
            }
        }
        acc.push(&buffer[run_start..]);
    }
    Ok(Some((info.name, acc.finish())))
}

/// Which dropout rows `path` has (all zero, repeated), by the rule of [`gyrolab::dropout`]
/// (far more of them than independent channels would give): a streaming pass over the file
/// that tallies zeros and repeats, only for files of two channels or more.
pub fn dropout_verdict(path: &Path, options: &SeriesOptions) -> EvalResult<DropoutVerdict> {
    let opts = SeriesOptions { zero_rows_missing: false, repeated_rows_missing: false, ..options.clone() };
    let mut r = gyrolab_io::series::SeriesReader::open(path, &opts)?;
    let nch = r.header().channels.len();
    if nch < 2 {
        return Ok(DropoutVerdict::default());
    }
    let mut tally = DropoutTally::new(nch);
    while let Some(b) = r.next_block()? {
        tally.push_block(&b.channels.iter().map(|c| &c[..]).collect::<Vec<_>>());
    }
    Ok(tally.verdict())
}

/// Bias repeatability of each channel present in two or more tests (paper eq. 12), in order of
/// first appearance.
pub fn repeatability_by_channel(tests: &[TestReport]) -> Vec<ChannelRepeatability> {
    let mut channels: Vec<&str> = Vec::new();
    for t in tests {
        if !channels.contains(&t.result.channel.as_str()) {
            channels.push(&t.result.channel);
        }
    }
    let mut out = Vec::new();
    for ch in channels {
        let of: Vec<_> = tests.iter().filter(|t| t.result.channel == ch).map(|t| t.result.clone()).collect();
        if of.len() >= 2 {
            if let Ok(r) = bias_repeatability(&of) {
                out.push(ChannelRepeatability { channel: ch.to_string(), repeatability: r });
            }
        }
    }
    out
}

/// Evaluates one static test held in memory (output samples, optional time stamps and
/// temperatures) with `config`, its scale factor and null set from the reference.
pub fn evaluate_samples(
    block: &gyrolab::static_test::SampleBlock<'_>,
    config: &StaticTestConfig,
    reference: &Reference,
) -> EvalResult<StaticTestResult> {
    let mut cfg = config.clone();
    reference.configure(&mut cfg, &config.channel, config.output_unit).map_err(EvalError::conflict)?;
    gyrolab::static_test::evaluate_static(block, &cfg)
        .map_err(|e| EvalError::Data(gyrolab_io::DataError::new(&config.channel, e.to_string())))
}
