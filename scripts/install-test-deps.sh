#!/usr/bin/env bash
# Installs what the tests need beyond the Rust toolchain: Python's allantools and scipy (from PyPI,
# into .venv) for the equality checks of the Allan deviations and the chi-squared quantiles
# (scripts/check_chi2_scipy.py), pytest, matplotlib and maturin for the Python package's tests
# (python/tests), rosbags, mcap and pyarrow as independent writers of the recordings the readers
# are tested on (scripts/write_recordings.py, crates/gyrolab-cli/tests/recordings.rs), and
# Chromium for the browser test of
# the HTML report (crates/gyrolab-cli/tests/browser.rs) and the PDF test of `--pdf`
# (crates/gyrolab-cli/tests/pdf.rs). Does nothing that is already done.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! .venv/bin/python -c "import allantools, scipy, pytest, matplotlib, maturin, rosbags, mcap, pyarrow" 2>/dev/null; then
    echo "install-test-deps: installing allantools, scipy, pytest, matplotlib, maturin, rosbags, mcap, pyarrow (PyPI) into .venv" >&2
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check "allantools==2024.6" "numpy<3" "scipy" \
        "pytest>=7" "matplotlib>=3.5" "maturin>=1.7,<2" "rosbags==0.11.9" "mcap==1.6.0" "pyarrow==26.0.1"
fi
if [ -x /usr/bin/chromium ]; then
    exit 0
fi
if [ "${GYROLAB_SKIP_BROWSER:-}" = "1" ]; then
    echo "install-test-deps: GYROLAB_SKIP_BROWSER=1, not installing chromium" >&2
    exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
    SUDO="sudo"
fi
echo "install-test-deps: installing chromium (Debian package) for the browser test" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends chromium
