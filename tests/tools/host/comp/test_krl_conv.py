#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""KUKA KRL through rcal compensate, judged by KUKA's conventions written here apart from rcal (issue 51).

Its own standard-DH forward kinematics (from the robot file's DH table), its own KUKA joint map (A1, A4, A6
turn opposite to the DH axes; A2, A3 read -90, +90 at the DH zero; $FLANGE has x out of the flange and equals
the root frame at home), its own A, B, C (Trans Rz(A) Ry(B) Rx(C), degrees), Status (bit 0 the wrist root
point at x < 0 in the A1 coordinate system, bit 1 A3 >= phi: the wrist in front of the line through A2 and A3,
bit 2 A5 < 0) and Turn (bit i: axis i+1 < 0), its own Newton IK and its own regex reader of KRL.

A simulated true robot (data/kr6.json with its DH table perturbed, written here) is the calibrated model. The
committed programs tests/tools/host/comp/data/krl/every_form.src and .dat (every instruction form) go through
`rcal compensate --full-pose`; then for every target the true robot driven by the compensated target, as the
controller reads it (the nominal IK of the corrected pose on the branch its S and T name; axis targets as
they are), must land where the nominal robot puts the original target: within 0.001 mm and 1e-6 rad; the
bytes outside the targets' numbers must be unchanged; the wrong inputs tests/tools/host/comp/data/krl/bad_*.src must be
refused at the file:line:col their first comment names, with nothing written.

