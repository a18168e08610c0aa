# SPDX-License-Identifier: MIT
"""Issue 33, item 5: Python gives the CLI's validation and the CLI's
failures. Each test is a gap found by comparing what `rcal` refuses
(tests/system/robust/*) with what the package accepted: shapes, dtypes and
non-finite values; labels; tracker positions through the same plausibility
checks and screening as `rcal calibrate --positions` (the same messages);
failed compensation targets flagged per target."""
import json
import math
import os
import random
import warnings

import pytest

import rcal

np = pytest.importorskip("numpy")

POSE = [10, 20, 30, 0, 40, 0]
MODEL = None


def model_file(tmp_path):
    p = tmp_path / "cal.json"
    rcal.calibrate("data/sim_irb120.csv").write(p)
    return p


def positions_rows(n=60, seed=7):
    """Flange points of the shipped truth at random poses, seen by a tracker
    turned 90 deg about z and 1.5 m away (as scripts/golden_check.sh)."""
    truth = rcal.Model.load("data/sim_irb120_truth.json")
    g = random.Random(seed)
    lim = truth.joint_limits_deg
    rows = []
    for _ in range(n):
        q = [round(0.5 * (lo + hi) + 0.4 * (hi - lo) * (2 * g.random() - 1), 3) for lo, hi in lim]
        q[1] = round(0.3 * q[1] + 10, 3)
        x, y, z = truth.fk(q)
        rows.append((q, (1500 - y, x + 300, z - 200)))
    return rows


