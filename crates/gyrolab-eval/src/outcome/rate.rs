//! The outcome of a rate-table evaluation of one axis: the evaluation with its record's facts.

use gyrolab::rate_test::RateEvaluation;
use gyrolab::units::OutputUnit;

/// One evaluated axis with what is needed to report it.
#[derive(Debug, Clone)]
pub struct AxisReport<'a> {
    /// Axis name.
    pub name: String,
    /// Source file as given.
    pub file: String,
    /// Layout the record was read in (`long` or `wide`).
    pub layout: String,
    /// Output unit.
    pub output_unit: OutputUnit,
    /// Number of output samples read.
    pub samples: usize,
    /// The evaluation.
    pub evaluation: &'a RateEvaluation,
}
