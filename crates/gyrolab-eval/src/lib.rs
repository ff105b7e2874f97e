//! gyrolab-eval: the file-to-evaluation pipeline that every front end shares (the command line,
//! the Python package, a records database or a server). Requests in, typed results and report
//! outputs out; no terminal, no process exit, nothing written but temporary simulated records.
//!
//! Layout (one module per request type):
//! - [`rate`]: rate-table records (long, wide, raw logs) to evaluated axes and calibrations;
//! - [`raw_log`]: raw rate-table logs segmented into plateaus, strokes and runs;
//! - [`triad`]: three-axis calibration sets;
//! - [`static_test`]: static tests (bias, bias stability, repeatability, drift, temperature);
//! - [`allan`]: Allan-variance analyses of time series, with noise terms;
//! - [`allan_memory`]: the same within a memory ceiling, streaming records beyond it;
//! - [`apply`]: a calibration applied to a time series, streaming;
//! - [`batch`]: many records on every core, resumable by input hash, one result row per channel;
//! - [`simulate`]: simulator configurations from a file and overrides;
//! - [`record_length`]: the record length a noise term's precision needs;
//! - [`recording`]: recordings (MCAP, ROS 1 bags, ULog): inventories and conversion to CSV/Parquet;
//! - [`test_plan`]: TOML test plans evaluated into a report folder;
//! - [`program_sim`]: SIMULATED records with known truth of a lab's test program (temperature, ...);
//! - [`demo`]: the paper's worked example and its report folder ([`paper`]: its data);
//! - [`report_folder`]: a report folder as named outputs the caller writes;
//! - [`reference`]: the output-to-rate reference (K, null, unit): the one place outputs become rates;
//! - [`progress`]: the progress trait front ends implement;
//! - [`error`]: [`EvalError`], whose option errors name request fields for each front end to spell.
//!
//! The rules themselves live in the core crate `gyrolab` (one sampling-interval estimator in
//! `gyrolab::sampling`, one set of option validators in `gyrolab::validate`, the formulas with
//! their sources); the readers and writers in `gyrolab-io`; rendering in `gyrolab-report`.

pub mod allan;
pub mod allan_memory;
pub mod apply;
pub mod batch;
pub mod demo;
pub mod error;
pub mod filter_export;
pub mod layout;
pub mod paper;
pub mod program_sim;
pub mod progress;
pub mod rate;
pub mod raw_log;
pub mod record_length;
pub mod recording;
pub mod reference;
pub mod report_folder;
pub mod simulate;
pub mod static_test;
pub mod test_plan;
pub mod triad;
pub mod verify;

pub use error::{EvalError, EvalResult};
pub use progress::{Progress, Silent};
