//! Allan-variance analysis of a time-series file: the deviation family with confidence
//! intervals per output channel (channels in parallel), converted to deg/s by the reference,
//! with IEEE 952 noise terms by slope lines and by the five-term fit (docs/METHODS.md section 3).

use crate::error::{EvalError, EvalResult};
use crate::layout::LogLayout;
use crate::outcome::allan::{ChannelAnalysis, LazyGmwm};
use crate::reference::{Conversion, Reference, ReferenceRequest};
use gyrolab::allan::gap_fill::{fill_isolated, FillCount, MAX_FILLED_SHARE};
use gyrolab::allan::{
    deviation_from_rate, deviation_from_rate_into, deviation_from_rate_with_gaps, deviation_from_rate_with_gaps_into,
    AllanCurve, AllanError, AllanOptions, DeviationKind, TauList,
};
use gyrolab::noise::{fit_noise_model, slope_line_terms};
use gyrolab::sampling::{estimate_interval, estimate_interval_of, ClockModel, Reset, SamplingError};
use gyrolab::stillness::{check_channel, StillnessCheck};
use gyrolab::units::{OutputUnit, Quantity, TimeUnit};
use gyrolab::validate::{self, InvalidOption};
use gyrolab_io::recording::{read_records, TopicMeta};
use gyrolab_io::series::{ChannelInfo, SeriesData, SeriesOptions};
use gyrolab_io::series::{LineMap, RowKind, SkipReason, SkippedColumn, UnitSource};
use gyrolab_io::DataError;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// An Allan analysis of the output channels of one file.
///
/// ```
/// use gyrolab_eval::allan::{analyse_file, AllanRequest};
/// use gyrolab::allan::{DeviationKind, TauList};
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("rate.csv");
/// let mut text = String::from("time_s,rate_dps\n");
/// for i in 0..4000 {
///     text.push_str(&format!("{},{}\n", i as f64 * 0.01, ((i * 7919) % 13) as f64 * 1e-3));
/// }
/// std::fs::write(&path, text)?;
/// let request = AllanRequest::new(path);
/// let outcome = analyse_file(&request)?;
/// assert_eq!(outcome.sample_interval_s, 0.01);
/// assert_eq!(outcome.analyses[0].curve.points[0].m, 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct AllanRequest {
    /// The time series.
    pub file: PathBuf,
    /// Output columns to analyse (default: every output column).
    pub columns: Vec<String>,
    /// Sample rate, Hz (required when the file has no time column).
    pub sample_rate_hz: Option<f64>,
    /// Output-to-rate reference.
    pub reference: ReferenceRequest,
    /// Deviation kind.
    pub kind: DeviationKind,
    /// Averaging times.
    pub taus: TauList,
    /// Confidence level of the bounds; `None`: no bounds and no noise identification.
    pub confidence: Option<f64>,
    /// Tau range of the five-term fit, s (default: the whole curve).
    pub fit_range_s: Option<(f64, f64)>,
    /// Units, time column and names of the file, as the user gives them.
    pub layout: LogLayout,
    /// What to do with missing samples (gaps in the time stamps, NaN or empty cells, dropout
    /// rows).
    pub gaps: GapPolicy,
    /// Topics of a recording (MCAP, ROS 1 bag, ULog) to analyse (default: every IMU topic).
    pub topics: Vec<String>,
    /// Analyse a record whose gyro or accelerometer channels moved (the stillness check,
    /// docs/METHODS.md): its outputs are marked; without it such a record is refused.
    pub allow_motion: bool,
    /// The part of the record analysed, seconds from its first sample: samples at or after
    /// the start and before the end (`None`: from the first, to the last). Each topic of a
    /// recording counts from its own first sample.
    pub window_s: (Option<f64>, Option<f64>),
}

/// What the Allan analysis does with missing samples (docs/METHODS.md, "Gap policies").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum GapPolicy {
    /// Compute over them: terms that touch a missing sample are left out (OADEV, ADEV, OHDEV,
    /// HDEV), as Stable32 and allantools' gradev.
    Analyse,
    /// Refuse a record with missing samples, naming the first.
    Error,
    /// Fill runs of up to three missing samples by linear interpolation between their
    /// neighbours ([`gyrolab::allan::gap_fill`]), counted in a note; longer runs as `Analyse`.
    /// The default: sparse drops then keep the long taus.
    #[default]
    Fill,
    /// Close the gaps of the time stamps up: the samples read are taken as consecutive at the
    /// record's interval (NaN cells and dropout rows stay missing, as `Analyse`).
    Contiguous,
}

impl GapPolicy {
    /// Parses `fill`, `analyse` (or `analyze`), `contiguous` or `error`.
    pub fn parse(text: &str) -> Result<GapPolicy, InvalidOption> {
        match text.trim() {
            "analyse" | "analyze" => Ok(GapPolicy::Analyse),
            "error" => Ok(GapPolicy::Error),
            "fill" => Ok(GapPolicy::Fill),
            "contiguous" => Ok(GapPolicy::Contiguous),
            other => Err(InvalidOption::new("gaps", format!("'{other}': expected fill, analyse, contiguous or error"))),
        }
    }

    /// The policy's name, as parsed.
    pub fn name(self) -> &'static str {
        match self {
            GapPolicy::Analyse => "analyse",
            GapPolicy::Error => "error",
            GapPolicy::Fill => "fill",
            GapPolicy::Contiguous => "contiguous",
        }
    }
}

impl AllanRequest {
    /// Octave OADEV of every output column with 68.3 % bounds.
    pub fn new(file: impl Into<PathBuf>) -> Self {
        AllanRequest {
            file: file.into(),
            columns: Vec::new(),
            sample_rate_hz: None,
            reference: ReferenceRequest::default(),
            kind: DeviationKind::Oadev,
            taus: TauList::Octave,
            confidence: Some(0.683),
            fit_range_s: None,
            layout: LogLayout::default(),
            gaps: GapPolicy::default(),
            topics: Vec::new(),
            allow_motion: false,
            window_s: (None, None),
        }
    }

    /// Whether a part of the record is asked for (`window_s`).
    pub fn has_window(&self) -> bool {
        self.window_s.0.is_some() || self.window_s.1.is_some()
    }
}

