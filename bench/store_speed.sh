#!/usr/bin/env bash
# Benchmark (not run in CI): the records store (docs/STORE.md, issue 35).
#   1. What storing adds to `gyrolab eval` on the example test program (the records of
#      examples/test_program, written by `gyrolab simulate test-program`): median wall time of
#      RUNS runs without and with `--store` (an SQLite file, then the PostgreSQL server),
#      alternating, and the overhead in per cent.
#   2. N stored evaluations (default 10,000 devices of lot BENCH, made from that report folder by
#      crates/gyrolab-store/examples/store_fill.rs, each in its own transaction; every 20th device
#      with two corrections), then the wall time of `gyrolab store lot BENCH` (statistics over N
#      devices) and `gyrolab store history BENCH-05000` (a device
#      in the middle, 3 revisions), best of RUNS, on SQLite and
#      on PostgreSQL (a throw-away server started by scripts/pg-test-server.sh, fsync off).
# Usage: bench/store_speed.sh [N] [RUNS]   (PROFILE=dev for the dev build; default release;
#        N = 0 runs part 1 only)
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-10000}
RUNS=${2:-11}
HS=$(printf "BENCH-%05d" $(( N / 2 / 20 * 20 ))) # a device with two corrections
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
# shellcheck source=../scripts/pg-test-server.sh
source scripts/pg-test-server.sh start
trap 'gyrolab_pg_stop; cleanup' EXIT
"$BIN" simulate test-program "$WORK/tp" >/dev/null 2>&1
PLAN=$WORK/tp/plan.toml

now() { date +%s.%N; }
elapsed() { python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.4f}')" "$1" "$2"; }
median() { python3 -c "import sys, statistics; print(f'{statistics.median(map(float, sys.argv[1:])):.4f}')" "$@"; }
best() { python3 -c "import sys; print(f'{min(map(float, sys.argv[1:])):.4f}')" "$@"; }
eval_ok() { "$@" || [ $? -eq 3 ]; }

overhead() { # $1 = store location, $2 = label
    local plain=() stored=() t0 t1 mp ms
    for _ in $(seq "$RUNS"); do
        t0=$(now); eval_ok "$BIN" eval "$PLAN" --out "$WORK/plain" -q; t1=$(now)
        plain+=("$(elapsed "$t0" "$t1")")
        t0=$(now); eval_ok "$BIN" eval "$PLAN" --out "$WORK/stored" -q --store "$1"; t1=$(now)
        stored+=("$(elapsed "$t0" "$t1")")
    done
    mp=$(median "${plain[@]}")
    ms=$(median "${stored[@]}")
    echo "$2: eval median ${mp} s; eval --store median ${ms} s; overhead $(python3 -c "print(f'{100 * ($ms - $mp) / $mp:.1f}')") %"
}

echo "== 1. gyrolab eval (example test program), without and with --store, $RUNS runs each, alternating"
echo "   (load average before: $(cut -d' ' -f1-3 /proc/loadavg))"
eval_ok "$BIN" eval "$PLAN" --out "$WORK/warm" -q
overhead "$WORK/eval.db" "SQLite"
overhead "$GYROLAB_TEST_PG_URL" "PostgreSQL"

query_times() { # $1 = store location, $2 = label
    local lot=() hist=() t0 t1
    "$BIN" store lot BENCH --store "$1" >/dev/null # warm the cache once
    for _ in $(seq "$RUNS"); do
        t0=$(now); "$BIN" store lot BENCH --store "$1" >/dev/null; t1=$(now); lot+=("$(elapsed "$t0" "$t1")")
        t0=$(now); "$BIN" store history "$HS" --store "$1" >/dev/null; t1=$(now); hist+=("$(elapsed "$t0" "$t1")")
    done
    echo "$2: store lot BENCH ($N devices) median $(median "${lot[@]}") s (best $(best "${lot[@]}")); store history $HS median $(median "${hist[@]}") s (best $(best "${hist[@]}"))"
}

[ "$N" -gt 0 ] || exit 0
echo "== 2. $N stored evaluations, then lot and history, $RUNS runs each"
"$FILL" "$WORK/bench.db" "$N" "$WORK/warm" "$PLAN"
query_times "$WORK/bench.db" "SQLite ($(du -h "$WORK/bench.db" | cut -f1))"
psql -q "$GYROLAB_TEST_PG_URL" -c "CREATE SCHEMA bench"
PGBENCH="${GYROLAB_TEST_PG_URL}?options=-c%20search_path%3Dbench"
"$FILL" "$PGBENCH" "$N" "$WORK/warm" "$PLAN"
query_times "$PGBENCH" "PostgreSQL"
