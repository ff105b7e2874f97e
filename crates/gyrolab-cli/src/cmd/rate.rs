//! `gyrolab rate FILE...`: evaluate rate-table records, one axis per file (a raw log: one axis
//! per output column), or a three-axis set (`--triad`).

use crate::error::{CliError, CliResult};
use crate::output::{output_error, print, to_json, write_file};
use clap::Args;
use gyrolab::triad::TableAxis;
use gyrolab::units::{OutputUnit, RateUnit};
use gyrolab_eval::outcome::rate::AxisReport;
use gyrolab_eval::outcome::segments::SegmentationReport;
use gyrolab_eval::rate::raw_log::SegmentationRequest;
use gyrolab_eval::rate::{calibration_file, evaluate_rates, EvaluatedAxis, RateRequest, RateSettings};
use gyrolab_eval::triad::{evaluate_triad, TriadRequest};
use gyrolab_io::atomic::{write_outputs, OutputFile};
use gyrolab_io::rate_table::RateColumns;
use gyrolab_report::rate::{rate_json, rate_text};
use gyrolab_report::segments::SegmentationJson;
use gyrolab_report::triad::{triad_json, triad_text};
use std::path::Path;
use std::path::PathBuf;

/// Options of `gyrolab rate`.
#[derive(Debug, Args)]
pub struct RateArgs {
    /// Rate-table records, one axis per file (long layout: rate_dps,run,stroke,output_v; or the
    /// wide layout of the paper's Table 1), or raw logs (time_s,table_rate_dps,OUTPUT...: one
    /// axis per output column).
    #[arg(required_unless_present = "triad", value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Treat every file as a raw log (time, table rate, outputs) even if its header does not say so.
    #[arg(long)]
    pub raw: bool,
    /// Raw logs: name of the table-rate column (default: table_rate_<unit> or rate_<unit>).
    #[arg(long, value_name = "NAME")]
    pub table_rate_column: Option<String>,
    /// Raw logs: a plateau's rate stays within this of its mean (plus 0.1 % of the rate), deg/s [0.05].
    #[arg(long, value_name = "DPS")]
    pub steady_tolerance_dps: Option<f64>,
    /// Raw logs: shortest plateau kept, after the settling time, s [5].
    #[arg(long, value_name = "S")]
    pub min_plateau_s: Option<f64>,
    /// Raw logs: time dropped at the start of each plateau, s [1].
    #[arg(long, value_name = "S")]
    pub settling_s: Option<f64>,
    /// Raw logs: a steady |rate| at most this at the start or end is a rest record, deg/s [0.05].
    #[arg(long, value_name = "DPS")]
    pub rest_tolerance_dps: Option<f64>,
    /// Raw log: write the segmentation (one row per segment) to this CSV file.
    #[arg(long, value_name = "FILE.csv")]
    pub segments_out: Option<PathBuf>,
    /// Raw log: use these segments instead of finding them (start_time_s,end_time_s,kind,run,stroke;
    /// a --segments-out file is accepted).
    #[arg(long, value_name = "FILE.csv")]
    pub segments: Option<PathBuf>,
    /// Three-axis calibration: a raw log of rotations about a table axis, both senses, as
    /// AXIS=FILE (x, y and z each at least once).
    #[arg(long, value_name = "AXIS=FILE", value_parser = parse_triad_file)]
    pub triad: Vec<(gyrolab::triad::TableAxis, PathBuf)>,
    /// Three-axis calibration: the gyro output columns x, y, z (default: the file's three outputs).
    #[arg(long, value_name = "GX,GY,GZ", value_delimiter = ',')]
    pub gyro_columns: Vec<String>,
    /// Axis names, one per file in order (default: each file's stem).
    #[arg(long = "axis", value_name = "NAME")]
    pub axes: Vec<String>,
    /// Print every figure as JSON (keys in docs/JSON.md).
    #[arg(long)]
    pub json: bool,
    /// Also print the per-point table (the paper's Table 2 with residuals).
    #[arg(long)]
    pub points: bool,
    /// Coverage factor k of the repeatability (3 or 2).
    #[arg(long, default_value_t = 3.0, value_name = "K")]
    pub coverage: f64,
    /// Quote hysteresis as half the largest forward-reverse difference.
    #[arg(long)]
    pub half_hysteresis: bool,
    /// Order of the polynomial model (1 = straight line).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub order: usize,
    /// Find the widest symmetric input range whose nonlinearity stays within PCT percent.
    #[arg(long, value_name = "PCT")]
    pub nonlinearity_limit: Option<f64>,
    /// Write the calibration (K, F0, polynomial, units, source, time) to this TOML file.
    #[arg(long, value_name = "FILE.toml")]
    pub cal_out: Option<PathBuf>,
    /// Name of the rate column (default: the column named rate_<unit>).
    #[arg(long, value_name = "NAME")]
    pub rate_column: Option<String>,
    /// Name of the run column (default: run).
    #[arg(long, value_name = "NAME")]
    pub run_column: Option<String>,
    /// Name of the stroke column (default: stroke).
    #[arg(long, value_name = "NAME")]
    pub stroke_column: Option<String>,
    /// Name of the output column (default: the column named output_<unit>).
    #[arg(long, value_name = "NAME")]
    pub output_column: Option<String>,
    /// Unit of the rates when the column name does not carry it: dps, rad_s, dph.
    #[arg(long, value_name = "UNIT", value_parser = crate::args::parse_rate_unit)]
    pub rate_unit: Option<RateUnit>,
    /// Unit of the outputs when the column name does not carry it: v, mv, lsb, dps, rad_s.
    #[arg(long, value_name = "UNIT", value_parser = crate::args::parse_output_unit)]
    pub output_unit: Option<OutputUnit>,
}

