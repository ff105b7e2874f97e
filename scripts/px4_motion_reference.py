#!/usr/bin/env python3
"""Independent reading of a REAL PX4 flight log (pyulog + numpy) for gyrolab's stillness check
(crates/gyrolab-cli/tests/integration/stillness.rs, `a_real_px4_flight_is_found_moving`).

For topic sensor_combined (its `timestamp` is the gyro's sampling time, microseconds), each of
gyro_rad[0..3] (float32 widened, times 180/pi: deg/s), read without gyrolab's clock model:
- windows of 1 s by time stamp, from the first message (window i holds the messages with
  i <= (t - t0) / 1 s < i + 1); a window is judged when it holds at least half the median
  window's messages;
- the still level: the median of the judged windows' means;
- windows whose mean departs from the still level by more than 1 deg/s (the check's floor for a
  gyro): counted, with the first one's start (s from the first message) and the largest
  departure.
The test allows for the different window grid (gyrolab places samples on its clock model's
grid): levels within 0.01 deg/s, episodes within a window.

Usage: px4_motion_reference.py [--check] ULG JSON
  writes JSON, or with --check compares a fresh reading with it (exit 1 on a difference).
"""
import json
import math
import sys

import numpy as np
from pyulog import ULog

FLOOR_DPS = 1.0


def reading(ulg):
    log = ULog(ulg, ["sensor_combined"])
    d = next(x for x in log.data_list if x.name == "sensor_combined")
    t = d.data["timestamp"].astype(np.float64) * 1e-6
    out = {
        "source": "examples/recordings/px4_sample_flight.ulg, topic sensor_combined (PX4/pyulog test/sample.ulg, BSD-3-Clause)",
        "made_by": "scripts/px4_motion_reference.py (pyulog %s, numpy %s)" % (__import__("pyulog").__version__, np.__version__),
        "messages": len(t),
        "span_s": float(t[-1] - t[0]),
        "floor_dps": FLOOR_DPS,
        "channels": {},
    }
    index = np.floor((t - t[0]) / 1.0).astype(np.int64)
    counts = np.bincount(index)
    judged = np.nonzero(counts * 2 >= np.median(counts))[0]
    for axis, name in enumerate(["gyro_x", "gyro_y", "gyro_z"]):
        y = d.data["gyro_rad[%d]" % axis].astype(np.float64) * (180.0 / math.pi)
        sums = np.bincount(index, weights=y)
        means = sums[judged] / counts[judged]
        level = float(np.median(means))
        dep = np.abs(means - level)
        moved = np.nonzero(dep > FLOOR_DPS)[0]
        out["channels"][name] = {
            "windows": int(len(judged)),
            "still_level_dps": level,
            "mean_moved_windows": int(len(moved)),
            "first_mean_moved_start_s": float(judged[moved[0]]) if len(moved) else None,
            "largest_mean_departure_dps": float(dep.max()),
        }
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
        stored = json.load(f)
    fresh.pop("made_by")
    stored.pop("made_by")
    if json.dumps(fresh, sort_keys=True) != json.dumps(stored, sort_keys=True):
        print("px4_motion_reference: %s differs from a fresh reading of %s" % (path, ulg), file=sys.stderr)
        return 1
    print("px4_motion_reference: matches " + path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
