//! Robotics recordings: ROS 2 MCAP files, ROS 1 bags and PX4 ULog files, read in one pass into
//! the IMU topics they hold (each a table of time stamps and gyro/accelerometer channels with
//! their units) and an inventory of every topic.
//!
//! - [`sniff_format`]: what a file is, by its first bytes (not its extension; [`crate::sniff`]);
//! - [`open`]: a regular file opened once, its format sniffed ([`OpenedFile`]), for the readers
//!   below without opening it again;
//! - [`read_recording`]: one pass over a recording: every topic counted, the selected IMU topics
//!   decoded ([`ros_msg`] for ROS messages, [`ulog`] for PX4 topics);
//! - [`read_records`]: any file gyrolab reads, by content, as records (a table, or one per
//!   IMU topic);
//! - [`ImuTopic::into_series`]: a topic as a [`SeriesData`], read by the header rules of a
//!   delimited file, so that every analysis of a CSV log takes it unchanged.
//!
//! Message time is the header stamp (ROS) or the sample time stamp (PX4); messages are put in
//! stamp order after reading (no separate sorting step).

mod bag;
mod mcap_file;
pub mod ros_msg;
pub mod ulog;

use crate::error::DataError;
pub use crate::input_file::{check_regular, open_regular};
use crate::series::{series_from_columns, RowKind, SeriesData, SeriesOptions};
pub use crate::sniff::{format_of, open_sniffed, sniff_format, FileFormat};
use std::path::Path;

/// Largest magnitude of a value read from a recording: 1e100. Beyond it, squares and sums of
/// squares of the Allan variance would leave the range of f64 (about 1.8e308); no sensor
/// reports such a number, so it is damage and an error naming the message.
pub const MAX_ABS_VALUE: f64 = 1e100;

/// Where a topic's time stamps come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StampSource {
    /// The message's header stamp (ROS).
    Header,
    /// The time the recorder logged the message (used when the header stamp is zero).
    LogTime,
    /// PX4's `timestamp_sample` (the time the sensor was sampled).
    Sample,
    /// PX4's `timestamp` (the time the message was published).
    Published,
}

impl StampSource {
    /// How the stamps were taken, for notes.
    pub fn describe(self) -> &'static str {
        match self {
            StampSource::Header => "header stamps",
            StampSource::LogTime => "log times (the header stamps are zero)",
            StampSource::Sample => "timestamp_sample (sensor sampling time)",
            StampSource::Published => "timestamp (publication time; the topic has no timestamp_sample)",
        }
    }
}

/// One topic of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicInfo {
    /// Topic name (`/imu0`; PX4: `sensor_gyro.0` with its instance).
    pub topic: String,
    /// Message type (`sensor_msgs/msg/Imu`, `sensor_combined`).
    pub message_type: String,
    /// Messages in the file.
    pub messages: u64,
    /// Whether gyrolab reads it as an IMU topic.
    pub imu: bool,
    /// First and last time stamps, ns (log time, or the sample stamps of an IMU topic).
    pub span_ns: Option<(i64, i64)>,
    /// Every time stamp, ns, in file order (kept when asked for: [`RecordingOptions::stamps`]).
    pub stamps_ns: Vec<i64>,
}

/// Fewer messages than this make no Allan curve worth a filter's parameters: such an IMU topic
/// is skipped unless named.
pub const MIN_CURVE_MESSAGES: u64 = 100;

/// An IMU topic slower than this (mean rate over its span) is a snapshot or status copy, not a
/// sensor's own sample stream (every MEMS IMU samples at tens of hertz or more): skipped unless
/// named.
pub const MIN_SENSOR_RATE_HZ: f64 = 10.0;

/// An IMU topic left out of an analysis where no topic was named, and why.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct SkippedTopic {
    /// The topic.
    pub topic: String,
    /// Why it is not a sensor's own sample stream.
    pub reason: String,
}

/// Why an IMU topic is not a sensor's own samples at their rate, or `None` when it is: PX4's
/// `vehicle_imu` (delta angles and velocities integrated over each publication interval), a
/// topic of fewer than [`MIN_CURVE_MESSAGES`] messages, or one whose typical rate (`rate_hz`:
/// from the median interval of its stamps, which a stray stamp does not move) is below
/// [`MIN_SENSOR_RATE_HZ`] (PX4's 1 Hz `sensor_gyro` / `sensor_accel` copies of a default log).
pub fn snapshot_reason(message_type: &str, messages: u64, rate_hz: Option<f64>) -> Option<String> {
    let at = rate_hz.map_or(String::new(), |r| format!(" at {r:.3} Hz"));
    if message_type == "vehicle_imu" {
        return Some(format!(
            "PX4's vehicle_imu ({messages} messages{at}): delta angles and velocities integrated over each interval, not the sensor's samples (sensor_combined, or sensor_gyro / sensor_accel logged at rate, hold those)"
        ));
    }
    if let Some(r) = rate_hz.filter(|&r| r < MIN_SENSOR_RATE_HZ) {
        return Some(format!(
            "{messages} messages at {r:.3} Hz: slower than {MIN_SENSOR_RATE_HZ} Hz, a snapshot or status copy, not a sensor's own sample stream"
        ));
    }
    (messages < MIN_CURVE_MESSAGES)
        .then(|| format!("{messages} messages{at}: fewer than {MIN_CURVE_MESSAGES}, too few for an Allan curve"))
}

/// The rate of the median interval between successive stamps (ns, in order), Hz; `None` for
/// fewer than two stamps or a median of zero.
pub fn median_rate_hz(stamps_ns: &[i64]) -> Option<f64> {
    let mut d: Vec<i64> = stamps_ns.windows(2).map(|w| w[1].saturating_sub(w[0])).collect();
    if d.is_empty() {
        return None;
    }
    let mid = d.len() / 2;
    let (_, &mut median, _) = d.select_nth_unstable(mid);
    (median > 0).then(|| 1e9 / median as f64)
}

