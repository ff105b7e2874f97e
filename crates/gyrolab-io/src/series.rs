//! Streaming reader of time-series text files (CSV, TSV, semicolon or whitespace separated).
//!
//! The file is read in large chunks (default 2 MiB); lines are found with `memchr`, a partial
//! last line is carried into the next chunk, and numbers are parsed with `fast-float2` straight
//! from the bytes (no allocation per line or field). Parsed values are handed out column by
//! column in blocks of at most `block_rows` rows, so memory stays constant whatever the length.
//!
//! Layout: optional UTF-8 BOM; `#` comment lines and blank lines anywhere; one header row whose
//! names carry unit suffixes (`time_s`, `temp_c`, `output_v`, `gyro_x_mv`, `rate_dps`,
//! `rate_rad_s`, `counts_lsb`); then one row of numbers per sample. The delimiter is sniffed
//! from the header ([`Delimiter::sniff`]: tab, semicolons between decimal-comma numbers, comma,
//! semicolon, else runs of whitespace). Where the delimiter is not the comma, numbers written
//! with a decimal comma (`0,25`) are read as with a point, by every path (issue 55).
//! Bad input is never repaired: every problem is a [`DataError`] with line and column, except
//! NaN and empty cells in tolerant mode, which are passed on as NaN and listed in
//! [`ReaderQuality`].

use crate::error::DataError;
use gyrolab::dropout::{DropoutKind, DropoutMarker, DropoutVerdict};
use gyrolab::sampling::CompactStamps;
use gyrolab::static_test::SampleBlock;
use gyrolab::units::{is_celsius, parse_column_name, OutputUnit, Quantity, RateUnit, TimeUnit};
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Default chunk size read from the file at once.
pub const DEFAULT_CHUNK_BYTES: usize = 2 << 20;
/// Default number of rows per block handed to the caller.
pub const DEFAULT_BLOCK_ROWS: usize = 1 << 16;
/// Longest line accepted (a guard against binary files read as text): see [`crate::text::MAX_LINE_BYTES`].
pub use crate::text::MAX_LINE_BYTES;
/// How many missing cells the reader lists individually (all are counted).
pub const FIRST_MISSING: usize = 100;

mod ranges;
pub use ranges::{read_series_in_ranges, RANGE_CHUNK_BYTES};
mod batches;
pub use batches::{BatchReader, SeriesBatch};

pub use crate::decimal::plain_decimal;
use crate::decimal::{read_rows, RowLayout, RowShapes, SKIP_COLUMN};
pub use crate::text::Delimiter;

/// Options of the time-series reader.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesOptions {
    /// Field separator; `None` sniffs it from the header.
    pub delimiter: Option<Delimiter>,
    /// Sample rate in Hz; required when the file has no time column.
    pub sample_rate_hz: Option<f64>,
    /// Units for named columns, overriding (or supplying) the header's unit.
    pub column_units: Vec<(String, OutputUnit)>,
    /// Units for every output column without one, at most one per quantity (an angular-rate or
    /// sensor-output unit for gyro and unnamed columns, an acceleration unit for columns named
    /// as accelerometers, such as `ax` or `acc_x`).
    pub default_units: Vec<OutputUnit>,
    /// Header name of the time column; `None` takes the first column named as a time
    /// (`time`, `t`, `timestamp`, `stamp`, ...).
    pub time_column: Option<String>,
    /// Unit of the time column, overriding (or supplying) the header's unit.
    pub time_unit: Option<TimeUnit>,
    /// Column names of a file without a header row (default `c1`, `c2`, ...).
    pub names: Option<Vec<String>>,
    /// Output channels to read by header name; `None` reads every non-time, non-temperature column.
    pub channels: Option<Vec<String>>,
    /// Header name of a table-rate column (raw rate-table logs, such as `table_rate_dps`): read
    /// separately from the output channels, converted to deg/s; `None` treats no column so.
    pub table_rate_column: Option<String>,
    /// Tolerant mode: NaN and empty cells become NaN and are listed, instead of being errors.
    pub tolerant: bool,
    /// Most data rows accepted (`None`: no limit); more is an error naming the line.
    pub max_rows: Option<u64>,
    /// Rows whose output channels are all exactly zero (dropouts, as the caller decided with
    /// [`gyrolab::dropout`]) are passed on as NaN in every channel and counted.
    pub zero_rows_missing: bool,
    /// Rows whose output channels all equal the row before (repeated-row dropouts, as the
    /// caller decided with [`gyrolab::dropout`]; not the row after an all-zero row when
    /// `zero_rows_missing` is set) are passed on as NaN in every channel and counted. Read
    /// sequentially (the row before crosses blocks).
    pub repeated_rows_missing: bool,
    /// [`read_series_all`] keeps the time stamps as [`CompactStamps`] (lossless, about 1.4
    /// bytes a row instead of 8) in [`SeriesData::time_compact`], `time` left `None`: for
    /// analyses that only search the stamps for the interval and gaps (the Allan analysis).
    pub compact_time: bool,
    /// Bytes read from the file at once.
    pub chunk_bytes: usize,
    /// Rows per block handed to the caller.
    pub block_rows: usize,
    /// Reads rows of plain decimals by the fast path (same values; on by default, off only to
    /// compare the two paths in tests and benchmarks).
    pub fast_rows: bool,
}

impl Default for SeriesOptions {
    fn default() -> Self {
        SeriesOptions {
            delimiter: None,
            sample_rate_hz: None,
            column_units: Vec::new(),
            default_units: Vec::new(),
            time_column: None,
            time_unit: None,
            names: None,
            channels: None,
            table_rate_column: None,
            tolerant: false,
            zero_rows_missing: false,
            repeated_rows_missing: false,
            compact_time: false,
            max_rows: None,
            chunk_bytes: DEFAULT_CHUNK_BYTES,
            block_rows: DEFAULT_BLOCK_ROWS,
            fast_rows: true,
        }
    }
}

/// What a column of the file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ColumnRole {
    /// Time stamps in seconds.
    Time,
    /// Temperature in degC.
    Temperature,
    /// Output channel (index into [`SeriesHeader::channels`]).
    Channel(usize),
    /// Not read (not among the selected channels).
    Ignored,
    /// The table rate of a raw rate-table log (see [`SeriesOptions::table_rate_column`]).
    TableRate,
}

/// A column of the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnInfo {
    /// 1-based position.
    pub index: usize,
    /// Header name as written.
    pub name: String,
    /// What it holds.
    pub role: ColumnRole,
}

/// An output channel of the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelInfo {
    /// Header name as written.
    pub name: String,
    /// 1-based column position.
    pub column: usize,
    /// Output unit ([`OutputUnit::Unitless`] when none is known).
    pub unit: OutputUnit,
    /// Where the unit came from.
    pub unit_source: UnitSource,
}

/// Where a column's unit came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnitSource {
    /// The header (a suffix such as `_dps`, or brackets such as `[rad/s]`).
    Header,
    /// An option naming the column (`--unit COLUMN=UNIT`, a plan key).
    Column,
    /// The default unit for columns without one (`--unit UNIT`).
    Default,
    /// The ROS message convention (REP 103: `angular_velocity` in rad/s,
    /// `linear_acceleration` in m/s^2).
    RosConvention,
    /// The magnitude of the time stamps (epoch seconds, milliseconds, microseconds or
    /// nanoseconds), for a time column without a unit.
    Magnitude,
    /// Assumed: seconds for a time column, degC for a temperature column without a unit.
    Assumed,
    /// No unit: a dimensionless channel.
    None,
}

/// Why a column is not read.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SkipReason {
    /// Not among the selected channels.
    NotSelected,
    /// A second time column (the first one is the time).
    SecondTime,
    /// A second temperature column.
    SecondTemperature,
    /// A counter or index (`seq`, `index`, `frame`, ...).
    Counter,
    /// Text in the first data row.
    Text,
    /// A unit that no channel can be in (the unit as written).
    UnknownUnit(String),
    /// An orientation or covariance field of a ROS message.
    RosField,
    /// Not a numeric column (a Parquet string, boolean or list column).
    NotNumeric,
}

/// A column the reader did not read, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedColumn {
    /// 1-based column.
    pub column: usize,
    /// Header name as written.
    pub name: String,
    /// Why.
    pub reason: SkipReason,
}

impl std::fmt::Display for SkippedColumn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = crate::text::excerpt(&self.name);
        let why = match &self.reason {
            SkipReason::NotSelected => "not selected".to_string(),
            SkipReason::SecondTime => "a second time column".to_string(),
            SkipReason::SecondTemperature => "a second temperature column".to_string(),
            SkipReason::Counter => "a counter or index".to_string(),
            SkipReason::Text => "text in the first data row".to_string(),
            SkipReason::UnknownUnit(u) => {
                format!("unit '{}' is none of {}", crate::text::excerpt(u), OutputUnit::accepted_channel_suffixes())
            }
            SkipReason::RosField => "an orientation or covariance field".to_string(),
            SkipReason::NotNumeric => "not a numeric column".to_string(),
        };
        write!(f, "column {} '{name}' skipped: {why}", self.column)
    }
}

