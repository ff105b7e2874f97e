"""The Python way over a fleet (for bench/batch_speed.sh): one record after another, each read
with pandas.read_csv and its octave OADEV computed by allantools (no bounds, no noise terms).

usage: batch_allantools_loop.py RATE_HZ FILE...     prints the number of records done
"""
import sys

import allantools
import pandas as pd


def main():
    rate = float(sys.argv[1])
    done = 0
    for path in sys.argv[2:]:
        frame = pd.read_csv(path, comment="#")
        data = frame.iloc[:, 1].to_numpy(dtype=float)
        allantools.oadev(data, rate=rate, data_type="freq", taus="octave")
        done += 1
    print(done)


if __name__ == "__main__":
    main()
