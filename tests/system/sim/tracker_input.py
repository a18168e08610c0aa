# SPDX-License-Identifier: MIT
"""tracker_input - bad positions files are refused with file:line:column, the
converter (scripts/positions_convert.py) reproduces a positions file from the
other layout, and the option rules of --positions hold. Standard library only.

    python3 tracker_input.py RCAL SOURCE_DIR
"""
import os
import subprocess
import sys
import tempfile

RCAL, SRC = sys.argv[1], sys.argv[2]
ROBOT = os.path.join(SRC, "data", "irb120.json")
tmp = tempfile.mkdtemp(prefix="rcal_tracker_input_")
fails = []


def run(*args):
    r = subprocess.run([RCAL] + list(args), capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def expect(what, args, code, text):
    rc, out = run(*args)
    if rc != code or text not in out:
        fails.append("%s: exit %d (want %d), output %r lacks %r" % (what, rc, code, out[-300:], text))


def write(name, text):
    p = os.path.join(tmp, name)
    with open(p, "w") as f:
        f.write(text)
    return p


good_rows = ["%d,%d,%d,10,-20,30,40,50,%.3f,%.3f,%.3f" % (i, t, 5 * i - 60, 1000 + 7 * i + t, -500 + 3 * i, 200 + t)
             for i in range(12) for t in range(2)]
head = "pose,q1,q2,q3,q4,q5,q6,target,x,y,z\n"
good_rows = ["%d,%d,10,-20,30,40,50,%d,%.3f,%.3f,%.3f" % (i, 5 * i - 60, t, 1000 + 7 * i + t, -500 + 3 * i, 200 + t)
             for i in range(12) for t in range(2)]
nox = write("nox.csv", head.replace(",x,", ",xx,") + "\n".join(good_rows) + "\n")
expect("missing column", ["calibrate", "--robot", ROBOT, "--positions", nox], 1, "nox.csv:1:1: header has no 'x' column")
bad = list(good_rows)
bad[2] = bad[2].rsplit(",", 2)[0] + ",12x,5"  # line 4: y not a number
col = len(bad[2].rsplit(",", 2)[0]) + 2
badnum = write("badnum.csv", head + "\n".join(bad) + "\n")
expect("not a number", ["calibrate", "--robot", ROBOT, "--positions", badnum], 1,
       "badnum.csv:4:%d: field 'y': '12x' is not a number" % col)
expect("not a number (evaluate)", ["evaluate", "--model", ROBOT, "--positions", badnum], 1,
       "badnum.csv:4:%d: field 'y'" % col)
bad = list(good_rows)
bad[5] = bad[5].replace(",40,50,1,", ",40,50,17,")
badt = write("badtarget.csv", head + "\n".join(bad) + "\n")
expect("target range", ["calibrate", "--robot", ROBOT, "--positions", badt], 1, "badtarget.csv:7:")
expect("target range text", ["calibrate", "--robot", ROBOT, "--positions", badt], 1, "is not a target number")
bad = list(good_rows)
bad[3] = bad[3].replace(",10,-20,", ",10,95,")  # joint 3 beyond the IRB120's +70 deg
badq = write("badq.csv", head + "\n".join(bad) + "\n")
expect("joint limits", ["calibrate", "--robot", ROBOT, "--positions", badq], 1, "badq.csv:5:")
rad = write("rad.csv", head + "\n".join(",".join([r.split(",")[0]] + ["%.6f" % (float(v) * 3.141592653589793 / 180.0)
                                                                     for v in r.split(",")[1:7]] + r.split(",")[7:])
                                        for r in good_rows) + "\n")
expect("radians", ["calibrate", "--robot", ROBOT, "--positions", rad], 1, "look like radians")
good = write("good.csv", head + "\n".join(good_rows) + "\n")
expect("both --data and --positions to evaluate", ["evaluate", "--model", ROBOT, "--positions", good, "--data", good],
       2, "one of --data and --positions")
expect("neither --data nor --positions", ["calibrate", "--robot", ROBOT], 2, "--data or --positions is required")
expect("the same file twice", ["calibrate", "--robot", ROBOT, "--positions", good, "--positions", good], 2,
       "given twice")
expect("--out over a positions file", ["calibrate", "--robot", ROBOT, "--positions", good, "--out", good], 2, good)

# the converter: joints and stacked positions (metres, radians, a leading pose column) back to the same rows
jq = write("joints.txt", "pose;q1;q2;q3;q4;q5;q6\n" + "\n".join(
    "%d;%s" % (i, ";".join("%.12g" % (v * 3.141592653589793 / 180.0) for v in (5 * i - 60, 10, -20, 30, 40, 50)))
    for i in range(12)) + "\n")
stacked = write("stacked.txt", "\n".join("%.9g %.9g %.9g" % (
    (1000 + 7 * i + t) / 1000.0, (-500 + 3 * i) / 1000.0, (200 + t) / 1000.0) for i in range(12) for t in range(2)))
conv = os.path.join(tmp, "conv.csv")
r = subprocess.run([sys.executable, os.path.join(SRC, "scripts", "positions_convert.py"), "--joints", jq,
                    "--positions", stacked, "--targets", "2", "--joints-unit", "rad", "--positions-unit", "m",
                    "--skip-cols", "1", "--out", conv], capture_output=True, text=True)
if r.returncode != 0:
    fails.append("converter: %s" % r.stderr)
else:
    got = [l.split(",") for l in open(conv).read().split("\n")[1:] if l]
    want = [(int(x.split(",")[0]), int(x.split(",")[7]), [float(v) for v in x.split(",")[1:7]],
             [float(v) for v in x.split(",")[8:]]) for x in good_rows]
    if len(got) != len(want):
        fails.append("converter: %d rows, want %d" % (len(got), len(want)))
    for g, (pose, t, q, p) in zip(got, want):
        gv = [float(v) for v in g]
        if int(gv[0]) != pose or int(gv[1]) != t or max(abs(a - b) for a, b in zip(gv[2:8], q)) > 1e-6 or \
                max(abs(a - b) for a, b in zip(gv[8:], p)) > 1e-6:
            fails.append("converter row %s != pose %d target %d %s %s" % (g, pose, t, q, p))
            break
    r2 = subprocess.run([sys.executable, os.path.join(SRC, "scripts", "positions_convert.py"), "--joints", jq,
                         "--positions", stacked, "--targets", "3", "--skip-cols", "1", "--out", conv],
                        capture_output=True, text=True)
    if r2.returncode == 0 or "24 position rows" not in r2.stderr:
        fails.append("converter with the wrong target count: %r" % r2.stderr)

for f in fails:
    print("FAIL:", f)
print("tracker_input: %d checks failed" % len(fails))
sys.exit(1 if fails else 0)
