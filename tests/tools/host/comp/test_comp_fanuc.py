#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""rcal compensate on Fanuc LS programs, judged by Fanuc's conventions written
here apart from rcal's code (issue 51): this file's own LS parser (regular
expressions), its own forward kinematics from the robot file's DH table, its
own controller joint map (the pendant's J3 from the horizon), its own W, P, R
(R = Rz(r) Ry(p) Rx(w)), its own CONFIG letters and turn numbers and its own
inverse kinematics (Newton from fixed starts, branch by the letters).

A simulated true robot (the LR Mate 200iD's table perturbed, seeded) is the
calibrated model. The committed program tests/tools/host/comp/data/fanuc/every_form.ls
(every instruction form, joint and Cartesian positions, UF/UT 0 and 1, every
CONFIG letter, turn numbers -1..1) is compensated with it, and for each
position the true robot driven by the compensated position as the controller
reads it (the nominal IK of the corrected pose on the branch and turns its
CONFIG names; the joints themselves for a joint position) must land where the
nominal robot puts the original: within 0.001 mm and 1e-6 rad. Every byte
outside the numbers is unchanged (LF and CRLF). Wrong input is refused with
file:line:col and nothing written.

usage: test_comp_fanuc.py RCAL REPO_ROOT"""
import json
import os
import random
import re
import subprocess
import sys
import tempfile

import numpy as np

D = np.pi / 180.0
TOL_MM, TOL_RAD = 1e-3, 1e-6


# ---- the robot: DH table and the controller's joint map ----

def dh_fk(dh, q, upto=6):
    """Standard DH: T_i = Rz(theta + q) Tz(d) Tx(a) Rx(alpha)."""
    T = np.eye(4)
    for i in range(upto):
        a, d, al, th = dh[i]
        th += q[i]
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                          [0, sa, ca, d], [0, 0, 0, 1.0]])
    return T


def read_robot(path):
    r = json.load(open(path))
    dh = [(row["a_mm"], row["d_mm"], row["alpha_deg"] * D, row["theta_deg"] * D) for row in r["dh"]]
    ctl = r.get("controller", {})
    sign = np.array(ctl.get("joint_sign", [1] * 6), float)
    zero = np.array(ctl.get("joint_zero_deg", [0] * 6), float) * D
    k = float(ctl.get("q3_coupling", 0.0))
    lim = np.array(r["joint_limits_deg"], float) * D
    return dh, (sign, zero, k), lim


def ctrl_to_model(J_rad, cm):
    sign, zero, k = cm
    q = sign * (np.asarray(J_rad) - zero)
    q[2] += k * q[1]
    return q


def model_to_ctrl(q, cm):
    sign, zero, k = cm
    q = np.array(q, float)
    q[2] -= k * q[1]
    return q / sign + zero


# ---- W, P, R ----

def rx(a):
    return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])


def ry(a):
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def rz(a):
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


def xyzwpr(v):
    T = np.eye(4)
    T[:3, :3] = rz(v[5] * D) @ ry(v[4] * D) @ rx(v[3] * D)
    T[:3, 3] = v[:3]
    return T


def rot_angle(Ra, Rb):
    c = (np.trace(Ra.T @ Rb) - 1) / 2
    s = np.linalg.norm(np.array([Ra.T @ Rb - Rb.T @ Ra])[0][[2, 0, 1], [1, 2, 0]]) / 2
    return float(np.arctan2(s, c))


# ---- Fanuc's CONFIG ----

def fanuc_config(dh, q, cm):
    """Letters and turns of model joints q: F when the pendant's J5 is negative
    (wrist flipped); U when the elbow (axis 3) is on the upper side of the line
    from axis 2 to the wrist centre in the arm's plane; T (front) when the wrist
    centre is ahead of axis 1 along the arm's direction; turns of J1, J4, J6:
    J in (-180, 180] + 360 t."""
    J = model_to_ctrl(q, cm) / D
    f = np.array([np.cos(q[0] + dh[0][3]), np.sin(q[0] + dh[0][3]), 0.0])
    o1 = dh_fk(dh, q, 1)[:3, 3]
    o2 = dh_fk(dh, q, 2)[:3, 3]
    wc = dh_fk(dh, q, 4)[:3, 3]
    u, v = o2 - o1, wc - o1
    up = (u @ f) * v[2] - u[2] * (v @ f) < 0
    j5 = (J[4] + 180) % 360 - 180
    letters = ("F" if j5 < 0 else "N") + ("U" if up else "D") + ("T" if wc @ f > 0 else "B")
    turns = tuple(int(np.ceil((J[k] - 180) / 360 - 1e-12)) for k in (0, 3, 5))
    return letters, turns


# ---- inverse kinematics (Newton, own Jacobian by differences) ----

def pose_err(T, G):
    e = np.zeros(6)
    e[:3] = G[:3, 3] - T[:3, 3]
    R = G[:3, :3] @ T[:3, :3].T
    e[3:] = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return e


def newton(dh, G, q0, iters=40):
    q = np.array(q0, float)
    for _ in range(iters):
        T = dh_fk(dh, q)
        e = pose_err(T, G)
        if np.linalg.norm(e[:3]) < 1e-11 and np.linalg.norm(e[3:]) < 1e-13:
            return q
        Jm = np.zeros((6, 6))
        for j in range(6):
            dq = np.zeros(6)
            dq[j] = 1e-7
            Jm[:, j] = pose_err(T, dh_fk(dh, q + dq)) / 1e-7  # the pose's change per joint step
        try:
            step = np.linalg.solve(Jm, e)
        except np.linalg.LinAlgError:
            return None
        q = q + np.clip(step, -0.5, 0.5)
    T = dh_fk(dh, q)
    e = pose_err(T, G)
    return q if np.linalg.norm(e[:3]) < 1e-8 and np.linalg.norm(e[3:]) < 1e-10 else None


def ik(dh, cm, G, letters, turns, seeds):
    sols = []
    for s in seeds:
        q = newton(dh, G, s)
        if q is None:
            continue
        q = (q + np.pi) % (2 * np.pi) - np.pi
        if fanuc_config(dh, q, cm)[0] == letters:
            sols.append(q)
            break
    if not sols:
        return None
    J = model_to_ctrl(sols[0], cm) / D
    for t, k in zip(turns, (0, 3, 5)):
        a = (J[k] + 180) % 360 - 180
        if a == -180:
            a = 180
        J[k] = a + 360 * t
    return ctrl_to_model(J * D, cm)


SEEDS = [np.array([a, b, c, d, e, 0.0]) * D for a in (0, 90, -90, 180) for b in (-60, 0, 60)
         for c in (-120, 0, 90) for d in (-90, 90) for e in (-60, 60)]


# ---- the LS parser ----

NUM = r"[-+]?\d*\.?\d+"
POS_RE = re.compile(r"P\[(\d+)(?::\"[^\"]*\")?\]\{\s*GP1:\s*UF\s*:\s*(\d+),\s*UT\s*:\s*(\d+),\s*(.*?)\};", re.S)
CFG_RE = re.compile(r"CONFIG\s*:\s*'([NF])\s+([UD])\s+([TB]),\s*(" + NUM + r"),\s*(" + NUM + r"),\s*(" + NUM + r")'")
FIELD_RE = re.compile(r"\b(X|Y|Z|W|P|R|J[1-6])\s*=\s*(" + NUM + r")\s*(mm|deg)")


def parse_ls(text):
    pos = {}
    body = text[text.index("/POS"):]
    for m in POS_RE.finditer(body):
        idx, uf, ut, rest = int(m.group(1)), int(m.group(2)), int(m.group(3)), m.group(4)
        f = {k: float(v) for k, v, _ in FIELD_RE.findall(rest)}
        c = CFG_RE.search(rest)
        if c:
            pos[idx] = dict(uf=uf, ut=ut, joint=False, letters="".join(c.group(1, 2, 3)),
                            turns=tuple(int(float(c.group(k))) for k in (4, 5, 6)),
                            v=np.array([f[k] for k in "XYZWPR"]))
        else:
            pos[idx] = dict(uf=uf, ut=ut, joint=True, v=np.array([f["J%d" % k] for k in range(1, 7)]))
    return pos


def tokens_outside_numbers(text):
    """The program with every position number replaced by '#': what must not change."""
    head, body = text[:text.index("/POS")], text[text.index("/POS"):]
    def hide(m, groups):
        s, at, o = m.group(0), 0, m.start(0)
        out = ""
        for g in groups:
            out += s[at:m.start(g) - o] + "#"
            at = m.end(g) - o
        return out + s[at:]

    body = FIELD_RE.sub(lambda m: hide(m, (2,)), body)
    body = CFG_RE.sub(lambda m: hide(m, (4, 5, 6)), body)
    return head + body


def read_frames(path):
    fr = {("uframe", 0): np.eye(4), ("utool", 0): np.eye(4)}
    for line in open(path):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        k, n, *v = line.split(",")
        fr[(k, int(n))] = xyzwpr(np.array(v, float))
    return fr


# ---- the checks ----

def run(rcal, *args):
    p = subprocess.run([rcal, "compensate", *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def check_program(rcal, prog, frames_path, nominal_path, cal_path, tmp, label):
    dh_nom, cm, lim = read_robot(nominal_path)
    dh_cal, _, _ = read_robot(cal_path)
    out = os.path.join(tmp, "out_" + label + ".ls")
    rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", prog, "--out", out,
                     "--fanuc-frames", frames_path, "--full-pose")
    assert rc == 0, (rc, se)
    src, dst = open(prog, newline="").read(), open(out, newline="").read()
    assert tokens_outside_numbers(src) == tokens_outside_numbers(dst), "bytes outside the numbers changed"
    assert src != dst
    fr = read_frames(frames_path)
    p0, p1 = parse_ls(src), parse_ls(dst)
    assert sorted(p0) == sorted(p1) and len(p0) == 11, sorted(p0)
    worst_mm = worst_rad = 0.0
    n_cart = 0
    for idx in sorted(p0):
        a, b = p0[idx], p1[idx]
        UT = fr[("utool", a["ut"])]
        if a["joint"]:
            q0 = ctrl_to_model(a["v"] * D, cm)
            q1 = ctrl_to_model(b["v"] * D, cm)
            want = dh_fk(dh_nom, q0) @ UT
            got = dh_fk(dh_cal, q1) @ UT
        else:
            n_cart += 1
            UF = fr[("uframe", a["uf"])]
            assert b["letters"] == a["letters"], (idx, a["letters"], b["letters"])
            want = UF @ xyzwpr(a["v"])  # where the nominal robot puts the original: the pose itself
            q0 = ik(dh_nom, cm, want @ np.linalg.inv(UT), a["letters"], a["turns"], SEEDS)
            assert q0 is not None, idx
            assert fanuc_config(dh_nom, q0, cm) == (a["letters"], a["turns"])
            # the controller reads the corrected position: the nominal IK on its branch and turns
            G1 = UF @ xyzwpr(b["v"]) @ np.linalg.inv(UT)
            q1 = ik(dh_nom, cm, G1, b["letters"], b["turns"], [q0] + SEEDS)
            assert q1 is not None, idx
            assert fanuc_config(dh_nom, q1, cm) == (b["letters"], b["turns"]), idx
            assert np.all(q1 >= lim[:, 0] - 1e-9) and np.all(q1 <= lim[:, 1] + 1e-9), idx
            got = dh_fk(dh_cal, q1) @ UT  # the true robot at those joints
            # the nominal robot at the original's own joints lands on the pose itself
            assert np.linalg.norm((dh_fk(dh_nom, q0) @ UT)[:3, 3] - want[:3, 3]) < 1e-6
        e_mm = float(np.linalg.norm(got[:3, 3] - want[:3, 3]))
        e_rad = rot_angle(got[:3, :3], want[:3, :3])
        worst_mm, worst_rad = max(worst_mm, e_mm), max(worst_rad, e_rad)
        assert e_mm < TOL_MM and e_rad < TOL_RAD, (idx, e_mm, e_rad)
        # and uncompensated the true robot would miss (the test has teeth)
        if not a["joint"]:
            miss = np.linalg.norm((dh_fk(dh_cal, q0) @ UT)[:3, 3] - want[:3, 3])
            assert miss > 0.1, (idx, miss)
    print("%s: %d positions (%d Cartesian): true robot at the compensated positions vs the nominal at the "
          "originals: max %.3g mm, %.3g rad" % (label, len(p0), n_cart, worst_mm, worst_rad))
    return worst_mm, worst_rad


def refusals(rcal, prog, frames_path, nominal_path, cal_path, tmp):
    src = open(prog).read()
    lines = src.split("\n")

    def line_of(s):
        return next(i + 1 for i, l in enumerate(lines) if s in l)

    cases = [  # (substitution old -> new, the line it ends on (text searched in the new program), expected words)
        ("L P[3] 500mm/sec FINE ;", "L PR[3] 500mm/sec FINE ;", "PR[3]", "position register"),
        ("L P[3] 500mm/sec FINE ;", "L P[3] 500mm/sec FINE Offset,PR[1] ;", "Offset,PR", "moves"),
        ("L P[3] 500mm/sec FINE ;", "L P[3] 500mm/sec FINE Tool_Offset ;", "Tool_Offset", "moves the target"),
        ("L P[3] 500mm/sec FINE ;", "L P[3] 500mm/sec FINE INC ;", "FINE INC", "moves the target"),
        ("L P[3] 500mm/sec FINE ;", "L P[3] 500mm/sec FINE FOO ;", "FINE FOO", "not one rcal knows"),
        ("J P[2:approach] 50% CNT50 ;", "J P[R[2]] 50% CNT50 ;", "P[R[2]]", "indirect"),
        ("UFRAME_NUM=1 ;", "UFRAME_NUM=R[4] ;", "UFRAME_NUM=R[4]", "not a literal number"),
        ("DO[1]=ON ;", "UFRAME[1]=PR[1] ;", "UFRAME[1]=PR", "changes a frame"),
        ("DO[1]=ON ;", "PR[2]=P[3] ;", "PR[2]=P[3]", "outside a motion"),
        ("J P[10] 30% CNT20 ;", "J P[99] 30% CNT20 ;", "P[99]", "not in the /POS"),
        ("UTOOL_NUM=1 ;", "UTOOL_NUM=0 ;", "L P[9] 100mm", "frame mismatch"),
        ("'F D T, 0, 0, 0'", "'X D T, 0, 0, 0'", "'X D T", "CONFIG letter 1"),
        ("X =   547.561  mm", "X =   5.47561e2  mm", "5.47561e2", "finite decimal"),
        ("X =   547.561  mm", "X =  5547.561  mm", "P[2:\"approach\"]", "reach"),
        ("J6=   300.000 deg\n", "J6=   300.000 deg,\tE1=  10.000 mm\n", "E1=", "extended axes"),
        ("/END", "/FOO\n/END", "/FOO", "unknown section"),
        ("'N U T, 0, 0, 1'", "'N U T, 0, 0, 2'", "P[3]{", "outside its limits"),
        ("  20:  J P[11] 100% FINE ;", "  20:  J P[11] 100% FINE", "J P[11] 100% FINE", "';'"),
    ]
    n = 0
    for old, new, where, words in cases:
        assert old in src, old
        text = src.replace(old, new, 1)
        bad = os.path.join(tmp, "bad.ls")
        open(bad, "w").write(text)
        out = os.path.join(tmp, "bad_out.ls")
        if os.path.exists(out):
            os.remove(out)
        rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", bad, "--out", out,
                         "--fanuc-frames", frames_path, "--full-pose")
        ln = next(i + 1 for i, l in enumerate(text.split("\n")) if where in l)
        assert rc != 0, (new, se)
        assert not os.path.exists(out), new
        assert re.search(re.escape(bad) + r":%d:\d+: " % ln, se), (new, ln, se)
        assert words in se, (new, words, se)
        n += 1
    # --format fanuc, and a blank line before /PROG: copied, and the lines counted from the file's first
    text = "\n" + src.replace("L P[3] 500mm/sec FINE ;", "L PR[3] 500mm/sec FINE ;", 1)
    bad = os.path.join(tmp, "bad_blank.ls")
    open(bad, "w").write(text)
    rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", bad, "--out",
                     os.path.join(tmp, "nb.ls"), "--fanuc-frames", frames_path, "--format", "fanuc")
    assert rc != 0 and re.search(re.escape(bad) + r":%d:10: " % (line_of("L P[3] 500mm/sec") + 1), se), se
    good = os.path.join(tmp, "good_blank.ls")
    open(good, "w").write("\n" + src)
    rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", good, "--out",
                     os.path.join(tmp, "gb.ls"), "--fanuc-frames", frames_path, "--format", "fanuc", "--summary",
                     "--json")
    assert rc == 0 and json.loads(so)["input_format"] == "fanuc", (rc, so, se)
    assert tokens_outside_numbers(open(os.path.join(tmp, "gb.ls")).read()) == tokens_outside_numbers("\n" + src)
    n += 2
    # a UF 1 position without the frames file
    rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", prog, "--out",
                     os.path.join(tmp, "nf.ls"), "--full-pose")
    assert rc != 0 and "no --fanuc-frames file" in se and re.search(re.escape(prog) + r":\d+:\d+: ", se), se
    assert not os.path.exists(os.path.join(tmp, "nf.ls"))
    # a frames file without user frame 1: its first position named
    fr2 = os.path.join(tmp, "frames_no_uf1.csv")
    open(fr2, "w").write("utool,1,10,-5,120,0,-15,0\n")
    rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", prog, "--out",
                     os.path.join(tmp, "nf.ls"), "--full-pose", "--fanuc-frames", fr2)
    ln = line_of("UF : 1, UT : 1,") - 2  # the P[...] line of the first position in UF 1
    assert rc != 0 and "user frame 1 is not given" in se and re.search(re.escape(prog) + r":%d:1: " % ln, se), se
    # a frames file with a wrong line
    open(fr2, "w").write("uframe,1,400,-100,50,0,0,30\nutool,1,10,-5,x,0,-15,0\n")
    rc, so, se = run(rcal, "--model", cal_path, "--nominal", nominal_path, "--in", prog, "--out",
                     os.path.join(tmp, "nf.ls"), "--full-pose", "--fanuc-frames", fr2)
    assert rc != 0 and re.search(re.escape(fr2) + r":2:15: ", se), se
    assert not os.path.exists(os.path.join(tmp, "nf.ls"))
    print("refusals: %d wrong programs refused with file:line:col, nothing written" % (n + 3))


def main():
    rcal, root = sys.argv[1], sys.argv[2]
    nominal = os.path.join(root, "data", "lrmate200id.json")
    prog = os.path.join(root, "tests", "tools", "host", "comp", "data", "fanuc", "every_form.ls")
    frames = os.path.join(root, "tests", "tools", "host", "comp", "data", "fanuc", "frames.csv")
    with tempfile.TemporaryDirectory() as tmp:
        # the simulated true robot: the nominal table perturbed (seeded)
        r = json.load(open(nominal))
        rnd = random.Random(51)
        for row in r["dh"]:
            row["a_mm"] += rnd.uniform(-0.5, 0.5)
            row["d_mm"] += rnd.uniform(-0.5, 0.5)
            row["alpha_deg"] += rnd.uniform(-0.05, 0.05)
            row["theta_deg"] += rnd.uniform(-0.05, 0.05)
        r["name"] = "simulated true LR Mate 200iD"
        cal = os.path.join(tmp, "true.json")
        json.dump(r, open(cal, "w"), indent=1)
        check_program(rcal, prog, frames, nominal, cal, tmp, "every_form.ls (LF)")
        crlf = os.path.join(tmp, "every_form_crlf.ls")
        open(crlf, "w", newline="").write(open(prog).read().replace("\n", "\r\n"))
        check_program(rcal, crlf, frames, nominal, cal, tmp, "every_form.ls (CRLF)")
        refusals(rcal, prog, frames, nominal, cal, tmp)
    print("ok")


if __name__ == "__main__":
    main()
