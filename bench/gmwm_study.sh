#!/usr/bin/env bash
# GMWM against simulated truth beside the slope readings and the five-term fit: three composite
# models (and a fourth with a Gauss-Markov process) x SEEDS seeds (default 100) of HOURS hours at 10 Hz (default 10): bias and RMSE of each
# parameter relative to the truth, the coverage of the GMWM 68.3 % two-sided intervals, and that of
# the intervals of the true model's processes fitted alone (no model choice) as a yardstick. The
# table goes into docs/METHODS.md section 3.1 ("GMWM study"). Not part of the normal test suite
# (minutes of CPU); the suite's short version is crates/gyrolab/src/gmwm/tests.rs.
# Figures of 100 seeds x 10 h, four models: about 29 s in release (one core; model B is generated
# at 100 Hz and averaged to 10 Hz, 18 s before that on this machine), after the build. Usage: bash bench/gmwm_study.sh [SEEDS] [HOURS]
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --quiet --release -p gyrolab --example gmwm_study
target/release/examples/gmwm_study "${1:-100}" "${2:-10}"
