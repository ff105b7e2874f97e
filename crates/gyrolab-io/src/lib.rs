//! gyrolab-io: readers and writers for gyrolab, with errors that name the file, line and column.
//!
//! - [`error`]: the [`DataError`] every reader returns;
//! - [`series`]: streaming reader of time-series files, and the static test of a file;
//! - [`atomic`]: outputs written to a temporary file and renamed into place.

pub mod atomic;
pub mod error;
pub mod series;

pub use error::DataError;