/// Keeps the samples of `data` whose time from the first sample lies in `[start, end)` (the
/// stamps, else the sample index over `rate_hz`); a note says what was kept. An empty or
/// inverted window, or one holding fewer than two samples, is an error naming the record's
/// length.
pub fn trim_to_window(
    data: &mut SeriesData,
    path: &Path,
    (start, end): (Option<f64>, Option<f64>),
    rate_hz: Option<f64>,
) -> EvalResult<Option<ReadNote>> {
    if start.is_none() && end.is_none() {
        return Ok(None);
    }
    for (name, v) in [("start_s", start), ("end_s", end)] {
        if let Some(v) = v {
            if !v.is_finite() || v < 0.0 {
                return Err(EvalError::conflict_on(
                    &[name],
                    format!("{{{name}}} must be a number of seconds >= 0, got {v}"),
                ));
            }
        }
    }
    if let (Some(a), Some(b)) = (start, end) {
        if b <= a {
            return Err(EvalError::conflict_on(
                &["start_s", "end_s"],
                format!("{{end_s}} {b} s is not after {{start_s}} {a} s"),
            ));
        }
    }
    let n = data.channels.first().map_or(0, Vec::len);
    let offset = |i: usize| -> Option<f64> {
        match (&data.time, rate_hz) {
            (Some(t), _) => Some(t[i] - t[0]),
            (None, Some(f)) => Some(i as f64 / f),
            _ => None,
        }
    };
    if n == 0 || offset(0).is_none() {
        return Err(EvalError::conflict_on(
            &["start_s", "end_s", "sample_rate_hz"],
            format!(
                "{}: {{start_s}} and {{end_s}} need the record's time stamps or {{sample_rate_hz}}",
                path.display()
            ),
        ));
    }
    let keep = |i: usize| offset(i).is_some_and(|s| start.is_none_or(|a| s >= a) && end.is_none_or(|b| s < b));
    let first = (0..n).find(|&i| keep(i));
    let last = (0..n).rev().find(|&i| keep(i));
    let length = offset(n - 1).unwrap_or(0.0);
    let (Some(from), Some(to)) = (first, last) else {
        return Err(EvalError::conflict_on(
            &["start_s", "end_s"],
            format!("{}: no sample between {{start_s}} and {{end_s}}: the record is {length} s long", path.display()),
        ));
    };
    if to <= from {
        return Err(EvalError::conflict_on(
            &["start_s", "end_s"],
            format!(
                "{}: fewer than two samples between {{start_s}} and {{end_s}}: the record is {length} s long",
                path.display()
            ),
        ));
    }
    let range = from..to + 1;
    let (from_s, to_s) = (offset(from).unwrap_or(0.0), offset(to).unwrap_or(0.0));
    let first_line = data.lines.get(from).unwrap_or(0);
    let last_line = data.lines.get(to).unwrap_or(0);
    for c in &mut data.channels {
        *c = c[range.clone()].to_vec();
    }
    if let Some(t) = &mut data.time {
        *t = t[range.clone()].to_vec();
    }
    if let Some(t) = &mut data.temperature {
        if t.len() >= range.end {
            *t = t[range.clone()].to_vec();
        }
    }
    if let Some(t) = &mut data.table_rate {
        if t.len() >= range.end {
            *t = t[range.clone()].to_vec();
        }
    }
    let mut lines = gyrolab_io::series::LineMap::default();
    for i in range.clone() {
        lines.push(data.lines.get(i).unwrap_or(0));
    }
    data.lines = lines;
    Ok(Some(ReadNote::Window { from_s, to_s, samples: range.len(), of: n, first_line, last_line }))
}

/// The analyses of a file (or of one topic of a recording).
#[derive(Debug, Clone)]
pub struct AllanOutcome {
    /// The topic, for a recording.
    pub topic: Option<TopicMeta>,
    /// One per channel, in column order.
    pub analyses: Vec<ChannelAnalysis>,
    /// The sampling interval used, s.
    pub sample_interval_s: f64,
    /// What the reader decided or left out, for the user (shown as `note:` lines).
    pub notes: Vec<ReadNote>,
}

/// Something the reader decided or left out, shown to the user.
#[derive(Debug, Clone, PartialEq)]
pub enum ReadNote {
    /// A column not read, and why.
    Skipped(SkippedColumn),
    /// The unit of the time column when it was not written in the header.
    TimeUnit {
        /// The column's name.
        column: String,
        /// The unit taken.
        unit: TimeUnit,
        /// Where it came from.
        source: UnitSource,
    },
    /// More than three orientation and covariance fields of a ROS export, skipped (one note for
    /// all of them).
    RosFieldsSkipped {
        /// How many.
        count: usize,
        /// The first one's name.
        first: String,
        /// The last one's name.
        last: String,
    },
    /// The time unit was assumed to be seconds, but the stamps step by a whole number of
    /// "seconds" (1 Hz or slower): perhaps a count of milliseconds. Shown as a warning.
    TimeUnitDoubt {
        /// The column's name.
        column: String,
        /// The sampling interval in the assumed unit (s).
        step: f64,
    },
    /// Channels without a unit: analysed in their own units, no noise terms.
    Unitless {
        /// Their names.
        channels: Vec<String>,
    },
    /// Gaps in the time stamps: samples missing, computed over.
    Gaps {
        /// Number of gaps.
        count: usize,
        /// Samples missing in all of them.
        missing: usize,
        /// (row of the first sample after the gap, samples missing), the first few.
        first: Vec<(u64, usize)>,
        /// What the rows count.
        rows: RowKind,
        /// What was done with them.
        policy: GapPolicy,
        /// Too many were missing for `fill`: the deviations are window averages of the samples
        /// present ([`ReadNote::FillDeclined`]).
        present: bool,
    },
    /// The clock model of the time stamps and the evidence it was decided on.
    Clock(ClockModel),
    /// The gravity check of a three-axis accelerometer (a warning when a window's magnitude is
    /// not 1 g within the tolerance).
    Gravity(gyrolab::stillness::GravityCheck),
    /// A time stamp going back to or before the first one (a clock reset, a trailer of zeros)
    /// ended the record: the rows before it are analysed. Shown as a warning.
    Reset {
        /// The reset.
        reset: Reset,
        /// Row of the stamp that goes back.
        row: u64,
        /// What the rows count.
        rows: RowKind,
    },
    /// Isolated missing samples filled (gap policy `fill`).
    Filled {
        /// Samples filled, per channel (the most of any channel).
        filled: usize,
        /// Runs filled.
        runs: usize,
        /// Samples left missing (runs longer than three, or at an end).
        left: usize,
        /// Samples of that channel's record (on its grid), filled ones included.
        samples: usize,
    },
    /// Gap policy `fill` declined: more samples missing than the fill rule is checked for
    /// ([`MAX_FILLED_SHARE`]); each tau's windows are averaged over the samples present
    /// (`gyrolab::allan::present`), which keeps the long taus.
    FillDeclined {
        /// Samples missing on the record's grid.
        missing: usize,
        /// Samples of the grid, missing ones included.
        samples: usize,
    },
    /// The gaps left out the long taus: the curve stops before a quarter of the record.
    LongTausLost {
        /// The longest tau of the curve, s.
        longest_s: f64,
        /// A quarter of the record's length, s.
        quarter_s: f64,
    },
    /// NaN or empty cells, treated as missing samples.
    MissingCells {
        /// How many.
        count: u64,
        /// The first one's row.
        first_line: u64,
        /// What the rows count.
        rows: RowKind,
    },
    /// Dropout rows (every channel zero, or repeating the row before), treated as missing.
    Dropouts {
        /// All-zero rows.
        all_zero: usize,
        /// Repeated rows.
        repeated: usize,
        /// Rows of the first few.
        first_lines: Vec<u64>,
        /// What the rows count.
        rows: RowKind,
    },
    /// Dropout rows could not be looked for: fewer than two channels were read, and the file's
    /// other channel columns were selected out.
    DropoutsUnchecked {
        /// The channels read.
        read: Vec<String>,
        /// The columns not read because they were not selected.
        not_read: Vec<String>,
    },
    /// A sample rate was given beside a time column: which one was used.
    SampleRateGiven {
        /// The given rate, Hz.
        given_hz: f64,
        /// The rate of the time stamps, Hz.
        stamps_hz: f64,
    },
    /// The sample rate estimated from the time stamps.
    SampleRateEstimated {
        /// The rate, Hz.
        hz: f64,
    },
    /// The topic of a recording that was read.
    Topic(TopicMeta),
    /// The recording ends early or is damaged: what was read is analysed.
    Truncated(String),
    /// The record's temperature moved by more than
    /// [`gyrolab::record_temperature::MOVED_SPAN_C`] (a warning).
    TemperatureMoved(gyrolab::record_temperature::RecordTemperature),
    /// The part of the record analysed (`window_s`).
    Window {
        /// Its first sample, s from the record's first.
        from_s: f64,
        /// Its last sample, s from the record's first.
        to_s: f64,
        /// Samples kept.
        samples: usize,
        /// Samples of the record.
        of: usize,
        /// Line (message) of its first sample.
        first_line: u64,
        /// Line (message) of its last sample.
        last_line: u64,
    },
    /// An IMU topic left out because no topic was named and it is no sensor's own sample
    /// stream (a snapshot, an integrated or a too-short topic).
    TopicSkipped(gyrolab_io::recording::SkippedTopic),
}

