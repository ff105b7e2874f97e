//! The Allan analysis of a record of any length within a memory ceiling (issue 37 part 2;
//! docs/METHODS.md section 3.2): a delimited text file, a recording (MCAP, ROS 1 bag, ULog:
//! [`recording`]) or a Parquet table ([`parquet`]) whose estimated in-memory size exceeds the
//! ceiling is read block by block into
//! [`gyrolab::allan::streaming::StreamingOadev`] (octave OADEV, full resolution for the short
//! taus, every `stride`-th angle point for the long ones), with the stillness check; every other
//! record takes the in-memory path of [`crate::allan::analyse_records`] unchanged.
//!
//! The streamed record must be complete: a gap in the time stamps, a NaN or empty cell, dropout
//! rows (found by the same tally as the in-memory path) or a stamp going back are refused, naming
//! the memory ceiling that would let the in-memory path analyse them; never a different number
//! in silence.

use crate::allan::{
    analyse_records, channel_analysis, gravity_of, physical_conversion, read_notes, record_timing, refuse_motion,
    AllanOutcome, AllanRequest, ChannelSetup, ReadNote,
};
use crate::error::{EvalError, EvalResult};
use crate::reference::{Conversion, Reference};
use gyrolab::allan::streaming::{StreamedPoint, StreamingOadev, StreamingPlan};
use gyrolab::allan::{AllanError, AllanOptions, DeviationKind, TauList};
use gyrolab::dropout::DropoutTally;
use gyrolab::sampling::{estimate_interval_of, CompactStamps};
use gyrolab::stillness::{StillnessAccumulator, StillnessCheck, StillnessRule};
use gyrolab::units::Quantity;
use gyrolab::validate::InvalidOption;
use gyrolab_io::recording::{FileFormat, TopicMeta};
use gyrolab_io::series::{
    BatchReader, ChannelInfo, LineMap, ReaderQuality, SeriesData, SeriesHeader, SeriesOptions, SeriesReader, SkipReason,
};
use gyrolab_io::DataError;
use rayon::prelude::*;
use serde::Serialize;

pub mod parquet;
pub mod recording;
use std::io::Read;
use std::path::Path;

/// The ceiling used when the machine's memory cannot be read: 2 GiB.
pub const FALLBACK_MEMORY_BYTES: u64 = 2 << 30;

/// Smallest ceiling accepted: 1 MiB.
pub const MIN_MEMORY_BYTES: u64 = 1 << 20;

/// Rows per block of the streamed read (the reader's header chunk).
const BLOCK_ROWS: usize = 1 << 16;

/// Bytes of each batch of the streamed read, parsed on every core: a 64th of the ceiling,
/// between 16 KiB and 4 MiB.
fn batch_bytes(memory_bytes: u64) -> usize {
    usize::try_from((memory_bytes / 64).clamp(16 << 10, 4 << 20)).unwrap_or(4 << 20)
}

/// Bytes a batch of `batch` bytes takes while in flight, for a record of `rows` rows in
/// `size` bytes with `slots` values a row: its bytes, their copy among the pieces, and its
/// rows (the values and the line of each, 8 bytes apiece).
fn batch_footprint(batch: usize, size: u64, rows: u64, slots: usize) -> u64 {
    let rows_per_batch = batch as f64 * rows.max(1) as f64 / size.max(1) as f64;
    2 * batch as u64 + (rows_per_batch * 8.0 * (slots as f64 + 1.0)).ceil() as u64
}

/// Bytes the in-memory path holds per row of a delimited text file: 8 per channel (the samples,
/// turned into the angle series in place) and 8 for the stamps and line map (generous).
fn in_memory_bytes_per_row(channels: usize) -> u64 {
    8 * channels as u64 + 8
}

/// The default ceiling: half the machine's physical memory (`MemTotal` of /proc/meminfo), else
/// [`FALLBACK_MEMORY_BYTES`].
pub fn default_memory_bytes() -> u64 {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|text| {
        let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib.saturating_mul(1024))
    });
    match total {
        Some(t) if t / 2 >= MIN_MEMORY_BYTES => t / 2,
        _ => FALLBACK_MEMORY_BYTES,
    }
}

