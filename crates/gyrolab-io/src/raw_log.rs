//! Raw rate-table logs: time, table rate and one or more outputs in one file, as labs log them
//! (100 to 1000 Hz). Detection of the layout from the header, reading into memory (the
//! segmentation needs the whole log), line-accurate segmentation errors, manual segment files
//! and the segment table written by `gyrolab rate --segments-out`.

use crate::error::DataError;
use crate::series::{read_series_all, SeriesHeader, SeriesOptions};
use crate::text::{parse_number, parse_text_table, Delimiter};
use gyrolab::rate_test::Stroke;
use gyrolab::segment::{ManualSegment, Segment, SegmentError, SegmentKind};
use gyrolab::units::{split_unit_suffix, RateUnit};
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// Base names (before the unit suffix) of a table-rate column, in order of preference.
pub const TABLE_RATE_NAMES: [&str; 2] = ["table_rate", "rate"];

/// The header names of a delimited text file (first line that is neither blank nor a comment).
pub fn header_names(path: &Path) -> Result<Vec<String>, DataError> {
    let (f, _) = crate::input_file::open_regular(path)?;
    let mut r = BufReader::new(f);
    let mut buf = Vec::new();
    let mut guard = crate::text::TextGuard::default();
    loop {
        buf.clear();
        // At most one line over the limit is read: the guard ends an endless line (`/dev/zero`).
        let n = (&mut r)
            .take(crate::text::MAX_LINE_BYTES as u64 + 2)
            .read_until(b'\n', &mut buf)
            .map_err(|e| DataError::io(path, &e))?;
        guard.check(path, &buf)?;
        if n == 0 {
            return Err(DataError::new(path, "the file is empty: expected a header row such as 'time_s,output_v'"));
        }
        let text = String::from_utf8_lossy(&buf);
        let t = text.trim().trim_start_matches('\u{feff}');
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let d = Delimiter::sniff(t);
        return Ok(d.split(t).into_iter().map(|s| s.trim_matches('"').trim().to_string()).collect());
    }
}

/// The table-rate column of a header: `table_rate_<unit>` or `rate_<unit>` (unit dps, rad_s, dph).
pub fn table_rate_column(names: &[String]) -> Option<String> {
    TABLE_RATE_NAMES.iter().find_map(|want| {
        names
            .iter()
            .find(|n| {
                let (base, sfx) = split_unit_suffix(n);
                base == *want && sfx.as_deref().and_then(RateUnit::parse).is_some()
            })
            .cloned()
    })
}

/// Whether a header is that of a raw log: a `time_s` column, a table-rate column and no `stroke`
/// column (the long rate-table layout has one). Returns the table-rate column's name.
pub fn detect_raw_log(names: &[String]) -> Option<String> {
    let has = |want: &str| names.iter().any(|n| n.eq_ignore_ascii_case(want));
    if !has("time_s") || has("stroke") {
        return None;
    }
    table_rate_column(names)
}

/// A raw log read into memory.
#[derive(Debug, Clone, PartialEq)]
pub struct RawLog {
    /// The file.
    pub file: PathBuf,
    /// Its header (channels, units, columns).
    pub header: SeriesHeader,
    /// Source line of each sample.
    pub lines: Vec<u64>,
    /// Time, s.
    pub time_s: Vec<f64>,
    /// Table rate, deg/s.
    pub table_rate_dps: Vec<f64>,
    /// One column per output channel, in the order of `header.channels`.
    pub channels: Vec<Vec<f64>>,
}

impl RawLog {
    /// The error of a segmentation of this log, located at the file line of the sample it names.
    pub fn segment_error(&self, e: &SegmentError) -> DataError {
        locate_segment_error(&self.file, &self.lines, e)
    }

    /// Index of the channel named `name` (case-insensitive).
    pub fn channel(&self, name: &str) -> Option<usize> {
        self.header.channels.iter().position(|c| c.name.eq_ignore_ascii_case(name))
    }
}

/// A segmentation error of a log as a [`DataError`] at the line of the sample it names.
pub fn locate_segment_error(file: &Path, lines: &[u64], e: &SegmentError) -> DataError {
    let d = DataError::new(file, e.to_string());
    match e.sample_index().and_then(|i| lines.get(i)) {
        Some(&l) => d.at_line(l),
        None => d,
    }
}

/// Reads a raw log: `table_rate` names the table-rate column, `channels` selects outputs (all
/// others by default). A time column is required.
pub fn read_raw_log(path: &Path, table_rate: &str, channels: Option<Vec<String>>) -> Result<RawLog, DataError> {
    read_raw_log_limited(path, table_rate, channels, MAX_RAW_LOG_ROWS)
}