/// The parsed header of a time-series file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeriesHeader {
    /// The file.
    pub file: PathBuf,
    /// 1-based line of the header row.
    pub header_line: u64,
    /// Field separator in use.
    pub delimiter: Delimiter,
    /// Every column.
    pub columns: Vec<ColumnInfo>,
    /// 1-based column of the time stamps.
    pub time_column: Option<usize>,
    /// 1-based column of the temperature.
    pub temperature_column: Option<usize>,
    /// Output channels read, in file order.
    pub channels: Vec<ChannelInfo>,
    /// Sample rate given by the caller, Hz.
    pub sample_rate_hz: Option<f64>,
    /// 1-based column of the table rate, when one was asked for.
    pub table_rate_column: Option<usize>,
    /// Unit of the table-rate column as written (values are handed out in deg/s).
    pub table_rate_unit: Option<RateUnit>,
    /// Unit of the time column as written (values are handed out in seconds).
    pub time_unit: Option<TimeUnit>,
    /// Where the time unit came from.
    pub time_unit_source: Option<UnitSource>,
    /// Whether the file has no header row (columns named `c1..cN` or by the caller).
    pub headerless: bool,
    /// Columns not read (other than the selected channels' neighbours the caller ignored on
    /// purpose), with the reason: shown to the user as notes.
    pub skipped: Vec<SkippedColumn>,
    /// What a row's number counts: text lines, or messages and rows of a binary file.
    #[serde(default)]
    pub rows: RowKind,
    /// Whether the first data row writes its numbers with a decimal comma (`0,25`), as a
    /// European spreadsheet exports a `;`- or tab-separated file. Decimal commas are read in
    /// every file whose delimiter is not the comma, as the text-table reader of `rate` reads them.
    #[serde(default)]
    pub decimal_comma: bool,
}

/// What the number of a row ([`LineMap`], [`DataError::line`]) counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RowKind {
    /// Lines of a text file (1-based, header and comments included).
    #[default]
    Line,
    /// Messages of a topic in a recording (1-based, in time-stamp order).
    Message,
    /// Rows of a table file such as Parquet (1-based).
    Row,
}

impl RowKind {
    /// The word for one row: `line`, `message` or `row`.
    pub fn word(self) -> &'static str {
        match self {
            RowKind::Line => "line",
            RowKind::Message => "message",
            RowKind::Row => "row",
        }
    }
}

/// A NaN or empty cell accepted in tolerant mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissingCell {
    /// 1-based line.
    pub line: u64,
    /// 1-based column.
    pub column: usize,
    /// Column name.
    pub name: String,
    /// The cell's text (empty for an empty cell).
    pub text: String,
}

/// Cells the reader passed on as NaN (tolerant mode only).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ReaderQuality {
    /// Count of NaN or empty cells.
    pub missing_cells: u64,
    /// The first of them (at most [`FIRST_MISSING`]).
    pub first_missing: Vec<MissingCell>,
    /// Rows whose channels were all exactly zero, passed on as NaN
    /// ([`SeriesOptions::zero_rows_missing`]).
    pub zero_rows: u64,
    /// Lines of the first of them (at most [`FIRST_MISSING`]).
    pub first_zero_rows: Vec<u64>,
    /// Rows whose channels all repeated the row before, passed on as NaN
    /// ([`SeriesOptions::repeated_rows_missing`]).
    pub repeated_rows: u64,
    /// Lines of the first of them (at most [`FIRST_MISSING`]).
    pub first_repeated_rows: Vec<u64>,
}

impl ReaderQuality {
    /// Adds the findings of the rows that follow (`other`, whose lines are counted from
    /// `line_offset` lines before), keeping the first [`FIRST_MISSING`] of each list.
    pub fn append(&mut self, other: ReaderQuality, line_offset: u64) {
        fn take_first<T>(into: &mut Vec<T>, from: Vec<T>, shift: impl Fn(T) -> T) {
            let room = FIRST_MISSING.saturating_sub(into.len());
            into.extend(from.into_iter().take(room).map(shift));
        }
        self.missing_cells += other.missing_cells;
        take_first(&mut self.first_missing, other.first_missing, |c| MissingCell { line: c.line + line_offset, ..c });
        self.zero_rows += other.zero_rows;
        take_first(&mut self.first_zero_rows, other.first_zero_rows, |l| l + line_offset);
        self.repeated_rows += other.repeated_rows;
        take_first(&mut self.first_repeated_rows, other.first_repeated_rows, |l| l + line_offset);
    }

    /// Counts a dropout row passed on as NaN (and lists its line among the first ones).
    pub fn count_dropout(&mut self, kind: DropoutKind, line: u64) {
        let (count, first) = match kind {
            DropoutKind::AllZero => (&mut self.zero_rows, &mut self.first_zero_rows),
            DropoutKind::Repeated => (&mut self.repeated_rows, &mut self.first_repeated_rows),
        };
        *count += 1;
        if first.len() < FIRST_MISSING {
            first.push(line);
        }
    }
}

/// The reader's dropout marker for the options' two flags (none when neither is set).
fn dropout_marker(zero_rows: bool, repeated_rows: bool) -> Option<DropoutMarker> {
    let verdict = DropoutVerdict { all_zero: zero_rows, repeated: repeated_rows };
    verdict.any().then(|| DropoutMarker::new(verdict))
}

/// The source line of every row of a record, stored as runs of consecutive lines (a record
/// without comment or blank lines between its rows is one run): the same answers as a vector
/// of line numbers in a few bytes instead of 8 per row.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LineMap {
    /// (first row, its line) of each run of consecutive lines.
    runs: Vec<(usize, u64)>,
    /// Rows.
    len: usize,
}

impl LineMap {
    /// Appends the line of the next row.
    pub fn push(&mut self, line: u64) {
        match self.runs.last() {
            Some(&(row, first)) if first + (self.len - row) as u64 == line => {}
            _ => self.runs.push((self.len, line)),
        }
        self.len += 1;
    }

    /// Appends `rows` rows numbered on from the last one (messages, table rows: numbered 1, 2, 3
    /// ... from the first), in one step.
    pub fn extend_numbered(&mut self, rows: usize) {
        if rows == 0 {
            return;
        }
        let next = self.len as u64 + 1;
        self.push(next);
        self.len += rows - 1;
    }

    /// Appends the lines of the next rows, strictly increasing as a reader gives them (so a
    /// block whose last line is its first plus its length less one is a run of consecutive
    /// lines, the usual case, appended in one step).
    pub fn extend_from_slice(&mut self, lines: &[u64]) {
        debug_assert!(lines.windows(2).all(|w| w[0] < w[1]), "lines must increase");
        match (lines.first(), lines.last()) {
            (Some(&a), Some(&b)) if b.checked_sub(a) == Some(lines.len() as u64 - 1) => {
                self.push(a);
                self.len += lines.len() - 1;
            }
            _ => lines.iter().for_each(|&l| self.push(l)),
        }
    }

    /// Appends the rows of `other`, whose lines are counted from `line_offset` lines before
    /// (a piece of a file read apart).
    pub fn append(&mut self, other: &LineMap, line_offset: u64) {
        for (k, &(row, line)) in other.runs.iter().enumerate() {
            let end = other.runs.get(k + 1).map_or(other.len, |r| r.0);
            self.push(line + line_offset);
            self.len += end - row - 1;
        }
    }

    /// The line of row `row`.
    pub fn get(&self, row: usize) -> Option<u64> {
        if row >= self.len {
            return None;
        }
        let k = self.runs.partition_point(|&(r, _)| r <= row).checked_sub(1)?;
        let (r, line) = self.runs[k];
        Some(line + (row - r) as u64)
    }

    /// Rows.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Every row's line.
    pub fn to_vec(&self) -> Vec<u64> {
        (0..self.len).filter_map(|i| self.get(i)).collect()
    }
}

/// A block of parsed rows, column by column (all slices have the same length).
#[derive(Debug, Clone, Copy)]
pub struct SeriesBlock<'a> {
    /// Source line of the first row.
    pub first_line: u64,
    /// Source line of each row.
    pub lines: &'a [u64],
    /// Time stamps, seconds.
    pub time: Option<&'a [f64]>,
    /// Temperature, degC.
    pub temp: Option<&'a [f64]>,
    /// Table rate, deg/s (raw rate-table logs).
    pub table_rate: Option<&'a [f64]>,
    /// One column per output channel, in the order of [`SeriesHeader::channels`].
    pub channels: &'a [Vec<f64>],
}

impl<'a> SeriesBlock<'a> {
    /// Rows in the block.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// Whether the block has no rows.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// The samples of one channel as a core [`SampleBlock`] (with time, temperature, lines).
    pub fn samples(&self, channel: usize) -> SampleBlock<'a> {
        SampleBlock {
            output: self.channels.get(channel).map_or(&[][..], |c| &c[..]),
            time_s: self.time,
            temperature_c: self.temp,
            lines: Some(self.lines),
        }
    }
}

const SKIP: u32 = SKIP_COLUMN;

/// Writes the decimal commas of a row's numbers as points (`0,25` as `0.25`) when the
/// delimiter is not the comma; whether there was one.
fn with_decimal_points(delim: Delimiter, fields: &mut [String]) -> bool {
    let mut found = false;
    if delim != Delimiter::Comma {
        for f in fields.iter_mut() {
            if crate::text::is_decimal_comma_number(f.trim()) {
                *f = f.replace(',', ".");
                found = true;
            }
        }
    }
    found
}

/// Parses the number at the start of `bytes` written with a decimal comma (`-0,25`, `1,5e-3`):
/// the field (up to a delimiter, blank or line end) is copied with its comma as a point and
/// parsed; the length counts the original bytes. `None` when the field holds no number or is
/// longer than any number is written.
fn parse_decimal_comma(bytes: &[u8], delim: u8, ws: bool) -> Option<(f64, usize)> {
    let mut copy = [0u8; 64];
    let mut len = 0;
    while len < bytes.len() && !is_field_end(bytes[len], delim, ws) && bytes[len] != b' ' {
        if len == copy.len() {
            return None;
        }
        copy[len] = if bytes[len] == b',' { b'.' } else { bytes[len] };
        len += 1;
    }
    fast_float2::parse_partial::<f64, _>(&copy[..len]).ok()
}

/// Whether a header field is a number (then the line is data, not a header).
fn is_number_text(f: &str) -> bool {
    let t = f.trim();
    !t.is_empty() && t.parse::<f64>().is_ok()
}

