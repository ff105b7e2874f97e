"""Writes the same IMU samples into the recording formats robotics tools produce, with
independent writers (not gyrolab's code), for the tests of gyrolab's readers (issue 17).

usage: write_recordings.py IN.csv OUTDIR

IN.csv: a header line `timestamp_ns,gx,gy,gz,ax,ay,az`, then rows of integer nanosecond stamps
(whole microseconds) and gyro (rad/s) and accelerometer (m/s^2) values.

Writes into OUTDIR:
- ros2/                : rosbag2 (rosbags, MCAP storage): /imu0 (sensor_msgs/msg/Imu; every 50th
                         message written after its successor, log times in write order), /imu1
                         (every value times 2), /temperature (sensor_msgs/msg/Temperature);
                         prints `ros2_mcap=PATH` of its .mcap file;
- plain_zstd.mcap,
  plain_lz4.mcap       : the `mcap` package's writer, zstd / lz4 chunks of 64 KiB, /imu0 in CDR
                         (bytes from rosbags' serializer); plain_zstd.mcap also /camera/info
                         (std_msgs/msg/String);
- imu.bag, imu_bz2.bag,
  imu_lz4.bag          : ROS 1 bags (rosbags), no compression / bz2 / lz4 chunks, the topics of
                         ros2/ in the same order;
- imu.ulg              : PX4 ULog written here from the published format specification
                         (docs.px4.io, "ULog File Format"): sensor_combined, sensor_gyro
                         (instance 0, timestamp_sample), vehicle_status; float32 values;
- imu_f32.csv          : the ULog's values exactly (float32 widened), stamps in ns;
- imu.parquet          : pyarrow, timestamp_ns (int64) and gx_rad_s ... az_m_s2 (double), snappy,
                         row groups of 100 000 rows;
- imu_zstd.parquet     : the same with zstd and a null in gx_rad_s at row index 10.
"""
import struct
import sys
from pathlib import Path

import numpy as np


def read_input(path):
    stamps, values = [], []
    with open(path) as f:
        header = f.readline().strip().split(",")
        assert header == ["timestamp_ns", "gx", "gy", "gz", "ax", "ay", "az"], header
        for line in f:
            parts = line.strip().split(",")
            if len(parts) != 7:
                continue
            stamps.append(int(parts[0]))
            values.append([float(x) for x in parts[1:]])
    return stamps, values


def write_order(n):
    """Indices in write order: every 50th message swapped with its successor."""
    order = list(range(n))
    for i in range(0, n - 1, 50):
        order[i], order[i + 1] = order[i + 1], order[i]
    return order