impl std::fmt::Display for ReadNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadNote::Skipped(s) => write!(f, "{s}"),
            ReadNote::TimeUnit { column, unit, source } => {
                let why = match source {
                    UnitSource::Magnitude => "from the magnitude of the stamps (epoch time)",
                    UnitSource::RosConvention => "by the ROS convention (rostopic echo -p writes nanoseconds)",
                    _ => "assumed: the header names no unit",
                };
                write!(f, "time column '{column}' read in {} ({why}); give {{units}} {column}=UNIT if that is wrong", unit.symbol())
            }
            ReadNote::RosFieldsSkipped { count, first, last } => write!(
                f,
                "{count} orientation and covariance fields of a ROS message skipped ('{}' to '{}')",
                gyrolab_io::text::excerpt(first),
                gyrolab_io::text::excerpt(last)
            ),
            ReadNote::TimeUnitDoubt { column, step } => write!(
                f,
                "time column '{column}' read in s (assumed: the header names no unit), but its stamps step by whole seconds ({step} s, {:.4} Hz): if they count milliseconds (a microcontroller's millis(), say), give {{units}} {column}=ms (then {} Hz)",
                1.0 / step,
                1000.0 / step
            ),
            ReadNote::Gaps { count, missing, first, rows, policy, present } => {
                let shown: Vec<String> =
                    first.iter().map(|(l, m)| format!("{} {l} ({m} missing)", rows.word())).collect();
                let done = match policy {
                    _ if *present => "too many for filling: each window averaged over the samples present (below)",
                    GapPolicy::Contiguous => "closed up ({gaps} contiguous: the samples taken as consecutive)",
                    GapPolicy::Fill => "runs of up to 3 filled by linear interpolation, longer ones computed over (terms that touch a missing sample are left out)",
                    _ => "computed over them (terms that touch a missing sample are left out)",
                };
                write!(
                    f,
                    "{count} gap(s) in the time stamps, {missing} sample(s) missing, first at {}: {done}; {{gaps}} fill, analyse, contiguous or error chooses",
                    shown.join(", ")
                )
            }
            ReadNote::Clock(c) => write!(f, "clock: {c}"),
            ReadNote::Gravity(g) if g.outside_windows == 0 => write!(
                f,
                "gravity: the accelerometer's magnitude is {:.4} m/s^2 (median of {} windows), within {:.3} m/s^2 \
                 of 1 g (9.80665 m/s^2) in every window",
                g.median_magnitude_m_s2, g.windows, g.tolerance_m_s2
            ),
            ReadNote::Gravity(g) => write!(
                f,
                "gravity: the accelerometer's magnitude is not 1 g (9.80665 m/s^2) within {:.3} m/s^2 in {} of {} \
                 windows (first at {:.1} s; median {:.4} m/s^2, largest departure {:.4} m/s^2): the sensor \
                 accelerated, or the accelerometer's unit or scale is wrong (m/s^2 against g: give {{units}}), or \
                 gravity was removed from the samples",
                g.tolerance_m_s2,
                g.outside_windows,
                g.windows,
                g.first_outside_s.unwrap_or(f64::NAN),
                g.median_magnitude_m_s2,
                g.largest_departure_m_s2
            ),
            ReadNote::Reset { reset, row, rows } => write!(
                f,
                "the time stamps go back at {} {row} (from {} s to {} s: a clock reset or a trailer of zeros): the record ends before it, {} row(s) from there left out",
                rows.word(),
                reset.from_s,
                reset.to_s,
                reset.left_out
            ),
            ReadNote::Filled { filled, runs, left, .. } => write!(
                f,
                "{filled} missing sample(s) in {runs} run(s) of up to 3 filled by linear interpolation between their neighbours ({{gaps}} fill; {left} left missing); {{gaps}} analyse leaves them out instead"
            ),
            ReadNote::FillDeclined { missing, samples } => write!(
                f,
                "{missing} missing sample(s), {:.2} % of the record: more than the {:.0} % the fill rule is checked for, so none is filled; each tau's windows are averaged over the samples present (a window with fewer than half its samples is not used) and the white-noise excess of the missing samples is removed, which keeps the long taus (docs/METHODS.md, present-sample estimator); {{gaps}} analyse leaves out every term that touches a missing sample instead",
                100.0 * *missing as f64 / (*samples).max(1) as f64,
                100.0 * MAX_FILLED_SHARE
            ),
            ReadNote::LongTausLost { longest_s, quarter_s } => write!(
                f,
                "the missing samples leave out the long taus: the curve stops at {longest_s:.6} s, a quarter of the record is {quarter_s:.6} s; {{gaps}} fill (isolated samples) or contiguous keeps them"
            ),
            ReadNote::MissingCells { count, first_line, rows } => write!(
                f,
                "{count} NaN or empty cell(s), first at {} {first_line}: treated as missing samples",
                rows.word()
            ),
            ReadNote::Dropouts { all_zero, repeated, first_lines, rows } => write!(
                f,
                "{} dropout row(s) ({all_zero} with every channel zero, {repeated} repeating the row before), first at {}(s) {}: treated as missing samples",
                all_zero + repeated,
                rows.word(),
                first_lines.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")
            ),
            ReadNote::DropoutsUnchecked { read, not_read } => write!(
                f,
                "dropout rows (every channel zero, or repeating the row before) are looked for over two or more channels: with only {} read, such rows count as data; read {} too (name them with {{columns}}, or leave {{columns}} out) to find them",
                gyrolab_io::text::excerpt(&read.join(", ")),
                gyrolab_io::text::excerpt(&not_read.join(", "))
            ),
            ReadNote::SampleRateGiven { given_hz, stamps_hz } => {
                write!(f, "sample rate {given_hz} Hz as given ({{sample_rate_hz}}); the time stamps say {stamps_hz:.6} Hz")?;
                if self.is_warning() {
                    write!(f, " ({:+.3} %): the given rate is used", (given_hz / stamps_hz - 1.0) * 100.0)?;
                }
                Ok(())
            }
            ReadNote::Topic(t) => {
                write!(
                    f,
                    "topic {} ({}): {} messages, time from {}",
                    gyrolab_io::text::excerpt(&t.topic),
                    gyrolab_io::text::excerpt(&t.message_type),
                    t.messages,
                    t.stamp_source.describe()
                )?;
                if t.out_of_order > 0 {
                    write!(f, "; {} message(s) came out of stamp order in the file and were put in order", t.out_of_order)?;
                }
                Ok(())
            }
            ReadNote::Truncated(what) => f.write_str(what),
            ReadNote::TemperatureMoved(t) => write!(
                f,
                "the temperature ({}) moved by {:.3} degC during the record ({:.3} to {:.3} degC, drift {:.3} degC/h), more than {} degC: slow terms (bias instability, rate random walk, rate ramp) may be the temperature's; test at a stabilised temperature",
                t.column,
                t.span_c,
                t.min_c,
                t.max_c,
                t.slope_c_per_h,
                gyrolab::record_temperature::MOVED_SPAN_C
            ),
            ReadNote::Window { from_s, to_s, samples, of, first_line, last_line } => write!(
                f,
                "analysed from {from_s} s to {to_s} s of the record ({{start_s}}, {{end_s}}): {samples} of {of} samples, rows {first_line} to {last_line}"
            ),
            ReadNote::TopicSkipped(s) => write!(
                f,
                "topic {} skipped: {}; name it with {{topics}} to analyse it anyway",
                gyrolab_io::text::excerpt(&s.topic),
                s.reason
            ),
            ReadNote::SampleRateEstimated { hz } => {
                write!(f, "sample rate {hz:.6} Hz, estimated from the time stamps (mean interval)")
            }
            ReadNote::Unitless { channels } => {
                let first = channels.first().map_or("gx", String::as_str);
                let accel =
                    gyrolab_io::series::is_accelerometer_name(&gyrolab::units::parse_column_name(first).base);
                write!(
                    f,
                    "no unit for {}: deviations in the columns' own units, no noise terms; give {{units}} {first}={} for one column, or {{units}} rad/s (and {{units}} m/s^2 for accelerometers) for every column without one",
                    channels.join(", "),
                    if accel { "m/s^2" } else { "rad/s" }
                )
            }
        }
    }
}