usage: test_krl_conv.py RCAL ROOT WORKDIR
"""
import json
import math
import os
import re
import subprocess
import sys

try:
    import numpy as np
except ImportError:
    print("SKIP: numpy is not installed (Debian python3-numpy)")
    sys.exit(77)

TOL_MM, TOL_RAD = 1e-3, 1e-6
SIGN = np.array([-1, 1, 1, -1, 1, -1.0])
ZERO = np.array([0, -90, 90, 0, 0, 0.0])


def dh_T(a, d, al, th):
    ca, sa, ct, st = math.cos(al), math.sin(al), math.cos(th), math.sin(th)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1.0]])


def load_dh(j):
    return [(r["a_mm"], r["d_mm"], math.radians(r["alpha_deg"]), math.radians(r["theta_deg"])) for r in j["dh"]]


def chain(dh, A):
    q = np.radians(SIGN * (np.asarray(A, float) - ZERO))
    M = np.eye(4)
    fr = [M]
    for (a, d, al, th), qi in zip(dh, q):
        M = M @ dh_T(a, d, al, th + qi)
        fr.append(M)
    return fr


def fk(dh, F, A):
    return chain(dh, A)[6] @ F


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def frame(v):
    T = np.eye(4)
    T[:3, :3] = rz(math.radians(v[3])) @ ry(math.radians(v[4])) @ rx(math.radians(v[5]))
    T[:3, 3] = v[:3]
    return T


def status(dh, A):
    W = chain(dh, A)[4][:3, 3]  # the wrist root point: axes 4, 5, 6 meet at frame 4's origin
    a1 = math.radians(A[0])
    x_a1 = W[0] * math.cos(a1) - W[1] * math.sin(a1)  # the A1 system: the root turned clockwise by A1
    phi = math.degrees(math.atan2(dh[2][0], dh[3][1]))  # A3 with the wrist on the line through A2 and A3
    s = 1 if x_a1 < 0 else 0
    if 0 <= ((A[2] - phi) % 360) < 180:
        s |= 2
    if ((A[4] + 180) % 360) - 180 < 0:
        s |= 4
    return s


def turn(A):
    return sum(1 << i for i in range(6) if A[i] < 0)


def rot_err(R1, R2):
    return math.acos(max(-1.0, min(1.0, (np.trace(R1.T @ R2) - 1) / 2)))


def ik(dh, F, Tg, S, T, lim):
    """The joints with Status S and Turn T that put the flange at Tg: Newton from seeds of that branch."""
    d6 = dh[5][1]
    W = Tg[:3, 3] - d6 * Tg[:3, 0]  # KUKA's flange x is the flange's normal
    a1 = -math.degrees(math.atan2(W[1], W[0])) + (180 if S & 1 else 0)
    a3s = [90, 60, 120, 30, 150] if S & 2 else [-10, 0, 200, 220]
    a5 = -60 if S & 4 else 60
    for a2 in [-90, -60, -120, -30, -150]:
        for a3 in a3s:
            for a4 in [0, 90, -90, 180]:
                A = np.array([a1, a2, a3, a4, a5, 0.0])
                for _ in range(60):
                    Tc = fk(dh, F, A)
                    e = np.concatenate([Tg[:3, 3] - Tc[:3, 3], 500 * 0.5 * vee(Tg[:3, :3] @ Tc[:3, :3].T)])
                    J = np.zeros((6, 6))
                    for i in range(6):
                        dA = A.copy()
                        dA[i] += 1e-6
                        Td = fk(dh, F, dA)
                        J[:, i] = np.concatenate([Td[:3, 3] - Tc[:3, 3],
                                                  500 * 0.5 * vee(Td[:3, :3] @ Tc[:3, :3].T)]) / 1e-6
                    step = np.linalg.lstsq(J, e, rcond=None)[0]
                    step = np.clip(step, -20, 20)
                    A = A + step
                    if np.max(np.abs(step)) < 1e-11:
                        break
                Tc = fk(dh, F, A)
                if np.linalg.norm(Tc[:3, 3] - Tg[:3, 3]) > 1e-7 or rot_err(Tc[:3, :3], Tg[:3, :3]) > 1e-10:
                    continue
                A = ((A + 180) % 360) - 180
                for i in range(6):
                    if (T >> i) & 1 and A[i] >= 0:
                        A[i] -= 360
                    elif not (T >> i) & 1 and A[i] < 0:
                        A[i] += 360
                if status(dh, A) == S and turn(A) == T and all(lo <= a <= hi for a, (lo, hi) in zip(A, lim)):
                    return A
    raise AssertionError("no IK solution with S %d T %d" % (S, T))


def vee(M):
    return np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]])


NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
COMP = re.compile(r"\s*([A-Za-z]\w*)\s+(" + NUM + r")\s*$")
AGG = re.compile(r"\{([^{}]*)\}")
TARGET_KEYS = set("X Y Z A B C S T".split()) | {"A%d" % i for i in range(1, 7)} | {"E%d" % i for i in range(1, 7)}


def comps(body):
    out = {}
    for part in body.split(","):
        m = COMP.match(part)
        if not m:
            return None
        out[m.group(1).upper()] = float(m.group(2))
    return out


def read_krl(text):
    """Targets of a KRL text: (line, span, kind, values, tool, base), by KUKA's own reading."""
    lines = text.split("\n")
    tool_data, base_data, fdat = {}, {}, {}
    for ln in lines:
        code = ln.split(";")[0]
        m = re.match(r"\s*(TOOL|BASE)_DATA\[(\d+)\]\s*=\s*\{(.*)\}\s*$", code, re.I)
        if m:
            c = comps(m.group(3))
            (tool_data if m.group(1).upper() == "TOOL" else base_data)[int(m.group(2))] = [c[k] for k in "XYZABC"]
        m = re.match(r"\s*DECL\s+FDAT\s+F(\w+)\s*=\s*\{\s*TOOL_NO\s+(\d+)\s*,\s*BASE_NO\s+(\d+)", code, re.I)
        if m:
            fdat["X" + m.group(1).upper()] = (int(m.group(2)), int(m.group(3)))
    zero = [0.0] * 6
    tool, base = zero, zero
    targets, off = [], 0
    for no, ln in enumerate(lines, 1):
        cut = ln.find(";")
        code = ln if cut < 0 else ln[:cut]
        u = code.upper()
        m = re.match(r"\s*\$(TOOL|BASE)\s*=\s*(.*?)\s*$", code, re.I)
        if m:
            rhs = m.group(2)
            if rhs.upper() == "$NULLFRAME":
                v = zero
            elif rhs.startswith("{"):
                c = comps(rhs[1:-1])
                v = [c[k] for k in "XYZABC"]
            else:
                k = int(re.match(r"(?:TOOL|BASE)_DATA\[(\d+)\]", rhs, re.I).group(1))
                v = (tool_data if m.group(1).upper() == "TOOL" else base_data)[k]
            if m.group(1).upper() == "TOOL":
                tool = v
            else:
                base = v
        m = re.match(r"\s*BAS\s*\(\s*#(TOOL|BASE|INITMOV)\s*,\s*(\d+)", code, re.I)
        if m:
            w, k = m.group(1).upper(), int(m.group(2))
            if w == "INITMOV":
                tool, base = zero, zero
            elif w == "TOOL":
                tool = tool_data[k] if k else zero
            else:
                base = base_data[k] if k else zero
        if not (re.match(r"\s*(\$TOOL|\$BASE|TOOL_DATA|BASE_DATA)", u) or re.match(r"\s*DECL\s+FRAME", u)):
            found = []
            for m in AGG.finditer(code):
                c = comps(m.group(1))
                if c is None or not set(c) <= TARGET_KEYS:
                    continue
                kind = "axis" if "A1" in c else "cart"
                name = re.search(r"(\w+)\s*=\s*$", code[:m.start()])
                t, b = tool, base
                if name and name.group(1).upper() in fdat:
                    tn, bn = fdat[name.group(1).upper()]
                    t = tool_data[tn] if tn else zero
                    b = base_data[bn] if bn else zero
                found.append(dict(line=no, span=(off + m.start(), off + m.end()), kind=kind, v=c, tool=t, base=b))
            if re.match(r"\s*S?CIRC\b", u) and len(found) == 2 and "S" not in found[0]["v"]:
                found[0]["ST"] = (found[1]["v"]["S"], found[1]["v"]["T"])  # the auxiliary point: its end's branch
            targets += found
        off += len(ln) + 1
    return targets


