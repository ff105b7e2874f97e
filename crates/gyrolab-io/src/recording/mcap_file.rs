//! MCAP files (format: mcap.dev "MCAP Format Specification"): ROS 2 `sensor_msgs/msg/Imu` and
//! `geometry_msgs/msg/Vector3Stamped` messages in CDR, and ROS 1 encoded ones.
//!
//! The `mcap` crate's streaming reader walks the top-level records (magic, opcode, length) with
//! a record length limit ([`MAX_RECORD_BYTES`]); every byte count it asks for is checked
//! against the bytes left in the file before a buffer is made. Chunks are taken whole and
//! opened here: the declared uncompressed size is checked against the limit, the data
//! decompressed into a buffer of at most that size (zstd, lz4 or none), its CRC checked, and
//! the records inside read with every length checked against the bytes that remain. A chunk
//! that fails any check is skipped (counted, with its byte offset) and reading goes on with
//! the next one. Only the Schema, Channel and Message records are parsed, by this module's own
//! bounds-checked code; a Schema's definition text is checked against the message layout the
//! decoder assumes ([`super::ros_msg::check_definition`]).

use super::ros_msg::{check_definition, decode, Encoding, RosImuType};
use super::{Collector, StampSource, Stop, TopicInfo};
use crate::error::DataError;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// Longest record (and uncompressed chunk) read, bytes: 256 MiB. MCAP writers make chunks of
/// about 1 to 4 MiB; a longer declared length is damage, refused before anything is allocated.
pub const MAX_RECORD_BYTES: u64 = 256 << 20;

const OP_FOOTER: u8 = 0x02;
const OP_SCHEMA: u8 = 0x03;
const OP_CHANNEL: u8 = 0x04;
const OP_MESSAGE: u8 = 0x05;
const OP_CHUNK: u8 = 0x06;
const OP_DATA_END: u8 = 0x0F;
const OP_STATISTICS: u8 = 0x0B;

/// The topics of an MCAP file with their message counts, from its summary section (the Schema,
/// Channel and Statistics records a writer puts after the data; MCAP specification, "Summary
/// Section" and "Footer"), without reading the data: `None` when the file has no summary or no
/// Statistics record, or when anything in them does not add up (a pass then counts the
/// messages). The span of every topic is the file's (the Statistics record's first and last
/// message times); stamps are not kept.
pub fn summary_topics(mut file: std::fs::File, size: u64) -> Option<Vec<TopicInfo>> {
    use std::io::{Seek, SeekFrom};
    // The end of the file: a Footer record (opcode, length 20: summary start, summary offset
    // start, summary CRC) and the closing magic.
    const TAIL: u64 = 9 + 20 + 8;
    if size < 8 + TAIL {
        return None;
    }
    let footer_at = size - TAIL;
    file.seek(SeekFrom::Start(footer_at)).ok()?;
    let mut tail = [0u8; 29];
    file.read_exact(&mut tail).ok()?;
    let mut f = Fields { b: &tail };
    let (op, len) = f.u8_len().ok()?;
    let summary_start = f.u64("summary start").ok()?;
    if op != OP_FOOTER || len != 20 || summary_start < 8 || summary_start >= footer_at {
        return None;
    }
    let n = footer_at - summary_start;
    if n > MAX_RECORD_BYTES {
        return None;
    }
    file.seek(SeekFrom::Start(summary_start)).ok()?;
    let mut summary = Vec::new();
    file.take(n).read_to_end(&mut summary).ok()?;
    if summary.len() as u64 != n {
        return None;
    }
    let mut schemas: HashMap<u16, String> = HashMap::new();
    let mut channels: Vec<(u16, String, String, bool)> = Vec::new();
    let mut counts: Option<(HashMap<u16, u64>, i64, i64)> = None;
    let mut rest = Fields { b: &summary };
    while !rest.b.is_empty() {
        let (op, len) = rest.u8_len().ok()?;
        let mut r = Fields { b: rest.take(len, "summary record").ok()? };
        match op {
            OP_SCHEMA => {
                let id = r.u16("schema id").ok()?;
                schemas.insert(id, r.string("schema name").ok()?);
            }
            OP_CHANNEL => {
                let id = r.u16("channel id").ok()?;
                let schema_id = r.u16("channel schema id").ok()?;
                let topic = r.string("channel topic").ok()?;
                let encoding = r.string("channel message encoding").ok()?;
                let ty = schemas.get(&schema_id).cloned().unwrap_or_else(|| encoding.clone());
                let imu = RosImuType::from_name(&ty).is_some() && (encoding == "cdr" || encoding == "ros1");
                channels.push((id, topic, ty, imu));
            }
            OP_STATISTICS => {
                let _messages = r.u64("message count").ok()?;
                let _schemas = r.u16("schema count").ok()?;
                let _channels = r.u32("channel count").ok()?;
                let _attachments = r.u32("attachment count").ok()?;
                let _metadata = r.u32("metadata count").ok()?;
                let _chunks = r.u32("chunk count").ok()?;
                let start = r.u64("message start time").ok()?;
                let end = r.u64("message end time").ok()?;
                let mut map = Fields { b: r.bytes32("channel message counts").ok()? };
                let mut by_channel = HashMap::new();
                while !map.b.is_empty() {
                    let id = map.u16("channel id").ok()?;
                    by_channel.insert(id, map.u64("message count").ok()?);
                }
                let ns = |t: u64| t.min(i64::MAX as u64) as i64;
                counts = Some((by_channel, ns(start), ns(end)));
            }
            _ => {}
        }
    }
    let (by_channel, start, end) = counts?;
    let mut topics: Vec<TopicInfo> = Vec::new();
    for (id, topic, ty, imu) in channels {
        let messages = by_channel.get(&id).copied().unwrap_or(0);
        match topics.iter_mut().find(|t| t.topic == topic && t.message_type == ty) {
            Some(t) => t.messages += messages,
            None => topics.push(TopicInfo {
                topic,
                message_type: ty,
                messages,
                imu,
                span_ns: (messages > 0).then_some((start, end)),
                stamps_ns: Vec::new(),
            }),
        }
    }
    Some(topics)
}

