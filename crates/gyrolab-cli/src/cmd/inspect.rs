//! `gyrolab inspect FILE`: the topics of a recording (MCAP, ROS 1 bag, PX4 ULog) with their
//! message types, counts, rates, time spans and gaps; a table file's channels.

use crate::error::CliResult;
use crate::output::{print, to_json};
use crate::progress::Bar;
use clap::Args;
use gyrolab_report::inventory::inventory_text;
use std::path::PathBuf;

/// Options of `gyrolab inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// A recording (ROS 2 MCAP, ROS 1 bag, PX4 ULog), a Parquet table or a delimited text file.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `gyrolab inspect`.
pub fn run(args: &InspectArgs) -> CliResult {
    let spinner = Bar::spinner(format!("reading {}", args.file.display()));
    let inventory = gyrolab_eval::recording::inspect(&args.file);
    spinner.finish();
    let inventory = inventory?;
    if args.json {
        return print(&to_json(&inventory)?);
    }
    print(&inventory_text(&inventory))
}
