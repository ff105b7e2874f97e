//! gyrolab-report: text tables, JSON documents and (later) HTML reports of gyrolab results.
//!
//! - [`rate`]: rate-table evaluation tables and JSON (keys in docs/JSON.md);
//! - [`paper`]: the paper's printed tables beside the recomputation, for `gyrolab demo`;
//! - [`format`]: number formatting.

pub mod format;
pub mod paper;
pub mod plot;
pub mod rate;
