"""Plots (issue 34): confidence level in the legend, the Allan minimum and IEEE B both named,
asymptotes only over the tau range that supports them, one colour per result and no doubled
legend entries, accelerometer asymptotes, MDEV asymptotes (the OADEV terms scaled by NIST SP 1065's
R(n) limits, against allantools' MDEV/OADEV ratios); dense tau lists get thinned error bars (their
timing is bench/python_plot.py, not a test)."""
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


TERM_OF_LABEL = {"N": "arw", "B": "allan_minimum", "K": "rrw", "VRW": "vrw", "AcRW": "accel_random_walk"}


def asymptote_lines(ax):
    """{term: line} of the asymptotes drawn on ax (labels 'N = ...', 'MDEV K = ...', ...)."""
    out = {}
    for line in ax.get_lines():
        words = line.get_label().split()
        if words and words[0] == "MDEV":
            words = words[1:]
        if len(words) > 1 and words[0] in TERM_OF_LABEL and words[1] in ("=", "(IEEE)"):
            out[TERM_OF_LABEL[words[0]]] = line
    return out


def test_legend_and_asymptote_ranges(record):
    r = gyrolab.allan(record, rate_hz=100.0)
    ax = r.plot()
    legend = texts(ax)
    assert any("68.3 % bounds" in t for t in legend), legend
    assert any(t.startswith("N = ") for t in legend)
    # IEEE B (its flicker floor, 0.664 B) and the Allan minimum: two entries, both values
    b = [t for t in legend if t.startswith("B (IEEE) = ")]
    assert b and f"{r.bias_instability_dph:.3g} deg/h" in b[0] and "0.664 B" in b[0], legend
    lows = [t for t in legend if t.startswith("Allan minimum = ")]
    assert lows and f"{r.allan_minimum_dph:.3g} deg/h" in lows[0], legend
    lines = asymptote_lines(ax)
    assert set(lines) == {"arw", "allan_minimum"}  # K is only an upper bound on this record
    for term, line in lines.items():
        lo, hi = next(g["tau_range_s"] for g in r.readings if g["term"] == term)
        x = line.get_xdata()
        assert x.min() >= lo * (1 - 1e-12) and x.max() <= hi * (1 + 1e-12), term
    assert "deg/s" in ax.get_ylabel()


@pytest.fixture(scope="module")
def random_walk_record():
    # N and K both read as values (8 h at 10 Hz), B only an upper bound
    return gyrolab.simulate_static(8 * 3600.0, 10.0, seed=3, arw_deg_rt_h=0.05, rrw_deg_h_rt_h=30.0)["output"]


def test_mdev_asymptotes_are_the_oadev_terms_scaled_as_sp1065(random_walk_record):
    allantools = pytest.importorskip("allantools")
    x = random_walk_record
    oadev = gyrolab.allan(x, rate_hz=10.0)
    mdev = gyrolab.allan(x, rate_hz=10.0, kind="mdev")
    plain = texts(mdev.plot())  # no terms of its own: no asymptotes
    assert not any("=" in t for t in plain), plain
    o_lines = asymptote_lines(oadev.plot())
    m_lines = asymptote_lines(mdev.plot(terms=oadev))
    assert set(m_lines) == set(o_lines) == {"arw", "rrw"}
    # independent: allantools' MDEV / OADEV of this record where each noise dominates
    # (white rate noise at m = 16, 32; random-walk rate noise at m = 1024, 4096)
    for term, ms in (("arw", [16, 32]), ("rrw", [1024, 4096])):
        xo, yo = o_lines[term].get_data()
        xm, ym = m_lines[term].get_data()
        assert np.array_equal(xo, xm)  # over the range the OADEV supports
        ratio = ym / yo
        assert np.allclose(ratio, ratio[0], rtol=1e-12)
        taus = np.array(ms) / 10.0
        _, md, _, _ = allantools.mdev(x, rate=10.0, data_type="freq", taus=taus)
        _, od, _, _ = allantools.oadev(x, rate=10.0, data_type="freq", taus=taus)
        assert np.allclose(md / od, ratio[0], rtol=0.05), (term, md / od, ratio[0])
    assert m_lines["arw"].get_label().startswith("MDEV N = ")


def test_mdev_flicker_floor_is_the_oadev_floor_scaled_as_sp1065():
    allantools = pytest.importorskip("allantools")
    x = gyrolab.simulate_static(4 * 3600.0, 10.0, seed=2, arw_deg_rt_h=0.01, bias_instability_dph=5.0)["output"]
    oadev = gyrolab.allan(x, rate_hz=10.0)
    mdev = gyrolab.allan(x, rate_hz=10.0, kind="mdev")
    o_line = asymptote_lines(oadev.plot())["allan_minimum"]
    m_line = asymptote_lines(mdev.plot(terms=oadev))["allan_minimum"]
    assert m_line.get_label().startswith("MDEV B (IEEE) = ")
    ratio = m_line.get_ydata()[0] / o_line.get_ydata()[0]
    # independent: allantools' MDEV / OADEV of this record inside the flicker floor's range
    taus = np.array([64, 256, 1024]) / 10.0
    _, md, _, _ = allantools.mdev(x, rate=10.0, data_type="freq", taus=taus)
    _, od, _, _ = allantools.oadev(x, rate=10.0, data_type="freq", taus=taus)
    assert np.allclose(md / od, ratio, rtol=0.05), (md / od, ratio)


def test_channels_draw_the_mdev_asymptotes_of_their_own_oadev_terms(record):
    both = {"g1": record, "g2": record * 2.0}
    oadev = gyrolab.allan(both, rate_hz=100.0, unit="dps")
    mdev = gyrolab.allan(both, rate_hz=100.0, kind="mdev", unit="dps")
    ax = mdev.plot(asymptotes=True, terms=oadev)
    n_lines = [line for line in ax.get_lines() if line.get_label().startswith("MDEV N = ")]
    assert len(n_lines) == 2
    levels = sorted(line.get_ydata()[0] for line in n_lines)
    assert levels[1] / levels[0] == pytest.approx(2.0, rel=1e-9)  # each channel its own N


def test_terms_of_another_unit_are_refused(record):
    gyro = gyrolab.allan(record, rate_hz=100.0)
    accel = gyrolab.allan(record, rate_hz=100.0, unit="m/s^2", kind="mdev")
    with pytest.raises(ValueError, match="terms="):
        accel.plot(terms=gyro)


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
    lines = asymptote_lines(r.plot())
    assert "vrw" in lines
    lo, hi = next(g["tau_range_s"] for g in r.readings if g["term"] == "vrw")
    assert lines["vrw"].get_xdata().min() >= lo * (1 - 1e-12) and lines["vrw"].get_xdata().max() <= hi * (1 + 1e-12)


def test_dense_taus_thin_the_error_bars(record):
    r = gyrolab.allan(record[:20_000], rate_hz=100.0, taus="all")
    ax = r.plot()
    assert len(r.taus_s) > 1000
    (bars,) = ax.containers  # one errorbar container, its vertical bars thinned
    segments = bars.lines[2][0].get_segments()
    assert 10 <= len(segments) <= 60
    (curve,) = [line for line in ax.get_lines() if "bounds" in line.get_label()]
    assert len(curve.get_xdata()) == len(r.taus_s)  # the curve keeps every tau
