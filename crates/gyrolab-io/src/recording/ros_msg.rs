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
