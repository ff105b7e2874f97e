#!/usr/bin/env bash
# Long recordings in bounded memory (issue 37 part 2; docs/PERFORMANCE.md "Long recordings").
#
# 1. A SIMULATED six-channel CSV of HOURS hours at RATE Hz (default 24 h at 1 kHz: 86.4 M rows,
#    about 7 GB; written by gyrolab-io/examples/long_record.rs) analysed by `gyrolab allan
#    --memory $MEMORY` (default 1GiB): peak RSS and wall time by /usr/bin/time -v, reading speed
#    in MB/s of CSV, the path taken and the stride from the JSON.
# 2. Reading speed on a record that fits both ways (FIT_HOURS, default 1 h, same rate): the
#    in-memory path (default ceiling) against the streamed one (--memory 64MiB), alternating,
#    best of RUNS each (default 3); the load average is printed before and after.
# 3. and 4. The same for a SIMULATED ROS 2 MCAP recording (one /imu topic of sensor_msgs/msg/Imu
#    in CDR, zstd chunks; written by gyrolab-io/examples/long_mcap.rs): HOURS at RATE under
#    --memory $MEMORY, then FIT_HOURS in memory against streamed. FORMATS=csv or mcap runs one
#    half (default: both).
#
# Everything is written to a temporary folder that is deleted at the end (also on error).
# Usage: bash bench/long_recording.sh   (HOURS=6 for a shorter record)
set -euo pipefail
HOURS=${HOURS:-24}
RATE=${RATE:-1000}
FIT_HOURS=${FIT_HOURS:-1}
MEMORY=${MEMORY:-1GiB}
RUNS=${RUNS:-3}
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrolab-cli
cargo build --release -q -p gyrolab-io --example long_record --example long_mcap
G=target/release/gyrolab
GEN=target/release/examples/long_record
GEN_MCAP=target/release/examples/long_mcap
FORMATS=${FORMATS:-csv mcap}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/long_recording.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

# run NAME FILE ARGS...: one timed `gyrolab allan`; prints "wall_s peak_rss_mib path stride"
run() {
    local name=$1 file=$2
    shift 2
    /usr/bin/time -v "$G" allan "$file" --json "$@" >"$WORK/$name.json" 2>"$WORK/$name.time"
    python3 - "$WORK/$name.json" "$WORK/$name.time" <<'EOF'
import json, re, sys
doc = json.load(open(sys.argv[1]))
t = open(sys.argv[2]).read()
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", t).group(1).split(":")
secs = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 1024
m = doc["memory"]
print(f"{secs:.2f} {rss:.0f} {m['path']} {m.get('stride', 1)}")
EOF
}

if [[ " $FORMATS " == *" csv "* ]]; then
echo "== 1. ${HOURS} h at ${RATE} Hz, six channels, --memory ${MEMORY}" >&2
start=$(date +%s.%N)
"$GEN" "$HOURS" "$RATE" 1 >"$WORK/long.csv"
gen_s=$(echo "$(date +%s.%N) - $start" | bc)
size=$(stat -c %s "$WORK/long.csv")
read -r wall rss path stride < <(run long "$WORK/long.csv" --memory "$MEMORY")
echo "record: $(echo "scale=2; $size / 10^9" | bc) GB of CSV, written in ${gen_s} s"
echo "long: path $path, stride $stride, wall ${wall} s, peak RSS ${rss} MiB, $(echo "scale=0; $size / 10^6 / $wall" | bc) MB/s"
python3 - "$WORK/long.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
m = d["memory"]
print(f"long: full resolution below m = {m.get('full_resolution_below_m')}, largest EDF loss {m.get('max_edf_loss')}, "
      f"{len(d['channels'])} channels, {d['samples']} samples, taus up to {max(d['taus_s']):.0f} s")
EOF
rm -f "$WORK/long.csv"

