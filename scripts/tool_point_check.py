#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Where a tool point 100 mm along the flange x axis lands on a TRUE robot
(a model file, e.g. data/sim_irb120_truth.json) for joint targets, against
where the program meant it (the nominal model at the original targets), and
the angle of the tool's axis (the flange z axis) against the meant one.

usage: scripts/tool_point_check.py TRUTH.json NOMINAL.json TARGET.csv [COMPENSATED.csv ...]
Each CSV holds lines of q1..q6 in degrees; the first is the original target
list, every further one a compensated version of it. Uses the Python package
(python/rcal, RCAL_FFI_LIB or the build tree's library)."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import rcal  # noqa: E402


def rows(path):
    out = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#") and line[0] not in "qQ":
                out.append([float(v) for v in line.split(",")[:6]])
    return out


def tool(model, q, nominal=False):
    p, r = model.fk(q, rotation=True, nominal=nominal)
    return [p[i] + 100.0 * r[3 * i] for i in range(3)]


def axis_deg(model, q, nominal=False):
    """The flange z axis (the tool's axis of a spindle or wheel on the flange) at q."""
    _, r = model.fk(q, rotation=True, nominal=nominal)
    return [r[3 * i + 2] for i in range(3)]


def angle_deg(a, b):
    c = sum(x * y for x, y in zip(a, b)) / math.sqrt(sum(x * x for x in a) * sum(y * y for y in b))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def main():
    if len(sys.argv) < 4:
        print(__doc__)
        return 2
    truth, nominal = rcal.Model.load(sys.argv[1]), rcal.Model.load(sys.argv[2])
    targets = rows(sys.argv[3])
    for path in sys.argv[3:]:
        qs = rows(path)
        errs = [math.dist(tool(truth, q), tool(nominal, t)) for q, t in zip(qs, targets)]
        axes = sorted(angle_deg(axis_deg(truth, q), axis_deg(nominal, t, nominal=True)) for q, t in zip(qs, targets))
        print("%-40s tool point error on the true robot: mean %.4f mm, max %.4f mm (%d targets); tool axis (flange "
              "z) median %.4f deg, max %.4f deg" % (path, sum(errs) / len(errs), max(errs), len(errs),
                                                    axes[len(axes) // 2], axes[-1]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