impl TopicInfo {
    /// [`snapshot_reason`] of this topic, its rate from its stamps when they were kept, else
    /// from its span (a stray stamp can make that look slow: the decoded topics of an analysis
    /// are judged by [`ImuTopic::snapshot_reason`]).
    pub fn snapshot_reason(&self) -> Option<String> {
        let rate = median_rate_hz(&self.stamps_ns).or_else(|| {
            self.span_ns.and_then(|(a, b)| {
                (b > a && self.messages > 1).then(|| (self.messages - 1) as f64 / ((b - a) as f64 * 1e-9))
            })
        });
        snapshot_reason(&self.message_type, self.messages, rate)
    }
}

/// The IMU topics analysed when none is named, from `(topic, why it is no sensor stream)`: the
/// sensors at their own rate; the others are skipped, each with its reason. An error naming
/// every IMU topic and its reason when none is left.
pub fn sensor_topics(
    path: &Path,
    reasons: impl IntoIterator<Item = (String, Option<String>)>,
) -> Result<(Vec<String>, Vec<SkippedTopic>), DataError> {
    let (mut kept, mut skipped) = (Vec::new(), Vec::new());
    for (topic, reason) in reasons {
        match reason {
            Some(reason) => skipped.push(SkippedTopic { topic, reason }),
            None => kept.push(topic),
        }
    }
    if kept.is_empty() && !skipped.is_empty() {
        let list: Vec<String> =
            skipped.iter().map(|s| format!("{} ({})", crate::text::excerpt(&s.topic), s.reason)).collect();
        return Err(DataError::new(
            path,
            format!(
                "no IMU topic is a sensor's own sample stream: {}; name a topic to analyse it anyway",
                list.join("; ")
            ),
        ));
    }
    Ok((kept, skipped))
}

/// A decoded IMU topic.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuTopic {
    /// Topic name.
    pub topic: String,
    /// Message type.
    pub message_type: String,
    /// Where the stamps come from.
    pub stamp_source: StampSource,
    /// Time stamps, ns, increasing (ties kept).
    pub stamps_ns: Vec<i64>,
    /// Channel names with their units in the gyrolab convention (`gyro_x_rad_s`,
    /// `accel_x_m_s2`; `x`, `y`, `z` for a Vector3Stamped, whose unit is not stated).
    pub names: Vec<String>,
    /// One column per channel, in stamp order.
    pub channels: Vec<Vec<f64>>,
    /// Messages that came before an earlier-stamped one in the file (put in order).
    pub out_of_order: u64,
}

impl ImuTopic {
    /// Keeps the messages stamped `[start, end)` seconds after the topic's first message
    /// (either bound open); the number kept. Stamps are in order, so the part is one run.
    pub fn keep_window(&mut self, start: Option<f64>, end: Option<f64>) -> usize {
        let Some(&first) = self.stamps_ns.first() else { return 0 };
        let offset = |t: i64| (i128::from(t) - i128::from(first)) as f64 * 1e-9;
        let inside = |t: i64| start.is_none_or(|a| offset(t) >= a) && end.is_none_or(|b| offset(t) < b);
        let from = self.stamps_ns.iter().position(|&t| inside(t)).unwrap_or(self.stamps_ns.len());
        let to = self.stamps_ns.iter().rposition(|&t| inside(t)).map_or(from, |i| i + 1).max(from);
        self.stamps_ns = self.stamps_ns[from..to].to_vec();
        for c in &mut self.channels {
            *c = c[from.min(c.len())..to.min(c.len())].to_vec();
        }
        to - from
    }

    /// [`snapshot_reason`] of this decoded topic, its rate from the median interval of its
    /// stamps.
    pub fn snapshot_reason(&self) -> Option<String> {
        snapshot_reason(&self.message_type, self.stamps_ns.len() as u64, median_rate_hz(&self.stamps_ns))
    }

    /// The topic as a time series: `time_s` (seconds from the first stamp) and the channels,
    /// read by the header rules of a delimited file (units from the names, `options` for the
    /// rest); rows are messages.
    pub fn into_series(self, file: &Path, options: &SeriesOptions) -> Result<(TopicMeta, SeriesData), DataError> {
        let first = self.stamps_ns.first().copied().unwrap_or(0);
        let meta = TopicMeta {
            topic: self.topic,
            message_type: self.message_type,
            stamp_source: self.stamp_source,
            messages: self.stamps_ns.len() as u64,
            out_of_order: self.out_of_order,
            first_stamp_ns: first,
        };
        // In 128 bits: stamps far apart (a negative header stamp, a log time near 2^63) cannot
        // overflow; in place (same size and alignment: the allocation of the stamps is reused).
        let time: Vec<f64> =
            self.stamps_ns.into_iter().map(|t| (i128::from(t) - i128::from(first)) as f64 * 1e-9).collect();
        let mut names = vec!["time_s".to_string()];
        names.extend(self.names);
        let mut columns = vec![time];
        columns.extend(self.channels);
        let options = SeriesOptions { time_column: None, time_unit: None, names: None, ..options.clone() };
        let data = series_from_columns(file, &names, columns, RowKind::Message, &options)?;
        Ok((meta, data))
    }
}

/// What a record read from a recording's topic was.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicMeta {
    /// Topic name.
    pub topic: String,
    /// Message type.
    pub message_type: String,
    /// Where the stamps come from.
    pub stamp_source: StampSource,
    /// Messages read.
    pub messages: u64,
    /// Messages that came before an earlier-stamped one in the file (put in order).
    pub out_of_order: u64,
    /// The first stamp, ns (`time_s` counts from it).
    pub first_stamp_ns: i64,
}

