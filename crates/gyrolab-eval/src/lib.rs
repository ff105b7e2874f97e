//! gyrolab-eval: the file-to-evaluation pipeline that every front end shares (the command line,
//! the Python package, the lab layer). Requests in, typed outcomes out ([`outcome`]); it renders
//! nothing (gyrolab-report does), stores nothing (gyrolab-store does), and writes nothing but
//! temporary simulated records.
//!
//! Layout (one module per request type):
//! - [`rate`]: rate-table records (long, wide, raw logs) to evaluated axes and calibrations;
//!   ([`rate::raw_log`]: raw rate-table logs segmented into plateaus, strokes and runs);
//! - [`triad`]: three-axis calibration sets;
//! - [`static_test`]: static tests (bias, bias stability, repeatability, drift, temperature);
//! - [`allan`]: Allan-variance analyses of time series, with noise terms;
//! - [`allan_memory`]: the same within a memory ceiling, streaming records beyond it;
//! - [`apply`]: a calibration applied to a time series, streaming;
//! - [`simulate`]: simulator configurations from a file and overrides;
//! - [`record_length`]: the record length a noise term's precision needs;
//! - [`recording`]: recordings (MCAP, ROS 1 bags, ULog): inventories and conversion to CSV/Parquet;
//! - [`program_sim`]: SIMULATED records with known truth of a lab's test program (temperature, ...);
//! - [`reference`](mod@reference): the output-to-rate reference (K, null, unit): the one place outputs become rates;
//! - [`outcome`]: the typed outcomes the requests return and gyrolab-report renders;
//! - [`progress`]: the progress trait front ends implement;
//! - [`error`]: [`EvalError`], whose option errors name request fields for each front end to spell.
//!
//! The rules themselves live in the core crate `gyrolab` (one sampling-interval estimator in
//! `gyrolab::sampling`, one set of option validators in `gyrolab::validate`, the formulas with
//! their sources); the readers and writers in `gyrolab-io`; rendering in `gyrolab-report`; the
//! workflows that combine them (a test plan into a report folder, batches, verify) in `gyrolab-lab`.

#![deny(missing_docs)]

pub mod allan;
pub mod allan_memory;
pub mod apply;
pub mod error;
pub mod filter_export;
pub mod layout;
pub mod outcome;
pub mod program_sim;
pub mod progress;
pub mod rate;
pub mod record_length;
pub mod recording;
pub mod reference;
pub mod simulate;
pub mod static_test;
pub mod triad;

pub use error::{EvalError, EvalResult};
pub use progress::{Progress, Silent};
