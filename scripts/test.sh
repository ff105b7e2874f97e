#!/usr/bin/env bash
# The project's test command (README): every test, including checks against references.
# Installs what the checks need (Python packages into .venv) on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --all-targets
