"""Time of AllanResult.plot() with every tau (taus="all") of a 2 h record at 100 Hz (about
180 k points; error bars thinned to 60), with the Agg backend, drawing included. Usage:
.venv/bin/python bench/python_plot.py [ROUNDS]"""
import statistics
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import gyrolab  # noqa: E402

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
s = gyrolab.simulate_static(7200.0, 100.0, seed=1, arw_deg_rt_h=0.3, bias_instability_dph=5.0)
r = gyrolab.allan(s["output"], rate_hz=100.0, taus="all")
times = []
for _ in range(rounds):
    t0 = time.perf_counter()
    ax = r.plot()
    ax.figure.canvas.draw()
    plt.close(ax.figure)
    times.append(time.perf_counter() - t0)
print(f"| plot taus='all' ({len(r.taus_s)} taus) | median {statistics.median(times):.3f} s | range {min(times):.3f}-{max(times):.3f} s |")