/// Most rows of a raw rate-table log: 50 M (about 14 h at 1 kHz; a log held whole in memory
/// needs 8 bytes per row and column).
pub const MAX_RAW_LOG_ROWS: u64 = 50_000_000;

/// [`read_raw_log`] with another row limit (more rows is an error naming the line).
pub fn read_raw_log_limited(
    path: &Path,
    table_rate: &str,
    channels: Option<Vec<String>>,
    max_rows: u64,
) -> Result<RawLog, DataError> {
    let options = SeriesOptions {
        table_rate_column: Some(table_rate.to_string()),
        channels,
        max_rows: Some(max_rows),
        ..Default::default()
    };
    let data = read_series_all(path, &options)?;
    let Some(time_s) = data.time else {
        return Err(
            DataError::new(path, "a raw log needs a time column named 'time_s'").at_line(data.header.header_line)
        );
    };
    let table_rate_dps = data.table_rate.unwrap_or_default();
    Ok(RawLog {
        file: path.to_path_buf(),
        header: data.header,
        lines: data.lines.to_vec(),
        time_s,
        table_rate_dps,
        channels: data.channels,
    })
}

/// A segment read from a manual segment file, with its line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManualSegmentRow {
    /// 1-based line in the segment file.
    pub line: u64,
    /// The segment.
    pub segment: ManualSegment,
}

/// Reads a manual segment file: columns `start_time_s`, `end_time_s`, `kind` (`rest_start`,
/// `rest_end`, `plateau`) and, for plateaus, `run` and `stroke` (`fwd`/`rev`); other columns
/// (as in a `--segments-out` file) are ignored. Rows must be in time order.
pub fn read_manual_segments(path: &Path) -> Result<Vec<ManualSegmentRow>, DataError> {
    let text = crate::text::read_text_file(path, crate::text::MAX_CONFIG_BYTES, "a segment file (CSV)")?;
    parse_manual_segments(path, &text)
}

/// Parses a manual segment file's text (see [`read_manual_segments`]); `path` names it in errors.
pub fn parse_manual_segments(path: &Path, text: &str) -> Result<Vec<ManualSegmentRow>, DataError> {
    let t = parse_text_table(path, text)?;
    let col = |name: &str| {
        t.column(name).ok_or_else(|| {
            DataError::new(
                path,
                format!(
                    "no '{name}' column: a segment file needs start_time_s,end_time_s,kind and, for plateaus, run,stroke \
                     (found {})",
                    crate::text::excerpt(&t.header.join(", "))
                ),
            )
            .at_line(t.header_line)
        })
    };
    let (cs, ce, ck) = (col("start_time_s")?, col("end_time_s")?, col("kind")?);
    let (cr, cst) = (t.column("run"), t.column("stroke"));
    let mut out: Vec<ManualSegmentRow> = Vec::with_capacity(t.rows.len());
    for row in &t.rows {
        let field = |c: usize| row.fields.get(c).map(String::as_str).unwrap_or("");
        let num = |c: usize| parse_number(path, row.line, c + 1, &t.header[c], field(c));
        let (start, end) = (num(cs)?, num(ce)?);
        let at =
            |c: usize, msg: String| DataError::new(path, msg).at_line(row.line).at_column(c + 1, Some(&t.header[c]));
        if end < start {
            return Err(at(ce, format!("end {end} s is before start {start} s")));
        }
        if let Some(prev) = out.last() {
            if start < prev.segment.end_time_s {
                return Err(at(
                    cs,
                    format!(
                        "segment starts at {start} s, before the previous one (line {}) ends at {} s: segments must be \
                         in time order and must not overlap",
                        prev.line, prev.segment.end_time_s
                    ),
                ));
            }
        }
        let run = match cr.map(field).map(str::trim).filter(|s| !s.is_empty()) {
            Some(s) => Some(s.parse::<u32>().map_err(|_| {
                at(cr.unwrap_or(0), format!("found '{}', expected a run number (1, 2, ...)", crate::text::excerpt(s)))
            })?),
            None => None,
        };
        let stroke = match cst.map(field).map(str::trim).filter(|s| !s.is_empty()) {
            Some(s) => Some(Stroke::from_label(s).ok_or_else(|| {
                at(
                    cst.unwrap_or(0),
                    format!("found '{}', expected a stroke: {}", crate::text::excerpt(s), Stroke::ACCEPTED),
                )
            })?),
            None => None,
        };
        let label = field(ck);
        let kind = SegmentKind::from_parts(label, run, stroke).ok_or_else(|| {
            let run = run.map_or_else(|| "no run".to_string(), |r| format!("run {r}"));
            let stroke = stroke.map_or_else(|| "no stroke".to_string(), |s| format!("stroke {}", s.label()));
            at(
                ck,
                format!(
                    "kind '{}' with {run} and {stroke}: expected rest_start, rest_end, or plateau with a run \
                     (1, 2, ...) and a stroke (fwd/rev)",
                    crate::text::excerpt(label)
                ),
            )
        })?;
        out.push(ManualSegmentRow {
            line: row.line,
            segment: ManualSegment { start_time_s: start, end_time_s: end, kind },
        });
    }
    if out.is_empty() {
        return Err(DataError::new(path, "the segment file has a header but no segments").at_line(t.header_line));
    }
    Ok(out)
}