def ros_messages(typestore, stamps, values, scale, ros1):
    """Serialized sensor_msgs/msg/Imu messages (CDR, or ROS 1 with `ros1`)."""
    t = typestore.types
    Imu, Header, Time = t["sensor_msgs/msg/Imu"], t["std_msgs/msg/Header"], t["builtin_interfaces/msg/Time"]
    V3, Q = t["geometry_msgs/msg/Vector3"], t["geometry_msgs/msg/Quaternion"]
    zero = np.zeros(9)
    quat = Q(x=0.0, y=0.0, z=0.0, w=1.0)
    out = []
    for k, (s, v) in enumerate(zip(stamps, values)):
        v = [x * scale for x in v]
        header = Header(seq=k, stamp=Time(sec=s // 10**9, nanosec=s % 10**9), frame_id="imu_link") if ros1 else Header(
            stamp=Time(sec=s // 10**9, nanosec=s % 10**9), frame_id="imu_link"
        )
        msg = Imu(
            header=header,
            orientation=quat,
            orientation_covariance=zero,
            angular_velocity=V3(x=v[0], y=v[1], z=v[2]),
            angular_velocity_covariance=zero,
            linear_acceleration=V3(x=v[3], y=v[4], z=v[5]),
            linear_acceleration_covariance=zero,
        )
        out.append(bytes(typestore.serialize_ros1(msg, Imu.__msgtype__) if ros1 else typestore.serialize_cdr(msg, Imu.__msgtype__)))
    return out


def temperature_messages(typestore, stamps, ros1):
    t = typestore.types
    Temp, Header, Time = t["sensor_msgs/msg/Temperature"], t["std_msgs/msg/Header"], t["builtin_interfaces/msg/Time"]
    out = []
    for k in range(0, len(stamps), 100):
        s = stamps[k]
        stamp = Time(sec=s // 10**9, nanosec=s % 10**9)
        header = Header(seq=k, stamp=stamp, frame_id="imu_link") if ros1 else Header(stamp=stamp, frame_id="imu_link")
        msg = Temp(header=header, temperature=25.0, variance=0.0)
        data = typestore.serialize_ros1(msg, Temp.__msgtype__) if ros1 else typestore.serialize_cdr(msg, Temp.__msgtype__)
        out.append((s, bytes(data)))
    return out


def write_topics(w, conns, stamps, imu0, imu1, temps):
    """/imu0 in write order (log time = the k-th stamp), /imu1 in order, /temperature between."""
    c0, c1, ct = conns
    ti = 0
    for k, i in enumerate(write_order(len(stamps))):
        log = stamps[k]
        w.write(c0, log, imu0[i])
        w.write(c1, stamps[i], imu1[i])
        while ti < len(temps) and temps[ti][0] <= log:
            w.write(ct, temps[ti][0], temps[ti][1])
            ti += 1


def write_ros2(out, stamps, imu0, imu1, temps):
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    path = out / "ros2"
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        c0 = w.add_connection("/imu0", "sensor_msgs/msg/Imu", typestore=ts)
        c1 = w.add_connection("/imu1", "sensor_msgs/msg/Imu", typestore=ts)
        ct = w.add_connection("/temperature", "sensor_msgs/msg/Temperature", typestore=ts)
        write_topics(w, (c0, c1, ct), stamps, imu0, imu1, temps)
    mcap = sorted(path.glob("*.mcap"))[0]
    print(f"ros2_mcap={mcap}")


def write_plain_mcap(out, stamps, imu0):
    from mcap.writer import CompressionType, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    definition = "".join(f"{t} {n}\n" for n, t in [
        ("header", "std_msgs/Header"),
        ("orientation", "geometry_msgs/Quaternion"),
        ("orientation_covariance", "float64[9]"),
        ("angular_velocity", "geometry_msgs/Vector3"),
        ("angular_velocity_covariance", "float64[9]"),
        ("linear_acceleration", "geometry_msgs/Vector3"),
        ("linear_acceleration_covariance", "float64[9]"),
    ]).encode()
    for name, comp in [("plain_zstd.mcap", CompressionType.ZSTD), ("plain_lz4.mcap", CompressionType.LZ4)]:
        with open(out / name, "wb") as f:
            w = Writer(f, chunk_size=64 * 1024, compression=comp)
            w.start(profile="ros2", library="write_recordings.py")
            schema = w.register_schema(name="sensor_msgs/msg/Imu", encoding="ros2msg", data=definition)
            ch = w.register_channel(topic="/imu0", message_encoding="cdr", schema_id=schema)
            if comp == CompressionType.ZSTD:
                s2 = w.register_schema(name="std_msgs/msg/String", encoding="ros2msg", data=b"string data\n")
                c2 = w.register_channel(topic="/camera/info", message_encoding="cdr", schema_id=s2)
                String = ts.types["std_msgs/msg/String"]
                for k in range(3):
                    data = bytes(ts.serialize_cdr(String(data=f"frame {k}"), "std_msgs/msg/String"))
                    w.add_message(channel_id=c2, log_time=stamps[k], publish_time=stamps[k], data=data)
            for s, data in zip(stamps, imu0):
                w.add_message(channel_id=ch, log_time=s, publish_time=s, data=data)
            w.finish()
        print(f"wrote {out / name}")


def write_bags(out, stamps, imu0, imu1, temps):
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    for name, comp in [("imu.bag", None), ("imu_bz2.bag", Writer.CompressionFormat.BZ2), ("imu_lz4.bag", Writer.CompressionFormat.LZ4)]:
        path = out / name
        if path.exists():
            path.unlink()
        w = Writer(path)
        if comp is not None:
            w.set_compression(comp)
        w.open()
        c0 = w.add_connection("/imu0", "sensor_msgs/msg/Imu", typestore=ts)
        c1 = w.add_connection("/imu1", "sensor_msgs/msg/Imu", typestore=ts)
        ct = w.add_connection("/temperature", "sensor_msgs/msg/Temperature", typestore=ts)
        write_topics(w, (c0, c1, ct), stamps, imu0, imu1, temps)
        w.close()
        print(f"wrote {path}")


# ULog (docs.px4.io "ULog File Format"): a 16-byte header, then messages of a 3-byte header
# (uint16 msg_size of the payload, uint8 msg_type) and the payload, little endian.
def ulog_message(kind, payload):
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def ulog_format(text):
    return ulog_message("F", text.encode())


def write_ulog(out, stamps, values):
    first = stamps[0]
    us = [(s - first) // 1000 + 1_000_000 for s in stamps]
    f32 = np.asarray(values, dtype=np.float32)
    b = bytearray(b"ULog" + bytes([0x01, 0x12, 0x35]) + bytes([1]) + struct.pack("<Q", us[0]))
    b += ulog_message("B", bytes(8) + bytes(8) + struct.pack("<QQQ", 0, 0, 0))
    b += ulog_format(
        "sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;"
        "int32_t accelerometer_timestamp_relative;float[3] accelerometer_m_s2;uint32_t accelerometer_integral_dt;"
        "uint8_t accelerometer_clipping;uint8_t gyro_clipping;uint8_t accel_calibration_count;uint8_t gyro_calibration_count;"
    )
    b += ulog_format(
        "sensor_gyro:uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;float x;float y;float z;"
        "float temperature;uint32_t error_count;uint8_t[3] clip_counter;uint8_t samples;uint8_t[4] _padding0;"
    )
    b += ulog_format("vehicle_status:uint64_t timestamp;uint8_t arming_state;uint8_t[7] _padding0;")
    key = b"char[7] sys_name"
    b += ulog_message("I", bytes([len(key)]) + key + b"gyrolab")
    b += ulog_message("A", struct.pack("<BH", 0, 0) + b"sensor_combined")
    b += ulog_message("A", struct.pack("<BH", 0, 1) + b"sensor_gyro")
    b += ulog_message("A", struct.pack("<BH", 0, 2) + b"vehicle_status")
    for k, t in enumerate(us):
        g, a = f32[k, :3], f32[k, 3:]
        body = struct.pack("<Q3fIi3fIBBBB", t, *g, 10000, 0, *a, 10000, 0, 0, 1, 1)
        b += ulog_message("D", struct.pack("<H", 0) + body)
        # The padding at the end of a format is not logged (PX4's logger writes a message
        # without its trailing padding field), so a data message is 4 bytes shorter than the format.
        body = struct.pack("<QQI4fI3BB", t + 200, t, 2293768, *g, 40.0, 0, 0, 0, 0, 1)
        b += ulog_message("D", struct.pack("<H", 1) + body)
        if k % 1000 == 0:
            b += ulog_message("D", struct.pack("<H", 2) + struct.pack("<QB", t, 1))
    (out / "imu.ulg").write_bytes(bytes(b))
    with open(out / "imu_f32.csv", "w") as f:
        f.write("timestamp_ns,gx,gy,gz,ax,ay,az\n")
        for k, t in enumerate(us):
            f.write(f"{t * 1000}," + ",".join(repr(float(x)) for x in f32[k]) + "\n")
    print(f"wrote {out / 'imu.ulg'}")


def write_parquet(out, stamps, values):
    import pyarrow as pa
    import pyarrow.parquet as pq

    v = np.asarray(values)
    names = ["gx_rad_s", "gy_rad_s", "gz_rad_s", "ax_m_s2", "ay_m_s2", "az_m_s2"]
    cols = {"timestamp_ns": pa.array(stamps, pa.int64())}
    cols.update({n: pa.array(v[:, k], pa.float64()) for k, n in enumerate(names)})
    pq.write_table(pa.table(cols), out / "imu.parquet", row_group_size=100_000, compression="snappy")
    gx = v[:, 0].tolist()
    gx[10] = None
    cols["gx_rad_s"] = pa.array(gx, pa.float64())
    pq.write_table(pa.table(cols), out / "imu_zstd.parquet", row_group_size=100_000, compression="zstd")
    print(f"wrote {out / 'imu.parquet'}")


def main():
    src, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    stamps, values = read_input(src)
    from rosbags.typesys import Stores, get_typestore

    ts2 = get_typestore(Stores.ROS2_HUMBLE)
    ts1 = get_typestore(Stores.ROS1_NOETIC)
    cdr0 = ros_messages(ts2, stamps, values, 1.0, False)
    cdr1 = ros_messages(ts2, stamps, values, 2.0, False)
    write_ros2(out, stamps, cdr0, cdr1, temperature_messages(ts2, stamps, False))
    write_plain_mcap(out, stamps, cdr0)
    del cdr0, cdr1
    r0 = ros_messages(ts1, stamps, values, 1.0, True)
    r1 = ros_messages(ts1, stamps, values, 2.0, True)
    write_bags(out, stamps, r0, r1, temperature_messages(ts1, stamps, True))
    del r0, r1
    write_ulog(out, stamps, values)
    write_parquet(out, stamps, values)


if __name__ == "__main__":
    main()
