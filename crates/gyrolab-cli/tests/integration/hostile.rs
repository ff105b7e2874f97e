//! Damaged and hostile recordings (issue 31): every length at its maximum, counts at 2^31,
//! leaping stamps, message definitions that differ from the decoder's layout, damaged chunks,
//! FIFOs. Each ends with exit 2 and a located message in words, or exit 0 and the figures of
//! the intact part (checked against the same messages written without the damage).
//!
//! The files are written here byte by byte from the published formats (mcap.dev "MCAP Format
//! Specification", ROS wiki "Bags/Format/2.0", docs.px4.io "ULog File Format", the Thrift
//! compact protocol of parquet-format), not by gyrolab's code. `GYROLAB_HOSTILE_DIR=DIR` keeps
//! them in DIR (scripts/test_hostile_ulimit.sh runs the binary on them under `ulimit -v`).

use crate::common;
use common::gyrolab;
use std::path::{Path, PathBuf};

const T0_NS: u64 = 1_700_000_000_000_000_000;
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Where the files go.
fn dir() -> PathBuf {
    let d = match std::env::var_os("GYROLAB_HOSTILE_DIR") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_TARGET_TMPDIR")).join("hostile"),
    };
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn put(name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The simulated gyro/accel values of message i (deterministic, a few mrad/s of noise).
fn sample(i: u64) -> [f64; 6] {
    let x = |k: u64| ((i * 7919 + k * 104_729) % 1000) as f64 * 1e-6 - 5e-4;
    [x(1), x(2), x(3), 0.1 + x(4), 0.2 + x(5), 9.81 + x(6)]
}

// ---------------------------------------------------------------------------------------------
// MCAP

fn s32(b: &mut Vec<u8>, s: &[u8]) {
    b.extend_from_slice(&(s.len() as u32).to_le_bytes());
    b.extend_from_slice(s);
}

fn record(op: u8, body: &[u8]) -> Vec<u8> {
    let mut r = vec![op];
    r.extend_from_slice(&(body.len() as u64).to_le_bytes());
    r.extend_from_slice(body);
    r
}

const IMU_DEF: &str = "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n================================================================================\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n================================================================================\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n================================================================================\nMSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n================================================================================\nMSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";

fn schema(def: &str) -> Vec<u8> {
    let mut b = 1u16.to_le_bytes().to_vec();
    s32(&mut b, b"sensor_msgs/msg/Imu");
    s32(&mut b, b"ros2msg");
    s32(&mut b, def.as_bytes());
    record(0x03, &b)
}

fn channel() -> Vec<u8> {
    let mut b = 1u16.to_le_bytes().to_vec();
    b.extend_from_slice(&1u16.to_le_bytes());
    s32(&mut b, b"/imu");
    s32(&mut b, b"cdr");
    b.extend_from_slice(&0u32.to_le_bytes()); // metadata: empty map
    record(0x04, &b)
}

/// A CDR sensor_msgs/msg/Imu (little-endian; alignment counted after the 4-byte encapsulation).
fn cdr_imu(stamp_ns: u64, v: [f64; 6]) -> Vec<u8> {
    let mut b = vec![0u8, 1, 0, 0];
    b.extend_from_slice(&((stamp_ns / 1_000_000_000) as i32).to_le_bytes());
    b.extend_from_slice(&((stamp_ns % 1_000_000_000) as u32).to_le_bytes());
    s32(&mut b, b"imu\0");
    while (b.len() - 4) % 8 != 0 {
        b.push(0);
    }
    let all = [0.0, 0.0, 0.0, 1.0].into_iter().chain([0.0; 9]).chain(v[..3].iter().copied()).chain([0.0; 9]);
    for x in all.chain(v[3..].iter().copied()).chain([0.0; 9]) {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b
}

fn message(stamp_ns: u64, log_ns: u64, v: [f64; 6]) -> Vec<u8> {
    let mut b = 1u16.to_le_bytes().to_vec();
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&log_ns.to_le_bytes());
    b.extend_from_slice(&log_ns.to_le_bytes());
    b.extend_from_slice(&cdr_imu(stamp_ns, v));
    record(0x05, &b)
}

fn header() -> Vec<u8> {
    let mut b = Vec::new();
    s32(&mut b, b"ros2");
    s32(&mut b, b"hostile.rs");
    record(0x01, &b)
}

/// An uncompressed chunk of `records` (CRC 0: not checked).
fn chunk(records: &[u8]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend_from_slice(&(records.len() as u64).to_le_bytes());
    b.extend_from_slice(&0u32.to_le_bytes());
    s32(&mut b, b"");
    b.extend_from_slice(&(records.len() as u64).to_le_bytes());
    b.extend_from_slice(records);
    record(0x06, &b)
}

fn mcap_end() -> Vec<u8> {
    let mut b = record(0x0F, &0u32.to_le_bytes());
    let mut f = 0u64.to_le_bytes().to_vec();
    f.extend_from_slice(&0u64.to_le_bytes());
    f.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&record(0x02, &f));
    b.extend_from_slice(MCAP_MAGIC);
    b
}

