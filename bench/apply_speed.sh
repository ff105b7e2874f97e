#!/usr/bin/env bash
# Streaming speed of `gyrolab apply`: generates a large raw log (time_s, table_rate_dps, gx_v;
# default 20 M rows at 1 kHz, about 0.8 GB), applies a single-axis calibration with
# target/release/gyrolab, and prints MB/s, rows/s and peak memory (from /usr/bin/time -v).
#
# Usage: bash bench/apply_speed.sh [ROWS] [WORKDIR]
# Build first: cargo build --release -p gyrolab-cli
set -euo pipefail
ROWS=${1:-20000000}
WORK=${2:-$(mktemp -d)}
BIN=${GYROLAB:-target/release/gyrolab}
[ -x "$BIN" ] || { echo "no $BIN: run cargo build --release -p gyrolab-cli" >&2; exit 1; }
mkdir -p "$WORK"
IN="$WORK/raw.csv"
CAL="$WORK/cal.toml"
OUT="$WORK/rates.csv"

if [ ! -s "$IN" ] || [ "$(($(wc -l <"$IN") - 1))" -ne "$ROWS" ]; then
  echo "generating $ROWS rows in $IN ..." >&2
  # Table rate: holds of 10 s at -300..300 deg/s; output 2.5 V + 7.5 mV/(deg/s) + noise
  # (a deterministic linear congruential generator, so every run writes the same file).
  awk -v n="$ROWS" 'BEGIN {
    srand(1); seed = 12345; print "time_s,table_rate_dps,gx_v";
    split("-300 -100 -30 0 30 100 300", r, " ");
    for (i = 0; i < n; i++) {
      t = i * 0.001; w = r[int(t / 10) % 7 + 1];
      seed = (seed * 1103515245 + 12345) % 2147483648; e = (seed / 2147483648 - 0.5) * 0.004;
      printf "%.3f,%.4f,%.6f\n", t, w, 2.5 + 0.0075 * w + e;
    }
  }' >"$IN"
fi
cat >"$CAL" <<'TOML'
format = "gyrolab-calibration-1"
generator = "bench/apply_speed.sh"
created = "2026-01-01T00:00:00Z"

[[axis]]
name = "gx"
source_file = "raw.csv"
output_unit = "V"
scale_factor = 0.0075
zero_offset = 2.5
rest_reference = 2.5
rate_min_dps = -300.0
rate_max_dps = 300.0

[axis.polynomial]
order = 1
coefficients = [2.5, 0.0075]
TOML

BYTES=$(stat -c %s "$IN")
run() {
  local label=$1; shift
  local log="$WORK/time-${label//[^a-z]/_}.txt"
  local t0 t1
  t0=$(date +%s.%N)
  /usr/bin/time -v "$@" 2>"$log" >/dev/null
  t1=$(date +%s.%N)
  local secs rss
  secs=$(echo "$t1 - $t0" | bc -l)
  rss=$(awk -F: '/Maximum resident set size/ {gsub(/ /, "", $2); print $2}' "$log")
  printf '%-28s %8.2f s  %8.1f MB/s  %6.2f M rows/s  peak RSS %6.1f MB\n' "$label" "$secs" \
    "$(echo "$BYTES / 1000000 / $secs" | bc -l)" "$(echo "$ROWS / 1000000 / $secs" | bc -l)" \
    "$(echo "$rss / 1024" | bc -l)"
}
echo "input: $IN ($ROWS rows, $((BYTES / 1000000)) MB)"
run "apply > /dev/null" "$BIN" apply --cal "$CAL" "$IN"
run "apply --out FILE" "$BIN" apply --cal "$CAL" "$IN" --out "$OUT"
echo "output: $OUT ($(($(stat -c %s "$OUT") / 1000000)) MB); head:"
head -3 "$OUT"
