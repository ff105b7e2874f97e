//! gyrolab-lab: the lab layer, the workflows across evaluation (gyrolab-eval), rendering
//! (gyrolab-report) and storage (gyrolab-store) that every front end calls (the command line,
//! the Python package, the lab's server). Front ends parse arguments, call a workflow here, print
//! and set exit codes; the workflows hold no formula and draw nothing themselves.
//!
//! - [`test_plan`]: a TOML test plan evaluated into a report folder (the parts of a lab's test
//!   program: rate table, three-axis set, static, power-ups, threshold, temperature,
//!   g-sensitivity, uncertainty budget);
//! - [`report_folder`]: a report folder assembled from evaluated parts as named outputs;
//! - [`demo`]: the paper's worked example and its report folder ([`paper`]: its printed tables);
//! - [`batch`]: many records on every core, resumable by input hash, one result row per channel;
//! - [`verify`]: a report folder checked against its manifest, plan and inputs;
//! - [`evaluate`]: evaluate and store (the store checked before anything is written);
//! - [`exports`]: the Kalibr and imu_utils noise files of an Allan run;
//! - [`issue`]: a stored evaluation issued or amended, signed, its report drawn;
//! - [`records`]: the store's queries as tables and a serial's history as a trend plot;
//! - [`reevaluate`]: a stored evaluation evaluated again and stored as its revision.

#![deny(missing_docs)]

pub mod batch;
pub mod demo;
pub mod evaluate;
pub mod exports;
pub mod issue;
pub mod paper;
pub mod raw_records;
pub mod records;
pub mod reevaluate;
pub mod report_folder;
pub mod test_plan;
pub mod verify;
