//! `gyrolab rate FILE...`: evaluate rate-table records, one axis per file.

use crate::cmd::raw;
use crate::error::{CliError, CliResult};
use crate::output::{print, to_json, write_file};
use clap::Args;
use gyrolab::rate_test::{evaluate, RateEvaluation, RateTestOptions};
use gyrolab::units::{OutputUnit, RateUnit};
use gyrolab_io::calibration::TriadSection;
use gyrolab_io::calibration::{AxisCalibration, CalibrationFile, PolynomialModel, CALIBRATION_FORMAT};
use gyrolab_io::rate_table::{read_rate_table, RateColumns, RateLayout, RateTableFile};
use gyrolab_io::raw_log::{detect_raw_log, header_names, segments_csv};
use gyrolab_report::rate::{rate_json, rate_points_table, rate_summary_table, AxisReport};
use gyrolab_report::segments::{segmentation_text, SegmentationJson, SegmentationReport};
use gyrolab_report::triad::{triad_json, triad_text, TriadReport};
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
    #[arg(long, value_name = "AXIS=FILE", value_parser = crate::cmd::raw::parse_triad_file)]
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
    #[arg(long, value_name = "UNIT", value_parser = parse_rate_unit)]
    pub rate_unit: Option<RateUnit>,
    /// Unit of the outputs when the column name does not carry it: v, mv, lsb, dps, rad_s.
    #[arg(long, value_name = "UNIT", value_parser = parse_output_unit)]
    pub output_unit: Option<OutputUnit>,
}

/// Parses a rate unit option.
pub fn parse_rate_unit(s: &str) -> Result<RateUnit, String> {
    RateUnit::parse(s).ok_or_else(|| format!("unknown rate unit '{s}': expected dps, rad_s or dph"))
}

/// Parses an output unit option.
pub fn parse_output_unit(s: &str) -> Result<OutputUnit, String> {
    OutputUnit::parse(s).ok_or_else(|| format!("unknown output unit '{s}': expected v, mv, lsb, dps or rad_s"))
}

impl RateArgs {
    /// The evaluation options these arguments ask for.
    pub fn options(&self) -> CliResult<RateTestOptions> {
        if !(self.coverage.is_finite() && self.coverage > 0.0) {
            return Err(CliError::Usage(format!("--coverage must be a positive number, got {}", self.coverage)));
        }
        if !(1..=9).contains(&self.order) {
            return Err(CliError::Usage(format!("--order must be 1 to 9, got {}", self.order)));
        }
        let limit = match self.nonlinearity_limit {
            Some(p) if p.is_finite() && p > 0.0 => Some(p / 100.0),
            Some(p) => {
                return Err(CliError::Usage(format!("--nonlinearity-limit must be a positive percentage, got {p}")))
            }
            None => None,
        };
        Ok(RateTestOptions {
            coverage: self.coverage,
            half_hysteresis: self.half_hysteresis,
            order: self.order,
            nonlinearity_limit: limit,
        })
    }
}

/// One evaluated file.
pub struct EvaluatedAxis {
    /// Axis name.
    pub name: String,
    /// Source path as given.
    pub file: String,
    /// What was read.
    pub record: RateTableFile,
    /// The figures.
    pub evaluation: RateEvaluation,
}

impl EvaluatedAxis {
    /// The report view of this axis.
    pub fn report(&self) -> AxisReport<'_> {
        AxisReport {
            name: self.name.clone(),
            file: self.file.clone(),
            layout: match self.record.layout {
                RateLayout::Long => "long".into(),
                RateLayout::Wide => "wide".into(),
                RateLayout::Raw => "raw".into(),
            },
            output_unit: self.record.output_unit,
            samples: self.record.samples,
            evaluation: &self.evaluation,
        }
    }

    /// The calibration entry of this axis.
    pub fn calibration(&self) -> AxisCalibration {
        let e = &self.evaluation;
        let rates = &self.record.table.rates_dps;
        AxisCalibration {
            name: self.name.clone(),
            source_file: self.file.clone(),
            output_unit: self.record.output_unit,
            scale_factor: e.scale_factor(),
            zero_offset: e.zero_offset(),
            rest_reference: e.rest_reference,
            rate_min_dps: rates.first().copied().unwrap_or(0.0),
            rate_max_dps: rates.last().copied().unwrap_or(0.0),
            polynomial: PolynomialModel {
                order: e.polynomial.order(),
                coefficients: e.polynomial.coefficients.clone(),
            },
        }
    }
}

/// Evaluates an already read record.
pub fn evaluate_record(
    name: String,
    file: String,
    record: RateTableFile,
    options: &RateTestOptions,
) -> CliResult<EvaluatedAxis> {
    let evaluation = evaluate(&record.table, options)
        .map_err(|e| CliError::Data(gyrolab_io::DataError::new(&file, format!("cannot evaluate: {e}"))))?;
    Ok(EvaluatedAxis { name, file, record, evaluation })
}

/// Builds a calibration file from evaluated axes.
pub fn calibration_file(axes: &[EvaluatedAxis]) -> CalibrationFile {
    CalibrationFile {
        format: CALIBRATION_FORMAT.into(),
        generator: format!("gyrolab {}", env!("CARGO_PKG_VERSION")),
        created: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        axes: axes.iter().map(EvaluatedAxis::calibration).collect(),
        triad: None,
    }
}

