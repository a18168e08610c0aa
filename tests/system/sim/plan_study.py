# SPDX-License-Identifier: MIT
"""plan_study - is `rcal poses`' predicted 3-D accuracy what the robot does?

The independent generator of truth_study.py (its own kinematics in numpy,
its own true robots with heavy-tailed errors) measures cable lengths at the
poses `rcal poses` planned and at random poses of the same count (the same
joint-limit margin and cable-length range), from outlets placed 20 mm off
the approximate places the planner was told, with 0.02 mm noise (the noise
the prediction is made for; rcal is not told it). Each design is calibrated
(`rcal calibrate`) and 300 workspace targets compensated (`rcal compensate`)
and driven on the true robot; the 3-D error is taken after aligning the
base heading and height (the gauge rcal holds). Checks:
  - the plan is no worse than random poses (95th percentile of the 3-D
    error, median over the cases, within 10 %);
  - the measured 95th percentile lies within a factor 2 of the predicted
    95 % radius (median of the prediction over the workspace);
  - three outlets predict a better accuracy than one (same poses count);
  - --choose-outlets picks places spanning a plane over a collinear triple;
  - --format rapid: a module that `rcal compensate` reads, with every pose.

    python3 plan_study.py RCAL WORKDIR [--cases N]
    python3 plan_study.py RCAL WORKDIR --table [--cases N]   (not a test: the table by outlets and design)
"""
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "common"))
import truth_study as ts  # noqa: E402
from rct_check import check, failures, passes  # noqa: E402

DEG = ts.DEG
NOISE = 0.02
COUNT = 30
LEN = (250.0, 1200.0)
MARGIN = 5.0


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print("FAILED:", " ".join(cmd), "\n", r.stdout[-2000:], r.stderr[-2000:])
    return r


def read_plan(path):
    with open(path) as f:
        hdr = f.readline().strip().split(",")
        rows = [list(map(float, l.split(","))) for l in f if l.strip()]
    a = np.array(rows)
    q = a[:, 1:7] * DEG
    o = a[:, hdr.index("outlet")].astype(int) if "outlet" in hdr else np.zeros(len(a), int)
    return q, o


def random_design(rng, nom, lim, outs, n):
    """n random poses inside the limits less MARGIN whose nominal lengths are in LEN from every outlet."""
    lo = np.array([l for l, _ in lim]) + MARGIN
    hi = np.array([h for _, h in lim]) - MARGIN
    Q = []
    while len(Q) < n:
        q = (lo + (hi - lo) * rng.random(6)) * DEG
        p = nom.point(q, [0, 0, 0])
        if all(LEN[0] <= np.linalg.norm(p - o) <= LEN[1] for o in outs):
            Q.append(q)
    Q = np.array(Q)
    q = np.concatenate([Q] * len(outs))
    o = np.repeat(np.arange(len(outs)), n)
    return q, o


