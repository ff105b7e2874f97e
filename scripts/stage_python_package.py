#!/usr/bin/env python3
"""Lays out the Python package from the test build, as the wheel of `pip install ./python` would.

The test command (scripts/test.sh) runs the Python package's tests against the native module that
`cargo build --workspace --lib --example chi2_quantiles` has just linked from the same crates the
Rust tests ran on (target/debug/lib_gyrolab.so, built with PYO3_BUILD_EXTENSION_MODULE=1 from
.cargo/config.toml), instead of a separate release build by maturin: that build compiled every
dependency once more, about 3 minutes on 2 cores (docs/PERFORMANCE.md, issue 32). The layout
follows python/pyproject.toml's [tool.maturin] table: the packages of `python-packages` copied from
`python-source`, the native module placed at `module-name` with the abi3 suffix, and a marker file
`STAGED_FROM_TEST_BUILD` beside it (the package's tests of the wheel itself skip on it).
`GYROLAB_TEST_WHEEL=1 bash scripts/test.sh` builds and tests the wheel itself.

usage: stage_python_package.py NATIVE_LIBRARY OUT_DIR
Prints OUT_DIR's absolute path, for PYTHONPATH. Exit 2 on a missing input or an unreadable table.
"""

import re
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = ROOT / "python" / "pyproject.toml"


def maturin_table(text):
    """The [tool.maturin] table (tomllib; on Pythons before 3.11 a reader of its one-line string and
    string-list values, the keys this layout needs)."""
    try:
        import tomllib
    except ImportError:
        tomllib = None
    if tomllib is not None:
        try:
            table = tomllib.loads(text).get("tool", {}).get("maturin")
        except tomllib.TOMLDecodeError as e:
            raise ValueError(f"{PYPROJECT}: {e}") from None
        if table is None:
            raise ValueError(f"{PYPROJECT}: no [tool.maturin] table")
    else:
        m = re.search(r"^\[tool\.maturin\]\s*$(.*?)(?=^\[|\Z)", text, re.M | re.S)
        if not m:
            raise ValueError(f"{PYPROJECT}: no [tool.maturin] table")
        table = {}
        for line in m.group(1).splitlines():
            kv = re.match(r'\s*([A-Za-z0-9_-]+)\s*=\s*(.+?)\s*$', line)
            if not kv:
                continue
            key, value = kv.groups()
            if value.startswith("[") and value.endswith("]"):
                table[key] = re.findall(r'"([^"]*)"', value)
            elif value.startswith('"') and value.endswith('"'):
                table[key] = value[1:-1]
    for key in ("module-name", "python-source", "python-packages"):
        if key not in table:
            raise ValueError(f"{PYPROJECT}: [tool.maturin] has no {key} (or not on one line)")
    if not isinstance(table["python-packages"], list) or not table["python-packages"]:
        raise ValueError(f"{PYPROJECT}: [tool.maturin] python-packages is not a list of packages")
    return table


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[-2], file=sys.stderr)
        return 2
    native, out = Path(argv[1]), Path(argv[2]).resolve()
    if not native.is_file():
        print(f"stage_python_package: {native}: no such file (build it with "
              "`cargo build --workspace --lib --example chi2_quantiles`, as scripts/test.sh does)",
              file=sys.stderr)
        return 2
    try:
        table = maturin_table(PYPROJECT.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        print(f"stage_python_package: {e}", file=sys.stderr)
        return 2
    source = (PYPROJECT.parent / table["python-source"]).resolve()
    tmp = out.with_name(out.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    for package in table["python-packages"]:
        shutil.copytree(source / package, tmp / package,
                        ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    *parents, module = table["module-name"].split(".")
    target = tmp.joinpath(*parents) / f"{module}.abi3.so"
    if not target.parent.is_dir():
        print(f"stage_python_package: {PYPROJECT}: module-name {table['module-name']} lies outside "
              f"the python-packages {table['python-packages']}", file=sys.stderr)
        return 2
    shutil.copy2(native, target)
    (target.parent / "STAGED_FROM_TEST_BUILD").write_text(
        f"laid out by scripts/stage_python_package.py from {native.resolve()}\n", encoding="utf-8")
    # The old folder is moved aside before the new one takes its name, so a test imports either
    # the old package or the new one whole, never a half-copied one.
    old = out.with_name(out.name + ".old")
    shutil.rmtree(old, ignore_errors=True)
    try:
        if out.exists():
            out.rename(old)
        tmp.rename(out)
    except OSError as e:
        print(f"stage_python_package: cannot put the package in {out}: {e}", file=sys.stderr)
        return 2
    shutil.rmtree(old, ignore_errors=True)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