/// Runs `gyrolab rate`.
pub fn run(args: &RateArgs) -> CliResult {
    let seg_options = raw::segment_options(args)?;
    if !args.triad.is_empty() {
        return run_triad(args, &seg_options);
    }
    let options = args.options()?;
    let mut is_raw = Vec::with_capacity(args.files.len());
    for path in &args.files {
        is_raw.push(args.raw || detect_raw_log(&header_names(path)?).is_some());
    }
    let raw_count = is_raw.iter().filter(|r| **r).count();
    if (args.segments_out.is_some() || args.segments.is_some()) && raw_count != 1 {
        return Err(CliError::Usage(format!(
            "--segments and --segments-out take exactly one raw log, but {raw_count} of the files are raw logs"
        )));
    }
    let columns = RateColumns {
        rate: args.rate_column.clone(),
        run: args.run_column.clone(),
        stroke: args.stroke_column.clone(),
        output: args.output_column.clone(),
        rate_unit: args.rate_unit,
        output_unit: args.output_unit,
    };
    let mut axes: Vec<EvaluatedAxis> = Vec::new();
    let mut logs: Vec<raw::SegmentedLog> = Vec::new();
    let mut names = args.axes.iter().cloned();
    for (i, path) in args.files.iter().enumerate() {
        let start = axes.len();
        if is_raw[i] {
            let log = raw::segment_file(path, args, &seg_options, args.segments.as_ref())?;
            if let Some(out) = &args.segments_out {
                write_file(out, segments_csv(&log.segments, &log.log.lines).as_bytes())?;
            }
            axes.extend(raw::evaluate_channels(&log, &options, &seg_options, &mut || names.next())?);
            logs.push(log);
        } else {
            let record = read_rate_table(path, &columns)?;
            let name = names.next().unwrap_or_else(|| {
                path.file_stem().map_or_else(|| format!("axis{}", i + 1), |s| s.to_string_lossy().into_owned())
            });
            axes.push(evaluate_record(name, path.display().to_string(), record, &options)?);
        }
        for a in &axes[start..] {
            if axes.iter().filter(|b| b.name == a.name).count() > 1 {
                return Err(CliError::Usage(format!(
                    "two axes are named '{}': name them with --axis (one per file, or per output column of a raw log)",
                    a.name
                )));
            }
        }
    }
    if !args.axes.is_empty() && args.axes.len() != axes.len() {
        return Err(CliError::Usage(format!(
            "--axis given {} time(s) for {} axes: give one name per file (per output column of a raw log), in order",
            args.axes.len(),
            axes.len()
        )));
    }
    if let Some(cal) = &args.cal_out {
        let text = calibration_file(&axes)
            .to_toml()
            .map_err(|e| CliError::Output(format!("cannot serialise the calibration: {e}")))?;
        write_file(cal, text.as_bytes())?;
    }
    let reports: Vec<AxisReport<'_>> = axes.iter().map(EvaluatedAxis::report).collect();
    let seg_reports: Vec<SegmentationReport<'_>> = logs
        .iter()
        .map(|l| SegmentationReport {
            file: l.log.file.display().to_string(),
            mode: l.mode,
            samples: l.log.time_s.len(),
            segments: &l.segments,
            lines: &l.log.lines,
        })
        .collect();
    if args.json {
        let mut doc = rate_json(&reports);
        doc.segmentation = seg_reports.iter().map(SegmentationJson::new).collect();
        return print(&to_json(&doc)?);
    }
    let mut text = String::new();
    for r in &seg_reports {
        text.push_str(&segmentation_text(r));
        text.push('\n');
    }
    if let Some(out) = &args.segments_out {
        text.push_str(&format!("Segments written to {}\n\n", out.display()));
    }
    text.push_str(&rate_summary_table(&reports));
    text.push('\n');
    if args.points {
        for r in &reports {
            text.push_str(&format!("\nAxis {} ({}): per-point means and residuals\n", r.name, r.file));
            text.push_str(&rate_points_table(r));
            text.push('\n');
        }
    }
    if let Some(cal) = &args.cal_out {
        text.push_str(&format!("\nCalibration written to {}\n", cal.display()));
    }
    print(&text)
}

/// Runs the three-axis mode of `gyrolab rate`.
fn run_triad(args: &RateArgs, seg_options: &gyrolab::segment::SegmentOptions) -> CliResult {
    if !args.files.is_empty() {
        return Err(CliError::Usage(format!(
            "{} is given as a positional file with --triad: give every log of the set as --triad AXIS=FILE",
            args.files[0].display()
        )));
    }
    let t = raw::triad(args, seg_options)?;
    if let Some(cal) = &args.cal_out {
        let mut file = calibration_file(&[]);
        file.triad = Some(TriadSection::from_calibration(
            &t.fit.calibration,
            ["x".into(), "y".into(), "z".into()],
            t.files.iter().map(|(_, f)| f.clone()).collect(),
            t.output_unit,
        ));
        let text = file.to_toml().map_err(|e| CliError::Output(format!("cannot serialise the calibration: {e}")))?;
        write_file(cal, text.as_bytes())?;
    }
    let report = TriadReport {
        files: t.files.clone(),
        gyro_columns: t.gyro_columns.clone(),
        output_unit: t.output_unit,
        fit: &t.fit,
    };
    if args.json {
        return print(&to_json(&triad_json(&report))?);
    }
    let mut text = triad_text(&report);
    if let Some(cal) = &args.cal_out {
        text.push_str(&format!("\nCalibration ([triad]) written to {}\n", cal.display()));
    }
    print(&text)
}