/// One record of a file: the table of a text or Parquet file, or one topic of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct FileRecord {
    /// The topic, for a recording.
    pub topic: Option<TopicMeta>,
    /// The time series.
    pub data: SeriesData,
}

/// Every record of a file, read whole.
#[derive(Debug, Clone, PartialEq)]
pub struct FileRecords {
    /// The file's format.
    pub format: FileFormat,
    /// Its records (one for a table; one per IMU topic of a recording).
    pub records: Vec<FileRecord>,
    /// Where a recording ends early or is damaged (the messages before it are read).
    pub truncated: Option<String>,
    /// IMU topics left out because none was named and they are no sensor's own sample stream
    /// ([`sensor_topics`]).
    pub skipped: Vec<SkippedTopic>,
}

/// Reads any file gyrolab reads, by its content: delimited text and Parquet as one table,
/// MCAP, ROS 1 bags and ULog as one record per IMU topic (`topics` selects; empty: every IMU
/// topic that is a sensor's own sample stream, [`sensor_topics`]).
pub fn read_records(path: &Path, options: &SeriesOptions, topics: &[String]) -> Result<FileRecords, DataError> {
    if path.as_os_str() == "-" {
        return read_stdin_records(path, options, topics);
    }
    open(path)?.read_records(options, topics)
}

/// A regular file opened once, its format read from its first bytes ([`open`]); its readers
/// ([`OpenedFile::read_records`], [`OpenedFile::read_recording`]) read it from there, so that
/// a file is opened once whatever is done with it.
#[derive(Debug)]
pub struct OpenedFile {
    path: std::path::PathBuf,
    file: std::fs::File,
    format: FileFormat,
    size: u64,
}

/// Opens a regular file once and reads its format ([`open_sniffed`]).
pub fn open(path: &Path) -> Result<OpenedFile, DataError> {
    let (file, format, size) = open_sniffed(path)?;
    Ok(OpenedFile { path: path.to_path_buf(), file, format, size })
}

impl OpenedFile {
    /// The file's format.
    pub fn format(&self) -> FileFormat {
        self.format
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The same open file a second time (its descriptor duplicated, not the path opened again),
    /// for a second read: each read starts at the file's first byte.
    pub fn try_clone(&self) -> Result<OpenedFile, DataError> {
        let file = self.file.try_clone().map_err(|e| DataError::io(&self.path, &e))?;
        Ok(OpenedFile { path: self.path.clone(), file, format: self.format, size: self.size })
    }

    /// [`read_records`] of this file.
    pub fn read_records(self, options: &SeriesOptions, topics: &[String]) -> Result<FileRecords, DataError> {
        let OpenedFile { path, mut file, format, size } = self;
        let path = path.as_path();
        rewind(path, &mut file)?;
        if !format.is_recording() && !topics.is_empty() {
            return Err(DataError::new(
                path,
                format!(
                    "topics were given, but this is a {} file, not a recording (MCAP, ROS 1 bag, PX4 ULog)",
                    format.name()
                ),
            ));
        }
        let table = |data| FileRecords {
            format,
            records: vec![FileRecord { topic: None, data }],
            truncated: None,
            skipped: Vec::new(),
        };
        match format {
            FileFormat::Sqlite => Err(sqlite_refused(path)),
            FileFormat::Text => Ok(table(crate::series::read_series_opened(path, file, size, options)?)),
            FileFormat::Parquet => Ok(table(crate::parquet_table::read_parquet_file(path, file, options)?)),
            _ => {
                let opened = OpenedFile { path: path.to_path_buf(), file, format, size };
                let mut rec =
                    opened.read_recording(&RecordingOptions { topics: topics.to_vec(), ..Default::default() })?;
                let mut skipped = Vec::new();
                if topics.is_empty() {
                    let (kept, left_out) =
                        sensor_topics(path, rec.imu.iter().map(|t| (t.topic.clone(), t.snapshot_reason())))?;
                    rec.imu.retain(|t| kept.contains(&t.topic));
                    skipped = left_out;
                }
                let mut records = Vec::with_capacity(rec.imu.len());
                for t in rec.imu {
                    let topic = t.topic.clone();
                    let (meta, data) = t.into_series(path, options).map_err(|mut e| {
                        e.message = format!("topic '{}': {}", crate::text::excerpt(&topic), e.message);
                        e
                    })?;
                    records.push(FileRecord { topic: Some(meta), data });
                }
                Ok(FileRecords { format, records, truncated: rec.truncated, skipped })
            }
        }
    }

    /// [`read_recording`] of this file.
    pub fn read_recording(self, options: &RecordingOptions) -> Result<Recording, DataError> {
        let format = self.format;
        let path = self.path.clone();
        let mut c = Collector::new(options);
        let truncated = self.pass(&mut c)?;
        c.finish(&path, format, truncated)
    }

    /// Reads the recording's IMU topics (`topics` selects; empty: all) in one pass and hands
    /// their messages to `sink` in blocks of `block` messages, each topic's in stamp order
    /// (messages out of order by up to 2 x `block` messages are put in order; an earlier one is
    /// an error), holding at most 3 x `block` messages a topic: memory bounded whatever the
    /// file's length. The topics are checked as [`OpenedFile::read_recording`] checks them.
    pub fn stream_recording(
        self,
        topics: &[String],
        block: usize,
        sink: &mut TopicSink<'_>,
    ) -> Result<StreamedRecording, DataError> {
        let format = self.format;
        let path = self.path.clone();
        let mut c = Collector::streaming(topics, block, sink);
        let truncated = self.pass(&mut c)?;
        c.finish_stream(&path, format, truncated)
    }

    /// One pass of the file's reader into `c`; the note of a file that ends early or has
    /// damaged chunks.
    fn pass(self, c: &mut Collector<'_>) -> Result<Option<String>, DataError> {
        let OpenedFile { path, mut file, format, size } = self;
        let path = path.as_path();
        rewind(path, &mut file)?;
        if format == FileFormat::Sqlite {
            return Err(sqlite_refused(path));
        }
        let end = match format {
            FileFormat::Mcap => mcap_file::read(path, file, size, c),
            FileFormat::RosBag => bag::read(path, file, size, c),
            FileFormat::ULog => ulog::read(path, file, c),
            _ => {
                return Err(DataError::new(
                    path,
                    format!("a {} file, not a recording: expected MCAP, a ROS 1 bag or a PX4 ULog file", format.name()),
                ))
            }
        };
        let mut notes = Vec::new();
        match end {
            Ok(()) => {}
            Err(Stop::Damaged { at, what }) if c.decoded_messages() > 0 => notes.push(format!(
                "the file ends early or is damaged at {at} ({}); the messages before it are analysed",
                crate::text::short_message(&what)
            )),
            Err(Stop::Damaged { at, what }) => {
                return Err(DataError::new(
                    path,
                    format!(
                        "at {at}: {}: expected a complete {} file",
                        crate::text::short_message(&what),
                        format.name()
                    ),
                ))
            }
            Err(Stop::Error(e)) => return Err(e),
        };
        if let Some((at, why)) = c.damaged_chunks.first() {
            let n = c.damaged_chunks.len();
            notes.insert(
                0,
                format!(
                    "{n} damaged chunk{} skipped (the first at byte {at}: {}); the messages of the other chunks are analysed",
                    if n == 1 { "" } else { "s" },
                    crate::text::short_message(why)
                ),
            );
        }
        Ok((!notes.is_empty()).then(|| notes.join("; ")))
    }
}

/// Moves a file's offset back to its first byte.
fn rewind(path: &Path, file: &mut std::fs::File) -> Result<(), DataError> {
    use std::io::Seek;
    file.rewind().map_err(|e| DataError::io(path, &e))
}

/// Standard input (`-`): delimited text.
fn read_stdin_records(path: &Path, options: &SeriesOptions, topics: &[String]) -> Result<FileRecords, DataError> {
    if !topics.is_empty() {
        return Err(DataError::new(
            path,
            "topics were given, but standard input is read as delimited text, not a recording (MCAP, ROS 1 bag, PX4 ULog)",
        ));
    }
    let data = crate::series::read_series_all(path, options)?;
    Ok(FileRecords {
        format: FileFormat::Text,
        records: vec![FileRecord { topic: None, data }],
        truncated: None,
        skipped: Vec::new(),
    })
}

/// What [`read_recording`] reads.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RecordingOptions {
    /// Topics to decode (default: every IMU topic). A name that is not in the file, or not an
    /// IMU topic, is an error listing the topics that are.
    pub topics: Vec<String>,
    /// Keep every topic's time stamps ([`TopicInfo::stamps_ns`], for inventories).
    pub stamps: bool,
    /// Count topics only: decode nothing.
    pub inventory_only: bool,
}

