//! ROS 1 bags, format 2.0 (the `rosbag` crate: chunks decompressed with bz2 or lz4):
//! `sensor_msgs/Imu` and `geometry_msgs/Vector3Stamped` messages.

use super::ros_msg::{decode, Encoding, RosImuType};
use super::{Collector, ImuLayout, StampSource, Stop};
use crate::error::DataError;
use rosbag::{ChunkRecord, MessageRecord, RosBag};
use std::collections::HashMap;
use std::path::Path;

/// The `index_pos` field of a bag's header record (ROS wiki "Bags/Format/2.0": after the
/// version line, a record of u32 header length and `name=value` fields, each with a u32 length).
fn index_pos(head: &[u8]) -> Option<u64> {
    let rest = head.strip_prefix(b"#ROSBAG V2.0\n")?;
    let len = u32::from_le_bytes(rest.get(..4)?.try_into().ok()?) as usize;
    let mut fields = rest.get(4..4 + len)?;
    while fields.len() >= 4 {
        let n = u32::from_le_bytes(fields[..4].try_into().ok()?) as usize;
        let field = fields.get(4..4 + n)?;
        if let Some(v) = field.strip_prefix(b"index_pos=") {
            return Some(u64::from_le_bytes(v.get(..8)?.try_into().ok()?));
        }
        fields = &fields[4 + n..];
    }
    None
}

/// Refuses a bag whose index lies beyond its end (cut off) or that has none (not closed): the
/// `rosbag` crate reads the chunks through the index position.
fn check_index(path: &Path) -> Result<(), Stop> {
    use std::io::Read;
    let mut head = vec![0u8; 4096];
    let mut f = std::fs::File::open(path).map_err(|e| DataError::io(path, &e))?;
    let size = f.metadata().map_err(|e| DataError::io(path, &e))?.len();
    let mut n = 0;
    while n < head.len() {
        match f.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) => return Err(DataError::io(path, &e).into()),
        }
    }
    match index_pos(&head[..n]) {
        None => Err(Stop::Damaged { at: "the start".into(), what: "no readable bag header record".into() }),
        Some(0) => Err(Stop::Damaged {
            at: "the start".into(),
            what: "the bag has no index (it was not closed; `rosbag reindex` rebuilds it)".into(),
        }),
        Some(p) if p > size => Err(Stop::Damaged {
            at: format!("byte {size}"),
            what: format!("the file ends before its index at byte {p} (cut off; `rosbag reindex` may recover it)"),
        }),
        Some(_) => Ok(()),
    }
}

/// Reads every message of a ROS 1 bag into `c`.
pub(super) fn read(path: &Path, c: &mut Collector) -> Result<(), Stop> {
    check_index(path)?;
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