impl ReadNote {
    /// Whether the note is a warning (the figures may be wrong as read) rather than information.
    pub fn is_warning(&self) -> bool {
        match self {
            ReadNote::SampleRateGiven { given_hz, stamps_hz } => {
                let off = (given_hz / stamps_hz - 1.0).abs();
                off.is_nan() || off > RATE_TOLERANCE
            }
            _ => matches!(
                self,
                ReadNote::Truncated(_)
                    | ReadNote::TemperatureMoved(_)
                    | ReadNote::Gravity(gyrolab::stillness::GravityCheck { outside_windows: 1.., .. })
                    | ReadNote::TimeUnitDoubt { .. }
                    | ReadNote::Reset { .. }
                    | ReadNote::LongTausLost { .. }
            ),
        }
    }

    /// The note with its option placeholders (`{units}`) spelled by the front end.
    pub fn render(&self, spell: &dyn Fn(&str) -> String) -> String {
        let mut t = self.to_string();
        for f in ["units", "gaps", "sample_rate_hz", "columns", "topics", "start_s", "end_s"] {
            t = t.replace(&format!("{{{f}}}"), &spell(f));
        }
        t
    }
}

/// The notes of a file's header: skipped columns, a time unit not written in the header,
/// channels without a unit.
pub fn read_notes(header: &gyrolab_io::series::SeriesHeader) -> Vec<ReadNote> {
    // Columns left out by the user's own selection are no news; a ROS export's many orientation
    // and covariance fields are one note.
    let ros: Vec<&SkippedColumn> = header.skipped.iter().filter(|s| s.reason == SkipReason::RosField).collect();
    let group_ros = ros.len() > 3;
    let mut notes: Vec<ReadNote> = header
        .skipped
        .iter()
        .filter(|s| s.reason != SkipReason::NotSelected && !(group_ros && s.reason == SkipReason::RosField))
        .cloned()
        .map(ReadNote::Skipped)
        .collect();
    if let (true, Some(first), Some(last)) = (group_ros, ros.first(), ros.last()) {
        notes.push(ReadNote::RosFieldsSkipped { count: ros.len(), first: first.name.clone(), last: last.name.clone() });
    }
    if let (Some(c), Some(unit), Some(source)) = (header.time_column, header.time_unit, header.time_unit_source) {
        if !matches!(source, UnitSource::Header | UnitSource::Column) {
            let column = header.columns.get(c - 1).map_or(String::new(), |x| x.name.clone());
            notes.push(ReadNote::TimeUnit { column, unit, source });
        }
    }
    let unitless: Vec<String> =
        header.channels.iter().filter(|c| c.unit == OutputUnit::Unitless).map(|c| c.name.clone()).collect();
    if !unitless.is_empty() {
        notes.push(ReadNote::Unitless { channels: unitless });
    }
    notes
}

/// Parses a tau list: `octave`, `decade`, `all`, `N/decade`, or seconds (`0.1,1,10`).
pub fn parse_taus(text: &str) -> EvalResult<TauList> {
    let bad = || {
        InvalidOption::new("taus", format!("'{text}': expected octave, decade, all, N/decade or seconds like 0.1,1,10"))
    };
    if text.chars().next().is_some_and(|c| c.is_ascii_digit()) && !text.contains('/') {
        let v: Result<Vec<f64>, _> = text.split(',').map(|s| s.trim().parse::<f64>()).collect();
        return Ok(TauList::Seconds(v.map_err(|_| bad())?));
    }
    TauList::parse(text).map_err(|e| EvalError::conflict(e.to_string()))
}

/// Parses a confidence level: a probability, or `none`.
pub fn parse_confidence(text: &str) -> Result<Option<f64>, InvalidOption> {
    match text.trim() {
        "none" => Ok(None),
        c => match c.parse::<f64>() {
            Ok(x) if x > 0.0 && x < 1.0 => Ok(Some(x)),
            _ => Err(InvalidOption::new(
                "confidence",
                format!("must lie strictly between 0 and 1, or be 'none'; got '{c}'"),
            )),
        },
    }
}

/// Largest relative difference between a given sample rate and the rate of the time stamps: 1 %.
pub const RATE_TOLERANCE: f64 = 0.01;

/// When a given sample rate disagrees with the time stamps `t` of `path` by more than
/// [`RATE_TOLERANCE`], the message saying so (`option` names the given rate: a flag placeholder
/// or a plan key); `None` when they agree or the stamps give no rate.
pub fn rate_disagreement(t: &[f64], given_hz: f64, option: &str, path: &Path) -> Option<String> {
    disagreement(&estimate_interval(t).ok()?, given_hz, option, path)
}

/// The message of [`rate_disagreement`] for an estimate already made.
fn disagreement(est: &gyrolab::sampling::IntervalEstimate, given_hz: f64, option: &str, path: &Path) -> Option<String> {
    let stamps_hz = est.rate_hz();
    if !stamps_hz.is_finite() || (given_hz * est.interval_s - 1.0).abs() <= RATE_TOLERANCE {
        return None;
    }
    Some(format!(
        "{option} = {given_hz} Hz disagrees with the time column of {}, whose stamps say {:.6} Hz (interval {} s): \
         give the rate the stamps say, or leave the rate out to use them",
        path.display(),
        stamps_hz,
        est.interval_s
    ))
}

/// The time stamps of the first `rows` samples of a file (none without a time column), for
/// checking a given rate against them without reading the whole file.
pub fn first_times(path: &Path, options: &SeriesOptions, rows: usize) -> EvalResult<Option<Vec<f64>>> {
    let options = SeriesOptions { block_rows: rows.max(2), ..options.clone() };
    let mut r = gyrolab_io::series::SeriesReader::open(path, &options)?;
    if r.header().time_column.is_none() {
        return Ok(None);
    }
    Ok(r.next_block()?.and_then(|b| b.time.map(<[f64]>::to_vec)))
}

/// The timing of a record: its sampling interval and where it came from, and the samples
/// missing from its time stamps.
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    /// The sampling interval used, s.
    pub tau0_s: f64,
    /// The gaps found in the time stamps (none without a time column).
    pub gaps: Vec<gyrolab::sampling::Gap>,
    /// Samples missing in all gaps.
    pub missing: usize,
    /// The note saying which rate was used.
    pub note: Option<ReadNote>,
    /// The clock model of the time stamps (none without a time column).
    pub clock: Option<ClockModel>,
    /// A stamp going back that ends the record: samples from its index on are left out.
    pub reset: Option<Reset>,
}

