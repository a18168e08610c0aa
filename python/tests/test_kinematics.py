# SPDX-License-Identifier: MIT
"""FK and cable length against an independent pure-Python DH implementation
(standard DH, T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), read straight
from the model file's JSON) at random poses, to 1e-9 mm."""
import json
import math
import random

import pytest

import rcal

TOL_MM = 1e-9


def dh_matrix(a, d, alpha, theta):
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return [[ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0]]


def matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def reference_fk(dh_rows, q_deg):
    """dh_rows: the file's rows (a_mm, d_mm, alpha_deg, theta_deg)."""
    T = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    for row, q in zip(dh_rows, q_deg):
        T = matmul(T, dh_matrix(row["a_mm"], row["d_mm"], math.radians(row["alpha_deg"]),
                                math.radians(q + row["theta_deg"])))
    return [T[0][3], T[1][3], T[2][3]], [T[i][j] for i in range(3) for j in range(3)]


def random_poses(limits, n, seed):
    g = random.Random(seed)
    return [[g.uniform(lo, hi) for (lo, hi) in limits] for _ in range(n)]


@pytest.fixture(scope="module")
def calibrated_file(tmp_path_factory, run_cli):
    path = tmp_path_factory.mktemp("kin") / "cal.json"
    run_cli("calibrate", "--data", "data/sim_irb120.csv", "--json", "--out", str(path))
    return path


@pytest.mark.parametrize("which", ["nominal", "truth", "calibrated"])
def test_fk_and_cable_length_against_reference(which, calibrated_file):
    path = {"nominal": "data/irb120.json", "truth": "data/sim_irb120_truth.json",
            "calibrated": str(calibrated_file)}[which]
    doc = json.load(open(path))
    assert "effects" not in doc  # the reference is pure DH
    m = rcal.Model.load(path)
    for mine, theirs in zip(m.joint_limits_deg, doc["joint_limits_deg"]):
        assert abs(mine[0] - theirs[0]) < 1e-9 and abs(mine[1] - theirs[1]) < 1e-9
    poses = random_poses(m.joint_limits_deg, 200, 42)
    pos, rot = m.fk(poses, rotation=True)
    lengths = m.cable_length(poses) if "encoder_mm" in doc else None
    worst = 0.0
    for k, q in enumerate(poses):
        p_ref, R_ref = reference_fk(doc["dh"], q)
        worst = max(worst, max(abs(a - b) for a, b in zip(pos[k], p_ref)))
        assert max(abs(a - b) for a, b in zip(rot[k], R_ref)) < 1e-12
        if lengths is not None:
            assert abs(lengths[k] - math.dist(p_ref, doc["encoder_mm"])) < TOL_MM
    assert worst < TOL_MM
    assert m.fk(poses[0]) == pos[0]  # one pose gives one point
    if which == "calibrated":  # the nominal table it carries
        nom = m.fk(poses, nominal=True)
        for k, q in enumerate(poses):
            p_ref, _ = reference_fk(doc["nominal"]["dh"], q)
            assert max(abs(a - b) for a, b in zip(nom[k], p_ref)) < TOL_MM


def test_zero_pose_is_the_drawing():
    m = rcal.Model.load("data/irb120.json")
    x, y, z = m.fk([0, 0, 0, 0, 0, 0])
    # IRB120 at zero: flange at x = 302 + 72, z = 290 + 270 + 70 (standard DH: a3 = 70 up)
    assert abs(x - 374.0) < 1e-9 and abs(y) < 1e-9 and abs(z - 630.0) < 1e-9


def test_numpy_in_numpy_out():
    np = pytest.importorskip("numpy")
    m = rcal.Model.load("data/irb120.json")
    poses = random_poses(m.joint_limits_deg, 5, 3)
    a = m.fk(np.array(poses))
    assert isinstance(a, np.ndarray) and a.shape == (5, 3)
    assert np.array_equal(a, np.array(m.fk(poses)))
    t = rcal.Model.load("data/sim_irb120_truth.json")
    L = t.cable_length(np.array(poses))
    assert isinstance(L, np.ndarray) and L.shape == (5,)
    assert L.tolist() == t.cable_length(poses)
    assert isinstance(t.cable_length(poses[0]), float)