echo "== 2. ${FIT_HOURS} h at ${RATE} Hz: in memory against streamed, best of ${RUNS}" >&2
"$GEN" "$FIT_HOURS" "$RATE" 2 >"$WORK/fit.csv"
size=$(stat -c %s "$WORK/fit.csv")
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
mw=999999 sw=999999
for _ in $(seq "$RUNS"); do
    read -r w r p _ < <(run in_memory "$WORK/fit.csv")
    if (($(echo "$w < $mw" | bc))); then mw=$w mr=$r mp=$p; fi
    read -r w r p s < <(run streamed "$WORK/fit.csv" --memory 64MiB)
    if (($(echo "$w < $sw" | bc))); then sw=$w sr=$r sp=$p ss=$s; fi
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "fit: $(echo "scale=2; $size / 10^9" | bc) GB of CSV"
echo "fit: $mp: wall ${mw} s, peak RSS ${mr} MiB, $(echo "scale=0; $size / 10^6 / $mw" | bc) MB/s"
echo "fit: $sp (stride $ss): wall ${sw} s, peak RSS ${sr} MiB, $(echo "scale=0; $size / 10^6 / $sw" | bc) MB/s"
echo "fit: streamed reading speed = $(echo "scale=2; 100 * $mw / $sw" | bc) % of the in-memory path's"
fi

if [[ " $FORMATS " == *" mcap "* ]]; then
echo "== 3. ${HOURS} h at ${RATE} Hz MCAP (/imu, sensor_msgs/msg/Imu, zstd), --memory ${MEMORY}" >&2
start=$(date +%s.%N)
"$GEN_MCAP" "$HOURS" "$RATE" "$WORK/long.mcap" 1
gen_s=$(echo "$(date +%s.%N) - $start" | bc)
size=$(stat -c %s "$WORK/long.mcap")
read -r wall rss path stride < <(run long_mcap "$WORK/long.mcap" --memory "$MEMORY")
echo "mcap record: $(echo "scale=2; $size / 10^9" | bc) GB of MCAP, written in ${gen_s} s"
echo "mcap long: path $path, stride $stride, wall ${wall} s, peak RSS ${rss} MiB, $(echo "scale=0; $size / 10^6 / $wall" | bc) MB/s"
python3 - "$WORK/long_mcap.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
m = d["memory"]
print(f"mcap long: full resolution below m = {m.get('full_resolution_below_m')}, largest EDF loss {m.get('max_edf_loss')}, "
      f"{len(d['channels'])} channels, {d['samples']} samples, taus up to {max(d['taus_s']):.0f} s")
EOF
rm -f "$WORK/long.mcap"

echo "== 4. ${FIT_HOURS} h at ${RATE} Hz MCAP: in memory against streamed, best of ${RUNS}" >&2
"$GEN_MCAP" "$FIT_HOURS" "$RATE" "$WORK/fit.mcap" 2
size=$(stat -c %s "$WORK/fit.mcap")
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
mw=999999 sw=999999
for _ in $(seq "$RUNS"); do
    read -r w r p _ < <(run in_memory_mcap "$WORK/fit.mcap")
    if (($(echo "$w < $mw" | bc))); then mw=$w mr=$r mp=$p; fi
    read -r w r p s < <(run streamed_mcap "$WORK/fit.mcap" --memory 64MiB)
    if (($(echo "$w < $sw" | bc))); then sw=$w sr=$r sp=$p ss=$s; fi
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "mcap fit: $(echo "scale=2; $size / 10^9" | bc) GB of MCAP"
echo "mcap fit: $mp: wall ${mw} s, peak RSS ${mr} MiB, $(echo "scale=0; $size / 10^6 / $mw" | bc) MB/s"
echo "mcap fit: $sp (stride $ss): wall ${sw} s, peak RSS ${sr} MiB, $(echo "scale=0; $size / 10^6 / $sw" | bc) MB/s"
echo "mcap fit: streamed reading speed = $(echo "scale=2; 100 * $mw / $sw" | bc) % of the in-memory path's"
fi
