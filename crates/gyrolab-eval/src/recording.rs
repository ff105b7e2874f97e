//! Recordings (ROS 2 MCAP, ROS 1 bags, PX4 ULog): the inventory of their topics (`gyrolab
//! inspect`) and their IMU topics written as CSV or Parquet (`gyrolab convert`).

use crate::error::{EvalError, EvalResult};
use crate::outcome::inventory::{Inventory, TopicInventory};
use gyrolab::sampling::estimate_interval;
use gyrolab_io::recording::{open, RecordingOptions};
use std::path::{Path, PathBuf};

/// Rate, duration, gaps of a topic's stamps (ns, any order).
fn timing_of(stamps: &[i64]) -> (Option<f64>, Option<f64>, Option<f64>, usize, usize) {
    if stamps.is_empty() {
        return (None, None, None, 0, 0);
    }
    let mut s = stamps.to_vec();
    s.sort_unstable();
    let first = s[0];
    let start = first as f64 * 1e-9;
    let duration = (s[s.len() - 1] - first) as f64 * 1e-9;
    let t: Vec<f64> = s.iter().map(|&x| (x - first) as f64 * 1e-9).collect();
    match estimate_interval(&t) {
        Ok(e) => (Some(start), Some(duration), Some(e.rate_hz()).filter(|r| r.is_finite()), e.gaps.len(), e.missing),
        Err(_) => (Some(start), Some(duration), None, 0, 0),
    }
}

/// The topics of a recording with their message types, counts, rates, spans and gaps (IMU
/// topics timed by their header stamps, others by their log times); a Parquet or text file is
/// reported as one table.
pub fn inspect(path: &Path) -> EvalResult<Inventory> {
    // Opened once: the file read is the file whose format was sniffed.
    let opened = open(path)?;
    let format = opened.format();
    let file = path.display().to_string();
    let version = env!("CARGO_PKG_VERSION").to_string();
    if !format.is_recording() {
        let data = opened.read_records(&Default::default(), &[])?;
        let record = &data.records[0].data;
        let names: Vec<String> =
            record.header.channels.iter().map(|c| format!("{} [{}]", c.name, c.unit.symbol())).collect();
        // The clock model of every command: a stamp going back to or before the first (a
        // clock reset, a trailer of zeros) ends the record, as `allan` and `bias` read it.
        let reset = record.time.as_deref().and_then(|t| estimate_interval(t).ok()).and_then(|e| e.reset);
        let kept = reset.map_or(record.lines.len(), |r| r.index);
        let (start, duration, rate, gaps, missing) = match &record.time {
            Some(t) => {
                let ns: Vec<i64> = t[..kept.min(t.len())].iter().map(|&x| (x * 1e9) as i64).collect();
                timing_of(&ns)
            }
            None => (None, None, None, 0, 0),
        };
        let truncated = reset.map(|r| {
            format!(
                "the time stamps go back at line {} (from {} s to {} s: a clock reset or a trailer of zeros): the record ends before it, {} row(s) from there left out",
                record.lines.get(r.index).unwrap_or(0),
                r.from_s,
                r.to_s,
                record.lines.len() - kept
            )
        });
        return Ok(Inventory {
            gyrolab_version: version,
            file,
            format: format.name().into(),
            topics: vec![TopicInventory {
                topic: "(table)".into(),
                message_type: names.join(", "),
                messages: kept as u64,
                imu: !record.header.channels.is_empty(),
                start_s: start,
                duration_s: duration,
                rate_hz: rate,
                gaps,
                missing,
                out_of_order: 0,
                stamps: if record.time.is_some() { "time column".into() } else { "no time column".into() },
            }],
            truncated,
        });
    }
    let again = opened.try_clone()?;
    let rec = opened.read_recording(&RecordingOptions { stamps: true, ..Default::default() });
    let rec = match rec {
        Ok(r) => r,
        // A recording without IMU topics is still inventoried.
        Err(_) => {
            again.read_recording(&RecordingOptions { stamps: true, inventory_only: true, ..Default::default() })?
        }
    };
    let mut topics = Vec::with_capacity(rec.topics.len());
    for t in &rec.topics {
        let decoded = rec.imu.iter().find(|i| i.topic == t.topic);
        let (start, duration, rate, gaps, missing) = timing_of(&t.stamps_ns);
        topics.push(TopicInventory {
            topic: t.topic.clone(),
            message_type: t.message_type.clone(),
            messages: t.messages,
            imu: t.imu,
            start_s: start,
            duration_s: duration,
            rate_hz: rate,
            gaps,
            missing,
            out_of_order: decoded.map_or(0, |d| d.out_of_order),
            stamps: decoded.map_or("log times".to_string(), |d| d.stamp_source.describe().to_string()),
        });
    }
    Ok(Inventory { gyrolab_version: version, file, format: rec.format.name().into(), topics, truncated: rec.truncated })
}

