#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""test_resid_report.py - `--residuals FILE.csv` (calibrate, evaluate,
compare, diagnose) and `--report FILE.html` (calibrate, diagnose), read by
Python's csv, json and re modules, not by rcal's code.

    test_resid_report.py RCAL SOURCE_DIR WORK_DIR

1. calibrate: every row of the residual CSV is the data line it names (q and
   L read from the input with the csv module), residual_mm = measured_mm -
   predicted_mm, and the RMS of the test rows and of the train rows equals
   the held-out and training RMSE the JSON prints (rmse_full_mm), to 1e-9 mm;
   with two --data files the file column names the right one.
2. Refusals: --residuals naming the --data file (directly and through a
   symbolic link) exits 2 and leaves the data byte for byte unchanged.
3. evaluate: RMS of the residuals = the JSON's residual RMSE, to 1e-9 mm.
4. compare: case 1's rows (n_test test, n_train train, case 1) and each
   method's held-out RMS = case 1's RMSE of the JSON (printed to 1e-6).
5. diagnose: the cross-validated geometry residuals' RMS = rmse_before_mm
   (printed with 6 digits).
6. --report: the page exists, is self-contained (no src/href to http(s)://),
   holds the parameter table with every DH parameter name, and its JSON
   beside it is what --json prints.
"""
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from rct_check import check, failures  # noqa: E402

RCAL, SRC, WORK = sys.argv[1:4]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
DATA = os.path.join(SRC, "data", "sim_irb120.csv")
ROBOT = os.path.join(SRC, "data", "irb120.json")


def w(name):
    return os.path.join(WORK, name)


def run(*args, expect=0):
    p = subprocess.run([RCAL, *args], capture_output=True, text=True, timeout=120)
    if p.returncode != expect:
        print(p.stdout[-2000:], p.stderr[-2000:])
    check(p.returncode == expect, "rcal %s -> exit %d (got %d)" % (" ".join(args), expect, p.returncode))
    return p


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def data_lines(path):
    """{1-based line: row dict} of a data file, by the csv module."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    return {k + 2: dict(zip(head, r)) for k, r in enumerate(rows[1:])}


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")


def fl(s):
    return float(s) if s != "" else float("nan")


# 1. calibrate, one file
p = run("calibrate", "--data", DATA, "--robot", ROBOT, "--json", "--residuals", w("cal_res.csv"))
cal = json.loads(p.stdout)
res = read_csv(w("cal_res.csv"))
lines = data_lines(DATA)
check(len(res) == 600 and "file" not in res[0], "calibrate: 600 rows, no file column for one file")
worst_row = worst_diff = 0.0
for r in res:
    src = lines[int(r["row"])]
    worst_row = max([worst_row, abs(fl(r["measured_mm"]) - float(src["L"]))] +
                    [abs(fl(r["q%d" % j]) - float(src["q%d" % j])) for j in range(1, 7)])
    worst_diff = max(worst_diff, abs(fl(r["residual_mm"]) - (fl(r["measured_mm"]) - fl(r["predicted_mm"]))))
check(worst_row < 1e-9, "calibrate: each row's q and L are its data line's (worst %.3g)" % worst_row)
check(worst_diff < 1e-12, "calibrate: residual_mm = measured_mm - predicted_mm (worst %.3g mm)" % worst_diff)
test = [fl(r["measured_mm"]) - fl(r["predicted_mm"]) for r in res if r["set"] == "test"]
train = [fl(r["measured_mm"]) - fl(r["predicted_mm"]) for r in res if r["set"] == "train"]
check((len(test), len(train)) == (cal["n_test"], cal["n_train"]), "calibrate: sets as the split (%d test, %d train)"
      % (len(test), len(train)))
d_test = abs(rms(test) - cal["after"]["rmse_full_mm"])
d_train = abs(rms(train) - cal["train_after"]["rmse_full_mm"])
print("      held-out RMS from the CSV %.12f mm, JSON %.12f mm" % (rms(test), cal["after"]["rmse_full_mm"]))
check(d_test < 1e-9 and d_train < 1e-9, "calibrate: RMS of test and train residuals = JSON's to 1e-9 mm (%.3g, %.3g)"
      % (d_test, d_train))
check(abs(round(rms(test), 6) - cal["after"]["rmse_mm"]) < 1.5e-6, "calibrate: and its 6-digit rmse_mm")

# 1b. two files: the file column, rows numbered in each file
with open(DATA) as f:
    text = f.read().strip().split("\n")
for name, part in (("a.csv", text[:301]), ("b.csv", [text[0]] + text[301:])):
    with open(w(name), "w") as f:
        f.write("\n".join(part) + "\n")
run("calibrate", "--data", w("a.csv"), "--data", w("b.csv"), "--robot", ROBOT, "--json", "--residuals",
    w("two_res.csv"))
two = read_csv(w("two_res.csv"))
files = {w("a.csv"): data_lines(w("a.csv")), w("b.csv"): data_lines(w("b.csv"))}
ok = len(two) == 600 and all(abs(fl(r["measured_mm"]) - float(files[r["file"]][int(r["row"])]["L"])) < 1e-9
                             for r in two)
check(ok, "calibrate, two --data: the file column and row name each sample's line")

# 1c. validate rows
run("calibrate", "--data", w("a.csv"), "--validate", w("b.csv"), "--robot", ROBOT, "--json", "--residuals",
    w("val_res.csv"))
check(sum(r["set"] == "validate" for r in read_csv(w("val_res.csv"))) == 300, "calibrate --validate: 300 validate rows")

# 2. refusals
before = open(DATA, "rb").read()
run("calibrate", "--data", DATA, "--robot", ROBOT, "--residuals", DATA, expect=2)
shutil.copy(DATA, w("copy.csv"))
os.symlink(w("copy.csv"), w("link.csv"))
run("calibrate", "--data", w("copy.csv"), "--robot", ROBOT, "--residuals", w("link.csv"), expect=2)
check(open(DATA, "rb").read() == before and open(w("copy.csv"), "rb").read() == before,
      "refusals: the data files unchanged")
run("evaluate", "--model", ROBOT, "--data", w("copy.csv"), "--residuals", w("link.csv"), expect=1)
check(open(w("copy.csv"), "rb").read() == before, "evaluate refusal: the data file unchanged")

# 3. evaluate
run("calibrate", "--data", w("a.csv"), "--robot", ROBOT, "--out", w("model.json"), "--json")
ev = json.loads(run("evaluate", "--model", w("model.json"), "--data", w("b.csv"), "--json", "--residuals",
                    w("ev_res.csv")).stdout)
er = read_csv(w("ev_res.csv"))
d_ev = abs(rms([fl(r["residual_mm"]) for r in er]) - ev["residual"]["rmse_mm"])
check(len(er) == 300 and all(r["set"] == "validate" for r in er) and d_ev < 1e-9,
      "evaluate: 300 validate rows, RMS = JSON's to 1e-9 mm (%.3g)" % d_ev)

# 4. compare
cmp_doc = json.loads(run("compare", "--data", DATA, "--robot", ROBOT, "--cases", "2", "--samples", "120",
                         "--methods", "LM,LTLM", "--json", "--residuals", w("cmp_res.csv")).stdout)
cr = read_csv(w("cmp_res.csv"))
check(len(cr) == 120 and all(r["case"] == "1" for r in cr)
      and sum(r["set"] == "test" for r in cr) == cmp_doc["n_test"], "compare: case 1's 120 rows, n_test held out")
names = [m["name"] for m in cmp_doc["methods"]]
for k, name in enumerate(names):
    col = "residual_mm" if name == "BC" else "residual_after_%s_mm" % name
    got = rms([fl(r[col]) for r in cr if r["set"] == "test"])
    want = cmp_doc["cases_rmse_mm"][0][k]
    check(abs(got - want) < 1.5e-6, "compare: %s held-out RMS of case 1 %.6f = JSON %.6f" % (name, got, want))

# 5. diagnose
dg = json.loads(run("diagnose", "--data", DATA, "--robot", ROBOT, "--folds", "2", "--steps", "1", "--json",
                    "--residuals", w("dg_res.csv")).stdout)
dr = read_csv(w("dg_res.csv"))
geo = rms([fl(r["residual_after_geometry_cv_mm"]) for r in dr])
check(len(dr) == 600 and abs(geo - dg["rmse_before_mm"]) <= 1e-5 * dg["rmse_before_mm"],
      "diagnose: cross-validated geometry RMS %.6g = rmse_before_mm %.6g" % (geo, dg["rmse_before_mm"]))


# 6. --report
def self_contained(path):
    with open(path) as f:
        html = f.read()
    bad = re.findall(r"""(?:src|href)\s*=\s*["']?\s*(?:https?:)?//""", html, re.I)
    return html, not bad


p = run("calibrate", "--data", DATA, "--robot", ROBOT, "--out", w("rep_model.json"), "--report", w("cal.html"),
        "--json")
html, ok = self_contained(w("cal.html"))
check(ok, "calibrate --report: no src/href leaves the file")
params = re.search(r'<section id="params">(.*?)</section>', html, re.S)
check(params is not None and "<table" in params.group(1), "calibrate --report: a parameter table")
check(params is not None and all(re.search(r"\b%s%d\b" % (n, j), params.group(1))
                                 for n in ("a", "d", "alpha", "theta") for j in range(1, 7)),
      "calibrate --report: every DH parameter in it")
beside = json.load(open(w("cal.calibration.json")))
printed = json.loads(p.stdout)
for doc in (beside, printed):
    doc.pop("time_ms")
    doc["provenance"].pop("date")
check(beside == printed, "calibrate --report: the JSON beside the page is what --json printed")
run("calibrate", "--data", DATA, "--robot", ROBOT, "--report", DATA, expect=2)
check(open(DATA, "rb").read() == before, "calibrate --report over --data refused, data unchanged")
# the JSON kept beside the page never replaces an input either (a data file
# that happens to carry its name); since issue 23 refused before the work (exit 2)
shutil.copyfile(DATA, w("named.calibration.json"))
named_before = open(w("named.calibration.json"), "rb").read()
run("calibrate", "--data", w("named.calibration.json"), "--robot", ROBOT, "--report", w("named.html"), expect=2)
check(open(w("named.calibration.json"), "rb").read() == named_before,
      "calibrate --report: the data file named like its JSON is refused and unchanged")
run("diagnose", "--data", w("named.calibration.json"), "--robot", ROBOT, "--folds", "2", "--steps", "1",
    "--report", w("named.html"), expect=2)
check(open(w("named.calibration.json"), "rb").read() == named_before,
      "diagnose --report: the data file named like its JSON is refused and unchanged")
run("diagnose", "--data", DATA, "--robot", ROBOT, "--folds", "2", "--steps", "1", "--report", w("dg.html"))
html, ok = self_contained(w("dg.html"))
check(ok and os.path.exists(w("dg.diagnosis.json")) and '<section id="diagnosis">' in html
      and '<section id="params">' in html, "diagnose --report: self-contained page with diagnosis and parameters")

if failures:
    print("%d FAILED" % len(failures))
    sys.exit(1)
print("all passed")