/// Whether a column's base name says it holds time stamps.
fn is_time_name(base: &str) -> bool {
    matches!(base, "time" | "t" | "timestamp" | "timestamps" | "stamp" | "time_stamp" | "ts" | "times")
        || base.ends_with(".stamp")
        || base.ends_with("_time")
        || base.ends_with("_timestamp")
        || base.ends_with(".timestamp")
}

/// Whether a column's base name says it holds a temperature.
fn is_temperature_name(base: &str) -> bool {
    matches!(base, "temp" | "temperature" | "tmp" | "die_temp" | "imu_temp" | "temp_imu" | "gyro_temp")
        || base.ends_with(".temperature")
}

/// The unit of a temperature column named in kelvin or fahrenheit (`temp_k`, `temperature_f`).
fn other_temperature_unit(base: &str) -> Option<&str> {
    let (b, u) = base.rsplit_once('_')?;
    (is_temperature_name(b) && matches!(u, "k" | "f" | "kelvin" | "fahrenheit")).then_some(u)
}

/// Whether a column's base name says it is a counter or index.
fn is_counter_name(base: &str) -> bool {
    matches!(
        base,
        "seq"
            | "sequence"
            | "counter"
            | "count"
            | "index"
            | "idx"
            | "frame"
            | "sample"
            | "packet"
            | "id"
            | "n"
            | "no"
            | "nr"
            | "row"
            | "line"
            | "cnt"
    ) || [".seq", "_seq", "_index", "_counter", "_count", "_id", "_cnt"].iter().any(|s| base.ends_with(s))
}

/// Orientation and covariance fields of a ROS `sensor_msgs/Imu` export.
fn is_ros_field_to_skip(base: &str) -> bool {
    base.contains("covariance") || base.contains("orientation")
}

/// The unit a ROS `sensor_msgs/Imu` field has by convention (REP 103).
fn ros_convention_unit(base: &str) -> Option<OutputUnit> {
    if base.contains("angular_velocity") {
        Some(OutputUnit::RadPerSec)
    } else if base.contains("linear_acceleration") {
        Some(OutputUnit::MeterPerSec2)
    } else {
        None
    }
}

/// Whether a column's base name says it is an accelerometer channel (`ax`, `acc_x`,
/// `accel_y`, `a_rs_s_z`, `linear_acceleration.x`, ...).
pub fn is_accelerometer_name(base: &str) -> bool {
    let b = base.trim_end_matches(['x', 'y', 'z', '1', '2', '3']).trim_end_matches(['_', '.', '-', ' ']);
    b == "a"
        || b.starts_with("acc")
        || b.contains("_acc")
        || b.contains(".acc")
        || b.contains("linear_acceleration")
        || b == "a_rs_s"
        || b.ends_with("_a")
        || b.ends_with("accelerometer")
}

/// Streaming reader: parse the header with [`SeriesReader::open`], then call
/// [`SeriesReader::next_block`] until it returns `None`. After an error the reader is spent.
pub struct SeriesReader<R: Read> {
    src: R,
    header: SeriesHeader,
    tolerant: bool,
    /// Marks dropout rows (all zero, repeated) as NaN, when the caller asked for it.
    dropouts: Option<DropoutMarker>,
    compact_time: bool,
    max_rows: Option<u64>,
    fast_rows: bool,
    block_rows: usize,
    chunk_bytes: usize,
    buf: Vec<u8>,
    pos: usize,
    filled: usize,
    complete: usize,
    eof: bool,
    line_no: u64,
    /// Bytes of the unfinished line at the end of the buffer (checked against [`MAX_LINE_BYTES`]).
    tail_len: usize,
    rows: u64,
    targets: Vec<u32>,
    shapes: RowShapes,
    /// Whether a row of the current block was read by the general path (whose values may
    /// exceed [`crate::text::MAX_MAGNITUDE`]; the fast path's stay below 10^42).
    general_rows: bool,
    crlf: bool,
    time_slot: Option<usize>,
    temp_slot: Option<usize>,
    rate_slot: Option<usize>,
    cols: Vec<Vec<f64>>,
    lines: Vec<u64>,
    quality: ReaderQuality,
    /// A piece of a file parsed by [`read_series_all`]'s parallel path: no header, and no rows
    /// is not an error.
    piece: bool,
    /// Bytes read from the source so far (the file offset of `buf[filled]`).
    consumed: u64,
}

/// The byte source of [`SeriesReader::open`]: a file, or standard input for the path `-`.
pub type Source = Box<dyn Read + Send>;

impl SeriesReader<Source> {
    /// Opens a file (`-`: standard input) and reads its header.
    pub fn open(path: impl AsRef<Path>, options: &SeriesOptions) -> Result<Self, DataError> {
        let path = path.as_ref();
        if path == Path::new("-") {
            return SeriesReader::from_reader("<stdin>", Box::new(std::io::stdin()) as Source, options);
        }
        let (f, _) = crate::input_file::open_regular(path)?;
        SeriesReader::from_reader(path, Box::new(f) as Source, options)
    }
}

fn is_blank_or_comment(line: &[u8]) -> bool {
    let t = line.trim_ascii();
    t.is_empty() || t[0] == b'#'
}

impl<R: Read> SeriesReader<R> {
    /// Reads the header from any byte source; `name` names it in errors.
    pub fn from_reader(name: impl AsRef<Path>, src: R, options: &SeriesOptions) -> Result<Self, DataError> {
        let file = name.as_ref().to_path_buf();
        let chunk_bytes = options.chunk_bytes.max(16);
        let mut r = SeriesReader {
            src,
            header: SeriesHeader {
                file: file.clone(),
                header_line: 0,
                delimiter: Delimiter::Comma,
                columns: Vec::new(),
                time_column: None,
                temperature_column: None,
                channels: Vec::new(),
                sample_rate_hz: options.sample_rate_hz,
                table_rate_column: None,
                table_rate_unit: None,
                time_unit: None,
                time_unit_source: None,
                headerless: false,
                skipped: Vec::new(),
                rows: RowKind::Line,
                decimal_comma: false,
            },
            tolerant: options.tolerant,
            dropouts: dropout_marker(options.zero_rows_missing, options.repeated_rows_missing),
            compact_time: options.compact_time,
            max_rows: options.max_rows,
            fast_rows: options.fast_rows,
            block_rows: options.block_rows.max(1),
            chunk_bytes,
            buf: vec![0; chunk_bytes],
            pos: 0,
            filled: 0,
            complete: 0,
            eof: false,
            line_no: 0,
            tail_len: 0,
            rows: 0,
            targets: Vec::new(),
            shapes: RowShapes::default(),
            general_rows: false,
            crlf: false,
            time_slot: None,
            temp_slot: None,
            rate_slot: None,
            cols: Vec::new(),
            lines: Vec::new(),
            quality: ReaderQuality::default(),
            piece: false,
            consumed: 0,
        };
        if let Some(f) = options.sample_rate_hz {
            if !(f.is_finite() && f > 0.0) {
                return Err(DataError::new(&file, format!("sample rate {f} Hz: expected a positive number")));
            }
        }
        // Header: the first line that is neither blank nor a comment, unless it holds only
        // numbers: then the file has no header row, or (Kalibr's imu0.csv) its header is the
        // comment line just above the data.
        let mut first = true;
        let mut last_comment: Option<(u64, String)> = None;
        let (header_text, data_start) = loop {
            if r.pos >= r.complete && !r.fill()? {
                return Err(DataError::new(
                    &file,
                    "the file is empty: expected a header row such as 'time_s,output_v', or rows of numbers",
                ));
            }
            let mut start = r.pos;
            let end = memchr::memchr(b'\n', &r.buf[start..r.complete]).map_or(r.complete, |i| start + i);
            r.pos = (end + 1).min(r.complete);
            r.line_no += 1;
            if first {
                if r.buf[start..end].starts_with(b"\xEF\xBB\xBF") {
                    start += 3;
                }
                first = false;
            }
            let line = &r.buf[start..end];
            if is_blank_or_comment(line) {
                let t = line.trim_ascii();
                last_comment =
                    (!t.is_empty()).then(|| (r.line_no, String::from_utf8_lossy(&t[1..]).trim().to_string()));
                continue;
            }
            r.crlf = line.ends_with(b"\r");
            if memchr::memchr(b'\r', line.strip_suffix(b"\r").unwrap_or(line)).is_some() {
                return Err(DataError::new(
                    &file,
                    "lines end with CR only (a classic Mac OS text file): expected LF or CR LF line ends",
                )
                .at_line(r.line_no));
            }
            break (String::from_utf8_lossy(line).trim().to_string(), start);
        };
        let delim = options.delimiter.unwrap_or_else(|| Delimiter::sniff(&header_text));
        let mut fields = delim.split(&header_text);
        let decimal_comma = with_decimal_points(delim, &mut fields);
        if fields.iter().all(|f| is_number_text(f)) {
            r.header.decimal_comma = decimal_comma;
            // No header row: hand the line back to the data parser.
            let data_line = r.line_no;
            r.pos = data_start;
            r.line_no -= 1;
            let commented = last_comment.filter(|(l, t)| {
                *l + 1 == data_line && {
                    let names = delim.split(t);
                    names.len() == fields.len() && names.iter().any(|n| !is_number_text(n))
                }
            });
            if let (Some((line, text)), None) = (commented, &options.names) {
                r.header.header_line = line;
                r.parse_header(&text, options, Some(&fields))?;
                return Ok(r);
            }
            let names: Vec<String> = match &options.names {
                Some(n) if n.len() != fields.len() => {
                    return Err(DataError::new(
                        &file,
                        format!(
                            "{} names given for a file without a header row whose first row has {} fields",
                            n.len(),
                            fields.len()
                        ),
                    )
                    .at_line(data_line));
                }
                Some(n) => n.clone(),
                None => (1..=fields.len()).map(|i| format!("c{i}")).collect(),
            };
            r.header.headerless = true;
            r.header.header_line = 0;
            let joined = names.join(&(delim.byte() as char).to_string());
            let joined = if delim == Delimiter::Whitespace { names.join(" ") } else { joined };
            r.parse_header(&joined, &SeriesOptions { delimiter: Some(delim), ..options.clone() }, Some(&fields))?;
            return Ok(r);
        }
        if options.names.is_some() {
            return Err(DataError::new(
                &file,
                "column names given for a file that has a header row: leave the names out",
            )
            .at_line(r.line_no));
        }
        r.header.header_line = r.line_no;
        let first_row = r.peek_first_row(delim)?;
        r.parse_header(&header_text, options, first_row.as_deref())?;
        Ok(r)
    }

