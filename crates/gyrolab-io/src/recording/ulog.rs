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
use px4_ulog::stream_parser::file_reader::{read_file_with_simple_callback, Message, SimpleCallbackResult};
use px4_ulog::stream_parser::model::{Completeness, FlattenedField, FlattenedFieldType, FlattenedFormat};
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

/// The description inside the parser's debug text of an error, without the message format it
/// quotes (`UlogParseError { .., description: "data message had wrong size 50, format: ..." }`).
fn parse_error_text(why: &str) -> String {
    let d = why.split_once("description: \"").map_or(why, |(_, d)| d);
    let d = d.split(", format:").next().unwrap_or(d);
    d.trim_end_matches(['"', ' ', '}']).to_string()
}

/// Reads every data message of a ULog file into `c`.
pub(super) fn read(path: &Path, c: &mut Collector) -> Result<(), Stop> {
    let shown = path.to_string_lossy().to_string();
    let mut plans: HashMap<(u16, u8), (usize, Option<Plan>)> = HashMap::new();
    let mut failure: Option<DataError> = None;
    let mut callback = |m: &Message| {
        let Message::Data(d) = m else { return SimpleCallbackResult::KeepReading };
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
            return SimpleCallbackResult::KeepReading;
        };
        if !c.decodes(id) {
            c.count(id, log_ns);
            return SimpleCallbackResult::KeepReading;
        }
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
                    failure = Some(DataError::new(
                        &shown,
                        format!(
                            "message {} of topic '{}': shorter than its format",
                            c.topics[id].info.messages + 1,
                            crate::text::excerpt(&c.topics[id].info.topic)
                        ),
                    ));
                    return SimpleCallbackResult::Stop;
                }
            }
        }
        let stamp_ns =
            plan.stamp.as_ref().and_then(|s| value(d.data, s)).map_or(log_ns, |us| (us as i64).saturating_mul(1000));
        let width = plan.values.len();
        c.push(id, stamp_ns, log_ns, &values[..width]);
        SimpleCallbackResult::KeepReading
    };
    let completeness = read_file_with_simple_callback(&shown, &mut callback);
    if let Some(e) = failure {
        return Err(Stop::Error(e));
    }
    match completeness {
        Ok(Completeness::Complete) => Ok(()),
        Ok(Completeness::Truncated) => {
            Err(Stop::Damaged { at: "the end".into(), what: "the last message is cut off".into() })
        }
        Ok(Completeness::MalformedRecord(why)) => {
            Err(Stop::Damaged { at: "a data message".into(), what: parse_error_text(&why) })
        }
        Err(e) => Err(Stop::Damaged { at: "the header or definitions".into(), what: e.to_string() }),
    }
}
