//! The inventory of a recording (`gyrolab inspect`): its topics with their message types,
//! counts, rates, time spans and gaps, as a text table or JSON.

use comfy_table::presets::UTF8_FULL_CONDENSED;
use comfy_table::{Cell, CellAlignment, Table};
use gyrolab::format::short;
use gyrolab_eval::outcome::inventory::Inventory;

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
