"""Notebook-style example: simulate a gyro at rest, compute its Allan deviation with bounds and
noise terms, and save the plot as a PNG.

    python python/examples/allan_plot.py allan.png
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import gyrolab  # noqa: E402

# Two hours at 100 Hz of a gyro with N = 0.3 deg/sqrt(h), B = 5 deg/h, K = 2 deg/h/sqrt(h).
rec = gyrolab.simulate_static(7200.0, 100.0, seed=7, arw_deg_rt_h=0.3, bias_instability_dph=5.0, rrw_deg_h_rt_h=2.0)
r = gyrolab.allan(rec["output"], rate_hz=100.0)  # octave OADEV, 68.3 % bounds, noise terms
print(f"N = {r.noise['arw_deg_rt_h']:.3f} deg/sqrt(h), B = {r.noise['bias_instability_dph']} deg/h,"
      f" K = {r.noise['rrw_deg_h_rt_h']} deg/h/sqrt(h)")
ax = r.plot()
ax.set_title("Simulated gyro at rest: OADEV with 68.3 % bounds (gyrolab)")
plt.tight_layout()
plt.savefig(sys.argv[1] if len(sys.argv) > 1 else "allan.png", dpi=120)
