#!/usr/bin/env bash
# The project's test command (README): every test, including checks against references and the
# browser test of the HTML report and the equality check with Python allantools. Installs what
# the checks need (allantools into .venv, Chromium) on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh
# A throw-away PostgreSQL server for the records store tests (exports GYROLAB_TEST_PG_URL; stopped
# and removed at exit; installs the Debian package postgresql when missing): docs/STORE.md.
source scripts/pg-test-server.sh start
cargo test --workspace --all-targets
# Allan deviations equal to Python allantools (rate data = data_type 'freq') at relative 1e-9.
cargo build --quiet -p gyrolab-cli
.venv/bin/python scripts/check_allantools.py target/debug/gyrolab
# Chi-squared quantiles (the confidence bounds) equal to scipy's chi2.ppf from 1 to 1e9 degrees
# of freedom at relative 1e-9.
cargo build --quiet -p gyrolab --example chi2_quantiles
.venv/bin/python scripts/check_chi2_scipy.py target/debug/examples/chi2_quantiles
# The Python package: built with maturin and installed into .venv, then its pytest suite
# (equality with allantools and with the command line, simulated truth, malformed inputs).
PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install --quiet --disable-pip-version-check --no-build-isolation ./python
GYROLAB_BIN=target/debug/gyrolab .venv/bin/python -m pytest -q -rs python/tests
