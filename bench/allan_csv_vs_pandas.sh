#!/usr/bin/env bash
# Benchmark (not run in CI): `gyrolab allan FILE` end to end (read the CSV, estimate the
# interval, octave OADEV with 68.3 % bounds and noise identification, noise terms, JSON) against
# the Python way, pandas.read_csv + allantools.oadev (octave, no bounds), on the same files in
# one run. Wall time and peak memory (GNU time's %M) of each whole process; best of N.
#   case 1: 10 M lines, time_s + one rate column (100 Hz)
#   case 2: 8 h at 400 Hz, time + 6 channels (11.5 M lines), Kalibr's imu0.csv layout
# Usage: bench/allan_csv_vs_pandas.sh [RUNS]    (creates bench/.venv and bench/.data if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-3}
VENV=bench/.venv
DATA=bench/.data
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import allantools, pandas" 2>/dev/null; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install -q allantools numpy pandas
fi
PY="$VENV/bin/python"
cargo build --release -q -p gyrolab-cli
BIN=target/release/gyrolab
mkdir -p "$DATA"
bash bench/make_data.sh rate_10m "$PY" "$DATA/rate_10m.csv"
if [ ! -f "$DATA/imu_8h_400hz.csv" ]; then
    "$PY" - "$DATA/imu_8h_400hz.csv" <<'PYEOF'
import sys, numpy as np
rng = np.random.default_rng(2); f = 400.0; n = int(8 * 3600 * f)
ts = 1_700_000_000_000_000_000 + (np.arange(n) * (1e9 / f)).astype(np.int64)
g = rng.standard_normal((n, 3)) * (0.005 * np.pi / 180 * np.sqrt(f))
a = rng.standard_normal((n, 3)) * (0.05 / 60 * np.sqrt(f)) + np.array([0, 0, 9.81])
with open(sys.argv[1], "w") as fh:
    fh.write("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
             "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n")
    np.savetxt(fh, np.column_stack([ts, g, a]), fmt=["%d"] + ["%.7e"] * 6, delimiter=",")
PYEOF
fi

# best of N wall seconds (to the millisecond: GNU time's %e has 10 ms steps) and the peak MB of
# that run (GNU time's %M): prints "wall_s peak_mb"
best() {
    local best_s="" best_m=""
    for _ in $(seq "$RUNS"); do
        local t0 t1
        t0=$(date +%s%N)
        /usr/bin/time -f "%M" -o "$DATA/time.txt" "$@" >/dev/null 2>"$DATA/err.txt" || { cat "$DATA/err.txt"; exit 1; }
        t1=$(date +%s%N)
        read -r m <"$DATA/time.txt"
        s=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.3f", (b - a) / 1e9}')
        if [ -z "$best_s" ] || awk -v a="$s" -v b="$best_s" 'BEGIN{exit !(a<b)}'; then best_s=$s; best_m=$m; fi
    done
    echo "$best_s $((best_m / 1024))"
}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
printf "| case | tool | wall s | peak MB | speed-up |\n|---|---|---:|---:|---:|\n"
for case in "10 M lines, 1 channel:rate_10m.csv:100" "8 h 400 Hz, 6 channels:imu_8h_400hz.csv:400"; do
    IFS=: read -r label file rate <<<"$case"
    read -r ps pm < <(best "$PY" bench/pandas_allan_csv.py "$DATA/$file" "$rate")
    read -r gs gm < <(best "$BIN" allan "$DATA/$file" --json)
    printf "| %s | pandas + allantools | %s | %s | 1.0 |\n" "$label" "$ps" "$pm"
    printf "| %s | gyrolab allan | %s | %s | %s |\n" "$label" "$gs" "$gm" "$(awk -v a="$ps" -v b="$gs" 'BEGIN{printf "%.1f", a/b}')"
done
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
