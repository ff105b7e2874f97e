"""Malformed arrays and files raise gyrolab.Error (a ValueError) with a located message; never
a crash of the interpreter."""
import numpy as np
import pytest

import gyrolab


@pytest.mark.parametrize(
    "x, fragment",
    [
        (np.array([1.0, np.nan, 2.0, 3.0]), "x[1] = NaN"),
        (np.array([1.0, np.inf, 2.0, 3.0]), "x[1] = inf"),
        (np.array([], dtype=float), "empty"),
        (np.zeros((10, 2, 2)), "1-D"),
        (["a", "b", "c"], "numbers"),
    ],
)
def test_bad_arrays_raise(x, fragment):
    with pytest.raises(gyrolab.Error, match=None) as e:
        gyrolab.allan(x, rate_hz=1.0)
    assert fragment in str(e.value)
    assert isinstance(e.value, ValueError)


def test_non_contiguous_and_integer_arrays_work():
    x = np.random.default_rng(1).standard_normal(8000)
    a = gyrolab.allan(x[::2], rate_hz=1.0, confidence=None)
    b = gyrolab.allan(np.ascontiguousarray(x[::2]), rate_hz=1.0, confidence=None)
    np.testing.assert_array_equal(a.dev, b.dev)
    # integer samples with their unit named: the same as the floats
    i = gyrolab.allan(np.arange(1000) % 7, rate_hz=1.0, unit="lsb", confidence=None)
    f = gyrolab.allan((np.arange(1000) % 7).astype(float), rate_hz=1.0, unit="lsb", confidence=None)
    np.testing.assert_array_equal(i.dev, f.dev)


def test_option_errors_name_the_keyword():
    x = np.zeros(100) + np.arange(100) % 3
    with pytest.raises(gyrolab.Error, match="rate_hz must be a positive number"):
        gyrolab.allan(x, rate_hz=0.0)
    with pytest.raises(gyrolab.Error, match="confidence"):
        gyrolab.allan(x, rate_hz=1.0, confidence=1.5)
    with pytest.raises(gyrolab.Error, match="unknown deviation kind"):
        gyrolab.allan(x, rate_hz=1.0, kind="xdev")
    with pytest.raises(gyrolab.Error, match="latitude_deg"):
        gyrolab.bias(x, rate_hz=1.0, latitude_deg=95.0)


def test_file_errors_name_file_and_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("time_s,rate_dps\n0,0.1\n0.01,oops\n")
    with pytest.raises(gyrolab.Error) as e:
        gyrolab.read(p, as_dataframe=False)
    assert "bad.csv" in str(e.value) and ":3" in str(e.value)
    with pytest.raises(gyrolab.Error, match="(?i)not found|no such file"):
        gyrolab.read(tmp_path / "missing.csv")
