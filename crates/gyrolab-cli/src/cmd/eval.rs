//! `gyrolab eval PLAN.toml --out DIR`: evaluate a test plan and write the report folder
//! (report.html, results.json, calibration.toml, CSV tables). Exit code 3 when a limit fails.

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
}

/// Runs `gyrolab eval`.
pub fn run(args: &EvalArgs) -> CliResult {
    let plan = read_test_plan(&args.plan)?;
    let bar = Bar::new(args.quiet);
    let folder = evaluate_test_plan(&plan, &args.plan.display().to_string(), &bar);
    bar.finish();
    write_and_finish(&args.out, &folder?, args.quiet)
}
