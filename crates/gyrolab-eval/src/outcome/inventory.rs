//! The inventory of a recording (`gyrolab inspect`): its topics with their message types,
//! counts, rates, time spans and gaps.

use serde::Serialize;

/// One topic of a recording (or the table of a text or Parquet file).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopicInventory {
    /// Topic name.
    pub topic: String,
    /// Message type.
    pub message_type: String,
    /// Messages.
    pub messages: u64,
    /// Whether gyrolab analyses it (an IMU topic).
    pub imu: bool,
    /// First time stamp, s (since the epoch for ROS, since boot for PX4).
    pub start_s: Option<f64>,
    /// Last minus first stamp, s.
    pub duration_s: Option<f64>,
    /// Mean message rate, Hz (the one sampling-interval estimator of gyrolab).
    pub rate_hz: Option<f64>,
    /// Gaps in the stamps (missing messages at the rate).
    pub gaps: usize,
    /// Messages missing in those gaps.
    pub missing: usize,
    /// Messages that came before an earlier-stamped one in the file.
    pub out_of_order: u64,
    /// Where the stamps come from (`header stamps`, `log times`, ...).
    pub stamps: String,
}

/// A recording's inventory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inventory {
    /// gyrolab version.
    pub gyrolab_version: String,
    /// The file.
    pub file: String,
    /// Its format (`MCAP`, `ROS 1 bag`, `PX4 ULog`, `Parquet`, `delimited text`).
    pub format: String,
    /// Its topics, in order of appearance.
    pub topics: Vec<TopicInventory>,
    /// Where the file ends early or is damaged, when it does.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub truncated: Option<String>,
}
