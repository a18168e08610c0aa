#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""test_json_all.py - every command of `rcal --help` run with --json on small
shipped data, its stdout read by Python's json module (not rcal's reader).

    test_json_all.py RCAL SIMDISPLAY SOURCE_DIR WORK_DIR

Each output must parse as one JSON object whose first three members are
"format" ("rcal-<command>/N"), "tool" ("rcal <version>", as `rcal --version`
prints it) and "command" (the command line, "rcal <command> ..."), and carry
what the command did (a member checked per command against the inputs the
test made). A command listed by `rcal --help` without a run below fails the
test: a new command must come with its JSON. acquire runs against
rcal_simdisplay on a pseudo-terminal (SIMDISPLAY "-" when the drivers are not
built: then acquire is reported as skipped, exit 77 if nothing else failed).
"""
import json
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from rct_check import check, failures  # noqa: E402

RCAL, SIMDISPLAY, SRC, WORK = sys.argv[1:5]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
DATA = os.path.join(SRC, "data", "sim_irb120.csv")
ROBOT = os.path.join(SRC, "data", "irb120.json")
TRUTH = os.path.join(SRC, "data", "sim_irb120_truth.json")
skipped = []


def w(name):
    return os.path.join(WORK, name)


def run(*args, codes=(0,)):
    p = subprocess.run([RCAL, *args], capture_output=True, text=True, timeout=120)
    if p.returncode not in codes:
        print(p.stdout[-2000:], p.stderr[-2000:])
    check(p.returncode in codes, "rcal %s -> exit %s (got %d)" % (" ".join(args), codes, p.returncode))
    return p


VERSION = subprocess.run([RCAL, "--version"], capture_output=True, text=True).stdout.split("\n")[0].strip()
check(re.fullmatch(r"rcal \S+", VERSION) is not None, "rcal --version names the tool: %r" % VERSION)


def doc_of(cmd, p):
    """stdout of `rcal cmd ... --json`: one JSON object with the header."""
    try:
        doc = json.loads(p.stdout, object_pairs_hook=lambda kv: kv)
    except json.JSONDecodeError as e:
        check(False, "%s: stdout is JSON (%s): %r" % (cmd, e, p.stdout[:300]))
        return {}
    check(isinstance(doc, list), "%s: one JSON object" % cmd)
    keys = [k for k, _ in doc]
    check(len(keys) == len(set(keys)), "%s: no member twice (%s)" % (cmd, keys))
    check(keys[:3] == ["format", "tool", "command"], "%s: starts with format, tool, command (%s)" % (cmd, keys[:3]))
    d = json.loads(p.stdout)
    check(re.fullmatch(r"rcal-%s/[1-9][0-9]*" % cmd, str(d.get("format"))) is not None,
          "%s: format %r is rcal-%s/N" % (cmd, d.get("format"), cmd))
    check(d.get("tool") == VERSION, "%s: tool %r is %r" % (cmd, d.get("tool"), VERSION))
    check(str(d.get("command", "")).startswith("rcal %s " % cmd) and "--json" in d.get("command", ""),
          "%s: command is the command line (%r)" % (cmd, d.get("command")))
    return d


def simulate():
    d = doc_of("simulate", run("simulate", "--robot", ROBOT, "--out", w("sim.csv"), "--truth-out", w("truth.json"),
                               "--samples", "40", "--seed", "3", "--json"))
    with open(w("sim.csv")) as f:
        rows = len(f.read().strip().split("\n")) - 1
    check(d.get("samples") == 40 == rows, "simulate: samples 40 = rows of the file (%s)" % rows)


def fkcheck():
    d = doc_of("fkcheck", run("fkcheck", "--data", DATA, "--robot", ROBOT, "--json", codes=(0, 3)))
    check(d.get("rows") == 600 and d.get("faults") == len(d.get("fault_lines", [None])),
          "fkcheck: 600 rows, faults = fault lines listed")


def calibrate():
    p = run("calibrate", "--data", DATA, "--robot", ROBOT, "--json", "--out", w("cal.json"))
    d = doc_of("calibrate", p)
    with open(w("calib.json"), "w") as f:
        f.write(p.stdout)
    check(d.get("n_train", 0) + d.get("n_test", 0) == 600, "calibrate: n_train + n_test = 600")
    check(d.get("after", {}).get("rmse_mm", 1) < d.get("before", {}).get("rmse_mm", 0), "calibrate: after < before")


def compare():
    d = doc_of("compare", run("compare", "--data", DATA, "--robot", ROBOT, "--cases", "2", "--samples", "80",
                              "--methods", "LM,LTLM", "--json"))
    check(d.get("cases") == 2 and len(d.get("cases_rmse_mm", [])) == 2, "compare: 2 cases")


def chaos():
    d = doc_of("chaos", run("chaos", "--points", "500", "--starts", "2", "--step", "0.25", "--json"))
    check(d.get("points") == 500 and len(d.get("curve", [])) == 17, "chaos: 500 points, 17 values of r")


def poses():
    d = doc_of("poses", run("poses", "--robot", ROBOT, "--count", "5", "--candidates", "200", "--seed", "4",
                            "--out", w("plan.csv"), "--json"))
    with open(w("plan.csv")) as f:
        rows = len(f.read().strip().split("\n")) - 1
    check(d.get("poses") == 5 == rows and d.get("out") == w("plan.csv"), "poses: 5 poses written (%d rows)" % rows)
    # a tool plate (issue 47): the JSON carries the points as told and each point count's prediction, the
    # figures the text prints
    plate = ["--robot", ROBOT, "--count", "6", "--candidates", "200", "--seed", "4", "--tool", "50,0,150",
             "--cable-point", "30,0,20", "--cable-point", "-15,26,20", "--cable-point", "-15,-26,20"]
    d = doc_of("poses", run("poses", *plate, "--out", w("plate_plan.csv"), "--json"))
    text = run("poses", *plate, "--out", w("plate_plan_text.csv")).stdout
    printed = [(int(m.group(1)), int(m.group(2)), float(m.group(3)), float(m.group(4))) for m in re.finditer(
        r"(\d) point\(s\), (\d+) rows: median ([0-9.]+) mm, 95th percentile ([0-9.]+) mm", text)]
    by = d.get("predicted_by_points", [])
    check(d.get("cable_points_mm") == [[30, 0, 20], [-15, 26, 20], [-15, -26, 20]],
          "poses --json: the plate's points as told: %s" % d.get("cable_points_mm"))
    check(len(by) == 3 == len(printed) and all(
        b["points"] == p[0] and b["rows"] == p[1] == 6 * p[0] and abs(b["median_mm"] - p[2]) < 6e-5 and
        abs(b["p95_mm"] - p[3]) < 6e-5 for b, p in zip(by, printed)),
        "poses --json: the prediction on 1, 2, 3 points as printed: %s against %s" % (by, printed))
    check(bool(by) and by[-1]["median_mm"] == d["predicted_position95_mm"]["plan"]["median_mm"],
          "poses --json: every point's prediction is the plan's")


def acquire():
    if SIMDISPLAY == "-" or not os.path.exists(SIMDISPLAY):
        skipped.append("acquire (rcal_simdisplay not built)")
        return
    sim = subprocess.Popen([SIMDISPLAY, "--truth", w("truth.json"), "--poses", w("plan.csv"), "--follow",
                            w("announce"), "--max-seconds", "60", "--protocol", "ascii", "--rate-hz", "100",
                            "--settle-ms", "50", "--seed", "1"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                           text=True)
    try:
        pty = sim.stdout.readline().strip()
        check(pty.startswith("/dev/"), "acquire: rcal_simdisplay on %s" % pty)
        d = doc_of("acquire", run("acquire", "--backend", "posix", "--port", pty, "--protocol", "ascii", "--poses",
                                  w("plan.csv"), "--out", w("acq.csv"), "--announce", w("announce"), "--robot",
                                  ROBOT, "--settle-ms", "60", "--read-timeout-ms", "300", "--pose-timeout-s", "10",
                                  "--poll-interval-ms", "10", "--stable-mm", "0.03", "--quiet", "--json"))
    finally:
        sim.terminate()
        sim.wait()
    with open(w("acq.csv")) as f:
        rows = len(f.read().strip().split("\n")) - 1
    check(d.get("samples_written") == 5 == rows and d.get("complete") is True and d.get("port") == pty,
          "acquire: 5 samples written (%d rows), complete, port named" % rows)


def diagnose():
    d = doc_of("diagnose", run("diagnose", "--data", DATA, "--robot", ROBOT, "--folds", "2", "--steps", "1",
                               "--json"))
    check(d.get("n") == 600 and "effect" in d, "diagnose: 600 samples, an effect named")


def flange_irb120(q_deg):
    """The IRB120's flange (standard DH of data/irb120.json), mm: test-side kinematics, not rcal's."""
    import math
    dh = [(0, 290, -90, 0), (270, 0, 0, -90), (70, 0, -90, 0), (0, 302, 90, 0), (0, 0, -90, 0), (0, 72, 0, 0)]
    T = [[1.0 if r == c else 0.0 for c in range(4)] for r in range(4)]
    for (a, d, al, off), qd in zip(dh, q_deg):
        th, al = math.radians(qd + off), math.radians(al)
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        A = [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]]
        T = [[sum(T[r][k] * A[k][c] for k in range(4)) for c in range(4)] for r in range(4)]
    return [T[0][3], T[1][3], T[2][3]]


def evaluate():
    d = doc_of("evaluate", run("evaluate", "--model", w("cal.json"), "--data", w("sim.csv"), "--json"))
    check(d.get("n") == 40, "evaluate: 40 samples")
    pos = w("positions.csv")  # tracker positions (docs/positions.md): the frame and target fitted here
    with open(pos, "w") as f:  # plausible ones (rcal refuses others): the IRB120's flange, a turned tracker, noise
        f.write("q1,q2,q3,q4,q5,q6,x,y,z\n")
        for i in range(8):
            q = [10 * i - 40, 3 * i, -20, 30, 40, 50]
            p = flange_irb120(q)
            x, y = 1500 + 0.6 * p[0] - 0.8 * p[1], -200 + 0.8 * p[0] + 0.6 * p[1]
            f.write("%d,%d,%d,%d,%d,%d,%.3f,%.3f,%.3f\n" % tuple(q + [x + 0.3 * (-1) ** i, y + 0.1 * i, p[2] + 300 - 0.2 * i]))
    d = doc_of("evaluate", run("evaluate", "--model", w("cal.json"), "--positions", pos, "--json"))
    pe = d.get("position_error_mm", {})
    check(d.get("rows") == 8 and d.get("n") == 24 and d.get("tracker_frame") == "fitted" and
          pe.get("points") == 8 and all(isinstance(pe.get(k), float) for k in ("rms", "mean", "max")),
          "evaluate --positions: 8 positions, frame fitted, position_error_mm rms/mean/max (%s)" % pe)


def bench():
    d = doc_of("bench", run("bench", "--data", w("sim.csv"), "--robot", ROBOT, "--runs", "1", "--json"))
    check(d.get("samples") == 40 and len(d.get("methods", [])) >= 1, "bench: 40 samples, methods listed")


def export():
    d = doc_of("export", run("export", "--model", w("cal.json"), "--format", "dh-csv", "--out", w("dh.csv"),
                             "--json"))
    with open(w("dh.csv")) as f:
        rows = len(f.read().strip().split("\n")) - 1
    check(d.get("rows") == rows > 0 and d.get("out") == w("dh.csv"), "export: rows = data rows of the CSV (%d)" % rows)
    run("export", "--model", w("cal.json"), "--format", "dh-csv", "--json", codes=(2,))  # stdout is the export


def compensate():
    with open(DATA) as f:
        lines = f.read().strip().split("\n")[1:8]
    with open(w("targets.csv"), "w") as f:
        f.write("q1,q2,q3,q4,q5,q6\n")
        for ln in lines:
            f.write(",".join(ln.split(",")[3:9]) + "\n")
    d = doc_of("compensate", run("compensate", "--model", w("cal.json"), "--in", w("targets.csv"), "--out",
                                 w("comp.csv"), "--json"))
    check(d.get("targets") == 7 and d.get("corrected", 0) + d.get("not_converged", 0) + d.get("left_uncertain", 0)
          == 7, "compensate: 7 targets, every one corrected, failed or left")
    check(isinstance(d.get("params", {}).get("dh_held"), list), "compensate: held parameters as a list")
    check(d.get("targets_not_corrected") == [], "compensate: no target left")
    # a RAPID module with a robtarget (issue 21): corrected through the nominal IK, counted
    with open(w("mixed.mod"), "w") as f:
        f.write("MODULE m\n"
                "  CONST jointtarget j1 := [[10,20,30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                "  CONST robtarget p1 := [[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],"
                "[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                "ENDMODULE\n")
    p = run("compensate", "--model", w("cal.json"), "--in", w("mixed.mod"), "--out", w("mixed_comp.mod"), "--json",
            codes=(0,))
    d = doc_of("compensate", p)
    check(d.get("exit") == 0 and d.get("input_format") == "rapid" and d.get("targets") == 2
          and d.get("corrected") == 2 and d.get("robtargets") == 1 and d.get("left_robtargets") == 0,
          "compensate, RAPID with a robtarget: 2 targets, both corrected, 1 of them a robtarget")
    run("compensate", "--model", w("cal.json"), "--in", w("targets.csv"), "--json", codes=(2,))


def grind():
    d = doc_of("grind", run("grind", "--model", w("cal.json"), "--truth", TRUTH, "--nominal", ROBOT, "--json"))
    check(d.get("points", 0) > 0 and "cases" in d, "grind: points and cases")


def report():
    d = doc_of("report", run("report", "--calibration", w("calib.json"), "--out", w("report.html"), "--json"))
    check(d.get("out") == w("report.html") and os.path.getsize(w("report.html")) > 1000, "report: the page written")


RUNS = {f.__name__: f for f in (simulate, fkcheck, calibrate, compare, chaos, poses, acquire, diagnose, evaluate,
                                bench, export, compensate, grind, report)}

helptext = subprocess.run([RCAL, "--help"], capture_output=True, text=True).stdout
listed = [m.group(1) for m in re.finditer(r"^  ([a-z]+) ", helptext.split("commands:")[1], re.M)]
check(len(listed) >= 14, "rcal --help lists %d commands" % len(listed))
t0 = time.time()
for name in RUNS:  # in this order: later runs read what earlier ones wrote
    if name in listed:
        RUNS[name]()
for name in listed:
    check(name in RUNS, "%s (listed by rcal --help) is run with --json here" % name)
print("%d commands in %.1f s" % (len(listed), time.time() - t0))
for s in skipped:
    print("SKIP  " + s)
if failures:
    print("%d FAILED" % len(failures))
    sys.exit(1)
sys.exit(77 if skipped else 0)