/// A recording as read.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Its format.
    pub format: FileFormat,
    /// Every topic, in the order they appear.
    pub topics: Vec<TopicInfo>,
    /// The decoded IMU topics, in the order they appear.
    pub imu: Vec<ImuTopic>,
    /// When the file ends early or is damaged after some messages: where and what, the
    /// messages before it being kept.
    pub truncated: Option<String>,
}

/// The error for an SQLite file: a ROS 2 bag in the older storage, which gyrolab does not read.
fn sqlite_refused(path: &Path) -> DataError {
    DataError::new(
        path,
        "an SQLite database (a ROS 2 bag in the older .db3 storage?): not read; convert the bag to MCAP, rosbag2's default storage (`ros2 bag convert`), and give the .mcap file",
    )
}

/// The topics of an MCAP file with their message counts, from its summary section without
/// reading its data; `None` for another format, or an MCAP file without a summary or
/// statistics (a pass with [`RecordingOptions::inventory_only`] counts them then).
pub fn mcap_summary_topics(path: &Path) -> Result<Option<Vec<TopicInfo>>, DataError> {
    let (file, format, size) = open_sniffed(path)?;
    Ok(if format == FileFormat::Mcap { mcap_file::summary_topics(file, size) } else { None })
}

/// Reads a recording (MCAP, ROS 1 bag, ULog) in one pass, the file opened once.
pub fn read_recording(path: &Path, options: &RecordingOptions) -> Result<Recording, DataError> {
    open(path)?.read_recording(options)
}

/// Why a pass over a file stopped early.
pub(crate) enum Stop {
    /// The file is damaged or ends early here.
    Damaged {
        /// Where: `byte 1234`, `chunk 5`.
        at: String,
        /// What was wrong.
        what: String,
    },
    /// Another error (a message that cannot be decoded, a wrong selection).
    Error(DataError),
}

impl From<DataError> for Stop {
    fn from(e: DataError) -> Self {
        Stop::Error(e)
    }
}

/// How the values of one topic's messages are laid out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ImuLayout {
    /// Channel names with units.
    pub names: Vec<String>,
}

impl ImuLayout {
    /// Gyro x/y/z (rad/s) and accel x/y/z (m/s^2).
    pub fn six() -> ImuLayout {
        ImuLayout {
            names: ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s", "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]
                .map(String::from)
                .to_vec(),
        }
    }
    /// Three channels by name.
    pub fn three(names: [&str; 3]) -> ImuLayout {
        ImuLayout { names: names.map(String::from).to_vec() }
    }
}

struct TopicState {
    info: TopicInfo,
    layout: Option<ImuLayout>,
    decode: bool,
    stamps: Vec<i64>,
    channels: Vec<Vec<f64>>,
    out_of_order: u64,
    zero_stamps: u64,
    source: StampSource,
    /// Streaming: messages handed over, the last stamp handed over, and whether the buffered
    /// messages are out of stamp order.
    streamed: u64,
    first_streamed: i64,
    last_streamed: Option<i64>,
    unsorted: bool,
    /// The stamp of the message pushed last (file order).
    last_pushed: Option<i64>,
}

