//! Raw rate-table logs (time, table rate, outputs): plateaus, strokes and runs found by
//! [`gyrolab::segment`] (or read from a manual segment file), then one rate-table record per
//! output channel (docs/METHODS.md section 5).

use super::{evaluate_record, EvaluatedAxis};
use crate::error::{EvalError, EvalResult};
use crate::outcome::segments::SegmentationReport;
use gyrolab::rate_test::{RateTable, RateTestOptions};
use gyrolab::segment::{
    rate_observations, segment_log, segments_from_manual, PlateauReduction, Segment, SegmentError, SegmentOptions,
};
use gyrolab::units::{split_unit_suffix, RateUnit};
use gyrolab::validate;
use gyrolab_io::rate_table::{RateLayout, RateTableFile};
use gyrolab_io::raw_log::{header_names, read_manual_segments, read_raw_log, segments_csv, table_rate_column, RawLog};
use gyrolab_io::DataError;
use std::path::{Path, PathBuf};

/// How raw logs are segmented; `None` keeps the default of [`SegmentOptions`].
///
/// ```
/// use gyrolab_eval::{rate::raw_log::SegmentationRequest, EvalError};
/// # fn main() -> Result<(), EvalError> {
/// let request = SegmentationRequest { settling_s: Some(2.0), min_plateau_s: Some(5.0), ..Default::default() };
/// let o = request.options()?;
/// assert_eq!((o.settling_s, o.min_duration_s), (2.0, 5.0));
/// // Unset fields keep the defaults.
/// let d = gyrolab::segment::SegmentOptions::default();
/// assert_eq!(o.tolerance_abs_dps, d.tolerance_abs_dps);
/// // A value outside its domain names its field.
/// let bad = SegmentationRequest { steady_tolerance_dps: Some(0.0), ..Default::default() };
/// match bad.options() {
///     Err(EvalError::Invalid(e)) => assert_eq!(e.field, "steady_tolerance_dps"),
///     other => panic!("{other:?}"),
/// }
/// # Ok(())
/// # }
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SegmentationRequest {
    /// Name of the table-rate column (default: `table_rate_<unit>` or `rate_<unit>`).
    pub table_rate_column: Option<String>,
    /// A plateau's rate stays within this of its mean (plus 0.1 % of the rate), deg/s.
    pub steady_tolerance_dps: Option<f64>,
    /// Shortest plateau kept, after the settling time, s.
    pub min_plateau_s: Option<f64>,
    /// Time dropped at the start of each plateau, s.
    pub settling_s: Option<f64>,
    /// A steady |rate| at most this at the start or end is a rest record, deg/s.
    pub rest_tolerance_dps: Option<f64>,
    /// Segments read from this file (start_time_s,end_time_s,kind,run,stroke) instead of found.
    pub manual_segments: Option<PathBuf>,
}

impl SegmentationRequest {
    /// The checked segmentation options (errors name the field).
    pub fn options(&self) -> EvalResult<SegmentOptions> {
        let mut o = SegmentOptions::default();
        if let Some(v) = self.steady_tolerance_dps {
            o.tolerance_abs_dps = validate::positive("steady_tolerance_dps", v)?;
        }
        if let Some(v) = self.min_plateau_s {
            o.min_duration_s = validate::positive("min_plateau_s", v)?;
        }
        if let Some(v) = self.settling_s {
            o.settling_s = validate::non_negative("settling_s", v)?;
        }
        if let Some(v) = self.rest_tolerance_dps {
            o.rest_tolerance_dps = validate::non_negative("rest_tolerance_dps", v)?;
        }
        Ok(o)
    }
}

/// The table-rate column of a file: given, or found from the header.
pub fn rate_column(path: &Path, given: Option<&str>) -> EvalResult<String> {
    if let Some(c) = given {
        return Ok(c.to_string());
    }
    let names = header_names(path)?;
    table_rate_column(&names).ok_or_else(|| {
        EvalError::conflict_on(
            &["table_rate_column"],
            format!(
                "{}: no table-rate column: expected a column named like 'table_rate_dps' or 'rate_dps' (found {}), \
                 or name it with {{table_rate_column}}",
                path.display(),
                names.join(", ")
            ),
        )
    })
}

/// How the segments of a log were obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SegmentationMode {
    /// Found from the table rate.
    Automatic,
    /// Read from a segment file.
    Manual,
}

impl SegmentationMode {
    /// `automatic` or `manual`, as reports and JSON name it.
    pub fn name(self) -> &'static str {
        match self {
            SegmentationMode::Automatic => "automatic",
            SegmentationMode::Manual => "manual",
        }
    }
}

