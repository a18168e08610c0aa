# SPDX-License-Identifier: MIT
"""Fixtures of the rcal package tests: the repository root (the working
directory of every test), the rcal binary of the same build (RCAL_BIN, else
build/tools/rcal) and a runner for it."""
import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# The package of this tree (python/rcal), whatever the working directory.
sys.path.insert(0, os.path.join(ROOT, "python"))


@pytest.fixture(autouse=True)
def at_root(monkeypatch):
    """Relative paths (data/sim_irb120.csv) mean the same to Python and CLI."""
    monkeypatch.chdir(ROOT)


@pytest.fixture(scope="session")
def rcal_bin():
    path = os.environ.get("RCAL_BIN", os.path.join(ROOT, "build", "tools", "rcal"))
    if not os.access(path, os.X_OK):
        pytest.fail("the rcal binary is not at %s (set RCAL_BIN or build it)" % path)
    return path


@pytest.fixture(scope="session")
def run_cli(rcal_bin):
    """run_cli("calibrate", "--data", ...) -> CompletedProcess (text)."""
    def run(*args, check=True):
        p = subprocess.run([rcal_bin] + list(args), cwd=ROOT, capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError("rcal %s failed (%d): %s" % (" ".join(args), p.returncode, p.stderr))
        return p
    return run
