#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The unattended cell loop of issue 48, whole: `rcal poses` plans N poses x 3 outlets (default 300), `rcal
acquire --controller` records every row from the simulated controller (sim_controller.py, written from
docs/controller-link.md alone) with the simulated display (rcal_simdisplay --follow) following the simulated
robot, through every fault class of the link (a disconnect mid-pose, a stalled move, an offset arrival,
garbage, a duplicate, an out-of-order report, a second controller, a slow network, and the cell stopping
mid-run with BYE, then the rerun resuming), then `rcal calibrate` on the file, judged against the truth
(data/sim_irb120_truth.json).

Asserts: 0 rows lost or duplicated; the file append-only through every run and fault (the file before a run is
the prefix of the file after it, whole lines); every fault named by rcal (its JSON summary and its stderr) and, where
the protocol answers one, received by the controller as a FAULT line; the recorded joints are the
controller's accepted reports at its precision (5 decimals, the plan's beside them); rcal's own time per pose
(docs/controller-link.md, "rcal's own time per pose": from the controller's AT to rcal's next command, less
--settle-ms and the display's stability window) <= 20 ms at the median and the 95th percentile of every
outlet's run, and its CPU time per pose <= 20 ms at the median (the largest wall and CPU times are printed: on a
loaded machine a pose now and then waits for the scheduler or the disk's fsync); the calibration's judge finds the model usable and its flange error
against the truth (calibrate --truth: rms over random poses) is within --max-flange-mm (default 0.05 mm).

usage: cell_loop.py RCAL SIMDISPLAY SOURCE_DIR WORK_DIR [--poses N] [--keep]"""
import csv
import json
import os
import shutil
import subprocess
import sys
import time

RCAL, SD, SRC, W = [os.path.abspath(a) for a in sys.argv[1:5]]
N_POSES = int(sys.argv[sys.argv.index("--poses") + 1]) if "--poses" in sys.argv else 300
MAX_FLANGE_MM = float(sys.argv[sys.argv.index("--max-flange-mm") + 1]) if "--max-flange-mm" in sys.argv else 0.05
HERE = os.path.dirname(os.path.abspath(__file__))
TRUTH = os.path.join(SRC, "data", "sim_irb120_truth.json")
OUTLETS = ["250,-460,10", "-250,-460,10", "0,-520,10"]
TOL_DEG = 0.05
OWN_MS = 20.0
# fast: a display at 1 kHz with a 10 ms move transient, 50 ms settle, joints at 4000 deg/s
SETTLE_MS, RATE_HZ, DISPLAY_SETTLE_MS, SPEED = 50, 1000, 10, 4000
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


def run(cmd, timeout):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        fail("no end within %d s: %s" % (timeout, " ".join(cmd)))


shutil.rmtree(W, ignore_errors=True)
os.makedirs(W)
os.chdir(W)
t0 = time.monotonic()
lap = {}

# 1. the plan
# (3000 candidates rather than the default 40 N: a quarter of the planning time; the plan's quality is judged by
# tests/system/sim/plan_*.py, this run judges the loop)
r = run([RCAL, "poses", "--count", str(N_POSES), "--candidates", "3000"] + sum([["--outlet", o] for o in OUTLETS], [])
        + ["--out", "plan.csv"], 600)
if r.returncode != 0:
    fail("rcal poses: " + r.stderr)
lap["plan"] = time.monotonic() - t0
plan = read_csv("plan.csv")
plan_q = {int(p["pose"]): [float(p["q%d" % j]) for j in range(1, 7)] for p in plan}
by_outlet = {}
for p in plan:
    by_outlet.setdefault(int(p["outlet"]), []).append(int(p["pose"]))
if sorted(by_outlet) != [0, 1, 2] or any(len(v) != N_POSES for v in by_outlet.values()):
    fail("plan: %s" % {k: len(v) for k, v in by_outlet.items()})

# 2. the display follows the robot
sd = subprocess.Popen([SD, "--protocol", "ascii", "--truth", TRUTH, "--poses", "plan.csv", "--follow", "ann.txt",
                       "--rate-hz", str(RATE_HZ), "--settle-ms", str(DISPLAY_SETTLE_MS), "--noise-mm", "0.003",
                       "--link", "tty.sim", "--max-seconds", "900"] + sum([["--outlet", o] for o in OUTLETS], []),
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


def acquire(k, wait_s="60"):
    return [RCAL, "acquire", "--port", "tty.sim", "--backend", "posix", "--protocol", "ascii", "--poses", "plan.csv",
            "--outlet", str(k), "--encoder", OUTLETS[k], "--out", "data.csv", "--settle-ms", str(SETTLE_MS),
            "--retries", "2", "--controller", "tcp:127.0.0.1:0", "--move-timeout-s", "1", "--link-timeout-s", "3",
            "--controller-wait-s", wait_s, "--controller-tol-deg", str(TOL_DEG), "--quiet", "--json"]


def controller(k, log, errf, faults, extra=()):
    return subprocess.Popen([sys.executable, os.path.join(HERE, "sim_controller.py"), "--port-from", errf,
                             "--poses", "plan.csv", "--outlet", str(k), "--follow", "ann.txt", "--log", log,
                             "--seed", str(k + 1), "--speed-deg-s", str(SPEED), "--slow-ms", "40",
                             "--max-seconds", "400"] + sum([["--fault", f] for f in faults], []) + list(extra),
                            stdout=subprocess.DEVNULL, stderr=open(log + ".err", "w"))


def rows_of(k):
    return [int(x["pose"]) for x in read_csv("data.csv") if int(x["outlet"]) == k]


# 3. the faults, spread over the run: (outlet, fault, index of the pose in the outlet's order)
at = lambda k, i: by_outlet[k][i]  # noqa: E731
Q = N_POSES // 6  # the cell stops at outlet 2's pose Q (BYE); a rerun resumes it
faults = {
    0: ["disconnect@%d" % at(0, N_POSES // 10), "stall@%d" % at(0, N_POSES // 2), "offset@%d" % at(0, 4 * N_POSES // 5)],
    1: ["garbage@%d" % at(1, N_POSES // 10), "duplicate@%d" % at(1, N_POSES // 3), "order@%d" % at(1, N_POSES // 2),
        "second@%d" % at(1, 4 * N_POSES // 5)],
    2: ["slow@%d" % at(2, N_POSES - 15)],
}
want = {0: ["LOST", "STALLED", "OFFSET"], 1: ["UNKNOWN", "DUPLICATE", "ORDER", "BUSY"], 2: []}
wire = {0: ["STALLED", "OFFSET"], 1: ["UNKNOWN", "DUPLICATE", "ORDER"], 2: []}

# outlet 2 first: the cell stops at pose Q of its order (BYE); rcal waits --controller-wait-s for it to come
# back, then stops with what it recorded
t1 = time.monotonic()
acq = subprocess.Popen(acquire(2, wait_s="10"), stdout=subprocess.PIPE, stderr=open("quit.err", "w"), text=True)
procs.append(acq)
ctl = controller(2, "quit.json", "quit.err", ["quit@%d" % at(2, Q)])
procs.append(ctl)
acq.communicate(timeout=300)
ctl.wait(timeout=30)
lap["outlet 2 to BYE"] = time.monotonic() - t1
if acq.returncode != 1 or "LOST: the controller said BYE" not in open("quit.err").read():
    fail("the cell stopped: exit %d: %s" % (acq.returncode, open("quit.err").read()[-2000:]))
if rows_of(2) != by_outlet[2][:Q]:
    fail("the cell stopped at pose %d: %d rows (want %d)" % (at(2, Q), len(rows_of(2)), Q))

qtext = open("quit.err").read()
if "LOST" not in qtext:
    fail("the cell's BYE not named LOST: " + qtext[-2000:])
summaries, logs, texts = {}, {}, {}
for k in (0, 1, 2):
    t1 = time.monotonic()
    before = open("data.csv", "rb").read()  # append-only through every fault: the file before is its prefix after
    err = open("acq%d.err" % k, "w")
    acq = subprocess.Popen(acquire(k), stdout=subprocess.PIPE, stderr=err, text=True)
    procs.append(acq)
    ctl = controller(k, "ctl%d.json" % k, "acq%d.err" % k, faults[k], ["--tcp"] if k == 2 else [])
    procs.append(ctl)
    try:
        out, _ = acq.communicate(timeout=600)
        ctl.wait(timeout=30)
    except subprocess.TimeoutExpired:
        fail("outlet %d: no end: %s" % (k, open("acq%d.err" % k).read()[-2000:]))
    err.close()
    lap["outlet %d" % k] = time.monotonic() - t1
    text = texts[k] = open("acq%d.err" % k).read()
    after = open("data.csv", "rb").read()
    if not after.startswith(before) or not after.endswith(b"\n"):
        fail("outlet %d: data.csv is not the file before the run with rows appended" % k)
    if acq.returncode != 0:
        fail("outlet %d: rcal acquire exit %d: %s" % (k, acq.returncode, text[-3000:]))
    summaries[k] = json.loads(out)
    with open("acq%d.json" % k, "w") as f:
        f.write(out)
    logs[k] = json.load(open("ctl%d.json" % k))
    if ctl.returncode != 0 or logs[k]["stop"] != "done":
        fail("outlet %d: the controller did not end on STOP done: %s" % (k, open("ctl%d.json.err" % k).read()))
    got = summaries[k]["controller"]["faults"]
    for name in want[k]:
        if got.get(name, 0) < 1 or (name + ":" not in text and name + " at" not in text):
            fail("outlet %d: fault %s not named (summary %s): %s" % (k, name, got, text[-3000:]))
    for name, n in got.items():
        if name not in want[k] and n:
            fail("outlet %d: unexpected fault %s x%d: %s" % (k, name, n, text[-3000:]))
    for name in wire[k]:
        if logs[k]["faults"].get(name, 0) < 1:
            fail("outlet %d: the controller got no FAULT %s: %s" % (k, name, logs[k]["faults"]))
    if k == 1 and logs[k]["busy_seen"] != 1:
        fail("the second controller was not told FAULT BUSY")
    if k == 0 and logs[k]["connections"] < 2:
        fail("outlet 0: the controller did not reconnect after the disconnect")
    if k == 2 and logs[k]["commands"][:2] != ["BACK %d" % at(2, Q - 1), "NEXT %d" % at(2, Q)]:
        fail("outlet 2 resumed with %s (want BACK %d, NEXT %d)" % (logs[k]["commands"][:2], at(2, Q - 1), at(2, Q)))

# 4. the file: every (pose, outlet) once; the controller's joints at its precision, the plan's beside
rows = read_csv("data.csv")
keys = [(int(x["pose"]), int(x["outlet"])) for x in rows]
if len(keys) != len(set(keys)):
    fail("duplicated rows: %d rows, %d distinct" % (len(keys), len(set(keys))))
if set(keys) != {(int(p["pose"]), int(p["outlet"])) for p in plan}:
    fail("rows lost: %d of %d" % (len(set(keys)), len(plan)))
reports = {}
for k in (0, 1, 2):
    for a in logs[k]["at"] + (json.load(open("quit.json"))["at"] if k == 2 else []):
        reports.setdefault((a["pose"], k), []).append(a["q"])
finer = 0
for x in rows:
    k, pose = int(x["outlet"]), int(x["pose"])
    q = [float(x["q%d" % j]) for j in range(1, 7)]
    qp = [float(x["q%d_plan" % j]) for j in range(1, 7)]
    if max(abs(a - b) for a, b in zip(qp, plan_q[pose])) > 1e-9:
        fail("pose %d: q_plan %s, plan %s" % (pose, qp, plan_q[pose]))
    good = [rq for rq in reports.get((pose, k), []) if max(abs(a - b) for a, b in zip(rq, plan_q[pose])) <= TOL_DEG]
    if not any(max(abs(a - b) for a, b in zip(rq, q)) < 5e-7 for rq in good):
        fail("pose %d outlet %d: recorded %s is none of the controller's accepted reports %s" % (pose, k, q, good))
    finer += any(abs(v * 1e4 - round(v * 1e4)) > 1e-3 for v in q)
if finer < len(rows) * 9 // 10:
    fail("only %d of %d rows carry the controller's 5th decimal" % (finer, len(rows)))
sd.kill()
sd.wait()

# 5. rcal's own time per pose
timing = {k: summaries[k]["controller"]["timing"] for k in (0, 1, 2)}
for k, t in timing.items():
    print("outlet %d: rcal's own time per pose (AT to the next command, less --settle-ms %d ms and the display's "
          "stability window, median %.1f ms): median %.2f ms, 95 %% %.2f ms, max %.2f ms over %d poses; CPU median "
          "%.2f ms, max %.2f ms; the controller's move median %.1f ms"
          % (k, t["settle_ms"], t["display_ms_median"], t["own_ms_median"], t["own_ms_p95"], t["own_ms_max"],
             t["poses"], t["cpu_ms_median"], t["cpu_ms_max"], t["move_ms_median"]))
    # the bound on the median and the 95th percentile: the largest (wall or CPU: one pose of a reconnect, a
    # resume, a re-read, or the scheduler on a shared CI machine; 20.4 ms CPU once) is printed, not asserted
    if (t["poses"] < summaries[k]["samples_written"] - 1 or t["own_ms_median"] > OWN_MS or t["own_ms_p95"] > OWN_MS
            or t["cpu_ms_median"] > OWN_MS):
        fail("outlet %d: rcal's own time per pose beyond %g ms (or too few poses timed): %s" % (k, OWN_MS, t))

# 6. straight into a calibration, judged against the truth
t1 = time.monotonic()
r = run([RCAL, "calibrate", "--data", "data.csv", "--truth", TRUTH, "--out", "model.json", "--json"], 600)
lap["calibrate"] = time.monotonic() - t1
if r.returncode != 0 or not os.path.exists("model.json"):
    fail("rcal calibrate: exit %d: %s" % (r.returncode, r.stderr[-3000:]))
j = json.loads(r.stdout)
judge = j.get("estimation", {}).get("judge", {})
fl = j.get("truth_flange", {})
if not judge.get("usable"):
    fail("the judge did not accept the model: %s" % judge)
if not fl or fl["after_rms_mm"] > MAX_FLANGE_MM:
    fail("flange error against the truth %s (bound %g mm rms)" % (fl, MAX_FLANGE_MM))
if "dequantiz" in r.stderr.lower():
    fail("calibrate asks for --dequantize-joints on a file of the controller's joints: " + r.stderr[-2000:])
print("calibration: %d rows, the judge: usable (ratio %.3g of factor %.3g); flange error against the truth: "
      "%.4f mm rms (max %.4f) after, %.3f mm rms before" % (len(rows), judge["ratio"], judge["factor"],
                                                            fl["after_rms_mm"], fl["after_max_mm"],
                                                            fl["before_rms_mm"]))
print("ok: %d poses x 3 outlets unattended, %d rows, 0 lost, 0 duplicated; faults named: %s; %s; %.1f s" % (
    N_POSES, len(rows), "; ".join("outlet %d: %s" % (k, ", ".join("%s %d" % (n, c) for n, c in
                                                                 summaries[k]["controller"]["faults"].items() if c)
                                                       or "a slow network (no fault: tolerated)")
                                  for k in (0, 1, 2)) + "; outlet 2 before: BYE (LOST), resumed",
    ", ".join("%s %.1f s" % kv for kv in lap.items()), time.monotonic() - t0))
