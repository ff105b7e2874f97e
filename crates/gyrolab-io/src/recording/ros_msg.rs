//! The IMU messages of ROS: `sensor_msgs/Imu` and `geometry_msgs/Vector3Stamped`, in ROS 2's
//! CDR (through the `cdr` crate) and in ROS 1's serialization (little-endian, packed, strings
//! with a length prefix: ROS wiki "roscpp/Overview/MessagesSerializationAndAdaptingTypes").
//!
//! Field order and types: `sensor_msgs/msg/Imu` = header (stamp: int32 sec, uint32 nanosec;
//! frame_id: string; ROS 1 adds uint32 seq first), orientation (4 float64),
//! orientation_covariance (9 float64), angular_velocity (3 float64, rad/s),
//! angular_velocity_covariance (9), linear_acceleration (3 float64, m/s^2),
//! linear_acceleration_covariance (9).

use serde::Deserialize;

/// How a message's bytes are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// ROS 2: OMG CDR with its 4-byte encapsulation header.
    Cdr,
    /// ROS 1 serialization.
    Ros1,
}

/// The IMU message types gyrolab reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RosImuType {
    /// `sensor_msgs/Imu`: gyro (rad/s) and accelerometer (m/s^2).
    Imu,
    /// `geometry_msgs/Vector3Stamped`: three values of unstated unit (a gyro topic).
    Vector3Stamped,
}

impl RosImuType {
    /// The type of a ROS 1 or ROS 2 type name (`sensor_msgs/Imu`, `sensor_msgs/msg/Imu`).
    pub fn from_name(name: &str) -> Option<RosImuType> {
        match name.replace("/msg/", "/").as_str() {
            "sensor_msgs/Imu" => Some(RosImuType::Imu),
            "geometry_msgs/Vector3Stamped" => Some(RosImuType::Vector3Stamped),
            _ => None,
        }
    }
}

impl RosImuType {
    /// The ROS 2 type name.
    pub fn name(self) -> &'static str {
        match self {
            RosImuType::Imu => "sensor_msgs/msg/Imu",
            RosImuType::Vector3Stamped => "geometry_msgs/msg/Vector3Stamped",
        }
    }

    /// The channels of the type.
    pub(crate) fn layout(self) -> super::ImuLayout {
        match self {
            RosImuType::Imu => super::ImuLayout::six(),
            RosImuType::Vector3Stamped => super::ImuLayout::three(["x", "y", "z"]),
        }
    }

    /// The MD5 sum ROS 1 gives the type's definition (the `md5sum` of a bag's connection):
    /// `rosmsg md5 sensor_msgs/Imu`, `rosmsg md5 geometry_msgs/Vector3Stamped` (ROS Noetic).
    pub fn ros1_md5(self) -> &'static str {
        match self {
            RosImuType::Imu => "6a62c6daae103f4ff57a132d6f95cec2",
            RosImuType::Vector3Stamped => "7b324c7325e683bf02a9b14b01090ec7",
        }
    }

    /// The fields of the type, in order: (type, name), types without their package's `msg/`.
    fn fields(self) -> &'static [(&'static str, &'static str)] {
        match self {
            RosImuType::Imu => &[
                ("std_msgs/Header", "header"),
                ("geometry_msgs/Quaternion", "orientation"),
                ("float64[9]", "orientation_covariance"),
                ("geometry_msgs/Vector3", "angular_velocity"),
                ("float64[9]", "angular_velocity_covariance"),
                ("geometry_msgs/Vector3", "linear_acceleration"),
                ("float64[9]", "linear_acceleration_covariance"),
            ],
            RosImuType::Vector3Stamped => &[("std_msgs/Header", "header"), ("geometry_msgs/Vector3", "vector")],
        }
    }
}

/// The fields of the types an IMU message holds, as the decoder reads them (ROS 2 and ROS 1
/// differ in the header and the time).
fn nested_fields(ty: &str, encoding: Encoding) -> Option<&'static [(&'static str, &'static str)]> {
    Some(match (ty, encoding) {
        ("geometry_msgs/Vector3", _) => &[("float64", "x"), ("float64", "y"), ("float64", "z")],
        ("geometry_msgs/Quaternion", _) => &[("float64", "x"), ("float64", "y"), ("float64", "z"), ("float64", "w")],
        ("std_msgs/Header", Encoding::Cdr) => &[("builtin_interfaces/Time", "stamp"), ("string", "frame_id")],
        ("std_msgs/Header", Encoding::Ros1) => &[("uint32", "seq"), ("time", "stamp"), ("string", "frame_id")],
        ("builtin_interfaces/Time", _) => &[("int32", "sec"), ("uint32", "nanosec")],
        _ => return None,
    })
}

