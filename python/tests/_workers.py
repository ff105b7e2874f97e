"""Functions the process-pool tests run in worker processes (importable under spawn)."""
import numpy as np

import gyrolab


def deviation(seed):
    """The OADEV of a seeded white-noise record, computed in the worker (long enough, 300,000
    samples, to run on the package's thread pool rather than on the calling thread)."""
    x = np.random.default_rng(seed).standard_normal(300_000) * 0.01
    return gyrolab.allan(x, rate_hz=100.0, confidence=None).dev


def result(seed):
    """A whole result object, to be pickled back to the parent."""
    x = np.random.default_rng(seed).standard_normal(20_000) * 0.01
    return gyrolab.allan(x, rate_hz=100.0)


def failing(_):
    """A call that fails with a located gyrolab.Error in the worker."""
    return gyrolab.allan(np.array([1.0, np.nan, 2.0, 3.0]), rate_hz=1.0)
