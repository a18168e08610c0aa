# SPDX-License-Identifier: MIT
"""The cable hooked in turn on three points of a tool plate, through Python
(calibrate(target=..., cable_points=...)): lengths written here from the
pure-Python DH of test_kinematics (not rcal's kinematics) on the demo's true
robot, its plate 0.02 mm (sd) off the drawing, 0.01 mm noise.

  - arrays and the same rows as a file with a target column give one result,
    and the CLI's (`--cable-point`) to the printed digit;
  - the tool point (50, 0, 150) of the calibrated model lands within 0.1 mm
    RMS of the true robot's over 200 new poses (after the best rigid motion:
    no sensor sees the cell frame), where the nominal model is over 0.5 mm;
  - a target column without cable_points, a label past 15: refused."""
import json
import math
import os
import random

import pytest

import rcal
from test_kinematics import random_poses, reference_fk

TRUTH = "data/sim_irb120_truth.json"
TCP = (50.0, 0.0, 150.0)
PLATE_NOM = [(60.0 * math.cos(2 * math.pi * k / 3), 60.0 * math.sin(2 * math.pi * k / 3), 20.0) for k in range(3)]


def true_point(doc, q, point):
    p, R = reference_fk(doc["dh"], q, [])
    return [p[r] + sum(R[3 * r + c] * point[c] for c in range(3)) for r in range(3)]


@pytest.fixture(scope="module")
def rows():
    from conftest import ROOT
    doc = json.load(open(os.path.join(ROOT, TRUTH)))
    g = random.Random(7)
    plate_true = [[c + g.gauss(0.0, 0.02) for c in p] for p in PLATE_NOM]
    limits = [(0.8 * lo, 0.8 * hi) for lo, hi in doc["joint_limits_deg"]]
    q, L, target = [], [], []
    for pose in random_poses(limits, 120, 3):
        for k in range(3):
            q.append(pose)
            L.append(math.dist(true_point(doc, pose, plate_true[k]), doc["encoder_mm"]) + g.gauss(0.0, 0.01))
            target.append(k)
    return doc, q, L, target


def write_csv(path, q, L, target):
    path.write_text("q1,q2,q3,q4,q5,q6,L,target\n" + "".join(
        ",".join("%.17g" % v for v in qq) + ",%.17g,%d\n" % (ll, t) for qq, ll, t in zip(q, L, target)))


def test_arrays_file_and_cli_agree(rows, tmp_path, run_cli):
    _, q, L, target = rows
    f = tmp_path / "plate.csv"
    write_csv(f, q, L, target)
    a = rcal.calibrate(q_deg=q, L_mm=L, target=target, cable_points=PLATE_NOM)
    b = rcal.calibrate(str(f), cable_points=PLATE_NOM)
    assert a.after == b.after and a.n_train == b.n_train == 324
    args = [x for p in PLATE_NOM for x in ("--cable-point", "%.17g,%.17g,%.17g" % p)]
    cli = json.loads(run_cli("calibrate", "--data", str(f), *args, "--json").stdout)
    assert float("%.6f" % b.after.rmse_mm) == cli["after"]["rmse_mm"]
    assert a.after.rmse_mm < 0.02  # noise 0.01 mm, the lengths' own floor


def test_tool_point_lands(rows, tmp_path):
    np = pytest.importorskip("numpy")
    doc, q, L, target = rows
    r = rcal.calibrate(q_deg=q, L_mm=L, target=target, cable_points=PLATE_NOM)
    path = tmp_path / "plate_model.json"
    r.write(str(path))
    m = rcal.Model.load(str(path))
    poses = random_poses([(0.8 * lo, 0.8 * hi) for lo, hi in doc["joint_limits_deg"]], 200, 99)
    truth = np.array([true_point(doc, p, TCP) for p in poses])

    def tcp_rms(model, nominal):
        pos, rot = model.fk(np.array(poses), nominal=nominal, rotation=True)
        pts = np.array(pos) + np.einsum("nij,j->ni", np.array(rot).reshape(-1, 3, 3), np.array(TCP))
        a, b = pts - pts.mean(0), truth - truth.mean(0)  # best rigid motion (Kabsch)
        u, _, vt = np.linalg.svd(a.T @ b)
        d = np.sign(np.linalg.det(u @ vt))
        R = u @ np.diag([1.0, 1.0, d]) @ vt
        return float(np.sqrt(np.mean(np.sum((a @ R - b) ** 2, axis=1))))

    calibrated, nominal = tcp_rms(m, False), tcp_rms(m, True)
    assert calibrated < 0.1 and nominal > 0.5, (calibrated, nominal)


def test_refused(rows, tmp_path):
    _, q, L, target = rows
    with pytest.raises(rcal.RcalError, match="cable.point|target"):
        rcal.calibrate(q_deg=q, L_mm=L, target=target)
    with pytest.raises(ValueError, match="target"):
        rcal.calibrate(q_deg=q, L_mm=L, target=[16] + target[1:], cable_points=PLATE_NOM)
    with pytest.raises(ValueError, match="cable_point_sd"):
        rcal.calibrate(q_deg=q, L_mm=L, target=target, cable_points=PLATE_NOM, cable_point_sd=-1.0)
    with pytest.raises(ValueError, match="cable_points"):
        rcal.calibrate(q_deg=q, L_mm=L, target=target, cable_points=[(1.0, 2.0)])