def judge(rcal, tmp, truth, nom, robot_path, q, o, outs_true, rng, name, robot_name="irb120"):
    L = np.array([np.linalg.norm(truth.point(qq, [0, 0, 0]) - outs_true[k]) for qq, k in zip(q, o)])
    L = np.round(L + NOISE * rng.standard_normal(len(L)), 4)
    data = os.path.join(tmp, name + ".csv")
    with open(data, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6,L,outlet\n")
        for qq, l, k in zip(q, L, o):
            f.write(",".join("%.4f" % (v / DEG) for v in qq) + ",%.4f,%d\n" % (l, k))
    model = os.path.join(tmp, name + ".json")
    if os.path.exists(model):
        os.remove(model)
    run([rcal, "calibrate", "--data", data, "--robot", robot_path, "--out", model, "--test-fraction", "0"])
    if not os.path.exists(model):
        return None, None
    lim = ts.ROBOTS[robot_name]["lim"]
    T = []
    while len(T) < 300:
        qq = ts.draw_q(rng, lim, 1)[0]
        if abs(np.sin(qq[4])) > 0.15:
            T.append(qq)
    T = np.array(T)
    tin, tout = os.path.join(tmp, "t.csv"), os.path.join(tmp, name + "_comp.csv")
    with open(tin, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6\n")
        for qq in T:
            f.write(",".join("%.6f" % (v / DEG) for v in qq) + "\n")
    if os.path.exists(tout):
        os.remove(tout)
    subprocess.run([rcal, "compensate", "--model", model, "--in", tin, "--out", tout, "--position-only",
                    "--max-uncertainty-mm", "100"], capture_output=True)  # exit 1: a few targets flagged
    C = np.loadtxt(tout, delimiter=",", skiprows=1, usecols=range(6)) * DEG
    meant = np.array([nom.point(qq, [0, 0, 0]) for qq in T])
    landed = np.array([truth.point(qq, [0, 0, 0]) for qq in C])
    e = np.linalg.norm(ts.gauge_align(landed, meant) - meant, axis=1)
    return e, model


def poses_cmd(rcal, robot, out, outs, extra=()):
    cmd = [rcal, "poses", "--robot", robot, "--count", str(COUNT), "--len-min-mm", str(LEN[0]), "--len-max-mm",
           str(LEN[1]), "--margin-deg", str(MARGIN), "--candidates", "1500", "--json", "--out", out]
    for o in outs:
        cmd += ["--outlet", ",".join("%g" % v for v in o)]
    r = run(cmd + list(extra))
    return json.loads(r.stdout) if r.returncode == 0 else None


OUTS4 = [np.array([500.0, -250.0, 50.0]), np.array([-400.0, -400.0, 350.0]), np.array([-100.0, 550.0, 0.0]),
         np.array([450.0, 400.0, 300.0])]


def table(rcal, work, cases):
    """The 3-D compensated error by outlets (1-4) and design, beside rcal poses' prediction, two robots."""
    print("robot    K design  | predicted 95 %% radius median / p95 | measured 3-D error p95 / RMS (median over "
          "%d cases)" % cases)
    for name in ("irb120", "irb1600"):
        sc = ts.ROBOTS[name]["reach"] / ts.ROBOTS["irb120"]["reach"]
        robot = os.path.join(work, name + ".json")
        ts.write_robot(robot, name)
        nom = ts.nominal_robot(name)
        for K in (1, 2, 3, 4):
            for split, count in (((False, COUNT),) if K == 1 else
                                 ((False, COUNT), (True, COUNT), (True, COUNT * K))):
                outs = [o * sc for o in OUTS4[:K]]
                pr, me = [], []
                for k in range(cases):
                    rng = np.random.default_rng([2028, K, k, split, count])
                    truth = ts.true_robot(rng, name, 0.03)
                    outs_true = [o + rng.normal(0, 20.0 / np.sqrt(3), 3) for o in outs]
                    plan = os.path.join(work, "t.csv")
                    cmd = [rcal, "poses", "--robot", robot, "--count", str(count), "--len-min-mm", "250",
                           "--len-max-mm", "%g" % (LEN[1] * sc), "--candidates", "1500", "--seed", str(k + 1),
                           "--json", "--out", plan] + (["--split"] if split else [])
                    for o in outs:
                        cmd += ["--outlet", ",".join("%g" % v for v in o)]
                    r = run(cmd)
                    if r.returncode != 0:
                        continue
                    d = json.loads(r.stdout)["predicted_position95_mm"]["plan"]
                    qp, op = read_plan(plan)
                    e, _ = judge(rcal, work, truth, nom, robot, qp, op, outs_true, rng, "t", name)
                    if e is None:
                        continue
                    pr.append((d["median_mm"], d["p95_mm"]))
                    me.append((np.percentile(e, 95), np.sqrt(np.mean(e ** 2))))
                if pr:
                    p_, m_ = np.median(np.array(pr), 0), np.median(np.array(me), 0)
                    print("%-8s %d %-7s %3d poses %3d rows | %.4f / %.4f mm | %.4f / %.4f mm" % (
                        name, K, "split" if split else "all", count, count if split else count * K, p_[0], p_[1],
                        m_[0], m_[1]), flush=True)
    return 0


def main():
    rcal, work = sys.argv[1], sys.argv[2]
    if "--table" in sys.argv:
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
        return table(rcal, work, int(sys.argv[sys.argv.index("--cases") + 1]) if "--cases" in sys.argv else 3)
    cases = int(sys.argv[sys.argv.index("--cases") + 1]) if "--cases" in sys.argv else 3
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    robot = os.path.join(work, "robot.json")
    ts.write_robot(robot, "irb120")
    nom = ts.nominal_robot("irb120")
    lim = ts.ROBOTS["irb120"]["lim"]
    outs = [np.array([500.0, -250.0, 50.0]), np.array([-400.0, -400.0, 350.0]), np.array([-100.0, 550.0, 0.0])]
    model = None
    outs_all = outs
    for K, n_cases, tol in ((1, cases, 1.0), (3, max(cases - 1, 1), 1.25)):
        outs = outs_all[:K]
        rows = []
        for k in range(n_cases):
            rng = np.random.default_rng([2027, K, k])
            truth = ts.true_robot(rng, "irb120", 0.03)
            outs_true = [o + rng.normal(0, 20.0 / np.sqrt(3), 3) for o in outs]
            plan = os.path.join(work, "plan%d_%d.csv" % (K, k))
            d = poses_cmd(rcal, robot, plan, outs, ["--seed", str(k + 1)])
            check(d is not None, "K=%d case %d: rcal poses planned" % (K, k))
            if d is None:
                continue
            qp, op = read_plan(plan)
            check(len(qp) == K * COUNT and list(np.bincount(op)) == [COUNT] * K,
                  "K=%d case %d: %d rows, %d per outlet (every pose from each)" % (K, k, len(qp), COUNT))
            qr, orr = random_design(rng, nom, lim, outs, COUNT)
            ep, m = judge(rcal, work, truth, nom, robot, qp, op, outs_true, rng, "plan%d_%d" % (K, k))
            er, _ = judge(rcal, work, truth, nom, robot, qr, orr, outs_true, rng, "rand%d_%d" % (K, k))
            check(ep is not None and er is not None, "K=%d case %d: both designs calibrated and compensated" % (K, k))
            if ep is None or er is None:
                continue
            model = model or m
            pr = d["predicted_position95_mm"]
            rows.append((np.percentile(ep, 95), np.percentile(er, 95), pr["plan"]["median_mm"],
                         pr["plan"]["p95_mm"], pr["random"]["median_mm"], np.median(ep), np.median(er)))
            print("K=%d case %d: 3-D error p95 plan %.4f mm (median %.4f), random %.4f mm (median %.4f); predicted "
                  "95 %% radius plan median %.4f p95 %.4f, random median %.4f" % ((K, k, rows[-1][0], rows[-1][5],
                                                                                 rows[-1][1], rows[-1][6])
                                                                                + rows[-1][2:5]))
        if rows:
            a = np.array(rows)
            mp, mr = np.median(a[:, 0]), np.median(a[:, 1])
            check(mp <= tol * mr, "K=%d: the plan is no worse than random poses: 3-D error p95 %.4f mm vs %.4f mm "
                  "(median over %d cases; allowed %.2f x)" % (K, mp, mr, len(rows), tol))
            ratio = a[:, 0] / a[:, 2]
            check(np.all((ratio > 0.5) & (ratio < 2.0)), "K=%d: measured 3-D p95 / predicted 95 %% radius (median "
                  "over the workspace) within [0.5, 2]: %s" % (K, ", ".join("%.2f" % v for v in ratio)))
    outs = outs_all
    # 2. three outlets predict better than one
    d1 = poses_cmd(rcal, robot, os.path.join(work, "k1.csv"), outs[:1])
    d3 = poses_cmd(rcal, robot, os.path.join(work, "k3.csv"), outs)
    if d1 and d3:
        m1, m3 = d1["predicted_position95_mm"]["plan"], d3["predicted_position95_mm"]["plan"]
        check(m3["median_mm"] < m1["median_mm"] and m3["p95_mm"] < m1["p95_mm"],
              "K = 3 predicts better than K = 1: median %.4f < %.4f mm, p95 %.4f < %.4f mm" % (
                  m3["median_mm"], m1["median_mm"], m3["p95_mm"], m1["p95_mm"]))
    # 3. choose 3 of 6 places: a collinear triple (0, 1, 2) against places around the robot
    cand = [(550, -350, 100), (550, 0, 100), (550, 350, 100), (-350, 500, 100), (-350, -500, 100), (-600, 0, 300)]
    cmd = [rcal, "poses", "--robot", robot, "--count", "20", "--candidates", "800", "--len-max-mm", "1200",
           "--choose-outlets", "3", "--json", "--out", os.path.join(work, "chosen.csv")]
    for c in cand:
        cmd += ["--candidate", "%g,%g,%g" % c]
    r = run(cmd)
    if r.returncode == 0:
        ch = json.loads(r.stdout)["choose_outlets"]
        best = [c for c in ch["combinations"] if c["chosen"]][0]
        line = [c for c in ch["combinations"] if c["candidates"] == [0, 1, 2]][0]
        check(len(ch["combinations"]) == 20, "choose-outlets: all 20 combinations judged")
        check(best["span"] == "plane" and best["candidates"] != [0, 1, 2] and best["median_mm"] < line["median_mm"],
              "choose-outlets picks %s (a plane, median %.4f mm) over the collinear triple (median %.4f mm)" % (
                  best["candidates"], best["median_mm"], line["median_mm"]))
    else:
        check(False, "choose-outlets ran")
    # 4. the plan as a RAPID module: every pose, read back by rcal compensate
    mod = os.path.join(work, "plan.mod")
    csvp = os.path.join(work, "plan_r.csv")
    base = [rcal, "poses", "--robot", robot, "--count", "6", "--candidates", "300", "--seed", "9"]
    for o in outs[:2]:
        base += ["--outlet", ",".join("%g" % v for v in o)]
    r1 = run(base + ["--out", csvp])
    r2 = run(base + ["--format", "rapid", "--out", mod])
    if r1.returncode == 0 and r2.returncode == 0:
        qc, oc = read_plan(csvp)
        text = open(mod).read()
        jt = re.findall(r"CONST jointtarget rcal_p(\d+):=\[\[([^\]]*)\],\[9E9,9E9,9E9,9E9,9E9,9E9\]\];", text)
        moves = re.findall(r"MoveAbsJ rcal_p(\d+)\\NoEOffs, v100, fine, tool0;", text)
        msgs = re.findall(r'TPWrite "rcal pose (\d+) outlet (\d+)";', text)
        qm = np.array([[float(v) for v in body.split(",")] for _, body in jt]) * DEG
        check(len(jt) == len(qc) == 12 and np.allclose(qm, qc, atol=1e-6) and len(moves) == 12 and
              [int(i) for i, _ in msgs] == list(range(12)) and [int(k) for _, k in msgs] == list(oc),
              "RAPID module: %d jointtargets equal to the CSV plan, %d MoveAbsJ, a message per pose naming its "
              "index and outlet" % (len(jt), len(moves)))
        check(text.count("WaitTime rcal_settle_s;") == 12 and "PROC rcal_outlet1()" in text,
              "RAPID module: a settle per pose, one PROC per outlet")
        if model:
            r3 = run([rcal, "compensate", "--model", model, "--in", mod, "--out", os.path.join(work, "plan_c.mod"),
                      "--json", "--max-uncertainty-mm", "100"])
            dj = json.loads(r3.stdout) if r3.returncode in (0, 1) and r3.stdout else {}
            check(dj.get("input_format") == "rapid" and dj.get("targets") == 12,
                  "rcal compensate reads the module: %s targets as %s" % (dj.get("targets"), dj.get("input_format")))
    else:
        check(False, "rcal poses --format rapid ran")
    print("%d passed, %d failed" % (len(passes), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
