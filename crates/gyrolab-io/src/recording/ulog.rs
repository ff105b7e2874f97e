//! PX4 ULog files (the `px4-ulog` crate's streaming parser, which keeps the readable part of a
//! truncated log): the gyro and accelerometer topics PX4 logs.
//!
//! | topic | stamp | channels |
//! |---|---|---|
//! | `sensor_combined` | `timestamp` | `gyro_rad[0..3]` rad/s, `accelerometer_m_s2[0..3]` m/s^2 |
//! | `sensor_gyro` | `timestamp_sample` | `x`, `y`, `z` rad/s |
//! | `sensor_accel` | `timestamp_sample` | `x`, `y`, `z` m/s^2 |
//! | `vehicle_imu` | `timestamp_sample` | `delta_angle[i]` / `delta_angle_dt`, `delta_velocity[i]` / `delta_velocity_dt` |
//!
//! Field names, types and units: PX4 uORB message definitions (`msg/SensorCombined.msg`,
//! `SensorGyro.msg`, `SensorAccel.msg`, `VehicleImu.msg`); time stamps are microseconds since
//! boot. A topic with several instances is named `name.N` for instance N > 0.

use super::{Collector, ImuLayout, StampSource, Stop};
use crate::error::DataError;
use px4_ulog::stream_parser::file_reader::LogParser;
use px4_ulog::stream_parser::model::{FlattenedField, FlattenedFieldType, FlattenedFormat};
use std::collections::HashMap;
use std::path::Path;

/// How one value of a message is computed: a field, or a field divided by a duration field
/// (microseconds), as `vehicle_imu`'s increments.
#[derive(Debug, Clone)]
enum Value {
    Field(FlattenedField),
    PerDuration(FlattenedField, FlattenedField),
}

/// How the messages of one subscription are read.
#[derive(Debug, Clone)]
struct Plan {
    stamp: Option<FlattenedField>,
    values: Vec<Value>,
}

/// The names of the topics gyrolab reads as IMU topics.
pub const IMU_TOPICS: [&str; 4] = ["sensor_combined", "sensor_gyro", "sensor_accel", "vehicle_imu"];

fn field(f: &FlattenedFormat, name: &str) -> Option<FlattenedField> {
    f.fields.iter().find(|x| x.flattened_field_name == name).cloned()
}

/// The value of a scalar field as f64 (`None` when the message is too short).
fn value(data: &[u8], f: &FlattenedField) -> Option<f64> {
    let o = f.offset as usize;
    macro_rules! le {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            let b: [u8; N] = data.get(o..o + N)?.try_into().ok()?;
            <$t>::from_le_bytes(b) as f64
        }};
    }
    Some(match f.field_type {
        FlattenedFieldType::Int8 => le!(i8),
        FlattenedFieldType::UInt8 | FlattenedFieldType::Bool | FlattenedFieldType::Char => le!(u8),
        FlattenedFieldType::Int16 => le!(i16),
        FlattenedFieldType::UInt16 => le!(u16),
        FlattenedFieldType::Int32 => le!(i32),
        FlattenedFieldType::UInt32 => le!(u32),
        FlattenedFieldType::Int64 => le!(i64),
        FlattenedFieldType::UInt64 => le!(u64),
        FlattenedFieldType::Float => le!(f32),
        FlattenedFieldType::Double => le!(f64),
    })
}