/// Header of the segment table (`--segments-out`).
pub const SEGMENTS_HEADER: &str = "index,kind,run,stroke,start_line,end_line,start_time_s,end_time_s,samples,rate_dps";

/// The segment table as CSV: one row per segment, with the log lines of its first and last
/// kept samples; a file in this layout is accepted back as a manual segment file.
pub fn segments_csv(segments: &[Segment], lines: &[u64]) -> String {
    let mut s = String::with_capacity(64 * (segments.len() + 1));
    s.push_str(SEGMENTS_HEADER);
    s.push('\n');
    for (i, g) in segments.iter().enumerate() {
        let (run, stroke) = match g.kind {
            SegmentKind::Plateau { run, stroke } => (run.to_string(), stroke.label().to_string()),
            _ => (String::new(), String::new()),
        };
        let line_of = |k: usize| lines.get(k).map_or(String::new(), u64::to_string);
        let _ = writeln!(
            s,
            "{},{},{run},{stroke},{},{},{},{},{},{}",
            i + 1,
            g.kind.label(),
            line_of(g.start_index),
            line_of(g.end_index.saturating_sub(1)),
            g.start_time_s,
            g.end_time_s,
            g.samples(),
            g.rate_dps
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(s: &str) -> Vec<String> {
        s.split(',').map(str::to_string).collect()
    }

    #[test]
    fn detects_raw_logs() {
        assert_eq!(detect_raw_log(&names("time_s,table_rate_dps,gx_v")), Some("table_rate_dps".into()));
        assert_eq!(detect_raw_log(&names("time_s,rate_rad_s,gx_v")), Some("rate_rad_s".into()));
        assert_eq!(detect_raw_log(&names("rate_dps,run,stroke,output_v")), None);
        assert_eq!(detect_raw_log(&names("time_s,rate_dps,stroke,output_v")), None);
        assert_eq!(detect_raw_log(&names("time_s,output_v")), None);
    }

    #[test]
    fn manual_segments_read_with_lines() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.csv");
        std::fs::write(&p, "start_time_s,end_time_s,kind,run,stroke\n0,5,rest_start,,\n10,20,plateau,1,fwd\n").unwrap();
        let m = read_manual_segments(&p).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[1].line, 3);
        assert_eq!(m[1].segment.kind, SegmentKind::Plateau { run: 1, stroke: Stroke::Forward });
        std::fs::write(&p, "start_time_s,end_time_s,kind,run,stroke\n0,5,rest_start,,\n4,20,plateau,1,fwd\n").unwrap();
        let e = read_manual_segments(&p).unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(e.to_string().contains("overlap"), "{e}");
        std::fs::write(&p, "start_time_s,end_time_s,kind\n0,5,plateau\n").unwrap();
        assert!(read_manual_segments(&p).unwrap_err().to_string().contains("kind 'plateau'"));
    }

    #[test]
    fn table_rate_read_apart_from_outputs_in_deg_per_s() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(&p, "# c\ntime_s,rate_rad_s,gx_v\n0,0,2.5\n0.01,3.141592653589793,2.6\n").unwrap();
        let log = read_raw_log(&p, "rate_rad_s", None).unwrap();
        assert_eq!(log.header.channels.len(), 1);
        assert_eq!(log.lines, [3, 4]);
        assert!((log.table_rate_dps[1] - 180.0).abs() < 1e-12);
        assert_eq!(log.channels[0], [2.5, 2.6]);
        let e = read_raw_log(&p, "table_rate_dps", None).unwrap_err();
        assert!(e.to_string().contains("'table_rate_dps' is not in the header"), "{e}");
    }

    #[test]
    fn a_log_beyond_the_row_limit_is_refused_at_its_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big.csv");
        let mut text = String::from("time_s,rate_dps,gx_v\n");
        for i in 0..10 {
            text.push_str(&format!("{},0,2.5\n", i as f64 * 0.01));
        }
        std::fs::write(&p, &text).unwrap();
        assert!(read_raw_log_limited(&p, "rate_dps", None, 10).is_ok());
        let e = read_raw_log_limited(&p, "rate_dps", None, 6).unwrap_err();
        // Row 7 (the first beyond 6) is on line 8.
        assert_eq!(e.line, Some(8), "{e}");
        assert!(e.to_string().contains("more than 6 data rows"), "{e}");
    }
}
