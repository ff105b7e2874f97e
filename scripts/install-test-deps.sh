#!/usr/bin/env bash
# Installs what the tests need beyond the Rust toolchain: Python's allantools and scipy (from PyPI,
# into .venv) for the equality checks of the Allan deviations and the chi-squared quantiles
# (scripts/check_chi2_scipy.py), pytest, matplotlib and maturin for the Python package's tests
# (python/tests), PyYAML and opencv-python-headless as the readers of the filter exports
# (scripts/check_exports.py), rosbags, mcap and pyarrow as independent writers of the recordings the readers
# are tested on (scripts/write_recordings.py, crates/gyrolab-cli/tests/integration/recordings.rs), and
# Chromium for the browser test of
# the HTML report (crates/gyrolab-cli/tests/integration/browser.rs) and the PDF test of `--pdf`
# (crates/gyrolab-cli/tests/integration/pdf.rs). Does nothing that is already done; says on stderr what it is
# about to install, and how not to.
#
# Opt-outs: GYROLAB_SKIP_PYTHON=1 (no .venv; the checks that need it print SKIPPED:),
# GYROLAB_SKIP_BROWSER=1 (no Chromium; the browser and PDF tests print SKIPPED:).
#
# usage: bash scripts/install-test-deps.sh            install what is missing
#        bash scripts/install-test-deps.sh --browser  exit 0 when /usr/bin/chromium is there, else 1
set -euo pipefail
cd "$(dirname "$0")/.."

# The browser the tests use (crates/gyrolab-cli/tests/integration/browser.rs and pdf.rs): /usr/bin/chromium.
have_browser() {
    [ -x /usr/bin/chromium ]
}
if [ "${1:-}" = "--browser" ]; then
    have_browser
    exit $?
fi

if [ "${GYROLAB_SKIP_PYTHON:-}" = "1" ]; then
    echo "install-test-deps: GYROLAB_SKIP_PYTHON=1, not creating .venv (the Python checks will be SKIPPED)" >&2
elif ! .venv/bin/python -c "import allantools, scipy, pytest, matplotlib, maturin, rosbags, mcap, pyarrow, pandas, dask, distributed, pyulog, yaml, cv2, pypdf" 2>/dev/null; then
    echo "install-test-deps: installing allantools, scipy, pytest, matplotlib, maturin, rosbags, mcap, pyarrow, pandas, dask, pyulog, pyyaml, opencv-python-headless, pypdf" >&2
    echo "install-test-deps: (PyPI, into $PWD/.venv, about 750 MB; GYROLAB_SKIP_PYTHON=1 skips the checks that need them instead)" >&2
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check "allantools==2024.6" "numpy<3" "scipy" \
        "pytest>=7" "matplotlib>=3.5" "maturin>=1.7,<2" "rosbags==0.11.9" "mcap==1.6.0" "pyarrow==26.0.1" \
        "pandas==3.1.1" "dask==2026.8.0" "distributed==2026.8.0" "pyulog==1.2.0" \
        "pyyaml==6.0.3" "opencv-python-headless==4.12.0.88" "pypdf==7.1.1"
fi

if have_browser; then
    exit 0
fi
if [ "${GYROLAB_SKIP_BROWSER:-}" = "1" ]; then
    echo "install-test-deps: GYROLAB_SKIP_BROWSER=1, not installing chromium (the browser and PDF tests will be SKIPPED)" >&2
    exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        SUDO="sudo -n"
    else
        cat >&2 <<'EOF'
install-test-deps: the browser and PDF tests need Chromium, which is not installed, and installing
it needs root (this user cannot sudo without a password). Either
    sudo apt-get install chromium          (Debian, Ubuntu: about 124 MB), then run the tests again, or
    GYROLAB_SKIP_BROWSER=1                 (skip those two tests; they print SKIPPED:).
This run goes on without them (scripts/test.sh sets GYROLAB_SKIP_BROWSER=1 for it).
EOF
        exit 0
    fi
fi
echo "install-test-deps: installing chromium (Debian package, about 124 MB) for the browser and PDF tests" >&2
echo "install-test-deps: (GYROLAB_SKIP_BROWSER=1 skips those tests instead)" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends chromium
