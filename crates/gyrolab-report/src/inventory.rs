//! The inventory of a recording (`gyrolab inspect`): its topics with their message types,
//! counts, rates, time spans and gaps, as a text table or JSON.

use crate::format::short;
use comfy_table::presets::UTF8_FULL_CONDENSED;
use comfy_table::{Cell, CellAlignment, Table};
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

/// The inventory as a text table.
pub fn inventory_text(inv: &Inventory) -> String {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(vec![
        "topic",
        "type",
        "messages",
        "IMU",
        "rate Hz",
        "duration s",
        "gaps (missing)",
        "out of order",
        "time from",
    ]);
    let opt = |v: Option<f64>, d: usize| v.map_or("-".to_string(), |x| short(x, d));
    for x in &inv.topics {
        t.add_row(vec![
            Cell::new(&x.topic),
            Cell::new(&x.message_type),
            Cell::new(x.messages).set_alignment(CellAlignment::Right),
            Cell::new(if x.imu { "yes" } else { "" }),
            Cell::new(opt(x.rate_hz, 6)).set_alignment(CellAlignment::Right),
            Cell::new(opt(x.duration_s, 6)).set_alignment(CellAlignment::Right),
            Cell::new(format!("{} ({})", x.gaps, x.missing)).set_alignment(CellAlignment::Right),
            Cell::new(x.out_of_order).set_alignment(CellAlignment::Right),
            Cell::new(&x.stamps),
        ]);
    }
    let imu = inv.topics.iter().filter(|x| x.imu).count();
    let mut s = format!("{} ({}): {} topic(s), {imu} IMU topic(s)\n{t}\n", inv.file, inv.format, inv.topics.len());
    if imu == 0 {
        s.push_str("no IMU topic: gyrolab reads sensor_msgs/Imu, geometry_msgs/Vector3Stamped and PX4 sensor_combined, sensor_gyro, sensor_accel, vehicle_imu\n");
    }
    if let Some(w) = &inv.truncated {
        s.push_str(&format!("warning: {w}\n"));
    }
    s
}