/// Parses a memory size: a number and a unit, `B`, SI `kB`/`MB`/`GB`/`TB` (powers of 1000) or
/// IEC `KiB`/`MiB`/`GiB`/`TiB` (powers of 1024; `K`, `M`, `G`, `T` alone are IEC too), such as
/// `1GiB`, `512 MiB`, `1.5G`; at least [`MIN_MEMORY_BYTES`].
pub fn parse_memory(text: &str) -> Result<u64, InvalidOption> {
    let t = text.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let bad = || InvalidOption::new("memory", format!("'{text}': expected a size such as 1GiB, 512MiB or 2GB"));
    let value: f64 = number.parse().map_err(|_| bad())?;
    let scale: f64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kib" => 1024.0,
        "m" | "mib" => 1024f64.powi(2),
        "g" | "gib" => 1024f64.powi(3),
        "t" | "tib" => 1024f64.powi(4),
        "kb" => 1e3,
        "mb" => 1e6,
        "gb" => 1e9,
        "tb" => 1e12,
        _ => return Err(bad()),
    };
    let bytes = value * scale;
    if !(bytes.is_finite() && bytes < 2f64.powi(63)) {
        return Err(bad());
    }
    let bytes = bytes as u64;
    if bytes < MIN_MEMORY_BYTES {
        return Err(InvalidOption::new("memory", format!("'{text}' is below the smallest ceiling, 1 MiB")));
    }
    Ok(bytes)
}

/// A size for messages: `1.50 GiB`, `512.0 MiB`.
pub fn size_text(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1024f64.powi(3) {
        format!("{:.2} GiB", b / 1024f64.powi(3))
    } else if b >= 1024f64.powi(2) {
        format!("{:.1} MiB", b / 1024f64.powi(2))
    } else {
        format!("{bytes} B")
    }
}

/// How the record was analysed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "path", rename_all = "snake_case")]
pub enum MemoryPath {
    /// Whole in memory, as without a ceiling.
    InMemory {
        /// The ceiling, bytes.
        memory_ceiling_bytes: u64,
        /// The estimated in-memory size, bytes (`None`: not estimated: standard input, a
        /// recording whose size alone shows that it fits, or a Parquet file whose footer cannot
        /// be read, whose error the in-memory path gives).
        estimated_in_memory_bytes: Option<u64>,
    },
    /// Streamed in blocks.
    Streaming(StreamingSummary),
}

/// What a streamed analysis did (JSON: the `memory` object, docs/JSON.md).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StreamingSummary {
    /// The ceiling, bytes.
    pub memory_ceiling_bytes: u64,
    /// The estimated in-memory size that exceeded it, bytes.
    pub estimated_in_memory_bytes: u64,
    /// Every `stride`-th angle point was kept for the long taus.
    pub stride: usize,
    /// Averaging factors below this were computed at full resolution (every term).
    pub full_resolution_below_m: usize,
    /// Rate samples at the start of the record on which the short taus' noise type was
    /// identified.
    pub noise_id_head_samples: usize,
    /// Largest EDF loss of any point of any channel (0 with stride 1).
    pub max_edf_loss: Option<f64>,
    /// Per channel, per tau.
    pub channels: Vec<StreamedChannel>,
}

impl StreamingSummary {
    /// The line that says a record was streamed, with its stride and EDF loss.
    pub fn note(&self, file: &str) -> String {
        let s = self;
        let loss =
            s.max_edf_loss.map_or("not evaluated (no confidence level)".to_string(), |l| format!("{:.1} %", 100.0 * l));
        let how = if s.stride == 1 {
            "every tau at full resolution".to_string()
        } else {
            format!(
                "taus with m < {} at full resolution, longer ones from every {}th angle point (largest EDF loss {loss})",
                s.full_resolution_below_m, s.stride
            )
        };
        format!(
            "{file}: streamed (about {} in memory, above the ceiling {}; --memory raises it): {how}",
            size_text(s.estimated_in_memory_bytes),
            size_text(s.memory_ceiling_bytes)
        )
    }
}

