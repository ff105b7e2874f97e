//! MCAP files (the `mcap` crate's streaming reader: chunks decompressed as they come, zstd and
//! lz4, any chunk size): ROS 2 `sensor_msgs/msg/Imu` and `geometry_msgs/msg/Vector3Stamped`
//! messages in CDR, and ROS 1 encoded ones.

use super::ros_msg::{decode, Encoding, RosImuType};
use super::{Collector, ImuLayout, StampSource, Stop};
use crate::error::DataError;
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader};
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// What a channel's messages are.
struct ChannelState {
    id: usize,
    kind: Option<(RosImuType, Encoding)>,
}

/// Reads every message of an MCAP file into `c`.
pub(super) fn read(path: &Path, c: &mut Collector) -> Result<(), Stop> {
    let mut file = std::fs::File::open(path).map_err(|e| DataError::io(path, &e))?;
    let mut reader = LinearReader::new();
    let mut offset: u64 = 0;
    let mut schemas: HashMap<u16, String> = HashMap::new();
    let mut channels: HashMap<u16, ChannelState> = HashMap::new();
    let damaged =
        |offset: u64, e: &dyn std::fmt::Display| Stop::Damaged { at: format!("byte {offset}"), what: e.to_string() };
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| damaged(offset, &e))? {
            LinearReadEvent::ReadRequest(n) => {
                let buf = reader.insert(n);
                let read = loop {
                    match file.read(buf) {
                        Ok(k) => break k,
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                        Err(e) => return Err(DataError::io(path, &e).into()),
                    }
                };
                offset += read as u64;
                reader.notify_read(read);
            }
            LinearReadEvent::Record { data, opcode } => {
                match mcap::parse_record(opcode, data).map_err(|e| damaged(offset, &e))? {
                    Record::Schema { header, .. } => {
                        schemas.insert(header.id, header.name);
                    }
                    Record::Channel(ch) => {
                        let ty = schemas.get(&ch.schema_id).cloned().unwrap_or_else(|| ch.message_encoding.clone());
                        let encoding = match ch.message_encoding.as_str() {
                            "cdr" => Some(Encoding::Cdr),
                            "ros1" => Some(Encoding::Ros1),
                            _ => None,
                        };
                        let kind = RosImuType::from_name(&ty).zip(encoding);
                        let layout = kind.map(|(k, _)| match k {
                            RosImuType::Imu => ImuLayout::six(),
                            RosImuType::Vector3Stamped => ImuLayout::three(["x", "y", "z"]),
                        });
                        let id = c.topic(&ch.topic, &ty, layout, StampSource::Header);
                        channels.insert(ch.id, ChannelState { id, kind });
                    }
                    Record::Message { header, data } => {
                        let Some(ch) = channels.get(&header.channel_id) else {
                            return Err(Stop::Damaged {
                                at: format!("byte {offset}"),
                                what: format!("a message on channel {} that was never declared", header.channel_id),
                            });
                        };
                        let log_ns = header.log_time.min(i64::MAX as u64) as i64;
                        match ch.kind {
                            Some((kind, encoding)) if c.decodes(ch.id) => {
                                let m = decode(kind, encoding, &data).map_err(|e| {
                                    DataError::new(
                                        path,
                                        format!(
                                            "message {} of topic '{}' (near byte {offset}): {e}",
                                            c.topics[ch.id].info.messages + 1,
                                            crate::text::excerpt(&c.topics[ch.id].info.topic)
                                        ),
                                    )
                                })?;
                                let width = c.topics[ch.id].channels.len();
                                c.push(ch.id, m.stamp_ns, log_ns, &m.values[..width]);
                            }
                            _ => c.count(ch.id, log_ns),
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(())
}
