"""Where gyrolab.allan's time goes on a 10 M-sample array, against the memory passes any
implementation needs (issue 18). Run with the bench venv after bench/python_allan.sh installed
the package: .venv/bin/python bench/python_allan_stages.py [SAMPLES] [ROUNDS]"""
import statistics, sys, time
import numpy as np
import gyrolab, allantools
from gyrolab import _gyrolab

n = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000_000
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 5
x = np.random.default_rng(1).standard_normal(n) * 0.01


def med(f):
    t = []
    for _ in range(rounds):
        t0 = time.perf_counter(); f(); t.append(time.perf_counter() - t0)
    return statistics.median(t), min(t)


rows = [
    ("numpy: copy into a new array (one read, one write, page faults)", lambda: x.copy()),
    ("numpy: cumulative sum into a new array", lambda: np.cumsum(x)),
    ("numpy: sum (one read)", lambda: np.add.reduce(x)),
    ("native allan, no bounds (copy, angle, OADEV sums, noise terms, JSON)",
     lambda: _gyrolab.allan(x, 100.0, "oadev", "octave", None, "dps")),
    ("native allan, 68.3 % bounds", lambda: _gyrolab.allan(x, 100.0, "oadev", "octave", 0.683, "dps")),
    ("gyrolab.allan, 68.3 % bounds (the package call)", lambda: gyrolab.allan(x, rate_hz=100.0)),
    ("allantools.oadev octave, no bounds",
     lambda: allantools.oadev(x, rate=100.0, data_type="freq", taus="octave")),
]
print(f"| stage ({n} samples) | median s | best s |")
print("|---|---:|---:|")
for name, f in rows:
    m, b = med(f)
    print(f"| {name} | {m:.4f} | {b:.4f} |")
