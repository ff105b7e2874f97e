"""Writes the SIMULATED sample recordings of this folder (examples/recordings/README.md):
60 s of IMU samples at 100 Hz with known truth, written by the project's independent test
writers (scripts/write_recordings.py: rosbags and the mcap package, not gyrolab's code).

usage (from the repository root, with the test venv of scripts/install-test-deps.sh):
    .venv/bin/python examples/recordings/make_simulated.py /tmp/rec
    cp /tmp/rec/out/plain_zstd.mcap examples/recordings/simulated_imu_ros2.mcap
    cp /tmp/rec/out/imu_bz2.bag examples/recordings/simulated_imu_ros1.bag
"""
import subprocess
import sys
from pathlib import Path

import numpy as np

work = Path(sys.argv[1])
work.mkdir(parents=True, exist_ok=True)
rng = np.random.default_rng(32)
n, fs = 6000, 100.0
t0 = 1_700_000_000_000_000_000
stamps = t0 + (np.arange(n) * 10_000_000)
# Gyro (rad/s): white noise of angle random walk N = 0.3 deg/sqrt(h), i.e. a per-sample standard
# deviation of N/60*sqrt(fs) deg/s, and constant biases of 20, -15, 10 deg/h.
sd_g = 0.3 / 60 * np.sqrt(fs) * np.pi / 180
bias = np.array([20.0, -15.0, 10.0]) / 3600 * np.pi / 180
g = rng.normal(0, sd_g, (n, 3)) + bias
# Accelerometer (m/s^2): velocity random walk 0.05 m/s/sqrt(h), gravity on z.
sd_a = 0.05 / 60 * np.sqrt(fs)
a = rng.normal(0, sd_a, (n, 3)) + np.array([0.0, 0.0, 9.80665])
with open(work / "in.csv", "w") as f:
    f.write("timestamp_ns,gx,gy,gz,ax,ay,az\n")
    for s, gg, aa in zip(stamps, g, a):
        f.write("%d,%r,%r,%r,%r,%r,%r\n" % (s, *map(float, gg), *map(float, aa)))
here = Path(__file__).resolve().parent
subprocess.run(
    [sys.executable, str(here.parent.parent / "scripts" / "write_recordings.py"), str(work / "in.csv"), str(work / "out")],
    check=True,
)
