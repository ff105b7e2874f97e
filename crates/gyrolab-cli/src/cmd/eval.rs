//! `gyrolab eval PLAN.toml --out DIR`: evaluate a test plan and write the report folder
//! (report.html, results.json, calibration.toml, CSV tables; report.pdf with `--pdf`). Exit code 3
//! when a limit fails, 1 when `--pdf` could not make the PDF.

use crate::error::CliResult;
use crate::folder::write_and_finish;
use crate::progress::Bar;
use clap::Args;
use gyrolab_eval::test_plan::{evaluate_test_plan, read_test_plan};
use std::path::PathBuf;

/// Options of `gyrolab eval`.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// The test plan (TOML; keys in docs/PLAN.md).
    #[arg(value_name = "PLAN.toml")]
    pub plan: PathBuf,
    /// Folder to write report.html, results.json, calibration.toml and the CSV tables into
    /// (created if missing; existing files of the same names are replaced, all or none).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// No progress bar and no summary on standard output (errors still go to stderr).
    #[arg(long, short)]
    pub quiet: bool,
    /// Also print report.html to report.pdf with headless Chromium (/usr/bin/chromium, or
    /// chromium, chromium-browser or google-chrome on PATH, or the path in GYROLAB_CHROMIUM; at
    /// most 120 s). Without a browser, or when printing fails, the other files are still written
    /// and the exit code is 1 with a message saying how to get the PDF.
    #[arg(long)]
    pub pdf: bool,
}

/// Runs `gyrolab eval`.
pub fn run(args: &EvalArgs) -> CliResult {
    let plan = read_test_plan(&args.plan)?;
    let bar = Bar::new(args.quiet);
    let folder = evaluate_test_plan(&plan, &args.plan.display().to_string(), &bar);
    bar.finish();
    write_and_finish(&args.out, &folder?, args.quiet, args.pdf)
}
