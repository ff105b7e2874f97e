//! A SIMULATED ROS 2 MCAP recording of one IMU, fast (for bench/long_recording.sh):
//! `long_mcap HOURS RATE_HZ OUT [SEED]`. One topic `/imu` of `sensor_msgs/msg/Imu` in CDR, zstd
//! chunks (the `mcap` crate's writer): gyro x/y/z in rad/s (white noise of 6e-4 rad/s a sample,
//! uniform, plus a random walk), accelerometer x/y/z in m/s^2 (white noise, 9.81 on z), header
//! stamps from 1.7e9 s at 1 / RATE_HZ; the channel's metadata says SIMULATED.

use std::collections::BTreeMap;
use std::io::BufWriter;

/// The message definition written into the schema (ROS 2 `ros2msg`).
const IMU_DEFINITION: &str = "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n\
float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n\
float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n\
float64[9] linear_acceleration_covariance\n";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: long_mcap HOURS RATE_HZ OUT [SEED]";
    let hours: f64 = args.get(1).and_then(|a| a.parse().ok()).ok_or(usage)?;
    let rate: u64 = args.get(2).and_then(|a| a.parse().ok()).ok_or(usage)?;
    let out = args.get(3).ok_or(usage)?;
    let seed: u64 = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(1);
    if rate == 0 || rate > 1_000_000 || !(hours > 0.0 && hours <= 1000.0) {
        return Err(usage.into());
    }
    let messages = (hours * 3600.0 * rate as f64).round() as u64;
    let file = BufWriter::with_capacity(1 << 20, std::fs::File::create(out)?);
    let mut w = mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).create(file)?;
    let schema = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", IMU_DEFINITION.as_bytes())?;
    let mut meta = BTreeMap::new();
    meta.insert("gyrolab".to_string(), format!("SIMULATED by long_mcap: {hours} h at {rate} Hz, seed {seed}"));
    let channel = w.add_channel(schema, "/imu", "cdr", &meta)?;
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut uniform = move || {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut walk = [0.0f64; 3];
    let mut msg = Vec::with_capacity(320);
    let t0_ns: u64 = 1_700_000_000_000_000_000;
    for i in 0..messages {
        let t = t0_ns + i * 1_000_000_000 / rate;
        msg.clear();
        // CDR, little endian: encapsulation, header (stamp, frame_id "imu"), then 37 doubles
        // (8-byte aligned after the 20-byte header: offset 16 of the payload).
        msg.extend_from_slice(&[0, 1, 0, 0]);
        msg.extend_from_slice(&((t / 1_000_000_000) as i32).to_le_bytes());
        msg.extend_from_slice(&((t % 1_000_000_000) as u32).to_le_bytes());
        msg.extend_from_slice(&4u32.to_le_bytes());
        msg.extend_from_slice(b"imu\0");
        let mut put = |v: f64| msg.extend_from_slice(&v.to_le_bytes());
        for v in [0.0, 0.0, 0.0, 1.0] {
            put(v);
        }
        (0..9).for_each(|_| put(0.0));
        for (axis, wk) in walk.iter_mut().enumerate() {
            *wk += 3.5e-7 * uniform();
            put([8e-4, -3e-4, 2e-4][axis] + 2e-3 * uniform() + *wk);
        }
        (0..9).for_each(|_| put(0.0));
        for axis in 0..3 {
            put([0.0, 0.0, 9.81][axis] + 0.0069 * uniform());
        }
        (0..9).for_each(|_| put(0.0));
        let header =
            mcap::records::MessageHeader { channel_id: channel, sequence: i as u32, log_time: t, publish_time: t };
        w.write_to_known_channel(&header, &msg)?;
    }
    w.finish()?;
    Ok(())
}
