"""Every option honoured or refused (issue 34): options a call would not use are errors naming
the keyword, in Python's words; taus rounded as allantools rounds them; the gaps policy;
compact repr."""
import allantools
import numpy as np
import pytest

import gyrolab

X = np.random.default_rng(8).standard_normal(10_000) * 0.01


def test_missing_rate_is_gyrolabs_message():
    with pytest.raises(gyrolab.Error, match="give rate_hz") as e:
        gyrolab.allan(X)
    assert e.value.keyword == "rate_hz"


def test_scale_factor_with_a_rate_unit_is_refused():
    with pytest.raises(gyrolab.Error, match="scale_factor applies to outputs in v, mv or lsb") as e:
        gyrolab.allan(X, rate_hz=100.0, unit="dps", scale_factor=0.0075)
    assert e.value.keyword == "scale_factor"
    with pytest.raises(gyrolab.Error, match="null"):
        gyrolab.allan(X, rate_hz=100.0, unit="m/s^2", null=2.5)


def test_integer_and_bool_samples():
    counts = (np.arange(4000) % 7).astype(np.int32)
    with pytest.raises(gyrolab.Error, match="integer samples") as e:
        gyrolab.allan(counts, rate_hz=1.0)
    assert e.value.keyword == "unit"
    r = gyrolab.allan(counts, rate_hz=1.0, unit="lsb", confidence=None)
    assert r.unit == "LSB" and r.noise_note
    with pytest.raises(gyrolab.Error, match="boolean"):
        gyrolab.allan(counts > 3, rate_hz=1.0, unit="lsb")


def test_unknown_unit_lists_every_accepted_unit():
    with pytest.raises(gyrolab.Error) as e:
        gyrolab.allan(X, rate_hz=1.0, unit="furlong/s")
    for u in ["dps", "dph", "rad_s", "m/s^2", "m/s2", "g", "mg", "ug", "v", "mv", "lsb"]:
        assert u in str(e.value), u
    for u in ["dps", "rad/s", "deg/s", "m/s^2", "m/s2", "g", "mg", "ug", "mrad/s", "dph"]:
        assert u in gyrolab.allan.__doc__ or u in gyrolab.UNITS, u
        gyrolab.allan(X, rate_hz=1.0, unit=u, confidence=None)


def test_fit_range_any_sequence_and_reversed_refused():
    s = gyrolab.simulate_static(600.0, 100.0, seed=2, arw_deg_rt_h=0.5)
    a = gyrolab.allan(s["output"], rate_hz=100.0, fit_range_s=[0.1, 10.0])
    b = gyrolab.allan(s["output"], rate_hz=100.0, fit_range_s=np.array([0.1, 10.0]))
    assert a.fit is not None and a.fit == b.fit
    assert a.fit["tau_range_s"][0] >= 0.1 and a.fit["tau_range_s"][1] <= 10.0
    with pytest.raises(gyrolab.Error, match="increasing") as e:
        gyrolab.allan(s["output"], rate_hz=100.0, fit_range_s=(10.0, 0.1))
    assert e.value.keyword == "fit_range_s"
    with pytest.raises(gyrolab.Error, match="fit_range_s"):
        gyrolab.allan(s["output"], rate_hz=100.0, fit_range_s=[1.0])


def test_taus_are_rounded_to_the_nearest_m_as_allantools_does():
    taus = np.logspace(-2, 1, 17)
    r = gyrolab.allan(X, rate_hz=100.0, taus=taus, confidence=None)
    a_taus, a_dev, _, _ = allantools.oadev(X, rate=100.0, data_type="freq", taus=taus)
    np.testing.assert_allclose(r.taus_s, a_taus, rtol=1e-12)
    np.testing.assert_allclose(r.dev, a_dev, rtol=1e-12)
    assert r.taus_rounded and all(abs(u * 100 - round(u * 100)) < 1e-9 for u in r.taus_rounded.values())
    with pytest.raises(gyrolab.Error, match="shorter than the sample interval"):
        gyrolab.allan(X, rate_hz=100.0, taus=[0.001, 1.0])


