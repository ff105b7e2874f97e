//! ROS 1 bags, format 2.0 (the `rosbag` crate: chunks decompressed with bz2 or lz4):
//! `sensor_msgs/Imu` and `geometry_msgs/Vector3Stamped` messages.

use super::ros_msg::{decode, Encoding, RosImuType};
use super::{Collector, ImuLayout, StampSource, Stop};
use crate::error::DataError;
use rosbag::{ChunkRecord, MessageRecord, RosBag};
use std::collections::HashMap;
use std::path::Path;

/// Reads every message of a ROS 1 bag into `c`.
pub(super) fn read(path: &Path, c: &mut Collector) -> Result<(), Stop> {
    let bag = RosBag::new(path).map_err(|e| Stop::Damaged { at: "the start".into(), what: e.to_string() })?;
    let mut conns: HashMap<u32, (usize, Option<RosImuType>)> = HashMap::new();
    let mut chunks = 0u64;
    for record in bag.chunk_records() {
        let record = record.map_err(|e| Stop::Damaged { at: format!("chunk {}", chunks + 1), what: e.to_string() })?;
        let ChunkRecord::Chunk(chunk) = record else { continue };
        chunks += 1;
        for msg in chunk.messages() {
            let msg = msg.map_err(|e| Stop::Damaged { at: format!("chunk {chunks}"), what: e.to_string() })?;
            match msg {
                MessageRecord::Connection(conn) => {
                    let kind = RosImuType::from_name(conn.tp);
                    let layout = kind.map(|k| match k {
                        RosImuType::Imu => ImuLayout::six(),
                        RosImuType::Vector3Stamped => ImuLayout::three(["x", "y", "z"]),
                    });
                    let id = c.topic(conn.topic, conn.tp, layout, StampSource::Header);
                    conns.insert(conn.id, (id, kind));
                }
                MessageRecord::MessageData(m) => {
                    let Some(&(id, kind)) = conns.get(&m.conn_id) else {
                        return Err(Stop::Damaged {
                            at: format!("chunk {chunks}"),
                            what: format!("a message on connection {} that was never declared", m.conn_id),
                        });
                    };
                    let log_ns = m.time.min(i64::MAX as u64) as i64;
                    match kind {
                        Some(kind) if c.decodes(id) => {
                            let d = decode(kind, Encoding::Ros1, m.data).map_err(|e| {
                                DataError::new(
                                    path,
                                    format!(
                                        "message {} of topic '{}' (chunk {chunks}): {e}",
                                        c.topics[id].info.messages + 1,
                                        crate::text::excerpt(&c.topics[id].info.topic)
                                    ),
                                )
                            })?;
                            let width = c.topics[id].channels.len();
                            c.push(id, d.stamp_ns, log_ns, &d.values[..width]);
                        }
                        _ => c.count(id, log_ns),
                    }
                }
            }
        }
    }
    Ok(())
}
