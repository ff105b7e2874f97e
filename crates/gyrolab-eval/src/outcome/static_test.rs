//! The outcomes of static (bias) tests: one test per channel of a file, the repeatability of a
//! channel across files, and the warm-up of a channel from power-on.

use gyrolab::static_test::{BiasRepeatability, StaticTestResult};
use serde::Serialize;

/// One evaluated test (one channel of one file).
#[derive(Debug, Clone, Serialize)]
pub struct TestReport {
    /// Source file.
    pub file: String,
    /// The figures (flattened into the JSON object).
    #[serde(flatten)]
    pub result: StaticTestResult,
}

/// Repeatability of one channel across the files.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelRepeatability {
    /// Channel name.
    pub channel: String,
    /// The figures.
    #[serde(flatten)]
    pub repeatability: BiasRepeatability,
}

/// The warm-up of one channel of one record (from power-on).
#[derive(Debug, Clone)]
pub struct WarmupReport {
    /// Source file.
    pub file: String,
    /// Channel.
    pub channel: String,
    /// The figures, in deg/h.
    pub result: gyrolab::warmup::WarmupResult,
}
