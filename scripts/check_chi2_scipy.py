#!/usr/bin/env python3
"""Chi-squared quantiles of gyrolab (allan::chi_squared_quantile) against scipy.stats.chi2.ppf.

The Rust example `chi2_quantiles` prints one line `p dof quantile` for p in {0.0005, 0.025, 0.1587,
0.5, 0.8413, 0.975, 0.9995} and dof in {1, 2, 3.7, 10, 100, 1e3, 1e4, 2.709e5, 1e6, 1e7, 1e8, 1e9};
every quantile must agree with scipy to relative 1e-9.
Usage: check_chi2_scipy.py CHI2_QUANTILES_BINARY   (cargo build -p gyrolab --example chi2_quantiles
gives target/debug/examples/chi2_quantiles)
Prints one line per point, then 'N passed, M failed', and exits non-zero on any failure.
"""
import subprocess
import sys

from scipy.stats import chi2

REL = 1e-9
EXPECTED_POINTS = 7 * 12


def main():
    out = subprocess.run([sys.argv[1]], check=True, capture_output=True, text=True).stdout
    passed = failed = 0
    for line in out.splitlines():
        p_text, dof_text, q_text = line.split()
        p, dof, q = float(p_text), float(dof_text), float(q_text)
        ref = chi2.ppf(p, dof)
        rel = abs(q / ref - 1.0) if ref != 0 else abs(q)
        ok = rel <= REL
        print(f"{'ok  ' if ok else 'FAIL'} p={p:<7g} dof={dof:<10g} gyrolab {q!r:<24} scipy {ref!r:<24} rel {rel:.1e}")
        passed += ok
        failed += not ok
    if passed + failed != EXPECTED_POINTS:
        print(f"FAIL expected {EXPECTED_POINTS} points, got {passed + failed}")
        failed += 1
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
