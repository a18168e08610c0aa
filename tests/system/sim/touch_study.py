# SPDX-License-Identifier: MIT
"""touch_study - rcal calibrated from points touched on flat plates, judged on the true robot.

A generator written apart from rcal (truth_study.py's own numpy kinematics, its true robots and its judge)
draws per case a true robot, a true touch probe on the tool (100-200 mm along the flange z, +-30 mm across)
and 3-4 true plates in front of the robot (a horizontal table, a vertical plate facing the robot, one
inclined 20-60 deg, a vertical plate to the side; or, with --one-plate, ONE plate at 3-4 placements). For
every touch it solves, with its own 6-D Newton inverse kinematics on the TRUE robot, the joints at which
the TRUE probe point lies on the plate at a random point of its extent, the probe's axis (the flange z)
within 40 deg of the plate's inward normal and turned at random about it (joints within limits, wrist not
singular), moved along the normal by a trigger noise (Gaussian, sd drawn 0.003-0.02 mm per case, about 2 %
of the rows heavy-tailed; never told to rcal), the joints rounded to 0.001 deg as a controller displays
them. The touch file (`pose,plane,q1..q6`) is calibrated with `rcal calibrate --data` (nothing about the
probe or the plates told), 500 targets are compensated (`rcal compensate --position-only`, at the probe's
tip with the model's fitted probe as `--tool`, and at the flange) and driven on the TRUE robot, and judged as
truth_study.py judges: the median of the pairwise distance errors, compensated against uncompensated (a
rigid motion of the whole cell is invisible to planes and to that figure); also after the landed points'
best-fit scale (touches measure no length: the robot's scale is the prior's; docs/touches.md).

    python3 touch_study.py RCAL [--seed S] [--cases N] [--robot irb120|irb1600] [--one-plate]
                           [--planes N] [--check] [--dir D] [--self-check] [--reference]
                           [--at probe|flange] [--judge pairs|scale-free] [--ratio R] [--gauge MM]
                           [--compare-plan N]

--planes 1: one plate, one placement (directions of the robot left unseen): rcal must exit 0 or refuse
naming what the data cannot determine. --self-check: the generator against its own kinematics (every
written row's true point on its plate to the trigger noise and the display rounding; the noise-free rows
reproduce; the same seed writes the same file); rcal is not run. --reference: the same data fitted and
compensated by this script's own least squares (DH rows, probe, planes, with a prior of rcal's size),
judged the same way: what the data allow, apart from rcal. --compare-plan N: per case N touches drawn as above
(spread evenly over the plates) against N planned by `rcal poses --plate ...` on the NOMINAL robot from the
cell's approximate placements (the true plates' centres off by up to 3 mm, normals by up to 2 deg, the probe
by 2 mm); each planned row touched on the TRUE robot at the point nearest the planned one along the true
plate's normal (this script's Newton, the flange's orientation kept; a row off the true face is not touched):
the generator decides what the true robot touches. Exit 77 without numpy.
"""
import argparse
import json
import os
import re
import sys
import tempfile

try:
    import numpy as np
except ImportError:
    print("SKIP: python3 with numpy not found (Debian package python3-numpy)")
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth_study as ts  # noqa: E402  (its kinematics, robots, draws and judge)

DEG = np.pi / 180.0
STEP_DEG = 0.001  # the controller's display step of the joints
CONE_DEG = 40.0  # the probe's axis within this angle of the plate's inward normal
EXTENT = {"irb120": 150.0, "irb1600": 300.0}  # a plate's side (mm)


# --- kinematics (truth_study's Robot, batched, and its joint Jacobian) -----------------------------------

