//! `gyrolab rate` on raw logs (time, table rate, outputs): segmentation, one axis per output
//! channel; and the three-axis mode `gyrolab rate --triad x=FILE --triad y=FILE --triad z=FILE`.

use crate::cmd::rate::{evaluate_record, EvaluatedAxis, RateArgs};
use crate::error::{CliError, CliResult};
use gyrolab::rate_test::{RateTable, RateTestOptions};
use gyrolab::segment::{
    find_steady_segments, rate_observations, segment_log, segments_from_manual, PlateauReduction, Segment,
    SegmentOptions,
};
use gyrolab::triad::{fit_triad, plateaus_from_segments, TableAxis, TriadError, TriadFit, TriadOptions, TriadPlateau};
use gyrolab::units::{split_unit_suffix, OutputUnit, RateUnit};
use gyrolab_io::rate_table::{RateLayout, RateTableFile};
use gyrolab_io::raw_log::{header_names, read_manual_segments, read_raw_log, table_rate_column, RawLog};
use gyrolab_io::DataError;
use std::path::{Path, PathBuf};

/// The segmentation options the arguments ask for.
pub fn segment_options(args: &RateArgs) -> CliResult<SegmentOptions> {
    let mut o = SegmentOptions::default();
    let checks = [
        ("--steady-tolerance-dps", args.steady_tolerance_dps, &mut o.tolerance_abs_dps, false),
        ("--min-plateau-s", args.min_plateau_s, &mut o.min_duration_s, false),
        ("--settling-s", args.settling_s, &mut o.settling_s, true),
        ("--rest-tolerance-dps", args.rest_tolerance_dps, &mut o.rest_tolerance_dps, true),
    ];
    for (flag, value, slot, zero_ok) in checks {
        if let Some(v) = value {
            if !(v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0))) {
                let what = if zero_ok { "a non-negative number" } else { "a positive number" };
                return Err(CliError::Usage(format!("{flag} must be {what}, got {v}")));
            }
            *slot = v;
        }
    }
    Ok(o)
}

/// The table-rate column of a file: `--table-rate-column`, or found from the header.
fn rate_column(path: &Path, given: Option<&String>) -> CliResult<String> {
    if let Some(c) = given {
        return Ok(c.clone());
    }
    let names = header_names(path)?;
    table_rate_column(&names).ok_or_else(|| {
        CliError::Data(DataError::new(
            path,
            format!(
                "no table-rate column: expected a column named like 'table_rate_dps' or 'rate_dps' (found {}), \
                 or name it with --table-rate-column",
                names.join(", ")
            ),
        ))
    })
}

/// A segmented raw log.
pub struct SegmentedLog {
    /// The log.
    pub log: RawLog,
    /// Its labelled segments.
    pub segments: Vec<Segment>,
    /// `automatic` or `manual`.
    pub mode: &'static str,
}

/// Reads and segments a raw log (automatically, or from a manual segment file).
pub fn segment_file(
    path: &Path,
    args: &RateArgs,
    options: &SegmentOptions,
    manual: Option<&PathBuf>,
) -> CliResult<SegmentedLog> {
    let rate = rate_column(path, args.table_rate_column.as_ref())?;
    let log = read_raw_log(path, &rate, args.output_column.clone().map(|c| vec![c]))?;
    let Some(seg_file) = manual else {
        let segments = segment_log(&log.time_s, &log.table_rate_dps, options).map_err(|e| log.segment_error(&e))?;
        return Ok(SegmentedLog { log, segments, mode: "automatic" });
    };
    let rows = read_manual_segments(seg_file)?;
    let manual: Vec<_> = rows.iter().map(|r| r.segment).collect();
    match segments_from_manual(&log.time_s, &log.table_rate_dps, &manual, options) {
        Ok(segments) => Ok(SegmentedLog { log, segments, mode: "manual" }),
        Err(e) => {
            // Name the segment file's row (the last one starting at or before the sample named)
            // and the log line.
            let located = log.segment_error(&e);
            let at = e.sample_index().and_then(|i| log.time_s.get(i)).copied();
            let row = at.and_then(|t| rows.iter().rev().find(|r| r.segment.start_time_s <= t));
            let mut d = DataError::new(seg_file, format!("{} (log {})", e, location(&located)));
            if let Some(r) = row.or(rows.first()) {
                d = d.at_line(r.line);
            }
            Err(CliError::Data(d))
        }
    }
}

fn location(d: &DataError) -> String {
    match d.line {
        Some(l) => format!("{}:{l}", d.file.display()),
        None => d.file.display().to_string(),
    }
}

/// Evaluates every output channel of a segmented log as an axis; `next_name` gives `--axis`
/// names in order (or `None` for the channel's base name).
pub fn evaluate_channels(
    s: &SegmentedLog,
    options: &RateTestOptions,
    seg_options: &SegmentOptions,
    next_name: &mut dyn FnMut() -> Option<String>,
) -> CliResult<Vec<EvaluatedAxis>> {
    let log = &s.log;
    let file = log.file.display().to_string();
    let samples: usize = s.segments.iter().map(Segment::samples).sum();
    let mut out = Vec::new();
    for (k, ch) in log.header.channels.iter().enumerate() {
        let (obs, rest) =
            rate_observations(&s.segments, &log.time_s, &log.channels[k], PlateauReduction::Mean, seg_options.rest)
                .map_err(|e| log.segment_error(&e))?;
        let table = RateTable::from_observations(&obs, rest)
            .map_err(|e| DataError::new(&log.file, format!("channel '{}': {e}", ch.name)))?;
        let record = RateTableFile {
            table,
            output_unit: ch.unit,
            rate_unit: log.header.table_rate_unit.unwrap_or(RateUnit::DegPerSec),
            layout: RateLayout::Raw,
            samples,
        };
        let name = next_name().unwrap_or_else(|| split_unit_suffix(&ch.name).0);
        out.push(evaluate_record(name, file.clone(), record, options)?);
    }
    Ok(out)
}

