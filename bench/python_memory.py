"""Peak memory of gyrolab.allan on a large contiguous float64 array, one subprocess per kind
(peak resident set size from getrusage, so nothing else shares the high-water mark). Prints
one Markdown row per kind: the input's size, the process's peak and the peak above the
interpreter with the input made (what gyrolab adds). Usage:
.venv/bin/python bench/python_memory.py [SAMPLES] [KIND ...]   (default 50000000 oadev totdev)"""
import subprocess
import sys

CHILD = r"""
import resource, sys, time
import numpy as np
import gyrolab
n, kind = int(sys.argv[1]), sys.argv[2]
x = np.random.default_rng(1).standard_normal(n)
x.flags.writeable = False
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
r = gyrolab.allan(x, rate_hz=100.0, kind=kind)
dt = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(before, peak, dt, len(r.taus_s))
"""


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 50_000_000
    kinds = sys.argv[2:] or ["oadev", "totdev"]
    mib = 1024.0
    print(f"| kind | samples | input (MiB) | peak RSS (MiB) | above input (MiB) | time (s) |")
    print("|---|---|---|---|---|---|")
    for kind in kinds:
        out = subprocess.run([sys.executable, "-c", CHILD, str(n), kind], check=True, capture_output=True, text=True)
        before, peak, dt, taus = out.stdout.split()
        before, peak = int(before) / mib, int(peak) / mib
        print(
            f"| {kind} | {n} | {n * 8 / 2**20:.0f} | {peak:.0f} | {peak - before:.0f} | {float(dt):.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