/// The timing of a record: the given rate (a warning note gives the stamps' reading when they
/// disagree), else the time column's by the one estimator and clock model
/// ([`gyrolab::sampling`]), with the gaps of the stamps. A stamp that does not increase is an
/// error naming its line, unless it goes back to or before the first stamp (a reset: the
/// record ends before it, [`Timing::reset`]); gaps are an error under [`GapPolicy::Error`].
pub fn record_timing(data: &SeriesData, path: &Path, given_hz: Option<f64>, policy: GapPolicy) -> EvalResult<Timing> {
    // The stamps as read, or kept compactly by the reader (the same estimate either way).
    let estimate = match &data.time {
        Some(t) => Some(estimate_interval(t)),
        None => data.time_compact.as_ref().map(estimate_interval_of),
    }
    .transpose()
    .map_err(|e| match e {
        SamplingError::TooShort => DataError::new(path, "fewer than two samples: nothing to analyse"),
        SamplingError::NotIncreasing => {
            DataError::new(path, "the time stamps do not increase: expected increasing time stamps")
        }
    })?;
    if let Some(e) = &estimate {
        if let Some(g) = e.first_non_increasing {
            let line = data.lines.get(g.index).unwrap_or(0);
            return Err(DataError::new(
                path,
                format!(
                    "the time stamp does not increase (interval {} s): the Allan variance needs increasing time stamps (remove repeated or unsorted rows)",
                    g.interval_s
                ),
            )
            .at_line(line)
            .into());
        }
        if policy == GapPolicy::Error {
            if let Some(g) = e.gaps.first() {
                let line = data.lines.get(g.index).unwrap_or(0);
                return Err(DataError::new(
                    path,
                    format!(
                        "a gap in the time stamps: {} sample(s) missing (interval {} s where the record's is {} s), and gaps were refused",
                        g.missing, g.interval_s, e.interval_s
                    ),
                )
                .at_line(line)
                .into());
            }
        }
    }
    let (mut gaps, mut missing) = estimate.as_ref().map_or((Vec::new(), 0), |e| (e.gaps.clone(), e.missing));
    let clock = estimate.as_ref().map(|e| e.clock);
    let reset = estimate.as_ref().and_then(|e| e.reset);
    // A given rate within GRID_AT_GIVEN_RATE of the stamps' builds the grid at that rate: the
    // gaps counted in its intervals. One that contradicts them (warned) keeps the stamps' grid:
    // the user may know the sensor's clock better than a logger that drops messages.
    if let Some((f, e)) =
        given_hz.zip(estimate.as_ref()).filter(|(f, e)| (f / e.rate_hz() - 1.0).abs() <= GRID_AT_GIVEN_RATE)
    {
        let end = e.reset.map_or(usize::MAX, |r| r.index);
        gaps = match (&data.time, &data.time_compact) {
            (Some(t), _) => gyrolab::sampling::gaps_at(&t[..], 1.0 / f, &e.clock, end),
            (None, Some(c)) => gyrolab::sampling::gaps_at(c, 1.0 / f, &e.clock, end),
            (None, None) => gaps,
        };
        missing = gaps.iter().map(|g| g.missing).sum();
    }
    check_grid_size(data, path, &gaps, missing)?;
    match (given_hz, &estimate) {
        // A given rate is used; the note (a warning when they disagree) gives the stamps'.
        (Some(f), Some(e)) => Ok(Timing {
            tau0_s: 1.0 / f,
            gaps,
            missing,
            note: Some(ReadNote::SampleRateGiven { given_hz: f, stamps_hz: e.rate_hz() }),
            clock,
            reset,
        }),
        (Some(f), None) => Ok(Timing { tau0_s: 1.0 / f, gaps, missing, note: None, clock, reset }),
        (None, Some(e)) => Ok(Timing {
            tau0_s: e.interval_s,
            gaps,
            missing,
            note: Some(ReadNote::SampleRateEstimated { hz: e.rate_hz() }),
            clock,
            reset,
        }),
        (None, None) => Err(EvalError::conflict_on(
            &["sample_rate_hz"],
            format!("{}: no time column (such as time_s): give {{sample_rate_hz}}", path.display()),
        )),
    }
}

/// Largest relative difference between a given sample rate and the stamps' for the record's
/// grid to be built at the given rate (beyond it the given rate contradicts the stamps, a
/// warning says so, and the stamps' own grid is kept with the given interval).
pub const GRID_AT_GIVEN_RATE: f64 = 0.05;

/// Most samples the gaps of a record may add to its uniform grid, as a multiple of the samples
/// it has: 1 (the grid at most twice the record). A stamp that leaps (far in the future, zero,
/// negative, a clock that falls back to another epoch) would otherwise size the grid: one stamp
/// 54 years away at 1 kHz asks for 1.7e12 slots (14 TB per channel). Such a record is refused,
/// naming the line (message) of its longest gap, before anything is allocated.
pub const MAX_GAP_FILL: usize = 1;

/// Refuses a record whose gaps would make its uniform grid more than [`MAX_GAP_FILL`] times its
/// samples longer (see there).
fn check_grid_size(data: &SeriesData, path: &Path, gaps: &[gyrolab::sampling::Gap], missing: usize) -> EvalResult<()> {
    let n = data.channels.first().map_or(0, Vec::len);
    if missing <= n.saturating_mul(MAX_GAP_FILL) {
        return Ok(());
    }
    let Some(g) = gaps.iter().max_by_key(|g| g.missing) else { return Ok(()) };
    let line = data.lines.get(g.index).unwrap_or(0);
    Err(DataError::new(
        path,
        format!(
            "the time stamps leap: a gap of {} s before this sample would leave {} samples missing ({} in all gaps), more than the record's {n} samples; a stamp far from the others (damaged, zero, or on another clock) — split the record at the leap or remove the stamp",
            g.interval_s, g.missing, missing
        ),
    )
    .at_line(line)
    .into())
}

/// Places a channel's samples on the uniform grid of the record: sample i goes to slot
/// i + (samples missing before it); missing slots hold NaN.
pub fn on_grid(values: Vec<f64>, gaps: &[gyrolab::sampling::Gap], missing: usize) -> Vec<f64> {
    if missing == 0 {
        return values;
    }
    let mut out = Vec::with_capacity(values.len() + missing + 1);
    let mut from = 0usize;
    for g in gaps {
        out.extend_from_slice(&values[from..g.index.min(values.len())]);
        out.extend(std::iter::repeat_n(f64::NAN, g.missing));
        from = g.index.min(values.len());
    }
    out.extend_from_slice(&values[from..]);
    out
}

/// The deviation curve of one channel's rate samples; a non-finite sample is an error naming
/// its file line and column (`lines[i]` is the line of sample i).
pub fn channel_curve(
    path: &Path,
    info: &ChannelInfo,
    values: Vec<f64>,
    lines: &LineMap,
    tau0_s: f64,
    opts: &AllanOptions,
) -> EvalResult<AllanCurve> {
    deviation_from_rate_with_gaps(values, tau0_s, opts).map_err(|e| curve_error(path, info, lines, e))
}

/// The error of a channel's deviation curve, located: a non-finite sample names its file line
/// and column.
fn curve_error(path: &Path, info: &ChannelInfo, lines: &LineMap, e: AllanError) -> EvalError {
    match e {
        AllanError::NonFinite { index, value } => match lines.get(index) {
            Some(line) => EvalError::Data(
                DataError::new(
                    path,
                    format!("sample {value} is not a finite number: the Allan variance needs a complete record"),
                )
                .at_line(line)
                .at_column(info.column, Some(&info.name)),
            ),
            // samples with no source lines (an array in memory): the index is the location
            None => EvalError::Data(DataError::new(
                path,
                format!(
                    "{}[{index}] = {value} is not a finite number: the Allan variance needs a complete record",
                    gyrolab_io::text::excerpt(&info.name)
                ),
            )),
        },
        other => EvalError::Data(DataError::new(
            path,
            format!("channel '{}': {other}", gyrolab_io::text::excerpt(&info.name)),
        )),
    }
}

/// What one channel's analysis needs besides its samples.
pub struct ChannelSetup<'a> {
    /// The file, as read.
    pub path: &'a Path,
    /// The file as shown in results.
    pub shown: String,
    /// The topic of a recording the channel belongs to.
    pub topic: Option<String>,
    /// Source line of each sample.
    pub lines: &'a LineMap,
    /// Sampling interval, s.
    pub tau0_s: f64,
    /// Deviation options.
    pub options: &'a AllanOptions,
    /// Output-to-rate reference.
    pub reference: &'a Reference,
    /// Tau range of the five-term fit, s.
    pub fit_range_s: Option<(f64, f64)>,
    /// What to tell the user when the data cannot be turned into rates.
    pub uncalibrated_hint: &'a str,
    /// The analysis of a channel that moved was asked for (marks the result).
    pub allow_motion: bool,
}