    /// The fields of the first data row after the header, without consuming it (`None` when
    /// it is not in the buffer).
    fn peek_first_row(&mut self, delim: Delimiter) -> Result<Option<Vec<String>>, DataError> {
        if self.pos >= self.complete && !self.fill()? {
            return Ok(None);
        }
        let mut p = self.pos;
        while p < self.complete {
            let end = memchr::memchr(b'\n', &self.buf[p..self.complete]).map_or(self.complete, |i| p + i);
            let line = &self.buf[p..end];
            if !is_blank_or_comment(line) {
                let mut fields = delim.split(String::from_utf8_lossy(line).trim());
                self.header.decimal_comma = with_decimal_points(delim, &mut fields);
                return Ok(Some(fields));
            }
            p = end + 1;
        }
        Ok(None)
    }

    fn parse_header(
        &mut self,
        text: &str,
        options: &SeriesOptions,
        first_row: Option<&[String]>,
    ) -> Result<(), DataError> {
        let file = self.header.file.clone();
        let line = self.header.header_line;
        let delim = options.delimiter.unwrap_or_else(|| Delimiter::sniff(text));
        self.header.delimiter = delim;
        let names: Vec<String> = match delim {
            Delimiter::Whitespace => text.split_ascii_whitespace().map(str::to_string).collect(),
            d => text.split(d.byte() as char).map(|s| s.trim().trim_matches('"').trim().to_string()).collect(),
        };
        let err = |col: usize, name: Option<&str>, msg: String| {
            Err(DataError::new(&file, msg).at_line(line).at_column(col, name))
        };
        for (i, n) in names.iter().enumerate() {
            if n.is_empty() {
                return err(i + 1, None, "empty column name in the header: expected a name such as 'output_v'".into());
            }
            if let Some(j) = names[..i].iter().position(|m| m.eq_ignore_ascii_case(n)) {
                return err(
                    i + 1,
                    Some(n),
                    format!(
                        "duplicate column name: column {} '{}' and column {} '{}'",
                        j + 1,
                        crate::text::excerpt(&names[j]),
                        i + 1,
                        crate::text::excerpt(n)
                    ),
                );
            }
        }
        let parsed: Vec<_> = names.iter().map(|n| parse_column_name(n)).collect();
        let matches = |given: &str, i: usize| {
            given.eq_ignore_ascii_case(&names[i]) || given.eq_ignore_ascii_case(&parsed[i].base)
        };
        let find = |given: &str| {
            (0..names.len())
                .find(|&i| given.eq_ignore_ascii_case(&names[i]))
                .or_else(|| (0..names.len()).find(|&i| matches(given, i)))
        };
        let text_at = |i: usize| first_row.and_then(|r| r.get(i)).is_some_and(|f| !f.is_empty() && !is_number_text(f));
        let in_header = |given: &str| (0..names.len()).any(|i| matches(given, i));
        // A column an option names that the header does not have (`subject` says which).
        let not_in_header = |subject: String| {
            let found = crate::text::excerpt(&names.join(", "));
            DataError::new(&file, format!("{subject} is not in the header: found {found}")).at_line(line)
        };
        // The time column: the one named by the option, else the first whose name is a time.
        let time_index = match &options.time_column {
            Some(t) => match find(t) {
                Some(i) => Some(i),
                None => return Err(not_in_header(format!("time column '{}'", crate::text::excerpt(t)))),
            },
            // A ROS export's message stamp (`field.header.stamp`, the driver's time) before its
            // receive time (`%time`, the host's, jittered by scheduling), then the first time name.
            // A driver that leaves the stamp unset writes 0: then the receive time.
            None => (0..names.len())
                .find(|&i| {
                    let unset = first_row.and_then(|r| r.get(i)).is_some_and(|f| f.trim().parse::<f64>() == Ok(0.0));
                    parsed[i].base == "field.header.stamp" && !text_at(i) && !unset
                })
                .or_else(|| (0..names.len()).find(|&i| is_time_name(&parsed[i].base) && !text_at(i))),
        };
        let selected = |i: usize| options.channels.as_ref().is_none_or(|l| l.iter().any(|c| matches(c, i)));
        let mut columns = Vec::with_capacity(names.len());
        let mut channels: Vec<ChannelInfo> = Vec::new();
        let mut skipped = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let shown = crate::text::excerpt(name);
            let cn = &parsed[i];
            let unit_text = cn.unit.as_deref();
            let unit_override = options.column_units.iter().find(|(c, _)| matches(c, i)).map(|p| p.1);
            let is_rate = options.table_rate_column.as_ref().is_some_and(|c| matches(c, i));
            let explicitly_selected = options.channels.as_ref().is_some_and(|l| l.iter().any(|c| matches(c, i)));
            let mut skip = |reason: SkipReason| {
                skipped.push(SkippedColumn { column: i + 1, name: name.clone(), reason });
                ColumnRole::Ignored
            };
            let role = if is_rate {
                let Some(unit) = unit_text.and_then(RateUnit::parse) else {
                    return err(
                        i + 1,
                        Some(name),
                        format!("table-rate column '{shown}': expected a rate unit (as in 'table_rate_dps' or 'rate [deg/s]')"),
                    );
                };
                self.header.table_rate_column = Some(i + 1);
                self.header.table_rate_unit = Some(unit);
                ColumnRole::TableRate
            } else if Some(i) == time_index {
                let (unit, source) = match (options.time_unit, unit_text) {
                    (Some(u), _) => (u, UnitSource::Column),
                    (None, Some(t)) => match TimeUnit::parse(t) {
                        Some(u) => (u, UnitSource::Header),
                        None => {
                            return err(
                                i + 1,
                                Some(name),
                                format!(
                                    "time column '{shown}': unit '{}' is not a time unit: expected s, ms, us or ns (as in 'time_s' or 'timestamp [ns]')",
                                    crate::text::excerpt(t)
                                ),
                            )
                        }
                    },
                    (None, None) if cn.base.ends_with(".stamp") || cn.base == "time" && name.starts_with('%') => {
                        (TimeUnit::Nanosecond, UnitSource::RosConvention)
                    }
                    (None, None) => match first_row.and_then(|r| r.get(i)).and_then(|f| f.parse::<f64>().ok()) {
                        Some(v) if v.abs() > 1e17 => (TimeUnit::Nanosecond, UnitSource::Magnitude),
                        Some(v) if v.abs() > 1e14 => (TimeUnit::Microsecond, UnitSource::Magnitude),
                        Some(v) if v.abs() > 1e11 => (TimeUnit::Millisecond, UnitSource::Magnitude),
                        _ => (TimeUnit::Second, UnitSource::Assumed),
                    },
                };
                self.header.time_column = Some(i + 1);
                self.header.time_unit = Some(unit);
                self.header.time_unit_source = Some(source);
                ColumnRole::Time
            } else if is_time_name(&cn.base) && unit_override.is_none() && !explicitly_selected {
                skip(SkipReason::SecondTime)
            } else if (is_temperature_name(&cn.base) || other_temperature_unit(&cn.base).is_some())
                && unit_override.is_none()
                && !explicitly_selected
            {
                if let Some(t) = unit_text.or(other_temperature_unit(&cn.base)).filter(|t| !is_celsius(t)) {
                    return err(
                        i + 1,
                        Some(name),
                        format!(
                            "temperature column '{shown}': unit '{}' is not degC: expected degC (as in 'temp_c' or 'temperature [degC]')",
                            crate::text::excerpt(t)
                        ),
                    );
                }
                if self.header.temperature_column.is_some() {
                    skip(SkipReason::SecondTemperature)
                } else {
                    self.header.temperature_column = Some(i + 1);
                    ColumnRole::Temperature
                }
            } else if !selected(i) {
                // Listed (for the dropout note of a one-channel selection) when it could have been a
                // channel; counters, ROS fields and text are simply left.
                if is_counter_name(&cn.base) || is_ros_field_to_skip(&cn.base) || text_at(i) {
                    ColumnRole::Ignored
                } else {
                    skip(SkipReason::NotSelected)
                }
            } else if !explicitly_selected && text_at(i) {
                // Text first: a ROS `frame_id` holds a name, whatever its `_id` suggests.
                skip(SkipReason::Text)
            } else if !explicitly_selected && is_counter_name(&cn.base) {
                skip(SkipReason::Counter)
            } else if !explicitly_selected && is_ros_field_to_skip(&cn.base) {
                skip(SkipReason::RosField)
            } else {
                let from_header = unit_text.map(|t| (t, OutputUnit::parse(t)));
                let resolved = match (unit_override, from_header) {
                    (Some(u), _) => Some((u, UnitSource::Column)),
                    (None, Some((_, Some(u)))) => Some((u, UnitSource::Header)),
                    (None, Some((t, None))) => {
                        if explicitly_selected {
                            return err(
                                i + 1,
                                Some(name),
                                format!(
                                    "unknown unit '{}' in column '{shown}': expected one of {} (as in 'gyro_x_dps' or 'gyro_x [rad/s]'), or a unit given for the column",
                                    crate::text::excerpt(t),
                                    OutputUnit::accepted_channel_suffixes()
                                ),
                            );
                        }
                        let _ = skip(SkipReason::UnknownUnit(t.to_string()));
                        None
                    }
                    (None, None) => Some(ros_convention_unit(&cn.base).map_or_else(
                        || {
                            let accel = is_accelerometer_name(&cn.base);
                            options
                                .default_units
                                .iter()
                                .find(|u| (u.quantity() == Quantity::Acceleration) == accel)
                                .map_or((OutputUnit::Unitless, UnitSource::None), |&u| (u, UnitSource::Default))
                        },
                        |u| (u, UnitSource::RosConvention),
                    )),
                };
                match resolved {
                    Some((unit, unit_source)) => {
                        channels.push(ChannelInfo { name: name.clone(), column: i + 1, unit, unit_source });
                        ColumnRole::Channel(channels.len() - 1)
                    }
                    None => ColumnRole::Ignored,
                }
            };
            columns.push(ColumnInfo { index: i + 1, name: name.clone(), role });
        }
        self.header.skipped = skipped;
        if let Some(rate) = &options.table_rate_column {
            if self.header.table_rate_column.is_none() {
                return Err(not_in_header(format!("table-rate column '{}'", crate::text::excerpt(rate))));
            }
        }
        if let Some(list) = &options.channels {
            if let Some(missing) = list.iter().find(|c| !in_header(c)) {
                return Err(not_in_header(format!("selected channel '{}'", crate::text::excerpt(missing))));
            }
        }
        if let Some((missing, _)) = options.column_units.iter().find(|(c, _)| !in_header(c)) {
            return Err(not_in_header(format!(
                "a unit is given for column '{}', which",
                crate::text::excerpt(missing)
            )));
        }
        if channels.is_empty() {
            let notes: Vec<String> = self.header.skipped.iter().map(|s| s.to_string()).collect();
            let why = if notes.is_empty() {
                String::new()
            } else {
                format!(" ({})", crate::text::excerpt(&notes.join("; ")))
            };
            return Err(DataError::new(
                &file,
                format!(
                    "no output channel in the header: expected a column such as 'output_v' or 'gyro_x [rad/s]'{why}"
                ),
            )
            .at_line(line));
        }
        if self.header.time_column.is_none() && self.header.sample_rate_hz.is_none() {
            let headerless = if self.header.headerless {
                format!(
                    " (the file has no header row: its columns are {}; name the time column, such as c1, or give column names that include a time)",
                    crate::text::excerpt(&names.join(", "))
                )
            } else {
                String::new()
            };
            return Err(DataError::new(
                &file,
                format!(
                    "no time column (such as 'time_s' or 'timestamp [ns]') and no sample rate given: expected one of them{headerless}"
                ),
            )
            .at_line(line));
        }
        let nch = channels.len();
        self.time_slot = self.header.time_column.map(|_| nch);
        self.temp_slot = self.header.temperature_column.map(|_| nch + usize::from(self.time_slot.is_some()));
        let mut nslots = nch + usize::from(self.time_slot.is_some()) + usize::from(self.temp_slot.is_some());
        if self.header.table_rate_column.is_some() {
            self.rate_slot = Some(nslots);
            nslots += 1;
        }
        self.targets = columns
            .iter()
            .map(|c| match c.role {
                ColumnRole::Channel(k) => k as u32,
                ColumnRole::Time => self.time_slot.map_or(SKIP, |s| s as u32),
                ColumnRole::Temperature => self.temp_slot.map_or(SKIP, |s| s as u32),
                ColumnRole::TableRate => self.rate_slot.map_or(SKIP, |s| s as u32),
                ColumnRole::Ignored => SKIP,
            })
            .collect();
        self.cols = (0..nslots).map(|_| Vec::with_capacity(self.block_rows)).collect();
        self.lines = Vec::with_capacity(self.block_rows);
        self.header.columns = columns;
        self.header.channels = channels;
        Ok(())
    }

    /// The parsed header.
    pub fn header(&self) -> &SeriesHeader {
        &self.header
    }

    /// NaN and empty cells passed on so far (tolerant mode).
    pub fn quality(&self) -> &ReaderQuality {
        &self.quality
    }

    /// Data rows read so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Reads more bytes; returns false when nothing is left to parse.
    fn fill(&mut self) -> Result<bool, DataError> {
        // Move the unparsed tail to the front.
        if self.pos > 0 {
            self.buf.copy_within(self.pos..self.filled, 0);
            self.filled -= self.pos;
            self.complete = self.complete.saturating_sub(self.pos);
            self.pos = 0;
        }
        loop {
            if let Some(i) = memchr::memrchr(b'\n', &self.buf[self.complete..self.filled]) {
                // Keep reading to fill the chunk unless the buffer is full or the file ended.
                if self.filled == self.buf.len() || self.eof {
                    self.complete += i + 1;
                    return Ok(true);
                }
            } else if self.eof {
                if self.filled > self.complete {
                    // A last line without a line end.
                    if self.filled == self.buf.len() {
                        self.buf.push(b'\n');
                    } else {
                        self.buf[self.filled] = b'\n';
                    }
                    self.filled += 1;
                    self.complete = self.filled;
                    return Ok(true);
                }
                return Ok(false);
            }
            if self.filled == self.buf.len() {
                // Only reached with a line longer than the chunk; the checks below end it at
                // MAX_LINE_BYTES.
                let n = (self.buf.len() * 2).max(self.chunk_bytes);
                self.buf.resize(n, 0);
            }
            match self.src.read(&mut self.buf[self.filled..]) {
                Ok(0) => self.eof = true,
                Ok(n) => {
                    self.check_new_bytes(self.filled, self.filled + n)?;
                    self.filled += n;
                    self.consumed += n as u64;
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(DataError::io(&self.header.file, &e)),
            }
        }
    }

    /// Checks bytes just read (`buf[from..to]`): no NUL byte, no line longer than
    /// [`MAX_LINE_BYTES`], so that a binary file or an endless one (`/dev/zero`) ends early.
    fn check_new_bytes(&mut self, from: usize, to: usize) -> Result<(), DataError> {
        let line_at =
            |r: &Self, i: usize| r.line_no + memchr::memchr_iter(b'\n', &r.buf[r.pos.min(i)..i]).count() as u64 + 1;
        if let Some(i) = memchr::memchr(0, &self.buf[from..to]) {
            let line = line_at(self, from + i);
            return Err(DataError::new(&self.header.file, "binary data (a NUL byte): expected a text file of numbers")
                .at_line(line));
        }
        let mut start = from;
        for i in memchr::memchr_iter(b'\n', &self.buf[from..to]) {
            let len = self.tail_len + (from + i - start);
            if len > MAX_LINE_BYTES {
                return Err(crate::text::long_line(&self.header.file, line_at(self, from + i)));
            }
            self.tail_len = 0;
            start = from + i + 1;
        }
        self.tail_len += to - start;
        if self.tail_len > MAX_LINE_BYTES {
            return Err(crate::text::long_line(&self.header.file, line_at(self, to)));
        }
        Ok(())
    }

    /// The next block of rows, or `None` at the end of the file.
    pub fn next_block(&mut self) -> Result<Option<SeriesBlock<'_>>, DataError> {
        for c in &mut self.cols {
            c.clear();
        }
        self.lines.clear();
        self.general_rows = false;
        while self.lines.len() < self.block_rows {
            if self.pos >= self.complete && !self.fill()? {
                break;
            }
            self.parse_rows()?;
        }
        if self.lines.is_empty() {
            if self.rows == 0 && !self.piece {
                return Err(no_data_rows(&self.header));
            }
            return Ok(None);
        }
        // Values that would overflow the figures: a corrupt cell, reported where it is (only the
        // general path reads such numbers).
        for (slot, col) in self.cols.iter().enumerate().filter(|_| self.general_rows) {
            if let Some(k) = col.iter().position(|v| v.abs() > crate::text::MAX_MAGNITUDE) {
                let ci = self.targets.iter().position(|&t| t as usize == slot).unwrap_or(0);
                let msg = crate::text::check_magnitude(col[k]).err().unwrap_or_default();
                return Err(self.err_at(self.lines[k], ci, msg));
            }
        }
        if let (Some(s), Some(unit)) = (self.time_slot, self.header.time_unit) {
            if unit != TimeUnit::Second {
                let f = unit.seconds();
                self.cols[s].iter_mut().for_each(|v| *v *= f);
            }
        }
        if let (Some(s), Some(unit)) = (self.rate_slot, self.header.table_rate_unit) {
            if unit != RateUnit::DegPerSec {
                self.cols[s].iter_mut().for_each(|v| *v = unit.to_dps(*v));
            }
        }
        if let Some(limit) = self.max_rows {
            if self.rows > limit {
                let over = self.lines.len().saturating_sub((self.rows - limit) as usize);
                let line = self.lines.get(over).copied().unwrap_or(self.line_no);
                return Err(too_many_rows(&self.header, limit, line));
            }
        }
        let nch = self.header.channels.len();
        if let Some(marker) = self.dropouts.as_mut() {
            let mut rows = Vec::new();
            let refs: Vec<&[f64]> = self.cols[..nch].iter().map(|c| &c[..]).collect();
            marker.mark_block(&refs, |i, kind| rows.push((i, kind)));
            for (i, kind) in rows {
                self.cols[..nch].iter_mut().for_each(|c| c[i] = f64::NAN);
                self.quality.count_dropout(kind, self.lines[i]);
            }
        }
        Ok(Some(SeriesBlock {
            first_line: self.lines[0],
            lines: &self.lines,
            time: self.time_slot.map(|s| &self.cols[s][..]),
            temp: self.temp_slot.map(|s| &self.cols[s][..]),
            table_rate: self.rate_slot.map(|s| &self.cols[s][..]),
            channels: &self.cols[..nch],
        }))
    }

    /// Parses complete lines from `pos` until the block is full or the chunk is used up.
    fn parse_rows(&mut self) -> Result<(), DataError> {
        let bytes = &self.buf[..self.complete];
        let end = self.complete;
        let ws = self.header.delimiter == Delimiter::Whitespace;
        let delim = self.header.delimiter.byte();
        let ncols = self.targets.len();
        // With whitespace, the fast path takes rows with exactly one space between fields (runs of
        // spaces, tabs and leading spaces go to the general path, which reads them the same).
        let fast = self.fast_rows && !self.header.decimal_comma;
        let decimal_comma = delim != b',';
        let mut refused_at = usize::MAX;
        // Rows the fast path refused in a row, and rows to leave to the general path before
        // trying it again (files whose numbers it never takes, such as `%e` exponents, would
        // otherwise pay for a refused attempt on every row).
        let (mut refusals, mut general_only) = (0u32, 0u32);
        let layout = RowLayout { delim, crlf: self.crlf };
        if self.shapes.len() != ncols {
            self.shapes = RowShapes::new(ncols);
        }
        let mut p = self.pos;
        let mut line_no = self.line_no;
        let result = 'rows: loop {
            if p >= end || self.lines.len() >= self.block_rows {
                break 'rows Ok(());
            }
            if general_only > 0 {
                general_only -= 1;
            } else if fast && p != refused_at {
                let room = self.block_rows - self.lines.len();
                let (next, rows) = read_rows(bytes, p, layout, &self.targets, &mut self.shapes, &mut self.cols, room);
                // The row where it stopped short of the room (refused, or the data's end) is the
                // general path's: no second attempt.
                if rows < room {
                    refused_at = next;
                }
                if rows == 0 {
                    refusals += 1;
                    if refusals >= 16 {
                        general_only = 4096;
                        refusals = 0;
                    }
                } else {
                    refusals = 0;
                }
                if rows > 0 {
                    self.lines.extend((1..=rows as u64).map(|k| line_no + k));
                    p = next;
                    line_no += rows as u64;
                    self.rows += rows as u64;
                    continue 'rows;
                }
            }
            line_no += 1;
            let line_start = p;
            let c0 = bytes[p];
            if c0 == b'#' || c0 == b'\n' || c0 == b'\r' || c0 == b' ' || c0 == b'\t' {
                let le = memchr::memchr(b'\n', &bytes[p..end]).map_or(end, |i| p + i);
                if is_blank_or_comment(&bytes[p..le]) {
                    p = le + 1;
                    continue 'rows;
                }
            }
            for (ci, &slot) in self.targets.iter().enumerate() {
                while bytes[p] == b' ' || (bytes[p] == b'\t' && delim != b'\t') {
                    p += 1;
                }
                let field_start = p;
                if slot == SKIP {
                    while !is_field_end(bytes[p], delim, ws) {
                        p += 1;
                    }
                } else {
                    let mut parsed = match plain_decimal(&bytes[p..end]) {
                        Some(hit) => Ok(hit),
                        None => fast_float2::parse_partial::<f64, _>(&bytes[p..end]),
                    };
                    if decimal_comma {
                        // `0,25` stops the parse at its comma: read it again as `0.25`.
                        if let Ok((_, n)) = parsed {
                            if bytes[p + n] == b',' && bytes.get(p + n + 1).is_some_and(u8::is_ascii_digit) {
                                if let Some(hit) = parse_decimal_comma(&bytes[p..end], delim, ws) {
                                    parsed = Ok(hit);
                                }
                            }
                        }
                    }
                    let value = match parsed {
                        Ok((v, n)) => {
                            p += n;
                            v
                        }
                        Err(_) if ws && is_field_end(bytes[p], delim, ws) => {
                            break 'rows Err(self.wrong_count(bytes, line_start, line_no, delim, ws));
                        }
                        Err(_) if is_field_end(bytes[p], delim, ws) => f64::NAN,
                        Err(_) => {
                            break 'rows Err(self.bad_number(bytes, field_start, line_no, ci, delim, ws));
                        }
                    };
                    if !value.is_finite() && !is_field_end_after_spaces(bytes, p, delim, ws) {
                        break 'rows Err(self.bad_number(bytes, field_start, line_no, ci, delim, ws));
                    }
                    if value.is_finite() {
                        self.cols[slot as usize].push(value);
                    } else {
                        let text = field_text(bytes, field_start, delim, ws);
                        if !self.tolerant || value == f64::INFINITY || value == f64::NEG_INFINITY {
                            let what = if text.is_empty() {
                                "an empty cell".to_string()
                            } else {
                                format!("'{}'", crate::text::excerpt(&text))
                            };
                            let hint = if value.is_nan() { " (tolerant mode reports NaN and empty cells)" } else { "" };
                            break 'rows Err(self.err_at(
                                line_no,
                                ci,
                                format!("found {what}, expected a finite number{hint}"),
                            ));
                        }
                        self.quality.missing_cells += 1;
                        if self.quality.first_missing.len() < FIRST_MISSING {
                            self.quality.first_missing.push(MissingCell {
                                line: line_no,
                                column: ci + 1,
                                name: self.header.columns[ci].name.clone(),
                                text: text.to_string(),
                            });
                        }
                        self.cols[slot as usize].push(f64::NAN);
                    }
                }
                // After the field: spaces, then a delimiter or the line end.
                let before = p;
                while bytes[p] == b' ' || (bytes[p] == b'\t' && delim != b'\t') {
                    p += 1;
                }
                let b = bytes[p];
                let at_eol = b == b'\n' || (b == b'\r' && bytes.get(p + 1) == Some(&b'\n'));
                if ci + 1 < ncols {
                    if at_eol {
                        break 'rows Err(self.wrong_count(bytes, line_start, line_no, delim, ws));
                    }
                    if ws {
                        if p == before {
                            break 'rows Err(self.bad_number(bytes, field_start, line_no, ci, delim, ws));
                        }
                    } else if b == delim {
                        p += 1;
                    } else {
                        break 'rows Err(self.bad_number(bytes, field_start, line_no, ci, delim, ws));
                    }
                } else if at_eol {
                    p += if b == b'\r' { 2 } else { 1 };
                } else if b == delim || (ws && p > before) {
                    break 'rows Err(self.wrong_count(bytes, line_start, line_no, delim, ws));
                } else {
                    break 'rows Err(self.bad_number(bytes, field_start, line_no, ci, delim, ws));
                }
            }
            self.lines.push(line_no);
            self.rows += 1;
            self.general_rows = true;
        };
        self.pos = p;
        self.line_no = line_no;
        result
    }

    fn err_at(&self, line: u64, ci: usize, msg: String) -> DataError {
        let name = self.header.columns.get(ci).map(|c| c.name.as_str());
        DataError::new(&self.header.file, msg).at_line(line).at_column(ci + 1, name)
    }

    fn bad_number(&self, bytes: &[u8], field_start: usize, line: u64, ci: usize, delim: u8, ws: bool) -> DataError {
        let text = crate::text::excerpt(&field_text(bytes, field_start, delim, ws));
        self.err_at(line, ci, format!("found '{text}', expected a number"))
    }

    fn wrong_count(&self, bytes: &[u8], line_start: usize, line: u64, delim: u8, ws: bool) -> DataError {
        let le = memchr::memchr(b'\n', &bytes[line_start..]).map_or(bytes.len(), |i| line_start + i);
        let text = bytes[line_start..le].trim_ascii();
        let found = if ws {
            text.split(|b| b.is_ascii_whitespace()).filter(|f| !f.is_empty()).count()
        } else {
            text.split(|&b| b == delim).count()
        };
        let expected = self.targets.len();
        let col = found.min(expected) + 1;
        let name = self.header.columns.get(found).map(|c| c.name.as_str());
        DataError::new(&self.header.file, format!("found {found} fields, expected {expected} (one per header column)"))
            .at_line(line)
            .at_column(col, name)
    }
}

