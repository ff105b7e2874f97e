//! gyrolab-io: readers and writers for gyrolab, with errors that name the file, line and column.
//!
//! - [`error`]: the [`DataError`] every reader returns;
//! - [`atomic`]: outputs written to a temporary file and renamed into place;
//! - [`sim_csv`]: fast CSV writer for simulated static records and rate-table tests.

pub mod atomic;
pub mod error;
pub mod sim_csv;

pub use error::DataError;