/// Analyses one channel: converts it to deg/s, computes the curve and, for data in deg/s and an
/// Allan deviation, the noise terms.
pub fn analyse_channel(setup: &ChannelSetup<'_>, info: &ChannelInfo, values: Vec<f64>) -> EvalResult<ChannelAnalysis> {
    analyse_channel_by(setup, info, values, false)
}

/// [`analyse_channel`] of a record with more samples missing than filling is safe for: each
/// tau's windows averaged over the samples present, the white-noise excess of the missing ones
/// removed ([`gyrolab::allan::present`]; windows with fewer than half their samples not used).
pub fn analyse_channel_present(
    setup: &ChannelSetup<'_>,
    info: &ChannelInfo,
    values: Vec<f64>,
) -> EvalResult<ChannelAnalysis> {
    analyse_channel_by(setup, info, values, true)
}

/// [`analyse_channel`] by the gap rule, or by the present-sample estimator (`present`).
fn analyse_channel_by(
    setup: &ChannelSetup<'_>,
    info: &ChannelInfo,
    mut values: Vec<f64>,
    present: bool,
) -> EvalResult<ChannelAnalysis> {
    let (quantity, conversion) = physical_conversion(setup, info)?;
    conversion.apply(&mut values);
    let stillness = check_channel(&values, setup.tau0_s, quantity);
    let curve = if present {
        gyrolab::allan::present::deviation_from_rate_present(
            &values,
            setup.tau0_s,
            setup.options,
            gyrolab::allan::present::DEFAULT_MIN_PRESENT_SHARE,
        )
        .map_err(|e| curve_error(setup.path, info, setup.lines, e))?
    } else {
        values.reserve_exact(1);
        channel_curve(setup.path, info, values, setup.lines, setup.tau0_s, setup.options)?
    };
    Ok(channel_analysis(setup, info, quantity, curve, stillness))
}

/// [`analyse_channel`] of borrowed samples: samples that need no unit conversion are read where
/// they are and the angle series is built in `buffer` (no copy of the record); others are
/// copied into `buffer` and converted there. Give `buffer` capacity N + 1 (on the pages you
/// want it on) to spare a reallocation. `missing`: [`GapPolicy::Analyse`] reads NaN samples as
/// missing ones (as [`analyse_channel`] does), [`GapPolicy::Error`] refuses them as it refuses
/// infinite ones.
pub fn analyse_channel_borrowed(
    setup: &ChannelSetup<'_>,
    info: &ChannelInfo,
    values: &[f64],
    mut buffer: Vec<f64>,
    missing: GapPolicy,
) -> EvalResult<ChannelAnalysis> {
    let (quantity, conversion) = physical_conversion(setup, info)?;
    if conversion != Conversion::Identity {
        buffer.clear();
        buffer.reserve_exact(values.len() + 1);
        buffer.extend_from_slice(values);
        conversion.apply(&mut buffer);
        let stillness = check_channel(&buffer, setup.tau0_s, quantity);
        let curve = match missing {
            GapPolicy::Analyse | GapPolicy::Fill | GapPolicy::Contiguous => {
                channel_curve(setup.path, info, buffer, setup.lines, setup.tau0_s, setup.options)?
            }
            GapPolicy::Error => deviation_from_rate(buffer, setup.tau0_s, setup.options)
                .map_err(|e| curve_error(setup.path, info, setup.lines, e))?,
        };
        return Ok(channel_analysis(setup, info, quantity, curve, stillness));
    }
    let stillness = check_channel(values, setup.tau0_s, quantity);
    match missing {
        GapPolicy::Analyse | GapPolicy::Fill | GapPolicy::Contiguous => {
            let curve = deviation_from_rate_with_gaps_into(values, buffer, setup.tau0_s, setup.options)
                .map_err(|e| curve_error(setup.path, info, setup.lines, e))?;
            Ok(channel_analysis(setup, info, quantity, curve, stillness))
        }
        GapPolicy::Error => analyse_complete(setup, info, quantity, values, buffer, stillness),
    }
}

/// The analysis of rate samples that must all be finite, the angle series built in `buffer`.
fn analyse_complete(
    setup: &ChannelSetup<'_>,
    info: &ChannelInfo,
    quantity: Quantity,
    values: &[f64],
    buffer: Vec<f64>,
    stillness: Option<StillnessCheck>,
) -> EvalResult<ChannelAnalysis> {
    let curve = deviation_from_rate_into(values, buffer, setup.tau0_s, setup.options)
        .map_err(|e| curve_error(setup.path, info, setup.lines, e))?;
    Ok(channel_analysis(setup, info, quantity, curve, stillness))
}

/// What the channel's samples are in physical terms, and the conversion that makes them so.
pub(crate) fn physical_conversion(setup: &ChannelSetup<'_>, info: &ChannelInfo) -> EvalResult<(Quantity, Conversion)> {
    setup.reference.physical_conversion(info.unit).map_err(|m| {
        EvalError::conflict(format!(
            "{}: channel '{}': {m}",
            setup.path.display(),
            gyrolab_io::text::excerpt(&info.name)
        ))
    })
}

/// The noise terms of a channel's curve (when its data and kind allow them), with the curve.
pub(crate) fn channel_analysis(
    setup: &ChannelSetup<'_>,
    info: &ChannelInfo,
    quantity: Quantity,
    curve: AllanCurve,
    stillness: Option<StillnessCheck>,
) -> ChannelAnalysis {
    let calibrated = matches!(quantity, Quantity::AngularRate | Quantity::Acceleration);
    let rate_unit = match quantity {
        Quantity::AngularRate => "deg/s".to_string(),
        Quantity::Acceleration => "m/s^2".to_string(),
        _ => info.unit.symbol().to_string(),
    };
    let allan_kind = matches!(setup.options.kind, DeviationKind::Oadev | DeviationKind::Adev);
    let gmwm = if calibrated && allan_kind {
        LazyGmwm::at_confidence(curve.confidence.unwrap_or(DEFAULT_GMWM_CONFIDENCE))
    } else {
        LazyGmwm::none()
    };
    let (slope_lines, model_fit, noise_note) = if quantity == Quantity::Unitless {
        (
            None,
            None,
            Some(
                "the column has no unit: give one (such as rad/s, deg/s, m/s^2, V with a scale factor) for noise terms"
                    .to_string(),
            ),
        )
    } else if !calibrated {
        (None, None, Some(format!("the data are in {rate_unit}: {}", setup.uncalibrated_hint)))
    } else if !allan_kind {
        (None, None, Some("noise terms are read from the Allan deviation (kind oadev or adev)".to_string()))
    } else {
        (slope_line_terms(&curve).ok(), fit_noise_model(&curve, setup.fit_range_s).ok(), None)
    };
    ChannelAnalysis {
        file: setup.shown.clone(),
        topic: setup.topic.clone(),
        channel: info.name.clone(),
        rate_unit,
        quantity,
        curve,
        slope_lines,
        model_fit,
        noise_note,
        gmwm,
        stillness,
        allow_motion: setup.allow_motion,
        gravity: None,
        temperature: None,
    }
}

/// Confidence of the GMWM intervals when the curve has none (68.3 %, the curve's default).
const DEFAULT_GMWM_CONFIDENCE: f64 = 0.683;

