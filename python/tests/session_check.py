# SPDX-License-Identifier: MIT
"""A Python session that calibrates, diagnoses and compensates with the rcal
package, each result checked against the rcal CLI run on the same files.

    python3 session_check.py RCAL_BIN SOURCE_ROOT WORKDIR [--demo-only]

imports whichever `rcal` the interpreter finds (the installed package in
the virtual environment of venv_install.py; the source tree's with
PYTHONPATH=python), runs on data/sim_irb120.csv and, when present, on
../shared/data/robotcali.csv (skipped with a message otherwise), and exits 0
when every figure equals the CLI's, 1 otherwise. Equal means: a held-out
figure within 1e-9 mm of the CLI's full-precision value (rmse_full_mm), the
CLI's printed figures reproduced digit for digit; the diagnosis's verdict
and Next command the same text; the compensated joints, printed as the CLI
prints them (%.6f), the same text (a difference of 0, so within 1e-9 of the
CLI's number), and u95 per target likewise. Prints the figures it compared.
"""
import json
import math
import os
import random
import subprocess
import sys

import rcal

METRICS = ("rmse_mm", "mean_abs_mm", "sd_mm", "mean_mm", "max_mm")


class Check:
    def __init__(self):
        self.failed = 0

    def ok(self, cond, what):
        if not cond:
            self.failed += 1
            print("FAIL: " + what)
        return cond


def cli(rcal_bin, root, *args):
    p = subprocess.run([rcal_bin] + list(args), cwd=root, capture_output=True, text=True)
    if p.returncode not in (0, 1):
        raise RuntimeError("rcal %s: exit %d: %s" % (" ".join(args), p.returncode, p.stderr))
    return p


def same_metrics(chk, label, mine, theirs):
    chk.ok(mine.n == theirs["n"], "%s: n %d vs %d" % (label, mine.n, theirs["n"]))
    d = abs(mine.rmse_mm - theirs["rmse_full_mm"])
    chk.ok(d <= 1e-9, "%s: RMSE %.17g vs CLI %.17g" % (label, mine.rmse_mm, theirs["rmse_full_mm"]))
    for k in METRICS:
        chk.ok(float("%.6f" % getattr(mine, k)) == theirs[k], "%s: %s %.9f vs CLI %s" % (label, k, getattr(mine, k),
                                                                                         theirs[k]))
    return d


def check_calibration(chk, rcal_bin, root, data, opts, work, tag):
    """calibrate with opts (the Python names) against the CLI's flags."""
    flags = []
    if opts.get("jumps"):
        flags.append("--jumps")
    if opts.get("dequantize"):
        flags.append("--dequantize-joints")
    if opts.get("effects"):
        flags += ["--effects", ",".join(opts["effects"])]
    cli_model = os.path.join(work, tag + "_cli.json")
    c = json.loads(cli(rcal_bin, root, "calibrate", "--data", data, "--json", "--out", cli_model, *flags).stdout)
    r = rcal.calibrate(data, **opts)
    label = "calibrate %s %s" % (data, " ".join(flags))
    d_before = same_metrics(chk, label + " before", r.before, c["before"])
    d_after = same_metrics(chk, label + " after (held out)", r.after, c["after"])
    if "after_unambiguous" in c:
        same_metrics(chk, label + " after_unambiguous", r.after_unambiguous, c["after_unambiguous"])
    chk.ok([p.name for p in r.params] == [p["name"] for p in c["params"]], label + ": parameter names")
    for p, q in zip(r.params, c["uncertainty"]["parameters"] if "uncertainty" in c else []):
        se = q["std_error"]
        chk.ok((se is None and (p.std_error is None or math.isnan(p.std_error))) or
               float("%.6g" % p.std_error) == se, "%s: %s std_error %r vs %r" % (label, p.name, p.std_error, se))
        chk.ok(p.identifiability == q["class"], "%s: %s class" % (label, p.name))
        chk.ok(p.data_vs_prior == q.get("data_vs_prior"), "%s: %s data_vs_prior" % (label, p.name))
    if "uncertainty" in c:
        pos = c["uncertainty"]["position95_mm"]
        chk.ok(float("%.6g" % r.predicted["position95_workspace_max_mm"]) == pos["workspace_max"],
               label + ": predicted u95 over the workspace")
    cj = c.get("length_jumps") or []
    chk.ok(len(r.jumps) == len(cj) and all(j.line == k["line"] and float("%.6f" % j.size_mm) == k["size_mm"]
                                           for j, k in zip(r.jumps, cj)), label + ": length jumps (line, size)")
    py_model = os.path.join(work, tag + "_py.json")
    r.write(py_model)
    print("%-60s held-out RMSE %.6f mm (CLI %.6f; |diff| %.1e), before %.6f (|diff| %.1e)"
          % (label, r.after.rmse_mm, c["after"]["rmse_full_mm"], d_after, r.before.rmse_mm, d_before))
    return r, py_model, cli_model


