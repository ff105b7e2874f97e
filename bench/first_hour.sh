#!/usr/bin/env bash
# A newcomer's first hour, timed (issue 32; docs/PERFORMANCE.md): the README's set-up commands (its
# first ```bash block: install line, demo, test command), in order, in a fresh clone with an empty
# cargo cache (CARGO_HOME and target/ empty), as a new user runs them.
#
#   bash bench/first_hour.sh [REPO] [STEPS]
#
# REPO: a local clone to clone from (default: this one), at its HEAD or at the commit in REF
# (REF=<commit> bash bench/first_hour.sh); its ../shared is linked beside the clone (the test
# command reads ../shared/reference). STEPS: which lines of the README's block to run, by number
# (default 1,2,3: all of them, in order). The commands are read from the clone's README.md, so the
# script times what the README says. The clone goes to a temporary folder under TMPDIR (default
# /tmp; it needs about 5 GB: target/ and .venv), removed at the end unless KEEP=1. Each command
# prints its wall time and exit code; the table at the end is what docs/PERFORMANCE.md records.
# Exit 0 when every command exited 0, else 1 (2 for bad usage). Settings of the caller's
# environment that would change the build (CARGO_TARGET_DIR, RUSTC_WRAPPER, RUSTFLAGS,
# CARGO_BUILD_*, CARGO_PROFILE_*, CARGO_INCREMENTAL) or the tests (GYROLAB_*, PYTHONPATH,
# VIRTUAL_ENV) are removed for the commands. The pip cache and the system packages (Chromium,
# PostgreSQL) are left as they are: the test command installs them where they are missing, and
# that is timed as part of it.
set -euo pipefail

repo=${1:-$(git -C "$(dirname "$0")" rev-parse --show-toplevel)}
steps=${2:-1,2,3}
[ -d "$repo/.git" ] || { echo "first_hour.sh: $repo is not a local git clone" >&2; exit 2; }
shared=$(cd "$repo/.." && pwd)/shared
[ -d "$shared" ] || { echo "first_hour.sh: $shared not found (the test command needs ../shared beside the clone)" >&2; exit 2; }

# The set-up block's commands, comments and blank lines dropped (the first ```bash block).
setup_commands() {
    awk '/^```bash[[:space:]]*$/ { if (!seen) { on = 1; seen = 1 }; next } /^```/ { on = 0 } on' "$1" |
        sed -e 's/[[:space:]]\{1,\}#.*$//' -e 's/^[[:space:]]*//' -e 's/[[:space:]]*$//' | grep -v '^$' || true
}
mapfile -t commands < <(setup_commands "$repo/README.md")
[ "${#commands[@]}" -gt 0 ] || { echo "first_hour.sh: no set-up block (a \`\`\`bash block) in $repo/README.md" >&2; exit 2; }
IFS=, read -r -a wanted <<< "$steps"
for step in "${wanted[@]}"; do
    if ! [[ "$step" =~ ^[0-9]+$ ]] || [ "$step" -lt 1 ] || [ "$step" -gt "${#commands[@]}" ]; then
        echo "first_hour.sh: step '$step' is not a line of the README's set-up block (1 to ${#commands[@]}):" >&2
        printf '  %s\n' "${commands[@]}" >&2
        exit 2
    fi
done

work=$(mktemp -d "${TMPDIR:-/tmp}/gyrolab-first-hour.XXXXXX")
cleanup() { if [ "${KEEP:-0}" != 1 ]; then rm -rf "$work"; else echo "first_hour.sh: kept $work" >&2; fi; }
trap cleanup EXIT
git clone -q "$repo" "$work/gyrolab"
[ -z "${REF:-}" ] || git -C "$work/gyrolab" checkout -q "$REF"
ln -s "$shared" "$work/shared"
cd "$work/gyrolab"
# The clone's own block (REF may differ from the work tree read above).
mapfile -t commands < <(setup_commands README.md)
export CARGO_HOME="$work/cargo-home"
mkdir -p "$CARGO_HOME"
unset CARGO_TARGET_DIR RUSTC_WRAPPER RUSTFLAGS CARGO_INCREMENTAL PYTHONPATH VIRTUAL_ENV
while IFS= read -r name; do unset "$name"; done < <(env | sed -n 's/^\(CARGO_BUILD_[A-Z_]*\|CARGO_PROFILE_[A-Z0-9_]*\|GYROLAB_[A-Z0-9_]*\)=.*/\1/p')
echo "first_hour.sh: $(git log -1 --format='%h %s' | cut -c1-72)" >&2
echo "first_hour.sh: CARGO_HOME=$CARGO_HOME (empty), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)" >&2

rows=()
failed=0
for step in "${wanted[@]}"; do
    command=${commands[$((step - 1))]:-}
    [ -n "$command" ] || { echo "first_hour.sh: the clone's README has no line $step in its set-up block" >&2; exit 2; }
    start=$(date +%s)
    echo "first_hour.sh: $step: $command" >&2
    if bash -c "$command" > "$work/step$step.log" 2>&1; then rc=0; else rc=$?; fi
    took=$(( $(date +%s) - start ))
    echo "first_hour.sh: $step: ${took} s, exit $rc (log $work/step$step.log)" >&2
    if [ "$rc" != 0 ]; then
        failed=1
        tail -20 "$work/step$step.log" >&2
    fi
    rows+=("| $step | \`$command\` | $(( took / 60 )) min $(( took % 60 )) s | $rc |")
done
echo
echo "| line | command | wall | exit |"
echo "|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "target/ $(du -sh target 2>/dev/null | cut -f1), cargo cache $(du -sh "$CARGO_HOME" | cut -f1), load $(cut -d' ' -f1-3 /proc/loadavg)"
exit "$failed"
