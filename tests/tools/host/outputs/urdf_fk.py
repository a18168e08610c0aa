#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""urdf_fk.py - flange position from a URDF's joint origins, independent of rcal.

Reads the URDF with xml.etree (Python's own XML parser), walks the kinematic
tree from the root link to its single leaf link, and composes for each joint
    T = T * origin(xyz, rpy) * rotation(axis, q)     (revolute, continuous)
    T = T * origin(xyz, rpy)                          (fixed)
with URDF's conventions (rpy fixed-axis: R = Rz(yaw) Ry(pitch) Rx(roll),
lengths in metres). Pure-Python 3x3 / 3-vector arithmetic, no numpy, no rcal
code.

    urdf_fk.py URDF FK.csv [TOL_MM]

FK.csv holds rcal's forward kinematics (tests/tools/host/outputs/fk_dump): lines
"q1..q6 (rad), x, y, z (mm)". Prints the largest distance between the URDF's
flange and rcal's over the lines; exit 0 when it is <= TOL_MM (1e-6), 1 when
it is larger, 2 on a malformed URDF.
"""
import math
import sys
import xml.etree.ElementTree as ET


def mat_mul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


def mat_vec(a, v):
    return [sum(a[r][k] * v[k] for k in range(3)) for r in range(3)]


def rot_rpy(roll, pitch, yaw):
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rx = [[1, 0, 0], [0, cr, -sr], [0, sr, cr]]
    ry = [[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]
    rz = [[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]
    return mat_mul(rz, mat_mul(ry, rx))


def rot_axis(axis, q):
    """Rodrigues: rotation by q about the unit vector axis."""
    n = math.sqrt(sum(c * c for c in axis))
    x, y, z = (c / n for c in axis)
    c, s, t = math.cos(q), math.sin(q), 1 - math.cos(q)
    return [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]


def floats(text, default):
    if text is None:
        return default
    vals = [float(v) for v in text.split()]
    if len(vals) != 3:
        raise ValueError("expected three numbers, got %r" % text)
    return vals


def chain(urdf_path):
    """The joints from the root link to the single leaf, in order."""
    root = ET.parse(urdf_path).getroot()
    if root.tag != "robot":
        raise ValueError("root element is not <robot>")
    joints = root.findall("joint")
    by_parent = {}
    children = set()
    for j in joints:
        parent = j.find("parent").get("link")
        child = j.find("child").get("link")
        by_parent.setdefault(parent, []).append(j)
        children.add(child)
    roots = [lk.get("name") for lk in root.findall("link") if lk.get("name") not in children]
    if len(roots) != 1:
        raise ValueError("expected one root link, found %r" % roots)
    out, link = [], roots[0]
    while link in by_parent:
        if len(by_parent[link]) != 1:
            raise ValueError("link %r has %d child joints" % (link, len(by_parent[link])))
        j = by_parent[link][0]
        out.append(j)
        link = j.find("child").get("link")
    return out


def flange_mm(joints, q):
    R = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    p = [0.0, 0.0, 0.0]
    k = 0
    for j in joints:
        o = j.find("origin")
        xyz = floats(o.get("xyz") if o is not None else None, [0.0, 0.0, 0.0])
        rpy = floats(o.get("rpy") if o is not None else None, [0.0, 0.0, 0.0])
        p = [p[r] + d for r, d in enumerate(mat_vec(R, xyz))]
        R = mat_mul(R, rot_rpy(*rpy))
        kind = j.get("type")
        if kind in ("revolute", "continuous"):
            ax = j.find("axis")
            axis = floats(ax.get("xyz") if ax is not None else None, [1.0, 0.0, 0.0])
            R = mat_mul(R, rot_axis(axis, q[k]))
            k += 1
        elif kind != "fixed":
            raise ValueError("joint type %r not handled" % kind)
    if k != len(q):
        raise ValueError("the URDF has %d movable joints, FK.csv %d" % (k, len(q)))
    return [1000.0 * v for v in p]


def main(argv):
    if len(argv) not in (3, 4):
        sys.stderr.write(__doc__)
        return 2
    tol = float(argv[3]) if len(argv) == 4 else 1e-6
    try:
        joints = chain(argv[1])
    except (ET.ParseError, ValueError, AttributeError) as e:
        print("urdf_fk: %s: %s" % (argv[1], e))
        return 2
    worst, n = 0.0, 0
    with open(argv[2]) as f:
        for line in f:
            v = [float(t) for t in line.split(",")]
            p = flange_mm(joints, v[:6])
            worst = max(worst, math.sqrt(sum((p[r] - v[6 + r]) ** 2 for r in range(3))))
            n += 1
    print("urdf_fk: %s: %d poses, max |flange(URDF) - rcal FK| = %.3g mm (tolerance %g)"
          % (argv[1], n, worst, tol))
    return 0 if n > 0 and worst <= tol else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
