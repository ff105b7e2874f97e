//! `gyrolab bias FILE...`: static (bias) tests, one file per test (a power-up or a temperature
//! point), one result per output channel.

use crate::cmd::rate::parse_output_unit;
use crate::error::{CliError, CliResult};
use crate::output::{print, to_json};
use crate::reference::{Reference, ReferenceArgs};
use clap::Args;
use gyrolab::static_test::{bias_repeatability, StaticTestConfig};
use gyrolab::units::OutputUnit;
use gyrolab_io::series::{evaluate_static_file, SeriesOptions};
use gyrolab_report::bias::{bias_json, bias_table, quality_lines, ChannelRepeatability, TestReport};
use std::path::PathBuf;

/// Options of `gyrolab bias`.
#[derive(Debug, Args)]
pub struct BiasArgs {
    /// Static records, one file per test: a time column `time_s` (or --sample-rate-hz), output
    /// columns with unit suffixes (`output_v`, `rate_dps`, ...), optional `temp_c`.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Output columns to evaluate (default: every output column), repeatable.
    #[arg(long = "column", value_name = "NAME")]
    pub columns: Vec<String>,
    /// Unit of the --column outputs when their names carry no suffix: v, mv, lsb, dps, rad_s.
    #[arg(long, value_name = "UNIT", value_parser = parse_output_unit, requires = "columns")]
    pub output_unit: Option<OutputUnit>,
    /// Sample rate in Hz (required when the file has no time column).
    #[arg(long, value_name = "HZ")]
    pub sample_rate_hz: Option<f64>,
    #[command(flatten)]
    pub reference: ReferenceArgs,
    /// Latitude in degrees (input axis vertical, up): subtract the earth rate from the bias.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub latitude: Option<f64>,
    /// Smoothing times in seconds for the bias stability (default 1,10,100, plus one sample).
    #[arg(long, value_name = "S,...", value_delimiter = ',')]
    pub smoothing: Vec<f64>,
    /// Fit a quadratic bias-temperature model as well as the linear one.
    #[arg(long)]
    pub temp_quadratic: bool,
    /// Remove outliers (beyond 6 sigma of the drift line) before computing the figures.
    #[arg(long)]
    pub drop_outliers: bool,
    /// Accept NaN and empty cells (reported with their lines, excluded) instead of stopping.
    #[arg(long)]
    pub tolerant: bool,
    /// Print every figure as JSON (keys in docs/JSON.md).
    #[arg(long)]
    pub json: bool,
}

/// Runs `gyrolab bias`.
pub fn run(args: &BiasArgs) -> CliResult {
    if let Some(f) = args.sample_rate_hz {
        if !(f.is_finite() && f > 0.0) {
            return Err(CliError::Usage(format!("--sample-rate-hz must be a positive number, got {f}")));
        }
    }
    if let Some(l) = args.latitude {
        if !(-90.0..=90.0).contains(&l) {
            return Err(CliError::Usage(format!("--latitude must be within -90..90 degrees, got {l}")));
        }
    }
    if let Some(t) = args.smoothing.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        return Err(CliError::Usage(format!("--smoothing times must be positive seconds, got {t}")));
    }
    let reference = Reference::from_args(&args.reference)?;
    let options = SeriesOptions {
        sample_rate_hz: args.sample_rate_hz,
        channels: if args.columns.is_empty() { None } else { Some(args.columns.clone()) },
        column_units: args
            .output_unit
            .map(|u| args.columns.iter().map(|c| (c.clone(), u)).collect())
            .unwrap_or_default(),
        tolerant: args.tolerant,
        ..SeriesOptions::default()
    };
    let mut tests: Vec<TestReport> = Vec::new();
    for path in &args.files {
        let mut mismatch = None;
        let (results, summary) = evaluate_static_file(path, &options, |ch| {
            let mut cfg = StaticTestConfig {
                latitude_deg: args.latitude,
                temperature_quadratic: args.temp_quadratic,
                drop_outliers: args.drop_outliers,
                ..StaticTestConfig::default()
            };
            if !args.smoothing.is_empty() {
                cfg.smoothing_times_s = args.smoothing.clone();
            }
            if let Err(m) = reference.configure(&mut cfg, &ch.name, ch.unit) {
                mismatch = Some(m);
            }
            cfg
        })?;
        if let Some(m) = mismatch {
            return Err(CliError::Usage(format!("{}: {m}", path.display())));
        }
        if summary.quality.missing_cells > 0 {
            if let Some(c) = summary.quality.first_missing.first() {
                eprintln!(
                    "warning: {}:{}:{}: {} missing cell(s) (NaN or empty) excluded, first in column '{}'",
                    path.display(),
                    c.line,
                    c.column,
                    summary.quality.missing_cells,
                    c.name
                );
            }
        }
        for result in results {
            tests.push(TestReport { file: path.display().to_string(), result });
        }
    }
    for t in &tests {
        for line in quality_lines(t) {
            eprintln!("warning: {} ({}): {line}", t.file, t.result.channel);
        }
        for note in &t.result.notes {
            eprintln!("note: {} ({}): {note}", t.file, t.result.channel);
        }
    }
    let mut channels: Vec<String> = Vec::new();
    for t in &tests {
        if !channels.contains(&t.result.channel) {
            channels.push(t.result.channel.clone());
        }
    }
    let mut repeatability = Vec::new();
    for ch in channels {
        let of: Vec<_> = tests.iter().filter(|t| t.result.channel == ch).map(|t| t.result.clone()).collect();
        if of.len() >= 2 {
            if let Ok(r) = bias_repeatability(&of) {
                repeatability.push(ChannelRepeatability { channel: ch, repeatability: r });
            }
        }
    }
    if args.json {
        return print(&to_json(&bias_json(tests, repeatability))?);
    }
    let mut text = bias_table(&tests, &repeatability);
    text.push('\n');
    if tests.iter().any(|t| t.result.earth_rate_subtracted) {
        text.push_str("The earth-rate component for a vertical input axis was subtracted from the bias.\n");
    } else if args.latitude.is_none() && tests.iter().any(|t| t.result.bias_dph.is_some()) {
        text.push_str(
            "No latitude given: the bias includes the earth-rate component (give --latitude to remove it).\n",
        );
    }
    if reference.is_none() && tests.iter().any(|t| t.result.bias_dps.is_none()) {
        text.push_str("No scale factor given (--cal or --scale-factor): figures are in output units only.\n");
    }
    print(&text)
}
