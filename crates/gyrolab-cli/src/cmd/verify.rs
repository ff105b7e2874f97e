//! `gyrolab verify DIR`: recomputes the SHA-256 of a report folder's plan and inputs and names
//! every file that changed or is missing (exit 3), else exit 0.

use crate::error::{CliError, CliResult};
use crate::output::print;
use clap::Args;
use gyrolab_eval::verify::{verify_folder, FileState};
use std::path::PathBuf;

/// Options of `gyrolab verify`.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// A report folder written by `gyrolab eval` (its results.json holds the integrity record).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The folder the plan's relative input paths start from (default: the folder of the plan
    /// named in results.json, as given to `gyrolab eval` from the current folder).
    #[arg(long, value_name = "DIR")]
    pub plan_dir: Option<PathBuf>,
}

/// Runs `gyrolab verify`.
pub fn run(args: &VerifyArgs) -> CliResult {
    let v = verify_folder(&args.dir, args.plan_dir.as_deref())?;
    let mut s = format!("Report {} ({}):\n", v.report_number, args.dir.display());
    let mut bad = Vec::new();
    for c in &v.checks {
        let (word, detail) = match &c.state {
            FileState::Unchanged => ("unchanged", String::new()),
            FileState::Changed { sha256, size_bytes } => {
                ("CHANGED", format!(" (SHA-256 now {sha256}, {size_bytes} bytes; recorded {})", c.recorded_sha256))
            }
            FileState::Missing { reason } => ("MISSING", format!(" ({reason})")),
        };
        let line = format!("{word:<9} {:<9} {}{detail}", c.role.word(), c.path.display());
        if c.state != FileState::Unchanged {
            bad.push(format!("{} {}", c.role.word(), c.path.display()));
        }
        s.push_str(&format!("  {line}\n"));
    }
    print(&s)?;
    if bad.is_empty() {
        return Ok(());
    }
    Err(CliError::Changed(format!(
        "{} of {} files of report {} changed or missing since it was made: {}",
        bad.len(),
        v.checks.len(),
        v.report_number,
        bad.join("; ")
    )))
}
