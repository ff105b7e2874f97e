#!/usr/bin/env bash
# Benchmark (not run in CI): `gyrolab allan FILE.mcap` end to end (read the ROS 2 MCAP, decode
# every sensor_msgs/msg/Imu message, put them in stamp order, estimate the interval, octave
# OADEV with 68.3 % bounds and noise identification on six channels, JSON) against the Python
# way: the `mcap` package's reader + rosbags' CDR deserializer + allantools.oadev on the six
# channels (octave, no bounds), on the same file in one run. Wall time and peak memory (GNU
# time's %M) of each whole process; best of RUNS.
# Usage: bench/recording_vs_python.sh [HOURS] [RUNS]   (defaults 8 and 1; 8 h at 400 Hz =
# 11.52 M messages; creates bench/.venv and bench/.data if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
HOURS=${1:-8}
RUNS=${2:-1}
VENV=bench/.venv
DATA=bench/.data
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import allantools, mcap, rosbags, zstandard" 2>/dev/null; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q allantools numpy pandas "mcap==1.6.0" "rosbags==0.11.9" zstandard
fi
PY="$VENV/bin/python"
cargo build --release -q -p gyrolab-cli
BIN=target/release/gyrolab
mkdir -p "$DATA"
FILE="$DATA/imu_${HOURS}h_400hz.mcap"
if [ ! -f "$FILE" ]; then
    echo "writing $FILE (one /imu topic, 400 Hz, zstd chunks)..." >&2
    "$PY" - "$FILE" "$HOURS" <<'PYEOF'
import struct, sys
import numpy as np
from mcap.writer import CompressionType, Writer
from rosbags.typesys import Stores, get_typestore
path, hours = sys.argv[1], float(sys.argv[2])
f_hz = 400.0; n = int(hours * 3600 * f_hz)
ts = get_typestore(Stores.ROS2_HUMBLE)
# CDR of sensor_msgs/msg/Imu built with struct (frame_id "imu"), checked once against rosbags.
head = struct.Struct("<4sii I4s")
body = struct.Struct("<4d9d3d9d3d9d")
def cdr(sec, nsec, g, a):
    return head.pack(b"\x00\x01\x00\x00", sec, nsec, 4, b"imu\x00") + body.pack(0, 0, 0, 1, *([0.0] * 9), *g, *([0.0] * 9), *a, *([0.0] * 9))
t = ts.types
m = t["sensor_msgs/msg/Imu"](header=t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=5, nanosec=7), frame_id="imu"),
    orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0), orientation_covariance=np.zeros(9),
    angular_velocity=t["geometry_msgs/msg/Vector3"](x=0.1, y=0.2, z=0.3), angular_velocity_covariance=np.zeros(9),
    linear_acceleration=t["geometry_msgs/msg/Vector3"](x=1.0, y=2.0, z=3.0), linear_acceleration_covariance=np.zeros(9))
assert bytes(ts.serialize_cdr(m, "sensor_msgs/msg/Imu")) == cdr(5, 7, (0.1, 0.2, 0.3), (1.0, 2.0, 3.0))
rng = np.random.default_rng(3)
sg, sa = 0.005 * np.pi / 180 * np.sqrt(f_hz), 0.05 / 60 * np.sqrt(f_hz)
t0 = 1_700_000_000_000_000_000
with open(path, "wb") as fh:
    w = Writer(fh, compression=CompressionType.ZSTD)
    w.start(profile="ros2", library="bench")
    s = w.register_schema(name="sensor_msgs/msg/Imu", encoding="ros2msg", data=b"")
    c = w.register_channel(topic="/imu", message_encoding="cdr", schema_id=s)
    block = 1_000_000
    for start in range(0, n, block):
        k = min(block, n - start)
        g = rng.standard_normal((k, 3)) * sg
        a = rng.standard_normal((k, 3)) * sa + np.array([0.0, 0.0, 9.81])
        for i in range(k):
            stamp = t0 + (start + i) * 2_500_000
            w.add_message(channel_id=c, log_time=stamp, publish_time=stamp,
                          data=cdr(stamp // 1_000_000_000, stamp % 1_000_000_000, g[i], a[i]))
        print(f"  {start + k} / {n} messages", file=sys.stderr)
    w.finish()
PYEOF
fi

# best of N wall seconds and the peak MB of that run: prints "wall_s peak_mb"
best() {
    local best_s="" best_m=""
    for _ in $(seq "$RUNS"); do
        /usr/bin/time -f "%e %M" -o "$DATA/time.txt" "$@" >"$DATA/out.txt" 2>"$DATA/err.txt" || { cat "$DATA/err.txt"; exit 1; }
        read -r s m <"$DATA/time.txt"
        if [ -z "$best_s" ] || awk -v a="$s" -v b="$best_s" 'BEGIN{exit !(a<b)}'; then best_s=$s; best_m=$m; fi
    done
    echo "$best_s $((best_m / 1024))"
}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "file: $FILE ($(du -m "$FILE" | cut -f1) MB)"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
printf "| case | tool | wall s | peak MB | speed-up |\n|---|---|---:|---:|---:|\n"
label="$HOURS h 400 Hz MCAP, 6 channels"
read -r ps pm < <(best "$PY" bench/python_mcap_allan.py "$FILE" 400)
pysplit=$(cat "$DATA/out.txt")
read -r gs gm < <(best "$BIN" allan "$FILE" --json)
printf "| %s | mcap + rosbags + allantools | %s | %s | 1.0 |\n" "$label" "$ps" "$pm"
printf "| %s | gyrolab allan | %s | %s | %s |\n" "$label" "$gs" "$gm" "$(awk -v a="$ps" -v b="$gs" 'BEGIN{printf "%.1f", a/b}')"
echo "python split: $pysplit"
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
