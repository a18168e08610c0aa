# SPDX-License-Identifier: MIT
"""tracker_checks - positions files that would mislead a fit are refused, and a
positions-only run speaks of positions (issue 47, item 7). Standard library
only; the positions come from the tests' own kinematics (tests/common/rct_dh.py).

  1. a target label with no rows (targets 0 and 2, none 1): refused with the
     file and line of the first row past the gap (before, target 1 was stored
     at (0, 0, 0) and `evaluate` judged a 0.02 mm model 39 mm off);
  2. the controller's own x, y, z with joints rounded to 0.1 deg: refused as
     computed positions (the rigid fit leaves what the rounding alone leaves,
     within 1.25 x either way); a tracker's measurements of a robot 0.3 mm off
     its drawing, with the same rounded joints or at joints exactly on whole
     degrees (a plan), still calibrate;
  3. the calibrate text of a positions-only run: the "before" row fits the
     tracker (not the encoder) and no known set trades against the encoder.

    python3 tracker_checks.py RCAL SOURCE_DIR
"""
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

RCAL, SRC = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
sys.path.insert(0, os.path.join(SRC, "tests", "common"))
from rct_dh import draw_q, point, qtext  # noqa: E402

tmp = tempfile.mkdtemp(prefix="rcal_tracker_checks_")
fails = []
NOM = json.load(open(os.path.join(SRC, "data", "irb120.json")))["dh"]
C, S = math.cos(0.5), math.sin(0.5)
R, T = [[C, -S, 0], [S, C, 0], [0, 0, 1]], [1400.0, -700.0, 150.0]  # the tracker 1.6 m away, turned 28.6 deg


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fails.append(what)


def run(*args):
    r = subprocess.run([RCAL] + list(args), capture_output=True, text=True, cwd=tmp)
    return r.returncode, r.stdout + r.stderr


def robot(rng, len_sd, ang_sd):
    dh = json.loads(json.dumps(NOM))
    for r in dh:
        r["a_mm"] += rng.gauss(0, len_sd)
        r["d_mm"] += rng.gauss(0, len_sd)
        r["alpha_deg"] += rng.gauss(0, ang_sd)
        r["theta_deg"] += rng.gauss(0, ang_sd)
    return dh


def tracker(dh, q, t, rng):
    p = point(dh, q, t)
    return [sum(R[r][j] * p[j] for j in range(3)) + T[r] + rng.gauss(0, 0.02) for r in range(3)]


def write(name, lines):
    with open(os.path.join(tmp, name), "w") as f:
        f.write("\n".join(lines) + "\n")
    return name


# ---- 1. a target label with no rows ----
rng = random.Random(5)
TG = {0: [0, 0, 80], 1: [60, 0, 60], 2: [0, 60, 60]}
rows = ["pose,target,q1,q2,q3,q4,q5,q6,x,y,z"]
for i in range(30):
    q = draw_q(rng)
    for k in (0, 2):
        rows.append("%d,%d,%s,%.3f,%.3f,%.3f" % (i, k, qtext(q), *tracker(NOM, q, TG[k], rng)))
write("gap.csv", rows)
rc, out = run("calibrate", "--positions", "gap.csv", "--out", "gap.json")
check(rc == 1 and "gap.csv:3:1: target 2, but no row has target 1" in out and not os.path.exists(
    os.path.join(tmp, "gap.json")), "a target with no rows is refused at the first row past the gap: %s" % out[-300:])
rc, out = run("diagnose", "--positions", "gap.csv")
check(rc != 0 and "no row has target 1" in out, "diagnose refuses it too: %s" % out[-200:])

# ---- 2. the controller's positions with rounded joints; a tracker's with the same rounding ----
for seed in (1, 2, 3):
    rng = random.Random(seed)
    true = robot(rng, 0.3, 0.03)
    ctrl, meas = ["q1,q2,q3,q4,q5,q6,x,y,z"], ["q1,q2,q3,q4,q5,q6,x,y,z"]
    for _ in range(40):
        q = draw_q(rng)
        qr = ",".join("%.1f" % round(v, 1) for v in q)
        ctrl.append("%s,%.1f,%.1f,%.1f" % (qr, *point(NOM, q, [0, 0, 0])))  # what the controller computes
        meas.append("%s,%.3f,%.3f,%.3f" % (qr, *tracker(true, q, [0, 0, 80], rng)))
    write("ctrl%d.csv" % seed, ctrl)
    write("meas%d.csv" % seed, meas)
    rc, out = run("calibrate", "--positions", "ctrl%d.csv" % seed)
    check(rc == 1 and "ctrl%d.csv: these are the controller's computed positions" % seed in out
          and "rounding to 0.1 deg" in out, "seed %d: the controller's x, y, z with 0.1 deg joints refused: %s"
          % (seed, out[-330:]))
    rc, out = run("calibrate", "--positions", "meas%d.csv" % seed)
    check(rc == 0, "seed %d: a tracker's measurements with the same joints calibrate: %s" % (seed, out[-200:]))

# joints exactly on whole degrees (a plan's poses, the robot there): not rounded, the robot's own errors are
# left whatever their size relative to a degree's rounding effect; accepted
rng = random.Random(9)
true = robot(rng, 0.3, 0.03)
plan = ["q1,q2,q3,q4,q5,q6,x,y,z"]
for _ in range(40):
    q = [float(round(v)) for v in draw_q(rng)]
    plan.append("%s,%.3f,%.3f,%.3f" % (",".join("%.0f" % v for v in q), *tracker(true, q, [0, 0, 80], rng)))
write("plan.csv", plan)
rc, out = run("calibrate", "--positions", "plan.csv")
check(rc == 0, "a tracker's measurements at joints exactly on whole degrees calibrate: %s" % out[-200:])

# ---- 3. a positions-only run speaks of positions and the tracker ----
rc, out = run("calibrate", "--positions", "meas1.csv")
check("before (nominal DH, fitted tracker)" in out and "fitted encoder" not in out,
      "the before row fits the tracker, not the encoder")
check("the encoder" not in out.replace("encoder e: no cable lengths (tracker positions only), held", "")
      and "lengths do not fix" not in out, "no known set trades against the encoder the run does not have")
check("coordinates, mm)" in out, "the held-out table counts coordinates of positions")

shutil.rmtree(tmp, ignore_errors=True) if not fails else print("kept: " + tmp)
print("%d failure(s)" % len(fails))
sys.exit(1 if fails else 0)
