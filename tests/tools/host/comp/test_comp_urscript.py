# SPDX-License-Identifier: MIT
"""rcal compensate on URScript programs (issue 51), judged with UR's conventions implemented here, apart from
rcal (urscript_conv.py: its own DH forward kinematics, rotation vectors, UR's closed-form IK and the
controller's nearest-solution rule; its own parser of the program by regular expressions).

A simulated true robot (the UR5e's table perturbed: a, d +-0.5 mm, alpha, theta +-0.05 deg) is the calibrated
model. Each committed example program (tests/tools/host/comp/data/urscript/) is compensated with it; then, walking the
compensated program as the controller does (targets in text order; a pose through the nominal IK nearest the
joints the robot stands at, or get_inverse_kin's qnear; the TCP of the last set_tcp), the true robot driven by
each compensated target must land where the nominal robot puts the original one: within 0.001 mm and 1e-6 rad.
Every byte outside the targets' numbers is unchanged. Wrong programs are refused with file:line:col and
nothing written.

Usage: test_comp_urscript.py RCAL REPO_ROOT WORKDIR"""
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402

import urscript_conv as u  # noqa: E402

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
LIT = re.compile(r"(p?)\[\s*(" + NUM + r"(?:\s*,\s*" + NUM + r")*)\s*\]")
FAIL = []


def check(cond, what):
    if not cond:
        FAIL.append(what)
        print("FAIL:", what)


def blank_comments_strings(text):
    """The text with comments and strings blanked (same length), so literals in them are not read."""
    out, i, n = list(text), 0, len(text)
    while i < n:
        ch = text[i]
        if ch == "#":
            while i < n and text[i] not in "\r\n":
                out[i] = " "
                i += 1
        elif ch in "\"'":
            j = i + 1
            while j < n and text[j] != ch:
                j += 1
            for k in range(i, min(j + 1, n)):
                out[k] = " "
            i = j + 1
        else:
            i += 1
    return "".join(out)


def targets(text):
    """Each literal with its role, in text order: (kind 'pose'|'joints', role, values, start, end)."""
    code = blank_comments_strings(text)
    res = []
    for m in LIT.finditer(code):
        vals = [float(v) for v in m.group(2).split(",")]
        before = code[:m.start()]
        line_before = before[before.rfind("\n") + 1:]
        kind = "pose" if m.group(1) else "joints"
        if re.search(r"set_tcp\(\s*$", before):
            role = "tcp"
        elif re.search(r"get_inverse_kin\(\s*$", before):
            role = "ik"
        elif re.search(r"get_inverse_kin\(\s*p\[[^\]]*\]\s*,\s*(qnear\s*=\s*)?$", before):
            role = "qnear"
        elif re.search(r"\b(movej|movel|movep|movec)\(\s*(\w+\s*=\s*)?$", before) or \
                re.search(r"\bmovec\(\s*(pose_via\s*=\s*)?p\[[^\]]*\]\s*,\s*(pose_to\s*=\s*)?$", before):
            role = "move"
        elif re.match(r"^\s*((global|local)\s+)?\w+\s*=\s*$", line_before):
            role = "assign"
        else:
            role = None
        res.append((kind, role, vals, m.start(), m.end()))
    return res


def outside_numbers(text, lits):
    """The text with the numbers of the target literals taken out (the rest must not change)."""
    pieces, at = [], 0
    for kind, role, vals, s, e in lits:
        if role in ("tcp", "qnear", None):
            continue
        pieces.append(text[at:s])
        pieces.append(re.sub(NUM, "#", text[s:e]))
        at = e
    pieces.append(text[at:])
    return "".join(pieces)


def perturbed_model(dh_path, out_path, seed):
    with open(dh_path) as f:
        m = json.load(f)
    rng = np.random.default_rng(seed)
    for r in m["dh"]:
        r["a_mm"] += rng.uniform(-0.5, 0.5)
        r["d_mm"] += rng.uniform(-0.5, 0.5)
        r["alpha_deg"] += rng.uniform(-0.05, 0.05)
        r["theta_deg"] = r.get("theta_deg", 0.0) + rng.uniform(-0.05, 0.05)
    m["name"] = "UR5e, a simulated true robot (seed %d)" % seed
    with open(out_path, "w") as f:
        json.dump(m, f, indent=1)


def walk(text, nom, lim, true=None):
    """The program as the controller runs it: per target (line, kind, the joints it drives the robot to, and
    the pose of the TCP on the robot `true` (or the nominal one) there)."""
    lits = targets(text)
    tcp = np.eye(4)
    cur = None
    out = []
    for i, (kind, role, vals, s, e) in enumerate(lits):
        line = text.count("\n", 0, s) + 1
        if role == "tcp":
            tcp = u.pose_to_mat(vals)
            continue
        if role == "qnear":
            continue
        if kind == "joints":
            q = vals
        else:
            seed = cur
            if role == "ik":
                seed = lits[i + 1][2]  # its qnear
            if seed is None:
                out.append((line, kind, None, None))
                continue
            T = u.pose_to_mat(vals) @ np.linalg.inv(tcp)
            q = u.nearest(u.ur_ik(nom, T), seed, lim)
            if q is None:
                out.append((line, kind, None, None))
                continue
        cur = q
        out.append((line, kind, q, u.fk(true or nom, q) @ tcp))
    return out, lits