/// The streamed taus of one channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StreamedChannel {
    /// The topic of a recording (null for a table).
    pub topic: Option<String>,
    /// The channel's name.
    pub channel: String,
    /// One per point of its curve, in order.
    pub taus: Vec<StreamedTau>,
}

/// How one point was estimated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StreamedTau {
    /// Averaging factor.
    pub m: usize,
    /// Stride of its terms (1: every term of the in-memory estimator).
    pub stride: usize,
    /// EDF of the full-resolution estimator for the same noise type.
    pub edf_full: Option<f64>,
    /// 1 - edf / edf_full.
    pub edf_loss: Option<f64>,
}

impl StreamedTau {
    fn of(p: &StreamedPoint) -> StreamedTau {
        StreamedTau { m: p.point.m, stride: p.stride, edf_full: p.edf_full, edf_loss: p.edf_loss() }
    }
}

/// [`analyse_records`] within `memory_bytes`: a delimited text file, a recording or a Parquet
/// table whose estimated in-memory size is above the ceiling is streamed (octave OADEV only; other kinds and
/// tau lists are refused there, naming the ceiling to raise), every other record is read in
/// memory.
pub fn analyse_records_within(
    request: &AllanRequest,
    memory_bytes: u64,
) -> EvalResult<(Vec<AllanOutcome>, MemoryPath)> {
    let in_memory = |estimate: Option<u64>| MemoryPath::InMemory {
        memory_ceiling_bytes: memory_bytes,
        estimated_in_memory_bytes: estimate,
    };
    crate::allan::validate_request(request)?;
    let path = &request.file;
    if path == Path::new("-") {
        return Ok((analyse_records(request)?, in_memory(None)));
    }
    let (_, format, size) = gyrolab_io::recording::open_sniffed(path)?;
    if format.is_recording() {
        // Small enough by its size alone: no count.
        if recording::size_bound(size) <= memory_bytes {
            return Ok((analyse_records(request)?, in_memory(None)));
        }
        let counts = recording::imu_topic_counts(request)?;
        let estimate = recording::counted_size(&counts);
        if estimate <= memory_bytes {
            return Ok((analyse_records(request)?, in_memory(Some(estimate))));
        }
        refuse_other_estimators(request, path, estimate, memory_bytes)?;
        // No topic named: the sensors at their own rate, as the in-memory path chooses them.
        let (named, skipped) = if request.topics.is_empty() {
            let reasons = counts.iter().map(|t| (t.topic.clone(), t.snapshot_reason()));
            let (kept, skipped) = gyrolab_io::recording::sensor_topics(path, reasons)?;
            (AllanRequest { topics: kept, ..request.clone() }, skipped)
        } else {
            (request.clone(), Vec::new())
        };
        let counts: Vec<_> = counts.into_iter().filter(|t| named.topics.contains(&t.topic)).collect();
        let estimate = recording::counted_size(&counts);
        let (mut outcomes, summary) = recording::analyse_recording_streaming(&named, memory_bytes, estimate, &counts)?;
        if let Some(first) = outcomes.first_mut() {
            let notes = skipped.into_iter().map(ReadNote::TopicSkipped).chain(std::mem::take(&mut first.notes));
            first.notes = notes.collect();
        }
        return Ok((outcomes, MemoryPath::Streaming(summary)));
    }
    if format == FileFormat::Parquet && request.topics.is_empty() {
        // Rows and columns from the footer; a file the reader refuses goes to the in-memory
        // path, whose error the user gets as before.
        let Ok(layout) = gyrolab_io::recording::open_sniffed(path)
            .and_then(|(file, _, _)| gyrolab_io::parquet_table::parquet_layout(path, file))
        else {
            return Ok((analyse_records(request)?, in_memory(None)));
        };
        let estimate = parquet::table_size(&layout);
        if estimate <= memory_bytes {
            return Ok((analyse_records(request)?, in_memory(Some(estimate))));
        }
        refuse_other_estimators(request, path, estimate, memory_bytes)?;
        let (outcome, summary) = parquet::analyse_parquet_streaming(request, memory_bytes, estimate, &layout)?;
        return Ok((vec![outcome], MemoryPath::Streaming(summary)));
    }
    if format != FileFormat::Text {
        return Ok((analyse_records(request)?, in_memory(None)));
    }
    // A file the reader refuses goes to the in-memory path, whose error the user gets as before.
    let Ok(options) = series_options(request) else { return Ok((analyse_records(request)?, in_memory(None))) };
    // The header's chunk no larger than a streamed batch, so that every batch is of that size.
    let options = SeriesOptions { chunk_bytes: batch_bytes(memory_bytes), ..options };
    let Ok(reader) = SeriesReader::open(path, &options) else {
        return Ok((analyse_records(request)?, in_memory(None)));
    };
    let channels = reader.header().channels.len().max(1);
    let rows = estimated_rows(path, size)?;
    let estimate = rows.saturating_mul(in_memory_bytes_per_row(channels));
    if estimate <= memory_bytes {
        drop(reader);
        return Ok((analyse_records(request)?, in_memory(Some(estimate))));
    }
    refuse_other_estimators(request, path, estimate, memory_bytes)?;
    let start = start_interval(path, &options, request.sample_rate_hz)?;
    let (outcome, summary) = analyse_streaming(request, reader, (rows, size), memory_bytes, estimate, start)?;
    Ok((vec![outcome], MemoryPath::Streaming(summary)))
}

