//! `gyrolab rate FILE...`: evaluate rate-table records, one axis per file.

use crate::error::{CliError, CliResult};
use crate::output::{print, to_json, write_file};
use clap::Args;
use gyrolab::rate_test::{evaluate, RateEvaluation, RateTestOptions};
use gyrolab::units::{OutputUnit, RateUnit};
use gyrolab_io::calibration::{AxisCalibration, CalibrationFile, PolynomialModel, CALIBRATION_FORMAT};
use gyrolab_io::rate_table::{read_rate_table, RateColumns, RateLayout, RateTableFile};
use gyrolab_report::rate::{rate_json, rate_points_table, rate_summary_table, AxisReport};
use std::path::PathBuf;

/// Options of `gyrolab rate`.
#[derive(Debug, Args)]
pub struct RateArgs {
    /// Rate-table records, one axis per file (long layout: rate_dps,run,stroke,output_v; or the
    /// wide layout of the paper's Table 1).
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
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
    if !args.axes.is_empty() && args.axes.len() != args.files.len() {
        return Err(CliError::Usage(format!(
            "--axis given {} time(s) for {} file(s): give one name per file, in order",
            args.axes.len(),
            args.files.len()
        )));
    }
    let options = args.options()?;
    let columns = RateColumns {
        rate: args.rate_column.clone(),
        run: args.run_column.clone(),
        stroke: args.stroke_column.clone(),
        output: args.output_column.clone(),
        rate_unit: args.rate_unit,
        output_unit: args.output_unit,
    };
    let mut axes = Vec::new();
    for (i, path) in args.files.iter().enumerate() {
        let record = read_rate_table(path, &columns)?;
        let name = args.axes.get(i).cloned().unwrap_or_else(|| {
            path.file_stem().map_or_else(|| format!("axis{}", i + 1), |s| s.to_string_lossy().into_owned())
        });
        if axes.iter().any(|a: &EvaluatedAxis| a.name == name) {
            return Err(CliError::Usage(format!("two files give axis name '{name}': name them with --axis")));
        }
        axes.push(evaluate_record(name, path.display().to_string(), record, &options)?);
    }
    if let Some(cal) = &args.cal_out {
        let text = calibration_file(&axes)
            .to_toml()
            .map_err(|e| CliError::Output(format!("cannot serialise the calibration: {e}")))?;
        write_file(cal, text.as_bytes())?;
    }
    let reports: Vec<AxisReport<'_>> = axes.iter().map(EvaluatedAxis::report).collect();
    if args.json {
        return print(&to_json(&rate_json(&reports))?);
    }
    let mut text = rate_summary_table(&reports);
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
