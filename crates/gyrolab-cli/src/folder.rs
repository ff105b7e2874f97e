//! Writing a report folder and ending the run: the files written, the PDF when asked for
//! (`--pdf`), the verdict of the spec limits, and exit code 3 when a limit failed, 5 when the
//! result is INCOMPLETE (a required check not evaluated), 6 when it is CONDITIONAL (`gyrolab
//! eval`, `gyrolab demo --out`), or 1 when the PDF was asked for and could not be made.

use crate::error::{CliError, CliResult};
use crate::output::{print, write_folder};
use gyrolab_lab::report_folder::ReportFolder;
use gyrolab::limits::Overall;
use std::path::Path;

/// Writes the folder whole, prints what was written (unless quiet), prints report.html to
/// report.pdf when `pdf` is set, and turns the overall result into its exit code (FAIL 3,
/// INCOMPLETE 5, CONDITIONAL 6).
///
/// When `pdf` is set and no PDF can be made (no browser, or the browser failed), the rest of the
/// folder stays written, an older report.pdf (which shows an earlier report) is removed, and the
/// run ends with exit code 1 and a message saying how to get the PDF.
pub fn write_and_finish(out: &Path, folder: &ReportFolder, quiet: bool, pdf: bool) -> CliResult {
    let files = write_folder(out, &folder.outputs, &folder.inputs)?;
    if !quiet {
        let mut s = format!("Wrote {} files to {}:\n", files.len(), out.display());
        for f in &files {
            s.push_str(&format!(
                "  {}\n",
                f.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned())
            ));
        }
        match folder.verdict {
            Some(v) if folder.simulated => s.push_str(&format!("Spec limits: {} (on SIMULATED data)\n", v.text())),
            Some(v) => s.push_str(&format!("Spec limits: {}\n", v.text())),
            None => s.push_str("Spec limits: none in the plan\n"),
        }
        for f in &folder.failures {
            s.push_str(&format!("  FAIL {f}\n"));
        }
        for f in &folder.undecided {
            s.push_str(&format!("  {f}\n"));
        }
        print(&s)?;
    }
    if pdf {
        match gyrolab_report::pdf::print_report(out) {
            Ok((path, size)) => {
                if !quiet {
                    print(&format!("Printed report.html to {} ({} kB)\n", path.display(), size.div_ceil(1024)))?;
                }
            }
            Err(e) => {
                let mut message = e.message(out);
                let stale = out.join("report.pdf");
                if stale.exists() && std::fs::remove_file(&stale).is_ok() {
                    message.push_str(
                        " (The older report.pdf of this folder, which showed an earlier report, was removed.)",
                    );
                }
                if folder.verdict == Some(Overall::Fail) {
                    message.push_str(&format!(
                        " Also {} spec limit check(s) failed: {}",
                        folder.failures.len(),
                        folder.failures.join("; ")
                    ));
                }
                return Err(CliError::Output(message));
            }
        }
    }
    match folder.verdict {
        Some(Overall::Fail) => Err(CliError::LimitFailed(format!(
            "{} spec limit check(s) failed (report written to {}): {}",
            folder.failures.len(),
            out.display(),
            folder.failures.join("; ")
        ))),
        Some(Overall::Incomplete) => Err(CliError::Incomplete(format!(
            "INCOMPLETE: no spec limit failed, but {} check(s) could not be decided (report written to {}): {}",
            folder.undecided.len(),
            out.display(),
            folder.undecided.join("; ")
        ))),
        Some(Overall::Conditional) => Err(CliError::Conditional(format!(
            "CONDITIONAL: no spec limit failed, but {} check(s) lie within the guard band (report written to {}): {}",
            folder.undecided.len(),
            out.display(),
            folder.undecided.join("; ")
        ))),
        Some(Overall::Pass) | None => Ok(()),
    }
}
