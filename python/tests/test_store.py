"""gyrolab.store: the records store read back as DataFrames, on an SQLite file and on the real
PostgreSQL server of GYROLAB_TEST_PG_URL (scripts/test.sh starts it; without it the PostgreSQL
cases print SKIPPED and fail under CI=true).

Independent values: three devices of one lot are evaluated from the bundled raw log with their
outputs scaled (so that their scale factors differ); each figure the store returns is checked
against the report folder's own summary.csv (read with pandas), the lot statistics against numpy
over those values (mean, sd with ddof=1, Pp/Ppk from the plan's limits by the AIAG formulas,
yield), and every table against the command line's `gyrolab store ... --csv` output."""
import io
import os
import pickle
import subprocess
import uuid

import numpy as np
import pandas as pd
import pytest

import gyrolab
from gyrolab.store import Store

LOT = "PY-LOT"
SERIALS = ["PY-1", "PY-2", "PY-3"]
SCALES = [1.0, 1.002, 0.997]  # output scaled about the 2.5 V null: K scaled the same
LIMITS = (0.0074, 0.0076)  # the plan's scale factor limits, V/(deg/s)


def _write_device(root, folder, serial, scale):
    src = (root / "examples" / "data" / "raw_log_x.csv").read_text().splitlines()
    out = []
    for line in src:
        if line.startswith("#") or line.startswith("time_s"):
            out.append(line)
            continue
        t, rate, v = line.split(",")
        out.append(f"{t},{rate},{2.5 + (float(v) - 2.5) * scale:.6f}")
    (folder / "data").mkdir(parents=True, exist_ok=True)
    (folder / "data" / f"{serial}.csv").write_text("\n".join(out) + "\n")
    plan = (root / "examples" / "raw_log_plan.toml").read_text()
    plan = plan.replace('serial = "SIM-2014"', f'serial = "{serial}"')
    plan = plan.replace('lot = "SIM-LOT-1"', f'lot = "{LOT}"')
    plan = plan.replace('file = "data/raw_log_x.csv"', f'file = "data/{serial}.csv"')
    p = folder / f"{serial}.toml"
    p.write_text(plan)
    return p


def _postgres_url():
    url = os.environ.get("GYROLAB_TEST_PG_URL")
    if not url:
        if os.environ.get("CI") == "true":
            pytest.fail("GYROLAB_TEST_PG_URL is not set under CI=true: scripts/test.sh starts the server")
        print("SKIPPED: GYROLAB_TEST_PG_URL not set: the PostgreSQL half of gyrolab.store's tests")
        pytest.skip("SKIPPED: GYROLAB_TEST_PG_URL not set (scripts/test.sh starts a PostgreSQL server)")
    schema = "py_" + uuid.uuid4().hex[:12]
    subprocess.run(["psql", "-q", url, "-c", f"CREATE SCHEMA {schema}"], check=True)
    sep = "&" if "?" in url else "?"
    return f"{url}{sep}options=-c%20search_path%3D{schema}"


@pytest.fixture(scope="module", params=["sqlite", "postgres"])
def filled(request, root, tmp_path_factory):
    """A store holding the three devices' evaluations, and their report folders."""
    work = tmp_path_factory.mktemp(f"store-{request.param}")
    location = str(work / "lab.db") if request.param == "sqlite" else _postgres_url()
    store = Store(location)
    folders = {}
    for serial, scale in zip(SERIALS, SCALES):
        plan = _write_device(root, work, serial, scale)
        out = work / f"report-{serial}"
        gyrolab.evaluate_plan(plan, out)
        store.add(out)
        folders[serial] = out
    return store, folders


def _summary(folder):
    """The report folder's summary.csv (comment lines skipped)."""
    text = (folder / "summary.csv").read_text()
    return pd.read_csv(io.StringIO("\n".join(l for l in text.splitlines() if not l.startswith("#"))))


def _value(folder, figure):
    s = _summary(folder)
    return float(s.loc[s["figure"] == figure, "value"].iloc[0])


def test_figures_equal_each_report_folders_summary(filled):
    store, folders = filled
    df = store.figures(LOT)
    assert set(df["serial"]) == set(SERIALS)
    sf = df[df["figure"] == "scale_factor"].set_index("serial")
    for serial, folder in folders.items():
        assert sf.loc[serial, "value"] == _value(folder, "scale_factor")
        assert (sf.loc[serial, "limit_min"], sf.loc[serial, "limit_max"]) == LIMITS
    assert sf["value"].dtype == np.float64
    assert str(df["evaluation"].dtype) == "Int64"
    # the scale factors follow the output scaling (K scaled the same)
    k = sf.loc[SERIALS, "value"].to_numpy()
    np.testing.assert_allclose(k / k[0], SCALES, rtol=2e-4)