#[inline(always)]
fn is_field_end(b: u8, delim: u8, ws: bool) -> bool {
    b == b'\n' || b == b'\r' || b == delim || (ws && (b == b' ' || b == b'\t'))
}

fn is_field_end_after_spaces(bytes: &[u8], mut p: usize, delim: u8, ws: bool) -> bool {
    while bytes[p] == b' ' || (bytes[p] == b'\t' && delim != b'\t') {
        p += 1;
    }
    is_field_end(bytes[p], delim, ws)
}

fn field_text(bytes: &[u8], start: usize, delim: u8, ws: bool) -> String {
    let mut e = start;
    while e < bytes.len() && !is_field_end(bytes[e], delim, ws) {
        e += 1;
    }
    String::from_utf8_lossy(bytes[start..e].trim_ascii()).into_owned()
}

/// Row count and findings of a streamed read.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesSummary {
    /// The header.
    pub header: SeriesHeader,
    /// Data rows read.
    pub rows: u64,
    /// NaN and empty cells passed on (tolerant mode).
    pub quality: ReaderQuality,
}

/// Streams a file block by block into `on_block`; stops at the first error (the reader's or the callback's).
pub fn read_series(
    path: impl AsRef<Path>,
    options: &SeriesOptions,
    mut on_block: impl FnMut(&SeriesHeader, &SeriesBlock) -> Result<(), DataError>,
) -> Result<SeriesSummary, DataError> {
    let mut r = SeriesReader::open(path, options)?;
    let header = r.header.clone();
    while let Some(b) = r.next_block()? {
        on_block(&header, &b)?;
    }
    Ok(SeriesSummary { header, rows: r.rows, quality: r.quality.clone() })
}

