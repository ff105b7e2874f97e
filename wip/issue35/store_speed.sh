#!/usr/bin/env bash
# Benchmark (not run in CI): the records store (docs/STORE.md).
#   1. What storing adds to `gyrolab eval` on the example test program
#      (examples/test_program/plan.toml): median wall time of RUNS runs without and with
#      `--store FILE` (SQLite), alternating, and the overhead in per cent.
#   2. 10,000 stored evaluations (N; copies of the example's record with their own serials and
#      scattered values, crates/gyrolab-store/examples/store_fill.rs), then the wall time of
#      `gyrolab store lot BENCH` (statistics over N devices) and `gyrolab store history SERIAL`,
#      best of RUNS, on SQLite and on PostgreSQL (a throw-away server, scripts/pg-test-server.sh).
# Usage: bench/store_speed.sh [N] [RUNS]   (PROFILE=dev for the debug build; default release)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-10000}
RUNS=${2:-5}
PROFILE=${PROFILE:-release}
DIR=$([ "$PROFILE" = dev ] && echo debug || echo "$PROFILE")
cargo build --profile "$PROFILE" -q -p gyrolab-cli
cargo build --profile "$PROFILE" -q -p gyrolab-store --example store_fill
BIN=$PWD/target/$DIR/gyrolab
FILL=$PWD/target/$DIR/examples/store_fill
echo "profile $PROFILE; $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
WORK=$(mktemp -d /tmp/gyrolab-store-bench.XXXXXX)
cleanup() { rm -rf "$WORK"; }
trap cleanup EXIT
PLAN=examples/test_program/plan.toml

now() { date +%s.%N; }
elapsed() { python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.4f}')" "$1" "$2"; }
median() { python3 -c "import sys, statistics; print(f'{statistics.median(map(float, sys.argv[1:])):.4f}')" "$@"; }
best() { python3 -c "import sys; print(f'{min(map(float, sys.argv[1:])):.4f}')" "$@"; }

echo "== 1. gyrolab eval $PLAN, without and with --store (SQLite), $RUNS runs each, alternating"
plain=()
stored=()
"$BIN" eval "$PLAN" --out "$WORK/warm" -q || [ $? -eq 3 ]
for i in $(seq "$RUNS"); do
    t0=$(now); "$BIN" eval "$PLAN" --out "$WORK/plain" -q || [ $? -eq 3 ]; t1=$(now)
    plain+=("$(elapsed "$t0" "$t1")")
    t0=$(now); "$BIN" eval "$PLAN" --out "$WORK/stored" -q --store "$WORK/eval.db" || [ $? -eq 3 ]; t1=$(now)
    stored+=("$(elapsed "$t0" "$t1")")
done
mp=$(median "${plain[@]}")
ms=$(median "${stored[@]}")
echo "eval median ${mp} s; eval --store median ${ms} s; overhead $(python3 -c "print(f'{100 * ($ms - $mp) / $mp:.1f}')") %"

query_times() { # $1 = store location, $2 = label
    local lot=() hist=() t0 t1
    for i in $(seq "$RUNS"); do
        t0=$(now); "$BIN" store lot BENCH --store "$1" >/dev/null; t1=$(now); lot+=("$(elapsed "$t0" "$t1")")
        t0=$(now); "$BIN" store history BENCH-04321 --store "$1" >/dev/null; t1=$(now); hist+=("$(elapsed "$t0" "$t1")")
    done
    echo "$2: store lot BENCH ($N devices) best $(best "${lot[@]}") s; store history BENCH-04321 best $(best "${hist[@]}") s"
}

echo "== 2. $N stored evaluations, then lot and history, best of $RUNS"
"$FILL" "$WORK/bench.db" "$N" "$WORK/stored" "$PLAN"
query_times "$WORK/bench.db" "SQLite ($(du -h "$WORK/bench.db" | cut -f1))"
# shellcheck source=../scripts/pg-test-server.sh
source scripts/pg-test-server.sh start
trap 'gyrolab_pg_stop; cleanup' EXIT
"$FILL" "$GYROLAB_TEST_PG_URL" "$N" "$WORK/stored" "$PLAN"
query_times "$GYROLAB_TEST_PG_URL" "PostgreSQL"