def test_lot_statistics_equal_numpy_and_aiag_formulas(filled):
    store, folders = filled
    values = np.array([_value(folders[s], "scale_factor") for s in SERIALS])
    lot = store.lot(LOT)
    row = lot[lot["figure"] == "scale_factor"].iloc[0]
    lo, hi = LIMITS
    mean, sd = values.mean(), values.std(ddof=1)
    assert row["n"] == 3
    assert row["mean"] == pytest.approx(mean, rel=1e-12)
    assert row["sd"] == pytest.approx(sd, rel=1e-9)
    assert (row["min"], row["max"]) == (values.min(), values.max())
    assert row["Pp"] == pytest.approx((hi - lo) / (6 * sd), rel=1e-9)
    assert row["Ppk"] == pytest.approx(min(hi - mean, mean - lo) / (3 * sd), rel=1e-9)
    assert row["yield"] == pytest.approx(np.mean((values >= lo) & (values <= hi)), rel=1e-12)
    assert row["yield_evaluated"] == row["yield"], "every device gives a value"
    assert (row["n_devices"], row["n_bounds"], row["n_not_evaluated"]) == (3, 0, 0)
    assert "capability from n = 3 values, fewer than 25" in row["notes"]
    assert lot.attrs["query"] == f"lot {LOT}"


NE_LOT = "PY-LOT-NE"


@pytest.fixture(scope="module", params=["sqlite", "postgres"])
def with_not_evaluated(request, root, tmp_path_factory):
    """A lot of four devices; the fourth's plan decides nonlinearity by the guarded rule, which
    needs an expanded uncertainty nonlinearity does not have: NOT EVALUATED with a value."""
    work = tmp_path_factory.mktemp(f"store-ne-{request.param}")
    location = str(work / "lab.db") if request.param == "sqlite" else _postgres_url()
    store = Store(location)
    folders = {}
    for serial, scale in [("NE-1", 1.0), ("NE-2", 1.002), ("NE-3", 0.997), ("NE-4", 1.001)]:
        plan = _write_device(root, work, serial, scale)
        text = plan.read_text().replace(f'lot = "{LOT}"', f'lot = "{NE_LOT}"')
        if serial == "NE-4":
            text = text.replace("nonlinearity_pct = { max = 0.1 }",
                                'nonlinearity_pct = { max = 0.1, rule = "guarded_acceptance" }')
        plan.write_text(text)
        out = work / f"report-{serial}"
        gyrolab.evaluate_plan(plan, out)
        store.add(out)
        folders[serial] = out
    return store, folders


def test_lot_counts_a_device_not_evaluated_and_keeps_its_value_out(with_not_evaluated, cli):
    store, folders = with_not_evaluated
    h = store.history("NE-4", figure="nonlinearity_pct")
    assert h["verdict"].tolist() == ["NOT EVALUATED"], "the set-up: NE-4's nonlinearity is not evaluated"
    lot = store.lot(NE_LOT)
    nl = lot[lot["figure"] == "nonlinearity_pct"].iloc[0]
    values = np.array([_value(folders[s], "nonlinearity_pct") for s in ["NE-1", "NE-2", "NE-3"]])
    assert (nl["n"], nl["n_devices"], nl["n_bounds"], nl["n_not_evaluated"]) == (3, 4, 0, 1)
    assert nl["mean"] == pytest.approx(values.mean(), rel=1e-12), "NE-4's value is kept out"
    # The yield counts NE-4 as not conforming: 3 of 4 devices, 3 of 3 values.
    assert nl["yield"] == pytest.approx(np.sum(values <= 0.1) / 4, rel=1e-12)
    assert nl["yield_evaluated"] == pytest.approx(np.mean(values <= 0.1), rel=1e-12)
    assert "1 device NOT EVALUATED (no value, or the verdict NOT EVALUATED): NE-4" in nl["notes"]
    # Ppk from the three values only (upper limit 0.1), with the few-values warning.
    assert nl["Ppk"] == pytest.approx((0.1 - values.mean()) / (3 * values.std(ddof=1)), rel=1e-9)
    assert "capability from n = 3 values, fewer than 25" in nl["notes"]
    # The scale factor: four values of four devices, Ppk by the AIAG formula, the warning.
    sf = lot[lot["figure"] == "scale_factor"].iloc[0]
    k = np.array([_value(folders[s], "scale_factor") for s in ["NE-1", "NE-2", "NE-3", "NE-4"]])
    lo, hi = LIMITS
    assert (sf["n"], sf["n_devices"], sf["n_not_evaluated"]) == (4, 4, 0)
    assert sf["Ppk"] == pytest.approx(min(hi - k.mean(), k.mean() - lo) / (3 * k.std(ddof=1)), rel=1e-9)
    assert "capability from n = 4 values, fewer than 25" in sf["notes"]
    # figures(): NE-4's nonlinearity has no value, its verdict says why.
    f = store.figures(NE_LOT)
    row = f[(f["serial"] == "NE-4") & (f["figure"] == "nonlinearity_pct")].iloc[0]
    assert np.isnan(row["value"]) and row["basis"] == "value" and row["verdict"] == "NOT EVALUATED"
    # The same table as the command line's CSV, notes included.
    _same_table(lot, _cli_csv(cli, store, "lot", NE_LOT))
    chart = store.control_chart("x", "nonlinearity_pct", lot=NE_LOT)
    assert any("NE-4" in n for n in chart.attrs["notes"]), chart.attrs["notes"]


