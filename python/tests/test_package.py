"""The package is built for CPython's stable ABI (abi3, CPython 3.9 and later): one wheel for
every interpreter version, as pyproject.toml and the pyo3 feature abi3-py39 ask."""
import sys
from pathlib import Path

import pytest

from gyrolab import _gyrolab


def test_native_module_uses_the_stable_abi():
    name = _gyrolab.__file__
    if (Path(name).parent / "STAGED_FROM_TEST_BUILD").exists():
        pytest.skip("the package laid out from the test build (scripts/stage_python_package.py) names "
                    "its native module itself; GYROLAB_TEST_WHEEL=1 bash scripts/test.sh tests the wheel's")
    if sys.platform.startswith("linux") or sys.platform == "darwin":
        assert name.endswith(".abi3.so"), f"the native module is not an abi3 build: {name}"
    else:
        assert name.endswith(".pyd"), name