def write_positions(path, rows, swap=False, scale=1.0, off=None):
    with open(path, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6,x,y,z\n")
        for k, (q, p) in enumerate(rows):
            p = [v * scale for v in p]
            if swap:
                p = [p[1], p[0], p[2]]
            if off and k == off[0]:
                p = [p[0] + off[1], p[1], p[2]]
            f.write(",".join("%.4f" % v for v in list(q) + list(p)) + "\n")
    return path


# ---- shapes, dtypes, non-finite values -------------------------------------

def test_flat_array_of_12_numbers_is_not_one_pose():
    m = rcal.Model.load(rcal.default_robot())
    with pytest.raises(ValueError, match=r"q_deg: expected shape \(6,\) or \(n, 6\), got shape \(12,\)"):
        m.fk(np.zeros(12))
    with pytest.raises(ValueError, match="q_deg: expected shape"):
        m.fk([0.0] * 12)
    with pytest.raises(ValueError, match=r"expected shape \(6,\) or \(n, 6\), got shape \(2, 3, 6\)"):
        m.fk(np.zeros((2, 3, 6)))
    with pytest.raises(ValueError, match=r"got shape \(4, 5\)"):
        m.cable_length(np.zeros((4, 5)))


def test_dtypes_and_non_finite_values_refused():
    m = rcal.Model.load(rcal.default_robot())
    with pytest.raises(ValueError, match="q_deg: expected real numbers .* dtype <U"):
        m.fk(np.array(["1", "2", "3", "4", "5", "6"]))
    with pytest.raises(ValueError, match="q_deg: expected real numbers .* complex128"):
        m.fk(np.zeros(6, dtype=complex))
    with pytest.raises(ValueError, match="q_deg: nan at row 0, column 2 is not finite"):
        m.fk([0, 0, float("nan"), 0, 0, 0])
    with pytest.raises(ValueError, match="q_deg: inf at row 1, column 0 is not finite"):
        m.fk(np.array([POSE, [math.inf, 0, 0, 0, 0, 0]]))
    with pytest.raises(ValueError, match="row 0 has 6 values"):
        m.fk([[0, 0, "x", 0, 0, 0]])
    with pytest.raises(ValueError, match="q_deg: expected numbers .* got a string"):
        m.fk("102030")
    with pytest.raises(ValueError, match=r"L_mm: sample 1 is 'a', expected a number"):
        rcal.calibrate(q_deg=[POSE, POSE], L_mm=[1000.0, "a"])
    with pytest.raises(ValueError, match=r"L_mm: expected shape \(n,\), got shape \(2, 2\)"):
        rcal.calibrate(q_deg=np.zeros((4, 6)), L_mm=np.zeros((2, 2)))
    with pytest.raises(ValueError, match="L_mm: nan at sample 0 is not finite"):
        rcal.calibrate(q_deg=[POSE], L_mm=[float("nan")])


def test_labels_as_the_csv_reader_checks_them():
    q = np.array([POSE] * 3, dtype=float)
    L = np.array([900.0, 900.0, 900.0])
    with pytest.raises(ValueError, match=r"outlet: sample 1: 1.5 is not an integer in 0..255"):
        rcal.calibrate(q_deg=q, L_mm=L, outlet=[0, 1.5, 0])
    with pytest.raises(ValueError, match=r"outlet: sample 2: 300 is not an integer in 0..255"):
        rcal.calibrate(q_deg=q, L_mm=L, outlet=[0, 0, 300])
    with pytest.raises(ValueError, match=r"group: sample 0: -1 is not an integer in 0..65535"):
        rcal.calibrate(q_deg=q, L_mm=L, group=[-1, 0, 0])
    with pytest.raises(ValueError, match=r"group: 2 values for 3 samples, expected shape \(3,\)"):
        rcal.calibrate(q_deg=q, L_mm=L, group=[0, 0])
    with pytest.raises(ValueError, match=r"outlet: sample 0: True is not an integer label"):
        rcal.calibrate(q_deg=q, L_mm=L, outlet=[True, 0, 0])


def test_array_errors_name_the_sample_not_a_temporary_file():
    d = np.loadtxt("data/sim_irb120.csv", delimiter=",", skiprows=1)
    q, L = d[:, 3:9].copy(), d[:, 9].copy()
    q[5, 1] = 170.0  # beyond q2's limit: the CLI's check, file:line:col
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(q_deg=q, L_mm=L)
    assert "arrays, sample 5 (0-based)" in str(e.value) and "rcal-ffi-" not in str(e.value)


def test_files_and_arrays_not_mixed():
    with pytest.raises(ValueError, match="either files"):
        rcal.calibrate("data/sim_irb120.csv", q_deg=[POSE], L_mm=[1.0])
    with pytest.raises(ValueError, match="go with q_deg"):
        rcal.calibrate("data/sim_irb120.csv", L_mm=[1.0])


# ---- tracker positions: the CLI's checks, screening, messages ----------------

def test_positions_equal_the_cli(run_cli, tmp_path):
    p = write_positions(tmp_path / "pos.csv", positions_rows())
    r = rcal.calibrate(positions=p)
    import json
    cli = json.loads(run_cli("calibrate", "--positions", str(p), "--json").stdout)
    mine = r.json()
    assert mine["after"] == cli["after"] and mine["before"] == cli["before"]
    assert r.screened == []


@pytest.mark.parametrize("how", ["mirror", "cm", "inches"])
def test_positions_refused_with_the_cli_message(run_cli, tmp_path, how):
    kw = {"mirror": {"swap": True}, "cm": {"scale": 0.1}, "inches": {"scale": 1 / 25.4}}[how]
    p = write_positions(tmp_path / "pos.csv", positions_rows(), **kw)
    cli = run_cli("calibrate", "--positions", str(p), check=False)
    assert cli.returncode != 0
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(positions=p)
    assert str(e.value) in cli.stderr, (str(e.value), cli.stderr)


def test_one_row_far_off_is_screened_and_named(run_cli, tmp_path):
    p = write_positions(tmp_path / "pos.csv", positions_rows(), off=(17, 1000.0))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        r = rcal.calibrate(positions=p)
    assert [(s["line"], s["sensor"]) for s in r.screened] == [(19, "tracker")]
    assert any(issubclass(x.category, rcal.RcalWarning) and "pos.csv:19" in str(x.message) for x in w)
    cli = run_cli("calibrate", "--positions", str(p))
    assert "pos.csv:19" in cli.stderr
    kept = rcal.calibrate(positions=p, screen=False)
    assert kept.screened == [] and kept.train_after.rmse_mm > 10 * r.train_after.rmse_mm


def test_positions_and_data_together_each_once(tmp_path):
    p = write_positions(tmp_path / "pos.csv", positions_rows())
    r = rcal.calibrate("data/sim_irb120.csv", positions=p)
    assert r.n_data > 500
    with pytest.raises(rcal.RcalError, match="given twice"):
        rcal.calibrate(positions=[p, p])


# ---- compensation: a failed target is flagged --------------------------------

def test_failed_target_is_flagged(tmp_path):
    m = model_file(tmp_path)
    targets = [POSE, [0, 0, 0, 0, 0, 0]]
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        out, st = rcal.compensate(m, targets, max_uncertainty_mm=1e-6, return_status=True)
    assert st == [3, 3]
    assert sum("left uncompensated" in str(x.message) for x in w) == 2
    with pytest.raises(rcal.RcalError, match="target 0: left uncompensated"):
        rcal.compensate(m, targets, max_uncertainty_mm=1e-6, on_fail="raise")
    with pytest.raises(rcal.RcalError, match="target 0: the model's 95 % position uncertainty .* refuse"):
        rcal.compensate(m, targets, max_uncertainty_mm=1e-6, u95_policy="refuse")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        out, st = rcal.compensate(m, targets, max_uncertainty_mm=1e-6, u95_policy="warn", return_status=True)
    assert st == [0, 0] or all(s in (0, 1) for s in st)
    assert sum("compensated, but" in str(x.message) for x in w) == 2
    with pytest.raises(ValueError, match="u95_policy"):
        rcal.compensate(m, targets, u95_policy="maybe")
    with pytest.raises(ValueError, match="max_dev_deg must be a finite number"):
        rcal.compensate(m, targets, max_dev_deg=float("nan"))
    with pytest.raises(ValueError, match=r"tool_mm: expected shape \(3,\)"):
        rcal.compensate(m, targets, tool_mm=(0, 0))
    with pytest.raises(ValueError, match="targets_deg: nan at row 1"):
        rcal.compensate(m, [POSE, [float("nan")] * 6])


REAL_FILE = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "robotcali.csv")


@pytest.mark.skipif(not os.path.exists(REAL_FILE), reason="the real data ../shared/data/robotcali.csv is absent")
def test_default_run_as_the_cli_dequantize_and_prior_scale(run_cli):
    """The default dequantizes a file whose joints are rounded (as `rcal calibrate` does), False keeps
    them as read, True forces it; the prior's scale is estimated unless prior_stated."""
    auto = rcal.calibrate(REAL_FILE)
    off = rcal.calibrate(REAL_FILE, dequantize=False)
    assert auto.figure("dequant_corrected") == 1039
    assert off.figure("dequant_corrected") is None
    assert auto.after.rmse_mm < 0.12 < off.after.rmse_mm
    cli = json.loads(run_cli("calibrate", "--data", REAL_FILE, "--json").stdout)
    assert abs(cli["after"]["rmse_mm"] - auto.after.rmse_mm) < 1e-6
    assert "prior_scale" in auto.json()["estimation"]
    assert "prior_scale" not in rcal.calibrate(REAL_FILE, prior_stated=True).json()["estimation"]
    with pytest.raises(ValueError):
        rcal.calibrate(REAL_FILE, dequantize="yes")