/// Parses a `--triad AXIS=FILE` value.
pub fn parse_triad_file(s: &str) -> Result<(TableAxis, PathBuf), String> {
    let (a, f) = s.split_once('=').ok_or_else(|| format!("'{s}': expected AXIS=FILE, such as x=turn_x.csv"))?;
    let axis = TableAxis::parse(a).ok_or_else(|| format!("'{a}' is not a table axis: expected x, y or z"))?;
    if f.trim().is_empty() {
        return Err(format!("'{s}': no file after '='"));
    }
    Ok((axis, PathBuf::from(f)))
}

/// A finished three-axis fit with its inputs.
pub struct TriadResult {
    /// The records, (axis, file as given).
    pub files: Vec<(TableAxis, String)>,
    /// Gyro output columns x, y, z (as in the first file).
    pub gyro_columns: [String; 3],
    /// Output unit.
    pub output_unit: OutputUnit,
    /// The fit.
    pub fit: TriadFit,
}

/// Reads the three-axis set, segments each log and fits the 12-parameter model.
pub fn triad(args: &RateArgs, options: &SegmentOptions) -> CliResult<TriadResult> {
    let files = &args.triad;
    let listed = || files.iter().map(|(a, f)| format!("{a}={}", f.display())).collect::<Vec<_>>().join(", ");
    for axis in TableAxis::ALL {
        if !files.iter().any(|(a, _)| *a == axis) {
            return Err(CliError::Usage(format!(
                "the three-axis set misses the {axis} axis (given: {}): give --triad {axis}=FILE, a log of rotations \
                 about {axis} in both senses",
                listed()
            )));
        }
    }
    if !args.gyro_columns.is_empty() && args.gyro_columns.len() != 3 {
        return Err(CliError::Usage(format!(
            "--gyro-columns needs three names (gyros x, y, z), got {}",
            args.gyro_columns.len()
        )));
    }
    let mut plateaus: Vec<TriadPlateau> = Vec::new();
    let mut unit: Option<OutputUnit> = None;
    let mut gyro_columns: Option<[String; 3]> = None;
    let mut described = Vec::new();
    for (axis, path) in files {
        let rate = rate_column(path, args.table_rate_column.as_ref())?;
        let select = (!args.gyro_columns.is_empty()).then(|| args.gyro_columns.clone());
        let log = read_raw_log(path, &rate, select)?;
        let chans = &log.header.channels;
        let order: Vec<usize> = if args.gyro_columns.is_empty() {
            if chans.len() != 3 {
                let names: Vec<&str> = chans.iter().map(|c| c.name.as_str()).collect();
                return Err(CliError::Data(
                    DataError::new(
                        path,
                        format!(
                            "{} output column(s) ({}): a three-axis log needs three; name them with \
                             --gyro-columns GX,GY,GZ",
                            chans.len(),
                            names.join(", ")
                        ),
                    )
                    .at_line(log.header.header_line),
                ));
            }
            vec![0, 1, 2]
        } else {
            // ok: read_raw_log selected exactly these columns, so each is present.
            args.gyro_columns.iter().map(|n| log.channel(n).unwrap_or(0)).collect()
        };
        let u0 = *unit.get_or_insert(chans[order[0]].unit);
        let mut outputs: Vec<Vec<f64>> = Vec::with_capacity(3);
        for &k in &order {
            let c = &chans[k];
            let f = c.unit.factor_to(u0).ok_or_else(|| {
                DataError::new(
                    path,
                    format!("output in {}, but the set's outputs are in {u0}: the units do not convert", c.unit),
                )
                .at_line(log.header.header_line)
                .at_column(c.column, Some(&c.name))
            })?;
            outputs.push(log.channels[k].iter().map(|v| v * f).collect());
        }
        gyro_columns.get_or_insert_with(|| [0, 1, 2].map(|i| chans[order[i]].name.clone()));
        let steady =
            find_steady_segments(&log.time_s, &log.table_rate_dps, options).map_err(|e| log.segment_error(&e))?;
        let o = [&outputs[0][..], &outputs[1][..], &outputs[2][..]];
        plateaus.extend(plateaus_from_segments(*axis, &steady, &log.time_s, o).map_err(|e| log.segment_error(&e))?);
        described.push((*axis, path.display().to_string()));
    }
    let topts = TriadOptions { rest_tolerance_dps: options.rest_tolerance_dps, ..TriadOptions::default() };
    let fit = fit_triad(&plateaus, &topts).map_err(|e| {
        // Name the file(s) of the axis the problem is about, else every file of the set.
        let axis = match &e {
            TriadError::MissingAxis { axis, .. } | TriadError::MissingSense { axis, .. } => Some(*axis),
            TriadError::NonFinite { axis, .. } => Some(*axis),
            _ => None,
        };
        let names: Vec<String> =
            files.iter().filter(|(a, _)| axis.is_none_or(|x| x == *a)).map(|(_, f)| f.display().to_string()).collect();
        CliError::Data(DataError::new(names.join(", "), format!("three-axis calibration: {e}")))
    })?;
    Ok(TriadResult {
        files: described,
        gyro_columns: gyro_columns.unwrap_or_else(|| ["x".into(), "y".into(), "z".into()]),
        output_unit: unit.unwrap_or(OutputUnit::Volt),
        fit,
    })
}