def rz_batch(t):
    c, s = np.cos(t), np.sin(t)
    R = np.zeros((len(t), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
    return R


def fk_batch(rob, Q):
    """The flange frames (R n x 3 x 3, p n x 3) of truth_study's Robot at the joints Q (n x 6, rad)."""
    n = len(Q)
    R = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    p = np.zeros((n, 3))
    for i, (a, d, al, off) in enumerate(rob.rows):
        Rz = rz_batch(Q[:, i] + off)
        p = p + np.einsum("nij,nj->ni", R, Rz @ np.array([a, 0.0, 0.0]) + np.array([0.0, 0.0, d]))
        R = R @ Rz @ (ts.rot("x", al) @ ts.rot("y", rob.beta[i]))
    return R, p


def tip_jacobian(rob, q, tip):
    """The tool point p + R tip, the flange rotation R and the 6 x 6 geometric Jacobian (rows: the point's
    velocity, the angular velocity) of truth_study's Robot at q: joint i turns about the z axis of the frame
    before its Rot_z, through that frame's origin."""
    R = np.eye(3)
    p = np.zeros(3)
    z, o = [], []
    for i, (a, d, al, off) in enumerate(rob.rows):
        z.append(R[:, 2].copy())
        o.append(p.copy())
        Rz = ts.rot("z", q[i] + off)
        p = p + R @ (Rz @ np.array([a, 0.0, 0.0]) + np.array([0.0, 0.0, d]))
        R = R @ Rz @ ts.rot("x", al) @ ts.rot("y", rob.beta[i])
    x = p + R @ tip
    J = np.zeros((6, 6))
    for i in range(6):
        J[:3, i] = np.cross(z[i], x - o[i])
        J[3:, i] = z[i]
    return x, R, J


def rotvec_of(R):
    """The rotation vector of R (angle < pi)."""
    c = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    th = np.arccos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if th < 1e-9:
        return 0.5 * w
    return w * th / (2.0 * np.sin(th))


def wrap(q):
    return (q + np.pi) % (2.0 * np.pi) - np.pi


def ik_pose(rob, q0, tip, x_goal, R_goal, iters=60):
    """Newton (damped near singularities) from q0 to the tool point x_goal with the flange rotation R_goal;
    None when it does not converge to 1e-9 mm and 1e-11 rad."""
    q = q0.copy()
    for _ in range(iters):
        x, R, J = tip_jacobian(rob, q, tip)
        e = np.concatenate([x_goal - x, rotvec_of(R_goal @ R.T)])
        if np.linalg.norm(e[:3]) < 1e-9 and np.linalg.norm(e[3:]) < 1e-11:
            return q
        lam = 1e-6
        dq = np.linalg.solve(J.T @ J + lam * np.eye(6), J.T @ e)
        n = np.linalg.norm(dq)
        if n > 0.3:
            dq *= 0.3 / n
        q = q + dq
    return None


def within(q, lim):
    qq = q.copy()
    qq[:5] = wrap(qq[:5])
    lo = np.array([l for l, _ in lim]) * DEG
    hi = np.array([h for _, h in lim]) * DEG
    if np.any(qq < lo + 1e-3) or np.any(qq > hi - 1e-3):
        return None
    if abs(np.sin(qq[4])) < 0.15:  # the wrist singularity (q5 near 0)
        return None
    return qq


# --- the cell: probe, plates, touches -------------------------------------------------------------------

def frame_of_normal(n):
    """Two unit vectors u, v spanning the plane of normal n."""
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, a)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def tilt(n_az_deg, tilt_deg):
    """The normal of a plate tilted tilt_deg from horizontal, facing the robot: +z turned towards the
    direction of azimuth n_az_deg (where the plate faces)."""
    t, a = tilt_deg * DEG, n_az_deg * DEG
    return np.array([np.sin(t) * np.cos(a), np.sin(t) * np.sin(a), np.cos(t)])


def draw_plates(rng, name, n_planes, one_plate):
    """Plates in the base frame (x ahead of the robot), each a dict: centre c, unit normal n pointing out of
    the surface the probe touches, in-plane axes u, v, side (mm), kind. Scaled by the arm's reach."""
    s = ts.ROBOTS[name]["reach"] / 580.0
    side0 = EXTENT[name]
    U = rng.uniform
    kinds = ["table", "front", "incline", "side"]
    if one_plate:
        kinds = ["table", "incline", "front", "incline"]
    if n_planes == 1:
        kinds = ["table"]
    plates = []
    side_y = rng.choice([-1.0, 1.0])
    for j in range(n_planes):
        kind = kinds[j % len(kinds)]
        az = U(-25, 25)  # where the robot is, seen from the plate (degrees of heading about the base z)
        if kind == "table":  # horizontal, below the shoulder, in front
            c = np.array([U(330, 420), U(-120, 120), U(0, 120)]) * s
            n = np.array([0.0, 0.0, 1.0])
        elif kind == "front":  # vertical, facing the robot
            r = U(430, 500) * s
            c = np.array([r * np.cos(az * DEG), r * np.sin(az * DEG), U(300, 450) * s])
            n = tilt(180.0 + az, 90.0)
        elif kind == "incline":  # 20-60 deg from horizontal, facing the robot
            t = U(20, 60)
            r = U(350, 430) * s
            c = np.array([r * np.cos(az * DEG), r * np.sin(az * DEG), U(120, 300) * s])
            n = tilt(180.0 + az + U(-40, 40), t)
        else:  # vertical, to one side, facing the robot
            c = np.array([U(150, 300) * s, side_y * U(380, 450) * s, U(200, 400) * s])
            n = tilt(np.degrees(np.arctan2(-c[1], -c[0])) + U(-20, 20), 90.0)
        n = n / np.linalg.norm(n)
        u, v = frame_of_normal(n)
        side = side0 if one_plate else side0 * U(0.8, 1.2)
        plates.append({"c": c, "n": n, "u": u, "v": v, "side": side, "kind": kind, "d": float(n @ c)})
    return plates


def draw_probe(rng):
    return np.array([rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(100, 200)])


def cone_axis(rng, n):
    """A probe axis pointing into the plate (-n) turned by up to CONE_DEG, uniform on the cap."""
    ct = rng.uniform(np.cos(CONE_DEG * DEG), 1.0)
    st = np.sqrt(1.0 - ct * ct)
    ph = rng.uniform(0, 2 * np.pi)
    u, v = frame_of_normal(n)
    return -ct * n + st * (np.cos(ph) * u + np.sin(ph) * v)


def frame_with_z(rng, a):
    """A flange rotation whose z axis is a, turned at random about it."""
    x0, y0 = frame_of_normal(a)
    ps = rng.uniform(0, 2 * np.pi)
    x = np.cos(ps) * x0 + np.sin(ps) * y0
    return np.column_stack([x, np.cross(a, x), a])


class Bank:
    """Random joint poses of the true robot with their probe points and axes: the starts of the Newton."""

    def __init__(self, rng, rob, lim, tip, n=40000):
        Q = ts.draw_q(rng, lim, n)
        Q = Q[np.abs(np.sin(Q[:, 4])) >= 0.15]
        R, p = fk_batch(rob, Q)
        self.Q, self.R = Q, R
        self.x = p + np.einsum("nij,j->ni", R, tip)

    def starts(self, x, R, k=6):
        # the closest in position (per 100 mm) and orientation (per rad, the angle of R_bank^T R)
        c = np.clip((np.einsum("nij,ij->n", self.R, R) - 1.0) / 2.0, -1.0, 1.0)
        cost = np.linalg.norm(self.x - x, axis=1) / 100.0 + np.arccos(c)
        return self.Q[np.argsort(cost)[:k]]


def touches(rng, rob, lim, tip, plates, n_per, noise_sd, bank):
    """Per plate n_per touches: the unrounded joints (rad), the plane index and the trigger noise along the
    normal (mm; positive: the probe point outside the surface, on the side of n)."""
    rows = []
    for j, pl in enumerate(plates):
        got, tries = 0, 0
        while got < n_per:
            tries += 1
            if tries > 40 * n_per:
                raise RuntimeError("plate %d (%s at %s, normal %s) out of reach: %d of %d touches" % (
                    j, pl["kind"], np.round(pl["c"]).tolist(), np.round(pl["n"], 3).tolist(), got, n_per))
            h = pl["side"] / 2.0
            pt = pl["c"] + rng.uniform(-h, h) * pl["u"] + rng.uniform(-h, h) * pl["v"]
            Rg = frame_with_z(rng, cone_axis(rng, pl["n"]))
            eps = rng.normal(0.0, noise_sd)
            if rng.random() < 0.02:  # a heavy-tailed trigger (dust, a slow approach)
                eps = float(np.clip(ts.heavy(rng, 8.0 * noise_sd), -0.25, 0.25))
            for q0 in bank.starts(pt, Rg, 3):
                q = ik_pose(rob, q0, tip, pt + eps * pl["n"], Rg)
                if q is None:
                    continue
                q = within(q, lim)
                if q is None:
                    continue
                rows.append((q, j, eps))
                got += 1
                break
    return rows


def write_touches(path, rows, plates=None):
    """The touch file: pose, plane, q1..q6 (deg, as displayed: 0.001 deg), no sigma. With a gauge plate among
    plates (--gauge): a height_mm column, the gauge's rows written as touches of the plate it stands on at its
    height (what docs/touches.md asks of a gauge block); the rows of the other plates at height 0."""
    gauged = plates is not None and any(pl["kind"] == "gauge" for pl in plates)
    with open(path, "w") as f:
        f.write("pose,plane,q1,q2,q3,q4,q5,q6" + (",height_mm" if gauged else "") + "\n")
        for i, (q, j, _) in enumerate(rows):
            label, h = j, 0.0
            if gauged and plates[j]["kind"] == "gauge":
                label, h = plates[j]["of"], plates[j]["height"]
            f.write("%d,%d,%s%s\n" % (i, label, ",".join("%.3f" % v for v in np.round(q / DEG, 3)),
                                       (",%.3f" % h) if gauged else ""))


def read_touches(path):
    d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return d[:, 1].astype(int), d[:, 2:8] * DEG


def gauge_plate(pl0, rng, height):
    """A 60 mm square face parallel to plate 0, height mm above it along its normal (gauge blocks under a
    small plate, or a block's face): a length the planes can be told."""
    c = pl0["c"] + height * pl0["n"] + rng.uniform(-0.2, 0.2) * pl0["side"] * pl0["u"]
    return {"c": c, "n": pl0["n"], "u": pl0["u"], "v": pl0["v"], "side": 60.0, "kind": "gauge",
            "d": float(pl0["n"] @ c), "of": 0, "height": height}


def make_case(seed, k, name, n_planes, one_plate, n_per=None, noise_free=False, gauge=0.0, n_total=0):
    """One case's truth and rows, from its own generator [seed, k] (the same for every run); gauge > 0: one more
    plane, parallel to plane 0 at that height (mm) above it."""
    rng = np.random.default_rng([seed, k])
    lim = ts.ROBOTS[name]["lim"]
    truth = ts.true_robot(rng, name)
    tip = draw_probe(rng)
    if n_planes <= 0:
        n_planes = int(rng.integers(3, 5))
    plates = draw_plates(rng, name, n_planes, one_plate)
    if gauge > 0:
        plates.append(gauge_plate(plates[0], np.random.default_rng([seed, k, 3]), gauge))
    noise_sd = rng.uniform(0.003, 0.02)
    if n_per is None:
        n_per = int(rng.integers(60, 121))
    if n_total > 0:  # --compare-plan: this many touches in all, spread evenly over the plates (the gauge's face one)
        n_per = max(3, n_total // len(plates))
    bank = Bank(np.random.default_rng([seed, k, 1]), truth, lim, tip)
    rows = touches(np.random.default_rng([seed, k, 2]), truth, lim, tip, plates, n_per,
                   0.0 if noise_free else noise_sd, bank)
    return {"truth": truth, "tip": tip, "plates": plates, "noise_sd": noise_sd, "rows": rows, "rng": rng,
            "name": name}


# --- the self-check: the generator against its own kinematics -------------------------------------------

def rounding_bound(rob, q, tip, n):
    """The largest move along n the display rounding (+-STEP_DEG/2 per joint) can make, to first order."""
    _, _, J = tip_jacobian(rob, q, tip)
    return float(np.sum(np.abs(n @ J[:3]))) * 0.5 * STEP_DEG * DEG


def self_check(a):
    from rct_check import check, failures, passes
    names = [a.robot] if a.robot else ["irb120", "irb1600"]
    tmp = a.dir or tempfile.mkdtemp(prefix="rcal_touch_self_")
    os.makedirs(tmp, exist_ok=True)
    worst_raw, worst_round, worst_ratio, worst_free, worst_cone = 0.0, 0.0, 0.0, 0.0, 0.0
    for k in range(a.cases):
        name = names[k % len(names)]
        case = make_case(a.seed, k, name, a.planes, a.one_plate, gauge=a.gauge)
        free = make_case(a.seed, k, name, a.planes, a.one_plate, noise_free=True, gauge=a.gauge)
        rob, tip = case["truth"], case["tip"]
        paths = [os.path.join(tmp, "self%d_%s.csv" % (k, s)) for s in ("a", "b", "free")]
        write_touches(paths[0], case["rows"])
        write_touches(paths[1], make_case(a.seed, k, name, a.planes, a.one_plate, gauge=a.gauge)["rows"])
        write_touches(paths[2], free["rows"])
        check(open(paths[0]).read() == open(paths[1]).read(), "case %d: the same seed writes the same file" % k)
        lim = ts.ROBOTS[name]["lim"]
        for which, c, path in (("noisy", case, paths[0]), ("noise-free", free, paths[2])):
            planes, Qr = read_touches(path)
            bad = 0
            for (q, j, eps), jr, qr in zip(c["rows"], planes, Qr):
                pl = c["plates"][j]
                R, p = rob.frames(q)
                x = p + R @ tip
                raw = abs(pl["n"] @ x - pl["d"] - eps)  # the unrounded joints: exactly the noise off
                Rr, pr = rob.frames(qr)
                dist = pl["n"] @ (pr + Rr @ tip) - pl["d"]
                bound = rounding_bound(rob, q, tip, pl["n"])
                off = abs(dist - eps)
                inplane = np.abs(np.array([pl["u"] @ (x - pl["c"]), pl["v"] @ (x - pl["c"])]))
                cone = np.degrees(np.arccos(np.clip(-(R[:, 2] @ pl["n"]), -1, 1)))
                lo = np.array([l for l, _ in lim]) * DEG
                hi = np.array([h for _, h in lim]) * DEG
                ok = (jr == j and raw < 1e-6 and off <= bound + 1e-6 and np.all(inplane <= pl["side"] / 2 + 1e-6)
                      and cone <= CONE_DEG + 1e-6 and np.all(qr >= lo) and np.all(qr <= hi)
                      and abs(np.sin(qr[4])) >= 0.149)
                bad += not ok
                worst_raw = max(worst_raw, raw)
                worst_cone = max(worst_cone, cone)
                if which == "noisy":
                    worst_round = max(worst_round, abs(dist))
                    worst_ratio = max(worst_ratio, off / max(bound, 1e-12))
                else:
                    worst_free = max(worst_free, abs(dist))
            check(bad == 0, "case %d %s (%s, %d planes, %d rows): every row's true point on its plate to the "
                  "trigger noise and the display rounding, inside its extent and the %g deg cone, joints within "
                  "limits, wrist not singular (%d rows not)" % (k, name, which, len(c["plates"]), len(c["rows"]),
                                                                CONE_DEG, bad))
    # the judge's reading of the fitted probe from a model (an effect naming a probe; nothing: an error, not 0)
    fake = os.path.join(tmp, "model_probe.json")
    for doc, want in (({"effects": [{"kind": "tracker_targets", "params": [9, 9, 9]},
                                    {"kind": "touch_probe", "params": [1.5, -2.0, 150.25]}]}, [1.5, -2.0, 150.25]),
                      ({"effects": [{"kind": "length_offset", "params": [0.1]}]}, None)):
        with open(fake, "w") as f:
            json.dump(doc, f)
        got, _ = model_probe(fake)
        check((got is None and want is None) or (got is not None and want is not None and np.allclose(got, want)),
              "the fitted probe read from a model: %s (wanted %s)" % (None if got is None else got.tolist(), want))
    print("largest distance of a written row's true point from its plate: %.4f mm (noisy rows; the noise "
          "itself included), %.4f mm (noise-free rows: the display rounding alone); unrounded joints: %.2e mm "
          "off the drawn noise; rounding's share of its first-order bound at most %.2f; probe axis at most "
          "%.1f deg off the inward normal" % (worst_round, worst_free, worst_raw, worst_ratio, worst_cone))
    print("%d passed, %d failed" % (len(passes), len(failures)))
    return 1 if failures else 0


# --- the judge (truth_study's) ----------------------------------------------------------------------------

def judge_targets(rng, name, tcp):
    """truth_study.one_case's 500 targets over the workspace."""
    lim = ts.ROBOTS[name]["lim"]
    nom = ts.nominal_robot(name)
    T = []
    while len(T) < 500:
        q = ts.draw_q(rng, lim, 1)[0]
        if abs(np.sin(q[4])) < 0.15:
            continue
        if nom.point(q, tcp)[2] < 50:
            continue
        T.append(q)
    return np.array(T)


def scale_free_pairs(landed, meant, rng):
    """The pairwise errors after the best-fit scale of the landed points (what planes alone can see)."""
    i = rng.integers(0, len(meant), 20000)
    j = rng.integers(0, len(meant), 20000)
    keep = i != j
    dl = np.linalg.norm(landed[i[keep]] - landed[j[keep]], axis=1)
    dm = np.linalg.norm(meant[i[keep]] - meant[j[keep]], axis=1)
    s = (dl @ dm) / (dl @ dl)
    return np.abs(s * dl - dm), s


def judge(k, case, T, C, tool, tool_true):
    """truth_study's figures of the compensated joints C of the targets T: the program meant the nominal robot's
    point `tool` (flange frame, as the model knows the tool); the TRUE robot carries it at tool_true. The
    uncompensated figure is the robot's own: the targets meant with the true tool (not with the fitted one)."""
    name, truth = case["name"], case["truth"]
    nom = ts.nominal_robot(name)
    meant = np.array([nom.point(q, tool) for q in T])
    meant_u = np.array([nom.point(q, tool_true) for q in T])
    landed = np.array([truth.point(q, tool_true) for q in C])
    uncomp = np.array([truth.point(q, tool_true) for q in T])
    pe_c = ts.pair_err(landed, meant, np.random.default_rng(k))
    pe_u = ts.pair_err(uncomp, meant_u, np.random.default_rng(k))
    ts.ALIGN = "rigid"
    e_c = np.linalg.norm(ts.align(landed, meant) - meant, axis=1)
    e_u = np.linalg.norm(ts.align(uncomp, meant_u) - meant_u, axis=1)
    sf, s = scale_free_pairs(landed, meant, np.random.default_rng(k))
    return {"pair_med_comp": float(np.median(pe_c)), "pair_med_uncomp": float(np.median(pe_u)),
            "pair_p95_comp": float(np.percentile(pe_c, 95)), "err_med_comp": float(np.median(e_c)),
            "err_med_uncomp": float(np.median(e_u)), "worse_share": float(np.mean(e_c > e_u)),
            "pair_med_scale_free": float(np.median(sf)), "scale_ppm": float((1.0 / s - 1.0) * 1e6)}


# --- an independent reference fit (--reference) -----------------------------------------------------------

PRIOR = (0.5, 0.5, 0.1 * DEG, 1.0 * DEG)  # a, d (mm), alpha, theta (rad): rcal's prior sd


def ref_fit(name, planes_idx, Q, n_planes, ties=None):
    """DH rows (theta1, d1 held: the base is not seen), the probe and the planes (n . x = d, n unit) from the
    rows by Gauss-Newton with a prior of rcal's size on the DH rows; returns the fitted Robot and probe.
    ties {j: (j0, h)}: plane j is told parallel to plane j0, h mm above it (its own parameters then unused)."""
    ties = ties or {}
    nom = ts.nominal_robot(name)
    x0 = np.array([v for r in nom.rows for v in r])  # a, d, alpha, off per link
    free = [i for i in range(24) if i not in (1, 3)]  # d1, theta1 held
    R0, p0 = fk_batch(nom, Q)
    # start: the probe 150 mm along z, each plane through its rows' centroid, normal from their spread, turned
    # against the probe's axis (out of the touched face: a tie's height counts along it)
    tip = np.array([0.0, 0.0, 150.0])
    X = p0 + np.einsum("nij,j->ni", R0, tip)
    pl = []
    for j in range(n_planes):
        P = X[planes_idx == j]
        c = P.mean(0)
        n = np.linalg.svd(P - c)[2][2]
        if np.mean(R0[planes_idx == j][:, :, 2] @ n) > 0:
            n = -n
        pl.append((n, float(n @ c)))

    def unpack(th):
        dh = x0.copy()
        dh[free] = th[:22]
        rob = ts.Robot([tuple(dh[4 * i:4 * i + 4]) for i in range(6)])
        t = th[22:25]
        P = th[25:].reshape(-1, 3)  # per plane: two in-plane turns of the start normal, the offset
        return rob, t, P

    def normals(P):
        out = []
        for (n0, _), (wu, wv, _) in zip(pl, P):
            u, v = frame_of_normal(n0)
            n = n0 + wu * u + wv * v
            out.append(n / np.linalg.norm(n))
        return np.array(out)

    sd = np.array([PRIOR[i % 4] for i in free])

    def resid(th, w=0.01):
        rob, t, P = unpack(th)
        R, p = fk_batch(rob, Q)
        x = p + np.einsum("nij,j->ni", R, t)
        N = normals(P)
        D = P[:, 2].copy()
        for j, (j0, h) in ties.items():
            N[j], D[j] = N[j0], D[j0] + h
        r = np.einsum("ni,ni->n", N[planes_idx], x) - D[planes_idx]
        unused = np.concatenate([P[j] for j in ties]) if ties else np.zeros(0)
        return np.concatenate([r / w, (th[:22] - x0[free]) / sd, unused])

    th = np.concatenate([x0[free], tip, np.array([[0.0, 0.0, d] for _, d in pl]).ravel()])
    for sigma in (0.01, None, None):  # the rows weighed by 0.01 mm, then twice by the residuals' robust sd
        if sigma is None:
            rd = resid(th, 1.0)[:len(Q)]
            sigma = max(1.4826 * np.median(np.abs(rd - np.median(rd))), 0.002)  # below: the fit ill-conditioned
        w = sigma
        th = gauss_newton(lambda t: resid(t, w), th)
    rob, tip, _ = unpack(th)
    return rob, tip


def gauss_newton(resid, th):
    last = np.inf
    for it in range(40):
        r = resid(th)
        J = np.zeros((len(r), len(th)))
        for i in range(len(th)):
            h = 1e-6 * max(1.0, abs(th[i]))
            tp = th.copy()
            tp[i] += h
            J[:, i] = (resid(tp) - r) / h
        lam = 1e-14 * np.trace(J.T @ J) / len(th)  # the prior makes it full rank; damping would stall it
        step = np.linalg.solve(J.T @ J + lam * np.eye(len(th)), -J.T @ r)
        th = th + step
        cost = r @ r
        if it > 2 and abs(last - cost) < 1e-9 * cost:
            break
        last = cost
    return th


def ref_compensate(model, nom, T, tcp):
    """Position-only: per target the joints nearest it whose model point is the nominal point meant."""
    out = []
    for q in T:
        goal = nom.point(q, tcp)
        c = q.copy()
        for _ in range(20):
            x, _, J = tip_jacobian(model, c, np.asarray(tcp, float))
            e = goal - x
            if np.linalg.norm(e) < 1e-9:
                break
            c = c + np.linalg.pinv(J[:3]) @ e
        out.append(c)
    return np.array(out)


# --- the study ----------------------------------------------------------------------------------------------

UNSEEN = re.compile(r"determin|unseen|not seen|identif|observ|rank|degenera", re.I)


def plan_args(case, rng, gauge):
    """What a user tells `rcal poses` of the cell, taught with the robot: the probe's drawing off by up to 2 mm;
    for each plate the touches already drawn on it (this script's own, on the TRUE robot) seen through the
    NOMINAL robot and that probe: the plane through those points (the normal on the side the TRUE one faces, as
    a user knows it), its point the taught touch nearest the face's centre, its usable diameter 20 mm inside the
    side; the gauge block's place the same way from the touches of its top, less its height. The truth's own
    numbers never reach the planner."""
    nom = ts.nominal_robot(case["name"])
    tip = case["tip"] + rng.uniform(-2, 2, 3)
    taught = {}
    for q, j, _ in case["rows"]:
        taught.setdefault(j, []).append(nom.point(q, tip))
    told = {}
    for j, pl in enumerate(case["plates"]):
        P = np.array(taught[j])
        m = P.mean(axis=0)
        n = np.linalg.svd(P - m)[2][2]
        n = n if n @ pl["n"] > 0 else -n
        # the touch the user made nearest the face's middle (where it landed on the TRUE face)
        k = int(np.argmin([np.linalg.norm(case["truth"].point(q, case["tip"]) - pl["c"])
                           for q, jj, _ in case["rows"] if jj == j]))
        c = P[k] - ((P[k] - m) @ n) * n
        told[j] = (c, n)
    args = []
    for j, pl in enumerate(case["plates"]):
        if pl["kind"] == "gauge":
            continue
        c, n = told[j]
        args += ["--plate", ",".join("%.3f" % x for x in list(c) + list(n) + [pl["side"] - 20.0])]
    args += ["--tool", ",".join("%.3f" % x for x in tip)]
    for j, pl in enumerate(case["plates"]):
        if pl["kind"] == "gauge":
            c, n = told[j]
            at = c - gauge * told[pl["of"]][1]
            args += ["--gauge-mm", "%g" % gauge, "--gauge-plate", "%d" % pl["of"], "--gauge-at",
                     ",".join("%.3f" % x for x in at), "--gauge-size-mm", "%g" % (pl["side"] - 20.0)]
    return args


def touch_plan(case, path, rng):
    """The planned rows (pose,plane,q1..q6[,height_mm], degrees) touched on the TRUE robot: at each row's joints
    the TRUE probe point is moved along the TRUE plate's normal onto its face (the gauge's top for a row with a
    height), the flange's orientation kept, and the joints solved by this script's Newton from the planned ones;
    the trigger noise as for a drawn touch. A row whose point falls off the true face, or whose joints leave the
    limits, is not touched (counted). Returns (rows, missed)."""
    rob, tip, lim = case["truth"], case["tip"], ts.ROBOTS[case["name"]]["lim"]
    d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    gi = [j for j, pl in enumerate(case["plates"]) if pl["kind"] == "gauge"]
    rows, missed = [], 0
    for r in d:
        q0 = r[2:8] * DEG
        j = gi[0] if (len(r) > 8 and r[8] > 0 and gi) else int(r[1])
        pl = case["plates"][j]
        x, R, _ = tip_jacobian(rob, q0, tip)
        x = x - (pl["n"] @ x - pl["d"]) * pl["n"]
        h = pl["side"] / 2.0
        if abs(pl["u"] @ (x - pl["c"])) > h or abs(pl["v"] @ (x - pl["c"])) > h:
            missed += 1
            continue
        eps = rng.normal(0.0, case["noise_sd"])
        if rng.random() < 0.02:
            eps = float(np.clip(ts.heavy(rng, 8.0 * case["noise_sd"]), -0.25, 0.25))
        q = ik_pose(rob, q0, tip, x + eps * pl["n"], R)
        q = within(q, lim) if q is not None else None
        if q is None:
            missed += 1
            continue
        rows.append((q, j, eps))
    return rows, missed


def one_case(a, k, name, tmp, planned=False):
    case = make_case(a.seed, k, name, a.planes, a.one_plate, gauge=a.gauge, n_total=a.compare_plan)
    rows = case["rows"]
    cdir = os.path.join(tmp, "case%02d%s" % (k, "_plan" if planned else ""))
    os.makedirs(cdir, exist_ok=True)
    robot = os.path.join(cdir, "robot.json")
    ts.write_robot(robot, name)
    missed = 0
    if planned:  # rcal poses plans the touches on the nominal robot from the approximate cell
        plan = os.path.join(cdir, "plan.csv")
        n_total = len(rows)
        cmd = [a.rcal, "poses", "--robot", robot, "--count", str(n_total), "--out", plan, "--seed", str(k + 1)]
        cmd += plan_args(case, np.random.default_rng([a.seed, k, 5]), a.gauge) + a.plan_args.split()
        rc, out, err = ts.run(cmd)
        if rc != 0:
            return {"case": k, "robot": name, "planes": len(case["plates"]), "rows": 0, "noise_mm": case["noise_sd"],
                    "error": "rcal poses rc %d: %s" % (rc, err.strip()[:400])}
        rows, missed = touch_plan(case, plan, np.random.default_rng([a.seed, k, 6]))
        case["rows"] = rows
    data = os.path.join(cdir, "touches.csv")
    write_touches(data, rows, None if a.reference else case["plates"])
    with open(os.path.join(cdir, "truth.txt"), "w") as f:
        f.write("probe %s (flange frame, mm)\nnoise_sd %.4f mm\n" % (case["tip"].tolist(), case["noise_sd"]))
        for j, pl in enumerate(case["plates"]):
            f.write("plane %d %s normal %s d %.4f centre %s side %.1f rows %d\n" % (
                j, pl["kind"], pl["n"].tolist(), pl["d"], pl["c"].tolist(), pl["side"],
                sum(1 for r in rows if r[1] == j)))
        for j, (ra, rd, ral, rth) in enumerate(case["truth"].rows):
            a0, d0, al0, th0 = ts.ROBOTS[name]["dh"][j]
            f.write("dh%d a %+.4f d %+.4f alpha %+.5f theta %+.5f (mm, deg, true - nominal)\n"
                    % (j + 1, ra - a0, rd - d0, ral / DEG - al0, rth / DEG - th0))
    res = {"case": k, "robot": name, "planes": len(case["plates"]), "rows": len(rows),
           "noise_mm": case["noise_sd"], "probe_true_mm": case["tip"].tolist(), "missed": missed}
    flange = np.zeros(3)
    T = judge_targets(case["rng"], name, flange)
    if a.reference:
        planes_idx, Q = read_touches(data)
        ties = {j: (pl["of"], pl["height"]) for j, pl in enumerate(case["plates"]) if pl["kind"] == "gauge"}
        model, tip = ref_fit(name, planes_idx, Q, len(case["plates"]), ties)
        res["probe_fit_mm"] = tip.tolist()
        for at, tool, tool_true in (("flange", flange, flange), ("probe", tip, case["tip"])):
            C = ref_compensate(model, ts.nominal_robot(name), T, tool)
            res[at] = judge(k, case, T, C, tool, tool_true)
        return res
    model = os.path.join(cdir, "model.json")
    if os.path.exists(model):
        os.remove(model)
    cmd = [a.rcal, "calibrate", "--robot", robot, "--data", data, "--out", model, "--test-fraction", "0"]
    rc, out, err = ts.run(cmd)
    res["calibrate"] = " ".join(cmd)
    res["calibrate_rc"] = rc
    res["calibrate_err"] = err.strip()
    if rc != 0 or not os.path.exists(model):
        res["error"] = "calibrate rc %d%s: %s" % (rc, "" if os.path.exists(model) else ", no model",
                                                  err.strip()[:400])
        return res
    tin, tout, uout = (os.path.join(cdir, f) for f in ("targets.csv", "comp.csv", "u95.csv"))
    with open(tin, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6\n")
        for q in T:
            f.write(",".join("%.6f" % (v / DEG) for v in q) + "\n")
    tip, where = model_probe(model)
    if tip is None:
        res["error"] = "the model %s names no fitted probe (%s)" % (model, where)
        return res
    res["probe_fit_mm"] = tip.tolist()
    for at, tool, tool_true in (("flange", flange, flange), ("probe", tip, case["tip"])):
        for f in (tout, uout):
            if os.path.exists(f):
                os.remove(f)
        cmd = [a.rcal, "compensate", "--model", model, "--in", tin, "--out", tout, "--summary", "--position-only",
               "--uncertainty-out", uout]
        if at == "probe":
            cmd += ["--tool", ",".join("%.6f" % v for v in tool)]
        rc, out, err = ts.run(cmd)
        if not os.path.exists(tout):
            res["error"] = "compensate (at the %s) rc %d: %s" % (at, rc, err.strip()[:400])
            return res
        C = np.loadtxt(tout, delimiter=",", skiprows=1, usecols=range(6), ndmin=2) * DEG
        if len(C) != len(T):
            res["error"] = "compensate (at the %s) wrote %d of %d targets" % (at, len(C), len(T))
            return res
        res[at] = judge(k, case, T, C, tool, tool_true)
    return res


def model_probe(path):
    """The fitted probe tip (flange frame, mm) in an rcal model: an effect whose kind names a probe or a touch,
    with 3 params, or a top-level key naming a probe with 3 numbers. (None, what was looked for) if none."""
    with open(path) as f:
        doc = json.load(f)
    for e in doc.get("effects", []):
        kind = str(e.get("kind", ""))
        if re.search("probe|touch", kind, re.I) and len(e.get("params", [])) == 3:
            return np.array(e["params"], float), kind
    for key, v in doc.items():
        if re.search("probe", key, re.I) and isinstance(v, list) and len(v) == 3:
            return np.array(v, float), key
    return None, "looked for an effect whose kind holds 'probe' or 'touch' with 3 params, or a key 'probe...'"


def compare_plan(a, name, tmp):
    """--compare-plan N: the same cases touched at N random places and at N planned ones; judged at a.at."""
    med = {False: [], True: []}
    errors = 0
    for k in range(a.cases):
        for planned in (False, True):
            r = one_case(a, k, name, tmp, planned)
            label = "planned" if planned else "random "
            if "error" in r:
                errors += 1
                print("case %2d %s ERROR %s" % (k, label, r["error"]), flush=True)
                continue
            j = r[a.at]
            med[planned].append(j["pair_med_comp"])
            print("case %2d %s rows %3d (missed %d) at the %s pair median %.4f mm (uncompensated %.4f), after the "
                  "best-fit scale %.4f, scale %+.0f ppm" % (k, label, r["rows"], r["missed"], a.at, j["pair_med_comp"],
                                                            j["pair_med_uncomp"], j["pair_med_scale_free"],
                                                            j["scale_ppm"]), flush=True)
    mr = float(np.median(med[False])) if med[False] else float("nan")
    mp = float(np.median(med[True])) if med[True] else float("nan")
    print("%d cases, %d touches each: median compensated pair median at the %s: planned %.4f mm, random %.4f mm "
          "(ratio %.2f); errors %d; files in %s" % (a.cases, a.compare_plan, a.at, mp, mr, mp / mr, errors, tmp))
    if not a.check:
        return 0
    from rct_check import check, failures, passes
    check(errors == 0, "every case planned, calibrated and compensated both ways (errors: %d)" % errors)
    check(mp < mr, "planned touches' median compensated pair median %.4f mm below random touches' %.4f mm" % (mp, mr))
    print("%d passed, %d failed" % (len(passes), len(failures)))
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rcal", nargs="?", help="the rcal tool (not needed with --self-check or --reference)")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--cases", type=int, default=4)
    ap.add_argument("--robot", choices=sorted(ts.ROBOTS), default=None,
                    help="the arm of every case (default irb120; with --self-check both in turn)")
    ap.add_argument("--one-plate", action="store_true", help="one plate at 3-4 placements (each its own plane)")
    ap.add_argument("--planes", type=int, default=0, help="plates or placements per case (default 3-4 at random; "
                                                          "1: one plate, one placement, the degenerate case)")
    ap.add_argument("--check", action="store_true", help="assert the goals; exit 1 when one fails")
    ap.add_argument("--dir", help="keep each case's files here (default a temporary directory)")
    ap.add_argument("--self-check", action="store_true", help="check the generator against its own kinematics")
    ap.add_argument("--reference", action="store_true",
                    help="fit and compensate with this script's own least squares instead of rcal")
    ap.add_argument("--ratio", type=float, default=0.35,
                    help="with --check: each case's compensated median at most RATIO x its uncompensated")
    ap.add_argument("--judge", choices=["pairs", "scale-free"], default="pairs",
                    help="with --check: the compensated pairwise median as truth_study.py judges it (pairs), or after "
                         "the landed points' best-fit scale (scale-free: planes alone measure no length)")
    ap.add_argument("--scale-ppm", type=float, default=3000.0,
                    help="with --judge scale-free: the landed points' best-fit scale within +-PPM of 1")
    ap.add_argument("--gauge", type=float, default=0.0, metavar="MM",
                    help="one more plane, a 60 mm face parallel to plane 0, MM above it; --reference is told that "
                         "length (rcal has no way to be told yet: to it an ordinary plane)")
    ap.add_argument("--at", choices=["probe", "flange"], default="probe",
                    help="with --check: judge the probe's tip (compensated with the model's fitted probe as the tool; "
                         "the point the touches see) or the flange (the judge of truth_study.py's default --tcp 0,0,0; "
                         "its split from the probe is not seen by touches). Both are printed")
    ap.add_argument("--compare-plan", type=int, default=0, metavar="N",
                    help="per case N random touches (spread evenly over the plates) against N planned by `rcal poses "
                         "--plate ...` from the cell's approximate placements, touched on the TRUE robot; with --check "
                         "the planned runs' median compensated pair median must be the lower")
    ap.add_argument("--plan-args", default="", metavar="'OPTS'",
                    help="with --compare-plan: further options of rcal poses (e.g. '--cone-deg 40')")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "common"))
    if a.planes < 0 or a.planes > 16:
        ap.error("--planes: 1..16 (0: 3-4 at random)")
    if a.self_check:
        return self_check(a)
    if not a.rcal and not a.reference:
        ap.error("the rcal tool is needed (or --self-check, --reference)")
    name = a.robot or "irb120"
    tmp = a.dir or tempfile.mkdtemp(prefix="rcal_touch_")
    os.makedirs(tmp, exist_ok=True)
    if a.compare_plan:
        return compare_plan(a, name, tmp)
    out = []
    for k in range(a.cases):
        r = one_case(a, k, name, tmp)
        out.append(r)
        head = "case %2d %-7s planes %d rows %3d noise %.4f mm" % (k, name, r["planes"], r["rows"], r["noise_mm"])
        if "error" in r:
            print("%s ERROR %s" % (head, r["error"]), flush=True)
            continue
        dtip = np.array(r["probe_fit_mm"]) - r["probe_true_mm"]
        print("%s probe fitted - true %s mm" % (head, np.round(dtip, 3).tolist()))
        for at in ("probe", "flange"):
            j = r[at]
            print("    at the %-6s pair median %.4f mm (uncompensated %.4f) ratio %.3f, p95 %.4f; rigid-aligned 3-D "
                  "median %.4f (uncompensated %.4f); after the best-fit scale %.4f, scale %+.0f ppm" % (
                      at, j["pair_med_comp"], j["pair_med_uncomp"], j["pair_med_comp"] / j["pair_med_uncomp"],
                      j["pair_p95_comp"], j["err_med_comp"], j["err_med_uncomp"], j["pair_med_scale_free"],
                      j["scale_ppm"]), flush=True)
    ok = [r for r in out if "error" not in r]
    for at in ("probe", "flange") if ok else ():
        sel = [r[at] for r in ok]
        print("at the %-6s cases %d (%s%s): median of pairwise medians %.4f mm (uncompensated %.4f), ratio median "
              "%.3f worst %.3f, cases worse %d; after the best-fit scale %.4f mm" % (
                  at, len(sel), "reference fit" if a.reference else "rcal", ", one plate" if a.one_plate else "",
                  np.median([j["pair_med_comp"] for j in sel]), np.median([j["pair_med_uncomp"] for j in sel]),
                  np.median([j["pair_med_comp"] / j["pair_med_uncomp"] for j in sel]),
                  max(j["pair_med_comp"] / j["pair_med_uncomp"] for j in sel),
                  sum(j["pair_med_comp"] > j["pair_med_uncomp"] for j in sel),
                  np.median([j["pair_med_scale_free"] for j in sel])))
    print("errors: %d; files in %s" % (len(out) - len(ok), tmp))
    if not a.check:
        return 0
    from rct_check import check, failures, passes
    if a.planes == 1 and not a.reference:
        for r in out:
            if r.get("calibrate_rc") == 0:
                print("one plane, case %d: rcal calibrated (exit 0)" % r["case"])
                check("error" not in r, "one plane, case %d: calibrated and compensated" % r["case"])
            else:
                msg = r.get("calibrate_err", "")
                print("one plane, case %d: rcal refused (exit %s): %s" % (r["case"], r.get("calibrate_rc"), msg))
                check(bool(UNSEEN.search(msg)) and "plane" in msg.lower(),
                      "one plane, case %d: the refusal names what the data cannot determine" % r["case"])
    else:
        check(len(ok) == len(out), "every case calibrated (exit 0, a model written) and compensated (%d of %d)"
              % (len(ok), len(out)))
        key = "pair_med_scale_free" if a.judge == "scale-free" else "pair_med_comp"
        for r in ok:
            j = r[a.at]
            check(j[key] <= a.ratio * j["pair_med_uncomp"],
                  "case %d: at the %s, compensated pair median%s %.4f mm <= %.2f x uncompensated %.4f" % (
                      r["case"], a.at, " after the best-fit scale" if a.judge == "scale-free" else "", j[key],
                      a.ratio, j["pair_med_uncomp"]))
            if a.judge == "scale-free":  # the scale the planes leave to the prior: bounded, not judged
                check(abs(j["scale_ppm"]) <= a.scale_ppm, "case %d: at the %s, the landed points' scale %+.0f ppm "
                      "within +-%g ppm" % (r["case"], a.at, j["scale_ppm"], a.scale_ppm))
        if ok:
            worse = [r["case"] for r in ok if r[a.at][key] > r[a.at]["pair_med_uncomp"]]
            check(not worse, "at the %s, no case worse than uncompensated (worse: %s)" % (a.at, worse))
    print("%d passed, %d failed" % (len(passes), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