/// A block of one topic's messages handed to a streaming reader's sink, in stamp order
/// ([`OpenedFile::stream_recording`]).
#[derive(Debug, Clone, Copy)]
pub struct TopicBlock<'a> {
    /// Topic name.
    pub topic: &'a str,
    /// Message type.
    pub message_type: &'a str,
    /// Channel names with their units, as [`ImuTopic::names`].
    pub names: &'a [String],
    /// Time stamps, ns, increasing (ties kept) within and across the topic's blocks.
    pub stamps_ns: &'a [i64],
    /// One column per channel.
    pub channels: &'a [Vec<f64>],
}

/// Where a streaming pass hands its blocks.
pub type TopicSink<'s> = dyn FnMut(TopicBlock<'_>) -> Result<(), DataError> + 's;

/// A recording streamed ([`OpenedFile::stream_recording`]): what was found, no samples.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamedRecording {
    /// Its format.
    pub format: FileFormat,
    /// Every topic of the file (stamps not kept).
    pub topics: Vec<TopicInfo>,
    /// The streamed IMU topics, in order of their first block.
    pub streamed: Vec<TopicMeta>,
    /// Where the file ends early or is damaged (the messages before it were streamed).
    pub truncated: Option<String>,
}

/// Gathers topics and messages during a pass over a recording.
pub(crate) struct Collector<'s> {
    want: Vec<String>,
    stamps: bool,
    inventory_only: bool,
    topics: Vec<TopicState>,
    /// Chunks skipped as damaged: (byte offset, why).
    pub damaged_chunks: Vec<(u64, String)>,
    /// Streaming: messages per block and the sink (`None`: messages are kept).
    stream: Option<(usize, &'s mut TopicSink<'s>)>,
    /// Streaming: topic ids in order of their first block.
    stream_order: Vec<usize>,
}

impl<'s> Collector<'s> {
    fn new(options: &RecordingOptions) -> Self {
        Collector {
            want: options.topics.clone(),
            stamps: options.stamps,
            inventory_only: options.inventory_only,
            topics: Vec::new(),
            damaged_chunks: Vec::new(),
            stream: None,
            stream_order: Vec::new(),
        }
    }

    /// A collector that hands each decoded topic's messages to `sink` in blocks of `block`
    /// messages, in stamp order (a block is handed over when 3 x `block` are buffered, so that
    /// messages out of order by up to 2 x `block` are put in order; an earlier one is an
    /// error), keeping at most 3 x `block` messages a topic.
    fn streaming(topics: &[String], block: usize, sink: &'s mut TopicSink<'s>) -> Self {
        let mut c = Collector::new(&RecordingOptions { topics: topics.to_vec(), ..RecordingOptions::default() });
        c.stream = Some((block.max(1), sink));
        c
    }

    /// Streaming: hands the `n` earliest buffered messages of topic `id` to the sink (all of
    /// them when `n` is larger), in stamp order.
    fn flush(&mut self, path: &Path, id: usize, n: usize) -> Result<(), DataError> {
        let Some((block, sink)) = self.stream.as_mut() else { return Ok(()) };
        let window = 2 * *block;
        let t = &mut self.topics[id];
        if t.stamps.is_empty() {
            return Ok(());
        }
        if t.unsorted {
            let stamps = std::mem::take(&mut t.stamps);
            let channels = std::mem::take(&mut t.channels);
            (t.stamps, t.channels) = in_stamp_order(stamps, channels, 1);
            t.unsorted = false;
        }
        if let Some(last) = t.last_streamed.filter(|&l| t.stamps[0] < l) {
            return Err(DataError::new(
                path,
                format!(
                    "topic '{}': a message stamped {} ns comes after messages stamped up to {last} ns were analysed: out of stamp order by more than the {} messages a streamed record is put in order over",
                    crate::text::excerpt(&t.info.topic),
                    t.stamps[0],
                    window
                ),
            ));
        }
        let n = n.min(t.stamps.len());
        if t.streamed == 0 {
            self.stream_order.push(id);
            t.first_streamed = t.stamps[0];
        }
        let columns: Vec<Vec<f64>> = t.channels.iter_mut().map(|c| c.drain(..n).collect()).collect();
        let stamps: Vec<i64> = t.stamps.drain(..n).collect();
        t.streamed += n as u64;
        t.last_streamed = stamps.last().copied();
        let names = t.layout.as_ref().map_or(&[][..], |l| &l.names[..]);
        sink(TopicBlock {
            topic: &t.info.topic,
            message_type: &t.info.message_type,
            names,
            stamps_ns: &stamps,
            channels: &columns,
        })
    }

    /// Registers a topic (or finds it again: ROS 1 bags repeat connections); returns its id.
    pub fn topic(&mut self, name: &str, message_type: &str, layout: Option<ImuLayout>, source: StampSource) -> usize {
        if let Some(i) = self.topics.iter().position(|t| t.info.topic == name && t.info.message_type == message_type) {
            return i;
        }
        let selected = self.want.is_empty() || self.want.iter().any(|w| w == name);
        let decode = layout.is_some() && selected && !self.inventory_only;
        let width = layout.as_ref().map_or(0, |l| l.names.len());
        self.topics.push(TopicState {
            info: TopicInfo {
                topic: name.to_string(),
                message_type: message_type.to_string(),
                messages: 0,
                imu: layout.is_some(),
                span_ns: None,
                stamps_ns: Vec::new(),
            },
            layout,
            decode,
            stamps: Vec::new(),
            channels: vec![Vec::new(); if decode { width } else { 0 }],
            out_of_order: 0,
            zero_stamps: 0,
            source,
            streamed: 0,
            first_streamed: 0,
            last_streamed: None,
            unsorted: false,
            last_pushed: None,
        });
        self.topics.len() - 1
    }

