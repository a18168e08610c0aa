#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""test_models_readable.py - every model the tools write is read back by the
tools (issue 33, item 7): `rcal compare --models` with and without --prior
(BC and all seven methods), each model read by `rcal grind --models`,
`rcal compensate` (with --uncertainty-out), `rcal export` and, when the
library is given, the Python API (load, compensate). An undetermined DH
parameter (a no-prior fit's weak direction, a standard error above 1 m or
1 rad) is written as such: named in "uncertainty"."undetermined", its
std_error and its covariance rows and columns null. Files written before
(the huge number in place of null) are still read; a file whose compensation
says it uses an undetermined parameter is refused with its position.

usage: test_models_readable.py RCAL SOURCE_DIR WORK_DIR [FFI_LIB]"""
import json
import os
import shutil
import subprocess
import sys

RCAL, SRC, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
FFI = sys.argv[4] if len(sys.argv) > 4 else ""
DATA = os.path.join(SRC, "data", "sim_irb120.csv")
TRUTH = os.path.join(SRC, "data", "sim_irb120_truth.json")
NAMES = ["BC"] + ["M%d-%s" % (i + 1, n) for i, n in enumerate(["LM", "EKF", "PF", "SCA", "QIBAS", "SSLM", "LTLM"])]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(args):
    p = subprocess.run([RCAL] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def read_errors(err, cmd):
    """stderr lines that are errors of the command, not per-target warnings"""
    return [l for l in err.splitlines() if l.startswith("rcal %s:" % cmd)]


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
targets = os.path.join(WORK, "targets.csv")
with open(targets, "w") as f:
    f.write("0,0,0,0,30,0\n10,20,-10,0,40,30\n-30,10,20,40,-50,90\n")

n_undetermined = 0
for label, extra in (("no-prior", []), ("prior", ["--prior"])):
    d = os.path.join(WORK, label)
    rc, out, err = run(["compare", "--data", DATA, "--cases", "1", "--models", d] + extra)
    check(rc == 0, "%s: rcal compare --models exit %d %s" % (label, rc, err.strip()[-300:]))
    for n in NAMES:
        check(os.path.exists(os.path.join(d, n + ".json")), "%s: %s.json written" % (label, n))
    rc, out, err = run(["grind", "--models", d, "--truth", TRUTH])
    check(rc == 0, "%s: rcal grind --models reads every model (exit %d) %s" % (label, rc, err.strip()[-300:]))
    for n in NAMES:
        path = os.path.join(d, n + ".json")
        if not os.path.exists(path):
            continue
        m = json.load(open(path))
        u = m.get("uncertainty", {})
        und = u.get("undetermined", [])
        n_undetermined += len(und)
        if u:
            cov = u["covariance_dh"]
            names = [p["name"] for p in u["parameters"]][:24]
            for k in range(24):
                v = cov[k * 24 + k]
                lim = 1e6 if k % 4 < 2 else 1.0
                check((v is None) == (names[k] in und) and (v is None or 0 <= v <= lim),
                      "%s/%s: %s variance %r: a calibrated one or null and listed" % (label, n, names[k], v))
            for p in u["parameters"]:
                if p["name"] in und:
                    check(p["std_error"] is None and p["compensation"] == "nominal",
                          "%s/%s: undetermined %s: std_error null, held nominal" % (label, n, p["name"]))
        u95 = os.path.join(d, n + ".u95.csv")
        rc, out, err = run(["compensate", "--model", path, "--in", targets, "--uncertainty-out", u95])
        check(not read_errors(err, "compensate") and len(out.splitlines()) == 3,
              "%s/%s: rcal compensate reads it (exit %d) %s" % (label, n, rc, err.strip()[-300:]))
        rc, out, err = run(["export", "--model", path, "--format", "dh-csv", "--out", os.path.join(d, n + ".csv")])
        check(rc == 0, "%s/%s: rcal export reads it %s" % (label, n, err.strip()[-300:]))
        rc, out, err = run(["export", "--model", path, "--format", "urdf", "--out", os.path.join(d, n + ".urdf")])
        check(rc == 0, "%s/%s: rcal export --format urdf reads it %s" % (label, n, err.strip()[-300:]))
        rc, out, err = run(["evaluate", "--model", path, "--data", DATA])
        check(not read_errors(err, "evaluate") or rc == 0,
              "%s/%s: rcal evaluate reads it (exit %d) %s" % (label, n, rc, err.strip()[-300:]))
check(n_undetermined > 0, "some model has an undetermined parameter (%d): the case of issue 33 is exercised"
      % n_undetermined)

# a file written before: the huge variance in place of null, no list: still read
src = None
for n in NAMES:
    path = os.path.join(WORK, "no-prior", n + ".json")
    if os.path.exists(path) and json.load(open(path)).get("uncertainty", {}).get("undetermined"):
        src = path
        break
if src:
    m = json.load(open(src))
    u = m["uncertainty"]
    und = u.pop("undetermined")
    names = [p["name"] for p in u["parameters"]][:24]
    cov = u["covariance_dh"]
    for i in range(24):
        for j in range(24):
            if cov[i * 24 + j] is None:
                cov[i * 24 + j] = 2.6e7 if i == j and i % 4 < 2 else 12.9 if i == j else 0.0
    for p in u["parameters"]:
        if p["name"] in und:
            p["std_error"] = 5000.0
    old = os.path.join(WORK, "old.json")
    json.dump(m, open(old, "w"), indent=1)
    rc, out, err = run(["compensate", "--model", old, "--in", targets])
    check(not read_errors(err, "compensate"), "a file written before (huge variance, no list) is read %s" % err.strip())
    # compensation "fitted" on a listed undetermined parameter: refused, with its position
    m = json.load(open(src))
    for p in m["uncertainty"]["parameters"]:
        if p["name"] == und[0]:
            p["compensation"] = "fitted"
    bad = os.path.join(WORK, "bad.json")
    json.dump(m, open(bad, "w"), indent=1)
    rc, out, err = run(["compensate", "--model", bad, "--in", targets])
    check(rc != 0 and "undetermined" in err and "bad.json:" in err,
          "compensation fitted on an undetermined parameter is refused: %s" % err.strip())
    # null outside an undetermined row: refused
    m = json.load(open(src))
    m["uncertainty"]["covariance_dh"][0] = None
    json.dump(m, open(bad, "w"), indent=1)
    rc, out, err = run(["compensate", "--model", bad, "--in", targets])
    check(rc != 0 and "covariance_dh" in err, "null outside an undetermined row is refused: %s" % err.strip())

if FFI:
    os.environ["RCAL_FFI_LIB"] = FFI
    sys.path.insert(0, os.path.join(SRC, "python"))
    import rcal
    import math
    for label in ("no-prior", "prior"):
        for n in NAMES:
            path = os.path.join(WORK, label, n + ".json")
            try:
                model = rcal.Model.load(path)
                c = rcal.compensate(model, [[0, 0, 0, 0, 30, 0], [10, 20, -10, 0, 40, 30]], details=True)
                check(len(c.q_deg) == 2 and all(math.isnan(v) or v >= 0 for v in c.u95_mm),
                      "python %s/%s: load and compensate (u95 %s)" % (label, n, list(c.u95_mm)))
            except Exception as e:  # noqa: BLE001 - any failure is the finding
                check(False, "python %s/%s: %s" % (label, n, e))

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