def _cli_csv(cli, store, *args):
    out = subprocess.run([cli, "store", *args, "--store", store.location, "--csv"], check=True, capture_output=True, text=True).stdout
    return pd.read_csv(io.StringIO(out), keep_default_na=False, na_values=[""])


def _same_table(py, cli):
    assert list(py.columns) == list(cli.columns)
    assert len(py) == len(cli)
    for c in py.columns:
        a, b = py[c].tolist(), cli[c].tolist()
        for x, y in zip(a, b):
            if x is None or x is pd.NA or (isinstance(x, float) and np.isnan(x)):
                assert y is None or (isinstance(y, float) and np.isnan(y)), (c, x, y)
            elif isinstance(x, str):  # an empty text is an empty CSV field
                assert (str(y) if isinstance(y, str) or not np.isnan(y) else "") == x, (c, x, y)
            else:
                assert float(y) == float(x), (c, x, y)


def test_every_table_equals_the_command_lines_csv(filled, cli):
    store, _ = filled
    _same_table(store.lot(LOT), _cli_csv(cli, store, "lot", LOT))
    _same_table(store.history("PY-2"), _cli_csv(cli, store, "history", "PY-2"))
    _same_table(
        store.control_chart("x", "scale_factor", lot=LOT),
        _cli_csv(cli, store, "chart", "--figure", "scale_factor", "--axis", "x", "--lot", LOT)
    )


def test_history_svg_is_the_command_lines_file(filled, cli, tmp_path):
    store, _ = filled
    out = tmp_path / "history.svg"
    subprocess.run([cli, "store", "history", "PY-2", "--store", store.location, "--svg", str(out)], check=True,
                   capture_output=True)
    svg = store.history_svg("PY-2")
    assert svg == out.read_text(), "the Python plot and the command line's are the same bytes"
    assert svg.startswith("<?xml") and "History of serial PY-2" in svg
    one = store.history_svg("PY-2", figure="scale_factor")
    assert "axis x: scale_factor" in one and one.count("axis x: ") == 1 < svg.count("axis x: ")
    with pytest.raises(gyrolab.Error, match="NO-SUCH-SERIAL"):
        store.history_svg("NO-SUCH-SERIAL")


def test_history_has_every_summary_row_and_evaluation_json(filled):
    store, folders = filled
    h = store.history("PY-1")
    summary = _summary(folders["PY-1"])
    assert len(h) == len(summary)
    assert set(h["current"]) == {"yes"}
    only = store.history("PY-1", figure="scale_factor")
    assert list(only["figure"]) == ["scale_factor"]
    e = store.evaluation(int(h["evaluation"].iloc[0]))
    assert e["record"]["serial"] == "PY-1" and e["record"]["lot"] == LOT
    assert all(len(f["sha256"]) == 64 for f in e["record"]["inputs"])


def test_the_report_folder_comes_back_byte_for_byte(filled, tmp_path):
    store, folders = filled
    eid = int(store.history("PY-3")["evaluation"].iloc[0])
    written = store.report(eid, tmp_path / "back")
    names = sorted(os.listdir(folders["PY-3"]))
    assert sorted(os.path.basename(p) for p in written) == names
    for n in names:
        assert (tmp_path / "back" / n).read_bytes() == (folders["PY-3"] / n).read_bytes(), n


def test_store_and_frames_pickle(filled):
    store, _ = filled
    again = pickle.loads(pickle.dumps(store))
    assert again.location == store.location
    df = pickle.loads(pickle.dumps(again.lot(LOT)))
    assert df["n"].tolist()[0] == 3


def test_bad_stores_raise_named_errors_without_passwords(tmp_path):
    missing = tmp_path / "none.db"
    with pytest.raises(gyrolab.Error) as e:
        Store(missing).lot(LOT)
    assert str(missing) in str(e.value)
    assert not missing.exists()
    foreign = tmp_path / "foreign.db"
    foreign.write_bytes(b"not a database at all" * 100)
    with pytest.raises(gyrolab.Error) as e:
        Store(foreign).history("X")
    assert str(foreign) in str(e.value)
    url = "postgres://lab:s3cret-pw@127.0.0.1:1/gyro"
    with pytest.raises(gyrolab.Error) as e:
        Store(url).lot(LOT)
    assert "s3cret-pw" not in str(e.value) and "***" in str(e.value)
    assert "s3cret-pw" not in repr(Store(url))
    with pytest.raises(gyrolab.Error) as e:
        Store(tmp_path / "x.db").lot(LOT, confidence=1.5)
    assert e.value.keyword == "confidence"