/// A type name as written in a definition, in one spelling: `pkg/msg/T` and `pkg/T` alike,
/// `Header` as `std_msgs/Header`, `time` of ROS 1 as itself.
fn normal_type(t: &str) -> String {
    let t = t.replace("/msg/", "/");
    if t == "Header" {
        "std_msgs/Header".to_string()
    } else {
        t
    }
}

/// The fields (type, name) of each section of a message definition (ROS 2 `ros2msg` or ROS 1
/// text: the type's own fields first, then `MSG: pkg/Type` sections after lines of `=`);
/// comments, blank lines and constants are left out.
fn definition_sections(text: &str) -> Vec<(String, Vec<(String, String)>)> {
    let mut sections = vec![(String::new(), Vec::new())];
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if line.len() >= 3 && line.bytes().all(|b| b == b'=') {
            sections.push((String::new(), Vec::new()));
            continue;
        }
        if let Some(name) = line.strip_prefix("MSG:") {
            if let Some(last) = sections.last_mut() {
                last.0 = normal_type(name.trim());
            }
            continue;
        }
        let mut parts = line.split_whitespace();
        let (Some(ty), Some(name)) = (parts.next(), parts.next()) else { continue };
        if name.contains('=') || parts.next().is_some_and(|p| p.starts_with('=')) {
            continue; // a constant
        }
        if let Some(last) = sections.last_mut() {
            last.1.push((normal_type(ty), name.to_string()));
        }
    }
    sections
}

/// Checks a message definition against the layout the decoder reads for `kind` in `encoding`:
/// the type's fields in order with their types, and those of the nested types the definition
/// spells out (a nested type it leaves out is the standard one its name says). An empty
/// definition is accepted (nothing to check). The error names the first field that differs.
pub fn check_definition(kind: RosImuType, encoding: Encoding, text: &str) -> Result<(), String> {
    let sections = definition_sections(text);
    let Some((_, top)) = sections.first() else { return Ok(()) };
    if top.is_empty() && sections.len() == 1 {
        return Ok(());
    }
    let compare = |owner: &str, got: &[(String, String)], want: &[(&str, &str)]| -> Result<(), String> {
        for (i, w) in want.iter().enumerate() {
            match got.get(i) {
                None => return Err(format!("{owner} has no field '{}' ({} expected)", w.1, w.0)),
                Some((t, n)) if n != w.1 || t != w.0 => {
                    return Err(format!(
                        "field {} of {owner} is '{} {}', where '{} {}' is expected",
                        i + 1,
                        crate::text::excerpt(t),
                        crate::text::excerpt(n),
                        w.0,
                        w.1
                    ))
                }
                Some(_) => {}
            }
        }
        if let Some((t, n)) = got.get(want.len()) {
            return Err(format!("{owner} has a field more, '{} {}'", crate::text::excerpt(t), crate::text::excerpt(n)));
        }
        Ok(())
    };
    compare(kind.name(), top, kind.fields())?;
    for (name, fields) in &sections[1..] {
        let name = if encoding == Encoding::Ros1 && name == "builtin_interfaces/Time" { "" } else { name.as_str() };
        if let Some(want) = nested_fields(name, encoding) {
            compare(name, fields, want)?;
        }
    }
    Ok(())
}

/// One decoded message: its header stamp (ns) and values (gyro x/y/z then accel x/y/z for an
/// Imu; x/y/z for a Vector3Stamped).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decoded {
    /// Header stamp, ns.
    pub stamp_ns: i64,
    /// Values, in the order of the type's channels.
    pub values: [f64; 6],
}

#[derive(Deserialize)]
struct Time {
    sec: i32,
    nanosec: u32,
}

#[derive(Deserialize)]
struct Header {
    stamp: Time,
    #[allow(dead_code)]
    frame_id: String,
}

#[derive(Deserialize)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Deserialize)]
struct Imu {
    header: Header,
    #[allow(dead_code)]
    orientation: [f64; 4],
    #[allow(dead_code)]
    orientation_covariance: [f64; 9],
    angular_velocity: Vector3,
    #[allow(dead_code)]
    angular_velocity_covariance: [f64; 9],
    linear_acceleration: Vector3,
    #[allow(dead_code)]
    linear_acceleration_covariance: [f64; 9],
}

#[derive(Deserialize)]
struct Vector3Stamped {
    header: Header,
    vector: Vector3,
}

fn stamp_ns(sec: i64, nanosec: u32) -> i64 {
    sec * 1_000_000_000 + i64::from(nanosec)
}

/// Decodes one message; the error says what was wrong with its bytes.
pub fn decode(kind: RosImuType, encoding: Encoding, bytes: &[u8]) -> Result<Decoded, String> {
    match encoding {
        Encoding::Cdr => decode_cdr(kind, bytes),
        Encoding::Ros1 => decode_ros1(kind, bytes),
    }
}

