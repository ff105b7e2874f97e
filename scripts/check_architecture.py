#!/usr/bin/env python3
"""The workspace's direction, checked (issue 52; docs/LAYOUT.md). Exits 1 naming each breach:

1. crate dependencies run one way: core <- io <- eval <- report, store (on io) <- lab <- front
   ends (no [dependencies] or [dev-dependencies] edge against it);
2. no SQL outside gyrolab-store's sources;
3. no front end (gyrolab-cli, gyrolab-py) depends on a plotting, table, Parquet or database crate
   or writes SVG;
4. no two top-level modules of a crate import each other, directly or through others;
5. the command line's code (lines neither blank nor comments) stays under 2,000 lines.
"""
import pathlib
import re
import sys
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent
CRATES = ROOT / "crates"

# Each crate and the workspace crates it may depend on (library or tests).
ALLOWED = {
    "gyrolab-fft": set(),
    "gyrolab": {"gyrolab-fft"},
    "gyrolab-io": {"gyrolab"},
    "gyrolab-eval": {"gyrolab", "gyrolab-io"},
    "gyrolab-report": {"gyrolab", "gyrolab-io", "gyrolab-eval"},
    "gyrolab-store": {"gyrolab", "gyrolab-io"},
    "gyrolab-lab": {"gyrolab", "gyrolab-io", "gyrolab-eval", "gyrolab-report", "gyrolab-store"},
    "gyrolab-cli": {"gyrolab", "gyrolab-io", "gyrolab-eval", "gyrolab-report", "gyrolab-store", "gyrolab-lab"},
    "gyrolab-py": {"gyrolab", "gyrolab-io", "gyrolab-eval", "gyrolab-report", "gyrolab-store", "gyrolab-lab"},
}
FRONT_ENDS = ["gyrolab-cli", "gyrolab-py"]
# Crates a front end may not depend on: drawing, tables and storage belong to the libraries.
FRONT_END_FORBIDDEN = {"plotters", "comfy-table", "parquet", "arrow", "rusqlite", "postgres"}
SQL = re.compile(r"\b(SELECT\s+[\w*]|INSERT\s+INTO|UPDATE\s+\w+\s+SET|DELETE\s+FROM|CREATE\s+(TABLE|INDEX|TRIGGER))\b")
CLI_LIMIT = 2000


def code_lines(text):
    return [l for l in text.splitlines() if l.strip() and not l.strip().startswith("//")]


def main():
    breaches = []
    for crate, allowed in ALLOWED.items():
        manifest = tomllib.loads((CRATES / crate / "Cargo.toml").read_text())
        for section in ("dependencies", "dev-dependencies", "build-dependencies"):
            for dep in manifest.get(section, {}):
                if dep.startswith("gyrolab") and dep not in allowed:
                    breaches.append(f"{crate} [{section}] depends on {dep}: against the direction (docs/LAYOUT.md)")
        if crate in FRONT_ENDS:
            for dep in manifest.get("dependencies", {}):
                if dep in FRONT_END_FORBIDDEN:
                    breaches.append(f"{crate} depends on {dep}: a front end neither draws, writes tables nor stores")
    for src in CRATES.glob("*/src/**/*.rs"):
        crate = src.relative_to(CRATES).parts[0]
        text = src.read_text()
        if crate != "gyrolab-store":
            for n, line in enumerate(text.splitlines(), 1):
                if SQL.search(line) and not line.strip().startswith("//"):
                    breaches.append(f"{src.relative_to(ROOT)}:{n}: SQL outside gyrolab-store")
        if crate in FRONT_ENDS and ("<svg" in text or "Panel::new" in text):
            breaches.append(f"{src.relative_to(ROOT)}: a front end builds SVG")
    for crate_dir in sorted(CRATES.iterdir()):
        src = crate_dir / "src"
        graph = {}
        for f in src.glob("**/*.rs"):
            rel = f.relative_to(src).parts
            top = rel[0].removesuffix(".rs")
            if top in ("lib", "main"):
                continue
            # A file's unit tests (its `#[cfg(test)]` module, at its end) may use any module.
            code = "\n".join(code_lines(f.read_text().split("#[cfg(test)]")[0]))
            uses = set(re.findall(r"\bcrate::(\w+)", code))
            graph.setdefault(top, set()).update(u for u in uses if u != top)
        for cycle in cycles(graph):
            breaches.append(f"{crate_dir.name}: modules import each other: {' -> '.join(cycle)}")
    cli = sum(len(code_lines(f.read_text())) for f in (CRATES / "gyrolab-cli" / "src").glob("**/*.rs"))
    if cli >= CLI_LIMIT:
        breaches.append(f"gyrolab-cli: {cli} lines of code, at most {CLI_LIMIT - 1}: move the work to the lab layer")
    for b in breaches:
        print(f"check_architecture: {b}", file=sys.stderr)
    print(f"check_architecture: {len(breaches)} breaches; gyrolab-cli {cli} lines of code", file=sys.stderr)
    return 1 if breaches else 0


def cycles(graph):
    """One cycle per strongly connected set of two or more modules (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp) + [sorted(comp)[0]])

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


if __name__ == "__main__":
    sys.exit(main())