/// An MCAP file: header, schema (`def`), channel, then `body`, then data end and footer.
fn mcap(def: &str, body: &[u8]) -> Vec<u8> {
    let mut b = MCAP_MAGIC.to_vec();
    b.extend_from_slice(&header());
    b.extend_from_slice(&schema(def));
    b.extend_from_slice(&channel());
    b.extend_from_slice(body);
    b.extend_from_slice(&mcap_end());
    b
}

/// `n` messages at 100 Hz from `T0_NS`, stamps from `stamp(i)`.
fn messages(range: std::ops::Range<u64>, stamp: impl Fn(u64) -> u64) -> Vec<u8> {
    range.flat_map(|i| message(stamp(i), T0_NS + i * 10_000_000, sample(i))).collect()
}

/// Runs gyrolab; (exit code, stdout, stderr).
fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = gyrolab().args(args).timeout(std::time::Duration::from_secs(60)).output().unwrap();
    let (o, e) = (String::from_utf8_lossy(&out.stdout).to_string(), String::from_utf8_lossy(&out.stderr).to_string());
    assert!(!e.contains("panicked") && !e.contains("memory allocation"), "{args:?}: {e}");
    (out.status.code(), o, e)
}

/// Exit 2 with a message holding every one of `words`, in plain words (no Rust debug text).
fn refused(args: &[&str], words: &[&str]) {
    let (code, _, err) = run(args);
    assert_eq!(code, Some(2), "{args:?}: {err}");
    for w in words {
        assert!(err.contains(w), "{args:?}: '{w}' not in: {err}");
    }
    plain(&err);
}

fn plain(err: &str) {
    // One line per message: no multi-line dumps of a parser's state.
    for line in err.lines() {
        assert!(!line.trim_start().starts_with(['(', ')', '{', '}']), "a dump in: {err}");
    }
    for debug in ["Error {", "Error:", "{ ", "UlogParseError", "FlattenedFormat", "os error", "rosbag::", "McapError"] {
        assert!(!err.contains(debug), "debug text '{debug}' in: {err}");
    }
}