/// What a channel's messages are.
struct ChannelState {
    id: usize,
    kind: Option<(RosImuType, Encoding)>,
}

/// A schema: its type name and definition (encoding, text).
struct Schema {
    name: String,
    encoding: String,
    data: Vec<u8>,
}

/// A little-endian cursor over one record's bytes; every length is checked against what is left.
struct Fields<'a> {
    b: &'a [u8],
}

impl<'a> Fields<'a> {
    fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], String> {
        if n > self.b.len() as u64 {
            return Err(format!("{what}: length {n} exceeds the {} bytes left in the record", self.b.len()));
        }
        let (head, rest) = self.b.split_at(n as usize);
        self.b = rest;
        Ok(head)
    }
    fn u16(&mut self, what: &str) -> Result<u16, String> {
        let s = self.take(2, what)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let s = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(u64::from_le_bytes(a))
    }
    /// A record's opcode and length.
    fn u8_len(&mut self) -> Result<(u8, u64), String> {
        let op = self.take(1, "record opcode")?[0];
        Ok((op, self.u64("record length")?))
    }
    fn bytes32(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32(what)?;
        self.take(u64::from(n), what)
    }
    fn string(&mut self, what: &str) -> Result<String, String> {
        let b = self.bytes32(what)?;
        std::str::from_utf8(b).map(str::to_string).map_err(|_| format!("{what}: not UTF-8 text"))
    }
}

/// The state of one pass.
struct Pass<'p> {
    path: &'p Path,
    schemas: HashMap<u16, Schema>,
    channels: HashMap<u16, ChannelState>,
}

