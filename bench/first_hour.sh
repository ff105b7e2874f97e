#!/usr/bin/env bash
# A newcomer's first hour, timed (issue 32; docs/PERFORMANCE.md): the README's three set-up
# commands, in order, in a fresh clone with an empty cargo cache (CARGO_HOME and target/ empty),
# as a new user runs them.
#
#   bash bench/first_hour.sh [REPO] [STEPS]
#
# REPO: the repository to clone (default: this one; its committed HEAD, not the work tree).
# STEPS: which commands to time, any of install,demo,test (default: all three, in that order).
# The clone goes to a temporary folder with the repository's ../shared linked beside it (the test
# command reads ../shared/reference); the folder is removed at the end unless KEEP=1. Each command
# prints its wall time and exit code; the table at the end is what docs/PERFORMANCE.md records.
# The pip cache and the system packages (Chromium, PostgreSQL) are not emptied: the test command
# installs them where they are missing and that is timed as part of it.
set -euo pipefail

repo=${1:-$(git -C "$(dirname "$0")" rev-parse --show-toplevel)}
steps=${2:-install,demo,test}
shared=$(cd "$repo/.." && pwd)/shared
[ -d "$shared" ] || { echo "first_hour.sh: $shared not found (the test command needs ../shared beside the clone)" >&2; exit 2; }

work=$(mktemp -d "${TMPDIR:-/tmp}/gyrolab-first-hour.XXXXXX")
cleanup() { if [ "${KEEP:-0}" != 1 ]; then rm -rf "$work"; else echo "first_hour.sh: kept $work" >&2; fi; }
trap cleanup EXIT
git clone -q "$repo" "$work/gyrolab"
ln -s "$shared" "$work/shared"
export CARGO_HOME="$work/cargo-home"
mkdir -p "$CARGO_HOME"
cd "$work/gyrolab"
echo "first_hour.sh: $(git log -1 --format='%h %s' | cut -c1-72)" >&2
echo "first_hour.sh: CARGO_HOME=$CARGO_HOME (empty), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)" >&2

rows=()
run() {
    local name=$1 command=$2 start rc
    start=$(date +%s)
    echo "first_hour.sh: $name: $command" >&2
    if bash -c "$command" > "$work/$name.log" 2>&1; then rc=0; else rc=$?; fi
    local took=$(( $(date +%s) - start ))
    echo "first_hour.sh: $name: ${took} s, exit $rc (log $work/$name.log)" >&2
    [ "$rc" = 0 ] || tail -20 "$work/$name.log" >&2
    rows+=("| $name | \`$command\` | $(( took / 60 )) min $(( took % 60 )) s | $rc |")
}
# The three commands exactly as the README's first block gives them.
IFS=, read -r -a wanted <<< "$steps"
for step in "${wanted[@]}"; do
    case $step in
        install) run install "cargo install --locked --path crates/gyrolab-cli --target-dir target" ;;
        demo) run demo "cargo run --release -- demo" ;;
        test) run test "bash scripts/test.sh" ;;
        *) echo "first_hour.sh: unknown step '$step' (install, demo, test)" >&2; exit 2 ;;
    esac
done
echo
echo "| step | command | wall | exit |"
echo "|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "target/ $(du -sh target 2>/dev/null | cut -f1), cargo cache $(du -sh "$CARGO_HOME" | cut -f1), load $(cut -d' ' -f1-3 /proc/loadavg)"
