# SPDX-License-Identifier: MIT
"""librcal_ffi.so computes with the reference LAPACK and BLAS the build
pinned (cmake/rcal_lapack.cmake), linked into the library: rcal.lapack()
says so, in this process and in one whose LD_LIBRARY_PATH puts another
liblapack.so.3/libblas.so.3 first (tests/system/pkg/fake_lapack.c: ILAVER 0.0.0;
the library computes only with what is linked in, so the same figures
follow). The CLI's --version line is the same."""
import os
import subprocess
import sys

import pytest

import rcal

PINNED = os.environ.get("RCAL_LAPACK_PINNED") == "1"
VERSION = os.environ.get("RCAL_LAPACK_VERSION", "")
OTHER = os.environ.get("RCAL_OTHER_LAPACK_DIR", "")

pytestmark = pytest.mark.skipif(not PINNED or not VERSION, reason="not a pinned build under ctest")

SNIPPET = """
import rcal
la = rcal.lapack()
print(la.version, int(la.linked_in))
print(la.line)
"""


def test_the_library_runs_the_pinned_lapack(run_cli):
    la = rcal.lapack()
    assert la.linked_in
    assert la.version == VERSION
    assert la.line.startswith("reference LAPACK %s and BLAS, linked in (pinned: " % VERSION)
    cli = [ln for ln in run_cli("--version").stdout.splitlines() if ln.startswith("BLAS/LAPACK: ")]
    assert cli == ["BLAS/LAPACK: " + la.line]


def test_another_lapack_on_the_path_changes_nothing():
    if not os.path.isfile(os.path.join(OTHER, "liblapack.so.3")):
        pytest.fail("the fake LAPACK is not built: %s" % OTHER)
    env = dict(os.environ, LD_LIBRARY_PATH=OTHER)
    p = subprocess.run([sys.executable, "-c", SNIPPET], env=env, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    la = rcal.lapack()
    assert p.stdout.splitlines() == ["%s 1" % VERSION, la.line]
