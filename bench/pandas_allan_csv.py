"""The Python way to an Allan deviation from a CSV log: pandas.read_csv, then allantools.oadev
(octave taus, rate data) on every channel. Times the whole process from the shell (this script
prints its own read and compute split and its peak memory).

usage: pandas_allan_csv.py FILE RATE_HZ
"""
import resource
import sys
import time

import allantools
import pandas as pd


def main():
    path, rate = sys.argv[1], float(sys.argv[2])
    t0 = time.perf_counter()
    df = pd.read_csv(path, comment="#")
    t1 = time.perf_counter()
    cols = [c for c in df.columns if not c.lower().startswith(("time", "t[", "#time", "timestamp"))]
    for c in cols:
        allantools.oadev(df[c].to_numpy(), rate=rate, data_type="freq", taus="octave")
    t2 = time.perf_counter()
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"read_s {t1 - t0:.3f} compute_s {t2 - t1:.3f} channels {len(cols)} peak_mb {peak_mb:.0f}")


if __name__ == "__main__":
    main()
