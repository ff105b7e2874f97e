#!/usr/bin/env bash
# The cargo-fuzz targets of the recording readers (MCAP, ROS 1 bag, PX4 ULog, Parquet), each run
# for SECONDS (default 600) under an address-space limit of 2 GiB (`ulimit -v`, as on small
# robots and in containers), one at a time, niced; built without a sanitizer (AddressSanitizer
# reserves terabytes of address space, which the limit forbids) and with debug assertions (an
# integer overflow is a crash). Any allocation beyond the limit aborts the target, which
# libFuzzer reports as a crash with its input in fuzz/artifacts/<target>/. docs/FUZZING.md.
# usage: scripts/fuzz_recordings.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds="${1:-600}"
shift || true
targets=("$@")
if [ "${#targets[@]}" -eq 0 ]; then
    targets=(mcap bag ulog parquet)
fi
toolchain=()
if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    toolchain=(+nightly)
else
    export RUSTC_BOOTSTRAP=1
fi
for t in "${targets[@]}"; do
    nice -n 10 cargo "${toolchain[@]}" fuzz build -s none -a "$t"
done
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    echo "== $t: $seconds s, ulimit -v 2097152 (2 GiB), $(date -u +%FT%TZ)"
    (
        ulimit -v 2097152
        nice -n 10 cargo "${toolchain[@]}" fuzz run -s none -a "$t" "corpus/$t" "seeds/$t" -- \
            -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 -print_final_stats=1 2>&1
    ) | grep -E '^(stat::|==|INFO: Running|#[0-9]+ *DONE|Done|.*(ERROR|SUMMARY|panicked|deadly|crash-|timeout-|oom-))' || true
done
