#!/usr/bin/env bash
# The deterministic outputs of one gyrolab build, for the golden comparison of issue 52
# (crates/gyrolab-cli/tests/integration/golden.rs runs the same commands): the paper's demo
# folder, the simulated test program's report folder, the export files of every filter stack,
# a batch table, rate and bias JSON, and the store's rows and trend plot of a stored report.
# Usage: scripts/golden_outputs.sh GYROLAB_BINARY OUT_DIR   (OUT_DIR must not exist)
set -u
# Every command runs in OUT_DIR with relative paths, as `gyrolab` found on PATH (the records'
# `command:` line then names neither the folder nor the binary's path).
bin=$(realpath "$1")
d=$2
mkdir "$d" || exit 2
repo=$(cd "$(dirname "$0")/.." && pwd)
cd "$d" || exit 2
mkdir .bin && ln -s "$bin" .bin/gyrolab
export PATH="$PWD/.bin:$PATH"
codes=exit_codes.txt
cp "$repo/examples/recordings/simulated_imu_ros2.mcap" "$repo/data/paper/paper_rate_table_x.csv" .
run() { local name=$1; shift; gyrolab "$@" >"$name.stdout" 2>/dev/null; echo "$name $?" >>"$codes"; }
run demo demo --out "demo"
run program simulate test-program "program" --seed 2026
run eval eval "program/plan.toml" --out "program_report" --quiet
run static simulate static --seed 11 --duration-s 400 --sample-rate-hz 100 --arw-deg-rt-h 0.2 --bias-instability-dph 2 --output-unit deg/s --out "static.csv"
mkdir -p exports
run exports allan "static.csv" --kind oadev --export "kalibr=exports/kalibr.yaml" --export "openvins=exports/openvins.yaml" \
  --export "vins=exports/vins.yaml" --export "orbslam3=exports/orbslam3.yaml" --export "basalt=exports/basalt.json" \
  --export "px4=exports/px4.txt" --export "px4-qgc=exports/px4.params" --export "ros-covariance=exports/ros_covariance.yaml" \
  --kalibr-yaml "exports/imu.yaml" --imu-utils-yaml "exports/imu_utils.yaml"
run allan_json allan "static.csv" --kind oadev --json
run batch batch "static.csv" simulated_imu_ros2.mcap --out "batch" --quiet
run rate rate paper_rate_table_x.csv --json
run bias bias "static.csv" --json
run store_add store add "program_report" --store "store.db"
run store_history store history SIM-0001 --csv --store "store.db"
run store_svg store history SIM-0001 --store "store.db" --svg history.svg
run store_show store show 1 --json --store "store.db"
rm -rf store.db batch/batch-journal.jsonl .bin
