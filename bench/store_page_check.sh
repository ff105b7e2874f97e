#!/usr/bin/env bash
# Benchmark (not run in CI): what SQLite's page check (PRAGMA quick_check, issue 53) adds to
# opening a store for writing, against the store's size. N evaluations of the example test
# program, each of its own simulated records (seed i: its raw records are kept, so the store
# grows by about 6 MB each), are stored; then, best of RUNS, the wall time of
#   `gyrolab store show 1`                          (opened for reading: no check)
#   `gyrolab store revise 999999 --kind correction` (opened for writing: the quick check with
#                                                    the page check, then refused: no such id)
#   `gyrolab store check`                           (the full check: integrity_check, every
#                                                    link, every stored file and raw record)
# Usage: bench/store_page_check.sh [N] [RUNS]   (default 40 evaluations, 5 runs; release build)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-40}
RUNS=${2:-5}
cargo build --release -q -p gyrolab-cli
BIN=$PWD/target/release/gyrolab
DATA=$(mktemp -d /tmp/gyrolab-page-check.XXXXXX)
trap 'rm -rf "$DATA"' EXIT
# shellcheck source=timing.sh
source bench/timing.sh
echo "$(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
for i in $(seq "$N"); do
    "$BIN" simulate test-program "$DATA/tp" --seed "$i" >/dev/null 2>&1
    "$BIN" eval "$DATA/tp/plan.toml" --out "$DATA/r" -q --store "$DATA/lab.db" || [ $? -eq 3 ]
    rm -rf "$DATA/tp" "$DATA/r"
done
MB=$(du -m "$DATA/lab.db" | cut -f1)
revise() { "$BIN" store revise 999999 --kind correction --by bench --reason bench --lot X --store "$DATA/lab.db" || [ $? -eq 2 ]; }
echo "store: $N evaluations, $MB MB"
echo "store show 1 (read, no check):        $(best "$RUNS" "$BIN" store show 1 --store "$DATA/lab.db") s"
echo "open for writing (quick + page check): $(best "$RUNS" revise) s"
echo "store check (full):                    $(best "$RUNS" "$BIN" store check --store "$DATA/lab.db") s"
