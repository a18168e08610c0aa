#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""positions_convert - other tracker layouts into rcal's positions file (docs/positions.md).

One common layout keeps the joint readings and the tracker's positions apart:
a file of joint rows (one per pose: six angles, in degrees or radians, with
or without a header; extra leading columns such as a pose number are
skipped with --skip-cols) and a file of stacked position rows (x, y, z; N
targets per pose, the N rows of pose k following those of pose k-1, in
metres or millimetres). This writes one positions file:

    pose,target,q1,q2,q3,q4,q5,q6,x,y,z      (degrees, mm)

    python3 scripts/positions_convert.py --joints Q.csv --positions P.csv --targets 3 \\
        [--joints-unit deg|rad] [--positions-unit mm|m] [--skip-cols K] --out OUT.csv

Separators: comma, semicolon, tab or blanks. A row that is not numbers (a
header) is skipped only as the first line. Errors name the file and line.
Standard library only.
"""
import argparse
import math
import re
import sys


def rows(path, want, skip):
    out = []
    with open(path, newline="") as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            fields = [x for x in re.split(r"[,;\t ]+", line) if x != ""]
            try:
                vals = [float(x) for x in fields]
            except ValueError:
                if not out and n == 1:
                    continue  # a header
                sys.exit("%s:%d: not a number in %r" % (path, n, line[:60]))
            vals = vals[skip:]
            if len(vals) < want:
                sys.exit("%s:%d: %d values, %d needed" % (path, n, len(vals), want))
            if not all(math.isfinite(v) for v in vals[:want]):
                sys.exit("%s:%d: a value is not finite" % (path, n))
            out.append(vals[:want])
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--joints", required=True)
    ap.add_argument("--positions", required=True)
    ap.add_argument("--targets", type=int, required=True, help="position rows per pose (targets on the tool)")
    ap.add_argument("--joints-unit", choices=("deg", "rad"), default="deg")
    ap.add_argument("--positions-unit", choices=("mm", "m"), default="mm")
    ap.add_argument("--skip-cols", type=int, default=0, help="leading columns of the joints file to skip")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    if a.targets < 1 or a.targets > 16:
        sys.exit("--targets: 1..16")
    q = rows(a.joints, 6, a.skip_cols)
    p = rows(a.positions, 3, 0)
    if len(p) != a.targets * len(q):
        sys.exit("%s has %d position rows, %s has %d poses: %d x %d = %d expected" % (
            a.positions, len(p), a.joints, len(q), len(q), a.targets, a.targets * len(q)))
    qs = 180.0 / math.pi if a.joints_unit == "rad" else 1.0
    ps = 1000.0 if a.positions_unit == "m" else 1.0
    with open(a.out, "w") as f:
        f.write("pose,target,q1,q2,q3,q4,q5,q6,x,y,z\n")
        for k, qk in enumerate(q):
            for j in range(a.targets):
                x = p[k * a.targets + j]
                f.write("%d,%d,%s,%s\n" % (k, j, ",".join("%.9g" % (v * qs) for v in qk),
                                           ",".join("%.9g" % (v * ps) for v in x)))
    print("%s: %d poses x %d targets" % (a.out, len(q), a.targets))


if __name__ == "__main__":
    main()
