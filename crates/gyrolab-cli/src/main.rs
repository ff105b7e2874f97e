//! The `gyrolab` command-line program: parses arguments into requests, calls `gyrolab-eval` and
//! the lab layer `gyrolab-lab`, prints what `gyrolab-report` renders, and sets the exit code. No
//! domain logic lives here.
//!
//! Layout: `cmd/` one module per subcommand (none imports another); [`args`] argument types
//! shared by several commands; [`error`] exit codes and the flag of each request field;
//! [`output`] standard output and atomic files; [`folder`] report folders; [`progress`] the
//! terminal progress bar.

mod args;
mod cmd;
mod error;
mod folder;
mod output;
mod progress;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// gyrolab: gyroscope test evaluation (rate-table calibration, bias, Allan variance).
#[derive(Debug, Parser)]
#[command(name = "gyrolab", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Evaluate rate-table records: scale factor, nonlinearity, linearity, hysteresis, repeatability...
    Rate(Box<cmd::rate::RateArgs>),
    /// Evaluate static (bias) tests: bias, bias stability, repeatability, drift, temperature.
    Bias(Box<cmd::bias::BiasArgs>),
    /// Allan-variance family with confidence intervals and noise terms (N, B, K, Kalibr YAML).
    Allan(Box<cmd::allan::AllanArgs>),
    /// Apply a calibration to a time series of outputs, streaming: outputs in, rates out.
    Apply(Box<cmd::apply::ApplyArgs>),
    /// List the topics of a recording (MCAP, ROS 1 bag, PX4 ULog): types, counts, rates, gaps.
    Inspect(cmd::inspect::InspectArgs),
    /// Write the IMU topics of a recording as CSV or Parquet, units in the column names.
    Convert(cmd::convert::ConvertArgs),
    /// Plan a test: the record length needed to measure a noise term to a stated precision.
    #[command(subcommand)]
    Plan(cmd::record_length::PlanCommand),
    /// Simulate records with known truth (static, rate-table) in the layouts gyrolab reads.
    #[command(subcommand)]
    Simulate(cmd::simulate::SimulateCommand),
    /// Evaluate a test plan and write the report folder (report.html, results.json, calibration, CSV).
    Eval(cmd::eval::EvalArgs),
    /// Allan analysis of many records on every core, resumable, one results table (CSV, Parquet).
    Batch(Box<cmd::batch::BatchArgs>),
    /// Run the paper's worked example on its data (built in) and compare with its printed tables.
    Demo(cmd::demo::DemoArgs),
    /// The records store: add report folders; history, lot statistics, comparison, control charts, revisions.
    #[command(subcommand)]
    Store(cmd::store::StoreCommand),
    /// Check a report folder's plan and inputs against the SHA-256 recorded when it was made.
    Verify(cmd::verify::VerifyArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Ctrl-C: remove the temporary files of outputs being written (the outputs they were to
    // replace stay as they were), then stop with the usual 130.
    let _ = ctrlc::set_handler(|| {
        gyrolab_io::atomic::remove_temporaries();
        gyrolab_report::pdf::remove_temporaries();
        std::process::exit(130);
    });
    let result = match &cli.command {
        Command::Rate(a) => cmd::rate::run(a),
        Command::Eval(a) => cmd::eval::run(a),
        Command::Demo(a) => cmd::demo::run(a),
        Command::Batch(a) => cmd::batch::run(a),
        Command::Bias(a) => cmd::bias::run(a),
        Command::Allan(a) => cmd::allan::run(a),
        Command::Apply(a) => cmd::apply::run(a),
        Command::Inspect(a) => cmd::inspect::run(a),
        Command::Convert(a) => cmd::convert::run(a),
        Command::Simulate(c) => cmd::simulate::run(c),
        Command::Plan(c) => cmd::record_length::run(c),
        Command::Store(c) => cmd::store::run(c),
        Command::Verify(a) => cmd::verify::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e @ (error::CliError::LimitFailed(_) | error::CliError::Changed(_))) => {
            eprintln!("FAIL: {e}");
            e.exit_code()
        }
        Err(e @ (error::CliError::Incomplete(_) | error::CliError::Conditional(_))) => {
            eprintln!("{e}");
            e.exit_code()
        }
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}
