//! Writing a report folder and ending the run: the files written, the PDF when asked for
//! (`--pdf`), the verdict of the spec limits, and exit code 3 when a limit failed, 5 when the
//! result is INCOMPLETE (a required check not evaluated), 6 when it is CONDITIONAL (`gyrolab
//! eval`, `gyrolab demo --out`), or 1 when the PDF was asked for and could not be made.

use crate::error::{CliError, CliResult};
use crate::output::{print, write_folder};
use gyrolab::limits::Overall;
use gyrolab_lab::report_folder::{print_pdf, written_text, ReportFolder};
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
        print(&written_text(out, &files, folder))?;
    }
    if pdf {
        let printed = print_pdf(out, folder).map_err(CliError::Output)?;
        if !quiet {
            print(&printed)?;
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
