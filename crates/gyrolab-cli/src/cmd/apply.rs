//! `gyrolab apply --cal FILE.toml IN.csv`: outputs to calibrated rates, streaming.

use crate::error::{CliError, CliResult};
use clap::Args;
use gyrolab::apply::{SingleAxisCalibration, TriadApplier};
use gyrolab::units::split_unit_suffix;
use gyrolab_io::apply_csv::{apply_file, ApplyModel, ApplyPlan, ApplySummary, StreamError};
use gyrolab_io::calibration::read_calibration;
use gyrolab_io::raw_log::{detect_raw_log, header_names};
use gyrolab_io::DataError;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

/// Options of `gyrolab apply`.
#[derive(Debug, Args)]
pub struct ApplyArgs {
    /// Calibration file (written by `gyrolab rate --cal-out`).
    #[arg(long, value_name = "FILE.toml")]
    pub cal: PathBuf,
    /// Time series of outputs (time_s and output columns such as gyro_v; CSV, TSV, ...).
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
}

/// Chooses the output columns: given, the file's only ones, or those whose base name is an axis name.
fn choose_columns(input: &Path, given: &[String], axis_names: &[String], skip: &[String]) -> CliResult<Vec<String>> {
    let n = axis_names.len();
    if !given.is_empty() {
        if given.len() != n {
            return Err(CliError::Usage(format!(
                "--column needs {n} name(s) for this calibration, got {}",
                given.len()
            )));
        }
        return Ok(given.to_vec());
    }
    let names = header_names(input)?;
    let outputs: Vec<&String> = names
        .iter()
        .filter(|c| {
            let (base, sfx) = split_unit_suffix(c);
            let special = matches!(base.as_str(), "time" | "t" | "timestamp" | "temp" | "temperature");
            !special && sfx.is_some() && !skip.iter().any(|s| s.eq_ignore_ascii_case(c))
        })
        .collect();
    if outputs.len() == n {
        return Ok(outputs.into_iter().cloned().collect());
    }
    let by_axis: Option<Vec<String>> = axis_names
        .iter()
        .map(|a| outputs.iter().find(|c| split_unit_suffix(c).0.eq_ignore_ascii_case(a)).map(|c| c.to_string()))
        .collect();
    by_axis.ok_or_else(|| {
        CliError::Data(DataError::new(
            input,
            format!(
                "{} output column(s) ({}) where the calibration needs {n} ({}): choose with --column",
                outputs.len(),
                outputs.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", "),
                axis_names.join(", ")
            ),
        ))
    })
}

/// Runs `gyrolab apply`.
pub fn run(args: &ApplyArgs) -> CliResult {
    let cal = read_calibration(&args.cal)?;
    let cal_err = |msg: String| CliError::Data(DataError::new(&args.cal, msg));
    let names = header_names(&args.input)?;
    // A raw log's table rate is passed through (as table_rate_dps), beside the calibrated rate.
    let table_rate = detect_raw_log(&names);
    let skip: Vec<String> = table_rate.iter().cloned().collect();
    let plan = match (&cal.triad, &args.cal_axis) {
        (Some(t), None) => {
            let model = TriadApplier::new(&t.calibration()).map_err(|e| cal_err(format!("[triad]: {e}")))?;
            let axes = t.axes.to_vec();
            ApplyPlan {
                model: ApplyModel::Triad(model),
                output_unit: t.output_unit,
                columns: choose_columns(&args.input, &args.columns, &axes, &skip)?,
                rate_names: axes.iter().map(|a| format!("rate_{a}_dps")).collect(),
                table_rate_column: table_rate,
            }
        }
        (_, name) => {
            let axis = cal.axis(name.as_deref()).map_err(cal_err)?;
            let model =
                SingleAxisCalibration::polynomial(&axis.polynomial.coefficients, axis.rate_min_dps, axis.rate_max_dps)
                    .map_err(|e| cal_err(format!("axis '{}': {e}", axis.name)))?;
            ApplyPlan {
                model: ApplyModel::Single(model),
                output_unit: axis.output_unit,
                columns: choose_columns(&args.input, &args.columns, std::slice::from_ref(&axis.name), &skip)?,
                rate_names: vec!["rate_dps".into()],
                table_rate_column: table_rate,
            }
        }
    };
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
            let (mut data_error, mut done) = (None, None);
            let r = gyrolab_io::atomic::write_atomic_with(path, |w| {
                match apply_file(&args.input, &plan, w, &mut progress) {
                    Ok(s) => {
                        done = Some(s);
                        Ok(())
                    }
                    Err(StreamError::Write(e)) => Err(e),
                    Err(StreamError::Data(d)) => {
                        data_error = Some(d);
                        Err(std::io::Error::other("bad input"))
                    }
                }
            });
            bar.finish_and_clear();
            if let Some(d) = data_error {
                return Err(CliError::Data(d));
            }
            r.map_err(|e| CliError::Output(format!("{}: cannot write the file: {e}", path.display())))?;
            done.unwrap_or_default()
        }
        None => {
            let stdout = std::io::stdout();
            let mut w = std::io::BufWriter::with_capacity(1 << 20, stdout.lock());
            let r = apply_file(&args.input, &plan, &mut w, &mut progress).and_then(|s| {
                w.flush().map_err(StreamError::Write)?;
                Ok(s)
            });
            bar.finish_and_clear();
            match r {
                Ok(s) => s,
                Err(StreamError::Data(d)) => return Err(CliError::Data(d)),
                Err(StreamError::Write(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
                Err(StreamError::Write(e)) => {
                    return Err(CliError::Output(format!("cannot write to standard output: {e}")))
                }
            }
        }
    };
    report(&summary, args.out.as_deref());
    Ok(())
}

fn report(s: &ApplySummary, out: Option<&Path>) {
    let flagged = s.below + s.above + s.not_finite;
    if flagged > 0 || out.is_some() {
        let dest = out.map_or_else(String::new, |p| format!(" to {}", p.display()));
        eprintln!(
            "applied the calibration to {} rows{dest}; flagged: {} below, {} above the calibrated range, {} not finite",
            s.rows, s.below, s.above, s.not_finite
        );
    }
}
