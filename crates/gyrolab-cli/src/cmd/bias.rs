//! `gyrolab bias FILE...`: static tests, one file per test (for example one per power-up), one
//! result per output channel, and the bias repeatability across the files.

use crate::args::RecordArgs;
use crate::error::CliResult;
use crate::output::{print, to_json};
use clap::Args;
use gyrolab::units::OutputUnit;
use gyrolab_eval::simulate::reference_from_headers;
use gyrolab_eval::static_test::{evaluate_static_tests, StaticTestRequest};
use gyrolab_report::bias::{bias_json, bias_table, figure_notes, warning_lines};
use std::path::PathBuf;

/// Options of `gyrolab bias`.
#[derive(Debug, Args)]
pub struct BiasArgs {
    /// Static records, one file per test: a time column `time_s` (or --sample-rate-hz), output
    /// columns with unit suffixes (`output_v`, `rate_dps`, ...), optional `temp_c`. Also, by
    /// content: Parquet tables, and recordings (ROS 2 MCAP, ROS 1 bags, PX4 ULog): every IMU
    /// topic, one test per topic.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    #[command(flatten)]
    pub record: RecordArgs,
    /// Unit of the --column outputs when their names carry no suffix: v, mv, lsb, dps, rad_s.
    #[arg(long, value_name = "UNIT", value_parser = crate::args::parse_output_unit, requires = "columns")]
    pub output_unit: Option<OutputUnit>,
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
    /// Also evaluate the warm-up (records that start at power-on): turn-on bias, the time the
    /// bias takes to stay within +-BAND deg/h of its final value, an exponential settling model.
    #[arg(long, value_name = "BAND")]
    pub warmup_band_dph: Option<f64>,
    /// Window of the warm-up's window means, s (default 10).
    #[arg(long, value_name = "S", requires = "warmup_band_dph")]
    pub warmup_window_s: Option<f64>,
    /// Evaluate each record from this many seconds after its first sample (each topic of a
    /// recording from its own first sample).
    #[arg(long, value_name = "SECONDS")]
    pub start: Option<f64>,
    /// Evaluate each record up to (not including) this many seconds after its first sample.
    #[arg(long, value_name = "SECONDS")]
    pub end: Option<f64>,
}

/// Runs `gyrolab bias`.
pub fn run(args: &BiasArgs) -> CliResult {
    let mut request = StaticTestRequest {
        files: args.files.clone(),
        columns: args.record.columns.clone(),
        output_unit: args.output_unit,
        sample_rate_hz: args.record.sample_rate_hz,
        reference: args.record.reference.request(),
        latitude_deg: args.latitude,
        smoothing_s: args.smoothing.clone(),
        temperature_quadratic: args.temp_quadratic,
        drop_outliers: args.drop_outliers,
        tolerant: args.tolerant,
        layout: args.record.layout.layout(),
        topics: args.record.topics.clone(),
        warmup: args.warmup_band_dph.map(|b| gyrolab::warmup::WarmupConfig {
            window_s: args.warmup_window_s.unwrap_or(10.0),
            ..gyrolab::warmup::WarmupConfig::new(b)
        }),
        window_s: (args.start, args.end),
    };
    if let Some((reference, stated)) = reference_from_headers(&args.files, &request.reference) {
        let shown = if args.files.len() == 1 { args.files[0].display().to_string() } else { "every file".into() };
        eprintln!("note: {}", crate::args::stated_reference_note(&shown, &stated));
        request.reference = reference;
    }
    let outcome = evaluate_static_tests(&request)?;
    for (file, note) in &outcome.notes {
        eprintln!("note: {file}: {}", note.render(&crate::error::flag));
    }
    let tests = outcome.tests;
    for line in warning_lines(&outcome.files, &tests) {
        eprintln!("{line}");
    }
    if args.json {
        return print(&to_json(&bias_json(tests, outcome.repeatability, &outcome.warmup))?);
    }
    let mut text = crate::output::simulated_lines(&args.files);
    text.push_str(&bias_table(&tests, &outcome.repeatability));
    text.push('\n');
    text.push_str(&gyrolab_report::bias::warmup_text(&outcome.warmup));
    text.push_str(&figure_notes(&tests, args.latitude.is_some(), !outcome.reference.is_none()));
    print(&text)
}
