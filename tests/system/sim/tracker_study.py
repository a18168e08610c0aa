# SPDX-License-Identifier: MIT
"""tracker_study - rcal calibrated from laser-tracker positions, judged against the truth.

The robot, its errors and the tracker come from truth_study.py's own numpy
kinematics (not rcal's): a true IRB120 (heavy-tailed DH errors, joint 3's
axis tilted), a tracker 1-2 m away and turned by a random rotation, three
targets on the tool. Positions of the targets at random poses with Gaussian
noise (never told to rcal) are written as a positions file; rcal calibrates
from them (`--positions`, optionally mixed with cable lengths `--data`), and:
  - `rcal evaluate --positions` on noise-free positions of the true robot at
    random poses gives the 3-D error of the calibrated model against the truth,
  - on noisy held-out positions it gives an RMS that should be near the noise.

    python3 tracker_study.py RCAL [--seed S] [--poses N] [--noise MM] [--mixed] [--robot irb120|irb1600]
                             [--check] [--dir D]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth_study as ts  # noqa: E402  (its kinematics, robots and draws)

DEG = np.pi / 180.0


def rotvec(w):
    th = np.linalg.norm(w)
    k = w / th
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def draw_poses(rng, lim, n):
    out = []
    while len(out) < n:
        q = ts.draw_q(rng, lim, 1)[0]
        if abs(np.sin(q[4])) < 0.15:
            continue
        out.append(q)
    return np.array(out)


def write_positions(path, rob, R, T, targets, Q, rng, noise, repeats=1):
    with open(path, "w") as f:
        f.write("pose,target,q1,q2,q3,q4,q5,q6,x,y,z\n")
        for i, q in enumerate(Q):
            for _ in range(repeats):
                for k, t in enumerate(targets):
                    y = R @ rob.point(q, t) + T + (rng.normal(0, noise, 3) if noise > 0 else 0)
                    f.write("%d,%d,%s,%.5f,%.5f,%.5f\n" % (i, k, ",".join("%.7f" % (v / DEG) for v in q), *y))


def write_lengths(path, rob, outlet, attach, Q, rng, noise):
    with open(path, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6,L\n")
        for q in Q:
            L = np.linalg.norm(rob.point(q, attach) - outlet) + rng.normal(0, noise)
            f.write("%s,%.5f\n" % (",".join("%.7f" % (v / DEG) for v in q), L))


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write("FAILED: %s\n%s%s" % (" ".join(cmd), r.stdout, r.stderr))
        sys.exit(1)
    return r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("rcal")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--poses", type=int, default=40)
    ap.add_argument("--noise", type=float, default=0.02)
    ap.add_argument("--mixed", action="store_true", help="also 300 cable lengths from one outlet (--data)")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--dir")
    ap.add_argument("--robot", choices=sorted(ts.ROBOTS), default="irb120")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    name = a.robot
    lim = ts.ROBOTS[name]["lim"]
    rob = ts.true_robot(rng, name, beta_deg=0.03)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    R = rotvec(axis * rng.uniform(0.5, 1.2))  # 30-70 deg
    d = rng.normal(size=3)
    T = d / np.linalg.norm(d) * rng.uniform(1000.0, 2000.0)
    targets = [np.array([60.0, 0.0, 30.0]), np.array([-30.0, 52.0, 30.0]), np.array([-30.0, -52.0, 30.0])]
    targets = [t + rng.normal(0, 2.0, 3) for t in targets]
    tmp = a.dir or tempfile.mkdtemp(prefix="rcal_tracker_")
    os.makedirs(tmp, exist_ok=True)
    nominal = os.path.join(tmp, "nominal.json")
    ts.write_robot(nominal, name)
    train, test, truth = (os.path.join(tmp, f) for f in ("train.csv", "test.csv", "truth.csv"))
    write_positions(train, rob, R, T, targets, draw_poses(rng, lim, a.poses), rng, a.noise)
    write_positions(test, rob, R, T, targets, draw_poses(rng, lim, 30), rng, a.noise, repeats=2)
    write_positions(truth, rob, R, T, targets, draw_poses(rng, lim, 300), rng, 0.0)
    model = os.path.join(tmp, "model.json")
    cmd = [a.rcal, "calibrate", "--robot", nominal, "--positions", train, "--out", model, "--json"]
    if a.mixed:
        lengths = os.path.join(tmp, "lengths.csv")
        write_lengths(lengths, rob, np.array([400.0, -300.0, 0.0]), np.array([0.0, 0.0, 60.0]),
                      draw_poses(rng, lim, 300), rng, 0.02)
        cmd += ["--data", lengths]
    cal = json.loads(run(cmd))
    ev_truth = json.loads(run([a.rcal, "evaluate", "--model", model, "--positions", truth, "--json"]))
    ev_test = json.loads(run([a.rcal, "evaluate", "--model", model, "--positions", test, "--json"]))
    ev_nom = json.loads(run([a.rcal, "evaluate", "--model", nominal, "--positions", truth, "--json"]))
    noise3 = a.noise * np.sqrt(3.0)
    # identified against the truth: the DH parameters the positions determine, and the tracker frame up
    # to the gauge (theta1, d1 held at nominal: the fitted frame holds the truth's heading and height)
    doc = json.load(open(model))
    dev = []
    for i, row in enumerate(doc["dh"]):
        ta, td, tal, tth = rob.rows[i]
        if i < 5:
            dev += [("a%d" % (i + 1), row["a_mm"] - ta, "mm"), ("alpha%d" % (i + 1), row["alpha_deg"] - tal / DEG, "deg")]
        if 0 < i < 5:
            dev.append(("theta%d" % (i + 1), row["theta_deg"] - tth / DEG, "deg"))
        if i in (3, 4):
            dev.append(("d%d" % (i + 1), row["d_mm"] - td, "mm"))
    eff = {e["kind"]: e["params"] for e in doc["effects"]}
    nom = ts.nominal_robot(name).rows
    Rg = R @ ts.rot("z", rob.rows[0][3] - nom[0][3])
    Tg = T + R @ np.array([0.0, 0.0, rob.rows[0][1] - nom[0][1]])
    Rf = rotvec(np.array(eff["tracker_rotation"]))
    frame_deg = np.degrees(np.arccos(np.clip((np.trace(Rf.T @ Rg) - 1) / 2, -1, 1)))
    frame_mm = np.linalg.norm(np.array(eff["tracker_position"]) - Tg)
    worst_mm = max(abs(d) for n, d, u in dev if u == "mm")
    worst_deg = max(abs(d) for n, d, u in dev if u == "deg")
    print("identified - true: %s" % ", ".join("%s %+.4f" % (n, d) for n, d, u in dev))
    print("  largest: %.4f mm, %.5f deg; tracker frame vs the truth's (gauge applied): %.5f deg, %.4f mm "
          "(the frame is %.0f mm and %.1f deg from the base)" % (worst_mm, worst_deg, frame_deg, frame_mm,
                                                                 np.linalg.norm(T),
                                                                 np.degrees(np.arccos((np.trace(R) - 1) / 2))))
    t, h, nm = ev_truth["position_error_mm"], ev_test["position_error_mm"], ev_nom["position_error_mm"]
    print("calibrate: held-out 3-D RMS %.4f mm (%d positions), %s" % (
        cal["positions"]["position_error_mm"]["rms"], cal["positions"]["position_error_mm"]["points"],
        "mixed with %d lengths" % (cal["n_train"] + cal["n_test"] - 3 * cal["positions"]["rows"]) if a.mixed else
        "positions only"))
    print("against the truth (300 random poses x 3 targets, noise-free): RMS %.4f mean %.4f max %.4f mm "
          "(nominal model, tracker fitted: RMS %.4f mm)" % (t["rms"], t["mean"], t["max"], nm["rms"]))
    print("held-out noisy positions (30 poses x 3 targets x 2 repeats): RMS %.4f mm (3-D noise %.4f mm), "
          "frame %s, AP max %.4f RP max %.4f mm" % (h["rms"], noise3, ev_test["tracker_frame"], h["ap_max"],
                                                    h["rp_max"]))
    if a.check:
        ok = True
        ok &= ev_truth["tracker_frame"] == "kept" and ev_nom["tracker_frame"] == "fitted"
        ok &= t["rms"] < 3.0 * noise3 and t["rms"] < 0.2 * nm["rms"]
        ok &= abs(h["rms"] - noise3) < 0.5 * noise3 + t["rms"]
        ok &= h["repeated"] == 90
        ok &= worst_mm < 0.05 and worst_deg < 0.01 and frame_deg < 0.01 and frame_mm < 0.2
        print("check:", "ok" if ok else "FAILED")
        return 0 if ok else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
