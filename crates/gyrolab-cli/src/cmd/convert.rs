//! `gyrolab convert FILE --out imu.csv`: the IMU topics of a recording written as CSV or
//! Parquet, with units in the column names, for other tools.

use crate::error::CliResult;
use crate::progress::Bar;
use clap::Args;
use std::path::PathBuf;

/// Options of `gyrolab convert`.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// A recording: ROS 2 MCAP, ROS 1 bag or PX4 ULog.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Output file, `.csv` or `.parquet`; with several topics one file per topic
    /// (`imu_<topic>.csv`). Written whole or not at all.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Topic to convert (default: every IMU topic), repeatable.
    #[arg(long = "topic", value_name = "NAME")]
    pub topics: Vec<String>,
    /// Keep the messages from this many seconds after each topic's first message.
    #[arg(long, value_name = "SECONDS")]
    pub start: Option<f64>,
    /// Keep the messages up to (not including) this many seconds after each topic's first
    /// message.
    #[arg(long, value_name = "SECONDS")]
    pub end: Option<f64>,
}

/// Runs `gyrolab convert`.
pub fn run(args: &ConvertArgs) -> CliResult {
    let spinner = Bar::spinner(format!("converting {}", args.file.display()));
    let converted = gyrolab_eval::recording::convert(&args.file, &args.topics, &args.out, (args.start, args.end));
    spinner.finish();
    let converted = converted?;
    if let Some(w) = &converted.truncated {
        eprintln!("warning: {w}");
    }
    for (topic, path, messages) in &converted.files {
        eprintln!("wrote {} ({topic}, {messages} messages)", path.display());
    }
    Ok(())
}