fn decode_cdr(kind: RosImuType, bytes: &[u8]) -> Result<Decoded, String> {
    // The frame_id length (after the 4-byte encapsulation and the 8-byte stamp) is checked
    // first: the cdr crate allocates a string's length before reading it.
    let len = bytes.get(12..16).ok_or_else(|| format!("{} bytes: too short for a stamped message", bytes.len()))?;
    let little = bytes.get(1).is_some_and(|&b| b & 1 == 1);
    let len = if little {
        u32::from_le_bytes([len[0], len[1], len[2], len[3]])
    } else {
        u32::from_be_bytes([len[0], len[1], len[2], len[3]])
    } as usize;
    if len > bytes.len() {
        return Err(format!("frame_id length {len} exceeds the message's {} bytes", bytes.len()));
    }
    let limit = cdr::Bounded(bytes.len() as u64);
    match kind {
        RosImuType::Imu => {
            let m: Imu =
                cdr::deserialize_from(bytes, limit).map_err(|e| format!("not a CDR sensor_msgs/msg/Imu: {e}"))?;
            let (g, a) = (m.angular_velocity, m.linear_acceleration);
            Ok(Decoded {
                stamp_ns: stamp_ns(i64::from(m.header.stamp.sec), m.header.stamp.nanosec),
                values: [g.x, g.y, g.z, a.x, a.y, a.z],
            })
        }
        RosImuType::Vector3Stamped => {
            let m: Vector3Stamped = cdr::deserialize_from(bytes, limit)
                .map_err(|e| format!("not a CDR geometry_msgs/msg/Vector3Stamped: {e}"))?;
            let v = m.vector;
            Ok(Decoded {
                stamp_ns: stamp_ns(i64::from(m.header.stamp.sec), m.header.stamp.nanosec),
                values: [v.x, v.y, v.z, 0.0, 0.0, 0.0],
            })
        }
    }
}

/// A little-endian cursor over a ROS 1 message.
struct Ros1<'a> {
    b: &'a [u8],
    pos: usize,
}

impl Ros1<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end =
            self.pos.checked_add(n).filter(|&e| e <= self.b.len()).ok_or_else(|| {
                format!("{} bytes: the message ends inside a field at byte {}", self.b.len(), self.pos)
            })?;
        let s = &self.b[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, String> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn f64s<const N: usize>(&mut self) -> Result<[f64; N], String> {
        let s = self.take(8 * N)?;
        let mut out = [0.0; N];
        for (i, c) in s.chunks_exact(8).enumerate() {
            out[i] = f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        }
        Ok(out)
    }
}