/// A record beyond the ceiling is streamed, which computes octave OADEV only: another kind or
/// tau list is refused, naming the options.
fn refuse_other_estimators(request: &AllanRequest, path: &Path, estimate: u64, memory_bytes: u64) -> EvalResult<()> {
    if request.has_window() {
        return Err(EvalError::conflict_on(
            &["memory", "start_s", "end_s"],
            format!(
                "{}: about {} in memory, above the ceiling {{memory}} {}: {{start_s}} and {{end_s}} cut a record read in memory (raise {{memory}} above {}, or cut the record first with `gyrolab convert`)",
                path.display(),
                size_text(estimate),
                size_text(memory_bytes),
                size_text(estimate)
            ),
        ));
    }
    if request.kind == DeviationKind::Oadev && request.taus == TauList::Octave {
        return Ok(());
    }
    Err(EvalError::conflict_on(
        &["memory", "kind", "taus"],
        format!(
            "{}: about {} in memory, above the ceiling {{memory}} {}: records beyond it are streamed, which computes octave OADEV only (give {{kind}} oadev and {{taus}} octave, or raise {{memory}} above {})",
            path.display(),
            size_text(estimate),
            size_text(memory_bytes),
            size_text(estimate)
        ),
    ))
}

/// The reader options of the in-memory path ([`analyse_records`]), in blocks of [`BLOCK_ROWS`].
fn series_options(request: &AllanRequest) -> EvalResult<SeriesOptions> {
    request.layout.apply(SeriesOptions {
        sample_rate_hz: request.sample_rate_hz,
        channels: if request.columns.is_empty() { None } else { Some(request.columns.clone()) },
        tolerant: true,
        block_rows: BLOCK_ROWS,
        ..SeriesOptions::default()
    })
}

/// Rows of a text file estimated from the line ends in its first MiB (exact for a file that
/// short).
fn estimated_rows(path: &Path, size: u64) -> EvalResult<u64> {
    let (file, _) = gyrolab_io::input_file::open_regular(path)?;
    let mut head = Vec::with_capacity(1 << 20);
    file.take(1 << 20).read_to_end(&mut head).map_err(|e| DataError::io(path, &e))?;
    let lines = head.iter().filter(|&&b| b == b'\n').count() as u64;
    if head.is_empty() {
        return Ok(0);
    }
    if head.len() as u64 >= size {
        return Ok(lines);
    }
    Ok((size as f64 * lines.max(1) as f64 / head.len() as f64).ceil() as u64)
}

/// Rows of the record's start whose stamps give the stillness check's interval.
const START_ROWS: usize = 10_000;

