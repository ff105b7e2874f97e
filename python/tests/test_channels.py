"""Many channels in one call (issue 34): a six-channel IMU DataFrame gives, channel by channel,
exactly (bit for bit) the results of six single calls; tidy tables; accelerometer terms
against simulated truth and against the same samples read as a gyro."""
import numpy as np
import pandas as pd
import pytest

import gyrolab

G_N = 9.80665


def imu_frame(n=40_000, rate=100.0, seed=3):
    rng = np.random.default_rng(seed)
    t = 1_700_000_000.0 + np.arange(n) / rate
    cols = {"time_s": t}
    for i, c in enumerate(["gx", "gy", "gz"]):
        cols[c] = rng.standard_normal(n) * 1e-3 * (i + 1)  # rad/s
    for i, c in enumerate(["ax", "ay", "az"]):
        cols[c] = rng.standard_normal(n) * 2e-3 * (i + 1) + (G_N if c == "az" else 0.0)  # m/s^2
    return pd.DataFrame(cols)


UNITS = {"gx": "rad/s", "gy": "rad/s", "gz": "rad/s", "ax": "m/s^2", "ay": "m/s2", "az": "m/s^2"}


def test_six_channels_equal_six_single_calls_bit_for_bit():
    df = imu_frame()
    many = gyrolab.allan(df, units=UNITS)
    assert list(many) == ["gx", "gy", "gz", "ax", "ay", "az"]
    for c, u in UNITS.items():
        one = gyrolab.allan(df[c].to_numpy(), time=df["time_s"].to_numpy(), unit=u, names=[c])
        got = many[c]
        for f in ["taus_s", "m", "dev", "ci_low", "ci_high", "n_terms", "alpha"]:
            np.testing.assert_array_equal(getattr(got, f), getattr(one, f), err_msg=f"{c} {f}")
        assert got.noise == one.noise and got.readings == one.readings
        assert got == one
    assert many["gx"].unit == "deg/s" and many["ax"].unit == "m/s^2"
    assert many["gx"].arw_deg_rt_h is not None and many["ax"].vrw_m_s_rt_h is not None
    # A 2-D array (samples x channels) with names gives the same.
    arr = df[list(UNITS)].to_numpy()
    again = gyrolab.allan(arr, time=df["time_s"].to_numpy(), names=list(UNITS), units=UNITS)
    np.testing.assert_array_equal(again["az"].dev, many["az"].dev)


def test_tidy_tables():
    df = imu_frame(n=20_000)
    many = gyrolab.allan(df, units=UNITS)
    curves = many.to_dataframe()
    assert {"channel", "tau_s", "dev", "ci_low", "ci_high", "n_terms", "alpha", "dev_unit"} <= set(curves.columns)
    assert len(curves) == sum(len(r.taus_s) for r in many.values())
    np.testing.assert_array_equal(curves[curves.channel == "gy"].dev.to_numpy(), many["gy"].dev)
    noise = many.noise_table()
    assert list(noise.columns)[:6] == ["channel", "term", "value", "unit", "basis", "support"]
    arw = noise[(noise.channel == "gx") & (noise.term == "arw")].iloc[0]
    assert arw.unit == "deg/sqrt(h)" and arw.basis == "value"
    assert arw.value == pytest.approx(many["gx"].arw_deg_rt_h, rel=1e-12)
    assert set(noise[noise.channel == "ax"].term) >= {"vrw", "bias_instability", "accel_random_walk"}


def test_read_units_are_used(tmp_path):
    df = imu_frame(n=5_000)
    p = tmp_path / "imu.csv"
    df.rename(columns={"gx": "gx_rad_s", "ax": "ax_m_s2"})[["time_s", "gx_rad_s", "ax_m_s2"]].to_csv(p, index=False)
    frame = gyrolab.read(p)
    r = gyrolab.allan(frame)  # the time column and the units read() found
    assert r["gx_rad_s"].unit == "deg/s" and r["ax_m_s2"].unit == "m/s^2"
    from_file = gyrolab.allan(p)
    assert from_file.record == str(p) and from_file["gx_rad_s"].record == str(p)
    np.testing.assert_array_equal(from_file["gx_rad_s"].dev, r["gx_rad_s"].dev)
    assert from_file["ax_m_s2"].noise == r["ax_m_s2"].noise


def test_accelerometer_terms_against_simulated_truth():
    # A simulated gyro record with known N = 0.5 and B = 5 (deg units), read as m/s^2: the
    # accelerometer terms are the same numbers in their units (VRW m/s/sqrt(h) = N; B in
    # micro-g = B/3600/g_n/1e-6); the simulated truth within the estimators' scatter.
    s = gyrolab.simulate_static(3600.0, 100.0, seed=21, arw_deg_rt_h=0.5, bias_instability_dph=5.0)
    gyro = gyrolab.allan(s["output"], rate_hz=100.0)
    acc = gyrolab.allan(s["output"], rate_hz=100.0, unit="m/s^2")
    assert acc.quantity == "acceleration" and acc.unit == "m/s^2" and acc.noise
    assert acc.vrw_m_s_rt_h == pytest.approx(gyro.arw_deg_rt_h, rel=1e-12)
    assert acc.vrw_m_s_rt_h == pytest.approx(0.5, rel=0.05)
    if gyro.bias_instability_dph is not None:
        assert acc.bias_instability_ug == pytest.approx(gyro.bias_instability_dph / 3600 / G_N * 1e6, rel=1e-9)
        assert acc.bias_instability_ug == pytest.approx(5.0 / 3600 / G_N * 1e6, rel=0.3)
    else:
        assert acc.bias_instability_ug is None
    terms = set(acc.noise_table().term)
    assert {"vrw", "bias_instability", "allan_minimum", "accel_random_walk"} <= terms
    # mg and micro-g give the same deviations in m/s^2
    mg = gyrolab.allan(s["output"] * 1e3 / G_N, rate_hz=100.0, unit="mg", confidence=None)
    ug = gyrolab.allan(s["output"] * 1e6 / G_N, rate_hz=100.0, unit="ug", confidence=None)
    np.testing.assert_allclose(ug.dev, mg.dev, rtol=1e-12)
    np.testing.assert_allclose(mg.dev, gyrolab.allan(s["output"], rate_hz=100.0, unit="m/s^2", confidence=None).dev, rtol=1e-12)
