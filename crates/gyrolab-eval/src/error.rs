//! The error of an evaluation: bad data (located in its file), an option outside its domain
//! (named by its request field), options that contradict each other or the data, or an output
//! that could not be produced. Front ends choose the exit code or exception class by the kind,
//! and spell fields their own way with [`EvalError::render`].

use gyrolab::validate::InvalidOption;
use gyrolab_io::DataError;
use thiserror::Error;

/// Why an evaluation failed.
#[derive(Debug, Error)]
pub enum EvalError {
    /// Bad input data, with its file, line and column.
    #[error(transparent)]
    Data(#[from] DataError),
    /// An option value outside its domain.
    #[error(transparent)]
    Invalid(#[from] InvalidOption),
    /// Options that contradict each other or the data given. The message names the request
    /// fields in `fields` as `{field}` placeholders (see [`EvalError::render`]).
    #[error("{}", render_fields(message, fields, &|f| format!("`{f}`")))]
    Conflict {
        /// The message, with placeholders.
        message: String,
        /// The fields named in it.
        fields: Vec<&'static str>,
    },
    /// An output (a plot, a serialised document, a simulated record) could not be produced.
    #[error("{0}")]
    Output(String),
    /// Filter parameters would come from a fit flagged POOR FIT and that was not allowed
    /// (front ends give it its own exit code or exception); the message names the field that
    /// allows it as `{allow_poor_fit}`.
    #[error("{}", .0.replace("{allow_poor_fit}", "`allow_poor_fit`"))]
    PoorFit(String),
}

impl EvalError {
    /// The message with every request field spelled by `spell` (a flag, a plan key, a keyword).
    pub fn render(&self, spell: &dyn Fn(&str) -> String) -> String {
        match self {
            EvalError::Invalid(e) => e.render(&spell(e.field)),
            EvalError::Conflict { message, fields } => render_fields(message, fields, spell),
            EvalError::PoorFit(message) => render_fields(message, &["allow_poor_fit"], spell),
            other => other.to_string(),
        }
    }

    /// A conflict that names no field.
    pub fn conflict(message: impl Into<String>) -> Self {
        EvalError::Conflict { message: message.into(), fields: Vec::new() }
    }

    /// A conflict between the options `fields`, each named in `message` as `{field}`.
    pub fn conflict_on(fields: &[&'static str], message: impl Into<String>) -> Self {
        EvalError::Conflict { message: message.into(), fields: fields.to_vec() }
    }
}

impl From<gyrolab_io::atomic::OutputError> for EvalError {
    /// An output refused for the request's sake (an input or a folder in the way, a file named
    /// twice) is a conflict (bad usage); a write the system refused is an output failure.
    fn from(e: gyrolab_io::atomic::OutputError) -> Self {
        if e.is_usage() {
            EvalError::conflict(e.to_string())
        } else {
            EvalError::Output(e.to_string())
        }
    }
}

/// Replaces `{field}` in `message` by `spell(field)` for each of `fields`.
fn render_fields(message: &str, fields: &[&'static str], spell: &dyn Fn(&str) -> String) -> String {
    let mut out = message.to_string();
    for f in fields {
        out = out.replace(&format!("{{{f}}}"), &spell(f));
    }
    out
}

/// Result of an evaluation step.
pub type EvalResult<T = ()> = Result<T, EvalError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_spelled_by_the_front_end() {
        let e = EvalError::conflict_on(&["axis_names"], "give one name per file with {axis_names}, in /a/{x} {");
        assert_eq!(
            e.render(&|f| format!("--{}", f.replace('_', "-"))),
            "give one name per file with --axis-names, in /a/{x} {"
        );
        assert_eq!(e.to_string(), "give one name per file with `axis_names`, in /a/{x} {");
        let i = EvalError::from(InvalidOption::new("coverage", "must be a positive number, got 0"));
        assert_eq!(i.render(&|f| format!("options.{f}")), "options.coverage must be a positive number, got 0");
    }
}