/// The sample interval at a streamed record's start, s, by which the stillness check cuts its
/// windows before the record's interval is known: the sample rate given, else the interval the
/// clock model reads from the first [`START_ROWS`] stamps (the in-memory path reads it from
/// all of them: the two agree on a complete record, the only kind streamed); `None` when
/// neither gives a positive finite number.
fn start_interval(path: &Path, options: &SeriesOptions, sample_rate_hz: Option<f64>) -> EvalResult<Option<f64>> {
    let interval = match sample_rate_hz {
        Some(r) => Some(1.0 / r),
        None => crate::allan::first_times(path, options, START_ROWS)?
            .and_then(|t| gyrolab::sampling::estimate_interval(&t).ok())
            .map(|e| e.interval_s),
    };
    Ok(interval.filter(|x| x.is_finite() && *x > 0.0))
}

/// Bytes the stillness checks of a streamed record hold: per channel and window (at most
/// `rows` / the window's samples + 1), its sums (72 bytes, doubled for the vector's growth)
/// and what the verdict copies (judged sums, means, variances, window means: 104 bytes).
fn stillness_footprint(rows: u64, channels: usize, tau0_s: f64) -> u64 {
    let Some(rule) = StillnessRule::for_quantity(gyrolab::units::Quantity::AngularRate) else { return 0 };
    let window = (rule.window_s / tau0_s).round().max(gyrolab::stillness::MIN_WINDOW_SAMPLES as f64);
    let windows = (rows as f64 / window).ceil() as u64 + 1;
    windows.saturating_mul(channels as u64).saturating_mul(2 * 72 + 104)
}

/// Why a streamed record is refused: it is incomplete, which only the in-memory path analyses.
fn incomplete(path: &Path, what: &str, estimate: u64) -> DataError {
    DataError::new(
        path,
        format!(
            "{what}: a record streamed within the memory ceiling must be complete (its gaps are analysed in memory only): raise the ceiling (--memory) above the record's estimated in-memory size, {}",
            size_text(estimate)
        ),
    )
}

/// The streamed channels of one record: their conversions to physical units, OADEV estimators
/// and stillness checks.
struct ChannelStreams {
    conversions: Vec<(Quantity, Conversion)>,
    estimators: Vec<StreamingOadev>,
    stillness: Vec<Option<StillnessAccumulator>>,
}

