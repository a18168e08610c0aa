# SPDX-License-Identifier: MIT
"""Failures raise rcal.RcalError carrying the C library's message: the same
text the CLI prints after "rcal <command>: "."""
import pytest

import rcal


def cli_message(run_cli, *args):
    p = run_cli(*args, check=False)
    assert p.returncode != 0
    prefix = "rcal %s: " % args[0]
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith(prefix)
    return line[len(prefix):]


def test_missing_model_file(run_cli):
    with pytest.raises(rcal.RcalError) as e:
        rcal.Model.load("no/such/model.json")
    assert "no/such/model.json" in str(e.value)
    assert e.value.kind == "bad input file"
    msg = cli_message(run_cli, "calibrate", "--data", "data/sim_irb120.csv", "--robot", "no/such/model.json")
    assert str(e.value) == msg


def test_missing_data_file(run_cli):
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(data_csv="no/such/data.csv")
    assert str(e.value) == cli_message(run_cli, "calibrate", "--data", "no/such/data.csv")


def test_bad_csv_names_line_and_column(run_cli, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("q1,q2,q3,q4,q5,q6,L\n1,2,3,4,5,6,500\n1,2,abc,4,5,6,500\n")
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(data_csv=str(bad))
    assert str(e.value).startswith("%s:3:5: " % bad)
    assert "'abc'" in str(e.value)
    assert str(e.value) == cli_message(run_cli, "calibrate", "--data", str(bad))


def test_malformed_model_names_line_and_column(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{\n  "format": "rcal-model/1",\n  "dh": 3\n}\n')
    with pytest.raises(rcal.RcalError) as e:
        rcal.Model.load(bad)
    assert str(e.value).startswith("%s:3:" % bad)


def test_too_few_samples():
    q = [[10.0 * k, 5.0, 5.0, 0.0, 30.0, 0.0] for k in range(10)]
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(q_deg=q, L_mm=[500.0] * 10)
    assert "training samples" in str(e.value) and e.value.kind == "calibration failed"


def test_bad_arguments():
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(data_csv="data/sim_irb120.csv", method="newton")
    assert "unknown method 'newton'" in str(e.value) and e.value.status == -1
    with pytest.raises(rcal.RcalError, match="unknown parameter 'zz'"):
        rcal.calibrate(data_csv="data/sim_irb120.csv", fix="a1,zz")
    with pytest.raises(ValueError):
        rcal.calibrate()
    with pytest.raises(ValueError):
        rcal.calibrate(q_deg=[[0.0] * 6], L_mm=[1.0, 2.0])
    with pytest.raises(ValueError):
        rcal.Model.load("data/irb120.json").fk([[1.0, 2.0, 3.0]])


def test_target_outside_joint_limits():
    m = rcal.Model.load("data/sim_irb120_truth.json")
    with pytest.raises(rcal.RcalError, match=r"target 1: q3 = 99 deg is outside the joint limits") as e:
        rcal.compensate(m, [[0, 0, 0, 0, 30, 0], [0, 0, 99, 0, 30, 0]])
    assert e.value.kind == "value out of range"
