#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""plan_order.py - `rcal poses` orders its plan for joint travel (issue 48 item 5), on the README's plans.

For each plan (one outlet; three outlets; three with --split; a plate with --tool and three --cable-point;
the length criterion), the same seed is written twice: --order selection (the selection's order) and the
default --order travel. Checked here with this script's own reading of the CSVs (standard library only):
  - the rows are the same: per outlet and plate point the same multiset of poses, a joint differing only by
    whole turns where its range (less the 5 deg margin) spans more than 360 deg, inside the limits less it;
  - the columns and the rows per outlet unchanged; the pose on each plate point kept together;
  - the travel (sum over each outlet's and point's session, from home q = 0, of the largest joint move per
    move, deg) recomputed from both CSVs equals what --json reports as before_deg / after_deg;
  - after <= 0.6 x before (issue 48's must-show), and the report line printed.
Usage: plan_order.py RCAL SOURCE_DIR
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

RCAL, SRC = sys.argv[1], sys.argv[2]
ROBOT = os.path.join(SRC, "data", "irb120.json")
MARGIN = 5.0
PLANS = [
    ["--outlet", "250,-460,10"],
    ["--outlet", "250,-460,10", "--outlet", "-300,-400,10", "--outlet", "0,450,10"],
    ["--outlet", "250,-460,10", "--outlet", "-300,-400,10", "--outlet", "0,450,10", "--split"],
    ["--outlet", "250,-460,10", "--tool", "50,0,150", "--cable-point", "30,0,150", "--cable-point", "-30,0,150",
     "--cable-point", "0,30,150"],
    ["--outlet", "250,-460,10", "--criterion", "length"],
]


def limits():
    with open(ROBOT) as f:
        return json.load(f)["joint_limits_deg"]


def read(path):
    with open(path, newline="") as f:
        r = csv.reader(f)
        head = next(r)
        rows = [[float(x) for x in line] for line in r]
    return head, rows


def sessions(head, rows):
    oi = head.index("outlet") if "outlet" in head else None
    ti = head.index("target") if "target" in head else None
    s = {}
    for row in rows:
        key = (int(row[oi]) if oi is not None else 0, int(row[ti]) if ti is not None else 0)
        s.setdefault(key, []).append(row[1:7])
    return s


def travel(sess):
    total = 0.0
    for qs in sess.values():
        prev = [0.0] * 6
        for q in qs:
            total += max(abs(a - b) for a, b in zip(q, prev))
            prev = q
    return total


def canon(q, lim):
    """q with each wrapping joint reduced to (-180, 180]: equal for poses equal up to whole turns."""
    out = []
    for j, v in enumerate(q):
        lo, hi = lim[j]
        if hi - lo - 2 * MARGIN > 360.0:
            v = (v + 180.0) % 360.0 - 180.0
            v = 180.0 if abs(v + 180.0) < 1e-6 else v
        out.append(round(v, 4))
    return tuple(out)


def main():
    lim = limits()
    fails = []
    work = tempfile.mkdtemp(prefix="plan_order_")
    for k, args in enumerate(PLANS):
        name = " ".join(args)
        paths = {}
        reports = {}
        for order in ("selection", "travel"):
            paths[order] = os.path.join(work, "plan%d_%s.csv" % (k, order))
            cmd = [RCAL, "poses", "--robot", ROBOT, "--count", "60", "--out", paths[order], "--order", order] + args
            reports[order] = json.loads(subprocess.run(cmd + ["--json"], check=True, capture_output=True,
                                                       text=True).stdout)
        text = subprocess.run([RCAL, "poses", "--robot", ROBOT, "--count", "60", "--out",
                               os.path.join(work, "text.csv")] + args, check=True, capture_output=True,
                              text=True).stdout
        h0, r0 = read(paths["selection"])
        h1, r1 = read(paths["travel"])
        s0, s1 = sessions(h0, r0), sessions(h1, r1)
        jt = reports["travel"]["joint_travel"]
        t0, t1 = travel(s0), travel(s1)
        ratio = t1 / t0
        print("%-100s travel %.0f -> %.0f deg (%.2f)" % (name, t0, t1, ratio))
        if h0 != h1 or len(r0) != len(r1):
            fails.append("%s: columns or row count changed" % name)
        if reports["travel"]["rows_per_outlet"] != reports["selection"]["rows_per_outlet"]:
            fails.append("%s: rows per outlet changed" % name)
        if abs(jt["before_deg"] - t0) > 0.05 or abs(jt["after_deg"] - t1) > 0.05:
            fails.append("%s: --json travel %s against %.2f / %.2f recomputed" % (name, jt, t0, t1))
        if ratio > 0.6:
            fails.append("%s: travel ratio %.3f > 0.6" % (name, ratio))
        if "joint travel: %.0f deg before ordering, %.0f deg after" % (t0, t1) not in text:
            fails.append("%s: the report line is missing or differs" % name)
        for key in s0:
            a = sorted(canon(q, lim) for q in s0[key])
            b = sorted(canon(q, lim) for q in s1.get(key, []))
            if a != b:
                fails.append("%s: session %s holds other poses after ordering" % (name, key))
        for row in r1:
            for j in range(6):
                if not (lim[j][0] + MARGIN - 1e-6 <= row[1 + j] <= lim[j][1] - MARGIN + 1e-6):
                    fails.append("%s: q%d = %.2f outside the limits less the margin" % (name, j + 1, row[1 + j]))
        if "target" in h1:  # the pose on each plate point kept together
            ti = h1.index("target")
            npts = int(max(r[ti] for r in r1)) + 1
            for i in range(0, len(r1), npts):
                if any(r1[i + t][1:7] != r1[i][1:7] or int(r1[i + t][ti]) != t for t in range(npts)):
                    fails.append("%s: the pose at row %d is not on each point in turn" % (name, i))
                    break
    for f in fails:
        print("FAIL:", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
