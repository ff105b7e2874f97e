#!/usr/bin/env bash
# The project's test command (README): every test, including checks against references and the
# browser test of the HTML report and the equality check with Python allantools. Installs what
# the checks need (allantools into .venv, Chromium) on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh
cargo test --workspace --all-targets
# Allan deviations equal to Python allantools (rate data = data_type 'freq') at relative 1e-9.
cargo build --quiet -p gyrolab-cli
.venv/bin/python scripts/check_allantools.py target/debug/gyrolab
