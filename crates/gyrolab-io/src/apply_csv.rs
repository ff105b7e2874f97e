//! Streaming application of a calibration to a time-series file (`gyrolab apply`): blocks from
//! [`SeriesReader`] go through the core appliers and out as CSV, so memory stays constant
//! whatever the file's length.
//!
//! Output columns: `time_s` (passed through, when the file has one), `table_rate_dps` (passed
//! through from a raw log's table-rate column, when asked for), then `rate_dps` (single axis) or
//! `rate_<axis>_dps` for each of three axes, then `flag`: `ok`, `below` / `above` (outside the
//! calibrated range: continued along the end tangent, or some |rate| above a triad's limit) or
//! `not_finite` (a NaN or empty output cell, or an empty temperature cell when the calibration
//! compensates for temperature; the rate is NaN).

use crate::error::DataError;
use crate::series::{SeriesOptions, SeriesReader};
use gyrolab::apply::{AppliedRate, AppliedTriad, RangeStatus, SingleAxisCalibration, TriadApplier};
use gyrolab::units::OutputUnit;
use std::io::Write;
use std::path::Path;

/// The calibration to apply.
#[derive(Debug, Clone)]
pub enum ApplyModel {
    /// One output column to one rate.
    Single(SingleAxisCalibration),
    /// Three output columns (gyros x, y, z) to a rate vector.
    Triad(TriadApplier),
}

/// What to apply, to which columns, and how to name the results.
#[derive(Debug, Clone)]
pub struct ApplyPlan {
    /// The calibration.
    pub model: ApplyModel,
    /// Unit of the outputs the calibration expects.
    pub output_unit: OutputUnit,
    /// Output columns read: one (single axis) or three (gyros x, y, z in this order).
    pub columns: Vec<String>,
    /// Names of the rate columns written (one or three, such as `rate_dps`).
    pub rate_names: Vec<String>,
    /// A table-rate column to pass through as `table_rate_dps` (raw logs).
    pub table_rate_column: Option<String>,
    /// Temperature compensation of a single axis (the calibration's `[axis.temperature]`): the
    /// input needs a temperature column, and each output is brought to the reference temperature
    /// before the rate model.
    pub temperature: Option<gyrolab::thermal::Compensation>,
}

/// Counts of a finished application.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ApplySummary {
    /// Rows written.
    pub rows: u64,
    /// Rows below the calibrated range.
    pub below: u64,
    /// Rows above the calibrated range.
    pub above: u64,
    /// Rows with a non-finite output.
    pub not_finite: u64,
    /// Rows whose temperature lay outside the compensation model's range (the range's end used).
    pub temperature_outside: u64,
    /// Rows compensated for temperature.
    pub temperature_compensated: u64,
}

/// Why a streamed application stopped.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// Bad input data or a unit that does not match the calibration.
    #[error("{0}")]
    Data(DataError),
    /// The output could not be written.
    #[error("writing the output: {0}")]
    Write(std::io::Error),
}

impl From<DataError> for StreamError {
    fn from(e: DataError) -> Self {
        StreamError::Data(e)
    }
}

fn flag(s: RangeStatus) -> &'static [u8] {
    match s {
        RangeStatus::Inside => b"ok",
        RangeStatus::Below => b"below",
        RangeStatus::Above => b"above",
        RangeStatus::NotFinite => b"not_finite",
    }
}

fn push_num(buf: &mut Vec<u8>, fmt: &mut ryu::Buffer, v: f64) {
    if v.is_finite() {
        buf.extend_from_slice(fmt.format_finite(v).as_bytes());
    } else {
        buf.extend_from_slice(b"NaN");
    }
}

