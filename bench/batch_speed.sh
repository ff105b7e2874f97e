#!/usr/bin/env bash
# Benchmark (not run in CI): `gyrolab batch` over COUNT simulated static records (10 min at
# 100 Hz each, 60,000 rows, made by `gyrolab simulate static`), in one run against
#   - the same batch on one worker thread (the single-record time x count): the all-core batch
#     should take that time / cores within 20 %;
#   - a shell loop of `gyrolab allan FILE --json` processes, one per record;
#   - a Python loop over the records: pandas.read_csv + allantools.oadev (octave; no bounds and
#     no noise terms, so less work than gyrolab does).
# Wall time of each whole run (date +%s%N), one run each (the runs are long; say the load).
# Usage: bench/batch_speed.sh [COUNT]   (default 1000; creates bench/.venv and bench/.data if
# missing; VENV=path uses another virtual environment with allantools and pandas;
# GYROLAB_BIN=path times that binary instead of building target/release/gyrolab)
set -euo pipefail
cd "$(dirname "$0")/.."
COUNT=${1:-1000}
VENV=${VENV:-bench/.venv}
DATA=bench/.data/batch_$COUNT
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import allantools, pandas" 2>/dev/null; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q allantools numpy pandas
fi
PY="$VENV/bin/python"
if [ -z "${GYROLAB_BIN:-}" ]; then cargo build --release -q -p gyrolab-cli; fi
BIN=${GYROLAB_BIN:-target/release/gyrolab}
bash bench/make_data.sh batch "$BIN" "$DATA/records" "$COUNT"
FILES=("$DATA"/records/*.csv)
CORES=$(nproc)

# wall seconds of a command (its output discarded; exit codes 0 only)
wall() {
    local t0 t1
    t0=$(date +%s%N)
    "$@" >/dev/null 2>"$DATA/err.txt" || { cat "$DATA/err.txt"; exit 1; }
    t1=$(date +%s%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.3f", (b - a) / 1e9}'
}
shell_loop() {
    for f in "${FILES[@]}"; do "$BIN" allan "$f" --json >/dev/null; done
}

echo "machine: $CORES cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "records: ${#FILES[@]} x 600 s at 100 Hz ($(du -sh "$DATA/records" | cut -f1))"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
rm -rf "$DATA/out1" "$DATA/outn" "$DATA/outr"
t1=$(wall "$BIN" batch "$DATA/records" --out "$DATA/out1" --jobs 1 --quiet)
tn=$(wall "$BIN" batch "$DATA/records" --out "$DATA/outn" --quiet)
rows=$(($(wc -l <"$DATA/outn/results.csv") - 1))
[ "$rows" -eq "${#FILES[@]}" ] || { echo "results.csv has $rows rows, expected ${#FILES[@]}"; exit 1; }
cmp -s "$DATA/out1/results.csv" "$DATA/outn/results.csv" || { echo "one worker and all cores disagree"; exit 1; }
tr=$(wall "$BIN" batch "$DATA/records" --out "$DATA/outn" --quiet)
ts=$(wall shell_loop)
tp=$(wall "$PY" bench/batch_allantools_loop.py 100 "${FILES[@]}")
printf "| way | wall s | records/s | gyrolab batch is faster by |\n|---|---:|---:|---:|\n"
row() { printf "| %s | %s | %s | %s |\n" "$1" "$2" "$(awk -v n="${#FILES[@]}" -v s="$2" 'BEGIN{printf "%.0f", n/s}')" \
    "$(awk -v a="$2" -v b="$tn" 'BEGIN{printf "%.1f x", a/b}')"; }
row "gyrolab batch, all $CORES cores" "$tn"
row "gyrolab batch --jobs 1" "$t1"
row "shell loop of gyrolab allan --json" "$ts"
row "Python loop: pandas.read_csv + allantools.oadev" "$tp"
printf "| gyrolab batch started again (all done: hashes only) | %s | %s | - |\n" "$tr" \
    "$(awk -v n="${#FILES[@]}" -v s="$tr" 'BEGIN{printf "%.0f", n/s}')"
echo "all-core batch / (one-worker batch / $CORES cores): $(awk -v a="$tn" -v b="$t1" -v c="$CORES" 'BEGIN{printf "%.2f", a / (b / c)}') (1.00 = perfect scaling; target <= 1.20)"
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