/// Parses a `--triad AXIS=FILE` value.
fn parse_triad_file(s: &str) -> Result<(TableAxis, PathBuf), String> {
    let (a, f) = s.split_once('=').ok_or_else(|| format!("'{s}': expected AXIS=FILE, such as x=turn_x.csv"))?;
    let axis = TableAxis::parse(a).ok_or_else(|| format!("'{a}' is not a table axis: expected x, y or z"))?;
    if f.trim().is_empty() {
        return Err(format!("'{s}': no file after '='"));
    }
    Ok((axis, PathBuf::from(f)))
}

impl RateArgs {
    fn segmentation(&self) -> SegmentationRequest {
        SegmentationRequest {
            table_rate_column: self.table_rate_column.clone(),
            steady_tolerance_dps: self.steady_tolerance_dps,
            min_plateau_s: self.min_plateau_s,
            settling_s: self.settling_s,
            rest_tolerance_dps: self.rest_tolerance_dps,
            manual_segments: self.segments.clone(),
        }
    }

    fn request(&self) -> RateRequest {
        RateRequest {
            files: self.files.clone(),
            raw: self.raw,
            columns: RateColumns {
                rate: self.rate_column.clone(),
                run: self.run_column.clone(),
                stroke: self.stroke_column.clone(),
                output: self.output_column.clone(),
                rate_unit: self.rate_unit,
                output_unit: self.output_unit,
            },
            segmentation: self.segmentation(),
            axis_names: self.axes.clone(),
            settings: RateSettings {
                coverage: self.coverage,
                half_hysteresis: self.half_hysteresis,
                order: self.order as i64,
                nonlinearity_limit_pct: self.nonlinearity_limit,
            },
            segments_out: self.segments_out.is_some(),
        }
    }
}

fn cal_toml(file: &gyrolab_io::calibration::CalibrationFile) -> CliResult<String> {
    file.to_toml().map_err(|e| CliError::Output(format!("cannot serialise the calibration: {e}")))
}

/// Runs `gyrolab rate`.
pub fn run(args: &RateArgs) -> CliResult {
    if !args.triad.is_empty() {
        return run_triad(args);
    }
    let outcome = evaluate_rates(&args.request())?;
    // The segments and the calibration written together (all or none), never over a record.
    let mut files = Vec::new();
    if let (Some(out), Some(log)) = (&args.segments_out, outcome.logs.first()) {
        files.push(OutputFile::bytes(out, log.segments_csv().into_bytes()));
    }
    if let Some(cal) = &args.cal_out {
        files.push(OutputFile::bytes(cal, cal_toml(&calibration_file(&outcome.axes))?.into_bytes()));
    }
    if !files.is_empty() {
        let inputs: Vec<&Path> = args.files.iter().map(PathBuf::as_path).collect();
        write_outputs(files, &inputs).map_err(output_error)?;
    }
    let reports: Vec<AxisReport<'_>> = outcome.axes.iter().map(EvaluatedAxis::report).collect();
    let seg_reports: Vec<SegmentationReport<'_>> = outcome.logs.iter().map(|l| l.report()).collect();
    if args.json {
        let mut doc = rate_json(&reports);
        doc.segmentation = seg_reports.iter().map(SegmentationJson::new).collect();
        return print(&to_json(&doc)?);
    }
    print(&rate_text(&reports, &seg_reports, args.points, args.segments_out.as_deref(), args.cal_out.as_deref()))
}

/// Runs the three-axis mode of `gyrolab rate`.
fn run_triad(args: &RateArgs) -> CliResult {
    if !args.files.is_empty() {
        return Err(gyrolab_eval::EvalError::conflict(format!(
            "{} is given as a positional file with --triad: give every log of the set as --triad AXIS=FILE",
            args.files[0].display()
        ))
        .into());
    }
    let request = TriadRequest {
        files: args.triad.clone(),
        gyro_columns: args.gyro_columns.clone(),
        segmentation: args.segmentation(),
    };
    let t = evaluate_triad(&request)?;
    if let Some(cal) = &args.cal_out {
        let inputs: Vec<&Path> = args.triad.iter().map(|(_, f)| f.as_path()).collect();
        write_file(cal, cal_toml(&t.calibration_file())?.as_bytes(), &inputs)?;
    }
    let report = t.report();
    if args.json {
        return print(&to_json(&triad_json(&report))?);
    }
    print(&triad_text(&report, args.cal_out.as_deref()))
}
