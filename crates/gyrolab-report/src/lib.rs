//! gyrolab-report: text tables, JSON documents and (later) HTML reports of gyrolab results.
//!
//! - [`allan`]: Allan-deviation tables, CSV, JSON, noise terms and Kalibr YAML;
//! - [`bias`]: static (bias) test tables and JSON;
//! - [`rate`]: rate-table evaluation tables and JSON (keys in docs/JSON.md);
//! - [`paper`]: the paper's printed tables beside the recomputation, for `gyrolab demo`;
//! - [`format`]: number formatting.

pub mod allan;
pub mod bias;
pub mod format;
pub mod paper;
pub mod rate;
