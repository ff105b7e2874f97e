#!/usr/bin/env python3
"""Independent reading of the PX4 ULog in examples/recordings (pyulog + numpy) for gyrolab's
clock-model test (crates/gyrolab-eval/tests/integration/clock.rs, `px4_log_matches_pyulog_and_numpy`).

For topic sensor_combined (its `timestamp` is the gyro's sampling time, microseconds):
- the clock model's rule done here in numpy: base = median interval; the stamps are a sample
  clock when at least 99 % of the intervals lie within 0.1 base of a whole multiple of it;
  an interval of k > 1 base intervals (rounded) holds k - 1 dropped samples;
- rate = (n - 1 + missing) / span;
- OADEV of gyro_rad[0..3] (float32 widened, times 180/pi: deg/s) on the uniform grid with the
  dropped samples missing, each term over a window of 2m samples left out when the window holds a
  missing sample (NIST SP 1065 section 8.7, allantools' gradev), at m = 1, 2, 4, ... 64.

Usage: px4_clock_reference.py [--check] ULG JSON
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
    dt = np.diff(t)
    base = float(np.median(dt))
    k = np.rint(dt / base)
    on_grid = float(np.mean((k >= 1) & (np.abs(dt / base - k) <= 0.1)))
    assert on_grid >= 0.99, on_grid
    k = k.astype(np.int64)
    missing = int(np.sum(k - 1))
    gaps = [[int(i + 1), int(kk - 1)] for i, kk in enumerate(k) if kk > 1]
    span = float(t[-1] - t[0])
    rate = (len(t) - 1 + missing) / span
    slots = np.concatenate([[0], np.cumsum(k)])
    out = {
        "source": "examples/recordings/px4_sample_log_small.ulg, topic sensor_combined (PX4/pyulog test/sample_log_small.ulg, BSD-3-Clause)",
        "made_by": "scripts/px4_clock_reference.py (pyulog %s, numpy %s)" % (__import__("pyulog").__version__, np.__version__),
        "messages": len(t),
        "base_interval_s": base,
        "on_grid": on_grid,
        "missing": missing,
        "gaps": gaps,
        "rate_hz": rate,
        "oadev_dps": {},
    }
    for axis, name in enumerate(["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]):
        y = np.full(int(slots[-1]) + 1, np.nan)
        y[slots] = d.data["gyro_rad[%d]" % axis].astype(np.float64) * (180.0 / math.pi)
        bad = np.concatenate([[0], np.cumsum(np.isnan(y))])
        c = np.concatenate([[0.0], np.cumsum(np.nan_to_num(y))])
        points = []
        m = 1
        while 2 * m <= len(y) and m <= 64:
            i = np.arange(0, len(y) - 2 * m + 1)
            ok = bad[i + 2 * m] - bad[i] == 0
            a = (c[i + m] - c[i]) / m
            b = (c[i + 2 * m] - c[i + m]) / m
            terms = int(np.sum(ok))
            if terms > 0:
                s = float(np.sum(((b - a)[ok]) ** 2))
                points.append([m, terms, math.sqrt(s / (2 * terms))])
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
    same = all(fresh[k] == kept[k] for k in ["messages", "missing", "gaps"])
    same &= abs(fresh["rate_hz"] / kept["rate_hz"] - 1) < 1e-12
    for name, pts in fresh["oadev_dps"].items():
        for (m, n, s), (m2, n2, s2) in zip(pts, kept["oadev_dps"][name]):
            same &= m == m2 and n == n2 and abs(s / s2 - 1) < 1e-12
    print("px4_clock_reference: %s" % ("matches" if same else "DIFFERS from") + " " + path)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