def check_diagnosis(chk, rcal_bin, root, data, dequantize):
    flags = ["--dequantize-joints"] if dequantize else []
    text = cli(rcal_bin, root, "diagnose", "--data", data, *flags).stdout
    c = json.loads(cli(rcal_bin, root, "diagnose", "--data", data, "--json", *flags).stdout)
    g = rcal.diagnose(data, dequantize=dequantize)
    nxt = [ln[len("Next: "):] for ln in text.splitlines() if ln.startswith("Next: ")]
    label = "diagnose %s %s" % (data, " ".join(flags))
    chk.ok(nxt and g.next_command == nxt[0], "%s: Next %r vs CLI %r" % (label, g.next_command, nxt))
    gj = g.json()
    for k in ("effect", "joint", "remaining", "rmse_before_mm", "rmse_after_mm", "noise_floor_mm", "length_jumps",
              "params"):
        chk.ok(gj.get(k) == c.get(k), "%s: %s %r vs CLI %r" % (label, k, gj.get(k), c.get(k)))
    chk.ok(g.effect == c["effect"] and g.joint == (c["joint"] or 0), label + ": verdict")
    chk.ok(float("%.6g" % g.rmse_after_mm) == c["rmse_after_mm"], label + ": held-out RMSE")
    print("%-60s verdict %s, held-out %.6g -> %.6g mm (CLI %s -> %s); Next: %s"
          % (label, g.effect, g.rmse_before_mm, g.rmse_after_mm, c["rmse_before_mm"], c["rmse_after_mm"],
             g.next_command))
    return g


def check_compensation(chk, rcal_bin, root, py_model, cli_model, work, tag, n=40, tool=(0.0, 0.0, 100.0)):
    m = rcal.Model.load(py_model)
    lim = m.joint_limits_deg
    rnd = random.Random(7)
    rows = [["%.6f" % (lo + (hi - lo) * (0.1 + 0.8 * rnd.random())) for lo, hi in lim] for _ in range(n)]
    targets = os.path.join(work, tag + "_targets.csv")
    with open(targets, "w") as f:
        f.write("".join(",".join(r) + "\n" for r in rows))
    out, unc = os.path.join(work, tag + "_cli_out.csv"), os.path.join(work, tag + "_cli_u95.csv")
    cli(rcal_bin, root, "compensate", "--model", cli_model, "--in", targets, "--out", out, "--tool",
        ",".join("%g" % t for t in tool), "--uncertainty-out", unc)
    q = [[float(v) for v in r] for r in rows]
    try:
        import numpy as np
        q = np.array(q)
    except ImportError:
        pass
    res = rcal.compensate(py_model, q, tool_mm=tool, details=True)
    with open(out) as f:
        cli_lines = [ln.strip() for ln in f if ln.strip()]
    with open(unc) as f:
        cli_u95 = [float(ln.split(",")[1]) for ln in list(f)[1:]]
    worst = 0.0
    for i, (row, line) in enumerate(zip(res.q_deg, cli_lines)):
        mine = ",".join("%.6f" % v for v in row)
        theirs = [float(v) for v in line.split(",")]
        worst = max(worst, max(abs(float("%.6f" % a) - b) for a, b in zip(row, theirs)))
        chk.ok(mine == line, "compensate %s target %d: %s vs CLI %s" % (tag, i, mine, line))
    chk.ok(len(cli_lines) == n, "compensate %s: %d CLI lines" % (tag, len(cli_lines)))
    u = list(res.u95_mm)
    chk.ok(len(cli_u95) == n and all(float("%.6f" % a) == b for a, b in zip(u, cli_u95)),
           "compensate %s: u95 per target" % tag)
    print("%-60s %d targets, tool %s: printed joints identical to the CLI's (largest |diff| %.1e deg), "
          "u95 %.4f..%.4f mm" % ("compensate " + tag, n, tool, worst, min(u), max(u)))


def main(argv):
    rcal_bin, root, work = argv[1], os.path.abspath(argv[2]), os.path.abspath(argv[3])
    demo_only = "--demo-only" in argv[4:]
    os.makedirs(work, exist_ok=True)
    os.chdir(root)  # relative data paths mean the same to the CLI and to Python
    chk = Check()
    print("rcal %s from %s" % (rcal.__version__, rcal.library_path()))
    chk.ok(rcal.__version__ == cli(rcal_bin, root, "--version").stdout.split()[1],
           "rcal.__version__ equals `rcal --version`")
    sim = "data/sim_irb120.csv"
    r, py_m, cli_m = check_calibration(chk, rcal_bin, root, sim, {}, work, "sim")
    check_diagnosis(chk, rcal_bin, root, sim, False)
    check_compensation(chk, rcal_bin, root, py_m, cli_m, work, "sim")
    real = "../shared/data/robotcali.csv"
    if demo_only:
        print("SKIPPED: %s (--demo-only: the real data are checked by the Release run of python_venv_install)"
              % real)
    elif os.path.exists(os.path.join(root, real)):
        g = check_diagnosis(chk, rcal_bin, root, real, True)
        opts = {"jumps": g.jumps, "dequantize": g.dequantize}
        if g.effects:
            opts["effects"] = g.effects
        r, py_m, cli_m = check_calibration(chk, rcal_bin, root, real, opts, work, "real")
        check_compensation(chk, rcal_bin, root, py_m, cli_m, work, "real")
    else:
        print("SKIPPED: %s is not present (the real IRB120 data); checked the demo data only" % real)
    print("session check: %s" % ("every figure equals the CLI's" if not chk.failed else "%d FAILED" % chk.failed))
    return 1 if chk.failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
