#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""End to end over the controller link (issue 48): a plan of poses x 3 outlets acquired by rcal acquire
--controller from the simulated controller (sim_controller.py, written from docs/controller-link.md) with the
simulated display (rcal_simdisplay --follow) following the simulated robot, through every fault class of the
link. Asserts 0 rows lost or duplicated, each fault named by rcal (its JSON summary and stderr) and by the
FAULT lines the controller received, the controller's joints recorded at its precision with the plan's
beside, and the file valid and resumable after a run that stopped on the link.
usage: controller_link_e2e.py RCAL SIMDISPLAY SOURCE_DIR WORK_DIR"""
import csv
import json
import os
import shutil
import subprocess
import sys
import time

RCAL, SD, SRC, W = sys.argv[1:5]
HERE = os.path.dirname(os.path.abspath(__file__))
OUTLETS = ["250,-460,10", "-250,-460,10", "0,-520,10"]
N_POSES = 8  # per outlet
TOL_DEG = 0.05
procs = []


def fail(msg):
    for p in procs:
        if p.poll() is None:
            p.kill()
    print("FAIL: " + msg)
    sys.exit(1)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


shutil.rmtree(W, ignore_errors=True)
os.makedirs(W)
os.chdir(W)
t_start = time.monotonic()
r = subprocess.run([RCAL, "poses", "--count", str(N_POSES)] + sum([["--outlet", o] for o in OUTLETS], [])
                   + ["--out", "plan.csv"], capture_output=True, text=True)
if r.returncode != 0:
    fail("rcal poses: " + r.stderr)
plan = read_csv("plan.csv")
plan_q = {int(p["pose"]): [float(p["q%d" % j]) for j in range(1, 7)] for p in plan}
by_outlet = {}
for p in plan:
    by_outlet.setdefault(int(p["outlet"]), []).append(int(p["pose"]))
if sorted(by_outlet) != [0, 1, 2]:
    fail("plan outlets %s" % sorted(by_outlet))

sd = subprocess.Popen([SD, "--protocol", "ascii", "--truth", os.path.join(SRC, "data/sim_irb120_truth.json"),
                       "--poses", "plan.csv", "--follow", "ann.txt", "--rate-hz", "100", "--noise-mm", "0.003",
                       "--link", "tty.sim", "--max-seconds", "170"]
                      + sum([["--outlet", o] for o in OUTLETS], []),
                      stdout=subprocess.DEVNULL, stderr=open("sim.err", "w"))
procs.append(sd)
for _ in range(100):
    if os.path.exists("tty.sim"):
        break
    if sd.poll() is not None:
        fail("the display stopped: " + open("sim.err").read())
    time.sleep(0.1)
else:
    fail("no pty in 10 s")


def acquire(k, extra=(), wait_s="10"):
    return [RCAL, "acquire", "--port", "tty.sim", "--backend", "posix", "--protocol", "ascii", "--poses", "plan.csv",
            "--outlet", str(k), "--encoder", OUTLETS[k], "--out", "data.csv", "--settle-ms", "100", "--retries",
            "2", "--controller", "tcp:127.0.0.1:0", "--move-timeout-s", "2", "--link-timeout-s", "3",
            "--controller-wait-s", wait_s, "--controller-tol-deg", str(TOL_DEG), "--quiet", "--json"] + list(extra)


# 1. no controller: the run stops on the link with nothing recorded; the file stays valid and resumes
r = subprocess.run(acquire(0, wait_s="1"), capture_output=True, text=True, timeout=30)
if r.returncode != 1 or "no controller connected within 1 s" not in r.stderr:
    fail("no controller: exit %d, %s" % (r.returncode, r.stderr))
if len(read_csv("data.csv")) != 0:
    fail("no controller: rows recorded")

# 2. the three outlets, each through its faults (at the outlet's 2nd, 3rd, ... pose in the run's order)
plans = {
    0: ["disconnect", "stall", "offset"],
    1: ["garbage", "duplicate", "order", "second"],
    2: ["slow"],
}
want = {0: ["LOST", "STALLED", "OFFSET"], 1: ["UNKNOWN", "DUPLICATE", "ORDER", "BUSY"], 2: []}
wire = {0: ["STALLED", "OFFSET"], 1: ["UNKNOWN", "DUPLICATE", "ORDER"], 2: []}
summaries, logs = {}, {}


def rows_of(k):
    return [int(x["pose"]) for x in read_csv("data.csv") if int(x["outlet"]) == k]


# outlet 2 first: the cell stops at its 5th pose (BYE); rcal stops with what it recorded, the rerun resumes
poses2 = by_outlet[2]
acq = subprocess.Popen(acquire(2, wait_s="2"), stdout=subprocess.PIPE, stderr=open("quit.err", "w"), text=True)
procs.append(acq)
ctl = subprocess.Popen([sys.executable, os.path.join(HERE, "sim_controller.py"), "--port-from", "quit.err",
                        "--poses", "plan.csv", "--outlet", "2", "--follow", "ann.txt", "--log", "quit.json",
                        "--fault", "quit@%d" % poses2[4], "--max-seconds", "30"], stdout=subprocess.DEVNULL)
procs.append(ctl)
acq.communicate(timeout=45)
ctl.wait(timeout=10)
before = rows_of(2)
if acq.returncode != 1 or "LOST: the controller said BYE" not in open("quit.err").read():
    fail("the cell stopped: exit %d: %s" % (acq.returncode, open("quit.err").read()[-2000:]))
if before != poses2[:4]:
    fail("the cell stopped at pose %d: rows %s (want %s)" % (poses2[4], before, poses2[:4]))

for k in (0, 1, 2):
    poses = by_outlet[k]
    flt = sum([["--fault", "%s@%d" % (kind, poses[1 + i])] for i, kind in enumerate(plans[k])], [])
    if k == 2:  # resumed: the slow network from its first new pose
        flt = ["--fault", "slow@%d" % poses[4]]
    err = open("acq%d.err" % k, "w")
    acq = subprocess.Popen(acquire(k), stdout=subprocess.PIPE, stderr=err, text=True)
    procs.append(acq)
    ctl = subprocess.Popen([sys.executable, os.path.join(HERE, "sim_controller.py"), "--port-from",
                            "acq%d.err" % k, "--poses", "plan.csv", "--outlet", str(k), "--follow", "ann.txt",
                            "--log", "ctl%d.json" % k, "--seed", str(k + 1), "--max-seconds", "50"] + flt
                           + (["--tcp"] if k == 2 else []),
                           stdout=subprocess.DEVNULL, stderr=open("ctl%d.err" % k, "w"))
    procs.append(ctl)
    try:
        out, _ = acq.communicate(timeout=55)
        ctl.wait(timeout=10)
    except subprocess.TimeoutExpired:
        fail("outlet %d: no end within 55 s: %s" % (k, open("acq%d.err" % k).read()[-2000:]))
    err.close()
    text = open("acq%d.err" % k).read()
    if acq.returncode != 0:
        fail("outlet %d: rcal acquire exit %d: %s" % (k, acq.returncode, text[-3000:]))
    summaries[k] = json.loads(out)
    logs[k] = json.load(open("ctl%d.json" % k))
    if ctl.returncode != 0 or logs[k]["stop"] != "done":
        fail("outlet %d: the controller did not end on STOP done: %s" % (k, logs[k]))
    faults = summaries[k]["controller"]["faults"]
    for name in want[k]:
        if faults.get(name, 0) < 1 or (name + ":" not in text and name + " at" not in text):
            fail("outlet %d: fault %s not named (summary %s): %s" % (k, name, faults, text[-3000:]))
    for name, n in faults.items():
        if name not in want[k] and n:
            fail("outlet %d: unexpected fault %s x%d: %s" % (k, name, n, text[-3000:]))
    for name in wire[k]:
        if logs[k]["faults"].get(name, 0) < 1:
            fail("outlet %d: the controller got no FAULT %s: %s" % (k, name, logs[k]))
    if k == 1 and logs[k]["busy_seen"] != 1:
        fail("the second controller was not told FAULT BUSY")
    if k == 0 and logs[k]["connections"] < 2:
        fail("outlet 0: the controller did not reconnect")
    if k == 2 and logs[k]["commands"][:2] != ["BACK %d" % poses[3], "NEXT %d" % poses[4]]:
        fail("outlet 2 resumed with %s (want BACK %d, NEXT %d)" % (logs[k]["commands"][:2], poses[3], poses[4]))

# 3. the file: every (pose, outlet) once, the controller's joints, the plan's beside
rows = read_csv("data.csv")
header = open("data.csv").readline().strip()
if not header.endswith(",q1_plan,q2_plan,q3_plan,q4_plan,q5_plan,q6_plan"):
    fail("header " + header)
keys = [(int(x["pose"]), int(x["outlet"])) for x in rows]
if len(keys) != len(set(keys)):
    fail("duplicated rows: %d rows, %d distinct" % (len(keys), len(set(keys))))
if set(keys) != {(int(p["pose"]), int(p["outlet"])) for p in plan}:
    fail("rows lost: %d of %d" % (len(set(keys)), len(plan)))
finer = 0
for x in rows:
    k, pose = int(x["outlet"]), int(x["pose"])
    q = [float(x["q%d" % j]) for j in range(1, 7)]
    qp = [float(x["q%d_plan" % j]) for j in range(1, 7)]
    if max(abs(a - b) for a, b in zip(qp, plan_q[pose])) > 1e-9:
        fail("pose %d: q_plan %s, plan %s" % (pose, qp, plan_q[pose]))
    ats = logs[k]["at"] + (json.load(open("quit.json"))["at"] if k == 2 else [])
    reports = [at["q"] for at in ats if at["pose"] == pose]
    good = [rq for rq in reports if max(abs(a - b) for a, b in zip(rq, plan_q[pose])) <= TOL_DEG]
    if not any(max(abs(a - b) for a, b in zip(rq, q)) < 5e-7 for rq in good):
        fail("pose %d: recorded %s is none of the controller's accepted reports %s" % (pose, q, good))
    finer += any(abs(v * 1e4 - round(v * 1e4)) > 1e-3 for v in q)
if finer < len(rows) // 2:
    fail("only %d of %d rows carry the controller's 5th decimal" % (finer, len(rows)))

# 4. resumable: a rerun has nothing to do; a run without --controller is refused on this file
r = subprocess.run(acquire(0), capture_output=True, text=True, timeout=30)
if r.returncode != 0 or "already holds all" not in r.stderr:
    fail("rerun: exit %d %s" % (r.returncode, r.stderr))
sd.kill()
sd.wait()
dt = time.monotonic() - t_start
print("ok: %d poses x 3 outlets, %d rows, 0 lost, 0 duplicated; faults named: %s; %.1f s" % (
    N_POSES, len(rows), ", ".join("%d: %s" % (k, summaries[k]["controller"]["faults"]) for k in (0, 1, 2)), dt))
