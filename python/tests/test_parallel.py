"""gyrolab in process pools (issue 34): after a call in the parent, fork-based
multiprocessing.Pool and ProcessPoolExecutor workers compute (gyrolab's thread pool is built
again in a forked child; before, they waited forever for the parent's threads); results and
errors pickle, so a spawn pool returns them with their message and location. Each pool is
bounded by a timeout, so a hang fails the test instead of freezing the suite."""
import concurrent.futures as cf
import multiprocessing as mp
import pickle
import sys

import numpy as np
import pytest

import gyrolab

sys.path.insert(0, __file__.rsplit("/", 1)[0])
import _workers  # noqa: E402

TIMEOUT_S = 60


def expected(seeds):
    return [_workers.deviation(s) for s in seeds]


@pytest.mark.skipif(sys.platform != "linux", reason="fork is the Linux start method")
def test_fork_pool_after_a_call_in_the_parent():
    seeds = [1, 2, 3, 4]
    want = expected(seeds)  # the parent's thread pool now has threads
    with mp.get_context("fork").Pool(2) as pool:
        got = pool.map_async(_workers.deviation, seeds).get(TIMEOUT_S)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


@pytest.mark.skipif(sys.platform != "linux", reason="fork is the Linux start method")
def test_fork_process_pool_executor_after_a_call_in_the_parent():
    seeds = [5, 6, 7]
    want = expected(seeds)
    with cf.ProcessPoolExecutor(2, mp_context=mp.get_context("fork")) as ex:
        got = [f.result(timeout=TIMEOUT_S) for f in [ex.submit(_workers.deviation, s) for s in seeds]]
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


@pytest.mark.skipif(sys.platform != "linux", reason="fork is the Linux start method")
def test_fork_pool_returns_results_and_located_errors():
    _workers.deviation(1)
    with mp.get_context("fork").Pool(1) as pool:
        r = pool.apply_async(_workers.result, (9,)).get(TIMEOUT_S)
        assert r == _workers.result(9)
        with pytest.raises(gyrolab.Error, match=r"x\[1\] = NaN"):
            pool.apply_async(_workers.failing, (0,)).get(TIMEOUT_S)


def test_spawn_pool_error_crosses_with_message_and_location():
    with mp.get_context("spawn").Pool(1) as pool:
        with pytest.raises(gyrolab.Error) as e:
            pool.apply_async(_workers.failing, (0,)).get(TIMEOUT_S)
    assert "x[1] = NaN is not a finite number" in str(e.value)
    assert e.value.file == "<array>" and isinstance(e.value, ValueError)


def test_errors_pickle_with_location_and_subclasses():
    e = gyrolab.Error("bad.csv:3: not a number", file="bad.csv", line=3, column="rate_dps", keyword=None)
    back = pickle.loads(pickle.dumps(e))
    assert type(back) is gyrolab.Error and str(back) == str(e)
    assert (back.file, back.line, back.column, back.keyword) == ("bad.csv", 3, "rate_dps", None)
    assert gyrolab.Error.__module__ == "gyrolab"

    class Custom(gyrolab.Error):
        pass

    globals()["Custom"] = Custom  # picklable by reference
    Custom.__qualname__ = "Custom"
    c = pickle.loads(pickle.dumps(Custom("m", keyword="rate_hz")))
    assert type(c) is Custom and c.keyword == "rate_hz" and str(c) == "m"
    # An error raised by the native module carries its location.
    with pytest.raises(gyrolab.Error) as raised:
        gyrolab.allan(np.ones(100), rate_hz=-1.0)
    assert raised.value.keyword == "rate_hz"
    again = pickle.loads(pickle.dumps(raised.value))
    assert again.keyword == "rate_hz" and str(again) == str(raised.value)


def test_results_pickle_and_compare():
    x = np.random.default_rng(4).standard_normal(30_000) * 0.01
    r = gyrolab.allan(x, rate_hz=100.0)
    back = pickle.loads(pickle.dumps(r))
    assert back == r and back.arw_deg_rt_h == r.arw_deg_rt_h
    other = gyrolab.allan(x * 2, rate_hz=100.0)
    assert (r == other) is False and r != other
    many = gyrolab.allan({"a": x, "b": x[::-1].copy()}, rate_hz=100.0)
    assert pickle.loads(pickle.dumps(many)) == many


@pytest.mark.skipif(sys.platform != "linux", reason="threads are counted in /proc/self/task")
def test_a_short_record_is_computed_on_the_calling_thread_and_starts_no_thread():
    # Below gyrolab.allan's parallel size (2^18 samples in all) the call runs on the caller's
    # thread with no thread pool (issue 56): no rayon pool is started, the package's nor rayon's
    # global one, so nothing waits on threads a fork would lose. A long record starts the
    # package's pool. In a fresh interpreter, so that no earlier test has started a pool.
    import subprocess
    import textwrap

    code = textwrap.dedent(
        """
        import os, numpy as np, gyrolab
        count = lambda: len(os.listdir("/proc/self/task"))
        x = np.random.default_rng(1).standard_normal(60_000) * 0.01
        before = count()
        for _ in range(3):
            r = gyrolab.allan(x, rate_hz=100.0)
        gyrolab.allan({"a": x, "b": x, "c": x}, rate_hz=100.0)
        short = count()
        # 200,000 stamped samples with a gap of 100,000: padded to 300,000 on the grid, so not
        # short: computed on the package's pool, and no thread of rayon's global pool started
        # (only threads named gyrolab-N are new)
        t = np.arange(200_000) * 0.01
        t[100_000:] += 1000.0
        others = lambda: sum(1 for d in os.listdir("/proc/self/task")
                             if not open(f"/proc/self/task/{d}/comm").read().startswith("gyrolab-"))
        y = np.random.default_rng(3).standard_normal(200_000) * 0.01
        gyrolab.allan(y, time=t, gaps="analyse", confidence=None)
        padded_others = others()
        gyrolab.allan(np.random.default_rng(2).standard_normal(300_000) * 0.01, rate_hz=100.0)
        print(before, short, count(), padded_others, r.dev[0] > 0)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, timeout=TIMEOUT_S)
    before, short, long, padded_others, ok = out.stdout.split()
    assert ok == "True"
    assert int(short) == int(before), out.stdout
    assert int(padded_others) == int(before), out.stdout
    assert int(long) > int(short), out.stdout