    /// Whether a topic of this name is among those to decode (all, when none were named).
    pub fn selected(&self, name: &str) -> bool {
        !self.inventory_only && (self.want.is_empty() || self.want.iter().any(|w| w == name))
    }

    /// Whether the messages of topic `id` are to be decoded.
    pub fn decodes(&self, id: usize) -> bool {
        self.topics[id].decode
    }

    /// Counts a message that is not decoded (`log_ns`: its log time).
    pub fn count(&mut self, id: usize, log_ns: i64) {
        let keep = self.stamps;
        let t = &mut self.topics[id];
        t.info.messages += 1;
        t.info.span_ns = Some(match t.info.span_ns {
            None => (log_ns, log_ns),
            Some((a, b)) => (a.min(log_ns), b.max(log_ns)),
        });
        if keep {
            t.info.stamps_ns.push(log_ns);
        }
    }

    /// Adds a decoded message: its stamp (ns; zero: use `log_ns`) and values.
    pub fn push(&mut self, id: usize, stamp_ns: i64, log_ns: i64, values: &[f64]) {
        let t = &mut self.topics[id];
        let stamp = if stamp_ns == 0 {
            t.zero_stamps += 1;
            log_ns
        } else {
            stamp_ns
        };
        if t.last_pushed.is_some_and(|last| stamp < last) {
            t.out_of_order += 1;
            t.unsorted = true;
        }
        t.last_pushed = Some(stamp);
        t.stamps.push(stamp);
        for (c, v) in t.channels.iter_mut().zip(values) {
            c.push(*v);
        }
        t.info.messages += 1;
        t.info.span_ns = Some(match t.info.span_ns {
            None => (stamp, stamp),
            Some((a, b)) => (a.min(stamp), b.max(stamp)),
        });
    }

    /// [`Collector::push`] after checking the values: one beyond [`MAX_ABS_VALUE`] (or
    /// infinite) is an error naming the message (its 1-based index in the topic), the channel
    /// and `at` (where in the file); NaN is kept (a missing sample).
    pub fn push_checked(
        &mut self,
        path: &Path,
        id: usize,
        stamp_ns: i64,
        log_ns: i64,
        values: &[f64],
        at: &str,
    ) -> Result<(), DataError> {
        if let Some(k) = values.iter().position(|v| v.abs() > MAX_ABS_VALUE) {
            let t = &self.topics[id];
            let name = t.layout.as_ref().and_then(|l| l.names.get(k)).map_or("a value", String::as_str);
            return Err(DataError::new(
                path,
                format!(
                    "message {} of topic '{}' ({at}): {name} is {:e}, beyond the range gyrolab computes with (magnitude at most {MAX_ABS_VALUE:e}): a damaged value",
                    t.info.messages + 1,
                    crate::text::excerpt(&t.info.topic),
                    values[k]
                ),
            ));
        }
        self.push(id, stamp_ns, log_ns, values);
        if let Some((block, _)) = self.stream {
            if self.topics[id].stamps.len() >= 3 * block {
                self.flush(path, id, block)?;
            }
        }
        Ok(())
    }

    fn decoded_messages(&self) -> u64 {
        self.topics.iter().filter(|t| t.decode).map(|t| t.stamps.len() as u64 + t.streamed).sum()
    }

    fn listing(&self) -> String {
        if self.topics.is_empty() {
            return "no topics".into();
        }
        let shown: Vec<String> = self
            .topics
            .iter()
            .take(20)
            .map(|t| {
                format!(
                    "{} ({}, {} messages)",
                    crate::text::excerpt(&t.info.topic),
                    crate::text::excerpt(&t.info.message_type),
                    t.info.messages
                )
            })
            .collect();
        let more = self.topics.len().saturating_sub(20);
        format!("{}{}", shown.join(", "), if more > 0 { format!(" and {more} more") } else { String::new() })
    }

    /// Streaming: the selection checked as [`Collector::finish`] checks it, every buffered
    /// message handed over, and what was streamed.
    fn finish_stream(
        mut self,
        path: &Path,
        format: FileFormat,
        truncated: Option<String>,
    ) -> Result<StreamedRecording, DataError> {
        self.check_selection(path, format)?;
        for id in 0..self.topics.len() {
            if self.topics[id].decode {
                self.flush(path, id, usize::MAX)?;
            }
        }
        let streamed = self
            .stream_order
            .iter()
            .map(|&id| {
                let t = &self.topics[id];
                TopicMeta {
                    topic: t.info.topic.clone(),
                    message_type: t.info.message_type.clone(),
                    stamp_source: if t.zero_stamps > 0 { StampSource::LogTime } else { t.source },
                    messages: t.streamed,
                    out_of_order: t.out_of_order,
                    first_stamp_ns: t.first_streamed,
                }
            })
            .collect();
        let topics = self.topics.into_iter().map(|t| t.info).collect();
        Ok(StreamedRecording { format, topics, streamed, truncated })
    }

