# SPDX-License-Identifier: MIT
"""FK and cable length against an independent pure-Python DH implementation
(standard DH, T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), with Hayati's
axis tilt Ry(beta) where the file has an axis_tilt effect and the measured
point at the file's tool_offset, read straight from the model file's JSON)
at random poses, to 1e-9 mm."""
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


def ry_matrix(b):
    cb, sb = math.cos(b), math.sin(b)
    return [[cb, 0.0, sb, 0.0], [0.0, 1.0, 0.0, 0.0], [-sb, 0.0, cb, 0.0], [0.0, 0.0, 0.0, 1.0]]


def reference_fk(dh_rows, q_deg, effects=()):
    """dh_rows: the file's rows (a_mm, d_mm, alpha_deg, theta_deg); effects:
    the file's "effects" (axis_tilt: Ry(beta) after its row, joint 1-based;
    tool_offset: the point in the flange frame)."""
    tilt = {e["joint"] - 1: e["params"][0] for e in effects if e["kind"] == "axis_tilt"}
    tool = next((e["params"] for e in effects if e["kind"] == "tool_offset"), [0.0, 0.0, 0.0])
    T = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    for i, (row, q) in enumerate(zip(dh_rows, q_deg)):
        T = matmul(T, dh_matrix(row["a_mm"], row["d_mm"], math.radians(row["alpha_deg"]),
                                math.radians(q + row["theta_deg"])))
        if i in tilt:
            T = matmul(T, ry_matrix(tilt[i]))
    p = [T[r][3] + sum(T[r][c] * tool[c] for c in range(3)) for r in range(3)]
    return p, [T[i][j] for i in range(3) for j in range(3)]


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
    effects = doc.get("effects", [])
    assert all(e["kind"] in ("axis_tilt", "tool_offset") for e in effects)  # what the reference models
    m = rcal.Model.load(path)
    for mine, theirs in zip(m.joint_limits_deg, doc["joint_limits_deg"]):
        assert abs(mine[0] - theirs[0]) < 1e-9 and abs(mine[1] - theirs[1]) < 1e-9
    poses = random_poses(m.joint_limits_deg, 200, 42)
    pos, rot = m.fk(poses, rotation=True)
    lengths = m.cable_length(poses) if "encoder_mm" in doc else None
    worst = 0.0
    for k, q in enumerate(poses):
        p_ref, R_ref = reference_fk(doc["dh"], q, effects)
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
