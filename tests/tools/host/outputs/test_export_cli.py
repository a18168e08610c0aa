#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""test_export_cli.py - `rcal export` end to end, checked by readers that are
not rcal's code.

    test_export_cli.py RCAL FK_DUMP SOURCE_DIR SHARED_CSV WORK_DIR

1. For the nominal robot, the simulated truth, models calibrated by `rcal
   calibrate` (simulated data, with and without a tool offset; the real data
   when SHARED_CSV exists) and a model with effects: the URDF's flange from
   its joint origins (urdf_fk.py, xml.etree + pure-Python matrices) against
   rcal's FK (fk_dump, the core's rc_fk) at 200 random joint vectors inside
   the limits, to 1e-6 mm.
2. Hostile names (quotes, <, &, --, control characters) in the model and in a
   nominal URDF give well-formed XML whose names read back as given.
3. --nominal-urdf: names in chain order from a URDF whose joints are out of
   order, with a transmission, a base joint and a tool0 flange.
4. The DH CSV of each model, parsed with the csv module, carries the
   model file's values.
5. Refusals: --out naming the model (the model unchanged), joint-side
   effects without --drop-joint-effects, --nominal-urdf with dh-csv.
"""
import csv
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "common"))
from rct_check import check, failures  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import urdf_fk  # noqa: E402

RCAL, FK_DUMP, SRC, SHARED, WORK = sys.argv[1:6]
os.makedirs(WORK, exist_ok=True)


def run(*args, expect=0):
    p = subprocess.run([RCAL, *args], capture_output=True, text=True)
    if p.returncode != expect:
        print(p.stdout, p.stderr)
    check(p.returncode == expect, "rcal %s -> exit %d (got %d)" % (" ".join(args), expect, p.returncode))
    return p


def w(name):
    return os.path.join(WORK, name)


def fk_against_urdf(model, urdf, label):
    dump = w(label + ".fk.csv")
    with open(dump, "w") as f:
        subprocess.run([FK_DUMP, model, "200", "7"], stdout=f, check=True)
    joints = urdf_fk.chain(urdf)
    worst, n = 0.0, 0
    with open(dump) as f:
        for line in f:
            v = [float(t) for t in line.split(",")]
            p = urdf_fk.flange_mm(joints, v[:6])
            worst = max(worst, math.sqrt(sum((p[r] - v[6 + r]) ** 2 for r in range(3))))
            n += 1
    print("      %s: %d poses, max |flange(URDF) - rcal FK| = %.3g mm" % (label, n, worst))
    check(n == 200 and worst <= 1e-6, "%s: URDF FK agrees with rcal's to 1e-6 mm" % label)


def model_dh(path):
    """The DH rows of a model file (mm, deg) and its nominal table."""
    with open(path) as f:
        m = json.load(f)
    keys = ("a_mm", "d_mm", "alpha_deg", "theta_deg")
    cal = [[row[k] for k in keys] for row in m["dh"]]
    nom = [[row[k] for k in keys] for row in m.get("nominal", m)["dh"]]
    return m, cal, nom


def check_csv(model, label):
    out = w(label + ".csv")
    run("export", "--model", model, "--format", "dh-csv", "--out", out)
    m, cal, nom = model_dh(model)
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    check(rows[0] == ["joint", "name", "unit", "nominal", "calibrated", "correction", "standard_error"],
          "%s: CSV header" % label)
    names = ("a", "d", "alpha", "theta")
    good = True
    for i in range(6):
        for k in range(4):
            r = rows[1 + 4 * i + k]
            good &= r[0] == str(i + 1) and r[1] == names[k] and r[2] == ("deg" if k >= 2 else "mm")
            good &= abs(float(r[3]) - nom[i][k]) <= 1e-9 * max(1.0, abs(nom[i][k]))
            good &= abs(float(r[4]) - cal[i][k]) <= 1e-9 * max(1.0, abs(cal[i][k]))
            corr = cal[i][k] - nom[i][k]
            if k >= 2:
                corr = (corr + 180.0) % 360.0 - 180.0
            good &= abs(float(r[5]) - corr) <= 1e-9 * max(1.0, abs(corr))
            good &= len(r) == 7
    if "encoder_mm" in m:
        enc = rows[25:28]
        for k in range(3):
            good &= enc[k][:3] == ["encoder", "xyz"[k], "mm"] and enc[k][3] == "" and enc[k][5] == ""
            good &= abs(float(enc[k][4]) - m["encoder_mm"][k]) <= 1e-9 * max(1.0, abs(m["encoder_mm"][k]))
    check(good, "%s: the DH CSV parses back to the model file's values" % label)
    # a model with a posterior (rcal-model/2 "uncertainty"): every DH row carries its standard error
    unc = {u["name"]: u.get("std_error") for u in m.get("uncertainty", {}).get("parameters", [])}
    if unc:
        se_ok = True
        for i in range(6):
            for k in range(4):
                want = unc.get("%s%d" % (names[k], i + 1))
                got = rows[1 + 4 * i + k][6]
                se_ok &= (got == "") if want is None else abs(float(got) - want) <= 1e-9 * max(1.0, abs(want))
        check(se_ok, "%s: the DH CSV's standard errors are the model's posterior ones" % label)


# --- 1. models ----------------------------------------------------------
models = [("nominal", os.path.join(SRC, "data/irb120.json")),
          ("truth", os.path.join(SRC, "data/sim_irb120_truth.json"))]
sim = os.path.join(SRC, "data/sim_irb120.csv")
run("calibrate", "--data", sim, "--out", w("cal_sim.json"))
models.append(("calibrated-sim", w("cal_sim.json")))
run("calibrate", "--data", sim, "--tool-offset", "--out", w("cal_sim_tool.json"))
models.append(("calibrated-sim-tool", w("cal_sim_tool.json")))
if os.path.exists(SHARED):
    run("calibrate", "--data", SHARED, "--jumps", "--dequantize-joints", "--out", w("cal_real.json"))
    models.append(("calibrated-real", w("cal_real.json")))
else:
    print("      (no real data at %s: that model is left out)" % SHARED)
with open(os.path.join(SRC, "data/sim_irb120_truth.json")) as f:
    base = json.load(f)
fx = dict(base)
fx["effects"] = [{"kind": "tool_offset", "params": [12.5, -30.25, 41.0]},
                 {"kind": "length_offset", "params": [0.5]}]
with open(w("effects.json"), "w") as f:
    json.dump(fx, f)
models.append(("tool+length-effects", w("effects.json")))

for label, model in models:
    urdf = w(label + ".urdf")
    run("export", "--model", model, "--format", "urdf", "--out", urdf)
    fk_against_urdf(model, urdf, label)
    check_csv(model, label)

# --- 2. hostile names ----------------------------------------------------
evil = 'A "quoted" <robot> & \'co\' --> <!-- ]]> é\u0001end-'
hx = dict(base)
hx["name"] = evil
with open(w("hostile.json"), "w") as f:
    json.dump(hx, f)
p = run("export", "--model", w("hostile.json"), "--format", "urdf")
try:
    root = ET.fromstring(p.stdout.encode())
    # a control character XML cannot carry is U+FFFD (rch_text.h: the one escaper)
    check(root.get("name") == evil.replace("\u0001", "\ufffd"), "hostile robot name reads back as given")
except ET.ParseError as e:
    check(False, "hostile robot name: well-formed XML (%s)" % e)

# --- 3. nominal URDF names ------------------------------------------------
nominal = """<?xml version="1.0"?>
<!-- a ROS-Industrial style description, joints deliberately out of order -->
<!DOCTYPE robot [ <!ENTITY unused "x"> ]>
<robot name="abb_irb120 &amp; &quot;friends&quot;" xmlns:xacro="http://ros.org/wiki/xacro">
  <link name="base_link"/>
  <joint name="joint_3" type="revolute"><parent link="link_2"/><child link="link_3"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><axis xyz="0 1 0"/></joint>
  <joint name="joint_1" type="revolute"><parent link="base_link"/><child link="link_1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <transmission name="t1"><joint name="joint_1"/><actuator name="m1"/></transmission>
  <joint name="base_link-base" type="fixed"><parent link="base_link"/><child link="base"/></joint>
  <joint name="joint_2" type="revolute"><parent link="link_1"/><child link="link_2"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name='joint_4&lt;&#x41;&#66;' type="revolute"><parent link="link_3"/><child link="link_4"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="joint_5" type="revolute"><parent link="link_4"/><child link="link_5"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="joint_6" type="continuous"><parent link="link_5"/><child link="link_6"/></joint>
  <joint name="joint_6-tool0" type="fixed"><parent link="link_6"/><child link="tool0"/></joint>
  <link name="link_1"/><link name="link_2"/><link name="link_3"/><link name="link_4"/>
  <link name="link_5"/><link name="link_6"/><link name="tool0"/><link name="base"/>
  <![CDATA[ <joint name="not_a_joint"/> ]]>