/// The Allan deviations of `allan --json` (every channel, every tau), to compare figures.
fn deviations(path: &Path) -> Vec<f64> {
    let (code, out, err) = run(&["allan", path.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let all: Vec<f64> = v["channels"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|c| c["dev"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
        .collect();
    assert!(all.len() >= 6 * 5, "too few deviations in {out}");
    all
}

#[test]
fn a_valid_hand_written_mcap_is_read() {
    let p = put("valid.mcap", &mcap(IMU_DEF, &messages(0..400, |i| T0_NS + i * 10_000_000)));
    let (code, _, err) = run(&["allan", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn mcap_lengths_at_their_maximum_are_located_errors() {
    // A Header record of length 2^63.
    let mut b = MCAP_MAGIC.to_vec();
    b.push(0x01);
    b.extend_from_slice(&(1u64 << 63).to_le_bytes());
    b.extend_from_slice(&[0; 8]);
    let p = put("mcap_header_2_63.mcap", &b);
    refused(&["allan", p.to_str().unwrap()], &["at byte 8", "9223372036854775808 bytes"]);
    // A chunk of length 2^40 after a valid header.
    let mut b = MCAP_MAGIC.to_vec();
    b.extend_from_slice(&header());
    let at = b.len();
    b.push(0x06);
    b.extend_from_slice(&(1u64 << 40).to_le_bytes());
    b.extend_from_slice(&[0; 64]);
    let p = put("mcap_chunk_2_40.mcap", &b);
    refused(&["allan", p.to_str().unwrap()], &[&format!("at byte {at}"), "1099511627776 bytes"]);
    // A schema name of length 0xFFFFFFF0 in a short record.
    let mut s = 1u16.to_le_bytes().to_vec();
    s.extend_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    s.extend_from_slice(b"sensor_msgs/msg/Imu");
    let mut b = MCAP_MAGIC.to_vec();
    b.extend_from_slice(&header());
    let at = b.len();
    b.extend_from_slice(&record(0x03, &s));
    b.extend_from_slice(&mcap_end());
    let p = put("mcap_schema_name.mcap", &b);
    refused(&["allan", p.to_str().unwrap()], &[&format!("at byte {at}"), "schema name: length 4294967280"]);
    // A chunk declaring 2^40 bytes uncompressed (zstd): refused, not decompressed.
    let mut c = Vec::new();
    c.extend_from_slice(&[0; 16]);
    c.extend_from_slice(&(1u64 << 40).to_le_bytes());
    c.extend_from_slice(&0u32.to_le_bytes());
    s32(&mut c, b"zstd");
    c.extend_from_slice(&4u64.to_le_bytes());
    c.extend_from_slice(&[0x28, 0xb5, 0x2f, 0xfd]);
    let mut b = MCAP_MAGIC.to_vec();
    b.extend_from_slice(&header());
    let at = b.len();
    b.extend_from_slice(&record(0x06, &c));
    b.extend_from_slice(&mcap_end());
    let p = put("mcap_chunk_uncompressed_2_40.mcap", &b);
    refused(&["allan", p.to_str().unwrap()], &["no IMU messages"]);
    let (code, out, err) = run(&["inspect", p.to_str().unwrap()]);
    assert!(code == Some(0) || code == Some(2), "{out}{err}");
    let _ = at;
}

#[test]
fn random_bytes_after_the_magic_are_an_error_not_a_panic() {
    // A linear congruential generator: the same bytes every run.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut b = MCAP_MAGIC.to_vec();
    for _ in 0..(1 << 20) {
        x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        b.push((x >> 56) as u8);
    }
    let p = put("mcap_random.mcap", &b);
    for cmd in ["allan", "inspect"] {
        let (code, _, err) = run(&[cmd, p.to_str().unwrap()]);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains("at byte 8"), "{err}");
        plain(&err);
    }
}

#[test]
fn a_damaged_chunk_is_skipped_and_the_others_are_read() {
    // Three chunks of 200 messages; the middle one's data overwritten with a wrong length.
    let chunks: Vec<Vec<u8>> =
        (0..3).map(|k| chunk(&messages(k * 200..(k + 1) * 200, |i| T0_NS + i * 10_000_000))).collect();
    let mut body = chunks[0].clone();
    let at = MCAP_MAGIC.len() + header().len() + schema(IMU_DEF).len() + channel().len() + body.len();
    let mut bad = chunks[1].clone();
    // The first record inside the chunk: its length (after 9 + 44 bytes of chunk header and
    // the opcode) set past the chunk's end.
    bad[9 + 44 + 1..9 + 44 + 9].copy_from_slice(&u64::MAX.to_le_bytes());
    body.extend_from_slice(&bad);
    body.extend_from_slice(&chunks[2]);
    let damaged = put("mcap_damaged_chunk.mcap", &mcap(IMU_DEF, &body));
    let (code, _, err) = run(&["allan", damaged.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains(&format!("1 damaged chunk skipped (the first at byte {at}")), "{err}");
    // The figures are those of the two intact chunks (message 200 to 399 missing: a gap).
    let mut intact = chunks[0].clone();
    intact.extend_from_slice(&chunks[2]);
    let intact = put("mcap_intact_chunks.mcap", &mcap(IMU_DEF, &intact));
    assert_eq!(deviations(&damaged), deviations(&intact));
}

#[test]
fn leaping_stamps_never_size_an_allocation() {
    // One stamp far in the future (2^62 ns, year 2116), in the middle of 1000 messages.
    let p = put(
        "mcap_future_stamp.mcap",
        &mcap(IMU_DEF, &messages(0..1000, |i| if i == 500 { 1 << 62 } else { T0_NS + i * 10_000_000 })),
    );
    refused(&["allan", p.to_str().unwrap()], &["the time stamps leap", "more than the record's 1000 samples"]);
    // Header stamps on a since-boot clock (from 100 s), one of them zero: the log time (epoch,
    // 2023) stands in for it, 54 years later.
    let p = put(
        "mcap_zero_stamp.mcap",
        &mcap(IMU_DEF, &messages(0..1000, |i| if i == 300 { 0 } else { 100_000_000_000 + i * 10_000_000 })),
    );
    refused(&["allan", p.to_str().unwrap()], &["the time stamps leap"]);
    // A clock that jumps forward by a day in the middle: refused the same way.
    let p = put(
        "mcap_day_jump.mcap",
        &mcap(IMU_DEF, &messages(0..1000, |i| T0_NS + i * 10_000_000 + if i >= 700 { 86_400_000_000_000 } else { 0 })),
    );
    refused(&["allan", p.to_str().unwrap()], &["the time stamps leap"]);
    // A negative header stamp (sec = -1, a clock before 1970): refused the same way, located.
    let mut body = Vec::new();
    for i in 0..1000u64 {
        let mut m = message(T0_NS + i * 10_000_000, T0_NS + i * 10_000_000, sample(i));
        if i == 500 {
            // opcode, length, channel id, sequence, log time, publish time, CDR encapsulation.
            m[35..39].copy_from_slice(&(-1i32).to_le_bytes());
        }
        body.extend(m);
    }
    let p = put("mcap_negative_stamp.mcap", &mcap(IMU_DEF, &body));
    let (code, _, err) = run(&["allan", p.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    plain(&err);
    assert!(err.contains("mcap_negative_stamp.mcap"), "{err}");
    assert!(err.contains("counted in time-stamp order: 1 of the topic's messages came out of order"), "{err}");
    // A short dropout (50 messages of 1000) is still a gap filled on the grid: exit 0.
    let p = put(
        "mcap_short_gap.mcap",
        &mcap(
            IMU_DEF,
            &[messages(0..400, |i| T0_NS + i * 10_000_000), messages(450..1000, |i| T0_NS + i * 10_000_000)].concat(),
        ),
    );
    let (code, _, err) = run(&["allan", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn definitions_that_differ_from_the_decoder_are_refused_with_the_field() {
    let f32 = IMU_DEF.replace(
        "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z",
        "MSG: geometry_msgs/Vector3\nfloat32 x\nfloat32 y\nfloat32 z",
    );
    let p = put("mcap_float32.mcap", &mcap(&f32, &messages(0..100, |i| T0_NS + i * 10_000_000)));
    refused(&["allan", p.to_str().unwrap()], &["geometry_msgs/Vector3", "'float32 x'", "'float64 x'"]);
    let swapped = IMU_DEF
        .replace("geometry_msgs/Vector3 angular_velocity\n", "geometry_msgs/Vector3 @@\n")
        .replace("geometry_msgs/Vector3 linear_acceleration\n", "geometry_msgs/Vector3 angular_velocity\n")
        .replace("geometry_msgs/Vector3 @@\n", "geometry_msgs/Vector3 linear_acceleration\n");
    let p = put("mcap_reordered.mcap", &mcap(&swapped, &messages(0..100, |i| T0_NS + i * 10_000_000)));
    refused(&["allan", p.to_str().unwrap()], &["field 4 of sensor_msgs/msg/Imu", "linear_acceleration"]);
}

#[test]
fn values_beyond_the_float_range_are_errors_with_their_message() {
    let body: Vec<u8> = (0..100u64)
        .flat_map(|i| {
            let mut v = sample(i);
            if i == 41 {
                v[1] = 1e308;
            }
            message(T0_NS + i * 10_000_000, T0_NS + i * 10_000_000, v)
        })
        .collect();
    let p = put("mcap_1e308.mcap", &mcap(IMU_DEF, &body));
    refused(&["allan", p.to_str().unwrap()], &["message 42 of topic '/imu'", "gyro_y_rad_s is 1e308"]);
}

// ---------------------------------------------------------------------------------------------
// Non-regular files

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_before_it_is_opened() {
    let p = dir().join("imu.fifo");
    let _ = std::fs::remove_file(&p);
    let st = std::process::Command::new("mkfifo").arg(&p).status().unwrap();
    assert!(st.success());
    // No writer: an open would block; the check refuses it first (the 60 s timeout of `run`).
    for cmd in ["allan", "inspect", "bias", "convert"] {
        let mut args = vec![cmd, p.to_str().unwrap()];
        let out = dir().join("fifo_out.csv");
        if cmd == "convert" {
            args.extend(["--out", out.to_str().unwrap()]);
        }
        let (code, _, err) = run(&args);
        assert_eq!(code, Some(2), "{cmd}: {err}");
        assert!(err.contains("a FIFO (named pipe), not a regular file"), "{cmd}: {err}");
    }
}

// ---------------------------------------------------------------------------------------------
// ROS 1 bags

/// A bag record: header fields and data.
fn bag_record(fields: &[(&str, &[u8])], data: &[u8]) -> Vec<u8> {
    let mut h = Vec::new();
    for (k, v) in fields {
        let mut f = format!("{k}=").into_bytes();
        f.extend_from_slice(v);
        s32(&mut h, &f);
    }
    let mut r = Vec::new();
    s32(&mut r, &h);
    s32(&mut r, data);
    r
}

const IMU_MD5: &str = "6a62c6daae103f4ff57a132d6f95cec2";
const ROS1_IMU_DEF: &str = "Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n================================================================================\nMSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n================================================================================\nMSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n================================================================================\nMSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";

fn ros1_imu(stamp_ns: u64, v: [f64; 6]) -> Vec<u8> {
    let mut b = 0u32.to_le_bytes().to_vec();
    b.extend_from_slice(&((stamp_ns / 1_000_000_000) as u32).to_le_bytes());
    b.extend_from_slice(&((stamp_ns % 1_000_000_000) as u32).to_le_bytes());
    s32(&mut b, b"imu");
    let all = [0.0, 0.0, 0.0, 1.0].into_iter().chain([0.0; 9]).chain(v[..3].iter().copied()).chain([0.0; 9]);
    for x in all.chain(v[3..].iter().copied()).chain([0.0; 9]) {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b
}

/// A bag of one uncompressed chunk (its `size` field given), connection (md5, definition), and
/// `n` messages; the index section is empty (gyrolab reads the chunks in order).
fn bag(md5: &str, def: &str, n: u64, size: Option<u32>) -> Vec<u8> {
    let mut conn_data = Vec::new();
    for (k, v) in [("topic", "/imu"), ("type", "sensor_msgs/Imu"), ("md5sum", md5), ("message_definition", def)] {
        s32(&mut conn_data, format!("{k}={v}").as_bytes());
    }
    let mut inner = bag_record(&[("op", &[0x07]), ("conn", &0u32.to_le_bytes()), ("topic", b"/imu")], &conn_data);
    for i in 0..n {
        let t = T0_NS + i * 10_000_000;
        let mut time = ((t / 1_000_000_000) as u32).to_le_bytes().to_vec();
        time.extend_from_slice(&((t % 1_000_000_000) as u32).to_le_bytes());
        inner.extend(bag_record(
            &[("op", &[0x02]), ("conn", &0u32.to_le_bytes()), ("time", &time)],
            &ros1_imu(t, sample(i)),
        ));
    }
    let size = size.unwrap_or(inner.len() as u32);
    let chunk = bag_record(&[("op", &[0x05]), ("compression", b"none"), ("size", &size.to_le_bytes())], &inner);
    let head_len = 13 + 4096 + 8;
    let index_pos = (head_len + chunk.len()) as u64;
    let mut head = bag_record(
        &[
            ("op", &[0x03]),
            ("index_pos", &index_pos.to_le_bytes()),
            ("conn_count", &1u32.to_le_bytes()),
            ("chunk_count", &1u32.to_le_bytes()),
        ],
        &[],
    );
    // The bag header record is padded to 4096 bytes of header + data.
    let hl = u32::from_le_bytes(head[..4].try_into().unwrap()) as usize;
    head.truncate(4 + hl);
    let pad = 4096 - hl;
    head.extend_from_slice(&(pad as u32).to_le_bytes());
    head.extend(std::iter::repeat_n(b' ', pad));
    let mut b = b"#ROSBAG V2.0\n".to_vec();
    b.extend_from_slice(&head);
    assert_eq!(b.len(), head_len);
    b.extend_from_slice(&chunk);
    b
}

#[test]
fn ros1_bags_hostile_sizes_and_definitions() {
    let p = put("valid.bag", &bag(IMU_MD5, ROS1_IMU_DEF, 300, None));
    let (code, _, err) = run(&["allan", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    // A chunk declaring 4 GiB uncompressed: skipped with its byte offset; nothing else: exit 2.
    let p = put("bag_chunk_4gib.bag", &bag(IMU_MD5, ROS1_IMU_DEF, 300, Some(u32::MAX)));
    refused(&["allan", p.to_str().unwrap()], &["no IMU messages"]);
    // float32 vectors: md5sum and definition differ; the field is named.
    let f32 = ROS1_IMU_DEF.replace("MSG: geometry_msgs/Vector3\nfloat64 x", "MSG: geometry_msgs/Vector3\nfloat32 x");
    let p = put("bag_float32.bag", &bag("0123456789abcdef0123456789abcdef", &f32, 300, None));
    refused(&["allan", p.to_str().unwrap()], &["md5sum 0123456789abcdef0123456789abcdef", "'float32 x'"]);
    // The standard definition with a wrong md5sum: refused too.
    let p = put("bag_md5.bag", &bag("0123456789abcdef0123456789abcdef", ROS1_IMU_DEF, 300, None));
    refused(&["allan", p.to_str().unwrap()], &["is not that of the sensor_msgs/msg/Imu layout"]);
}

// ---------------------------------------------------------------------------------------------
// PX4 ULog

/// A ULog message: size u16, type, body.
fn ulog_msg(kind: u8, body: &[u8]) -> Vec<u8> {
    let mut m = (body.len() as u16).to_le_bytes().to_vec();
    m.push(kind);
    m.extend_from_slice(body);
    m
}

/// A ULog file (version 1, flag bits, one format) with `format`, a subscription of it as
/// msg_id 0, and data messages.
fn ulog(format: &str, data: &[Vec<u8>]) -> Vec<u8> {
    let mut b = b"ULog\x01\x12\x35\x01".to_vec();
    b.extend_from_slice(&0u64.to_le_bytes());
    b.extend(ulog_msg(b'B', &[0u8; 40]));
    b.extend(ulog_msg(b'F', format.as_bytes()));
    let mut add = vec![0u8];
    add.extend_from_slice(&0u16.to_le_bytes());
    add.extend_from_slice(format.split(':').next().unwrap().as_bytes());
    b.extend(ulog_msg(b'A', &add));
    for d in data {
        let mut m = 0u16.to_le_bytes().to_vec();
        m.extend_from_slice(d);
        b.extend(ulog_msg(b'D', &m));
    }
    b
}

const SENSOR_GYRO: &str = "sensor_gyro:uint64_t timestamp;uint64_t timestamp_sample;float x;float y;float z;";

fn gyro_data(t_us: u64, v: [f32; 3]) -> Vec<u8> {
    let mut d = t_us.to_le_bytes().to_vec();
    d.extend_from_slice(&t_us.to_le_bytes());
    for x in v {
        d.extend_from_slice(&x.to_le_bytes());
    }
    d
}

#[test]
fn ulog_stamps_near_1e18_us_and_damaged_definitions_are_clear() {
    let ok: Vec<Vec<u8>> = (0..300u64).map(|i| gyro_data(1_000_000 + i * 5000, [0.001, 0.002, 0.003])).collect();
    let p = put("valid.ulg", &ulog(SENSOR_GYRO, &ok));
    let (code, _, err) = run(&["allan", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    // Stamps near 1e18 us that increase: beyond the nanosecond range, said so.
    let far: Vec<Vec<u8>> =
        (0..300u64).map(|i| gyro_data(1_000_000_000_000_000_000 + i * 5000, [0.001, 0.002, 0.003])).collect();
    let p = put("ulog_1e18.ulg", &ulog(SENSOR_GYRO, &far));
    refused(
        &["allan", p.to_str().unwrap()],
        &["message 1 of topic 'sensor_gyro'", "beyond the range of nanosecond stamps"],
    );
    // Damaged definitions: an array of 2^31, a format without a colon, an undefined type, a
    // self-referencing format. Each: exit 2, words only.
    for (name, format) in [
        ("ulog_array_2_31.ulg", "sensor_gyro:uint64_t timestamp;float[2147483648] x;"),
        ("ulog_no_colon.ulg", "sensor_gyro uint64_t timestamp;float x;"),
        ("ulog_undefined_type.ulg", "sensor_gyro:uint64_t timestamp;nosuch_t x;"),
        ("ulog_self_reference.ulg", "sensor_gyro:uint64_t timestamp;sensor_gyro inner;"),
    ] {
        let p = put(name, &ulog(format, &ok));
        let (code, _, err) = run(&["allan", p.to_str().unwrap()]);
        assert_eq!(code, Some(2), "{name}: {err}");
        plain(&err);
    }
    // Cut inside the last message: a warning naming the byte where the file ends.
    let whole = ulog(SENSOR_GYRO, &ok);
    let p = put("ulog_cut.ulg", &whole[..whole.len() - 7]);
    let (code, _, err) = run(&["allan", p.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains(&format!("the file ends at byte {}", whole.len() - 7)), "{err}");
}

// ---------------------------------------------------------------------------------------------
// Parquet

/// A Parquet file whose footer's schema holds a root declaring `children` (Thrift compact:
/// FileMetaData{1: version i32, 2: schema list<SchemaElement{4: name, 5: num_children}>}).
fn parquet_children(children: i32) -> Vec<u8> {
    let mut f = vec![0x15, 0x02]; // field 1, i32, zigzag(1)
    f.push(0x19); // field 2 (delta 1), list
    f.push(0x1c); // 1 element of struct
    f.push(0x48); // field 4 (delta 4), binary
    f.push(4);
    f.extend_from_slice(b"root");
    f.push(0x15); // field 5, i32
    let mut z = ((children << 1) ^ (children >> 31)) as u32;
    loop {
        let b = (z & 0x7f) as u8;
        z >>= 7;
        if z == 0 {
            f.push(b);
            break;
        }
        f.push(b | 0x80);
    }
    f.push(0); // end of element
    f.push(0); // end of FileMetaData
    let mut b = b"PAR1".to_vec();
    b.extend_from_slice(&f);
    b.extend_from_slice(&(f.len() as u32).to_le_bytes());
    b.extend_from_slice(b"PAR1");
    b
}

#[test]
fn a_parquet_schema_with_2_30_children_is_refused_before_allocation() {
    let p = put("parquet_2_30_children.parquet", &parquet_children(1 << 30));
    refused(&["allan", p.to_str().unwrap()], &["schema element 1 declares 1073741824 children"]);
    let mut b = parquet_children(0);
    let n = b.len();
    b[n - 8..n - 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = put("parquet_footer_4gib.parquet", &b);
    refused(&["allan", p.to_str().unwrap()], &["the footer declares 4294967295 bytes"]);
}

/// A ULog file of `head` messages (flag bits, formats, info, subscriptions; as given) and
/// `data` messages of msg_id 0.
fn ulog_raw(head: &[Vec<u8>], data: &[Vec<u8>]) -> Vec<u8> {
    let mut b = b"ULog\x01\x12\x35\x01".to_vec();
    b.extend_from_slice(&0u64.to_le_bytes());
    for m in head {
        b.extend_from_slice(m);
    }
    for d in data {
        let mut m = 0u16.to_le_bytes().to_vec();
        m.extend_from_slice(d);
        b.extend(ulog_msg(b'D', &m));
    }
    b
}

fn ulog_subscription(msg_id: u16, name: &str) -> Vec<u8> {
    let mut add = vec![0u8];
    add.extend_from_slice(&msg_id.to_le_bytes());
    add.extend_from_slice(name.as_bytes());
    ulog_msg(b'A', &add)
}

#[test]
fn damaged_ulog_headers_and_definitions_are_messages_in_words() {
    let ok: Vec<Vec<u8>> = (0..300u64).map(|i| gyro_data(1_000_000 + i * 5000, [0.001, 0.002, 0.003])).collect();
    let flags = |incompat0: u8| {
        let mut f = [0u8; 40];
        f[8] = incompat0;
        ulog_msg(b'B', &f)
    };
    let gyro = || ulog_msg(b'F', SENSOR_GYRO.as_bytes());
    let mut info_overflow = vec![255u8];
    info_overflow.extend_from_slice(b"char[4] ab");
    let cases: Vec<(&str, Vec<Vec<u8>>)> = vec![
        ("ulog_flag_size.ulg", vec![ulog_msg(b'B', &[0u8; 10]), gyro(), ulog_subscription(0, "sensor_gyro")]),
        ("ulog_incompat_flag.ulg", vec![flags(0x80), gyro(), ulog_subscription(0, "sensor_gyro")]),
        (
            "ulog_key_overflow.ulg",
            vec![flags(0), ulog_msg(b'I', &info_overflow), gyro(), ulog_subscription(0, "sensor_gyro")],
        ),
        (
            "ulog_mutual_reference.ulg",
            vec![
                flags(0),
                ulog_msg(b'F', b"alpha:uint64_t timestamp;beta inner;"),
                ulog_msg(b'F', b"beta:uint64_t timestamp;alpha inner;"),
                gyro(),
                ulog_subscription(0, "sensor_gyro"),
                ulog_subscription(1, "alpha"),
            ],
        ),
        (
            "ulog_nested_size.ulg",
            vec![
                flags(0),
                ulog_msg(b'F', b"inner:uint64_t[65535] x;"),
                ulog_msg(b'F', b"middle:inner[65535] y;"),
                ulog_msg(b'F', b"outer:middle[65535] z;"),
                gyro(),
                ulog_subscription(0, "sensor_gyro"),
                ulog_subscription(1, "outer"),
            ],
        ),
        (
            "ulog_duplicate_msg_id.ulg",
            vec![
                flags(0),
                gyro(),
                ulog_msg(b'F', b"other:uint64_t timestamp;float v;"),
                ulog_subscription(0, "sensor_gyro"),
                ulog_subscription(0, "other"),
            ],
        ),
    ];
    for (name, head) in cases {
        let p = put(name, &ulog_raw(&head, &ok));
        for cmd in ["allan", "inspect"] {
            let (code, out, err) = run(&[cmd, p.to_str().unwrap()]);
            assert!(code == Some(2) || code == Some(0), "{name} {cmd}: {out}{err}");
            plain(&err);
            plain(&out);
            if code == Some(2) {
                assert!(err.contains(name), "{name} {cmd}: the file is not named: {err}");
            }
        }
    }
}

#[test]
fn a_stamp_far_in_the_future_in_a_bag_or_a_ulog_sizes_nothing() {
    // ULog: one sample stamp at 2^62 us... beyond nanoseconds; one at 2^50 us (35 years).
    let data: Vec<Vec<u8>> = (0..1000u64)
        .map(|i| gyro_data(if i == 500 { 1 << 50 } else { 1_000_000 + i * 5000 }, [0.001, 0.002, 0.003]))
        .collect();
    let p = put("ulog_future_stamp.ulg", &ulog(SENSOR_GYRO, &data));
    refused(&["allan", p.to_str().unwrap()], &["the time stamps leap"]);
    // ROS 1 bag: the header stamp of message 150 in 2106 (u32 seconds at their maximum).
    let mut b = bag(IMU_MD5, ROS1_IMU_DEF, 300, None);
    let needle = ros1_imu(T0_NS + 150 * 10_000_000, sample(150));
    let at = b.windows(needle.len()).position(|w| w == needle.as_slice()).unwrap();
    b[at + 4..at + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = put("bag_future_stamp.bag", &b);
    refused(&["allan", p.to_str().unwrap()], &["the time stamps leap"]);
}

#[test]
fn counts_at_2_31_are_refused_before_allocation() {
    // An MCAP channel whose metadata map declares 2^31 bytes.
    let mut ch = 1u16.to_le_bytes().to_vec();
    ch.extend_from_slice(&1u16.to_le_bytes());
    s32(&mut ch, b"/imu");
    s32(&mut ch, b"cdr");
    ch.extend_from_slice(&(1u32 << 31).to_le_bytes());
    let mut b = MCAP_MAGIC.to_vec();
    b.extend_from_slice(&header());
    b.extend_from_slice(&schema(IMU_DEF));
    b.extend_from_slice(&record(0x04, &ch));
    b.extend_from_slice(&messages(0..100, |i| T0_NS + i * 10_000_000));
    b.extend_from_slice(&mcap_end());
    let p = put("mcap_metadata_2_31.mcap", &b);
    let (code, out, err) = run(&["allan", p.to_str().unwrap()]);
    plain(&err);
    // Read (the metadata is not needed; the messages are whole): the figures of the same
    // messages in a valid file.
    assert_eq!(code, Some(0), "{out}{err}");
    let valid = put("valid_100.mcap", &mcap(IMU_DEF, &messages(0..100, |i| T0_NS + i * 10_000_000)));
    assert_eq!(deviations(&p), deviations(&valid));
    // A bag whose header declares 2^31 connections and chunks.
    let mut b = bag(IMU_MD5, ROS1_IMU_DEF, 300, None);
    for key in [&b"conn_count="[..], &b"chunk_count="[..]] {
        let at = b.windows(key.len()).position(|w| w == key).unwrap() + key.len();
        b[at..at + 4].copy_from_slice(&(1u32 << 31).to_le_bytes());
    }
    let p = put("bag_counts_2_31.bag", &b);
    let (code, out, err) = run(&["allan", p.to_str().unwrap(), "--json"]);
    assert!(code == Some(0) || code == Some(2), "{out}{err}");
    plain(&err);
    // A ULog format whose array holds 2^31 - 1 elements of 8 bytes.
    let p = put("ulog_array_2_31_u64.ulg", &ulog("sensor_gyro:uint64_t timestamp;uint64_t[2147483647] x;", &[]));
    let (code, out, err) = run(&["allan", p.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{out}{err}");
    plain(&err);
}