impl ChannelStreams {
    /// Streams for channels converted by `conversions`; the stillness checks cut their windows
    /// at `start_interval` (none without it).
    fn new(
        path: &Path,
        conversions: Vec<(Quantity, Conversion)>,
        options: &AllanOptions,
        plan: StreamingPlan,
        start_interval: Option<f64>,
    ) -> EvalResult<ChannelStreams> {
        let estimators = conversions
            .iter()
            .map(|_| StreamingOadev::new(options, plan))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| EvalError::conflict(format!("{}: {e}", path.display())))?;
        let stillness = conversions
            .iter()
            .map(|(q, _)| {
                let tau0 = start_interval?;
                StillnessRule::for_quantity(*q).and_then(|r| StillnessAccumulator::new(r, tau0))
            })
            .collect();
        Ok(ChannelStreams { conversions, estimators, stillness })
    }

    /// Converts a block (one column per channel) in place and pushes it, channels in parallel;
    /// the error of the first channel that refused a sample.
    fn push(&mut self, block: &mut [Vec<f64>]) -> Result<(), (usize, AllanError)> {
        let failed = self
            .estimators
            .par_iter_mut()
            .zip(self.stillness.par_iter_mut())
            .zip(block.par_iter_mut())
            .zip(self.conversions.par_iter())
            .enumerate()
            .map(|(c, (((est, still), values), (_, conversion)))| {
                conversion.apply(values);
                if let Some(acc) = still {
                    acc.push(values);
                }
                est.push(values).err().map(|e| (c, e))
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .min_by_key(|(c, _)| *c);
        failed.map_or(Ok(()), Err)
    }
}

/// The error of a sample the estimators refused (`index`: its row in the record).
fn pushed_error(path: &Path, info: &ChannelInfo, lines: &LineMap, e: AllanError, estimate: u64) -> EvalError {
    match e {
        AllanError::NonFinite { index, value } => {
            let line = lines.get(index).unwrap_or(0);
            let e = if value.is_nan() {
                incomplete(path, "a NaN or empty cell (a missing sample)", estimate)
            } else {
                DataError::new(
                    path,
                    format!("sample {value} is not a finite number: the Allan variance needs a complete record"),
                )
            };
            e.at_line(line).at_column(info.column, Some(&info.name)).into()
        }
        e => DataError::new(path, format!("channel '{}': {e}", gyrolab_io::text::excerpt(&info.name))).into(),
    }
}

/// What the reader side of a streamed record kept (no samples): its header, stamps (seconds,
/// compactly; none without a time column), lines and dropout tally.
struct StreamedRecord {
    header: SeriesHeader,
    quality: ReaderQuality,
    stamps: Option<CompactStamps>,
    lines: LineMap,
    tally: DropoutTally,
    topic: Option<TopicMeta>,
}

/// The end of a streamed record: refused when incomplete (gaps in the stamps, dropout rows, a
/// stamp going back: the in-memory path analyses those, the estimators have taken every
/// sample); else its timing as the in-memory path reads it, and each channel's curve, noise
/// terms and stillness check, with the gravity check.
fn finish_streamed(
    request: &AllanRequest,
    reference: &Reference,
    options: &AllanOptions,
    record: StreamedRecord,
    streams: ChannelStreams,
    estimate: u64,
) -> EvalResult<(AllanOutcome, Vec<StreamedChannel>)> {
    let path = request.file.as_path();
    let StreamedRecord { header, quality, stamps, lines, tally, topic } = record;
    let infos = header.channels.clone();
    let located = |e: EvalError| crate::allan::located_in(e, header.rows, topic.as_ref());
    // Gaps in the stamps: refused (the in-memory path places the samples on their grid).
    if let Some(stamps) = &stamps {
        if let Ok(e) = estimate_interval_of(stamps) {
            if e.first_non_increasing.is_none() {
                if let Some(g) = e.gaps.first() {
                    let what = format!(
                        "a gap in the time stamps: {} sample(s) missing (interval {} s where the record's is {} s; {} missing in {} gap(s))",
                        g.missing,
                        g.interval_s,
                        e.interval_s,
                        e.missing,
                        e.gaps.len()
                    );
                    return Err(located(
                        incomplete(path, &what, estimate).at_line(lines.get(g.index).unwrap_or(0)).into(),
                    ));
                }
            }
        }
    }
    // Dropout rows (every channel zero, or repeating the row before, beyond chance): the
    // in-memory path analyses them as missing samples; the streamed one had them in its sums.
    if tally.verdict().any() {
        return Err(located(
            incomplete(
                path,
                "dropout rows (every channel zero, or repeating the row before, more often than chance)",
                estimate,
            )
            .into(),
        ));
    }
    // The timing of the in-memory path on the stamps and lines kept (no samples).
    let mut stub = SeriesData {
        header: header.clone(),
        lines,
        time: None,
        time_compact: stamps,
        temperature: None,
        table_rate: None,
        channels: Vec::new(),
        quality,
    };
    let timing = record_timing(&stub, path, request.sample_rate_hz, request.gaps).map_err(located)?;
    // A stamp going back (a reset, a trailer of zeros) ends the record in memory; the streamed
    // estimators have taken the samples after it: refused.
    if let Some(r) = timing.reset {
        let what = format!(
            "the time stamps go back (from {} s to {} s: a clock reset or a trailer), which ends the record before it",
            r.from_s, r.to_s
        );
        return Err(located(incomplete(path, &what, estimate).at_line(stub.lines.get(r.index).unwrap_or(0)).into()));
    }
    let lines = std::mem::take(&mut stub.lines);
    drop(stub);
    let tau0 = timing.tau0_s;
    let mut notes = read_notes(&header);
    notes.extend(timing.clock.map(ReadNote::Clock));
    notes.extend(timing.note.clone());
    let not_read: Vec<String> =
        header.skipped.iter().filter(|s| s.reason == SkipReason::NotSelected).map(|s| s.name.clone()).collect();
    if infos.len() < 2 && !not_read.is_empty() {
        notes.push(ReadNote::DropoutsUnchecked { read: infos.iter().map(|c| c.name.clone()).collect(), not_read });
    }
    let setup = ChannelSetup {
        path,
        shown: path.display().to_string(),
        topic: topic.as_ref().map(|t| t.topic.clone()),
        lines: &lines,
        tau0_s: tau0,
        options,
        reference,
        fit_range_s: request.fit_range_s,
        uncalibrated_hint: "give a calibration or a scale factor for noise terms in deg units",
        allow_motion: request.allow_motion,
    };
    let ChannelStreams { conversions, estimators, stillness } = streams;
    let finished: Vec<EvalResult<_>> = estimators
        .into_par_iter()
        .zip(stillness.into_par_iter())
        .zip(infos.par_iter())
        .zip(conversions.par_iter())
        .map(|(((est, still), info), (quantity, _))| {
            let (curve, points) = est.finish(tau0).map_err(|e| {
                EvalError::Data(DataError::new(
                    path,
                    format!("channel '{}': {e}", gyrolab_io::text::excerpt(&info.name)),
                ))
            })?;
            let streamed = StreamedChannel {
                topic: topic.as_ref().map(|t| t.topic.clone()),
                channel: info.name.clone(),
                taus: points.iter().map(StreamedTau::of).collect(),
            };
            let stillness = match still {
                Some(acc) => Some(acc.finish_at_interval(tau0)),
                None => StillnessRule::for_quantity(*quantity).map(|rule| {
                    StillnessCheck::not_evaluated(
                        rule,
                        "the interval of the streamed record's start could not be read from its first time stamps",
                    )
                }),
            };
            Ok((channel_analysis(&setup, info, *quantity, curve, stillness), streamed))
        })
        .collect();
    let mut analyses = Vec::with_capacity(finished.len());
    let mut streamed = Vec::with_capacity(finished.len());
    for f in finished {
        let (a, s) = f.map_err(located)?;
        analyses.push(a);
        streamed.push(s);
    }
    if let Some(g) = gravity_of(&mut analyses) {
        notes.push(ReadNote::Gravity(g));
    }
    Ok((AllanOutcome { topic, analyses, sample_interval_s: tau0, notes }, streamed))
}

/// The summary of a streamed analysis: the plans' largest stride and EDF loss, every channel's
/// taus.
fn streaming_summary(
    memory_bytes: u64,
    estimate: u64,
    plans: &[StreamingPlan],
    channels: Vec<StreamedChannel>,
) -> StreamingSummary {
    let max_edf_loss = channels.iter().flat_map(|c| c.taus.iter().filter_map(|t| t.edf_loss)).reduce(f64::max);
    let widest = plans.iter().max_by_key(|p| p.stride).copied().unwrap_or(StreamingPlan {
        stride: 1,
        full_resolution_below: 1,
        head_samples: 0,
    });
    StreamingSummary {
        memory_ceiling_bytes: memory_bytes,
        estimated_in_memory_bytes: estimate,
        stride: widest.stride,
        full_resolution_below_m: widest.full_resolution_below,
        noise_id_head_samples: plans.iter().map(|p| p.head_samples).min().unwrap_or(0),
        max_edf_loss,
        channels,
    }
}

/// The Allan options of a request (octave OADEV when streamed).
fn allan_options(request: &AllanRequest) -> AllanOptions {
    AllanOptions { kind: request.kind, taus: request.taus.clone(), confidence: request.confidence, max_factor: None }
}

/// Each channel's conversion to physical units, as the in-memory path converts it.
fn conversions_of(
    path: &Path,
    infos: &[ChannelInfo],
    options: &AllanOptions,
    reference: &Reference,
) -> EvalResult<Vec<(Quantity, Conversion)>> {
    let lines_probe = LineMap::default();
    let probe = ChannelSetup {
        path,
        shown: path.display().to_string(),
        topic: None,
        lines: &lines_probe,
        tau0_s: 1.0,
        options,
        reference,
        fit_range_s: None,
        uncalibrated_hint: "",
        allow_motion: false,
    };
    infos.iter().map(|i| physical_conversion(&probe, i)).collect()
}

/// Streams one delimited text file through the estimators of its channels: the reader parses
/// batches on every core, handed over in file order from this thread; the estimators take them
/// on another (channels in parallel).
fn analyse_streaming(
    request: &AllanRequest,
    reader: SeriesReader<gyrolab_io::series::Source>,
    (rows, size): (u64, u64),
    memory_bytes: u64,
    estimate: u64,
    start_interval: Option<f64>,
) -> EvalResult<(AllanOutcome, StreamingSummary)> {
    let path = request.file.as_path();
    let mut reader = BatchReader::new(reader, rayon::current_num_threads(), batch_bytes(memory_bytes));
    let reference = request.reference.resolve()?;
    let header = reader.header().clone();
    let infos = header.channels.clone();
    let options = allan_options(request);
    // The stamps (about a byte a row), the batches in flight (one read, two queued, one taken)
    // and the stillness checks come off the ceiling before the plan shares it among the channels.
    let slots = infos.len() + 3;
    let stillness_bytes = start_interval.map_or(0, |tau0| stillness_footprint(rows, infos.len(), tau0));
    let overhead = rows + 4 * batch_footprint(reader.batch_bytes(), size, rows, slots) + stillness_bytes;
    let budget = memory_bytes.saturating_sub(overhead).max(MIN_MEMORY_BYTES / 2);
    let plan = StreamingPlan::for_memory(
        usize::try_from(rows).unwrap_or(usize::MAX),
        infos.len(),
        usize::try_from(budget).unwrap_or(usize::MAX),
    );
    let conversions = conversions_of(path, &infos, &options, &reference)?;
    let mut streams = ChannelStreams::new(path, conversions, &options, plan, start_interval)?;
    let mut stamps = CompactStamps::default();
    let mut lines = LineMap::default();
    let mut tally = DropoutTally::new(infos.len());
    let has_time = header.time_column.is_some();
    let (read, pushed) = std::thread::scope(|scope| {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Vec<f64>>>(2);
        let streams = &mut streams;
        let consumer = scope.spawn(move || -> Result<(), (usize, AllanError)> {
            for mut block in rx {
                streams.push(&mut block)?;
            }
            Ok(())
        });
        let read = (|| -> Result<(), DataError> {
            while let Some(batch) = reader.next_batch()? {
                let refs: Vec<&[f64]> = batch.channels.iter().map(|c| &c[..]).collect();
                tally.push_block(&refs);
                if has_time {
                    if let Some(t) = &batch.time {
                        stamps.extend_from_slice(t);
                    }
                }
                lines.extend_from_slice(&batch.lines);
                if tx.send(batch.channels).is_err() {
                    break; // the estimators stopped on an error, reported below
                }
            }
            Ok(())
        })();
        drop(tx);
        let pushed = consumer.join();
        (read, pushed)
    });
    // A sample the estimators refused comes before any later reader error.
    match pushed {
        Ok(Ok(())) => {}
        Ok(Err((c, e))) => return Err(pushed_error(path, &infos[c], &lines, e, estimate)),
        Err(_) => return Err(EvalError::conflict(format!("{}: the streamed analysis failed", path.display()))),
    }
    read?;
    let quality = reader.quality().clone();
    drop(reader);
    let record = StreamedRecord { header, quality, stamps: has_time.then_some(stamps), lines, tally, topic: None };
    let (outcome, channels) = finish_streamed(request, &reference, &options, record, streams, estimate)?;
    refuse_motion(&outcome.analyses, path, request.allow_motion)?;
    Ok((outcome, streaming_summary(memory_bytes, estimate, &[plan], channels)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_sizes_parse_in_iec_and_si_units_and_bad_ones_are_refused() {
        assert_eq!(parse_memory("1GiB"), Ok(1 << 30));
        assert_eq!(parse_memory(" 512 MiB "), Ok(512 << 20));
        assert_eq!(parse_memory("2GB"), Ok(2_000_000_000));
        assert_eq!(parse_memory("1.5G"), Ok(3 << 29));
        assert_eq!(parse_memory("1m"), Ok(1 << 20));
        for bad in ["lots", "", "GiB", "1 PiB", "100k", "-1G", "1e3G"] {
            let e = parse_memory(bad).unwrap_err();
            assert_eq!(e.field, "memory", "{bad}");
        }
        assert_eq!(size_text(3 << 29), "1.50 GiB");
        assert_eq!(size_text(512 << 20), "512.0 MiB");
    }
}