/// A segmented raw log.
#[derive(Debug, Clone)]
pub struct SegmentedLog {
    /// The log.
    pub log: RawLog,
    /// Its labelled segments.
    pub segments: Vec<Segment>,
    /// How they were obtained.
    pub mode: SegmentationMode,
}

impl SegmentedLog {
    /// The segmentation as CSV, one row per segment (the format manual segment files take).
    pub fn segments_csv(&self) -> String {
        segments_csv(&self.segments, &self.log.lines)
    }

    /// The report view of this segmentation.
    pub fn report(&self) -> SegmentationReport<'_> {
        SegmentationReport {
            file: self.log.file.display().to_string(),
            mode: self.mode.name(),
            samples: self.log.time_s.len(),
            segments: &self.segments,
            lines: &self.log.lines,
        }
    }
}

/// Reads and segments a raw log (automatically, or from the request's manual segment file);
/// `output_column` keeps one output column.
pub fn segment_file(
    path: &Path,
    request: &SegmentationRequest,
    options: &SegmentOptions,
    output_column: Option<&str>,
) -> EvalResult<SegmentedLog> {
    let rate = rate_column(path, request.table_rate_column.as_deref())?;
    let log = read_raw_log(path, &rate, output_column.map(|c| vec![c.to_string()]))?;
    let Some(seg_file) = &request.manual_segments else {
        let segments = segment_log(&log.time_s, &log.table_rate_dps, options).map_err(|e| log.segment_error(&e))?;
        return Ok(SegmentedLog { log, segments, mode: SegmentationMode::Automatic });
    };
    let rows = read_manual_segments(seg_file)?;
    let manual: Vec<_> = rows.iter().map(|r| r.segment).collect();
    match segments_from_manual(&log.time_s, &log.table_rate_dps, &manual, options) {
        Ok(segments) => Ok(SegmentedLog { log, segments, mode: SegmentationMode::Manual }),
        Err(e) => {
            // Name the segment file's row (the last one starting at or before the sample named)
            // and the log line.
            let located = log.segment_error(&e);
            let at = e.sample_index().and_then(|i| log.time_s.get(i)).copied();
            let row = match e {
                // The window asked for names its row exactly.
                SegmentError::EmptySegment { start_s, end_s, .. } => {
                    rows.iter().find(|r| r.segment.start_time_s == start_s && r.segment.end_time_s == end_s)
                }
                _ => at.and_then(|t| rows.iter().rev().find(|r| r.segment.start_time_s <= t)),
            };
            let mut d = DataError::new(seg_file, format!("{} (log {})", e, location(&located)));
            if let Some(r) = row.or(rows.first()) {
                d = d.at_line(r.line);
            }
            Err(EvalError::Data(d))
        }
    }
}

fn location(d: &DataError) -> String {
    match d.line {
        Some(l) => format!("{}:{l}", d.file.display()),
        None => d.file.display().to_string(),
    }
}

/// Evaluates every output channel of a segmented log as an axis; `next_name` gives axis names
/// in order (or `None` for the channel's base name).
pub fn evaluate_channels(
    s: &SegmentedLog,
    options: &RateTestOptions,
    seg_options: &SegmentOptions,
    next_name: &mut dyn FnMut() -> Option<String>,
) -> EvalResult<Vec<EvaluatedAxis>> {
    let log = &s.log;
    let file = log.file.display().to_string();
    let samples: usize = s.segments.iter().map(Segment::samples).sum();
    let mut out = Vec::new();
    for (k, ch) in log.header.channels.iter().enumerate() {
        let (obs, rest) =
            rate_observations(&s.segments, &log.time_s, &log.channels[k], PlateauReduction::Mean, seg_options.rest)
                .map_err(|e| log.segment_error(&e))?;
        let table = RateTable::from_observations(&obs, rest).map_err(|e| {
            DataError::new(&log.file, format!("channel '{}': {e}", gyrolab_io::text::excerpt(&ch.name)))
        })?;
        let record = RateTableFile {
            table,
            output_unit: ch.unit,
            rate_unit: log.header.table_rate_unit.unwrap_or(RateUnit::DegPerSec),
            layout: RateLayout::Raw,
            samples,
        };
        // A name taken from a column header becomes a plain file name ('/' and the like as '_').
        let name = next_name().unwrap_or_else(|| {
            split_unit_suffix(&ch.name)
                .0
                .chars()
                .map(|c| if matches!(c, '/' | '\\' | ':') || c.is_control() { '_' } else { c })
                .collect()
        });
        out.push(evaluate_record(name, file.clone(), record, options)?);
    }
    Ok(out)
}
