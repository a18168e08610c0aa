#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Runs the documented cell loop (issue 48): the ```sh block after the line starting `<!-- cell loop:` in DOC
(docs/controller-link.md, "The cell loop"; the README's when it moves there), as a user pastes it, from a work
directory that looks like the repository root after the build (build/, data/, tests/ linked in). Asserts the
block ends with status 0 and did what it says: the plan's 30 poses x 3 outlets all recorded once in cell.csv
with the controller's joints beside the plan's, the RAPID program holds the plan's joints, each acquisition
printed the link's summary with no fault, and the calibration wrote its model without --dequantize-joints.
usage: doc_cell_loop.py DOC SOURCE_DIR BINARY_DIR WORK_DIR"""
import csv
import os
import re
import shutil
import signal
import subprocess
import sys

DOC, SRC, BIN, W = [os.path.abspath(a) for a in sys.argv[1:5]]


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


text = open(DOC).read()
m = re.search(r"^<!-- cell loop:.*?\n```sh\n(.*?)\n```", text, re.S | re.M)
if not m:
    fail("%s: no ```sh block after a line '<!-- cell loop: ...'" % DOC)
block = m.group(1)
shutil.rmtree(W, ignore_errors=True)
os.makedirs(W)
for name, target in (("build", BIN), ("data", os.path.join(SRC, "data")), ("tests", os.path.join(SRC, "tests"))):
    os.symlink(target, os.path.join(W, name))
with open(os.path.join(W, "block.sh"), "w") as f:
    f.write("set -e\n" + block + "\n")
p = subprocess.Popen(["bash", "block.sh"], cwd=W, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                     start_new_session=True)
try:
    out, _ = p.communicate(timeout=240)
except subprocess.TimeoutExpired:
    os.killpg(p.pid, signal.SIGKILL)
    fail("the block did not end within 240 s")
finally:
    try:
        os.killpg(p.pid, signal.SIGTERM)  # a display or controller left over
    except ProcessLookupError:
        pass
if p.returncode != 0:
    print(out[-6000:])
    fail("the block ended with status %d" % p.returncode)
print("\n".join(x for x in out.splitlines() if x.startswith("rcal acquire:") or "RMSE" in x or "written" in x))

os.chdir(W)
plan = list(csv.DictReader(open("plan.csv")))
rows = list(csv.DictReader(open("cell.csv")))
keys = [(int(r["pose"]), int(r["outlet"])) for r in rows]
want = {(int(r["pose"]), int(r["outlet"])) for r in plan}
if len(plan) != 90 or len(keys) != len(set(keys)) or set(keys) != want:
    fail("cell.csv: %d rows, %d distinct, the plan %d" % (len(keys), len(set(keys)), len(plan)))
if "q1_plan" not in rows[0]:
    fail("cell.csv has no q1_plan column: %s" % list(rows[0]))
mod = open("rcal_link.mod").read()
targets = re.findall(r"CONST jointtarget rcal_p(\d+):=\[\[([^\]]*)\]", mod)
if len(targets) != len(plan):
    fail("rcal_link.mod: %d jointtargets, the plan %d" % (len(targets), len(plan)))
for (i, vals), r in zip(targets, plan):
    q = [float(v) for v in vals.split(",")]
    if int(i) != int(r["pose"]) or max(abs(a - float(r["q%d" % (j + 1)])) for j, a in enumerate(q)) > 1e-4:
        fail("rcal_link.mod: pose %s is not the plan's: %s vs %s" % (i, vals, r))
links = re.findall(r"controller link \S+: (\d+) connections?; faults:((?: \w+ \d+)+)", out)
if len(links) != 3 or any(set(re.findall(r" \w+ (\d+)", f)) != {"0"} for _, f in links):
    fail("the link summaries: %s" % links)
if not os.path.exists("cell_model.json") or "dequantiz" in out.lower():
    fail("the calibration wrote no model, or asked to dequantize the joints")
print("ok: the cell loop block ran: 90 rows, 3 link summaries without fault, the program the plan's, a model")
