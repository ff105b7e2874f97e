#!/usr/bin/env bash
# Benchmark of `gyrolab simulate static` on a long record: where the time goes (simulation alone,
# formatting and writing alone on one thread, both on two threads) and the command itself writing
# a file, against the output's own speed: dd copying the same bytes, and dd writing as many bytes
# from /dev/zero (both flushed to disk, as the command does).
# Usage: bash bench/sim_speed.sh [SAMPLES (default 100000000)] [WORK_DIR (default /tmp/gyrolab-bench)]
# The record is `time_s,output_v` at 100 Hz with 7 decimals (ADXRS646 preset), about 25 bytes a line.
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-100000000}
DIR=${2:-/tmp/gyrolab-bench}
mkdir -p "$DIR"
cargo build --release -q -p gyrolab-cli
cargo build --release -q -p gyrolab-io --example sim_speed
EX=target/release/examples/sim_speed
F="$DIR/sim_$N.csv"
DUR=$(awk "BEGIN { printf \"%.2f\", $N / 100 }")
printf '%-52s %9s %9s %9s %12s %9s\n' "run" "wall s" "CPU s" "MB/s" "samples/s" "peak MB"
row() { # label wall user+sys peak_kb bytes
    awk -v l="$1" -v w="$2" -v u="$3" -v m="$4" -v b="$5" -v n="$N" \
        'BEGIN { printf "%-52s %9.2f %9.2f %9.1f %12.3g %9.1f\n", l, w, u, b / w / 1e6, n / w, m / 1024 }'
}
timed() { # label bytes command...
    local label=$1 bytes=$2
    shift 2
    /usr/bin/time -f "%e %U %S %M" -o "$DIR/sim.time" "$@" > /dev/null 2> /dev/null
    read -r w u s m < "$DIR/sim.time"
    row "$label" "$w" "$(awk -v u="$u" -v s="$s" 'BEGIN { print u + s }')" "$m" "$bytes"
}
rm -f "$F"
/usr/bin/time -f "%e %U %S %M" -o "$DIR/sim.time" target/release/gyrolab simulate static --preset adxrs646 \
    --sample-rate-hz 100 --duration-s "$DUR" --decimals 7 --seed 1 --out "$F"
BYTES=$(stat -c %s "$F")
read -r w u s m < "$DIR/sim.time"
row "gyrolab simulate static --decimals 7 --out F" "$w" "$(awk -v u="$u" -v s="$s" 'BEGIN { print u + s }')" "$m" "$BYTES"
timed "simulation only (no text)" "$BYTES" "$EX" "$N" adxrs646 generate
timed "simulate + format + write, one thread, > /dev/null" "$BYTES" "$EX" "$N" adxrs646 fixed7
timed "simulate + format + write, two threads, > /dev/null" "$BYTES" "$EX" "$N" adxrs646 fixed7 pipelined
timed "disk: dd the same bytes to a file (fdatasync)" "$BYTES" dd if="$F" of="$DIR/copy.csv" bs=4M conv=fdatasync
rm -f "$DIR/copy.csv"
# The output alone: as many zero bytes written from memory (no reading), then flushed to disk.
timed "disk: dd as many bytes from /dev/zero (fdatasync)" "$BYTES" dd if=/dev/zero of="$DIR/copy.csv" bs=256K \
    count=$((BYTES / 262144)) conv=fdatasync
rm -f "$DIR/copy.csv"
echo "file: $F ($BYTES bytes, $N samples); cores: $(nproc); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
