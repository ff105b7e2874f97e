"""The stillness check from Python (issue 30): an array whose gyro moved is refused with the
keyword allow_motion; allow_motion=True analyses it and marks the result and every export.
Truth: white noise written here with a 20 deg/s rotation from 30 s to 34 s."""
import numpy as np
import pytest

import gyrolab

RATE = 100.0


def record(episode_dps: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(int(90 * RATE)) / RATE
    x = 0.3 + 0.05 * rng.standard_normal(t.size)
    x[(t >= 30.0) & (t < 34.0)] += episode_dps
    return x


def test_a_moving_array_is_refused_naming_the_keyword_and_the_episode():
    with pytest.raises(gyrolab.Error) as e:
        gyrolab.allan(record(20.0, 1), rate_hz=RATE, unit="dps")
    assert e.value.keyword == "allow_motion"
    assert "moved in 4 of 90 windows of 1 s" in e.value.message
    assert "first episode 30.0 to 34.0 s" in e.value.message
    assert "give allow_motion to analyse it anyway" in e.value.message


def test_allow_motion_marks_the_result_and_the_export():
    r = gyrolab.allan(record(20.0, 2), rate_hz=RATE, unit="dps", allow_motion=True)
    s = r.stillness
    assert s["moved"] is True and s["allow_motion"] is True
    assert (s["first_episode"]["start_s"], s["first_episode"]["end_s"]) == (30.0, 34.0)
    assert abs(s["first_episode"]["peak_departure"] - 20.0) < 0.1
    assert s["motion"].startswith("MOTION: the record is not static:")
    text = r.export("kalibr")
    assert "MOTION: the record is not static:" in text


def test_a_still_array_passes():
    for seed in (3, 4, 5):
        r = gyrolab.allan(record(0.0, seed), rate_hz=RATE, unit="dps")
        assert r.stillness["evaluated"] is True and r.stillness["moved"] is False
        assert "motion" not in r.stillness
        assert "MOTION" not in r.export("kalibr")
