#!/usr/bin/env python3
"""Independent time-binned reading of the dense drops of a REAL PX4 log (pyulog + numpy) for
gyrolab's present-sample Allan estimator (crates/gyrolab-eval/tests/integration/clock.rs,
`dense_drops_keep_the_long_taus_of_a_real_px4_log`).

Topic sensor_combined of examples/recordings/px4_sample_logging_tagged_and_default_params.ulg
(PX4/pyulog's test log, BSD-3-Clause): a 4 ms sample clock with single 8 ms steps, a quarter of
the samples missing. Each message is put in its 4 ms time slot (round((t - t0) / base)); for
tau = m x base, every window of m slots is averaged over the messages in it (the time-binned
mean, no interpolation) and used when it holds at least half its slots; the overlapping Allan
deviation is sqrt(mean of (next window mean - window mean)^2 / 2) over the pairs of usable
windows, at m = 16 ... 512, for each gyro axis in deg/s. No white-noise correction: gyrolab's
estimator removes the white excess of the missing samples (docs/METHODS.md), a few percent here.

Usage: px4_dense_drops_reference.py [--check] ULG JSON
  writes JSON, or with --check compares a fresh reading with it (exit 1 on a difference).
"""
import json
import math
import sys

import numpy as np
from pyulog import ULog


def reading(ulg):
    log = ULog(ulg, ["sensor_combined"])
    d = next(x for x in log.data_list if x.name == "sensor_combined")
    t = d.data["timestamp"].astype(np.float64) * 1e-6
    base = float(np.median(np.diff(t)))
    slot = np.rint((t - t[0]) / base).astype(np.int64)
    n = int(slot[-1]) + 1
    out = {
        "source": "examples/recordings/px4_sample_logging_tagged_and_default_params.ulg, topic sensor_combined (PX4/pyulog test/sample_logging_tagged_and_default_params.ulg, BSD-3-Clause)",
        "made_by": "scripts/px4_dense_drops_reference.py (pyulog %s, numpy %s)"
        % (__import__("pyulog").__version__, np.__version__),
        "messages": len(t),
        "slots": n,
        "base_interval_s": base,
        "oadev_dps": {},
    }
    for axis, name in enumerate(["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]):
        y = np.zeros(n)
        have = np.zeros(n)
        y[slot] = d.data["gyro_rad[%d]" % axis].astype(np.float64) * (180.0 / math.pi)
        have[slot] = 1.0
        c = np.concatenate([[0.0], np.cumsum(y)])
        k = np.concatenate([[0.0], np.cumsum(have)])
        points = []
        m = 16
        while 2 * m <= n and m <= 512:
            i = np.arange(0, n - 2 * m + 1)
            k1 = k[i + m] - k[i]
            k2 = k[i + 2 * m] - k[i + m]
            ok = (k1 >= math.ceil(0.5 * m)) & (k2 >= math.ceil(0.5 * m))
            a = (c[i + m] - c[i])[ok] / k1[ok]
            b = (c[i + 2 * m] - c[i + m])[ok] / k2[ok]
            if ok.any():
                points.append([m, int(ok.sum()), math.sqrt(float(np.mean((b - a) ** 2)) / 2.0)])
            m *= 2
        out["oadev_dps"][name] = points
    return out


def main():
    args = sys.argv[1:]
    check = args and args[0] == "--check"
    if check:
        args = args[1:]
    ulg, path = args
    fresh = reading(ulg)
    if not check:
        with open(path, "w") as f:
            json.dump(fresh, f, indent=1)
            f.write("\n")
        return 0
    with open(path) as f:
        kept = json.load(f)
    same = fresh["messages"] == kept["messages"] and fresh["slots"] == kept["slots"]
    for name, pts in fresh["oadev_dps"].items():
        for (m, n, s), (m2, n2, s2) in zip(pts, kept["oadev_dps"][name]):
            same &= m == m2 and n == n2 and abs(s / s2 - 1) < 1e-12
    print("px4_dense_drops_reference: %s" % ("matches" if same else "DIFFERS from") + " " + path)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
