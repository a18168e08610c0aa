# SPDX-License-Identifier: MIT
"""session_check.py in the test suite (the package of this tree): calibrate,
diagnose and compensate from Python equal to the CLI on the demo data (the
venv test runs the same script with the installed package, there also on
the real IRB120 data when present)."""
import os

import session_check
from conftest import ROOT


def test_session_equals_cli(rcal_bin, tmp_path, capsys):
    cwd = os.getcwd()
    try:
        rc = session_check.main(["session_check.py", rcal_bin, ROOT, str(tmp_path), "--demo-only"])
    finally:
        os.chdir(cwd)
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "every figure equals the CLI's" in out
