//! gyrolab-io: readers and writers for gyrolab, with errors that name the file, line and column.
//!
//! - [`error`]: the [`DataError`] every reader returns;
//! - [`atomic`]: outputs written to a temporary file and renamed into place;
//! - [`provenance`]: where outputs come from: the SIMULATED marks of records and outputs, a
//!   report folder's outputs and their manifest (names, SHA-256, sizes);
//! - [`sniff`]: what a file is, by its first bytes;
//! - [`text`]: a small delimited-text parser with line numbers;
//! - [`rate_table`]: rate-table records in the long and wide layouts;
//! - [`calibration`]: calibration files (TOML) written by `gyrolab rate --cal-out`;
//! - [`raw_log`]: raw rate-table logs (detection, reading, segment files);
//! - [`apply_csv`]: streaming application of a calibration to a time-series file;
//! - [`decimal`]: exact fast reading of plain decimal numbers and rows of them;
//! - [`pages`]: how large in-memory records are backed (huge pages);
//! - [`series`]: streaming reader of time-series files, and the static test of a file;
//! - [`sim_csv`]: fast CSV writer for simulated static records and rate-table tests;
//! - [`test_plan`]: test plans (TOML) for `gyrolab eval`, one child module per plan section
//!   (`test_plan::temperature`, `test_plan::uncertainty`, power-ups, threshold, g-sensitivity);
//! - [`threshold_record`]: threshold and resolution records (rate, output per sample);
//! - [`test_plan`]: test plans (TOML) for `gyrolab eval`.

#![deny(missing_docs)]

pub mod apply_csv;
pub mod atomic;
pub mod calibration;
pub mod contained;
pub mod decimal;
pub mod error;
pub mod input_file;
pub mod noise_export;
pub mod pages;
pub mod parquet_table;
pub mod provenance;
pub mod rate_table;
pub mod raw_log;
pub mod recording;
pub mod series;
pub mod sim_csv;
pub mod sniff;
pub mod text;
pub mod threshold_record;

pub use error::DataError;
pub mod test_plan;
