#!/usr/bin/env python3
"""Equality of gyrolab's deviations with Python allantools on random records.

Rate data are allantools' data_type='freq'. For every kind, gyrolab's taus (octave and decade
lists) are passed to allantools, and every deviation must agree to relative 1e-9. Records:
white noise, random walk and a large offset (2.5 + 1e-4 noise), seeded so runs repeat.
Usage: check_allantools.py GYROLAB_BINARY
Prints 'N passed, M failed' and exits non-zero on any failure.
"""
import json
import os
import subprocess
import sys
import tempfile

import allantools
import numpy as np

KINDS = ["oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev"]
REL = 1e-9


def records():
    rng = np.random.default_rng(20261122)
    yield "white", rng.standard_normal(5000) * 0.01, 100.0
    yield "random-walk", np.cumsum(rng.standard_normal(4096)) * 1e-3 + 0.2 * rng.standard_normal(4096), 10.0
    yield "offset", 2.5 + 1e-4 * rng.standard_normal(3000), 1.0


def main():
    binary = sys.argv[1]
    passed = failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name, data, rate in records():
            path = os.path.join(tmp, f"{name}.csv")
            with open(path, "w") as f:
                f.write("rate_dps\n")
                f.writelines(f"{v!r}\n" for v in data.tolist())
            for kind in KINDS:
                for taus in ["octave", "decade"]:
                    out = subprocess.run(
                        [binary, "allan", path, "--sample-rate-hz", repr(rate), "--kind", kind, "--taus", taus,
                         "--confidence", "none", "--json"],
                        check=True, capture_output=True, text=True).stdout
                    g = json.loads(out)
                    g_taus = np.array(g["taus_s"])
                    g_dev = np.array(g["dev"])
                    fn = getattr(allantools, kind)
                    a_taus, a_dev, _, _ = fn(data, rate=rate, data_type="freq", taus=g_taus)
                    common = [i for i, t in enumerate(g_taus) if np.any(np.isclose(a_taus, t, rtol=1e-12))]
                    if not common:
                        print(f"FAIL {name} {kind} {taus}: no common taus")
                        failed += 1
                        continue
                    worst = 0.0
                    for i in common:
                        j = int(np.argmin(np.abs(a_taus - g_taus[i])))
                        worst = max(worst, abs(g_dev[i] / a_dev[j] - 1.0))
                    ok = worst <= REL
                    print(f"{'ok  ' if ok else 'FAIL'} {name:12s} {kind:7s} {taus:7s} taus {len(common):3d}"
                          f" worst relative difference {worst:.2e}")
                    passed += ok
                    failed += not ok
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
