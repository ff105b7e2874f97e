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