fn decode_ros1(kind: RosImuType, bytes: &[u8]) -> Result<Decoded, String> {
    let mut r = Ros1 { b: bytes, pos: 0 };
    let _seq = r.u32()?;
    let sec = r.u32()?;
    let nsec = r.u32()?;
    let frame_len = r.u32()? as usize;
    r.take(frame_len)?;
    let stamp_ns = stamp_ns(i64::from(sec), nsec);
    let values = match kind {
        RosImuType::Imu => {
            let _orientation: [f64; 13] = r.f64s()?;
            let g: [f64; 3] = r.f64s()?;
            let _cov: [f64; 9] = r.f64s()?;
            let a: [f64; 3] = r.f64s()?;
            let _cov: [f64; 9] = r.f64s()?;
            [g[0], g[1], g[2], a[0], a[1], a[2]]
        }
        RosImuType::Vector3Stamped => {
            let v: [f64; 3] = r.f64s()?;
            [v[0], v[1], v[2], 0.0, 0.0, 0.0]
        }
    };
    Ok(Decoded { stamp_ns, values })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A CDR sensor_msgs/msg/Imu written by hand from the CDR rules (alignment to the type's
    /// size, counted from the end of the encapsulation header).
    fn cdr_imu(sec: i32, nsec: u32, frame: &str, g: [f64; 3], a: [f64; 3]) -> Vec<u8> {
        let mut b = vec![0u8, 1, 0, 0];
        let body_len = |b: &Vec<u8>| b.len() - 4;
        b.extend_from_slice(&sec.to_le_bytes());
        b.extend_from_slice(&nsec.to_le_bytes());
        b.extend_from_slice(&(frame.len() as u32 + 1).to_le_bytes());
        b.extend_from_slice(frame.as_bytes());
        b.push(0);
        while body_len(&b) % 8 != 0 {
            b.push(0);
        }
        let mut f = |v: f64| b.extend_from_slice(&v.to_le_bytes());
        for v in [0.0, 0.0, 0.0, 1.0].into_iter().chain([0.0; 9]).chain(g).chain([0.0; 9]).chain(a).chain([0.0; 9]) {
            f(v);
        }
        b
    }

    #[test]
    fn cdr_imu_decodes_stamp_gyro_and_accel() {
        let b = cdr_imu(1_700_000_000, 5_000_000, "imu_link", [0.1, -0.2, 0.3], [0.0, 0.5, 9.81]);
        let d = decode(RosImuType::Imu, Encoding::Cdr, &b).unwrap();
        assert_eq!(d.stamp_ns, 1_700_000_000_005_000_000);
        assert_eq!(d.values, [0.1, -0.2, 0.3, 0.0, 0.5, 9.81]);
        // Another frame_id length moves the alignment padding.
        let b = cdr_imu(2, 7, "imu", [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]);
        let d = decode(RosImuType::Imu, Encoding::Cdr, &b).unwrap();
        assert_eq!((d.stamp_ns, d.values), (2_000_000_007, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
    }

    #[test]
    fn truncated_or_lying_messages_are_errors_not_panics() {
        let b = cdr_imu(1, 2, "imu", [1.0; 3], [2.0; 3]);
        for n in 0..b.len() {
            assert!(decode(RosImuType::Imu, Encoding::Cdr, &b[..n]).is_err(), "{n}");
        }
        let mut lying = b.clone();
        lying[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode(RosImuType::Imu, Encoding::Cdr, &lying).unwrap_err().contains("frame_id length"));
        assert!(decode(RosImuType::Imu, Encoding::Ros1, &b[..10]).is_err());
    }

    #[test]
    fn ros1_imu_decodes() {
        let mut b = Vec::new();
        b.extend_from_slice(&7u32.to_le_bytes());
        b.extend_from_slice(&3u32.to_le_bytes());
        b.extend_from_slice(&500u32.to_le_bytes());
        b.extend_from_slice(&3u32.to_le_bytes());
        b.extend_from_slice(b"imu");
        for v in
            [0.0f64; 13].into_iter().chain([0.5, 0.25, -1.0]).chain([0.0; 9]).chain([1.0, 2.0, 3.0]).chain([0.0; 9])
        {
            b.extend_from_slice(&v.to_le_bytes());
        }
        let d = decode(RosImuType::Imu, Encoding::Ros1, &b).unwrap();
        assert_eq!(d.stamp_ns, 3_000_000_500);
        assert_eq!(d.values, [0.5, 0.25, -1.0, 1.0, 2.0, 3.0]);
        assert!(decode(RosImuType::Imu, Encoding::Ros1, &b[..b.len() - 1]).is_err());
    }

    #[test]
    fn vector3_stamped_decodes_in_both_encodings() {
        // CDR: header (stamp, frame_id "g" + NUL), padding to 8-byte alignment counted from
        // the end of the encapsulation header (14 -> 16), then x, y, z.
        let mut b = vec![0u8, 1, 0, 0];
        b.extend_from_slice(&9i32.to_le_bytes());
        b.extend_from_slice(&11u32.to_le_bytes());
        b.extend_from_slice(&2u32.to_le_bytes());
        b.extend_from_slice(b"g\0");
        b.extend_from_slice(&[0; 2]);
        for v in [0.5f64, -0.25, 2.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        let d = decode(RosImuType::Vector3Stamped, Encoding::Cdr, &b).unwrap();
        assert_eq!((d.stamp_ns, &d.values[..3]), (9_000_000_011, &[0.5, -0.25, 2.0][..]));
        // ROS 1: seq, sec, nsec, frame_id (u32 length, no NUL), x, y, z.
        let mut r = Vec::new();
        for v in [1u32, 9, 11, 1] {
            r.extend_from_slice(&v.to_le_bytes());
        }
        r.push(b'g');
        for v in [0.5f64, -0.25, 2.0] {
            r.extend_from_slice(&v.to_le_bytes());
        }
        let d = decode(RosImuType::Vector3Stamped, Encoding::Ros1, &r).unwrap();
        assert_eq!((d.stamp_ns, &d.values[..3]), (9_000_000_011, &[0.5, -0.25, 2.0][..]));
    }

    #[test]
    fn type_names_of_both_ros_versions() {
        assert_eq!(RosImuType::from_name("sensor_msgs/msg/Imu"), Some(RosImuType::Imu));
        assert_eq!(RosImuType::from_name("sensor_msgs/Imu"), Some(RosImuType::Imu));
        assert_eq!(RosImuType::from_name("geometry_msgs/msg/Vector3Stamped"), Some(RosImuType::Vector3Stamped));
        assert_eq!(RosImuType::from_name("std_msgs/msg/String"), None);
    }
}
