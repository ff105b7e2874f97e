"""Resources of a long call (issue 34): the interpreter is released while gyrolab computes (a
second Python thread keeps running), and no kind copies a contiguous float64 input or builds
anything proportional to N beyond its one angle series (peak RSS of a fresh subprocess; the
figures at 50 M samples are bench/python_memory.py's, in docs/PERFORMANCE.md)."""
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import gyrolab


def test_a_second_thread_runs_while_allan_computes():
    x = np.random.default_rng(5).standard_normal(4_000_000)
    span = {}

    def work():
        span["start"] = time.perf_counter()
        gyrolab.allan(x, rate_hz=100.0, kind="mdev")
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=work)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    duration = span["end"] - span["start"]
    inside = [t for t in ticks if span["start"] < t < span["end"]]
    assert duration > 0.05, f"the call took {duration:.3f} s: too short to tell"
    # With the interpreter held for the whole call the main thread could not tick at all.
    assert len(inside) >= 10, (len(inside), duration)
    gaps = np.diff([span["start"], *inside, span["end"]])
    assert gaps.max() < 0.5 * duration, (gaps.max(), duration)


CHILD = r"""
import resource, sys
import numpy as np
import gyrolab
x = np.random.default_rng(1).standard_normal(int(sys.argv[1]))
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
gyrolab.allan(x, rate_hz=100.0, kind=sys.argv[2])
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="ru_maxrss is in KiB on Linux")
@pytest.mark.parametrize("kind", ["oadev", "mdev", "totdev"])
def test_no_copy_of_the_input_and_one_angle_series(kind):
    n = 3_000_000
    out = subprocess.run([sys.executable, "-c", CHILD, str(n), kind], check=True, capture_output=True, text=True)
    added_bytes = int(out.stdout) * 1024
    # one angle series (N + 1 values) and small change; a copy of the input would add another
    # N values, TOTDEV's former reflected series three.
    assert added_bytes < 1.5 * n * 8, f"{kind}: {added_bytes / 2**20:.0f} MiB added for a {n * 8 / 2**20:.0f} MiB input"