    /// The topics named are in the file and are IMU topics, and some IMU message was decoded.
    fn check_selection(&self, path: &Path, format: FileFormat) -> Result<(), DataError> {
        for w in &self.want {
            match self.topics.iter().find(|t| &t.info.topic == w) {
                None => {
                    return Err(DataError::new(
                        path,
                        format!("topic '{}' is not in the file; it has: {}", crate::text::excerpt(w), self.listing()),
                    ))
                }
                Some(t) if t.layout.is_none() => {
                    return Err(DataError::new(
                        path,
                        format!(
                            "topic '{}' holds {} messages, not IMU data (sensor_msgs/Imu, geometry_msgs/Vector3Stamped, or PX4 sensor_combined, sensor_gyro, sensor_accel, vehicle_imu); the file has: {}",
                            crate::text::excerpt(w),
                            crate::text::excerpt(&t.info.message_type),
                            self.listing()
                        ),
                    ))
                }
                Some(_) => {}
            }
        }
        if !self.inventory_only && !self.topics.iter().any(|t| t.decode && (!t.stamps.is_empty() || t.streamed > 0)) {
            return Err(DataError::new(
                path,
                format!(
                    "no IMU messages (sensor_msgs/Imu, geometry_msgs/Vector3Stamped, or PX4 sensor_combined, sensor_gyro, sensor_accel, vehicle_imu) in this {} file; it has: {}",
                    format.name(),
                    self.listing()
                ),
            ));
        }
        Ok(())
    }

    fn finish(self, path: &Path, format: FileFormat, truncated: Option<String>) -> Result<Recording, DataError> {
        self.check_selection(path, format)?;
        let mut topics = Vec::with_capacity(self.topics.len());
        let mut imu = Vec::new();
        for t in self.topics {
            let mut info = t.info;
            if t.decode && !t.stamps.is_empty() {
                if self.stamps {
                    info.stamps_ns = t.stamps.clone();
                }
                let (stamps_ns, channels) = in_stamp_order(t.stamps, t.channels, t.out_of_order);
                imu.push(ImuTopic {
                    topic: info.topic.clone(),
                    message_type: info.message_type.clone(),
                    stamp_source: if t.zero_stamps > 0 { StampSource::LogTime } else { t.source },
                    stamps_ns,
                    names: t.layout.map(|l| l.names).unwrap_or_default(),
                    channels,
                    out_of_order: t.out_of_order,
                });
            }
            topics.push(info);
        }
        Ok(Recording { format, topics, imu, truncated })
    }
}

/// Sorts the messages by stamp (stable: ties keep file order) when some came out of order.
fn in_stamp_order(stamps: Vec<i64>, channels: Vec<Vec<f64>>, out_of_order: u64) -> (Vec<i64>, Vec<Vec<f64>>) {
    if out_of_order == 0 {
        return (stamps, channels);
    }
    let mut order: Vec<u32> = (0..stamps.len() as u32).collect();
    order.sort_by_key(|&i| stamps[i as usize]);
    let permute = |v: &[f64]| order.iter().map(|&i| v[i as usize]).collect::<Vec<f64>>();
    let channels = channels.iter().map(|c| permute(c)).collect();
    let stamps = order.iter().map(|&i| stamps[i as usize]).collect();
    (stamps, channels)
}

/// Writes a topic as CSV: `timestamp_ns` (integer, as recorded) and the channels with their
/// units in the names, each value in the shortest form that reads back to the same f64.
pub fn write_topic_csv(out: &mut dyn std::io::Write, topic: &ImuTopic) -> std::io::Result<()> {
    use std::io::Write;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, out);
    writeln!(w, "timestamp_ns,{}", topic.names.join(","))?;
    let mut fmt = ryu::Buffer::new();
    let mut line = String::with_capacity(256);
    for (i, t) in topic.stamps_ns.iter().enumerate() {
        line.clear();
        line.push_str(&t.to_string());
        for c in &topic.channels {
            line.push(',');
            let v = c[i];
            line.push_str(if v.is_finite() { fmt.format(v) } else { "NaN" });
        }
        line.push('\n');
        w.write_all(line.as_bytes())?;
    }
    w.flush()
}

