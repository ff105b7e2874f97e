//! The outcome of a three-axis calibration: the fit with its records, columns and unit.

use gyrolab::triad::{TableAxis, TriadFit};
use gyrolab::units::OutputUnit;

/// A three-axis fit with what is needed to report it.
#[derive(Debug, Clone)]
pub struct TriadReport<'a> {
    /// The records: (table axis, file as given).
    pub files: Vec<(TableAxis, String)>,
    /// Names of the gyro output columns, in the order x, y, z.
    pub gyro_columns: [String; 3],
    /// Unit of the outputs.
    pub output_unit: OutputUnit,
    /// The fit.
    pub fit: &'a TriadFit,
}