/// The reading plan of an IMU topic, with its layout; `None` for other topics or when the
/// format lacks the fields.
fn plan_of(f: &FlattenedFormat) -> Option<(ImuLayout, StampSource, Option<FlattenedField>, Vec<Value>)> {
    let name = f.message_name.as_str();
    let xyz = |prefix: &str| -> Option<Vec<Value>> {
        ["x", "y", "z"].iter().map(|a| field(f, &format!("{prefix}{a}")).map(Value::Field)).collect()
    };
    let arr =
        |n: &str| -> Option<Vec<Value>> { (0..3).map(|i| field(f, &format!("{n}[{i}]")).map(Value::Field)).collect() };
    let (stamp, source) = match field(f, "timestamp_sample") {
        Some(s) => (Some(s), StampSource::Sample),
        None => (field(f, "timestamp"), StampSource::Published),
    };
    let gyro = ImuLayout::three(["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]);
    let accel = ImuLayout::three(["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"]);
    match name {
        "sensor_combined" => {
            let mut v = arr("gyro_rad")?;
            v.extend(arr("accelerometer_m_s2")?);
            // sensor_combined's timestamp is the gyro's sampling time.
            Some((ImuLayout::six(), StampSource::Sample, field(f, "timestamp"), v))
        }
        "sensor_gyro" => Some((gyro, source, stamp, xyz("")?)),
        "sensor_accel" => Some((accel, source, stamp, xyz("")?)),
        "vehicle_imu" => {
            let da = field(f, "delta_angle_dt")?;
            let dv = field(f, "delta_velocity_dt")?;
            let mut v = Vec::new();
            for i in 0..3 {
                v.push(Value::PerDuration(field(f, &format!("delta_angle[{i}]"))?, da.clone()));
            }
            for i in 0..3 {
                v.push(Value::PerDuration(field(f, &format!("delta_velocity[{i}]"))?, dv.clone()));
            }
            Some((ImuLayout::six(), source, stamp, v))
        }
        _ => None,
    }
}

/// The parser's error description in words: without the message format it may quote
/// (`data message had wrong size 50, format: FlattenedFormat { .. }`) or any other debug text.
fn parse_error_text(description: &str) -> String {
    let mut d = description;
    if let Some(id) = d.strip_prefix("duplicate registration for msg_id ") {
        let id: String = id.chars().take_while(char::is_ascii_digit).collect();
        return format!("two subscriptions (A messages) register msg_id {id}");
    }
    for cut in ["\n", ", initial one", ", format", "FlattenedFormat", "Some(", " {", "Format {"] {
        if let Some(i) = d.find(cut) {
            d = &d[..i];
        }
    }
    let d = d.trim_end_matches([':', ',', ' ', '"', '(']).trim();
    if d.is_empty() {
        "a message the ULog parser cannot read".to_string()
    } else {
        crate::text::short_message(d)
    }
}

/// A time stamp field (microseconds, an integer type) read exactly, as ns; `Err` when it is
/// beyond the range of nanosecond stamps (about 292 years).
fn stamp_value(data: &[u8], f: &FlattenedField) -> Option<Result<i64, u64>> {
    let o = f.offset as usize;
    let us: u64 = match f.field_type {
        FlattenedFieldType::UInt64 | FlattenedFieldType::Int64 => {
            let b: [u8; 8] = data.get(o..o + 8)?.try_into().ok()?;
            let v = u64::from_le_bytes(b);
            if f.field_type == FlattenedFieldType::Int64 && (v as i64) < 0 {
                return Some(Err(v));
            }
            v
        }
        _ => {
            let v = value(data, f)?;
            if !(0.0..9.2e18).contains(&v) {
                return Some(Err(u64::MAX));
            }
            v as u64
        }
    };
    Some(i64::try_from(us).ok().and_then(|u| u.checked_mul(1000)).ok_or(us))
}

/// Bytes fed to the parser at once.
const FEED: usize = 64 * 1024;

/// The message headers of a ULog file, walked over the bytes before they are fed to the
/// `px4-ulog` parser, which indexes the first bytes of a message without checking its size
/// (an `A` message of 2 bytes panicked, found by fuzzing): each message's size is checked
/// against what its kind holds (docs.px4.io "ULog File Format") and the key length of info
/// and parameter messages against the message.
#[derive(Debug)]
struct Framer {
    /// File offset of the next message's header (after the 16-byte file header).
    next: u64,
    /// The bytes of that header read so far: size (2), type (1), and the first two data bytes.
    head: Vec<u8>,
}

impl Framer {
    fn new() -> Self {
        Framer { next: 16, head: Vec::with_capacity(5) }
    }

    /// Walks `bytes`, which start at file offset `at`: `Err((offset, what))` for the first
    /// message whose size cannot hold its kind's fields.
    fn feed(&mut self, bytes: &[u8], at: u64) -> Result<(), (u64, String)> {
        let end = at + bytes.len() as u64;
        loop {
            let mut need = 3;
            if self.head.len() >= 3 {
                need = 3 + usize::from(u16::from_le_bytes([self.head[0], self.head[1]])).min(2);
            }
            while self.head.len() < need {
                let pos = self.next + self.head.len() as u64;
                if pos >= end {
                    return Ok(());
                }
                if pos >= at {
                    self.head.push(bytes[(pos - at) as usize]);
                }
                if self.head.len() == 3 {
                    need = 3 + usize::from(u16::from_le_bytes([self.head[0], self.head[1]])).min(2);
                }
            }
            let size = usize::from(u16::from_le_bytes([self.head[0], self.head[1]]));
            if let Some(what) = message_fault(self.head[2], size, &self.head[3..]) {
                return Err((self.next, what));
            }
            self.next += 3 + size as u64;
            self.head.clear();
        }
    }
}

/// Why a ULog message of kind `kind`, `size` bytes, whose data starts with `first` (its first
/// two bytes, fewer in a shorter message), cannot be read: `None` when its size holds its kind's
/// fixed fields.
fn message_fault(kind: u8, size: usize, first: &[u8]) -> Option<String> {
    let least = match kind {
        b'B' => 40,
        b'S' => 8,
        b'L' => 9,
        b'C' => 11,
        b'A' => 3,
        b'D' | b'R' | b'O' | b'M' | b'Q' => 2,
        b'I' | b'P' => 1,
        _ => 0,
    };
    let name = |k: u8| if k.is_ascii_graphic() { format!("'{}'", k as char) } else { format!("of type {k}") };
    if size < least {
        return Some(format!("a message {} of {size} bytes, shorter than the {least} bytes of its fields", name(kind)));
    }
    let key = match kind {
        b'I' | b'P' => Some((usize::from(first[0]), 1)),
        b'M' | b'Q' => Some((usize::from(first[1]), 2)),
        _ => None,
    };
    match key {
        Some((k, o)) if o + k > size => {
            Some(format!("a message {} of {size} bytes whose key of {k} bytes runs past its end", name(kind)))
        }
        _ => None,
    }
}

/// Reads every data message of a ULog file (opened once) into `c`.
pub(super) fn read(path: &Path, mut file: std::fs::File, c: &mut Collector) -> Result<(), Stop> {
    use std::io::Read;
    let mut plans: HashMap<(u16, u8), (usize, Option<Plan>)> = HashMap::new();
    let mut failure: Option<DataError> = None;
    // Where the bytes being parsed start: a message found there is located by them.
    let fed_from = std::cell::Cell::new(0u64);
    let fed_to = std::cell::Cell::new(0u64);
    let stopped = std::cell::Cell::new(false);
    let mut callback = |d: &px4_ulog::stream_parser::model::DataMessage| {
        if stopped.get() {
            return;
        }
        let fmt = d.flattened_format;
        let multi = d.multi_id.value();
        let (id, plan) = plans.entry((d.msg_id, multi)).or_insert_with(|| {
            let topic = if multi == 0 { fmt.message_name.clone() } else { format!("{}.{multi}", fmt.message_name) };
            match plan_of(fmt) {
                Some((layout, source, stamp, values)) => {
                    (c.topic(&topic, &fmt.message_name, Some(layout), source), Some(Plan { stamp, values }))
                }
                None => (c.topic(&topic, &fmt.message_name, None, StampSource::Published), None),
            }
        });
        let id = *id;
        let log_us = fmt.timestamp_field.as_ref().and_then(|t| {
            let o = t.offset as usize;
            d.data.get(o..o + 8).map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
        });
        let log_ns = log_us.map_or(0, |u| (u.min(i64::MAX as u64 / 1000) * 1000) as i64);
        let Some(plan) = plan else {
            c.count(id, log_ns);
            return;
        };
        if !c.decodes(id) {
            c.count(id, log_ns);
            return;
        }
        let at = format!("in bytes {} to {}", fed_from.get(), fed_to.get());
        let located = |c: &Collector, what: String| {
            DataError::new(
                path,
                format!(
                    "message {} of topic '{}' ({at}): {what}",
                    c.topics[id].info.messages + 1,
                    crate::text::excerpt(&c.topics[id].info.topic)
                ),
            )
        };
        let mut values = [0.0f64; 6];
        for (slot, v) in values.iter_mut().zip(&plan.values) {
            let x = match v {
                Value::Field(f) => value(d.data, f),
                Value::PerDuration(f, dt) => match (value(d.data, f), value(d.data, dt)) {
                    (Some(x), Some(us)) if us > 0.0 => Some(x / (us * 1e-6)),
                    (Some(_), Some(_)) => Some(f64::NAN),
                    _ => None,
                },
            };
            match x {
                Some(x) => *slot = x,
                None => {
                    failure = Some(located(c, "shorter than its format".into()));
                    stopped.set(true);
                    return;
                }
            }
        }
        let stamp_ns = match plan.stamp.as_ref().and_then(|s| stamp_value(d.data, s)) {
            None => log_ns,
            Some(Ok(ns)) => ns,
            Some(Err(us)) => {
                failure = Some(located(
                    c,
                    format!(
                        "its time stamp {us} us is beyond the range of nanosecond stamps (about 292 years since boot): a damaged stamp"
                    ),
                ));
                stopped.set(true);
                return;
            }
        };
        let width = plan.values.len();
        if let Err(e) = c.push_checked(path, id, stamp_ns, log_ns, &values[..width], &at) {
            failure = Some(e);
            stopped.set(true);
        }
    };
    let mut parser = LogParser::default();
    parser.set_data_message_callback(&mut callback);
    let mut buf = vec![0u8; FEED];
    let mut offset = 0u64;
    let mut parse_error = None;
    let mut framing_error = None;
    let mut framer = Framer::new();
    loop {
        let n = match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(DataError::io(path, &e).into()),
        };
        fed_from.set(offset);
        fed_to.set(offset + n as u64);
        if let Err((at, what)) = framer.feed(&buf[..n], offset) {
            // The messages before it are fed; the damaged one is not.
            let before = (at.saturating_sub(offset) as usize).min(n);
            let fed = crate::contained::contain(|| parser.consume_bytes(&buf[..before]));
            let in_data = parser.in_data();
            drop(fed);
            framing_error = Some((at, what, in_data));
            break;
        }
        match crate::contained::contain(|| parser.consume_bytes(&buf[..n])) {
            Ok(Ok(())) => {}
            Ok(Err(e)) => {
                parse_error = Some((offset, offset + n as u64, parse_error_text(&e.description), parser.in_data()));
                break;
            }
            Err(panic) => {
                let what = format!("a message the ULog parser cannot read ({panic})");
                parse_error = Some((offset, offset + n as u64, what, parser.in_data()));
                break;
            }
        }
        offset += n as u64;
        if stopped.get() {
            break;
        }
    }
    let leftover = parser.has_leftover();
    drop(parser);
    if let Some(e) = failure {
        return Err(Stop::Error(e));
    }
    if let Some((at, what, in_data)) = framing_error {
        let part = if in_data { "a data message" } else { "the header or definitions" };
        return Err(Stop::Damaged { at: format!("{part} at byte {at}"), what });
    }
    match parse_error {
        Some((from, to, what, true)) => {
            Err(Stop::Damaged { at: format!("a data message in bytes {from} to {to}"), what })
        }
        Some((from, to, what, false)) => {
            Err(Stop::Damaged { at: format!("the header or definitions (bytes {from} to {to})"), what })
        }
        None if leftover => Err(Stop::Damaged {
            at: format!("byte {offset}"),
            what: format!("the last message is cut off: the file ends at byte {offset} inside it"),
        }),
        None => Ok(()),
    }
}
