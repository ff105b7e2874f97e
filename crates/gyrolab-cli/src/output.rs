//! Writing results: to standard output (a closed pipe is not an error) or atomically to a file
//! or a report folder.

use crate::error::{CliError, CliResult};
use gyrolab_io::provenance::NamedOutput;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Prints text to standard output; a closed pipe (`| head`) ends quietly.
pub fn print(text: &str) -> CliResult {
    // Control characters from stored or read text (an escape sequence in a lot or operator
    // name) never reach the terminal raw: shown as \u{1b}; line breaks and tabs stay.
    let shown;
    let text = if text.chars().any(|c| c.is_control() && c != '\n' && c != '\t') {
        shown =
            text.chars()
                .map(|c| {
                    if c.is_control() && c != '\n' && c != '\t' {
                        c.escape_unicode().to_string()
                    } else {
                        c.to_string()
                    }
                })
                .collect::<String>();
        shown.as_str()
    } else {
        text
    };
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(CliError::Output(format!("cannot write to standard output: {e}"))),
    }
}

/// Writes a file whole or not at all, never over one of `inputs`.
pub fn write_file(path: &Path, bytes: &[u8], inputs: &[&Path]) -> CliResult {
    gyrolab_io::atomic::write_outputs(vec![gyrolab_io::atomic::OutputFile::bytes(path, bytes)], inputs)
        .map(drop)
        .map_err(output_error)
}

/// Writes a report folder: every output to a temporary file first, then all renamed into place,
/// so that a failure leaves the folder as it was, and never over one of `inputs` (exit 2).
/// Returns the paths written, in order.
pub fn write_folder(dir: &Path, outputs: &[NamedOutput], inputs: &[PathBuf]) -> CliResult<Vec<PathBuf>> {
    let files: Vec<(&str, &[u8])> = outputs.iter().map(|o| (o.name.as_str(), &o.bytes[..])).collect();
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    gyrolab_io::atomic::write_folder(dir, &files, &inputs).map_err(output_error)
}

/// The error of a set of outputs not written: bad usage (exit 2) when the request put an input
/// or a folder in the way, else an output failure (exit 1); the message says what is on disk.
pub fn output_error(e: gyrolab_io::atomic::OutputError) -> CliError {
    CliError::Eval(gyrolab_eval::EvalError::from(e))
}

/// Serialises a value as pretty JSON with a final newline.
pub fn to_json<T: serde::Serialize>(value: &T) -> CliResult<String> {
    serde_json::to_string_pretty(value)
        .map(|s| s + "\n")
        .map_err(|e| CliError::Output(format!("cannot serialise JSON: {e}")))
}

/// One `SIMULATED: ...` line per input that gyrolab's simulator wrote (empty when none is), for
/// the head of a text report: a simulated input is marked in every output.
pub fn simulated_lines(files: &[PathBuf]) -> String {
    files
        .iter()
        .filter(|f| gyrolab_io::provenance::is_gyrolab_simulation(f))
        .map(|f| {
            format!("SIMULATED: {} is a simulated record (gyrolab simulate), not a measured sensor\n", f.display())
        })
        .collect()
}
