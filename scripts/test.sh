#!/usr/bin/env bash
# The project's test command (README): every test, including checks against references and the
# browser test of the HTML report and the equality check with Python allantools, and every
# example of the README. Installs what the checks need (allantools into .venv, Chromium) where
# it is missing, saying so first (scripts/install-test-deps.sh: opt-outs GYROLAB_SKIP_PYTHON=1,
# GYROLAB_SKIP_BROWSER=1, each check then printing SKIPPED:).
#
# One build: `cargo test --workspace --all-targets` builds the gyrolab binary and the libraries
# with the workspace's features; the checks below use those files (a `cargo build -p ...` here
# would resolve other features and build the crates again; docs/PERFORMANCE.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-test-deps.sh
if [ "${GYROLAB_SKIP_BROWSER:-}" != "1" ] && ! bash scripts/install-test-deps.sh --browser; then
    export GYROLAB_SKIP_BROWSER=1
fi
skip_python=0
if [ "${GYROLAB_SKIP_PYTHON:-}" = "1" ]; then
    skip_python=1
fi
# A throw-away PostgreSQL server for the records store tests (exports GYROLAB_TEST_PG_URL; stopped
# and removed at exit; installs the Debian package postgresql when missing): docs/STORE.md.
source scripts/pg-test-server.sh start
cargo test --workspace --all-targets
# The documentation examples (`--all-targets` leaves doctests out): each public formula's example
# with its published or hand value runs here.
cargo test --workspace --doc
bin=target/debug/gyrolab
# The binary is built by `cargo test --workspace --all-targets` (should a cargo version not leave it
# there, build it once).
if [ ! -x "$bin" ]; then
    echo "test.sh: $bin not left by cargo test: building it" >&2
    cargo build --quiet -p gyrolab-cli
fi
# `--all-targets` builds the examples as test harnesses, not their own programs: link the one the
# scipy check runs. `--workspace` keeps the test build's feature set, so no dependency is compiled
# again (a `-p gyrolab` build resolves that package's features alone; docs/PERFORMANCE.md).
cargo build --quiet --workspace --example chi2_quantiles
# The hostile recordings written by crates/gyrolab-cli/tests/hostile.rs, each read again by
# `allan` and `inspect` under an address-space limit of 2 GiB (issue 31).
bash scripts/test_hostile_ulimit.sh "$bin"
if [ "$skip_python" = "1" ]; then
    echo "SKIPPED: GYROLAB_SKIP_PYTHON=1: allantools and scipy equality checks, the Python package's tests" >&2
else
    # Allan deviations equal to Python allantools (rate data = data_type 'freq') at relative 1e-9.
    .venv/bin/python scripts/check_allantools.py "$bin"
    # Chi-squared quantiles (the confidence bounds) equal to scipy's chi2.ppf from 1 to 1e9 degrees
    # of freedom at relative 1e-9.
    .venv/bin/python scripts/check_chi2_scipy.py target/debug/examples/chi2_quantiles
    # The clock model's reference for the real PX4 log (crates/gyrolab-eval/tests/clock.rs) read
    # again by pyulog + numpy: the committed JSON must equal a fresh independent reading.
    .venv/bin/python scripts/px4_clock_reference.py --check examples/recordings/px4_sample_log_small.ulg \
        crates/gyrolab-eval/tests/data/px4_clock_reference.json
    # The stillness check's reference for the real PX4 flight (crates/gyrolab-cli/tests/stillness.rs),
    # read again by pyulog + numpy the same way.
    .venv/bin/python scripts/px4_motion_reference.py --check examples/recordings/px4_sample_flight.ulg \
        crates/gyrolab-cli/tests/data/px4_motion_reference.json
    # The filter exports (`allan --export`) read by each stack's reader or the closest one (PyYAML,
    # OpenCV FileStorage, json, a PX4 parameter-file parser) against hand conversions and truth.
    .venv/bin/python scripts/check_exports.py "$bin"
    # The Python package: built with maturin and installed into .venv, then its pytest suite
    # (equality with allantools and with the command line, simulated truth, malformed inputs).
    PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install --quiet --disable-pip-version-check --no-build-isolation ./python
    GYROLAB_BIN="$bin" .venv/bin/python -m pytest -q -rs python/tests
fi
# Every example of the README, as written (python blocks SKIPPED without the package).
GYROLAB_PYTHON="$PWD/.venv/bin/python" bash scripts/readme_examples.sh "$bin"