impl Pass<'_> {
    /// One record (`at`: its byte offset in the file, or the offset of its chunk).
    fn record(&mut self, c: &mut Collector, opcode: u8, data: &[u8], at: &str) -> Result<(), Stop> {
        let damaged = |what: String| Stop::Damaged { at: at.to_string(), what };
        let mut f = Fields { b: data };
        match opcode {
            OP_SCHEMA => {
                let id = f.u16("schema id").map_err(damaged)?;
                let name = f.string("schema name").map_err(damaged)?;
                let encoding = f.string("schema encoding").map_err(damaged)?;
                let data = f.bytes32("schema data").map_err(damaged)?.to_vec();
                self.schemas.insert(id, Schema { name, encoding, data });
            }
            OP_CHANNEL => {
                let id = f.u16("channel id").map_err(damaged)?;
                let schema_id = f.u16("channel schema id").map_err(damaged)?;
                let topic = f.string("channel topic").map_err(damaged)?;
                let message_encoding = f.string("channel message encoding").map_err(damaged)?;
                let schema = self.schemas.get(&schema_id);
                let ty = schema.map_or_else(|| message_encoding.clone(), |s| s.name.clone());
                let encoding = match message_encoding.as_str() {
                    "cdr" => Some(Encoding::Cdr),
                    "ros1" => Some(Encoding::Ros1),
                    _ => None,
                };
                let kind = RosImuType::from_name(&ty).zip(encoding);
                if let (Some((k, e)), Some(s)) = (kind, schema) {
                    if s.encoding == "ros2msg" || s.encoding == "ros1msg" {
                        let text = String::from_utf8_lossy(&s.data);
                        check_definition(k, e, &text).map_err(|why| {
                            DataError::new(
                                self.path,
                                format!(
                                    "topic '{}' ({}): its message definition differs from the {} layout gyrolab decodes: {why}; not read",
                                    crate::text::excerpt(&topic),
                                    crate::text::excerpt(&ty),
                                    k.name()
                                ),
                            )
                        })?;
                    }
                }
                let layout = kind.map(|(k, _)| k.layout());
                let cid = c.topic(&topic, &ty, layout, StampSource::Header);
                self.channels.insert(id, ChannelState { id: cid, kind });
            }
            OP_MESSAGE => {
                let channel = f.u16("message channel id").map_err(damaged)?;
                let _sequence = f.u32("message sequence").map_err(damaged)?;
                let log_time = f.u64("message log time").map_err(damaged)?;
                let _publish = f.u64("message publish time").map_err(damaged)?;
                let Some(ch) = self.channels.get(&channel) else {
                    return Err(damaged(format!("a message on channel {channel} that was never declared")));
                };
                let log_ns = log_time.min(i64::MAX as u64) as i64;
                match ch.kind {
                    Some((kind, encoding)) if c.decodes(ch.id) => {
                        let index = c.topics[ch.id].info.messages + 1;
                        let topic = || crate::text::excerpt(&c.topics[ch.id].info.topic);
                        let m = decode(kind, encoding, f.b).map_err(|e| {
                            DataError::new(self.path, format!("message {index} of topic '{}' ({at}): {e}", topic()))
                        })?;
                        let width = c.topics[ch.id].channels.len();
                        c.push_checked(self.path, ch.id, m.stamp_ns, log_ns, &m.values[..width], at)?;
                    }
                    _ => c.count(ch.id, log_ns),
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// A chunk record at byte `offset`: opened and its records read, or skipped when damaged.
    fn chunk(&mut self, c: &mut Collector, data: &[u8], offset: u64) -> Result<(), Stop> {
        let records = match open_chunk(data) {
            Ok(r) => r,
            Err(why) => {
                c.damaged_chunks.push((offset, why));
                return Ok(());
            }
        };
        let at = format!("the chunk at byte {offset}");
        let mut rest = &records[..];
        while !rest.is_empty() {
            let mut f = Fields { b: rest };
            let head = f.u8_len();
            let (opcode, len) = match head {
                Ok(h) => h,
                Err(why) => {
                    c.damaged_chunks.push((offset, why));
                    return Ok(());
                }
            };
            let body = match f.take(len, "record inside the chunk") {
                Ok(b) => b,
                Err(why) => {
                    c.damaged_chunks.push((offset, why));
                    return Ok(());
                }
            };
            match self.record(c, opcode, body, &at) {
                Err(Stop::Damaged { what, .. }) => {
                    c.damaged_chunks.push((offset, what));
                    return Ok(());
                }
                other => other?,
            }
            rest = f.b;
        }
        Ok(())
    }
}

/// The records of a chunk, decompressed, its sizes and CRC checked; the error says why not.
fn open_chunk(data: &[u8]) -> Result<Vec<u8>, String> {
    let mut f = Fields { b: data };
    let _start = f.u64("chunk start time")?;
    let _end = f.u64("chunk end time")?;
    let size = f.u64("chunk uncompressed size")?;
    let crc = f.u32("chunk CRC")?;
    let compression = f.string("chunk compression")?;
    let n = f.u64("chunk records length")?;
    let compressed = f.take(n, "chunk records")?;
    if size > MAX_RECORD_BYTES {
        return Err(format!(
            "declares {size} bytes uncompressed, more than the {MAX_RECORD_BYTES} this reader accepts"
        ));
    }
    let records = match compression.as_str() {
        "" => {
            if n != size {
                return Err(format!("uncompressed, but its size {size} differs from its {n} bytes of records"));
            }
            compressed.to_vec()
        }
        "zstd" => {
            // At most `size` bytes are written: a longer output is an error, not a larger buffer.
            let mut out = zstd::bulk::decompress(compressed, size as usize)
                .map_err(|e| format!("zstd data does not decompress to the declared {size} bytes ({e})"))?;
            out.shrink_to_fit();
            out
        }
        "lz4" => {
            let mut out = Vec::new();
            let mut d = lz4_flex::frame::FrameDecoder::new(compressed).take(size + 1);
            d.read_to_end(&mut out).map_err(|e| format!("lz4 data does not decompress ({e})"))?;
            out
        }
        other => return Err(format!("unknown compression '{}'", crate::text::excerpt(other))),
    };
    if records.len() as u64 != size {
        return Err(format!("decompresses to {} bytes where {size} were declared", records.len()));
    }
    if crc != 0 && crc32fast::hash(&records) != crc {
        return Err("its CRC does not match its content".into());
    }
    Ok(records)
}

/// Reads every message of an MCAP file (opened once, `size` bytes) into `c`.
pub(super) fn read(path: &Path, mut file: std::fs::File, size: u64, c: &mut Collector) -> Result<(), Stop> {
    let options = LinearReaderOptions::default()
        .with_emit_chunks(true)
        .with_skip_end_magic(true)
        .with_record_length_limit(MAX_RECORD_BYTES as usize);
    let mut reader = LinearReader::new_with_options(options);
    // Bytes given to the reader, and the offset of the next top-level record.
    let mut offset: u64 = 0;
    let mut record_at: u64 = 8;
    let mut pass = Pass { path, schemas: HashMap::new(), channels: HashMap::new() };
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| Stop::Damaged { at: format!("byte {record_at}"), what: mcap_error_text(&e) })?;
        match event {
            LinearReadEvent::ReadRequest(n) => {
                // A record longer than the rest of the file (cut off, or a damaged length) is
                // refused before the reader's buffer grows to it.
                if n as u64 > size.saturating_sub(offset) {
                    return Err(end_of(record_at, size));
                }
                if read_into(path, &mut file, &mut reader, n, &mut offset)? == 0 {
                    return Err(end_of(record_at, offset));
                }
            }
            LinearReadEvent::Record { data, opcode } => {
                let at = record_at;
                record_at += 9 + data.len() as u64;
                if opcode == OP_DATA_END {
                    // Every message is in the data section; the summary after it repeats
                    // schemas, channels and indexes, which this pass does not need.
                    break;
                }
                if opcode == OP_CHUNK {
                    let data = data.to_vec();
                    pass.chunk(c, &data, at)?;
                } else {
                    let data = data.to_vec();
                    pass.record(c, opcode, &data, &format!("byte {at}"))?;
                }
            }
        }
    }
    Ok(())
}

/// The stop at the end of the file inside a record.
fn end_of(record_at: u64, offset: u64) -> Stop {
    Stop::Damaged {
        at: format!("byte {record_at}"),
        what: format!("the record there runs past the end of the file at byte {offset}"),
    }
}

/// Reads up to `n` bytes of the file into the reader; returns how many.
fn read_into(
    path: &Path,
    file: &mut std::fs::File,
    reader: &mut LinearReader,
    n: usize,
    offset: &mut u64,
) -> Result<usize, Stop> {
    let buf = reader.insert(n);
    let read = loop {
        match file.read(buf) {
            Ok(k) => break k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(DataError::io(path, &e).into()),
        }
    };
    *offset += read as u64;
    reader.notify_read(read);
    Ok(read)
}

/// The `mcap` crate's error in words (no type names).
fn mcap_error_text(e: &mcap::McapError) -> String {
    use mcap::McapError as E;
    match e {
        E::BadMagic => "not an MCAP file: the magic bytes are missing or wrong".into(),
        E::RecordTooLarge { opcode, len } => format!(
            "a record (opcode 0x{opcode:02x}) declares {len} bytes, more than the {MAX_RECORD_BYTES} this reader accepts"
        ),
        E::ChunkTooLarge(len) => {
            format!("a chunk declares {len} bytes, more than the {MAX_RECORD_BYTES} this reader accepts")
        }
        E::UnexpectedEof => "the file ends inside a record".into(),
        other => crate::text::short_message(&other.to_string()),
    }
}
