#!/usr/bin/env bash
# The benchmark records, made once and kept in bench/.data (shared by bench/allan_csv_vs_pandas.sh,
# bench/batch_speed.sh and bench/speed_guard.sh, so that they time the same files):
#   rate_10m PY FILE          10 M lines `time_s,rate_dps` (100 Hz; white noise, a random walk and a
#                             0.5 deg/s offset; time `%.2f`, rate `%.7e`), seed 1, with numpy
#   batch BIN DIR COUNT       COUNT records of 10 min at 100 Hz made by `gyrolab simulate static`
#                             (N 0.3 deg/sqrt(h), B 5 deg/h, K 2 deg/h/sqrt(h)), seeds 1..COUNT,
#                             DIR/r0001.csv ...
# Files already there are kept.
set -euo pipefail
case "${1:-}" in
rate_10m)
    [ -f "$3" ] && exit 0
    "$2" - "$3" <<'PYEOF'
import sys, numpy as np
rng = np.random.default_rng(1); n = 10_000_000
t = np.arange(n) * 0.01
x = rng.standard_normal(n) * 1e-2 + np.cumsum(rng.standard_normal(n)) * 3e-6 + 0.5
np.savetxt(sys.argv[1], np.column_stack([t, x]), fmt=["%.2f", "%.7e"], delimiter=",", header="time_s,rate_dps", comments="")
PYEOF
    ;;
batch)
    mkdir -p "$3"
    for i in $(seq 1 "$4"); do
        f=$(printf "%s/r%04d.csv" "$3" "$i")
        [ -f "$f" ] || "$2" simulate static --duration-s 600 --sample-rate-hz 100 --arw-deg-rt-h 0.3 \
            --bias-instability-dph 5 --rrw-deg-h-rt-h 2 --seed "$i" --out "$f"
    done
    ;;
*)
    echo "usage: bench/make_data.sh rate_10m PYTHON FILE | batch GYROLAB DIR COUNT" >&2
    exit 2
    ;;
esac
