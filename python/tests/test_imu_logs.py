"""gyrolab.read on IMU logs as recorded (issue 16): Kalibr imu0.csv, units given, headerless."""
import numpy as np
import pytest

import gyrolab


def test_kalibr_layout_reads_with_units_and_seconds(tmp_path):
    p = tmp_path / "imu0.csv"
    p.write_text(
        "#timestamp [ns],w_RS_S_x [rad s^-1],a_RS_S_x [m s^-2]\n"
        "1403636579758555392,0.5,9.8\n1403636579763555584,0.25,9.7\n"
    )
    arrays, units = gyrolab.read_with_units(p)
    assert units["w_RS_S_x [rad s^-1]"] == "rad/s"
    assert units["a_RS_S_x [m s^-2]"] == "m/s^2"
    t = arrays["timestamp [ns]"]  # the comment mark is not part of the name
    # 5 000 192 ns between the stamps, read in seconds (f64 resolution at 1.4e9 s: 2.4e-7 s).
    assert abs((t[1] - t[0]) - 0.005000192) < 5e-7
    np.testing.assert_array_equal(arrays["w_RS_S_x [rad s^-1]"], [0.5, 0.25])


def test_units_time_column_and_names(tmp_path):
    p = tmp_path / "log.txt"
    p.write_text("0 1.5 9.81\n10 1.25 9.80\n")
    arrays, units = gyrolab.read_with_units(p, units=["gx=deg/s", "m/s^2"], names=["t", "gx", "az"])
    assert units["gx"] == "deg/s" and units["az"] == "m/s^2" and units["t"] == "s"
    with pytest.raises(gyrolab.Error, match="unknown unit"):
        gyrolab.read_with_units(p, units=["furlong"], names=["t", "gx", "az"])
    arrays, units = gyrolab.read_with_units(p, units=["host=ms"], names=["host", "gx", "az"])
    np.testing.assert_allclose(arrays["host"], [0.0, 0.01])


def test_accelerometer_array_gives_velocity_random_walk():
    # White noise of VRW 0.05 m/s/sqrt(h) = 8.33e-4 m/s^2/sqrt(Hz) at 200 Hz for 1 h.
    rate = 200.0
    x = np.random.default_rng(3).standard_normal(720_000) * (0.05 / 60 * np.sqrt(rate))
    d = gyrolab.allan(x, rate_hz=rate, unit="m/s^2").to_dict()
    assert d["quantity"] == "acceleration" and d["dev_unit"] == "m/s^2"
    assert d["noise"] is None
    assert abs(d["accel_noise"]["vrw_m_s_rt_h"] / 0.05 - 1) < 0.05


def test_parquet_and_mcap_recordings_are_read_by_content(tmp_path):
    # Independent writers: pyarrow (Parquet) and rosbags (rosbag2 with MCAP storage).
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    rng = np.random.default_rng(5)
    gx = rng.standard_normal(500) * 1e-3
    stamps = 1_700_000_000_000_000_000 + np.arange(500, dtype=np.int64) * 5_000_000
    p = tmp_path / "imu.bin"  # no extension: read by its content
    pq.write_table(pa.table({"timestamp_ns": stamps, "gx_rad_s": gx}), p)
    arrays, units = gyrolab.read_with_units(p)
    np.testing.assert_array_equal(arrays["gx_rad_s"], gx)
    assert units["gx_rad_s"] == "rad/s"

    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    t = ts.types
    z = np.zeros(9)
    with Writer(tmp_path / "bag", version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conns = [w.add_connection(name, "sensor_msgs/msg/Imu", typestore=ts) for name in ("/imu0", "/imu1")]
        for i, s in enumerate(stamps.tolist()):
            m = t["sensor_msgs/msg/Imu"](
                header=t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=s // 10**9, nanosec=s % 10**9), frame_id="imu"),
                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=z,
                angular_velocity=t["geometry_msgs/msg/Vector3"](x=float(gx[i]), y=0.0, z=0.0),
                angular_velocity_covariance=z,
                linear_acceleration=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=9.81),
                linear_acceleration_covariance=z,
            )
            for c in conns:
                w.write(c, s, ts.serialize_cdr(m, "sensor_msgs/msg/Imu"))
    mcap = next((tmp_path / "bag").glob("*.mcap"))
    with pytest.raises(gyrolab.Error, match="2 IMU topics"):
        gyrolab.read_with_units(mcap)
    arrays = gyrolab.read(mcap, as_dataframe=False, topic="/imu1")
    np.testing.assert_array_equal(arrays["gyro_x_rad_s"], gx)
    np.testing.assert_allclose(np.diff(arrays["time_s"]), 0.005, rtol=0, atol=1e-12)
    # allan() takes the topic too (its error above said "topic="), with the same deviations as
    # reading the topic first; without a path the keyword is refused.
    with pytest.raises(gyrolab.Error, match="2 IMU topics"):
        gyrolab.allan(mcap)
    direct = gyrolab.allan(mcap, topic="/imu1")
    via_read = gyrolab.allan(gyrolab.read(mcap, topic="/imu1"))
    np.testing.assert_array_equal(direct["gyro_x_rad_s"].dev, via_read["gyro_x_rad_s"].dev)
    with pytest.raises(gyrolab.Error) as e:
        gyrolab.allan(gx, rate_hz=200.0, topic="/imu1")
    assert e.value.keyword == "topic"