/// Applies `plan` to the file at `path`, writing CSV to `out`; `progress` is called after each
/// block with the rows written so far. NaN and empty output cells are passed on (flagged).
pub fn apply_file(
    path: &Path,
    plan: &ApplyPlan,
    out: &mut dyn Write,
    progress: &mut dyn FnMut(u64),
) -> Result<ApplySummary, StreamError> {
    let n = match plan.model {
        ApplyModel::Single(_) => 1,
        ApplyModel::Triad(_) => 3,
    };
    if plan.columns.len() != n || plan.rate_names.len() != n {
        return Err(DataError::new(
            path,
            format!("the calibration needs {n} output column(s), {} given", plan.columns.len()),
        )
        .into());
    }
    let options = SeriesOptions {
        channels: Some(plan.columns.clone()),
        table_rate_column: plan.table_rate_column.clone(),
        tolerant: true,
        ..SeriesOptions::default()
    };
    let mut reader = SeriesReader::open(path, &options)?;
    let header = reader.header().clone();
    if plan.temperature.is_some() && header.temperature_column.is_none() {
        return Err(DataError::new(
            path,
            "the calibration compensates this axis for temperature, but the file has no temperature column \
             (expected a column named temp_c or temperature_c, degC)",
        )
        .at_line(header.header_line)
        .into());
    }
    // Channel slot and unit factor of each wanted column, in the plan's order.
    let mut slots = Vec::with_capacity(n);
    for want in &plan.columns {
        let (k, ch) =
            header.channels.iter().enumerate().find(|(_, c)| c.name.eq_ignore_ascii_case(want)).ok_or_else(|| {
                DataError::new(path, format!("no output column '{want}'")).at_line(header.header_line)
            })?;
        let factor = ch.unit.factor_to(plan.output_unit).ok_or_else(|| {
            DataError::new(
                path,
                format!(
                    "the column is in {} but the calibration is for outputs in {}: the units do not convert",
                    ch.unit, plan.output_unit
                ),
            )
            .at_line(header.header_line)
            .at_column(ch.column, Some(&ch.name))
        })?;
        slots.push((k, factor));
    }
    let mut head = Vec::new();
    if header.time_column.is_some() {
        head.push("time_s".to_string());
    }
    if header.table_rate_column.is_some() {
        head.push("table_rate_dps".to_string());
    }
    head.extend(plan.rate_names.iter().cloned());
    head.push("flag".into());
    out.write_all(format!("{}\n", head.join(",")).as_bytes()).map_err(StreamError::Write)?;
    let mut summary = ApplySummary::default();
    let (mut single, mut triad): (Vec<AppliedRate>, Vec<AppliedTriad>) = (Vec::new(), Vec::new());
    let mut scaled: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let mut buf: Vec<u8> = Vec::with_capacity(1 << 20);
    let mut statuses: Vec<RangeStatus> = Vec::new();
    let mut fmt = ryu::Buffer::new();
    while let Some(b) = reader.next_block()? {
        for (i, &(k, factor)) in slots.iter().enumerate() {
            scaled[i].clear();
            scaled[i].extend(b.channels[k].iter().map(|v| v * factor));
        }
        if let (Some(comp), Some(temp)) = (&plan.temperature, b.temp) {
            for (u, &t) in scaled[0].iter_mut().zip(temp) {
                if !t.is_finite() {
                    *u = f64::NAN;
                    continue;
                }
                let (v, outside) = comp.to_reference(*u, t);
                *u = v;
                summary.temperature_outside += outside as u64;
                summary.temperature_compensated += 1;
            }
        }
        statuses.clear();
        match &plan.model {
            ApplyModel::Single(cal) => {
                cal.apply_block(&scaled[0], &mut single);
                statuses.extend(single.iter().map(|a| a.status));
            }
            ApplyModel::Triad(cal) => {
                cal.apply_block(&scaled[0], &scaled[1], &scaled[2], &mut triad)
                    .map_err(|e| DataError::new(path, e.to_string()).at_line(b.first_line))?;
                statuses.extend(triad.iter().map(|a| a.status));
            }
        }
        buf.clear();
        for (r, status) in statuses.iter().enumerate() {
            if let Some(t) = b.time {
                push_num(&mut buf, &mut fmt, t[r]);
                buf.push(b',');
            }
            if let Some(t) = b.table_rate {
                push_num(&mut buf, &mut fmt, t[r]);
                buf.push(b',');
            }
            match &plan.model {
                ApplyModel::Single(_) => push_num(&mut buf, &mut fmt, single[r].rate_dps),
                ApplyModel::Triad(_) => {
                    for (c, v) in triad[r].rates_dps.iter().enumerate() {
                        if c > 0 {
                            buf.push(b',');
                        }
                        push_num(&mut buf, &mut fmt, *v);
                    }
                }
            }
            buf.push(b',');
            buf.extend_from_slice(flag(*status));
            buf.push(b'\n');
            match status {
                RangeStatus::Inside => {}
                RangeStatus::Below => summary.below += 1,
                RangeStatus::Above => summary.above += 1,
                RangeStatus::NotFinite => summary.not_finite += 1,
            }
        }
        out.write_all(&buf).map_err(StreamError::Write)?;
        summary.rows += statuses.len() as u64;
        progress(summary.rows);
    }
    Ok(summary)
}