/// Analyses every selected channel of a file, in parallel: a delimited text or Parquet file,
/// or the single IMU topic of a recording (several topics: an error asking for one; see
/// [`analyse_records`]).
pub fn analyse_file(request: &AllanRequest) -> EvalResult<AllanOutcome> {
    let mut outcomes = analyse_records(request)?;
    if outcomes.len() == 1 {
        return Ok(outcomes.remove(0));
    }
    let names: Vec<String> =
        outcomes.iter().filter_map(|o| o.topic.as_ref().map(|t| gyrolab_io::text::excerpt(&t.topic))).collect();
    Err(EvalError::conflict_on(
        &["topics"],
        format!(
            "{}: {} IMU topics ({}): choose one with {{topics}}",
            request.file.display(),
            names.len(),
            names.join(", ")
        ),
    ))
}

/// The request's numbers: a positive sample rate, a confidence in (0, 1), an increasing fit
/// range.
pub(crate) fn validate_request(request: &AllanRequest) -> EvalResult<()> {
    if let Some(f) = request.sample_rate_hz {
        validate::positive("sample_rate_hz", f)?;
    }
    if let Some(c) = request.confidence {
        validate::confidence("confidence", c)?;
    }
    if let Some((a, b)) = request.fit_range_s {
        validate::increasing_pair("fit_range_s", &[a, b])?;
    }
    Ok(())
}

/// Analyses every record of any file gyrolab reads (by content): the table of a delimited
/// text or Parquet file, or each IMU topic of an MCAP file, ROS 1 bag or ULog file (read in
/// one pass; `request.topics` selects), each record's channels in parallel.
pub fn analyse_records(request: &AllanRequest) -> EvalResult<Vec<AllanOutcome>> {
    validate_request(request)?;
    let reference = request.reference.resolve()?;
    let path = &request.file;
    let options = request.layout.apply(SeriesOptions {
        sample_rate_hz: request.sample_rate_hz,
        channels: if request.columns.is_empty() { None } else { Some(request.columns.clone()) },
        tolerant: true,
        // Only the interval and gap search reads the stamps: kept compactly (whole when a part
        // of the record is asked for, to cut it by them).
        compact_time: !request.has_window(),
        ..SeriesOptions::default()
    })?;
    let records = read_records(path, &options, &request.topics)?;
    let mut outcomes = Vec::with_capacity(records.records.len());
    let mut skipped: Vec<ReadNote> = records.skipped.iter().cloned().map(ReadNote::TopicSkipped).collect();
    for record in records.records {
        let rows = record.data.header.rows;
        let topic = record.topic;
        let mut outcome = analyse_data(request, &reference, record.data, topic.as_ref())
            .map_err(|e| located_in(e, rows, topic.as_ref()))?;
        // The topics skipped, said once, before the first topic analysed.
        let mut notes = std::mem::take(&mut skipped);
        if let Some(t) = &topic {
            notes.push(ReadNote::Topic(t.clone()));
        }
        if let Some(what) = &records.truncated {
            notes.push(ReadNote::Truncated(what.clone()));
        }
        notes.append(&mut outcome.notes);
        if let Some(g) = gravity_of(&mut outcome.analyses) {
            notes.push(ReadNote::Gravity(g));
        }
        outcome.notes = notes;
        outcome.topic = topic;
        outcomes.push(outcome);
    }
    refuse_motion(outcomes.iter().flat_map(|o| &o.analyses), &request.file, request.allow_motion)?;
    Ok(outcomes)
}

/// The gravity check of a record with exactly three accelerometer channels (in m/s^2, each with
/// an evaluated stillness check), attached to each of them; `None` for other records.
pub fn gravity_of(analyses: &mut [ChannelAnalysis]) -> Option<gyrolab::stillness::GravityCheck> {
    use gyrolab::units::Quantity;
    let accel: Vec<usize> = (0..analyses.len()).filter(|&i| analyses[i].quantity == Quantity::Acceleration).collect();
    let [a, b, c] = accel[..] else { return None };
    let g = {
        let checks =
            [analyses[a].stillness.as_ref()?, analyses[b].stillness.as_ref()?, analyses[c].stillness.as_ref()?];
        gyrolab::stillness::gravity_check(checks, gyrolab::stillness::GRAVITY_TOLERANCE_M_S2)?
    };
    for i in [a, b, c] {
        analyses[i].gravity = Some(g.clone());
    }
    Some(g)
}

/// Computes the GMWM fit of every channel that has one (each is otherwise computed when first
/// asked for, [`ChannelAnalysis::gmwm`]), the channels in parallel: for an output that shows
/// them all (a record's six IMU channels fitted one after another as they are rendered took
/// a seventh of an MCAP recording's analysis; issue 56).
pub fn prepare_gmwm<'a>(analyses: impl IntoIterator<Item = &'a ChannelAnalysis>) {
    let all: Vec<&ChannelAnalysis> = analyses.into_iter().collect();
    all.par_iter().for_each(|a| {
        a.gmwm();
    });
}

/// Refuses records whose gyro or accelerometer channels moved (the stillness check), unless
/// motion is allowed: the error names each channel that moved, its episodes and {allow_motion}.
pub fn refuse_motion<'a>(
    analyses: impl IntoIterator<Item = &'a ChannelAnalysis>,
    file: &Path,
    allow_motion: bool,
) -> EvalResult<()> {
    if allow_motion {
        return Ok(());
    }
    let moved: Vec<String> = analyses
        .into_iter()
        .filter_map(|a| {
            let summary = a.stillness.as_ref()?.motion_summary()?;
            let topic =
                a.topic.as_ref().map_or(String::new(), |t| format!("topic '{}' ", gyrolab_io::text::excerpt(t)));
            Some(format!("{topic}channel '{}' {summary}", gyrolab_io::text::excerpt(&a.channel)))
        })
        .collect();
    if moved.is_empty() {
        return Ok(());
    }
    Err(EvalError::conflict_on(
        &["allow_motion"],
        format!(
            "{}: the record is not static, so its noise terms would not be a still sensor's: {}; record the \
             sensor at rest, or give {{allow_motion}} to analyse it anyway (every output is then marked)",
            file.display(),
            moved.join("; ")
        ),
    ))
}

/// An error of a record whose rows are not text lines (messages, table rows): the row is named
/// in the message (`message 12: ...`) rather than as a line, with the topic.
pub fn located_in(e: EvalError, rows: RowKind, topic: Option<&TopicMeta>) -> EvalError {
    match e {
        EvalError::Data(mut d) if rows != RowKind::Line || topic.is_some() => {
            if rows != RowKind::Line {
                if let Some(l) = d.line.take() {
                    // Messages are counted in time-stamp order; say so where that differs
                    // from the file's order.
                    let order = match topic {
                        Some(t) if t.out_of_order > 0 => format!(
                            " (counted in time-stamp order: {} of the topic's messages came out of order in the file)",
                            t.out_of_order
                        ),
                        _ => String::new(),
                    };
                    d.message = format!("{} {l}{order}: {}", rows.word(), d.message);
                }
            }
            if let Some(t) = topic {
                d.message = format!("topic '{}': {}", gyrolab_io::text::excerpt(&t.topic), d.message);
            }
            EvalError::Data(d)
        }
        other => other,
    }
}

