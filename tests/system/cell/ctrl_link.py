#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A controller whose joints are not the model's (the robot file's "controller" member: KUKA-like signs and a
Fanuc-like zero on J2/J3), in the cell loop (issues 48, 51). The robot programs `rcal poses` writes state the
controller's joints; over the link the controller reports its own joints and `rcal acquire` records the
model's, checked against the plan in the controller's terms. This file maps with its own formula
(c = s q + z, from docs/model-format.md), and the simulated controller is given the plan in the controller's
joints, as the program on a real controller holds them.
usage: ctrl_link.py RCAL SIMDISPLAY SOURCE_DIR WORK_DIR"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import time

RCAL, SD, SRC, W = sys.argv[1:5]
HERE = os.path.dirname(os.path.abspath(__file__))
SIGN = [-1, 1, 1, -1, 1, -1]
ZERO = [0.0, -90.0, 90.0, 0.0, 0.0, 0.0]
procs = []


def fail(msg):
    for p in procs:
        if p.poll() is None:
            p.kill()
    print("FAIL: " + msg)
    sys.exit(1)


def to_ctrl(q):
    return [SIGN[j] * q[j] + ZERO[j] for j in range(6)]


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


shutil.rmtree(W, ignore_errors=True)
os.makedirs(W)
os.chdir(W)
robot = json.load(open(os.path.join(SRC, "data/irb120.json")))
robot["controller"] = {"joint_sign": SIGN, "joint_zero_deg": ZERO, "note": "test: KUKA-like signs, shifted zeros"}
json.dump(robot, open("r.json", "w"), indent=1)

# 1. the plan (model joints) and the programs (controller joints), the same poses
for extra, out in (([], "plan.csv"), (["--format", "rapid"], "plain.mod"),
                   (["--format", "rapid-link", "--controller", "tcp:127.0.0.1:5151"], "link.mod"),
                   (["--format", "urscript-link", "--controller", "tcp:127.0.0.1:5151"], "link.script")):
    r = subprocess.run([RCAL, "poses", "--robot", "r.json", "--count", "8", "--outlet", "250,-460,10", "--out", out]
                       + extra, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        fail("rcal poses %s: %s" % (" ".join(extra), r.stderr))
plan = read_csv("plan.csv")
want = [to_ctrl([float(p["q%d" % j]) for j in range(1, 7)]) for p in plan]
for prog in ("plain.mod", "link.mod"):
    got = [[float(v) for v in m.group(1).split(",")]
           for m in re.finditer(r"jointtarget\s+\w+\s*:=\s*\[\[([^\]]*)\]", open(prog).read())]
    if len(got) != len(want):
        fail("%s: %d jointtargets, the plan has %d poses" % (prog, len(got), len(want)))
    for k, (g, w) in enumerate(zip(got, want)):
        if max(abs(a - b) for a, b in zip(g, w)) > 1e-3:
            fail("%s: pose %d states %s, the controller's joints are %s" % (prog, k, g, w))
m = re.search(r"rcal_plan = \[(\[.*?\])\]\n", open("link.script").read())
if not m:
    fail("link.script: no rcal_plan list")
rows_ur = [[float(v) for v in r.strip("[] ").split(",")] for r in re.findall(r"\[[^\[\]]*\]", m.group(1))]
if len(rows_ur) != len(want):
    fail("link.script: %d poses, the plan has %d" % (len(rows_ur), len(want)))
for k, (g, w) in enumerate(zip(rows_ur, want)):  # URScript states radians
    if max(abs(a * 180.0 / 3.141592653589793 - b) for a, b in zip(g, w)) > 1e-3:
        fail("link.script: pose %d states %s rad, the controller's joints are %s deg" % (k, g, w))

# 2. over the link: the controller holds the plan in its own joints and reports them
with open("plan_ctrl.csv", "w", newline="") as f:
    wr = csv.writer(f)
    wr.writerow(["pose"] + ["q%d" % j for j in range(1, 7)])
    for p, w in zip(plan, want):
        wr.writerow([p["pose"]] + ["%.6f" % v for v in w])
sd = subprocess.Popen([SD, "--protocol", "ascii", "--truth", os.path.join(SRC, "data/sim_irb120_truth.json"),
                       "--poses", "plan.csv", "--follow", "ann.txt", "--rate-hz", "200", "--noise-mm", "0.003",
                       "--link", "tty.sim", "--max-seconds", "100"], stdout=subprocess.DEVNULL,
                      stderr=open("sim.err", "w"))
procs.append(sd)
for _ in range(100):
    if os.path.exists("tty.sim"):
        break
    time.sleep(0.1)
else:
    fail("no pty: " + open("sim.err").read())
acq = subprocess.Popen([RCAL, "acquire", "--port", "tty.sim", "--backend", "posix", "--protocol", "ascii",
                        "--poses", "plan.csv", "--robot", "r.json", "--encoder", "250,-460,10", "--out", "data.csv",
                        "--controller", "tcp:127.0.0.1:0", "--settle-ms", "50", "--controller-tol-deg", "0.05",
                        "--quiet", "--json"], stdout=subprocess.PIPE, stderr=open("acq.err", "w"), text=True)
procs.append(acq)
ctl = subprocess.Popen([sys.executable, os.path.join(HERE, "sim_controller.py"), "--port-from", "acq.err",
                        "--poses", "plan_ctrl.csv", "--follow", "ann.txt", "--speed-deg-s", "2000", "--log",
                        "ctl.json", "--max-seconds", "60"], stdout=subprocess.DEVNULL, stderr=open("ctl.err", "w"))
procs.append(ctl)
try:
    out, _ = acq.communicate(timeout=90)
    ctl.wait(timeout=10)
except subprocess.TimeoutExpired:
    fail("acquire: no end in 90 s: " + open("acq.err").read()[-2000:])
sd.kill()
if acq.returncode != 0:
    fail("acquire exit %d: %s" % (acq.returncode, open("acq.err").read()[-3000:]))
faults = json.loads(out)["controller"]["faults"]
if any(faults.values()):
    fail("faults %s (a plan checked in the model's joints against the controller's?): %s" % (
        faults, open("acq.err").read()[-2000:]))
rows = read_csv("data.csv")
if len(rows) != len(plan):
    fail("%d rows of %d" % (len(rows), len(plan)))
reports = {a["pose"]: a["q"] for a in json.load(open("ctl.json"))["at"]}
for x in rows:
    pose = int(x["pose"])
    q = [float(x["q%d" % j]) for j in range(1, 7)]
    qp = [float(x["q%d_plan" % j]) for j in range(1, 7)]
    c = reports[pose]
    back = [SIGN[j] * (c[j] - ZERO[j]) for j in range(6)]  # the controller's report, in the model's joints
    if max(abs(a - b) for a, b in zip(q, back)) > 1e-6:
        fail("pose %d: recorded %s, the controller's %s is %s in the model's joints" % (pose, q, c, back))
    if max(abs(a - b) for a, b in zip(q, qp)) > 0.05:
        fail("pose %d: recorded %s far from the plan %s" % (pose, q, qp))
print("ok: 8 poses; programs in the controller's joints (RAPID, link RAPID, URScript); over the link the "
      "controller's joints recorded as the model's, 0 faults")