def masked(text, targets):
    out, at = [], 0
    for t in targets:
        a, b = t["span"]
        out.append(text[at:a])
        out.append(re.sub(NUM, "#", text[a:b]))
        at = b
    out.append(text[at:])
    return "".join(out)


def main():
    rcal, root, work = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(work, exist_ok=True)
    nominal_path = os.path.join(root, "data", "kr6.json")
    nom_j = json.load(open(nominal_path))
    dh_nom = load_dh(nom_j)
    lim = nom_j["joint_limits_deg"]
    lim_ctrl = []
    for i, (lo, hi) in enumerate(lim):  # the model's limits read as KUKA's axis values
        a, b = SIGN[i] * lo + ZERO[i], SIGN[i] * hi + ZERO[i]
        lim_ctrl.append((min(a, b), max(a, b)))
    F = np.eye(4)
    F[:3, :3] = chain(dh_nom, ZERO)[6][:3, :3].T  # $FLANGE equals the root frame at home
    # the simulated true robot: every DH parameter moved (fixed numbers, a few tenths of a mm and of a degree)
    cal_j = json.loads(json.dumps(nom_j))
    rng = np.random.default_rng(51)
    for r in cal_j["dh"]:
        r["a_mm"] += float(rng.uniform(-0.5, 0.5))
        r["d_mm"] += float(rng.uniform(-0.5, 0.5))
        r["alpha_deg"] += float(rng.uniform(-0.05, 0.05))
        r["theta_deg"] += float(rng.uniform(-0.05, 0.05))
    cal_j["name"] = "simulated true KR 6 (test_krl_conv)"
    cal_path = os.path.join(work, "true_kr6.json")
    json.dump(cal_j, open(cal_path, "w"), indent=1)
    dh_cal = load_dh(cal_j)

    worst_mm = worst_rad = raw_mm = 0.0
    n_cart = n_axis = 0
    data = os.path.join(root, "tests", "tools", "host", "comp", "data", "krl")
    for name in ("every_form.src", "every_form.dat"):
        src = os.path.join(data, name)
        out = os.path.join(work, name)
        r = subprocess.run([rcal, "compensate", "--model", cal_path, "--nominal", nominal_path, "--in", src,
                            "--out", out, "--full-pose"], capture_output=True, text=True)
        assert r.returncode == 0, (name, r.returncode, r.stderr)
        text0, text1 = open(src, newline="").read(), open(out, newline="").read()
        t0, t1 = read_krl(text0), read_krl(text1)
        assert len(t0) == len(t1) and len(t0) > 0, (name, len(t0), len(t1))
        assert masked(text0, t0) == masked(text1, t1), name + ": bytes outside the targets' numbers changed"
        for a, b in zip(t0, t1):
            where = "%s:%d" % (name, a["line"])
            assert a["kind"] == b["kind"] and set(a["v"]) == set(b["v"]), where
            if a["kind"] == "axis":
                A0 = [a["v"]["A%d" % i] for i in range(1, 7)]
                A1 = [b["v"]["A%d" % i] for i in range(1, 7)]
                T0, T1 = fk(dh_nom, F, A0), fk(dh_cal, F, A1)
                raw_mm = max(raw_mm, float(np.linalg.norm(T0[:3, 3] - fk(dh_cal, F, A0)[:3, 3])))
                n_axis += 1
            else:
                S0, Tu0 = a.get("ST", (a["v"].get("S"), a["v"].get("T")))
                S1, Tu1 = b.get("ST", (b["v"].get("S"), b["v"].get("T")))
                X0 = frame([a["v"][k] for k in "XYZABC"])
                X1 = frame([b["v"][k] for k in "XYZABC"])
                Bf, Tf = frame(a["base"]), frame(a["tool"])
                assert a["tool"] == b["tool"] and a["base"] == b["base"], where
                Ti = np.linalg.inv(Tf)
                A0 = ik(dh_nom, F, Bf @ X0 @ Ti, int(S0), int(Tu0), lim_ctrl)
                A1 = ik(dh_nom, F, Bf @ X1 @ Ti, int(S1), int(Tu1), lim_ctrl)  # the controller reads X', S', T'
                assert np.max(np.abs(A1 - A0)) < 5.0, (where, "branch changed", A0, A1)
                if "ST" not in b:
                    assert status(dh_nom, A1) == int(S1) and turn(A1) == int(Tu1), where
                T0 = Bf @ X0  # where the nominal robot puts the original target's TCP
                T1 = fk(dh_cal, F, A1) @ Tf  # the true robot driven by the compensated target
                raw_mm = max(raw_mm, float(np.linalg.norm(T0[:3, 3] - (fk(dh_cal, F, A0) @ Tf)[:3, 3])))
                n_cart += 1
            e_mm = float(np.linalg.norm(T0[:3, 3] - T1[:3, 3]))
            e_rad = rot_err(T0[:3, :3], T1[:3, :3])
            worst_mm, worst_rad = max(worst_mm, e_mm), max(worst_rad, e_rad)
            assert e_mm <= TOL_MM and e_rad <= TOL_RAD, (where, e_mm, e_rad)
    print("every_form: %d Cartesian and %d axis targets; worst %.2e mm, %.2e rad (limits %g mm, %g rad); "
          "uncompensated the true robot misses by up to %.3f mm" % (n_cart, n_axis, worst_mm, worst_rad, TOL_MM,
                                                                    TOL_RAD, raw_mm))
    assert n_cart >= 24 and n_axis >= 6
    assert raw_mm > 100 * TOL_MM, raw_mm  # the true robot differs: the check above can fail

    # CRLF line ends and lower case (KRL is case-insensitive): the same corrections, the line ends kept
    src = os.path.join(data, "every_form.src")
    variant = os.path.join(work, "crlf_lower.src")
    with open(variant, "w", newline="") as f:
        f.write(open(src, newline="").read().lower().replace("\n", "\r\n"))
    r = subprocess.run([rcal, "compensate", "--model", cal_path, "--nominal", nominal_path, "--in", variant,
                        "--out", variant + ".out", "--full-pose"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    want = open(os.path.join(work, "every_form.src"), newline="").read().lower().replace("\n", "\r\n")
    assert open(variant + ".out", newline="").read() == want, "CRLF / lower case read differently"

    # wrong inputs: refused at file:line:col, nothing written
    n_bad = 0
    for name in sorted(os.listdir(data)):
        if not name.startswith("bad_"):
            continue
        src = os.path.join(data, name)
        want = re.search(r"expect: (\d+):(\d+)", open(src).read()).groups()
        out = os.path.join(work, name + ".out")
        if os.path.exists(out):
            os.remove(out)
        r = subprocess.run([rcal, "compensate", "--model", cal_path, "--nominal", nominal_path, "--in", src,
                            "--out", out, "--full-pose"], capture_output=True, text=True)
        tag = "%s:%s:%s:" % (src, want[0], want[1])
        assert r.returncode == 1 and tag in r.stderr and not os.path.exists(out), (name, r.returncode, r.stderr)
        print("%s: refused: %s" % (name, r.stderr.strip().splitlines()[0]))
        n_bad += 1
    assert n_bad >= 5, n_bad
    return 0


if __name__ == "__main__":
    sys.exit(main())
