#!/usr/bin/env bash
# The hostile recordings of crates/gyrolab-cli/tests/integration/hostile.rs (issue 31), each read by
# `gyrolab allan` and `gyrolab inspect` under an address-space limit of 2 GiB (`ulimit -v`), as on
# small robots and in containers: every run must end with exit 0 or 2 (never an abort on memory,
# a panic or a signal) within 60 s. The files are those the test wrote into target/tmp/hostile
# (run `cargo test -p gyrolab-cli --test integration -- hostile::` first; scripts/test.sh does).
# usage: scripts/test_hostile_ulimit.sh [GYROLAB_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-target/debug/gyrolab}"
dir="target/tmp/hostile"
shopt -s nullglob
files=("$dir"/*.mcap "$dir"/*.bag "$dir"/*.ulg "$dir"/*.parquet)
if [ "${#files[@]}" -lt 20 ]; then
  echo "test_hostile_ulimit: expected the hostile files in $dir (cargo test -p gyrolab-cli --test integration -- hostile::)" >&2
  exit 1
fi
failed=0
for f in "${files[@]}"; do
  for cmd in allan inspect; do
    set +e
    err=$( (ulimit -v 2097152; timeout 60 "$bin" "$cmd" "$f" 2>&1 >/dev/null) )
    code=$?
    set -e
    if [ "$code" -ne 0 ] && [ "$code" -ne 2 ]; then
      echo "FAILED: $cmd $f: exit $code under ulimit -v 2097152: $err" >&2
      failed=1
    elif grep -q -e "panicked" -e "memory allocation" <<<"$err"; then
      echo "FAILED: $cmd $f: $err" >&2
      failed=1
    fi
  done
done
if [ "$failed" -ne 0 ]; then
  exit 1
fi
echo "test_hostile_ulimit: ${#files[@]} hostile recordings, allan and inspect, exit 0 or 2 under ulimit -v 2 GiB"
