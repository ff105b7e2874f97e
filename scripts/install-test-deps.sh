#!/usr/bin/env bash
# Installs what the tests need beyond the Rust toolchain: Chromium for the browser test of the
# HTML report (crates/gyrolab-cli/tests/browser.rs). Does nothing when it is already there.
set -euo pipefail
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
