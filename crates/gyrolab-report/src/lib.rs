//! gyrolab-report: text tables, JSON documents and (later) HTML reports of gyrolab results.
//!
//! - [`bias`]: static (bias) test tables and JSON;
//! - [`rate`]: rate-table evaluation tables and JSON (keys in docs/JSON.md);
//! - [`segments`]: segmentation summaries of raw rate-table logs;
//! - [`triad`]: three-axis calibration tables and JSON;
//! - [`paper`]: the paper's printed tables beside the recomputation, for `gyrolab demo`;
//! - [`format`]: number formatting.

pub mod bias;
pub mod format;
pub mod paper;
pub mod rate;
pub mod segments;
pub mod triad;
