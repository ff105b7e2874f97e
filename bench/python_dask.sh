#!/usr/bin/env bash
# gyrolab.dask on a distributed.LocalCluster: 200 records on one worker process and on two, in
# one run (docs/PERFORMANCE.md). Usage: bash bench/python_dask.sh [RECORDS] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh >/dev/null
PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install --quiet --disable-pip-version-check --no-build-isolation ./python
.venv/bin/python bench/python_dask.py "${1:-200}" "${2:-3}"
