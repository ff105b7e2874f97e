#!/usr/bin/env bash
# gyrolab.allan (the Python package) against allantools.oadev on the same 10 M-sample numpy array
# (octave taus; gyrolab with 68.3 % bounds and noise terms, allantools without), and the
# package's import time, in one run. Usage: bash bench/python_allan.sh [SAMPLES] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh >/dev/null
PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install --quiet --disable-pip-version-check --no-build-isolation ./python
N=${1:-10000000}
ROUNDS=${2:-3}
.venv/bin/python - "$N" "$ROUNDS" <<'PY'
import statistics, subprocess, sys, time
import numpy as np
n, rounds = int(sys.argv[1]), int(sys.argv[2])
imp = []
for _ in range(5):
    out = subprocess.run([sys.executable, "-X", "importtime", "-c", "import gyrolab"], capture_output=True, text=True).stderr
    total = [int(l.split("|")[1]) for l in out.splitlines() if l.rstrip().endswith("gyrolab") and "|" in l]
    imp.append(total[-1] / 1e6)
import gyrolab, allantools
x = np.random.default_rng(1).standard_normal(n) * 0.01
def best(f):
    t = []
    for _ in range(rounds):
        t0 = time.perf_counter(); f(); t.append(time.perf_counter() - t0)
    return statistics.median(t), min(t), max(t)
g = best(lambda: gyrolab.allan(x, rate_hz=100.0))
a = best(lambda: allantools.oadev(x, rate=100.0, data_type="freq", taus="octave"))
print(f"| run ({n} samples, octave OADEV) | median s | range s |")
print("|---|---:|---:|")
print(f"| gyrolab.allan (68.3 % bounds, noise terms) | {g[0]:.3f} | {g[1]:.3f}-{g[2]:.3f} |")
print(f"| allantools.oadev (no bounds) | {a[0]:.3f} | {a[1]:.3f}-{a[2]:.3f} |")
print(f"| speed-up (median) | {a[0] / g[0]:.1f}x | |")
print(f"| import gyrolab (cumulative, -X importtime, median of 5) | {statistics.median(imp):.3f} | {min(imp):.3f}-{max(imp):.3f} |")
PY
