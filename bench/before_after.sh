#!/usr/bin/env bash
# Two builds of gyrolab on the same cases, one after the other, alternating (issue 52: no speed
# lost to a restructuring). Each case is timed best of ROUNDS for each build in turn: the 10 M-line
# CSV (`allan FILE --json`), the 1 h 400 Hz MCAP recording (`allan FILE.mcap --json`), a batch of
# COUNT records with one worker and with every core, and the Python `gyrolab.allan` on 60,000 and
# 10 M samples (median of 100 and of 5 calls) when both native modules are given.
#
# Usage: bash bench/before_after.sh OLD_BIN NEW_BIN [OLD_SO NEW_SO] [ROUNDS] [COUNT]
#   OLD_SO, NEW_SO: the `lib_gyrolab.so` of each build (laid out as packages with
#   scripts/stage_python_package.py); give `-` for none. Data in bench/.data (bench/make_data.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
OLD=$1 NEW=$2 OLD_SO=${3:--} NEW_SO=${4:--} ROUNDS=${5:-3} COUNT=${6:-100}
PY=.venv/bin/python
DATA=bench/.data
mkdir -p "$DATA"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); load $(cut -d' ' -f1-3 /proc/loadavg)"

source bench/timing.sh
row() { # name old new
    printf "| %s | %s | %s | %s |\n" "$1" "$2" "$3" "$(awk -v a="$2" -v b="$3" 'BEGIN{printf "%+.1f %%", (b / a - 1) * 100}')"
}

CSV=$DATA/rate_10m.csv
bash bench/make_data.sh rate_10m "$PY" "$CSV"
REC=$DATA/batch_$COUNT/records
bash bench/make_data.sh batch "$NEW" "$REC" "$COUNT"
MCAP=$DATA/imu_1h_400hz.mcap
[ -f "$MCAP" ] || bash bench/recording_vs_python.sh 1 1 >/dev/null

echo
echo "| case (s, best of $ROUNDS) | before | after | change |"
echo "|---|---:|---:|---:|"
# Each case: the old build, then the new, then the old and the new again, the best of each kept.
pair() { # name command-args... (BIN substituted)
    local name=$1 o1 n1 o2 n2
    shift
    o1=$(best "$ROUNDS" "$OLD" "$@"); n1=$(best "$ROUNDS" "$NEW" "$@")
    o2=$(best "$ROUNDS" "$OLD" "$@"); n2=$(best "$ROUNDS" "$NEW" "$@")
    row "$name" "$(awk -v a="$o1" -v b="$o2" 'BEGIN{print (a<b)?a:b}')" "$(awk -v a="$n1" -v b="$n2" 'BEGIN{print (a<b)?a:b}')"
}
pair "csv_10m allan --json" allan "$CSV" --json
pair "mcap_1h allan --json" allan "$MCAP" --json
batch_of() { local bin=$1; shift; rm -rf "$DATA/ba_batch"; "$bin" batch "$REC" --out "$DATA/ba_batch" --quiet "$@"; }
bo=$(best "$ROUNDS" batch_of "$OLD" --jobs 1); bn=$(best "$ROUNDS" batch_of "$NEW" --jobs 1)
row "batch $COUNT records --jobs 1" "$bo" "$bn"
bo=$(best "$ROUNDS" batch_of "$OLD"); bn=$(best "$ROUNDS" batch_of "$NEW")
row "batch $COUNT records, all cores" "$bo" "$bn"

if [ "$OLD_SO" != "-" ] && [ "$NEW_SO" != "-" ]; then
    OLD_PKG=$("$PY" scripts/stage_python_package.py "$OLD_SO" "$DATA/ba_pkg_old")
    NEW_PKG=$("$PY" scripts/stage_python_package.py "$NEW_SO" "$DATA/ba_pkg_new")
    py_case() { # package n rounds
        PYTHONPATH="$1" "$PY" - "$2" "$3" <<'PY'
import statistics, sys, time
import numpy as np
import gyrolab
n, rounds = int(sys.argv[1]), int(sys.argv[2])
x = np.random.default_rng(1).standard_normal(n) * 0.01
gyrolab.allan(x, rate_hz=100.0)
t = []
for _ in range(rounds):
    t0 = time.perf_counter(); gyrolab.allan(x, rate_hz=100.0); t.append(time.perf_counter() - t0)
print(f"{statistics.median(t):.6f}")
PY
    }
    for n_r in "60000 100" "10000000 5"; do
        set -- $n_r
        o1=$(py_case "$OLD_PKG" "$1" "$2"); n1=$(py_case "$NEW_PKG" "$1" "$2")
        o2=$(py_case "$OLD_PKG" "$1" "$2"); n2=$(py_case "$NEW_PKG" "$1" "$2")
        row "python gyrolab.allan $1 samples (median)" "$(awk -v a="$o1" -v b="$o2" 'BEGIN{print (a<b)?a:b}')" "$(awk -v a="$n1" -v b="$n2" 'BEGIN{print (a<b)?a:b}')"
    done
fi
echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