def _mpu_with_trailer(path):
    # An MPU6050 logger's CSV: millisecond stamps at 100 Hz, 6,280 rows, then 720 rows of
    # zeros, the stamps included (issue 54: one clock model in every front end).
    rng = np.random.default_rng(11)
    rows = ["timestamp_ms,gx_dps,gy_dps,gz_dps"]
    for i in range(6280):
        g = 0.1 * (rng.random(3) - 0.5) + [0.1, -0.2, 0.05]
        rows.append(f"{1010 + 10 * i},{g[0]:.4f},{g[1]:.4f},{g[2]:.4f}")
    rows += ["0,0,0,0"] * 720
    path.write_text("\n".join(rows) + "\n")


def test_a_zero_trailer_ends_the_record_as_the_command_line_ends_it(tmp_path):
    p = tmp_path / "mpu.csv"
    _mpu_with_trailer(p)
    with pytest.warns(UserWarning, match=r"mpu.csv: the time stamps go back at time\[6280\] \(from 63.8\d* s to 0 s.*720 sample\(s\) from there left out"):
        r = gyrolab.allan(p)
    gx = r["gx_dps"]
    assert abs(gx.tau0_s - 0.01) < 1e-12
    # The figures of the rows before the trailer, as an array of them alone gives.
    arrays = gyrolab.read(p)
    alone = gyrolab.allan(arrays["gx_dps"][:6280], rate_hz=100.0, unit="deg/s")
    np.testing.assert_array_equal(gx.dev, alone.dev)
    np.testing.assert_array_equal(gx.taus_s, alone.taus_s)


def test_host_stamps_with_single_drops_read_as_the_command_line_reads_them():
    # A 50 Hz stream stamped on arrival 0 to 6 ms late, 1.5 % of the samples dropped one at a
    # time (the ArDrone bag's pattern, issue 54): the grid is 50 Hz with every drop counted,
    # from the stamps alone and with rate_hz=50 given.
    rng = np.random.default_rng(54)
    keep, last = [], 0
    for i in range(4600):
        if 40 < i < 4560 and i - last > 10 and rng.random() < 0.016:
            last = i
            continue
        keep.append(i)
    keep = np.array(keep)
    t = keep / 50.0 + 0.006 * rng.random(len(keep))
    x = rng.standard_normal(len(keep)) * 0.01
    dropped = 4600 - len(keep)
    assert dropped > 40
    for given in (None, 50.0):
        d = gyrolab.allan(x, time=t, rate_hz=given, unit="rad/s", gaps="analyse").to_dict()
        assert d["samples"] == len(keep) + dropped, given
        assert abs(d["tau0_s"] * 50.0 - 1.0) < 5e-4, (given, d["tau0_s"])


def test_a_real_px4_log_is_read_at_its_sample_clock():
    # pyulog's sample_logging_tagged_and_default_params.ulg (BSD-3-Clause): sensor_combined at
    # 250 Hz with 665 dropped samples (the grid 2,693 samples), as every command reads it
    # (crates/gyrolab-cli/tests/integration/recordings.rs).
    import pathlib
    import warnings

    ulg = pathlib.Path(__file__).parents[2] / "examples/recordings/px4_sample_logging_tagged_and_default_params.ulg"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = gyrolab.allan(ulg, gaps="analyse")
    for name in ("gyro_x_rad_s", "accel_z_m_s2"):
        d = r[name].to_dict()
        assert (d["tau0_s"], d["samples"]) == (0.004, 2693), name
