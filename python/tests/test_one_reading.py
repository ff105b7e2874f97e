"""One reading for every front end (issue 55): a DataFrame or a dict of named columns is read as
the command line reads a CSV file with that header, so the same table gives the same figures
and the same warnings; the three cases the issue found silently wrong are tested here."""
import json
import subprocess
import warnings

import numpy as np
import pytest

import gyrolab

pd = pytest.importorskip("pandas")


def _frame(n=60_000, ms=True):
    rng = np.random.default_rng(55)
    stamp = np.arange(n) * (10 if ms else 0.01)
    return pd.DataFrame(
        {
            "timestamp": stamp,
            "gx": rng.standard_normal(n) * 0.01,
            "gy": rng.standard_normal(n) * 0.01,
            "temp": 25.0 + rng.standard_normal(n) * 0.01,
        }
    )


def test_a_millisecond_counter_read_as_seconds_is_warned_as_the_cli_warns():
    # Before: 0.1 Hz (10 s steps) with no word. Now the CLI's warning, and the fix it names works.
    df = _frame()
    with pytest.warns(UserWarning, match=r"time column 'timestamp' read in s \(assumed.*whole seconds"):
        r = gyrolab.allan(df, units=["deg/s"])
    assert r["gx"].tau0_s == 10.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = gyrolab.allan(df, units={"timestamp": "ms", "gx": "deg/s", "gy": "deg/s"})
    assert r["gx"].tau0_s == pytest.approx(0.01, rel=1e-12)


def test_timestamp_is_the_time_column_and_temp_is_not_a_gyro():
    r = gyrolab.allan(_frame(ms=False), unit="deg/s")
    assert list(r) == ["gx", "gy"], "temp is a temperature column, timestamp the time"
    assert r["gx"].tau0_s == pytest.approx(0.01, rel=1e-12)
    assert r["gx"].to_dict()["noise"] is not None


def test_a_table_gives_the_figures_and_warnings_of_the_cli_on_its_csv(cli, tmp_path):
    df = _frame(ms=False)
    path = tmp_path / "imu_log.csv"
    df.to_csv(path, index=False, float_format="%.17g")
    out = subprocess.run([cli, "allan", str(path), "--unit", "deg/s", "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = gyrolab.allan(df, unit="deg/s")
    for channel in doc["channels"]:
        mine = r[channel["channel"]]
        np.testing.assert_array_equal(mine.taus_s, channel["taus_s"])
        np.testing.assert_allclose(mine.dev, channel["dev"], rtol=1e-13)
    assert [c["channel"] for c in doc["channels"]] == list(r)
    cli_warnings = [l for l in out.stderr.splitlines() if l.startswith("warning:")]
    assert len(caught) == len(cli_warnings), (cli_warnings, [str(w.message) for w in caught])
