//! ROS 1 bags, format 2.0 (ROS wiki "Bags/Format/2.0"): `sensor_msgs/Imu` and
//! `geometry_msgs/Vector3Stamped` messages.
//!
//! Read here, record by record, from the file opened once: every record is a header (u32
//! length, then `name=value` fields each with a u32 length) and data (u32 length). Every length
//! is checked against the bytes left in the file and against a limit ([`MAX_HEADER_BYTES`],
//! [`MAX_CHUNK_BYTES`]) before a buffer is made. A chunk's declared uncompressed size is checked
//! against the limit and its data decompressed (bz2, lz4 or none) into at most that many bytes;
//! a chunk that fails (bad size, bad compressed data, a record inside running past its end) is
//! skipped, counted with its byte offset, and the next chunk is read. A connection's `md5sum`
//! and message definition are checked against the layout the decoder reads.

use super::ros_msg::{check_definition, decode, Encoding, RosImuType};
use super::{Collector, StampSource, Stop};
use crate::error::DataError;
use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// Longest record header read, bytes (1 MiB; bag writers write a few hundred).
pub const MAX_HEADER_BYTES: u64 = 1 << 20;
/// Longest chunk (compressed or not) read, bytes: 256 MiB (`rosbag record` writes 768 KiB).
pub const MAX_CHUNK_BYTES: u64 = 256 << 20;

const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_CHUNK: u8 = 0x05;
const OP_CONNECTION: u8 = 0x07;

/// One `name=value` field of a record header: the name's bytes and the value's bytes.
type Field<'a> = (&'a [u8], &'a [u8]);

/// The `name=value` fields of a record header (or a connection's data).
fn fields(mut b: &[u8]) -> Result<Vec<Field<'_>>, String> {
    let mut out = Vec::new();
    while !b.is_empty() {
        let n = b.get(..4).ok_or("a header field length is cut off")?;
        let n = u32::from_le_bytes([n[0], n[1], n[2], n[3]]) as u64;
        if n > (b.len() - 4) as u64 {
            return Err(format!("a header field declares {n} bytes, more than the {} left", b.len() - 4));
        }
        let field = &b[4..4 + n as usize];
        let eq = field.iter().position(|&c| c == b'=').ok_or("a header field without '='")?;
        out.push((&field[..eq], &field[eq + 1..]));
        b = &b[4 + n as usize..];
    }
    Ok(out)
}

fn field<'a>(f: &[(&[u8], &'a [u8])], name: &str) -> Option<&'a [u8]> {
    f.iter().find(|(k, _)| *k == name.as_bytes()).map(|(_, v)| *v)
}

fn u32_field(f: &[(&[u8], &[u8])], name: &str) -> Result<u32, String> {
    let v = field(f, name).ok_or_else(|| format!("no '{name}' field"))?;
    let b: [u8; 4] = v.try_into().map_err(|_| format!("the '{name}' field is not 4 bytes"))?;
    Ok(u32::from_le_bytes(b))
}

fn text(v: &[u8]) -> String {
    String::from_utf8_lossy(v).into_owned()
}

/// Why a connection record is not taken.
enum ConnError {
    /// Its bytes are damaged.
    Damaged(String),
    /// Its definition is not the layout the decoder reads.
    Refused(String),
}

/// The state of one pass.
struct Pass<'p> {
    path: &'p Path,
    conns: HashMap<u32, (usize, Option<RosImuType>)>,
}

