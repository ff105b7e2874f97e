//! `gyrolab verify DIR`: recomputes the SHA-256 of a report folder's plan, inputs and outputs
//! (against its manifest.json) and names every file that changed, is missing or was added (exit
//! 3); a folder without a manifest has its outputs NOT CHECKED (exit 5); else exit 0.

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
    match &v.outputs {
        Some(outputs) => {
            for o in outputs {
                let (word, detail) = match &o.state {
                    FileState::Unchanged => ("unchanged", String::new()),
                    FileState::Changed { sha256, size_bytes } => (
                        "CHANGED",
                        format!(" (SHA-256 now {sha256}, {size_bytes} bytes; manifest {})", o.recorded_sha256),
                    ),
                    FileState::Missing { reason } => ("MISSING", format!(" ({reason})")),
                };
                if o.state != FileState::Unchanged {
                    bad.push(format!("output {}", o.name));
                }
                s.push_str(&format!("  {word:<9} {:<9} {}{detail}\n", "output", o.name));
            }
            for e in &v.extra {
                bad.push(format!("added {e}"));
                s.push_str(&format!("  {:<9} {:<9} {e} (in the folder, not in its manifest)\n", "ADDED", "file"));
            }
            for u in &v.uncovered {
                s.push_str(&format!(
                    "  {:<9} {:<9} {u} (printed from report.html after the manifest: not covered by it)\n",
                    "uncovered", "file"
                ));
            }
        }
        None => s.push_str(
            "  NOT CHECKED: the outputs (the folder has no manifest.json: written by a gyrolab before 0.3)\n",
        ),
    }
    print(&s)?;
    if bad.is_empty() {
        if !v.outputs_checked() {
            return Err(CliError::Incomplete(format!(
                "report {}: the plan and inputs are unchanged, but the outputs were NOT CHECKED (no manifest.json in {})",
                v.report_number,
                args.dir.display()
            )));
        }
        return Ok(());
    }
    Err(CliError::Changed(format!(
        "{} of {} files of report {} changed, missing or added since it was made: {}",
        bad.len(),
        v.checks.len() + v.outputs.as_ref().map_or(0, Vec::len) + v.extra.len(),
        v.report_number,
        bad.join("; ")
    )))
}