/// A whole time series in memory, column by column.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesData {
    /// The header.
    pub header: SeriesHeader,
    /// Source line of each row.
    pub lines: LineMap,
    /// Time stamps, seconds.
    pub time: Option<Vec<f64>>,
    /// Time stamps, seconds, stored compactly ([`SeriesOptions::compact_time`]; then `time` is
    /// `None`).
    pub time_compact: Option<CompactStamps>,
    /// Temperature, degC.
    pub temperature: Option<Vec<f64>>,
    /// Table rate, deg/s (when a table-rate column was asked for).
    pub table_rate: Option<Vec<f64>>,
    /// One column per output channel, in the order of `header.channels`.
    pub channels: Vec<Vec<f64>>,
    /// NaN and empty cells passed on (tolerant mode).
    pub quality: ReaderQuality,
}

/// Most rows [`read_series_all`] reserves room for before reading them.
const MAX_RESERVE_ROWS: usize = 1 << 30;

/// Bytes read at once by the parallel path of [`read_series_all`].
pub const PARALLEL_BATCH_BYTES: usize = 4 << 20;

/// Reads a whole file (`-`: standard input) into memory, for analyses that need the whole
/// record (such as the Allan variance). Large inputs are parsed in parallel by the same row
/// parser as [`SeriesReader::next_block`] (same values, same errors with their lines; the first
/// error in file order is returned): a regular file in one byte range per thread, each read and
/// parsed on its own ([`read_series_in_ranges`]); a stream (standard input, a pipe) in batches
/// of [`PARALLEL_BATCH_BYTES`] read in turn and split at line ends into one piece per thread.
pub fn read_series_all(path: impl AsRef<Path>, options: &SeriesOptions) -> Result<SeriesData, DataError> {
    let path = path.as_ref();
    if path == Path::new("-") {
        let r = SeriesReader::open(path, options)?;
        if rayon::current_num_threads() < 2 {
            return collect_series(r);
        }
        return collect_series_parallel(r, rayon::current_num_threads(), u64::MAX, PARALLEL_BATCH_BYTES);
    }
    let (file, size) = crate::input_file::open_regular(path)?;
    read_series_opened(path, file, size, options)
}

