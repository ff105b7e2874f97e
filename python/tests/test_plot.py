"""Plots (issue 34): confidence level in the legend, the Allan minimum and IEEE B both named,
asymptotes only over the tau range that supports them, one colour per result and no doubled
legend entries, accelerometer asymptotes; dense tau lists get thinned error bars."""
import numpy as np
import pytest

import gyrolab

matplotlib = pytest.importorskip("matplotlib", reason="matplotlib is an optional dependency")
matplotlib.use("Agg")


@pytest.fixture(scope="module")
def record():
    # N and B both resolved as values on this record (B's flat region lies inside it)
    return gyrolab.simulate_static(1800.0, 100.0, seed=2, arw_deg_rt_h=0.1, bias_instability_dph=5.0)["output"]


def texts(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_legend_and_asymptote_ranges(record):
    r = gyrolab.allan(record, rate_hz=100.0)
    ax = r.plot()
    legend = texts(ax)
    assert any("68.3 % bounds" in t for t in legend), legend
    assert any(t.startswith("N = ") for t in legend)
    b = [t for t in legend if t.startswith("Allan minimum")]
    assert b and "B (IEEE)" in b[0]
    for line in ax.get_lines():
        label = line.get_label()
        term = {"N": "arw", "Allan minimum": "allan_minimum", "K": "rrw"}.get(label.split(" ")[0] if not label.startswith("Allan") else "Allan minimum")
        if term is None:
            continue
        lo, hi = next(g["tau_range_s"] for g in r.readings if g["term"] == term)
        x = line.get_xdata()
        assert x.min() >= lo * (1 - 1e-12) and x.max() <= hi * (1 + 1e-12), label
    assert "deg/s" in ax.get_ylabel()


def test_two_results_one_axes_consistent_colours_no_duplicates(record):
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    a = gyrolab.allan(record, rate_hz=100.0)
    b = gyrolab.allan(record * 2.0, rate_hz=100.0)
    a.plot(ax=ax, label="unit 1")
    b.plot(ax=ax, label="unit 2")
    legend = texts(ax)
    assert len(legend) == len(set(legend))
    from matplotlib.colors import to_rgba

    colours = {}
    for line in ax.get_lines():
        colours.setdefault(to_rgba(line.get_color()), []).append(line.get_label())
    assert len(colours) == 2  # every line of a result in that result's colour


def test_accelerometer_asymptotes(record):
    r = gyrolab.allan(record, rate_hz=100.0, unit="m/s^2")
    legend = texts(r.plot())
    assert any(t.startswith("VRW = ") and "m/s/√h" in t for t in legend), legend


def test_dense_taus_thin_the_error_bars(record):
    r = gyrolab.allan(record[:20_000], rate_hz=100.0, taus="all")
    ax = r.plot()
    assert len(r.taus_s) > 1000
    (bars,) = ax.containers  # one errorbar container, its vertical bars thinned
    segments = bars.lines[2][0].get_segments()
    assert 10 <= len(segments) <= 60
    (curve,) = [line for line in ax.get_lines() if "bounds" in line.get_label()]
    assert len(curve.get_xdata()) == len(r.taus_s)  # the curve keeps every tau
