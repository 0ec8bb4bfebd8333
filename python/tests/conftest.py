"""Shared fixtures of the imufit Python tests.

The module under test is the one on sys.path (scripts/test.sh puts <build>/python first). The
`imufit` command they compare with is IMUFIT_BINARY, or the one of the same build tree
(<build>/app/imufit next to <build>/python/imufit).
"""

import os
import pathlib
import subprocess

import pytest

import imufit

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures"


def _binary() -> pathlib.Path:
    if "IMUFIT_BINARY" in os.environ:
        return pathlib.Path(os.environ["IMUFIT_BINARY"])
    return pathlib.Path(imufit.__file__).resolve().parents[2] / "app" / "imufit"


@pytest.fixture(scope="session")
def fixtures() -> pathlib.Path:
    return FIXTURES


@pytest.fixture(scope="session")
def run_imufit():
    """Runs the imufit command; returns the CompletedProcess (text). Fails the test when the
    binary is missing rather than skipping: the comparison is the point."""
    binary = _binary()
    if not binary.is_file():
        pytest.fail(f"the imufit command is not at {binary}; build it or set IMUFIT_BINARY")

    def run(*args, check=True):
        result = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, timeout=600)
        if check and result.returncode != 0:
            raise AssertionError(f"imufit {' '.join(map(str, args))} exited {result.returncode}: {result.stderr}")
        return result

    return run