/// [`read_series_all`] of a regular file already opened (once, by
/// [`crate::input_file::open_regular`] or [`crate::recording::open_sniffed`]) and rewound, of
/// `size` bytes.
pub fn read_series_opened(
    path: &Path,
    file: File,
    size: u64,
    options: &SeriesOptions,
) -> Result<SeriesData, DataError> {
    let threads = rayon::current_num_threads();
    if threads < 2 || size < (4 << 20) {
        return collect_series(SeriesReader::from_reader(path, Box::new(file) as Source, options)?);
    }
    let shared = file.try_clone().map_err(|e| DataError::io(path, &e))?;
    let r = SeriesReader::from_reader(path, Box::new(file) as Source, options)?;
    ranges::collect_series_ranges(r, &shared, size, threads, RANGE_CHUNK_BYTES)
}

/// Reads every row of an open reader into memory like [`collect_series`], parsing batches of
/// `batch_bytes` in `threads` pieces at once (the parallel path of [`read_series_all`], exposed
/// to test it against [`collect_series`] on any input).
pub fn collect_series_in_parallel<R: Read>(
    r: SeriesReader<R>,
    threads: usize,
    batch_bytes: usize,
) -> Result<SeriesData, DataError> {
    collect_series_parallel(r, threads.max(1), 0, batch_bytes.max(16))
}

impl<R: Read> SeriesReader<R> {
    /// A parser of one piece of the data rows (`buf` holds the piece and ends with a line end;
    /// `line_no` is the number of lines before it), sharing this reader's header and column
    /// layout; `cols` and `lines` are reused buffers, large enough for every row of the piece.
    fn piece_parser(
        &self,
        buf: Vec<u8>,
        line_no: u64,
        rows: usize,
        cols: Vec<Vec<f64>>,
        lines: Vec<u64>,
    ) -> SeriesReader<std::io::Empty> {
        let len = buf.len();
        SeriesReader {
            src: std::io::empty(),
            header: self.header.clone(),
            tolerant: self.tolerant,
            dropouts: self.dropouts.as_ref().map(|m| DropoutMarker::new(m.verdict())),
            compact_time: false,
            max_rows: None,
            fast_rows: self.fast_rows,
            block_rows: rows.max(1),
            chunk_bytes: len.max(16),
            buf,
            pos: 0,
            filled: len,
            complete: len,
            eof: true,
            line_no,
            tail_len: 0,
            rows: 0,
            targets: self.targets.clone(),
            shapes: RowShapes::default(),
            general_rows: false,
            crlf: self.crlf,
            time_slot: self.time_slot,
            temp_slot: self.temp_slot,
            rate_slot: self.rate_slot,
            cols,
            lines,
            quality: ReaderQuality::default(),
            piece: true,
            consumed: 0,
        }
    }
}

/// A piece parsed by a piece parser: its rows (channels, then time, temperature, table rate)
/// and its buffers for reuse.
struct Piece {
    buf: Vec<u8>,
    lines: Vec<u64>,
    cols: Vec<Vec<f64>>,
    quality: ReaderQuality,
}

/// Parses a whole piece in one block (its block size is at least its line count).
fn parse_piece(mut p: SeriesReader<std::io::Empty>) -> Result<Piece, DataError> {
    p.next_block()?;
    Ok(Piece {
        buf: std::mem::take(&mut p.buf),
        lines: std::mem::take(&mut p.lines),
        cols: std::mem::take(&mut p.cols),
        quality: std::mem::take(&mut p.quality),
    })
}

fn collect_series_parallel<R: Read>(
    mut r: SeriesReader<R>,
    threads: usize,
    size: u64,
    batch_bytes: usize,
) -> Result<SeriesData, DataError> {
    use rayon::prelude::*;
    if r.dropouts.as_ref().is_some_and(|m| m.verdict().repeated) {
        // Repeated rows compare each row with the one before, across pieces: read in order.
        return collect_series(r);
    }
    let header = r.header.clone();
    let nch = header.channels.len();
    let nslots = r.cols.len();
    // Slots in the parser's order: channels, then time, temperature, table rate.
    let mut slots: Vec<Vec<f64>> = vec![Vec::new(); nslots];
    // The time stamps kept compactly instead of in their slot, when asked for.
    let compact_slot = if r.compact_time { r.time_slot } else { None };
    let mut compact = compact_slot.map(|_| CompactStamps::default());
    let mut lines = LineMap::default();
    let mut quality = ReaderQuality::default();
    if r.buf.len() < batch_bytes {
        r.buf.resize(batch_bytes, 0);
    }
    let mut pool: Vec<Piece> = (0..threads)
        .map(|_| Piece {
            buf: Vec::new(),
            lines: Vec::new(),
            cols: vec![Vec::new(); nslots],
            quality: ReaderQuality::default(),
        })
        .collect();
    let mut reserved = false;
    loop {
        if r.pos >= r.complete && !r.fill()? {
            break;
        }
        let batch = &r.buf[r.pos..r.complete];
        // Split at line ends into one piece per thread; count the lines of each piece.
        let bounds = line_bounds(batch, threads);
        let mut line_no = r.line_no;
        let mut parsers = Vec::with_capacity(threads);
        for (k, w) in bounds.windows(2).enumerate() {
            let piece = &batch[w[0]..w[1]];
            let count = memchr::memchr_iter(b'\n', piece).count();
            let mut slot = std::mem::replace(
                &mut pool[k],
                Piece { buf: Vec::new(), lines: Vec::new(), cols: Vec::new(), quality: ReaderQuality::default() },
            );
            slot.buf.clear();
            slot.buf.extend_from_slice(piece);
            slot.lines.clear();
            slot.lines.reserve(count);
            for c in &mut slot.cols {
                c.clear();
                c.reserve(count);
            }
            parsers.push(r.piece_parser(slot.buf, line_no, count, slot.cols, slot.lines));
            line_no += count as u64;
        }
        if !reserved {
            // Reserve for the whole file from the first batch's bytes per line (no regrowth).
            let per_line = (batch.len() as f64 / (line_no - r.line_no).max(1) as f64).max(1.0);
            let estimate = (((size as f64 / per_line) * 1.02) as usize + 16).min(MAX_RESERVE_ROWS);
            for (k, s) in slots.iter_mut().enumerate() {
                if Some(k) != compact_slot {
                    s.reserve_exact(estimate);
                }
            }
            reserved = true;
        }
        let pieces: Vec<Result<Piece, DataError>> = parsers.into_par_iter().map(parse_piece).collect();
        for (k, p) in pieces.into_iter().enumerate() {
            let mut p = p?;
            lines.extend_from_slice(&p.lines);
            for (k, (s, c)) in slots.iter_mut().zip(&p.cols).enumerate() {
                match compact.as_mut() {
                    Some(stamps) if Some(k) == compact_slot => stamps.extend_from_slice(c),
                    _ => s.extend_from_slice(c),
                }
            }
            quality.append(std::mem::take(&mut p.quality), 0);
            pool[k] = p;
        }
        r.line_no = line_no;
        r.pos = r.complete;
        check_row_limit(&header, &lines, r.max_rows)?;
    }
    if lines.is_empty() {
        return Err(no_data_rows(&header));
    }
    let mut it = slots.into_iter();
    let channels: Vec<Vec<f64>> = it.by_ref().take(nch).collect();
    let time = header.time_column.map(|_| it.next().unwrap_or_default()).filter(|_| compact.is_none());
    let temperature = header.temperature_column.map(|_| it.next().unwrap_or_default());
    let table_rate = header.table_rate_column.map(|_| it.next().unwrap_or_default());
    let mut channels = channels;
    channels.iter_mut().for_each(|c| c.shrink_to_fit());
    Ok(SeriesData { header, lines, time, time_compact: compact, temperature, table_rate, channels, quality })
}

/// The error of a file with a header and no data rows.
fn no_data_rows(header: &SeriesHeader) -> DataError {
    DataError::new(&header.file, "the file has a header but no data rows: expected at least one row of numbers")
        .at_line(header.header_line)
}