</robot>
"""
with open(w("nominal.urdf"), "w") as f:
    f.write(nominal)
truth = os.path.join(SRC, "data/sim_irb120_truth.json")
run("export", "--model", truth, "--format", "urdf", "--nominal-urdf", w("nominal.urdf"), "--out", w("named.urdf"))
root = ET.parse(w("named.urdf")).getroot()
check(root.get("name") == 'abb_irb120 & "friends"', "robot name taken from the nominal URDF")
jn = [(j.get("name"), j.get("type"), j.find("parent").get("link"), j.find("child").get("link"))
      for j in root.findall("joint")]
want = [("joint_1", "revolute", "base_link", "link_1"), ("joint_2", "revolute", "link_1", "link_2"),
        ("joint_3", "revolute", "link_2", "link_3"), ("joint_4<AB", "revolute", "link_3", "link_4"),
        ("joint_5", "revolute", "link_4", "link_5"), ("joint_6", "continuous", "link_5", "link_6"),
        ("joint_6-tool0", "fixed", "link_6", "tool0")]
check(jn == want, "joint and link names of the nominal URDF in chain order (got %r)" % (jn,))
fk_against_urdf(truth, w("named.urdf"), "truth-with-nominal-names")

# --- 5. refusals -----------------------------------------------------------
with open(w("cal_sim.json"), "rb") as f:
    before = f.read()
run("export", "--model", w("cal_sim.json"), "--format", "urdf", "--out", w("cal_sim.json"), expect=1)
with open(w("cal_sim.json"), "rb") as f:
    check(f.read() == before, "--out naming the model: refused, the model unchanged")
jx = dict(base)
jx["effects"] = [{"kind": "joint_periodic", "joint": 3, "params": [1e-3, 0, 0, 0]}]
with open(w("joint_effect.json"), "w") as f:
    json.dump(jx, f)
p = run("export", "--model", w("joint_effect.json"), "--format", "urdf", expect=1)
check("joint_periodic" in p.stderr, "a joint-side effect is named in the refusal")
run("export", "--model", w("joint_effect.json"), "--format", "urdf", "--drop-joint-effects", "--out",
    w("dropped.urdf"))
run("export", "--model", truth, "--format", "dh-csv", "--nominal-urdf", w("nominal.urdf"), expect=2)
with open(w("bad.urdf"), "w") as f:
    f.write(nominal.replace("</robot>", ""))
p = run("export", "--model", truth, "--format", "urdf", "--nominal-urdf", w("bad.urdf"), expect=1)
check("bad.urdf" in p.stderr, "an unclosed nominal URDF is refused with its name")

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
