"""Table and agreement check for bench/allan_vs_allantools.sh.

usage: report.py DIR CASE... where each CASE is "label:gyrolab_stem:allantools_stem"; a stem
names STEM.time (compute_s / peak_mb lines) and STEM.txt ("m deviation" lines) in DIR.
Exit status 1 if a common tau differs by more than 1e-9 relative.
"""
import sys


def read_time(path):
    vals = {}
    for line in open(path):
        k, v = line.split()
        vals[k] = float(v)
    return vals


def read_devs(path):
    return {int(m): float(d) for m, d in (line.split() for line in open(path))}


def main():
    root, cases = sys.argv[1], sys.argv[2:]
    ok = True
    print(f"{'tool':<11} {'case':<34} {'compute s':>10} {'peak MB':>8} {'speed-up':>9}")
    for case in cases:
        label, g, a = case.split(":")
        gt, at = read_time(f"{root}/{g}.time"), read_time(f"{root}/{a}.time")
        print(f"{'allantools':<11} {label:<34} {at['compute_s']:>10.3f} {at['peak_mb']:>8.0f} {'1.0':>9}")
        speed = at["compute_s"] / gt["compute_s"]
        print(f"{'gyrolab':<11} {label:<34} {gt['compute_s']:>10.3f} {gt['peak_mb']:>8.0f} {speed:>9.1f}")
        gd, ad = read_devs(f"{root}/{g}.txt"), read_devs(f"{root}/{a}.txt")
        common = sorted(set(gd) & set(ad))
        worst = max(abs(gd[m] - ad[m]) / abs(ad[m]) for m in common if ad[m] != 0)
        agree = worst <= 1e-9
        ok &= agree
        print(f"{'':<11} agreement on {len(common)} common taus: max rel diff {worst:.2e} ({'ok' if agree else 'FAIL'} at 1e-9)")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