/// Writes a topic as a Parquet table: `timestamp_ns` (INT64) and the channels (DOUBLE).
pub fn write_topic_parquet(out: &mut (dyn std::io::Write + Send), topic: &ImuTopic) -> std::io::Result<()> {
    let cols: Vec<&[f64]> = topic.channels.iter().map(|c| &c[..]).collect();
    crate::parquet_table::write_parquet(out, "timestamp_ns", &topic.stamps_ns, &topic.names, &cols)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_by_first_bytes() {
        assert_eq!(format_of(b"\x89MCAP0\r\n"), FileFormat::Mcap);
        assert_eq!(format_of(b"#ROSBAG V2.0\n"), FileFormat::RosBag);
        assert_eq!(format_of(b"ULog\x01\x12\x35\x01"), FileFormat::ULog);
        assert_eq!(format_of(b"PAR1\x15"), FileFormat::Parquet);
        assert_eq!(format_of(b"SQLite format 3\0"), FileFormat::Sqlite);
        assert_eq!(format_of(b"time_s,rate_dps\n"), FileFormat::Text);
        assert_eq!(format_of(b""), FileFormat::Text);
    }

    #[test]
    fn unsorted_messages_are_put_in_stamp_order() {
        let mut c = Collector::new(&RecordingOptions::default());
        let id = c.topic("/imu", "sensor_msgs/msg/Imu", Some(ImuLayout::six()), StampSource::Header);
        for (s, v) in [(10, 1.0), (30, 3.0), (20, 2.0), (40, 4.0)] {
            c.push(id, s, 0, &[v; 6]);
        }
        let r = c.finish(Path::new("x.mcap"), FileFormat::Mcap, None).unwrap();
        assert_eq!(r.imu[0].stamps_ns, [10, 20, 30, 40]);
        assert_eq!(r.imu[0].channels[5], [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(r.imu[0].out_of_order, 1);
    }

    #[test]
    fn an_mcap_summary_counts_what_a_pass_counts() {
        // the bundled ROS 2 MCAP (written by the Python `mcap` package): the summary's counts
        // equal those of a pass over the data, topic by topic; a file without a summary (a
        // ROS 1 bag here) gives none
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/recordings");
        let mcap = root.join("simulated_imu_ros2.mcap");
        let summary = mcap_summary_topics(&mcap).unwrap().expect("the file has a summary with statistics");
        let options = RecordingOptions { inventory_only: true, ..Default::default() };
        let pass = read_recording(&mcap, &options).unwrap().topics;
        assert_eq!(summary.len(), pass.len());
        for (s, p) in summary.iter().zip(&pass) {
            assert_eq!((&s.topic, &s.message_type, s.messages, s.imu), (&p.topic, &p.message_type, p.messages, p.imu));
        }
        assert!(summary.iter().any(|t| t.imu && t.messages == 6000), "{summary:?}");
        assert_eq!(mcap_summary_topics(&root.join("simulated_imu_ros1.bag")).unwrap(), None);
    }

    #[test]
    fn streamed_messages_come_in_blocks_in_stamp_order() {
        // blocks of 3, put in order over 6: a message out of order by two is put in place, one
        // earlier than a message already handed over is an error naming the topic
        let mut got: Vec<(Vec<i64>, Vec<f64>)> = Vec::new();
        let mut sink = |b: TopicBlock<'_>| -> Result<(), DataError> {
            assert_eq!((b.topic, b.names.len(), b.channels.len()), ("/imu", 6, 6));
            got.push((b.stamps_ns.to_vec(), b.channels[5].clone()));
            Ok(())
        };
        let mut c = Collector::streaming(&[], 3, &mut sink);
        let id = c.topic("/imu", "sensor_msgs/msg/Imu", Some(ImuLayout::six()), StampSource::Header);
        let path = Path::new("x.mcap");
        for s in [10, 20, 40, 50, 30, 60, 70, 80, 90, 100] {
            c.push_checked(path, id, s, 0, &[s as f64; 6], "here").unwrap();
        }
        let r = c.finish_stream(path, FileFormat::Mcap, None).unwrap();
        assert_eq!(r.streamed.len(), 1);
        assert_eq!((r.streamed[0].messages, r.streamed[0].out_of_order, r.streamed[0].first_stamp_ns), (10, 1, 10));
        let stamps: Vec<i64> = got.iter().flat_map(|(s, _)| s.clone()).collect();
        assert_eq!(stamps, [10, 20, 30, 40, 50, 60, 70, 80, 90, 100]);
        assert!(got.iter().all(|(s, v)| s.iter().map(|&x| x as f64).eq(v.iter().copied())));
        assert_eq!(got[0].0.len(), 3, "blocks of 3");
        let mut sink = |_: TopicBlock<'_>| -> Result<(), DataError> { Ok(()) };
        let mut c = Collector::streaming(&[], 2, &mut sink);
        let id = c.topic("/imu", "sensor_msgs/msg/Imu", Some(ImuLayout::six()), StampSource::Header);
        let mut result = Ok(());
        for s in [10, 20, 30, 40, 50, 60, 15] {
            result = result.and_then(|_| c.push_checked(path, id, s, 0, &[1.0; 6], "here"));
        }
        let e = result.and_then(|_| c.finish_stream(path, FileFormat::Mcap, None).map(|_| ())).unwrap_err().to_string();
        assert!(e.contains("topic '/imu'") && e.contains("out of stamp order by more than the 4 messages"), "{e}");
    }

    #[test]
    fn selection_errors_list_the_topics() {
        let opts = RecordingOptions { topics: vec!["/imu9".into()], ..Default::default() };
        let mut c = Collector::new(&opts);
        let id = c.topic("/imu0", "sensor_msgs/msg/Imu", Some(ImuLayout::six()), StampSource::Header);
        c.count(id, 5);
        let e = c.finish(Path::new("x.mcap"), FileFormat::Mcap, None).unwrap_err().to_string();
        assert!(
            e.contains("'/imu9' is not in the file") && e.contains("/imu0 (sensor_msgs/msg/Imu, 1 messages)"),
            "{e}"
        );
        let opts = RecordingOptions { topics: vec!["/tf".into()], ..Default::default() };
        let mut c = Collector::new(&opts);
        c.topic("/tf", "tf2_msgs/msg/TFMessage", None, StampSource::Header);
        let e = c.finish(Path::new("x.mcap"), FileFormat::Mcap, None).unwrap_err().to_string();
        assert!(e.contains("not IMU data"), "{e}");
        let mut c = Collector::new(&RecordingOptions::default());
        c.topic("/tf", "tf2_msgs/msg/TFMessage", None, StampSource::Header);
        let e = c.finish(Path::new("x.mcap"), FileFormat::Mcap, None).unwrap_err().to_string();
        assert!(e.contains("no IMU messages") && e.contains("/tf (tf2_msgs/msg/TFMessage"), "{e}");
    }

    #[test]
    fn a_topic_reads_as_a_series_with_units_from_its_names() {
        let t = ImuTopic {
            topic: "/imu".into(),
            message_type: "sensor_msgs/msg/Imu".into(),
            stamp_source: StampSource::Header,
            stamps_ns: vec![1_700_000_000_000_000_000, 1_700_000_000_005_000_000],
            names: ImuLayout::six().names,
            channels: vec![vec![0.5, 0.25]; 6],
            out_of_order: 0,
        };
        let (meta, s) = t.into_series(Path::new("x.mcap"), &SeriesOptions::default()).unwrap();
        assert_eq!((meta.messages, meta.first_stamp_ns), (2, 1_700_000_000_000_000_000));
        assert_eq!(s.time.as_deref(), Some(&[0.0, 0.005][..]));
        assert_eq!(s.header.channels.len(), 6);
        assert_eq!(s.header.channels[0].unit, gyrolab::units::OutputUnit::RadPerSec);
        assert_eq!(s.header.channels[3].unit, gyrolab::units::OutputUnit::MeterPerSec2);
        assert_eq!(s.header.rows, RowKind::Message);
        assert_eq!(s.lines.get(1), Some(2));
    }
}
