"""The defaults of the Python package agree with the command line's (issue 32)."""

import os
import subprocess

import numpy as np
import pytest

import gyrolab


def test_simulate_static_without_options_is_a_typical_mems_gyro_not_zeros():
    with pytest.warns(UserWarning, match="typical MEMS gyro"):
        rec = gyrolab.simulate_static(1200.0, 100.0, seed=3)
    y = rec["output"]
    # white noise of N = 0.3 deg/sqrt(h) at 100 Hz: per-sample sigma = N/60 * sqrt(100) = 0.05 deg/s
    assert abs(np.std(y) / 0.05 - 1.0) < 0.05
    # the constant bias of 20 deg/h, in deg/s, within a few sigma of the mean
    assert abs(np.mean(y) - 20.0 / 3600.0) < 5 * 0.05 / np.sqrt(y.size) + 5e-3


def test_a_noise_term_turns_the_default_off():
    rec = gyrolab.simulate_static(10.0, 100.0, seed=3, arw_deg_rt_h=0.0)
    assert np.all(rec["output"] == 0.0)


def test_python_and_command_line_simulate_the_same_default_record(tmp_path):
    binary = os.environ.get("GYROLAB_BIN")
    if not binary or not os.path.exists(binary):
        pytest.skip("SKIPPED: GYROLAB_BIN not set to a built gyrolab binary")
    out = tmp_path / "s.csv"
    subprocess.run([binary, "simulate", "static", "--duration-s", "60", "--seed", "5", "--out", str(out)],
                   check=True, capture_output=True)
    rows = [line for line in out.read_text().splitlines() if line and not line.startswith("#")]
    cli = np.array([float(line.split(",")[1]) for line in rows[1:]])  # rows[0]: time_s,rate_dps
    with pytest.warns(UserWarning):
        py = gyrolab.simulate_static(60.0, 100.0, seed=5)["output"]
    assert cli.size == py.size
    np.testing.assert_allclose(cli, py, rtol=1e-9, atol=1e-12)
