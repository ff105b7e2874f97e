"""gyrolab.allan against allantools (every kind, relative 1e-12), against `gyrolab allan --json`
on the same file, and against simulated truth."""
import json
import pickle
import subprocess

import allantools
import numpy as np
import pytest

import gyrolab

KINDS = ["oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev"]


def records():
    rng = np.random.default_rng(20261123)
    yield "white", rng.standard_normal(5000) * 0.01, 100.0
    yield "random-walk", np.cumsum(rng.standard_normal(4096)) * 1e-3 + 0.2 * rng.standard_normal(4096), 10.0
    yield "offset", 2.5 + 1e-4 * rng.standard_normal(3000), 1.0


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("taus", ["octave", "decade"])
def test_equal_to_allantools(kind, taus):
    for name, data, rate in records():
        r = gyrolab.allan(data, rate_hz=rate, kind=kind, taus=taus, confidence=None)
        a_taus, a_dev, _, _ = getattr(allantools, kind)(data, rate=rate, data_type="freq", taus=r.taus_s)
        common = 0
        for t, d in zip(r.taus_s, r.dev):
            j = np.flatnonzero(np.isclose(a_taus, t, rtol=1e-12))
            if j.size:
                common += 1
                assert d == pytest.approx(a_dev[j[0]], rel=1e-12), f"{name} {kind} tau {t}"
        assert common >= 3, f"{name} {kind}: only {common} taus in common"


def test_same_as_the_command_line(cli, tmp_path):
    data = np.random.default_rng(5).standard_normal(20_000) * 0.02
    path = tmp_path / "rate.csv"
    path.write_text("time_s,rate_dps\n" + "".join(f"{i * 0.01!r},{v!r}\n" for i, v in enumerate(data.tolist())))
    out = subprocess.run([cli, "allan", str(path), "--json"], check=True, capture_output=True, text=True).stdout
    c = json.loads(out)
    r = gyrolab.allan(data, rate_hz=100.0)
    p = r.to_dict()
    for key in ["taus_s", "m", "dev", "ci_low", "ci_high", "n_terms", "alpha", "edf"]:
        assert p[key] == c[key], key
    assert p["noise"] == c["noise"]
    np.testing.assert_array_equal(r.dev, np.array(c["dev"]))
    np.testing.assert_array_equal(r.ci_high, np.array([np.nan if v is None else v for v in c["ci_high"]]))


def test_the_gmwm_is_computed_when_first_read_and_equals_the_command_line(cli, tmp_path):
    # The GMWM is the costliest part of a short record's analysis and most calls never read it:
    # it is computed on first use (r.gmwm, to_dict, export, pickling), and is then the CLI's.
    data = np.random.default_rng(8).standard_normal(30_000) * 0.02
    path = tmp_path / "rate.csv"
    path.write_text("time_s,rate_dps\n" + "".join(f"{i * 0.01!r},{v!r}\n" for i, v in enumerate(data.tolist())))
    out = subprocess.run([cli, "allan", str(path), "--json"], check=True, capture_output=True, text=True).stdout
    want = json.loads(out)["gmwm"]
    assert want is not None and want["parameters"]
    r = gyrolab.allan(data, rate_hz=100.0)
    assert "_gmwm" in r.__dict__ and repr(r.__dict__["_gmwm"]) == "<not yet computed>"
    assert r.gmwm == want
    assert r.to_dict()["gmwm"] == want
    # pickled before first use: computed for the pickle, equal after it
    fresh = gyrolab.allan(data, rate_hz=100.0)
    again = pickle.loads(pickle.dumps(fresh))
    assert again.gmwm == want and again == r
    assert again.export("kalibr", estimator="gmwm") == r.export("kalibr", estimator="gmwm")
    # copies of a result not read yet work (the native analyses are shared, never copied)
    import copy
    import dataclasses

    unread = gyrolab.allan(data, rate_hz=100.0)
    assert copy.deepcopy(unread) == r and copy.copy(unread).gmwm == want
    assert dataclasses.asdict(gyrolab.allan(data, rate_hz=100.0))["kind"] == "oadev"


def test_simulated_arw_is_recovered():
    # White rate noise of N = 0.5 deg/sqrt(h): the slope-line N is within 3 % of the truth on a
    # 1 h record at 100 Hz (the OADEV at tau = 1 s has about 1 % standard error there).
    s = gyrolab.simulate_static(3600.0, 100.0, seed=11, arw_deg_rt_h=0.5)
    r = gyrolab.allan(s["output"], rate_hz=100.0)
    assert r.unit == "deg/s"
    assert r.noise["arw_deg_rt_h"] == pytest.approx(0.5, rel=0.03)
    i = int(np.argmin(np.abs(r.taus_s - 1.28)))
    assert r.dev[i] == pytest.approx(0.5 / 60.0 / np.sqrt(r.taus_s[i]), rel=0.05)


def test_units_convert():
    x = np.random.default_rng(3).standard_normal(4000) * 0.01
    dps = gyrolab.allan(x, rate_hz=10.0, confidence=None)
    dph = gyrolab.allan(x * 3600.0, rate_hz=10.0, unit="dph", confidence=None)
    np.testing.assert_allclose(dph.dev, dps.dev, rtol=1e-12)
    volts = gyrolab.allan(2.5 + 0.0075 * x, rate_hz=10.0, unit="v", scale_factor=0.0075, null=2.5, confidence=None)
    np.testing.assert_allclose(volts.dev, dps.dev, rtol=1e-9)
    raw = gyrolab.allan(2.5 + 0.0075 * x, rate_hz=10.0, unit="v", confidence=None)
    assert raw.unit == "V" and not raw.noise


def test_plot_draws_curve_bounds_and_asymptotes():
    matplotlib = pytest.importorskip("matplotlib", reason="matplotlib is an optional dependency")
    matplotlib.use("Agg")
    s = gyrolab.simulate_static(600.0, 100.0, seed=2, arw_deg_rt_h=0.5, bias_instability_dph=5.0)
    ax = gyrolab.allan(s["output"], rate_hz=100.0).plot()
    assert ax.get_xscale() == "log" and "deg/s" in ax.get_ylabel()
    assert any("N =" in t.get_text() for t in ax.get_legend().get_texts())
