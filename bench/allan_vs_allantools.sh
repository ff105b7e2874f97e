#!/usr/bin/env bash
# Benchmark (not run in CI): gyrolab vs Python allantools, overlapping ADEV of rate ("freq")
# data, both tools on the same records in one run on this machine.
#   case 1: 10 M samples, octave taus          (allantools taus='octave')
#   case 2: 1 M samples, every m up to N/4     (gyrolab TauList::All stops at Stable32's N/4;
#           allantools gets the same m list as an array, like for like. Its taus='all' goes to
#           m = N/2, 4/3 of that work: ALLANTOOLS_ALL=1 also times it.)
# Compute time excludes loading the record; peak memory is the process's VmHWM / ru_maxrss.
# Gyrolab and allantools 10 M: best of 3 runs; the 1 M all-tau case: one run each.
# Usage: bench/allan_vs_allantools.sh            (creates bench/.venv and bench/.data if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=bench/.venv
DATA=bench/.data
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import allantools" 2>/dev/null; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q allantools numpy
fi
PY="$VENV/bin/python"
cargo build --release -q -p gyrolab --example allan_bench
BIN=target/release/examples/allan_bench
mkdir -p "$DATA"
[ -f "$DATA/rate_10m.bin" ] || "$BIN" gen "$DATA/rate_10m.bin" 10000000 1
[ -f "$DATA/rate_1m.bin" ] || "$BIN" gen "$DATA/rate_1m.bin" 1000000 2

# best of N: runs "$@" N times, keeps the output with the smallest compute_s in $OUT.time
best_of() {
    local n=$1 out=$2
    shift 2
    local best=""
    for _ in $(seq "$n"); do
        "$@" >"$out.try"
        local t
        t=$(awk '/compute_s/{print $2}' "$out.try")
        if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN{exit !(a<b)}'; then
            best=$t
            grep -v '^taus' "$out.try" >"$out.time"
        fi
    done
    rm -f "$out.try"
}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
best_of 3 "$DATA/g10m" "$BIN" run "$DATA/rate_10m.bin" oadev octave "$DATA/g10m.txt"
best_of 3 "$DATA/a10m" "$PY" bench/allantools_time.py "$DATA/rate_10m.bin" octave "$DATA/a10m.txt"
best_of 1 "$DATA/g1m" "$BIN" run "$DATA/rate_1m.bin" oadev all "$DATA/g1m.txt"
best_of 1 "$DATA/a1m" "$PY" bench/allantools_time.py "$DATA/rate_1m.bin" quarter "$DATA/a1m.txt"
cases=("10M OADEV octave:g10m:a10m" "1M OADEV all m<=N/4:g1m:a1m")
if [ "${ALLANTOOLS_ALL:-0}" = 1 ]; then
    best_of 1 "$DATA/a1mall" "$PY" bench/allantools_time.py "$DATA/rate_1m.bin" all "$DATA/a1mall.txt"
    cases+=("1M OADEV all (allantools to N/2):g1m:a1mall")
fi
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
"$PY" bench/report.py "$DATA" "${cases[@]}"
