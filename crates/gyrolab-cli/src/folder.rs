//! Writing a report folder and ending the run: the files written, the verdict of the spec
//! limits, and exit code 3 when a limit failed (`gyrolab eval`, `gyrolab demo --out`).

use crate::error::{CliError, CliResult};
use crate::output::{print, write_folder};
use gyrolab_eval::report_folder::ReportFolder;
use gyrolab_report::limits::Verdict;
use std::path::Path;

/// Writes the folder whole, prints what was written (unless quiet) and turns a failed limit
/// into exit code 3.
pub fn write_and_finish(out: &Path, folder: &ReportFolder, quiet: bool) -> CliResult {
    let files = write_folder(out, &folder.outputs)?;
    if !quiet {
        let mut s = format!("Wrote {} files to {}:\n", files.len(), out.display());
        for f in &files {
            s.push_str(&format!(
                "  {}\n",
                f.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned())
            ));
        }
        match folder.verdict {
            Some(v) => s.push_str(&format!("Spec limits: {}\n", v.text())),
            None => s.push_str("Spec limits: none in the plan\n"),
        }
        for f in &folder.failures {
            s.push_str(&format!("  FAIL {f}\n"));
        }
        print(&s)?;
    }
    if folder.verdict == Some(Verdict::Fail) {
        return Err(CliError::LimitFailed(format!(
            "{} spec limit check(s) failed (report written to {}): {}",
            folder.failures.len(),
            out.display(),
            folder.failures.join("; ")
        )));
    }
    Ok(())
}
