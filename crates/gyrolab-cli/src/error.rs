//! Errors of the command-line program and their exit codes (documented in README):
//! 0 success; 1 an internal or output failure; 2 bad usage or bad data (a plan error included);
//! 3 a spec limit failed (`gyrolab eval`: every output was written, the report shows FAIL), or
//! `gyrolab verify` found a plan or input changed or missing since the report was made;
//! 4 some inputs of a batch failed (`gyrolab batch`: the others were evaluated and written);
//! 5 the result is INCOMPLETE (`gyrolab eval`: no limit failed, but a required check could not be
//! evaluated: a check not evaluated never counts as passed); 6 the result is CONDITIONAL (no
//! limit failed, every check evaluated, at least one inside the guard band of its decision rule);
//! 7 filter parameters would come from a GMWM fit flagged POOR FIT (`gyrolab allan --export
//! --estimator gmwm`: nothing written; `--allow-poor-fit` writes them).

use gyrolab_eval::EvalError;
use std::process::ExitCode;
use thiserror::Error;

/// A failure that ends the program.
#[derive(Debug, Error)]
pub enum CliError {
    /// The evaluation failed: bad data or options (exit 2), or an output it could not make (exit 1).
    #[error("{}", .0.render(&flag))]
    Eval(#[from] EvalError),
    /// Could not write an output (exit 1).
    #[error("{0}")]
    Output(String),
    /// The evaluation succeeded and its outputs were written, but a spec limit failed (exit 3).
    #[error("{0}")]
    LimitFailed(String),
    /// `gyrolab verify`: a file of the report changed or is missing; `gyrolab store check`: the
    /// store's chain, files or triggers broken (exit 3).
    #[error("{0}")]
    Changed(String),
    /// The outputs were written; no limit failed but at least one required check was not
    /// evaluated (exit 5).
    #[error("{0}")]
    Incomplete(String),
    /// The outputs were written; no limit failed, every check was evaluated, and at least one is
    /// CONDITIONAL (inside its guard band; exit 6).
    #[error("{0}")]
    Conditional(String),
    /// Some inputs of a batch failed; the others were evaluated and written (exit 4).
    #[error("{0}")]
    SomeFailed(String),
    /// An error of the records store (exit 2 for the store or data, 1 for a database failure).
    #[error("{0}")]
    Store(#[from] gyrolab_store::StoreError),
    /// A bad argument found after parsing (exit 2).
    #[error("{0}")]
    Usage(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> ExitCode {
        match self {
            CliError::Eval(EvalError::Output(_)) | CliError::Output(_) => ExitCode::from(1),
            CliError::Eval(EvalError::PoorFit(_)) => ExitCode::from(7),
            CliError::Eval(_) => ExitCode::from(2),
            CliError::LimitFailed(_) | CliError::Changed(_) => ExitCode::from(3),
            CliError::SomeFailed(_) => ExitCode::from(4),
            CliError::Incomplete(_) => ExitCode::from(5),
            CliError::Conditional(_) => ExitCode::from(6),
            CliError::Store(e) if !e.is_bad_input() => ExitCode::from(1),
            CliError::Store(_) | CliError::Usage(_) => ExitCode::from(2),
        }
    }
}

impl From<gyrolab_io::DataError> for CliError {
    fn from(e: gyrolab_io::DataError) -> Self {
        CliError::Eval(EvalError::Data(e))
    }
}

impl From<gyrolab::validate::InvalidOption> for CliError {
    fn from(e: gyrolab::validate::InvalidOption) -> Self {
        CliError::Eval(EvalError::Invalid(e))
    }
}

/// The command-line spelling of a request field: its flag.
pub fn flag(field: &str) -> String {
    match field {
        "axis_names" => "--axis".into(),
        "columns" => "--column".into(),
        "out" => "--out".into(),
        "topics" => "--topic".into(),
        "units" => "--unit".into(),
        "manual_segments" => "--segments".into(),
        "calibration" => "--cal".into(),
        "calibration_axis" => "--cal-axis".into(),
        "latitude_deg" => "--latitude".into(),
        "smoothing_s" => "--smoothing".into(),
        "fit_range_s" => "--fit-range".into(),
        "nonlinearity_limit_pct" => "--nonlinearity-limit".into(),
        "temperature_quadratic" => "--temp-quadratic".into(),
        "triad_x" => "--triad x=FILE".into(),
        "triad_y" => "--triad y=FILE".into(),
        "triad_z" => "--triad z=FILE".into(),
        "start_s" => "--start".into(),
        "end_s" => "--end".into(),
        other => format!("--{}", other.replace('_', "-")),
    }
}

/// Result of a subcommand.
pub type CliResult<T = ()> = Result<T, CliError>;
