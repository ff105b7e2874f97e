#!/usr/bin/env bash
# Runs every example of README.md as written, so that none can rot (called by scripts/test.sh).
#
# Every ```sh block is run line by line in a temporary copy of the repository's data/ and
# examples/ folders, with `gyrolab` on PATH being the binary given (default target/debug/gyrolab,
# which `cargo test` builds). A line must exit 0, or the code its trailing comment documents
# (`# exit 3`). Every ```python block is run with the Python given in GYROLAB_PYTHON (default
# .venv/bin/python) when it can `import gyrolab`, else skipped with a SKIPPED: line. The set-up
# block (```bash: install, demo, test command) is not run here: it is what runs this script
# (bench/first_hour.sh reads and times it).
#
# usage: bash scripts/readme_examples.sh [GYROLAB_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
bin="${1:-${GYROLAB_BIN:-target/debug/gyrolab}}"
case "$bin" in /*) ;; *) bin="$root/$bin" ;; esac
if [ ! -x "$bin" ]; then
    echo "readme_examples: no gyrolab binary at $bin (build it: cargo build -p gyrolab-cli)" >&2
    exit 2
fi
python="${GYROLAB_PYTHON:-$root/.venv/bin/python}"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin"
ln -s "$bin" "$work/bin/gyrolab"
# The files the examples read: tracked and new ones, not the ignored (generated) records.
git ls-files -co --exclude-standard -- data examples python/examples | while IFS= read -r f; do
    [ -f "$f" ] || continue
    mkdir -p "$work/copy/$(dirname "$f")"
    cp "$f" "$work/copy/$f"
done

# Extracts the blocks: one file per block, named <n>.<lang>, holding the block's lines.
awk -v dir="$work/blocks" '
    BEGIN { system("mkdir -p " dir); n = 0; lang = "" }
    /^```/ {
        if (lang != "") { close(file); lang = ""; next }
        tag = substr($0, 4)
        if (tag == "sh" || tag == "python") { n++; lang = tag; file = sprintf("%s/%03d.%s", dir, n, tag); printf "" > file }
        else { lang = "skip"; file = "/dev/null" }
        next
    }
    lang == "sh" || lang == "python" { print >> file; next }
' README.md

failures=0
ran=0
start=$SECONDS
for block in "$work"/blocks/*; do
    [ -e "$block" ] || continue
    case "$block" in
    *.python)
        if ! where=$("$python" -c "import gyrolab; print(gyrolab.__file__)" 2>/dev/null); then
            echo "SKIPPED: README python block $(basename "$block"): $python cannot import gyrolab (pip install ./python)" >&2
            continue
        fi
        # Say which package the blocks run on (scripts/test.sh lays one out from its build and puts
        # it first on PYTHONPATH; run alone, this script uses what .venv holds).
        if [ -z "${said_where:-}" ]; then
            echo "readme_examples: python blocks import gyrolab from ${where%/__init__.py}" >&2
            said_where=1
        fi
        ran=$((ran + 1))
        if ! (cd "$work/copy" && PATH="$work/bin:$PATH" MPLBACKEND=Agg "$python" "$block" >"$work/out" 2>&1); then
            echo "readme_examples: FAILED python block $(basename "$block"):" >&2
            sed 's/^/    /' "$block" >&2
            sed 's/^/  | /' "$work/out" >&2
            failures=$((failures + 1))
        fi
        ;;
    *.sh)
        while IFS= read -r line; do
            case "$line" in '' | '#'*) continue ;; esac
            expected=0
            if [[ "$line" =~ \#\ exit\ ([0-9]+) ]]; then
                expected="${BASH_REMATCH[1]}"
            fi
            ran=$((ran + 1))
            set +e
            (cd "$work/copy" && PATH="$work/bin:$PATH" bash -c "$line" >"$work/out" 2>&1 </dev/null)
            code=$?
            set -e
            if [ "$code" != "$expected" ]; then
                echo "readme_examples: FAILED (exit $code, expected $expected): $line" >&2
                sed 's/^/  | /' "$work/out" | tail -20 >&2
                failures=$((failures + 1))
            fi
        done <"$block"
        ;;
    esac
done
echo "readme_examples: $ran README example(s) run in $((SECONDS - start)) s, $failures failed" >&2
[ "$failures" = 0 ]
