#!/usr/bin/env python3
"""Convert an ADIS16405 record of the SMAC-Group imudata R package to a CSV gyrolab reads.

The GMWM authors' public data (https://github.com/SMAC-Group/imudata, data/adis_16405_imu<K>.rda,
CC BY-NC-SA 4.0, (c) S. Guerrier and R. Molinari): a 6 x 1,000,000 matrix of a static ADIS16405
sampled at 100 Hz (attribute freq = 100) for 10,000 s; columns "Gyro. X" .. "Accel. Z". The
units are not stated in the package; the values sit on grids of 0.05 (gyro: the ADIS16405's
deg/s per LSB) and 0.00333 (accelerometer: g per LSB), so the gyro columns are written as deg/s
and the accelerometer columns as g. The converted file is not part of the repository (licence:
non-commercial, share-alike); docs/METHODS.md 3.1 shows the command and the figures.

Usage: python3 scripts/adis16405_to_csv.py data/adis_16405_imu1.rda out.csv
Needs the PyPI package `rdata` (pip install rdata numpy).
"""
import sys

import numpy as np
import rdata


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    parsed = rdata.parser.parse_file(sys.argv[1])
    vec = parsed.object.value[0]
    values = np.asarray(vec.value, dtype=np.float64)
    if values.size % 6:
        sys.exit(f"{sys.argv[1]}: {values.size} values is not a 6-column matrix")
    rows = values.size // 6
    matrix = values.reshape(6, rows).T  # R stores matrices column-major
    cols = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps", "accel_x_g", "accel_y_g", "accel_z_g"]
    with open(sys.argv[2], "w") as out:
        out.write("# ADIS16405 static record, SMAC-Group/imudata " + sys.argv[1] + " (CC BY-NC-SA 4.0), 100 Hz\n")
        out.write("time_s," + ",".join(cols) + "\n")
        for i, row in enumerate(matrix.tolist()):
            out.write(repr(i / 100.0) + "," + ",".join(repr(v) for v in row) + "\n")
    print(f"{sys.argv[2]}: {rows} rows", file=sys.stderr)


if __name__ == "__main__":
    main()
