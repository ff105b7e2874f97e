#!/usr/bin/env bash
# Terms reported only where the record shows them (issue 55): how often the slope lines and the
# GMWM report bias instability B and rate random walk K as values on simulated gyros without
# that process (white; white + random walk; white + rate ramp), and how often they find and cover
# them where present; 10 min to 4 h at 100 Hz, SEEDS records per case and length (default 100).
# The table goes into docs/METHODS.md section 3 ("Terms reported only where the record shows
# them"). Not part of the test suite (minutes of CPU on two cores); the suite's guards are the
# tests named there. Usage: bash bench/term_detection_study.sh [SEEDS]
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --quiet --release -p gyrolab --example term_detection_study
/usr/bin/time -f "term_detection_study: %e s wall, %U s user" target/release/examples/term_detection_study "${1:-100}"
