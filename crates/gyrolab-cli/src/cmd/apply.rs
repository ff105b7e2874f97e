//! `gyrolab apply --cal FILE.toml IN.csv`: outputs to calibrated rates, streaming.

use crate::error::{CliError, CliResult};
use clap::Args;
use gyrolab_eval::apply::{apply_into, apply_to, prepare_apply, stage_input, summary_lines, ApplyRequest};
use gyrolab_io::apply_csv::StreamError;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

/// Options of `gyrolab apply`.
#[derive(Debug, Args)]
pub struct ApplyArgs {
    /// Calibration file (written by `gyrolab rate --cal-out`).
    #[arg(long, value_name = "FILE.toml")]
    pub cal: PathBuf,
    /// Time series of outputs (time_s and output columns such as gyro_v; CSV, TSV, ...), or by
    /// content a Parquet table or a recording (ROS 2 MCAP, ROS 1 bag, PX4 ULog: one IMU topic).
    #[arg(value_name = "IN.csv")]
    pub input: PathBuf,
    /// Write the calibrated rates to this file (atomically) instead of standard output.
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Apply this [[axis]] of the calibration (default: the [triad] when there is one, else the only axis).
    #[arg(long, value_name = "NAME")]
    pub cal_axis: Option<String>,
    /// Output column(s) to calibrate: one for an axis, three (x, y, z) for a [triad]
    /// (default: the file's only output, or the columns named after the axes).
    #[arg(long = "column", value_name = "NAME", value_delimiter = ',')]
    pub columns: Vec<String>,
    /// The IMU topic of a recording (MCAP, ROS 1 bag, PX4 ULog) to calibrate, when it has
    /// several; its channels are `gyro_x_rad_s` ... (`--column` picks them).
    #[arg(long, value_name = "NAME")]
    pub topic: Option<String>,
}

/// Runs `gyrolab apply`.
pub fn run(args: &ApplyArgs) -> CliResult {
    // Recordings and Parquet tables are staged as CSV (one IMU topic) for the streaming path.
    let staged = stage_input(&args.input, args.topic.as_deref())?;
    if let Some(n) = &staged.note {
        eprintln!("note: read {n}");
    }
    let input = staged.path.clone();
    let plan = prepare_apply(&ApplyRequest {
        calibration: args.cal.clone(),
        input: input.clone(),
        calibration_axis: args.cal_axis.clone(),
        columns: args.columns.clone(),
    })?;
    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new_spinner();
        b.set_message("applying the calibration");
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut progress = |rows: u64| bar.set_message(format!("{rows} rows"));
    let summary = match &args.out {
        Some(path) => {
            // Never over the record or the calibration file it applies.
            let r = apply_into(&input, &plan, path, &[args.input.as_path(), args.cal.as_path()], &mut progress);
            bar.finish_and_clear();
            r?
        }
        None => {
            let stdout = std::io::stdout();
            let mut w = std::io::BufWriter::with_capacity(1 << 20, stdout.lock());
            let r = apply_to(&input, &plan, &mut w, &mut progress).and_then(|s| {
                w.flush().map_err(StreamError::Write)?;
                Ok(s)
            });
            bar.finish_and_clear();
            match r {
                Ok(s) => s,
                Err(StreamError::Data(d)) => return Err(d.into()),
                Err(StreamError::Write(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
                Err(StreamError::Write(e)) => {
                    return Err(CliError::Output(format!("cannot write to standard output: {e}")))
                }
            }
        }
    };
    for line in summary_lines(&summary, args.out.as_deref()) {
        eprintln!("{line}");
    }
    Ok(())
}