def run(rcal, args):
    return subprocess.run([rcal, "compensate"] + args, capture_output=True, text=True)


def main():
    rcal, root, work = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(work, exist_ok=True)
    nominal = os.path.join(root, "data", "ur5e.json")
    nom, lim = u.load_dh(nominal)
    data = os.path.join(root, "tests", "tools", "host", "comp", "data", "urscript")
    worst_mm, worst_rad, n_checked = 0.0, 0.0, 0
    for seed in (1, 2, 3):
        model = os.path.join(work, "true_%d.json" % seed)
        perturbed_model(nominal, model, seed)
        true, _ = u.load_dh(model)
        for name in sorted(f for f in os.listdir(data) if f.startswith("every_")):
            src = os.path.join(data, name)
            dst = os.path.join(work, "%s.%d.out" % (name, seed))
            r = run(rcal, ["--model", model, "--nominal", nominal, "--full-pose", "--in", src, "--out", dst])
            check(r.returncode == 0, "%s seed %d: exit %d: %s" % (name, seed, r.returncode, r.stderr))
            if r.returncode != 0:
                continue
            text_in = open(src, newline="").read()
            text_out = open(dst, newline="").read()
            orig, lits_in = walk(text_in, nom, lim)
            comp, lits_out = walk(text_out, nom, lim, true)
            check(outside_numbers(text_in, lits_in) == outside_numbers(text_out, lits_out),
                  "%s: bytes outside the targets' numbers changed" % name)
            # the literals that are not targets (TCP, qnear) are byte for byte the same
            same = [text_in[s:e] for k, ro, v, s, e in lits_in if ro in ("tcp", "qnear")]
            same_out = [text_out[s:e] for k, ro, v, s, e in lits_out if ro in ("tcp", "qnear")]
            check(same == same_out, "%s: set_tcp or qnear changed" % name)
            check(len(orig) == len(comp) and len(orig) >= 10, "%s: %d targets" % (name, len(orig)))
            for (line, kind, q0, F0), (_, _, q1, F1) in zip(orig, comp):
                check(q0 is not None and q1 is not None, "%s:%d: no IK" % (name, line))
                if q0 is None or q1 is None:
                    continue
                e_mm = float(np.linalg.norm(F0[:3, 3] - F1[:3, 3]))
                e_rad = u.rot_angle(F0[:3, :3], F1[:3, :3])
                worst_mm, worst_rad = max(worst_mm, e_mm), max(worst_rad, e_rad)
                n_checked += 1
                check(e_mm <= 0.001 and e_rad <= 1e-6,
                      "%s:%d (%s, seed %d): the true robot lands %.6f mm / %.3g rad off" %
                      (name, line, kind, seed, e_mm, e_rad))
    print("compensated targets checked: %d; the true robot lands within %.3g mm and %.3g rad of the nominal "
          "robot's place for the original target" % (n_checked, worst_mm, worst_rad))
    # how far off the uncompensated program is on the same robot (that the check can fail)
    model = os.path.join(work, "true_1.json")
    true, _ = u.load_dh(model)
    src = os.path.join(data, "every_form.script")
    text_in = open(src, newline="").read()
    orig, _ = walk(text_in, nom, lim)
    unc, _ = walk(text_in, nom, lim, true)
    unc_mm = max(float(np.linalg.norm(a[3][:3, 3] - b[3][:3, 3])) for a, b in zip(orig, unc))
    print("uncompensated, the same robot misses by up to %.4f mm" % unc_mm)
    check(unc_mm > 0.1, "the perturbation is visible")

    # wrong programs: refused with file:line:col, nothing written
    model = os.path.join(work, "true_1.json")
    for name in sorted(f for f in os.listdir(data) if f.startswith("bad_")):
        src = os.path.join(data, name)
        dst = os.path.join(work, name + ".out")
        if os.path.exists(dst):
            os.remove(dst)
        text = open(src, newline="").read()
        r = run(rcal, ["--model", model, "--nominal", nominal, "--full-pose", "--in", src, "--out", dst])
        check(r.returncode == 1, "%s: exit %d" % (name, r.returncode))
        check(not os.path.exists(dst), "%s: an output was written" % name)
        # each marked line "#! refused: TEXT" names the literal TEXT on the next line that must be named
        lines = text.split("\n")
        n_mark = 0
        for i, ln in enumerate(lines):
            m = re.search(r"#! refused: (.*)$", ln)
            if not m:
                continue
            n_mark += 1
            col = lines[i + 1].find(m.group(1)) + 1
            where = "%s:%d:%d:" % (src, i + 2, col)
            check(col > 0 and where in r.stderr, "%s: %s not named (stderr: %s)" % (name, where, r.stderr))
        check(n_mark > 0, "%s: no marked refusal" % name)
        print("%s: refused, %d places named: %s" % (name, n_mark, r.stderr.strip().splitlines()[-1]))
    if FAIL:
        print("%d failures" % len(FAIL))
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