/// The output format of [`convert`], by the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConvertFormat {
    /// CSV (`.csv`).
    Csv,
    /// Parquet (`.parquet`).
    Parquet,
}

/// What [`convert`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Converted {
    /// (topic, file written, messages).
    pub files: Vec<(String, PathBuf, usize)>,
    /// Where the recording ends early or is damaged, when it does.
    pub truncated: Option<String>,
}

/// `imu.csv` for topic `/imu0` among several -> `imu_imu0.csv`.
pub fn per_topic_path(path: &Path, topic: &str) -> PathBuf {
    let plain: String = topic
        .trim_start_matches('/')
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
        .take(64)
        .collect();
    let stem = path.file_stem().map_or("imu".into(), |s| s.to_string_lossy().to_string());
    let ext = path.extension().map_or(String::new(), |e| format!(".{}", e.to_string_lossy()));
    path.with_file_name(format!("{stem}_{plain}{ext}"))
}

/// Writes the IMU topics of a recording (`topics` selects; empty: all) as CSV or Parquet
/// (by `out`'s extension): `timestamp_ns` and the channels with their units in the names, in
/// stamp order; one file per topic (`out` itself for one topic, `stem_topic.ext` for several).
///
/// `window_s` keeps the messages `[start, end)` seconds after each topic's first message; a
/// topic with fewer than two there is an error naming its length.
pub fn convert(
    path: &Path,
    topics: &[String],
    out: &Path,
    window_s: (Option<f64>, Option<f64>),
) -> EvalResult<Converted> {
    for (name, v) in [("start_s", window_s.0), ("end_s", window_s.1)] {
        if let Some(v) = v {
            if !v.is_finite() || v < 0.0 {
                return Err(EvalError::conflict_on(
                    &[name],
                    format!("{{{name}}} must be a number of seconds >= 0, got {v}"),
                ));
            }
        }
    }
    if let (Some(a), Some(b)) = window_s {
        if b <= a {
            return Err(EvalError::conflict_on(
                &["start_s", "end_s"],
                format!("{{end_s}} {b} s is not after {{start_s}} {a} s"),
            ));
        }
    }
    let format = match out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("csv") => ConvertFormat::Csv,
        Some("parquet") => ConvertFormat::Parquet,
        _ => {
            return Err(EvalError::conflict_on(
                &["out"],
                format!("{}: expected a .csv or .parquet file name for {{out}}", out.display()),
            ))
        }
    };
    let opened = open(path)?;
    let kind = opened.format();
    if !kind.is_recording() {
        return Err(EvalError::Data(gyrolab_io::DataError::new(
            path,
            format!("a {} file, not a recording: convert reads MCAP, ROS 1 bags and PX4 ULog files", kind.name()),
        )));
    }
    let mut rec = opened.read_recording(&RecordingOptions { topics: topics.to_vec(), ..Default::default() })?;
    if window_s.0.is_some() || window_s.1.is_some() {
        for t in &mut rec.imu {
            let length = match (t.stamps_ns.first(), t.stamps_ns.last()) {
                (Some(a), Some(b)) => (i128::from(*b) - i128::from(*a)) as f64 * 1e-9,
                _ => 0.0,
            };
            if t.keep_window(window_s.0, window_s.1) < 2 {
                return Err(EvalError::conflict_on(
                    &["start_s", "end_s"],
                    format!(
                        "{}: topic '{}': fewer than two messages between {{start_s}} and {{end_s}}: the topic is {length} s long",
                        path.display(),
                        gyrolab_io::text::excerpt(&t.topic)
                    ),
                ));
            }
        }
    }
    let several = rec.imu.len() > 1;
    // Every topic's file written together (all or none), never over the recording.
    let mut files = Vec::new();
    let mut outputs = Vec::new();
    for t in &rec.imu {
        let target = if several { per_topic_path(out, &t.topic) } else { out.to_path_buf() };
        outputs.push(match format {
            ConvertFormat::Csv => {
                gyrolab_io::atomic::OutputFile::stream(&target, |w| gyrolab_io::recording::write_topic_csv(w, t))
            }
            ConvertFormat::Parquet => {
                gyrolab_io::atomic::OutputFile::stream(&target, |w| gyrolab_io::recording::write_topic_parquet(w, t))
            }
        });
        files.push((t.topic.clone(), target, t.stamps_ns.len()));
    }
    gyrolab_io::atomic::write_outputs(outputs, &[path])?;
    Ok(Converted { files, truncated: rec.truncated })
}
