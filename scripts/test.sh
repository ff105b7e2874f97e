#!/usr/bin/env bash
# The project's test command (README): every test, including checks against references and the
# browser test of the HTML report and the equality check with Python allantools, and every
# example of the README. Installs what the checks need (allantools into .venv, Chromium) where
# it is missing, saying so first (scripts/install-test-deps.sh: opt-outs GYROLAB_SKIP_PYTHON=1,
# GYROLAB_SKIP_BROWSER=1, each check then printing SKIPPED:).
#
# One build: `cargo test --workspace --lib --bins --tests` builds the gyrolab binary and the
# libraries with the workspace's features; the checks below use those files (a `cargo build -p ...`
# here would resolve other features and build the crates again; docs/PERFORMANCE.md). The examples
# (benchmarks and studies, no tests in them) are not linked here: clippy checks them in CI
# (`--all-targets`), and `cargo build --release --examples` or the bench/ scripts build them.
set -euo pipefail
cd "$(dirname "$0")/.."
# The time of each step, on stderr (docs/PERFORMANCE.md keeps the figures of fresh clones).
step_start=$SECONDS
step_done() {
    echo "test.sh: $1: $((SECONDS - step_start)) s" >&2
    step_start=$SECONDS
}
# Every integration-test file is a module of its crate's one test binary (docs/LAYOUT.md): a file
# that main.rs does not name would never run, and a file directly in tests/ would be a binary of
# its own again.
for dir in crates/*/tests; do
    for f in "$dir"/*.rs; do
        [ -e "$f" ] || continue
        echo "test.sh: $f: integration tests belong in $dir/integration/ as a module of main.rs" >&2
        exit 1
    done
    [ -d "$dir/integration" ] || continue
    for f in "$dir"/integration/*.rs; do
        m=$(basename "$f" .rs)
        if [ "$m" != main ] && ! grep -q "^mod $m;" "$dir/integration/main.rs"; then
            echo "test.sh: $f is not a module of $dir/integration/main.rs (add \`mod $m;\`)" >&2
            exit 1
        fi
    done
done
# The workspace's direction (docs/LAYOUT.md): dependencies, SQL, front ends, module circles.
python3 scripts/check_architecture.py
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
step_done "installs and the PostgreSQL server"
cargo test --workspace --lib --bins --tests
step_done "cargo test (build and run)"
# The documentation examples (left out above): each public formula's example
# with its published or hand value runs here.
cargo test --workspace --doc
# The libraries' documentation builds without a warning (the binary's doc comments are its --help).
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --lib --quiet
step_done "doctests"
bin=target/debug/gyrolab
# The binary is built by `cargo test --workspace` (should a cargo version not leave it
# there, build it once).
if [ ! -x "$bin" ]; then
    echo "test.sh: $bin not left by cargo test: building it" >&2
    cargo build --quiet -p gyrolab-cli
fi
# Link the example the scipy check runs and the Python package's native module (a cdylib, which
# `cargo test` leaves unlinked). `--workspace` with an example keeps the test build's feature set
# (dev-dependencies included), so no dependency is compiled again (a `-p` build resolves that
# package's features alone; docs/PERFORMANCE.md).
cargo build --quiet --workspace --lib --example chi2_quantiles
# The hostile recordings written by crates/gyrolab-cli/tests/integration/hostile.rs, each read again by
# `allan` and `inspect` under an address-space limit of 2 GiB (issue 31).
bash scripts/test_hostile_ulimit.sh "$bin"
step_done "the example, the native module and the hostile recordings under ulimit"
if [ "$skip_python" = "1" ]; then
    echo "SKIPPED: GYROLAB_SKIP_PYTHON=1: allantools and scipy equality checks, the Python package's tests" >&2
    # The README's python blocks are skipped too (they would import whatever gyrolab .venv holds).
    export GYROLAB_PYTHON=/nonexistent/python
else
    # Allan deviations equal to Python allantools (rate data = data_type 'freq') at relative 1e-9.
    .venv/bin/python scripts/check_allantools.py "$bin"
    # Chi-squared quantiles (the confidence bounds) equal to scipy's chi2.ppf from 1 to 1e9 degrees
    # of freedom at relative 1e-9.
    .venv/bin/python scripts/check_chi2_scipy.py target/debug/examples/chi2_quantiles
    # The clock model's reference for the real PX4 log (crates/gyrolab-eval/tests/integration/clock.rs) read
    # again by pyulog + numpy: the committed JSON must equal a fresh independent reading.
    .venv/bin/python scripts/px4_clock_reference.py --check examples/recordings/px4_sample_log_small.ulg \
        crates/gyrolab-eval/tests/data/px4_clock_reference.json
    # The stillness check's reference for the real PX4 flight (crates/gyrolab-cli/tests/integration/stillness.rs),
    # read again by pyulog + numpy the same way.
    .venv/bin/python scripts/px4_motion_reference.py --check examples/recordings/px4_sample_flight.ulg \
        crates/gyrolab-cli/tests/data/px4_motion_reference.json
    # The dense drops of pyulog's tagged log, time-binned by pyulog + numpy the same way.
    .venv/bin/python scripts/px4_dense_drops_reference.py --check \
        examples/recordings/px4_sample_logging_tagged_and_default_params.ulg \
        crates/gyrolab-eval/tests/data/px4_dense_drops_reference.json
    # The filter exports (`allan --export`) read by each stack's reader or the closest one (PyYAML,
    # OpenCV FileStorage, json, a PX4 parameter-file parser) against hand conversions and truth.
    .venv/bin/python scripts/check_exports.py "$bin"
    step_done "the checks against allantools, scipy, pyulog and the stacks' readers"
    # The Python package laid out from this build (its sources and the native module linked
    # above, where the wheel puts them: scripts/stage_python_package.py), then its pytest suite
    # (equality with allantools and with the command line, simulated truth, malformed inputs).
    # The release wheel of `pip install ./python` compiles every crate again (about 3 min);
    # GYROLAB_TEST_WHEEL=1 builds it, installs it into .venv and runs the suite on it too.
    PYTHONPATH="$(.venv/bin/python scripts/stage_python_package.py target/debug/lib_gyrolab.so target/python-dev)"
    export PYTHONPATH
    where=$(.venv/bin/python -c "import gyrolab; print(gyrolab.__file__)")
    if [ "$where" != "$PYTHONPATH/gyrolab/__init__.py" ]; then
        echo "test.sh: the Python tests would import gyrolab from $where, not from $PYTHONPATH" >&2
        exit 1
    fi
    GYROLAB_BIN="$bin" .venv/bin/python -m pytest -q -rs python/tests
    if [ "${GYROLAB_TEST_WHEEL:-}" = "1" ]; then
        PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install --quiet --disable-pip-version-check --no-build-isolation ./python
        (unset PYTHONPATH; GYROLAB_BIN="$bin" .venv/bin/python -m pytest -q -rs python/tests)
    fi
    step_done "the Python package's tests"
fi
# Every example of the README, as written (python blocks SKIPPED without the package; they import
# the package laid out above).
GYROLAB_PYTHON="${GYROLAB_PYTHON:-$PWD/.venv/bin/python}" bash scripts/readme_examples.sh "$bin"
step_done "the README's examples"
