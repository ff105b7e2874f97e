#!/usr/bin/env bash
# Benchmark of `gyrolab bias` on a long static record (and of `gyrolab simulate static`, which
# writes it). Prints a table: wall time, CPU time, MB/s and samples/s (of wall time), peak memory.
# Usage: bash bench/bias_speed.sh [SAMPLES (default 100000000)] [WORK_DIR (default /tmp/gyrolab-bench)]
# The record is `time_s,output_v` at 100 Hz with 7 decimals (ADXRS646 preset), about 24 bytes a line.
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-100000000}
DIR=${2:-/tmp/gyrolab-bench}
mkdir -p "$DIR"
cargo build --release -q -p gyrolab-cli
BIN=target/release/gyrolab
F="$DIR/static_$N.csv"
DUR=$(awk "BEGIN { printf \"%.2f\", $N / 100 }")
printf '%-34s %9s %9s %9s %12s %9s\n' "run" "wall s" "CPU s" "MB/s" "samples/s" "peak MB"
row() { # label wall user peak_kb bytes
    awk -v l="$1" -v w="$2" -v u="$3" -v m="$4" -v b="$5" -v n="$N" \
        'BEGIN { printf "%-34s %9.2f %9.2f %9.1f %12.3g %9.1f\n", l, w, u, b / w / 1e6, n / w, m / 1024 }'
}
if [ ! -f "$F" ]; then
    /usr/bin/time -f "%e %U %M" -o "$DIR/sim.time" \
        "$BIN" simulate static --preset adxrs646 --sample-rate-hz 100 --duration-s "$DUR" --decimals 7 --seed 1 --out "$F"
    read -r w u m < "$DIR/sim.time"
    row "simulate static (write)" "$w" "$u" "$m" "$(stat -c %s "$F")"
fi
BYTES=$(stat -c %s "$F")
for run in 1 2 3; do
    /usr/bin/time -f "%e %U %M" -o "$DIR/bias.time" "$BIN" bias "$F" --scale-factor 0.0075 --null 2.5 > /dev/null
    read -r w u m < "$DIR/bias.time"
    row "bias, run $run" "$w" "$u" "$m" "$BYTES"
done
echo "file: $F ($BYTES bytes, $N samples); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