impl Pass<'_> {
    /// A connection record (header fields, data = the connection header).
    fn connection(&mut self, c: &mut Collector, head: &[(&[u8], &[u8])], data: &[u8]) -> Result<(), ConnError> {
        let id = u32_field(head, "conn").map_err(ConnError::Damaged)?;
        let topic = text(field(head, "topic").ok_or(ConnError::Damaged("a connection without a topic".into()))?);
        let info = fields(data).map_err(ConnError::Damaged)?;
        let tp = text(field(&info, "type").unwrap_or(b""));
        let kind = RosImuType::from_name(&tp);
        if let Some(k) = kind {
            if c.selected(&topic) {
                let md5 = text(field(&info, "md5sum").unwrap_or(b"*"));
                let definition = text(field(&info, "message_definition").unwrap_or(b""));
                let why = check_definition(k, Encoding::Ros1, &definition).err();
                if (md5 != "*" && md5 != k.ros1_md5()) || why.is_some() {
                    return Err(ConnError::Refused(format!(
                        "topic '{}' ({}): its md5sum {} is not that of the {} layout gyrolab decodes ({}): {}; not read",
                        crate::text::excerpt(&topic),
                        crate::text::excerpt(&tp),
                        crate::text::excerpt(&md5),
                        k.name(),
                        k.ros1_md5(),
                        why.unwrap_or_else(|| "the message definition differs".into())
                    )));
                }
            }
        }
        let cid = c.topic(&topic, &tp, kind.map(RosImuType::layout), StampSource::Header);
        self.conns.insert(id, (cid, kind));
        Ok(())
    }

    /// The records of a chunk's data (at `offset`, its byte offset in the file).
    fn chunk_records(&mut self, c: &mut Collector, mut b: &[u8], offset: u64) -> Result<(), Stop> {
        let skip = |c: &mut Collector, why: String| {
            c.damaged_chunks.push((offset, why));
            Ok(())
        };
        while !b.is_empty() {
            let Some((head, data, rest)) = split_record(b) else {
                return skip(c, "a record inside the chunk runs past its end".into());
            };
            b = rest;
            let head = match fields(head) {
                Ok(h) => h,
                Err(why) => return skip(c, why),
            };
            match field(&head, "op").and_then(|o| o.first().copied()) {
                Some(OP_CONNECTION) => match self.connection(c, &head, data) {
                    Ok(()) => {}
                    Err(ConnError::Refused(why)) => return Err(DataError::new(self.path, why).into()),
                    Err(ConnError::Damaged(why)) => return skip(c, why),
                },
                Some(OP_MESSAGE) => {
                    let conn = match u32_field(&head, "conn") {
                        Ok(v) => v,
                        Err(why) => return skip(c, why),
                    };
                    let Some(time) = field(&head, "time").and_then(|t| <[u8; 8]>::try_from(t).ok()) else {
                        return skip(c, "a message without an 8-byte time".into());
                    };
                    let sec = u32::from_le_bytes([time[0], time[1], time[2], time[3]]);
                    let nsec = u32::from_le_bytes([time[4], time[5], time[6], time[7]]);
                    let log_ns = i64::from(sec) * 1_000_000_000 + i64::from(nsec);
                    let Some(&(id, kind)) = self.conns.get(&conn) else {
                        return skip(c, format!("a message on connection {conn} that was never declared"));
                    };
                    match kind {
                        Some(kind) if c.decodes(id) => {
                            let index = c.topics[id].info.messages + 1;
                            let d = decode(kind, Encoding::Ros1, data).map_err(|e| {
                                DataError::new(
                                    self.path,
                                    format!(
                                        "message {index} of topic '{}' (the chunk at byte {offset}): {e}",
                                        crate::text::excerpt(&c.topics[id].info.topic)
                                    ),
                                )
                            })?;
                            let width = c.topics[id].channels.len();
                            let at = format!("the chunk at byte {offset}");
                            c.push_checked(self.path, id, d.stamp_ns, log_ns, &d.values[..width], &at)?;
                        }
                        _ => c.count(id, log_ns),
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// One record of a byte slice: (header, data, the rest), or `None` when it runs past the end.
fn split_record(b: &[u8]) -> Option<(&[u8], &[u8], &[u8])> {
    let hl = u32::from_le_bytes(b.get(..4)?.try_into().ok()?) as usize;
    let head = b.get(4..4usize.checked_add(hl)?)?;
    let rest = &b[4 + hl..];
    let dl = u32::from_le_bytes(rest.get(..4)?.try_into().ok()?) as usize;
    let data = rest.get(4..4usize.checked_add(dl)?)?;
    Some((head, data, &rest[4 + dl..]))
}

/// A chunk's records, decompressed into at most its declared size; the error says why not.
fn open_chunk(head: &[(&[u8], &[u8])], data: &[u8]) -> Result<Vec<u8>, String> {
    let compression = text(field(head, "compression").ok_or("a chunk without a compression field")?);
    let size = u64::from(u32_field(head, "size")?);
    if size > MAX_CHUNK_BYTES {
        return Err(format!("declares {size} bytes uncompressed, more than the {MAX_CHUNK_BYTES} this reader accepts"));
    }
    let mut out = Vec::new();
    let read = match compression.as_str() {
        "none" => {
            out.extend_from_slice(data);
            Ok(0)
        }
        "bz2" => bzip2::read::BzDecoder::new(data).take(size + 1).read_to_end(&mut out),
        "lz4" => lz4_flex::frame::FrameDecoder::new(data).take(size + 1).read_to_end(&mut out),
        other => return Err(format!("unknown compression '{}'", crate::text::excerpt(other))),
    };
    read.map_err(|e| {
        format!("its {compression} data does not decompress ({})", crate::text::short_message(&e.to_string()))
    })?;
    if out.len() as u64 != size {
        return Err(format!("holds {} bytes where {size} were declared", out.len()));
    }
    Ok(out)
}

/// Reads exactly `n` bytes at the file's position.
fn read_exact(path: &Path, f: &mut impl Read, n: u64, at: u64) -> Result<Vec<u8>, Stop> {
    let mut buf = Vec::new();
    f.take(n).read_to_end(&mut buf).map_err(|e| DataError::io(path, &e))?;
    if (buf.len() as u64) < n {
        return Err(Stop::Damaged {
            at: format!("byte {at}"),
            what: format!("the record there runs past the end of the file at byte {}", at + buf.len() as u64),
        });
    }
    Ok(buf)
}

/// Reads every message of a ROS 1 bag (opened once, `size` bytes) into `c`.
pub(super) fn read(path: &Path, file: std::fs::File, size: u64, c: &mut Collector) -> Result<(), Stop> {
    let mut f = std::io::BufReader::with_capacity(1 << 20, file);
    let magic = read_exact(path, &mut f, MAGIC.len() as u64, 0)?;
    if magic != MAGIC {
        return Err(Stop::Damaged { at: "the start".into(), what: "not a ROS 1 bag version 2.0".into() });
    }
    let mut pass = Pass { path, conns: HashMap::new() };
    let mut at = MAGIC.len() as u64;
    let mut index_pos = size;
    let damaged = |at: u64, what: String| Stop::Damaged { at: format!("byte {at}"), what };
    // Every bag 2.0 begins with its bag header record (its first record after the version
    // line): a file cut before it holds no connection, no chunk and no index.
    if at >= size {
        return Err(Stop::Damaged {
            at: format!("byte {size}"),
            what: "the file ends after its version line: no bag header, no records and no index (cut off, or an empty bag never written)".into(),
        });
    }
    let mut header_seen = false;
    while at < index_pos.min(size) {
        let left = size - at;
        let hl = u64::from(u32::from_le_bytes(
            read_exact(path, &mut f, 4, at)?.try_into().map_err(|_| damaged(at, "a cut record".into()))?,
        ));
        if hl > MAX_HEADER_BYTES || hl + 8 > left {
            return Err(damaged(
                at,
                format!("a record header of {hl} bytes, more than the file's {left} bytes left or the {MAX_HEADER_BYTES} accepted"),
            ));
        }
        let head = read_exact(path, &mut f, hl, at)?;
        let dl = u64::from(u32::from_le_bytes(
            read_exact(path, &mut f, 4, at)?.try_into().map_err(|_| damaged(at, "a cut record".into()))?,
        ));
        let left = left - hl - 8;
        if dl > left {
            return Err(damaged(
                at,
                format!("the record declares {dl} bytes of data, more than the {left} left in the file"),
            ));
        }
        let head_fields = fields(&head).map_err(|why| damaged(at, why))?;
        let op = field(&head_fields, "op").and_then(|o| o.first().copied());
        if !header_seen && op != Some(OP_BAG_HEADER) {
            return Err(damaged(
                at,
                "the first record is not the bag header (op 0x03) a ROS 1 bag 2.0 begins with".into(),
            ));
        }
        match op {
            Some(OP_BAG_HEADER) => {
                header_seen = true;
                let p = field(&head_fields, "index_pos")
                    .and_then(|v| <[u8; 8]>::try_from(v).ok())
                    .map(u64::from_le_bytes)
                    .ok_or_else(|| damaged(at, "the bag header has no index_pos".into()))?;
                if p == 0 {
                    return Err(Stop::Damaged {
                        at: "the start".into(),
                        what: "the bag has no index (it was not closed; `rosbag reindex` rebuilds it)".into(),
                    });
                }
                if p > size {
                    return Err(Stop::Damaged {
                        at: format!("byte {size}"),
                        what: format!(
                            "the file ends before its index at byte {p} (cut off; `rosbag reindex` may recover it)"
                        ),
                    });
                }
                index_pos = p;
                f.seek_relative(dl as i64).map_err(|e| DataError::io(path, &e))?;
            }
            Some(OP_CHUNK) => {
                if dl > MAX_CHUNK_BYTES {
                    c.damaged_chunks.push((at, format!("{dl} bytes, more than the {MAX_CHUNK_BYTES} accepted")));
                    f.seek(SeekFrom::Current(dl as i64)).map_err(|e| DataError::io(path, &e))?;
                } else {
                    let data = read_exact(path, &mut f, dl, at)?;
                    match open_chunk(&head_fields, &data) {
                        Ok(records) => {
                            drop(data);
                            pass.chunk_records(c, &records, at)?;
                        }
                        Err(why) => c.damaged_chunks.push((at, why)),
                    }
                }
            }
            Some(OP_CONNECTION) => {
                let data = read_exact(path, &mut f, dl, at)?;
                match pass.connection(c, &head_fields, &data) {
                    Ok(()) => {}
                    Err(ConnError::Refused(why)) => return Err(DataError::new(path, why).into()),
                    Err(ConnError::Damaged(why)) => return Err(damaged(at, why)),
                }
            }
            _ => f.seek(SeekFrom::Current(dl as i64)).map(drop).map_err(|e| DataError::io(path, &e))?,
        }
        at += 8 + hl + dl;
    }
    Ok(())
}
