"""Times allantools.oadev on a little-endian f64 rate record (compute only, loading excluded).

usage: allantools_time.py FILE TAUS OUT
TAUS: octave | all | quarter (every m from 1 to N/4, gyrolab's Stable32 stop limit, as an array).
Prints compute_s and peak_mb (ru_maxrss of the process), writes "m deviation" lines to OUT.
"""
import resource
import sys
import time

import allantools
import numpy as np

RATE = 100.0  # tau0 = 0.01 s, as allan_bench


def main():
    path, taus, out = sys.argv[1], sys.argv[2], sys.argv[3]
    data = np.fromfile(path, dtype="<f8")
    if taus == "quarter":
        taus = np.arange(1, len(data) // 4 + 1) / RATE
    t = time.perf_counter()
    tau, dev, _err, _n = allantools.oadev(data, rate=RATE, data_type="freq", taus=taus)
    dt = time.perf_counter() - t
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"compute_s {dt:.4f}\npeak_mb {peak_mb:.1f}\ntaus {len(tau)}")
    with open(out, "w") as f:
        for ta, d in zip(tau, dev):
            f.write(f"{int(round(ta * RATE))} {d:.17e}\n")


if __name__ == "__main__":
    main()
