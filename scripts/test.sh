#!/usr/bin/env bash
# The project's test command (README): every test, including checks against references and the
# browser test of the HTML report. Installs what the checks need (Chromium) on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh
cargo test --workspace --all-targets
