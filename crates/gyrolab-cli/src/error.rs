//! Errors of the command-line program and their exit codes (documented in README):
//! 0 success; 1 an internal or output failure; 2 bad usage or bad data (a plan error included);
//! 3 a spec limit failed (`gyrolab eval`: every output was written, the report shows FAIL).

use gyrolab_io::DataError;
use std::fmt;
use std::process::ExitCode;

/// A failure that ends the program.
#[derive(Debug)]
pub enum CliError {
    /// Bad input data (exit 2).
    Data(DataError),
    /// Bad usage: options that contradict each other or are out of range (exit 2).
    Usage(String),
    /// Could not write an output (exit 1).
    Output(String),
    /// The evaluation succeeded and its outputs were written, but a spec limit failed (exit 3).
    LimitFailed(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> ExitCode {
        match self {
            CliError::Data(_) | CliError::Usage(_) => ExitCode::from(2),
            CliError::Output(_) => ExitCode::from(1),
            CliError::LimitFailed(_) => ExitCode::from(3),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Data(e) => write!(f, "{e}"),
            CliError::Usage(m) => write!(f, "{m}"),
            CliError::Output(m) => write!(f, "{m}"),
            CliError::LimitFailed(m) => write!(f, "{m}"),
        }
    }
}

impl From<DataError> for CliError {
    fn from(e: DataError) -> Self {
        CliError::Data(e)
    }
}

/// Result of a subcommand.
pub type CliResult<T = ()> = Result<T, CliError>;
