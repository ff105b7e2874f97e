//! Progress of a long evaluation, reported to whatever the front end shows (a terminal bar, a
//! notebook widget, a log). Every method has an empty default, so a front end implements only
//! what it shows; [`Silent`] shows nothing.

/// Receives the progress of an evaluation. Called from the evaluating thread only, but `Sync`
/// so that a front end can share it with its own threads.
pub trait Progress: Sync {
    /// The evaluation will take about `steps` steps.
    fn begin(&self, _steps: u64) {}
    /// What is being done now (`axis x: static test s1.csv`).
    fn message(&self, _text: &str) {}
    /// `steps` steps are done.
    fn advance(&self, _steps: u64) {}
}

/// Shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}
