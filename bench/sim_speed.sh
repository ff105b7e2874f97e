#!/usr/bin/env bash
# Benchmark of `gyrolab simulate static` on a long record: where the time goes (simulation alone,
# formatting and writing alone on one thread, both on two threads) and the command itself writing
# a file, against the output's own speed: gyrolab's file writer alone writing as many bytes from
# memory (the command's output side with nothing to compute), dd copying the same bytes, and dd
# writing as many bytes from /dev/zero (all flushed to disk, as the command does).
# Each run is repeated (the rounds alternate between the rows, so that a slow minute of a shared
# machine does not fall on one row only); the table gives the median and the range of wall times.
# Usage: bash bench/sim_speed.sh [SAMPLES (default 100000000)] [WORK_DIR (default /tmp/gyrolab-bench)] [ROUNDS (default 3)]
# The record is `time_s,output_v` at 100 Hz with 7 decimals (ADXRS646 preset), about 25 bytes a line.
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-100000000}
DIR=${2:-/tmp/gyrolab-bench}
ROUNDS=${3:-3}
mkdir -p "$DIR"
cargo build --release -q -p gyrolab-cli
cargo build --release -q -p gyrolab-io --example sim_speed --example write_speed
EX=target/release/examples/sim_speed
WX=target/release/examples/write_speed
F="$DIR/sim_$N.csv"
COPY="$DIR/copy.csv"
DUR=$(awk "BEGIN { printf \"%.2f\", $N / 100 }")
LABELS=(
    "gyrolab simulate static --decimals 7 --out F"
    "simulation only (no text)"
    "simulate + format + write, one thread, > /dev/null"
    "simulate + format + write, two threads, > /dev/null"
    "output alone: gyrolab's file writer, bytes from memory"
    "output: dd the same bytes to a file (fdatasync)"
    "output: dd as many bytes from /dev/zero (fdatasync)"
)
simulate() { # the record, into the file $1 (which does not exist)
    target/release/gyrolab simulate static --preset adxrs646 --sample-rate-hz 100 --duration-s "$DUR" \
        --decimals 7 --seed 1 --out "$1"
}
run_row() { # row index; the file F exists and COPY does not (every row writes COPY but 1 to 3)
    case $1 in
        0) simulate "$COPY" ;;
        1) "$EX" "$N" adxrs646 generate ;;
        2) "$EX" "$N" adxrs646 fixed7 ;;
        3) "$EX" "$N" adxrs646 fixed7 pipelined ;;
        4) "$WX" "$F" "$COPY" "$BYTES" ;;
        5) dd if="$F" of="$COPY" bs=4M conv=fdatasync ;;
        6) dd if=/dev/zero of="$COPY" bs=256K count=$((BYTES / 262144)) conv=fdatasync ;;
    esac
}
rm -f "$F" "$COPY"
simulate "$F"
BYTES=$(stat -c %s "$F")
: > "$DIR/sim.times"
for round in $(seq "$ROUNDS"); do
    for row in 0 1 2 3 4 5 6; do
        /usr/bin/time -f "$row %e %U %S %M" -a -o "$DIR/sim.times" bash -c "$(declare -f simulate run_row); \
            F='$F' COPY='$COPY' EX='$EX' WX='$WX' N='$N' DUR='$DUR' BYTES='$BYTES'; run_row $row" > /dev/null 2> /dev/null
        rm -f "$COPY"
    done
    echo "round $round of $ROUNDS done" >&2
done
printf '%-52s %9s %15s %9s %9s %12s %9s\n' "run" "wall s" "(range)" "CPU s" "MB/s" "samples/s" "peak MB"
for row in 0 1 2 3 4 5 6; do
    awk -v r="$row" -v l="${LABELS[$row]}" -v b="$BYTES" -v n="$N" '
        $1 == r { w[++k] = $2; c[k] = $3 + $4; m[k] = $5 }
        END {
            # Median by wall time (insertion sort of the few rounds), with its own CPU time.
            for (i = 2; i <= k; i++) for (j = i; j > 1 && w[j - 1] > w[j]; j--) {
                t = w[j]; w[j] = w[j - 1]; w[j - 1] = t; t = c[j]; c[j] = c[j - 1]; c[j - 1] = t
            }
            h = int((k + 1) / 2)
            printf "%-52s %9.2f %6.2f - %6.2f %9.2f %9.1f %12.3g %9.1f\n", l, w[h], w[1], w[k], c[h], b / w[h] / 1e6, n / w[h], m[1] / 1024
        }' "$DIR/sim.times"
done
echo "file: $F ($BYTES bytes, $N samples); $ROUNDS rounds; cores: $(nproc); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
