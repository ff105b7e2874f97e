"""Shared fixtures: the repository root and the command-line binary (built by scripts/test.sh)."""
import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """The gyrolab binary: $GYROLAB_BIN, else target/debug/gyrolab; the tests that compare with
    it fail (not skip) when it is missing, saying how to build it."""
    path = pathlib.Path(os.environ.get("GYROLAB_BIN", ROOT / "target" / "debug" / "gyrolab"))
    assert path.exists(), f"{path} not found: build it with `cargo build -p gyrolab-cli` or set GYROLAB_BIN"
    return str(path)