def test_gaps_policy():
    x = X.copy()
    x[100] = np.nan
    with pytest.raises(gyrolab.Error, match=r"x\[100\] = NaN"):
        gyrolab.allan(x, rate_hz=100.0)
    r = gyrolab.allan(x, rate_hz=100.0, gaps="analyse", confidence=None)
    # Independent value: the overlapping Allan deviation over the terms that touch no missing
    # sample, sigma^2 = mean over valid i of (mean(y[i+m:i+2m]) - mean(y[i:i+m]))^2 / 2.
    for m in (1, 2, 4, 8):
        c = np.concatenate([[0.0], np.cumsum(np.nan_to_num(x))])
        bad = np.concatenate([[0], np.cumsum(np.isnan(x))])
        i = np.arange(x.size - 2 * m + 1)
        d = ((c[i + 2 * m] - c[i + m]) - (c[i + m] - c[i])) / m
        ok = bad[i + 2 * m] == bad[i]
        want = np.sqrt(np.mean(d[ok] ** 2) / 2)
        j = int(np.flatnonzero(r.m == m)[0])
        assert r.dev[j] == pytest.approx(want, rel=1e-9), m
        assert r.n_terms[j] == ok.sum()
    t = np.arange(X.size) / 100.0
    t[5000:] += 0.05  # five samples missing
    with pytest.raises(gyrolab.Error, match=r"gap in the time stamps before time\[5000\]: 5 sample"):
        gyrolab.allan(X, time=t)
    assert gyrolab.allan(X, time=t, gaps="analyse").samples == X.size + 5
    with pytest.raises(gyrolab.Error, match="gaps="):
        gyrolab.allan(X, rate_hz=100.0, gaps="skip")


def test_a_files_errors_name_the_file(tmp_path):
    # The same gap read from a file: the error names the file, as the CLI's does.
    t = np.arange(X.size) / 100.0
    t[5000:] += 0.05
    path = tmp_path / "gap.csv"
    np.savetxt(path, np.column_stack([t, X]), delimiter=",", header="time_s,rate_dps", comments="", fmt="%.17g")
    with pytest.raises(gyrolab.Error, match=r"gap\.csv: a gap in the time stamps before time\[5000\]") as e:
        gyrolab.allan(path)
    assert e.value.file == str(path) and e.value.keyword == "gaps"
    assert gyrolab.allan(path, gaps="analyse")["rate_dps"].samples == X.size + 5


def test_rate_and_time_must_agree():
    t = np.arange(X.size) / 100.0
    with pytest.raises(gyrolab.Error, match="rate_hz = 50 Hz disagrees"):
        gyrolab.allan(X, rate_hz=50.0, time=t)


def test_messages_use_keywords_not_flags():
    for call in [
        lambda: gyrolab.allan(X, rate_hz=0.0),
        lambda: gyrolab.allan(X, rate_hz=1.0, taus="sometimes"),
        lambda: gyrolab.allan(X, rate_hz=1.0, confidence=2.0),
        lambda: gyrolab.allan(X, time=np.ones(X.size)),
    ]:
        with pytest.raises(gyrolab.Error) as e:
            call()
        assert "--" not in str(e.value), str(e.value)


def test_simulate_unknown_preset_lists_presets():
    with pytest.raises(gyrolab.Error, match="adxrs646, adis16470, stim300"):
        gyrolab.simulate_static(10.0, preset="nope")


def test_rate_table_files_honour_their_options(root):
    f = [root / "data" / "paper" / "paper_rate_table_x.csv"]
    plain = gyrolab.rate_table(files=f, axis_names=["x"])["axes"][0]
    half = gyrolab.rate_table(files=f, axis_names=["x"], half_hysteresis=True)["axes"][0]
    assert half["hysteresis_pct"] == pytest.approx(plain["hysteresis_pct"] / 2, rel=1e-12)
    with pytest.raises(gyrolab.Error):
        gyrolab.rate_table(files=f, unit="furlong")
    with pytest.raises(gyrolab.Error, match="one source"):
        gyrolab.rate_table([1.0], [1.0], [1], ["fwd"], files=f)


def test_repr_is_compact_and_html_names_the_terms():
    s = gyrolab.simulate_static(600.0, 100.0, seed=2, arw_deg_rt_h=0.5, bias_instability_dph=5.0)
    r = gyrolab.allan(s["output"], rate_hz=100.0, taus="all")
    text = repr(r)
    assert len(text) < 300 and "N=" in text and "deg/√h" in text, text
    html = r._repr_html_()
    assert "arw" in html and "<table>" in html and len(html) < 4000
    many = gyrolab.allan({"a": s["output"], "b": s["output"]}, rate_hz=100.0)
    assert len(repr(many)) < 600
    assert r.noise_note is None
    assert gyrolab.allan(s["output"], rate_hz=100.0, kind="mdev").noise_note