/// Analyses the channels of one record held in memory, in parallel.
pub fn analyse_data(
    request: &AllanRequest,
    reference: &Reference,
    mut data: SeriesData,
    topic: Option<&TopicMeta>,
) -> EvalResult<AllanOutcome> {
    let path = &request.file;
    let rows = data.header.rows;
    let mut notes = read_notes(&data.header);
    notes.extend(trim_to_window(&mut data, path, request.window_s, request.sample_rate_hz)?);
    let timing = record_timing(&data, path, request.sample_rate_hz, request.gaps)?;
    let tau0 = timing.tau0_s;
    // A stamp going back ends the record: the rows before it are analysed.
    if let Some(r) = timing.reset {
        notes.push(ReadNote::Reset { reset: r, row: data.lines.get(r.index).unwrap_or(0), rows });
        for c in &mut data.channels {
            c.truncate(r.index);
        }
    }
    // Seconds assumed, and a whole number of them between samples (1 Hz or slower): more likely
    // a millisecond counter than an IMU logged at 1 Hz; the warning replaces the plain note.
    if data.header.time_unit_source == Some(UnitSource::Assumed)
        && request.sample_rate_hz.is_none()
        && tau0 >= 1.0
        && (tau0 - tau0.round()).abs() <= 1e-9 * tau0
    {
        for n in &mut notes {
            if let ReadNote::TimeUnit { column, .. } = n {
                *n = ReadNote::TimeUnitDoubt { column: std::mem::take(column), step: tau0.round() };
            }
        }
    }
    notes.extend(timing.clock.map(ReadNote::Clock));
    notes.extend(timing.note.clone());
    if timing.missing > 0 {
        let first = timing.gaps.iter().take(5).map(|g| (data.lines.get(g.index).unwrap_or(0), g.missing)).collect();
        notes.push(ReadNote::Gaps {
            count: timing.gaps.len(),
            missing: timing.missing,
            first,
            rows,
            policy: request.gaps,
            present: false,
        });
    }
    if data.quality.missing_cells > 0 {
        let first_line = data.quality.first_missing.first().map_or(0, |c| c.line);
        if request.gaps == GapPolicy::Error {
            return Err(DataError::new(path, "a NaN or empty cell, and missing samples were refused")
                .at_line(first_line)
                .into());
        }
        notes.push(ReadNote::MissingCells { count: data.quality.missing_cells, first_line, rows });
    }
    // Dropout rows (over every channel of the file that was read): missing samples.
    let dropouts = {
        let refs: Vec<&[f64]> = data.channels.iter().map(|c| &c[..]).collect();
        gyrolab::dropout::find_dropouts(&refs)
    };
    if !dropouts.is_empty() {
        let dropped = dropouts.rows();
        if request.gaps == GapPolicy::Error {
            let line = data.lines.get(dropped[0]).unwrap_or(0);
            return Err(DataError::new(
                path,
                "a dropout row (every channel zero, or repeating the row before), and missing samples were refused",
            )
            .at_line(line)
            .into());
        }
        for c in &mut data.channels {
            for &r in &dropped {
                c[r] = f64::NAN;
            }
        }
        notes.push(ReadNote::Dropouts {
            all_zero: dropouts.all_zero.len(),
            repeated: dropouts.repeated.len(),
            first_lines: dropped.iter().take(5).map(|&r| data.lines.get(r).unwrap_or(0)).collect(),
            rows,
        });
    }
    let not_read: Vec<String> =
        data.header.skipped.iter().filter(|s| s.reason == SkipReason::NotSelected).map(|s| s.name.clone()).collect();
    if data.channels.len() < 2 && !not_read.is_empty() {
        let read = data.header.channels.iter().map(|c| c.name.clone()).collect();
        notes.push(ReadNote::DropoutsUnchecked { read, not_read });
    }
    data.time = None;
    data.time_compact = None;
    // The record's temperature column (rows up to a reset), carried into every channel.
    let temperature = data.temperature.take().and_then(|t| {
        let n = data.channels.first().map_or(t.len(), Vec::len).min(t.len());
        let column = data
            .header
            .temperature_column
            .and_then(|c| data.header.columns.get(c - 1))
            .map_or_else(|| "temperature".to_string(), |c| c.name.clone());
        gyrolab::record_temperature::record_temperature(&column, &t[..n], tau0)
    });
    if let Some(t) = temperature.as_ref().filter(|t| t.moved) {
        notes.push(ReadNote::TemperatureMoved(t.clone()));
    }
    let opts = AllanOptions {
        kind: request.kind,
        taus: request.taus.clone(),
        confidence: request.confidence,
        max_factor: None,
    };
    let infos = data.header.channels.clone();
    let lines = std::mem::take(&mut data.lines);
    let channels = std::mem::take(&mut data.channels);
    let setup = ChannelSetup {
        path,
        shown: path.display().to_string(),
        topic: topic.map(|t| t.topic.clone()),
        lines: &lines,
        tau0_s: tau0,
        options: &opts,
        reference,
        fit_range_s: request.fit_range_s,
        uncalibrated_hint: "give a calibration or a scale factor for noise terms in deg units",
        allow_motion: request.allow_motion,
    };
    let mut policy = request.gaps;
    // Too many missing for `fill`: the present-sample estimator (its long taus kept).
    let mut present = false;
    if policy == GapPolicy::Fill {
        let samples = channels.first().map_or(0, |c| c.len() + timing.missing);
        if timing.missing as f64 > MAX_FILLED_SHARE * samples as f64 {
            notes.push(ReadNote::FillDeclined { missing: timing.missing, samples });
            policy = GapPolicy::Analyse;
            present = true;
            for n in notes.iter_mut() {
                if let ReadNote::Gaps { present: said, .. } = n {
                    *said = true;
                }
            }
        }
    }
    let one = |(values, info): (Vec<f64>, ChannelInfo)| -> EvalResult<(ChannelAnalysis, FillCount, usize)> {
        {
            let mut values = match policy {
                GapPolicy::Contiguous => values,
                _ => on_grid(values, &timing.gaps, timing.missing),
            };
            let fill = if policy == GapPolicy::Fill { fill_isolated(&mut values) } else { FillCount::default() };
            let n = values.len();
            let analysis = if present {
                analyse_channel_present(&setup, &info, values)?
            } else {
                analyse_channel(&setup, &info, values)?
            };
            Ok((analysis, fill, n))
        }
    };
    // A short record on the calling thread, without any rayon call (no pool started: the
    // Python package's small calls, issue 56); else the channels in parallel.
    let total: usize = channels.iter().map(|c| c.len().saturating_add(timing.missing)).sum();
    let results: Vec<EvalResult<(ChannelAnalysis, FillCount, usize)>> = if gyrolab::allan::runs_serially(total) {
        channels.into_iter().zip(infos).map(one).collect()
    } else {
        channels.into_par_iter().zip(infos.into_par_iter()).map(one).collect()
    };
    let results = results.into_iter().collect::<Result<Vec<_>, _>>()?;
    if let Some(most) = results.iter().map(|r| r.1).max_by_key(|f| f.filled).filter(|f| f.filled > 0) {
        let samples = results.iter().map(|r| r.2).max().unwrap_or(0);
        notes.push(ReadNote::Filled { filled: most.filled, runs: most.runs, left: most.left, samples });
    }
    // The gaps left out the long taus of a channel: said once.
    let lost = results.iter().find_map(|(a, _, n)| {
        let quarter_s = *n as f64 * tau0 / 4.0;
        let longest_s = a.curve.points.last().map_or(0.0, |p| p.tau_s);
        let complete = deviation_reaches(&opts, *n, tau0, quarter_s);
        (complete && longest_s < quarter_s / 2.0).then_some(ReadNote::LongTausLost { longest_s, quarter_s })
    });
    notes.extend(lost);
    let mut analyses: Vec<ChannelAnalysis> = results.into_iter().map(|r| r.0).collect();
    for a in &mut analyses {
        a.temperature = temperature.clone();
    }
    Ok(AllanOutcome { topic: None, analyses, sample_interval_s: tau0, notes })
}

/// Whether the averaging times of `opts` over a complete record of `n` samples reach half of
/// `quarter_s` (else a short curve is the tau list's doing, not the gaps').
fn deviation_reaches(opts: &AllanOptions, n: usize, tau0_s: f64, quarter_s: f64) -> bool {
    gyrolab::allan::averaging_factors(opts, n, tau0_s)
        .ok()
        .and_then(|ms| ms.last().copied())
        .is_some_and(|m| m as f64 * tau0_s >= quarter_s / 2.0)
}