/// The error of a record with more than `limit` data rows (`line`: the first row over it).
fn too_many_rows(header: &SeriesHeader, limit: u64, line: u64) -> DataError {
    DataError::new(
        &header.file,
        format!("more than {limit} data rows: this record is larger than the reader accepts here (cut it into parts)"),
    )
    .at_line(line)
}

/// A whole record's rows against the reader's limit (`max_rows`).
fn check_row_limit(header: &SeriesHeader, lines: &LineMap, max_rows: Option<u64>) -> Result<(), DataError> {
    match max_rows {
        Some(limit) if lines.len() as u64 > limit => {
            Err(too_many_rows(header, limit, lines.get(limit as usize).unwrap_or(0)))
        }
        _ => Ok(()),
    }
}

/// Reads every block of an open reader into memory.
pub fn collect_series<R: Read>(mut r: SeriesReader<R>) -> Result<SeriesData, DataError> {
    let header = r.header.clone();
    let mut lines = LineMap::default();
    let compact_time = r.compact_time;
    let mut time = header.time_column.filter(|_| !compact_time).map(|_| Vec::new());
    let mut time_compact = header.time_column.filter(|_| compact_time).map(|_| CompactStamps::default());
    let mut temperature = header.temperature_column.map(|_| Vec::new());
    let mut table_rate = header.table_rate_column.map(|_| Vec::new());
    let mut channels = vec![Vec::new(); header.channels.len()];
    while let Some(b) = r.next_block()? {
        lines.extend_from_slice(b.lines);
        if let (Some(t), Some(bt)) = (time.as_mut(), b.time) {
            t.extend_from_slice(bt);
        }
        if let (Some(t), Some(bt)) = (time_compact.as_mut(), b.time) {
            t.extend_from_slice(bt);
        }
        if let (Some(t), Some(bt)) = (temperature.as_mut(), b.temp) {
            t.extend_from_slice(bt);
        }
        if let (Some(t), Some(bt)) = (table_rate.as_mut(), b.table_rate) {
            t.extend_from_slice(bt);
        }
        for (c, bc) in channels.iter_mut().zip(b.channels) {
            c.extend_from_slice(bc);
        }
    }
    let quality = r.quality.clone();
    Ok(SeriesData { header, lines, time, time_compact, temperature, table_rate, channels, quality })
}

/// Named numeric columns already in memory (a Parquet table, the messages of a recording's
/// topic), read by the same header rules as a delimited file: roles, units from the names or
/// `options`, the time column and its unit, skipped columns. Rows are numbered 1..N as
/// `rows`; a NaN in an output channel is a missing cell (tolerant mode) or an error naming its
/// row and column.
pub fn series_from_columns(
    file: &Path,
    names: &[String],
    mut columns: Vec<Vec<f64>>,
    rows: RowKind,
    options: &SeriesOptions,
) -> Result<SeriesData, DataError> {
    let n = columns.first().map_or(0, Vec::len);
    if columns.len() != names.len() || columns.iter().any(|c| c.len() != n) {
        return Err(DataError::new(file, "columns of different lengths: expected a table"));
    }
    if let Some(limit) = options.max_rows {
        if n as u64 > limit {
            return Err(DataError::new(
                file,
                format!("{n} {}s: more than the {limit} this reader accepts", rows.word()),
            ));
        }
    }
    // The header rules are those of the text reader: it reads a header row and one data row
    // (for the magnitude of unitless time stamps) built from the names and the first values.
    let clean: Vec<String> = names.iter().map(|c| c.replace([',', '\n', '\r', '"', '#'], " ")).collect();
    let first: Vec<String> = columns
        .iter()
        .map(|c| c.first().filter(|v| v.is_finite()).map_or("0".to_string(), |v| format!("{v:?}")))
        .collect();
    let text = format!("{}\n{}\n", clean.join(","), first.join(","));
    let opts = SeriesOptions { delimiter: Some(Delimiter::Comma), ..options.clone() };
    let reader = SeriesReader::from_reader(file, std::io::Cursor::new(text.into_bytes()), &opts)?;
    let mut header = reader.header.clone();
    header.rows = rows;
    header.header_line = 0;
    let mut take = |c: usize| std::mem::take(&mut columns[c - 1]);
    let mut time = header.time_column.map(&mut take);
    if let (Some(t), Some(unit)) = (time.as_mut(), header.time_unit) {
        if unit != TimeUnit::Second {
            let f = unit.seconds();
            t.iter_mut().for_each(|v| *v *= f);
        }
    }
    let temperature = header.temperature_column.map(&mut take);
    let mut table_rate = header.table_rate_column.map(&mut take);
    if let (Some(r), Some(unit)) = (table_rate.as_mut(), header.table_rate_unit) {
        r.iter_mut().for_each(|v| *v = unit.to_dps(*v));
    }
    let channels: Vec<Vec<f64>> = header.channels.iter().map(|c| take(c.column)).collect();
    let mut quality = ReaderQuality::default();
    for (info, values) in header.channels.iter().zip(&channels) {
        for (i, v) in values.iter().enumerate().filter(|(_, v)| !v.is_finite()) {
            if !options.tolerant || !v.is_nan() {
                return Err(DataError::new(
                    file,
                    format!("{} {}: value {v}: expected a finite number", rows.word(), i + 1),
                )
                .at_column(info.column, Some(&info.name)));
            }
            quality.missing_cells += 1;
            if quality.first_missing.len() < FIRST_MISSING {
                quality.first_missing.push(MissingCell {
                    line: i as u64 + 1,
                    column: info.column,
                    name: info.name.clone(),
                    text: "NaN".into(),
                });
            }
        }
    }
    let mut lines = LineMap::default();
    if n > 0 {
        lines.runs.push((0, 1));
        lines.len = n;
    }
    Ok(SeriesData { header, lines, time, time_compact: None, temperature, table_rate, channels, quality })
}

#[cfg(test)]
mod line_map_tests {
    use super::LineMap;

    #[test]
    fn runs_answer_as_the_vector_would() {
        // Lines 3..=5, a comment on 6, 7..=8, two blank lines, 11.
        let lines = [3u64, 4, 5, 7, 8, 11];
        let mut m = LineMap::default();
        m.extend_from_slice(&lines);
        assert_eq!(m.runs.len(), 3);
        assert_eq!(m.to_vec(), lines);
        for (i, &l) in lines.iter().enumerate() {
            assert_eq!(m.get(i), Some(l));
        }
        assert_eq!(m.get(6), None);
        assert_eq!(LineMap::default().get(0), None);
    }
}

#[cfg(test)]
mod compact_time_tests {
    use super::*;

    /// A record of `n` rows: jittered stamps with a gap of 7 samples, two channels, every 500th
    /// row repeating the row before.
    fn text(n: usize) -> String {
        let mut s = String::from("time_s,a_dps,b_dps\n");
        for i in 0..n {
            let k = if i >= n / 2 { i + 7 } else { i };
            let jitter = ((i * 7919) % 13) as f64 * 1e-4;
            // Every 500th row repeats the row before (a logger's repeated-row dropout).
            let src = if i % 500 == 499 { i - 1 } else { i };
            let (a, b) = ((src % 17) as f64 * 0.1, (src % 23) as f64 * -0.2);
            s.push_str(&format!("{:.4},{a},{b}\n", k as f64 * 0.01 + jitter));
        }
        s
    }

    fn read(text: &str, options: &SeriesOptions, parallel: bool) -> SeriesData {
        let r = SeriesReader::from_reader("t.csv", text.as_bytes(), options).unwrap();
        if parallel {
            collect_series_in_parallel(r, 3, 4096).unwrap()
        } else {
            collect_series(r).unwrap()
        }
    }

    #[test]
    fn compact_stamps_hold_the_time_column_bit_for_bit() {
        let text = text(20_000);
        let plain = read(&text, &SeriesOptions::default(), false);
        let t = plain.time.clone().unwrap();
        for parallel in [false, true] {
            let opts = SeriesOptions { compact_time: true, ..SeriesOptions::default() };
            let d = read(&text, &opts, parallel);
            assert!(d.time.is_none());
            let back = d.time_compact.as_ref().unwrap().to_vec();
            assert_eq!(
                back.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                t.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
            assert_eq!(d.channels, plain.channels);
        }
    }

    #[test]
    fn repeated_rows_are_marked_across_blocks_and_pieces() {
        let text = text(20_000);
        let opts = SeriesOptions { repeated_rows_missing: true, block_rows: 333, ..SeriesOptions::default() };
        for parallel in [false, true] {
            let d = read(&text, &opts, parallel);
            // Repeats: rows equal to the row before, found here from the values read plainly.
            let plain = read(&text, &SeriesOptions::default(), false);
            let expected: Vec<usize> =
                (1..plain.channels[0].len()).filter(|&i| plain.channels.iter().all(|c| c[i] == c[i - 1])).collect();
            let nan: Vec<usize> = (0..d.channels[0].len()).filter(|&i| d.channels[0][i].is_nan()).collect();
            assert_eq!(expected, (499..20_000).step_by(500).collect::<Vec<_>>());
            assert_eq!(nan, expected);
            assert_eq!(d.quality.repeated_rows, expected.len() as u64);
        }
    }
}

/// The bounds of `threads` pieces of `batch` split at line ends (each piece but the last ends
/// just after a `\n`; pieces may be empty): `threads + 1` offsets from 0 to `batch.len()`.
pub(crate) fn line_bounds(batch: &[u8], threads: usize) -> Vec<usize> {
    let mut bounds = vec![0usize];
    for k in 1..threads {
        let at = (batch.len() * k / threads).max(*bounds.last().unwrap_or(&0));
        let cut = memchr::memchr(b'\n', &batch[at..]).map_or(batch.len(), |i| at + i + 1);
        bounds.push(cut.min(batch.len()));
    }
    bounds.push(batch.len());
    bounds
}
