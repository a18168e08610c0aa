#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A simulated KUKA RSI controller against rcal-rt --rsi-port (issue 49).

Written apart from rcal-rt's code: the <Rob> datagrams are built by hand as
KUKA's RSI sends them (RIst, RSol, AIPos, ASPos, Delay, IPOC), the <Sen>
answers read with regular expressions (not expat), loopback only.

  test_rsi_sim.py RCAL RCAL_RT REPO_ROOT WORKDIR

Runs (each a few seconds; timing is never asserted, correctness is):
 1. clean path with jitter: every answer echoes its IPOC; once the start ramp
    is over every AK equals `rcal compensate`'s joints minus the setpoint to
    1e-6 deg; the correction never changes by more than the step limit.
 2. faults on the same path: drops, reordering, duplicates, garbage (random
    bytes, cut XML, wrong root, a DOCTYPE, non-numbers, NaN), a setpoint out
    of the joint limits, a target the solver cannot compensate, a second
    sender, a late datagram, the model file replaced, a silence that ends the
    session: nothing stale, malformed or foreign is answered, the correction
    never jumps, each fault is counted in the report, and after each the
    answers equal compensate's again.
 3. relative corrections: the sum of the increments equals compensate's.
 4. --rsi-config: RSI's own Ethernet configuration file names the answer
    (SENTYPE, the RECEIVE group); a file with ONLYSEND TRUE or no DEF_ASPos is
    refused with its place.
"""
import json
import math
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

FAILS = []
TOL = 1e-6  # deg: rcal compensate writes 6 decimals (rounding 5e-7)
STEP = 0.01  # the default --rsi-max-step-deg
CYCLE = 0.004


def check(cond, what):
    if not cond:
        FAILS.append(what)
        print("FAIL:", what)
    return cond


def path(n, hold):
    """A smooth closed joint path in a KR 6's limits (deg), the first `hold`
    cycles at its start (the correction ramps in there)."""
    c = [10, -40, 60, 5, 30, 20]
    a = [25, 12, 15, 40, 20, 60]
    out = []
    for k in range(n):
        t = max(0, k - hold) / (n - hold)
        out.append([round(c[i] + a[i] * math.sin(2 * math.pi * t + i), 6) for i in range(6)])
    return out


def rob(q, ipoc, act=None, delay=0, typ="KUKA"):
    act = act or q
    ax = lambda tag, v: "<%s %s/>" % (tag, " ".join('A%d="%.6f"' % (i + 1, v[i]) for i in range(6)))
    return ('<Rob Type="%s"><RIst X="445.0" Y="0.0" Z="890.0" A="0.0" B="90.0" C="0.0"/>'
            '<RSol X="445.0" Y="0.0" Z="890.0" A="0.0" B="90.0" C="0.0"/>%s%s<Delay D="%d"/>'
            '<IPOC>%d</IPOC></Rob>' % (typ, ax("AIPos", act), ax("ASPos", q), delay, ipoc)).encode()


SEN = re.compile(r'^<(\w+) Type="([\w.-]+)"><(\w+)((?: [\w.-]+="[-0-9.]+"){6})/><IPOC>(\d+)</IPOC></\1>$')
ATTR = re.compile(r' ([\w.-]+)="([-0-9.]+)"')


def parse_sen(data, root="Sen", typ="ImFree", tag="AK", attrs=("A1", "A2", "A3", "A4", "A5", "A6")):
    m = SEN.match(data.decode())
    if not check(m is not None, "answer is a <Sen> of six axes and an IPOC: %r" % data[:200]):
        return None, None
    check(m.group(1) == root and m.group(2) == typ and m.group(3) == tag,
          "answer names <%s Type=%s><%s>: %r" % (root, typ, tag, data[:80]))
    kv = ATTR.findall(m.group(4))
    check([k for k, _ in kv] == list(attrs), "answer attributes %s" % [k for k, _ in kv])
    for _, v in kv:
        check(len(v.split(".")[1]) >= 9, "AK written with at least 9 decimals: %s" % v)
    return [float(v) for _, v in kv], int(m.group(5))


def compensate(rcal, model, targets, work, name):
    tin = os.path.join(work, name + "_targets.csv")
    tout = os.path.join(work, name + "_comp.csv")
    with open(tin, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6\n")
        for q in targets:
            f.write(",".join("%.6f" % v for v in q) + "\n")
    r = subprocess.run([rcal, "compensate", "--model", model, "--in", tin, "--out", tout],
                       capture_output=True, text=True)
    check(r.returncode == 0, "rcal compensate exit %d: %s" % (r.returncode, r.stderr[-500:]))
    rows = [l.strip().split(",") for l in open(tout).read().splitlines()[1:]]
    return [[float(v) for v in row[:6]] for row in rows]


class RtProc:
    def __init__(self, rt, args):
        self.p = subprocess.Popen([rt, "--rsi-port", "0", "--json"] + args, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True)
        self.err = []
        self.port = None
        t0 = time.time()
        while time.time() - t0 < 20:
            line = self.p.stderr.readline()
            if not line:
                break
            self.err.append(line)
            m = re.search(r"listening on 127\.0\.0\.1:(\d+)", line)
            if m:
                self.port = int(m.group(1))
                break
        check(self.port is not None, "rcal-rt says where it listens: %s" % "".join(self.err))

    def stop(self):
        self.p.send_signal(signal.SIGTERM)
        out, err = self.p.communicate(timeout=30)
        self.err.append(err)
        check(self.p.returncode == 0, "rcal-rt exit %d after SIGTERM: %s" % (self.p.returncode, err[-800:]))
        try:
            return json.loads(out)
        except ValueError:
            check(False, "rcal-rt's report is JSON: %r" % out[-500:])
            return {"faults": {}}


class Ctrl:
    """The controller's socket: sends a Rob, waits for the Sen."""

    def __init__(self, port):
        self.s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.s.bind(("127.0.0.1", 0))
        self.dst = ("127.0.0.1", port)
        self.big_step = 0.0
        self.new_session()

    def send(self, data):
        self.s.sendto(data, self.dst)

    def recv(self, timeout):
        self.s.settimeout(timeout)
        try:
            return self.s.recv(65536)
        except socket.timeout:
            return None

    def answer(self, d, ipoc, what, rel=False):
        """Parse an answer, check its IPOC and the step of the correction; returns AK (absolute)."""
        if not check(d is not None, "%s (ipoc %d) answered" % (what, ipoc)):
            return None
        ak, echo = parse_sen(d)
        if ak is None:
            return None
        check(echo == ipoc, "%s: IPOC echoed (%s, sent %d)" % (what, echo, ipoc))
        if rel:
            step = max(abs(v) for v in ak)
            self.acc = [self.acc[i] + ak[i] for i in range(6)]
            cur = self.acc
        else:
            step = max(abs(ak[i] - self.prev[i]) for i in range(6))
            cur = ak
        self.prev = ak if not rel else self.prev
        self.big_step = max(self.big_step, step)
        check(step <= STEP + 1e-9, "%s: the correction moved %.9f deg (limit %g)" % (what, step, STEP))
        return cur

    def new_session(self):
        self.prev = [0.0] * 6
        self.acc = [0.0] * 6

    def nothing(self, what, wait=0.03):
        d = self.recv(wait)
        check(d is None, "%s: not answered (got %r)" % (what, d[:100] if d else d))


def run_path(ctrl, targets, ref, ipoc0, faults=None, jitter=0.0, rel=False, label=""):
    """Send the path; every answer checked against ref[k] - setpoint once the
    ramp (and 30 answers after a fault) is over. A fault returns the next
    IPOC base, and a new reference (list) when it starts a new session."""
    faults = faults or {}
    rng = random.Random(7)
    ipoc = ipoc0
    since_fault = 99
    equal = compared = 0
    worst = 0.0
    answers = 0
    ctrl.new_session()
    for k, q in enumerate(targets):
        if k in faults:
            r = faults[k](ctrl, ipoc, q)
            if isinstance(r, tuple):
                ipoc, ref = r
            else:
                ipoc = r
            since_fault = 0
        if jitter:
            time.sleep(CYCLE + rng.uniform(-jitter, jitter))
        ipoc += 4
        ctrl.send(rob(q, ipoc))
        cur = ctrl.answer(ctrl.recv(2.0), ipoc, "%s cycle %d" % (label, k), rel)
        if cur is None:
            continue
        answers += 1
        since_fault += 1
        if k >= 60 and since_fault > 30:
            compared += 1
            e = max(abs(cur[i] - (ref[k][i] - q[i])) for i in range(6))
            worst = max(worst, e)
            equal += e <= TOL
            if e > TOL and compared - equal <= 3:
                print("%s cycle %d: AK %s vs compensate %s (%.3g deg)" %
                      (label, k, cur, [ref[k][i] - q[i] for i in range(6)], e))
    print("%s: %d answers, %d of %d compared equal to compensate's (worst %.3g deg), largest step %.6f deg" %
          (label, answers, equal, compared, worst, ctrl.big_step))
    check(compared > 0 and equal == compared, "%s: every AK after the ramp equals rcal compensate's" % label)
    return answers


def garbage_list(q):
    good = rob(q, 1).decode()
    return [
        b"\x00\xff\xfe garbage",
        b"",
        good[: len(good) // 2].encode(),
        good.replace("Rob", "Bob").encode(),
        b'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;">]>'
        b"<Rob><IPOC>&b;</IPOC></Rob>",
        good.replace("<IPOC>1</IPOC>", "<IPOC>12x</IPOC>").encode(),
        good.replace("<IPOC>1</IPOC>", "").encode(),
        good.replace("<IPOC>1</IPOC>", "<IPOC>1</IPOC><IPOC>2</IPOC>").encode(),
        b"<Rob>" + b"<RIst/>" * 3000 + b"<IPOC>5</IPOC></Rob>",
    ]


def main():
    rcal, rt, root, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    src_model = os.path.join(root, "tests", "firmware_host", "data", "kr6_cal.json")
    model = os.path.join(work, "model.json")
    shutil.copyfile(src_model, model)
    n, hold = 500, 80
    targets = path(n, hold)
    ref = compensate(rcal, src_model, targets, work, "path")
    check(len(ref) == n, "compensate wrote %d rows" % len(ref))
    corr = max(abs(ref[k][i] - targets[k][i]) for k in range(n) for i in range(6))
    print("largest correction on the path: %.4f deg" % corr)
    check(corr > 0.05, "the model corrects something (%.4f deg)" % corr)

    # 1. clean, with jitter
    p = RtProc(rt, ["--model", model])
    c = Ctrl(p.port)
    run_path(c, targets, ref, 100000, jitter=0.001, label="clean")
    rep = p.stop()
    check(rep.get("answered") == n and rep.get("sessions") == 1, "clean: %s" % rep)
    check(all(v == 0 for k, v in rep["faults"].items() if k not in ("step_limited", "late")),
          "clean: no faults but the start ramp and jitter: %s" % rep["faults"])

    # 2. faults
    p = RtProc(rt, ["--model", model, "--rsi-timeout-ms", "300"])
    c = Ctrl(p.port)
    other = Ctrl(p.port)
    sent = {"garbage": 0}

    def drop(ctrl, ipoc, q):
        return ipoc + 4 * 3  # three cycles never sent

    def reorder(ctrl, ipoc, q):
        ctrl.send(rob(q, ipoc + 8))  # the next one overtakes this one
        ctrl.answer(ctrl.recv(2.0), ipoc + 8, "reorder: the newer datagram")
        ctrl.send(rob(q, ipoc + 4))
        ctrl.nothing("reorder: the stale datagram")
        return ipoc + 8

    def dup(ctrl, ipoc, q):
        ctrl.send(rob(q, ipoc + 4))
        ctrl.answer(ctrl.recv(2.0), ipoc + 4, "dup: the first")
        ctrl.send(rob(q, ipoc + 4))
        ctrl.nothing("dup: the same IPOC again")
        return ipoc + 4

    def garbage(ctrl, ipoc, q):
        for g in garbage_list(q):
            ctrl.send(g)
            ctrl.nothing("garbage %r" % g[:40], 0.02)
            sent["garbage"] += 1
        rng = random.Random(3)
        for _ in range(20):
            ctrl.send(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 300))))
            sent["garbage"] += 1
        ctrl.nothing("random bytes", 0.05)
        return ipoc

    def bad_values(ctrl, ipoc, q):
        # a setpoint the robot cannot have: answered, the correction held
        for mangle in (lambda s: s.replace('A3="', 'A3="x', 1), lambda s: s.replace('A2="', 'A2="nan', 1)):
            ipoc += 4
            s = rob(q, ipoc).decode()
            i = s.index("<ASPos")
            ctrl.send((s[:i] + mangle(s[i:])).encode())
            ctrl.answer(ctrl.recv(2.0), ipoc, "a bad setpoint value (held)")
        q2 = list(q)
        q2[1] = 75.0  # beyond A2's +60 limit
        ipoc += 4
        ctrl.send(rob(q2, ipoc))
        ctrl.answer(ctrl.recv(2.0), ipoc, "a setpoint out of the limits (held)")
        q3 = list(q)
        q3[0] -= 20.0  # a jump no robot makes in a cycle
        ipoc += 4
        ctrl.send(rob(q3, ipoc))
        ctrl.answer(ctrl.recv(2.0), ipoc, "a setpoint that jumps (held)")
        return ipoc

    def foreign(ctrl, ipoc, q):
        for j in range(3):
            other.send(rob(q, ipoc + 4 + j))
        other.nothing("a second sender", 0.05)
        return ipoc

    def robot_late(ctrl, ipoc, q):
        ctrl.send(rob(q, ipoc + 4, delay=2))  # the robot counts two late answers (DEF_Delay)
        ctrl.answer(ctrl.recv(2.0), ipoc + 4, "a Rob with Delay 2")
        return ipoc + 4

    def late(ctrl, ipoc, q):
        time.sleep(0.03)
        return ipoc

    # another calibration of the same robot: its corrections differ from the first's
    with open(src_model) as f:
        mb = json.load(f)
    for j, row in enumerate(mb["dh"]):
        row["theta_deg"] = mb["nominal"]["dh"][j]["theta_deg"] + 2.0 * (row["theta_deg"] - mb["nominal"]["dh"][j]["theta_deg"])
    model_b = os.path.join(work, "model_b.json")
    with open(model_b, "w") as f:
        json.dump(mb, f)
    state = {"ref_b": None}

    def hold(ctrl, ipoc, q, seconds, want, what):
        """q sent each cycle for `seconds` (or until AK equals want): every answer's step checked; returns
        (ipoc, the cycle AK first equalled want or None, answers)."""
        t0 = time.time()
        first = None
        n = 0
        while time.time() - t0 < seconds:
            time.sleep(CYCLE)
            ipoc += 4
            ctrl.send(rob(q, ipoc))
            ak = ctrl.answer(ctrl.recv(2.0), ipoc, what)
            n += 1
            if ak is not None and first is None and max(abs(ak[i] - want[i]) for i in range(6)) <= TOL:
                first = n
        return ipoc, first, n

    def replace_model(ctrl, ipoc, q):
        # the model file replaced in a session: the answers move to the new model's, never by more than the step
        k0 = targets.index(q)
        state["ref_b"] = [None] * k0 + compensate(rcal, model_b, targets[k0:], work, "rest_b")
        want_b = [state["ref_b"][k0][i] - q[i] for i in range(6)]
        want_a = [ref[k0][i] - q[i] for i in range(6)]
        check(max(abs(want_b[i] - want_a[i]) for i in range(6)) > 5 * STEP,
              "the second model's correction differs from the first's (%s vs %s)" % (want_b, want_a))
        shutil.copyfile(model_b, model + ".new")
        os.replace(model + ".new", model)
        ipoc, first, n = hold(ctrl, ipoc, q, 2.0, want_b, "the model file replaced")
        check(first is not None, "after the model file was replaced the answers equal the new model's (%d sent)" % n)
        return ipoc, state["ref_b"]

    def broken_model(ctrl, ipoc, q):
        # a file that is not a model: counted, the model in use kept (the answers stay the new model's)
        with open(model + ".new", "w") as f:
            f.write('{"format": "rcal-model/1", "dh": [')
        os.replace(model + ".new", model)
        k0 = targets.index(q)
        want = [state["ref_b"][k0][i] - q[i] for i in range(6)]
        ipoc, first, n = hold(ctrl, ipoc, q, 0.8, want, "a broken model file")
        check(first == 1, "a broken model file: the answers stay the model in use's (first equal %s)" % first)
        return ipoc

    def silence(ctrl, ipoc, q):
        time.sleep(0.4)  # over --rsi-timeout-ms: the session ends
        ctrl.new_session()
        # a new session is a new run of the program: compensate's reference starts there too
        k0 = targets.index(q)
        shutil.copyfile(model_b, model + ".new")
        os.replace(model + ".new", model)
        time.sleep(0.6)  # the watcher takes the good file again
        return ipoc + 4000, [None] * k0 + compensate(rcal, model_b, targets[k0:], work, "rest")

    faults = {100: drop, 140: reorder, 180: dup, 220: garbage, 260: bad_values, 300: foreign, 320: robot_late,
              340: late, 380: replace_model, 420: broken_model, 460: silence}
    run_path(c, targets, ref, 200000, faults=faults, label="faults")
    rep = p.stop()
    f = rep["faults"]
    print("fault counts:", f)
    check(f.get("dropped", 0) >= 1, "drops counted")
    check(f.get("reordered", 0) == 1, "the stale datagram counted")
    check(f.get("duplicate", 0) == 1, "the duplicate counted")
    check(f.get("malformed", 0) >= sent["garbage"] - 2, "garbage counted (%s of %d)" % (f.get("malformed"),
                                                                                      sent["garbage"]))
    check(f.get("bad_target", 0) == 4, "bad setpoints counted (2 values, 1 beyond the limits, 1 jump)")
    check(f.get("foreign_sender", 0) == 3, "the second sender counted")
    check(f.get("late", 0) >= 1, "the late datagram counted")
    check(f.get("robot_late", 0) == 1, "the robot's rising Delay count logged once")
    check(f.get("model_file_changed", 0) >= 3, "the replaced model files counted (%s)" % f.get("model_file_changed"))
    check(f.get("model_reload_refused", 0) >= 1, "the broken model file counted")
    check(rep.get("reloads", 0) >= 2, "the replaced model taken (%s)" % rep.get("reloads"))
    check(rep.get("sessions") == 2, "the silence started a second session (%s)" % rep.get("sessions"))
    check(rep.get("largest_step_deg", 1) <= STEP + 1e-12, "the correction never jumped (%s)" %
          rep.get("largest_step_deg"))
    check(any("model_file_changed" in e for e in p.err), "the model change is logged")
    check(any("foreign_sender" in e for e in p.err), "the second sender is logged")

    # 2b. a target the solver cannot compensate: A1 at its limit, the correction pushing beyond it
    p = RtProc(rt, ["--model", src_model])
    c = Ctrl(p.port)
    q = [163.906057, 18.694165, -109.998900, 179.998200, 119.998800, 9.640164]  # compensate: a joint limit is in the way (joints 3 5)
    for j in range(20):
        c.send(rob(q, 5000 + 4 * j))
        ak = c.answer(c.recv(2.0), 5000 + 4 * j, "unreachable %d" % j)
        check(ak is not None and max(abs(v) for v in ak) == 0.0, "unreachable: the correction held at 0: %s" % ak)
    rep = p.stop()
    check(rep["faults"].get("not_converged") == 20, "unreachable: counted (%s)" % rep["faults"])
    check(any("did not converge" in e for e in p.err), "unreachable: logged")

    # 3. relative corrections
    p = RtProc(rt, ["--model", src_model, "--rsi-mode", "relative"])
    c = Ctrl(p.port)
    run_path(c, targets[:250], ref, 300000, rel=True, label="relative")
    rep = p.stop()
    check(rep.get("mode") == "relative" and rep.get("answered") == 250, "relative: %s" % rep)

    # 4. RSI's configuration file
    cfg = os.path.join(work, "rsi_eth.xml")
    elems = "".join('<ELEMENT TAG="Corr.K%d" TYPE="DOUBLE" INDX="%d" HOLDON="1" />\n' % (i, i) for i in range(6, 0, -1))
    conf = ('<ROOT>\n <CONFIG>\n  <IP_NUMBER>127.0.0.1</IP_NUMBER>\n  <PORT>0</PORT>\n  <SENTYPE>rcal</SENTYPE>\n'
            '  <ONLYSEND>FALSE</ONLYSEND>\n </CONFIG>\n <SEND>\n  <ELEMENTS>\n'
            '   <ELEMENT TAG="DEF_AIPos" TYPE="DOUBLE" INDX="INTERNAL" />\n'
            '   <ELEMENT TAG="DEF_ASPos" TYPE="DOUBLE" INDX="INTERNAL" />\n  </ELEMENTS>\n </SEND>\n'
            ' <RECEIVE>\n  <ELEMENTS>\n' + elems +
            '   <ELEMENT TAG="Out.01" TYPE="BOOL" INDX="7" HOLDON="1" />\n  </ELEMENTS>\n </RECEIVE>\n</ROOT>\n')
    conf = conf.replace("<PORT>0</PORT>", "<PORT>1</PORT>")
    with open(cfg, "w") as fh:
        fh.write(conf)
    p = RtProc(rt, ["--model", src_model, "--rsi-config", cfg, "--rsi-max-step-deg", "1"])
    c = Ctrl(p.port)
    c.send(rob(targets[0], 7))
    d = c.recv(2.0)
    if check(d is not None, "--rsi-config: answered"):
        ak, echo = parse_sen(d, typ="rcal", tag="Corr", attrs=("K1", "K2", "K3", "K4", "K5", "K6"))
        check(ak is not None and max(abs(ak[i] - (ref[0][i] - targets[0][i])) for i in range(6)) <= TOL,
              "--rsi-config: the correction in the configured names")
    p.stop()
    for bad, what, where in ((conf.replace("<ONLYSEND>FALSE", "<ONLYSEND>TRUE"), "ONLYSEND", ":6:"),
                             (conf.replace("DEF_ASPos", "DEF_RSol"), "DEF_ASPos", ""),
                             (conf.replace("</RECEIVE>", ""), "mismatched tag", ":")):
        with open(cfg, "w") as fh:
            fh.write(bad)
        r = subprocess.run([rt, "--model", src_model, "--rsi-config", cfg, "--rsi-port", "0", "--seconds", "1"],
                           capture_output=True, text=True, timeout=30)
        check(r.returncode == 1 and what in r.stderr and (cfg + where) in r.stderr,
              "--rsi-config refused (%s), with its place: exit %d %s" % (what, r.returncode, r.stderr[-300:]))

    # 5. the controller's axes (a "controller" member: A1 turns the other way, A2 and A3 read -90 and +90 at
    # the model's zero): the setpoints are the controller's, AK in its axes, equal to rcal compensate's on the
    # same (controller) joints
    ctrl_model = os.path.join(root, "tests", "firmware_host", "data", "kr6_ctrl.json")
    sign, zero = [-1, 1, 1, 1, 1, 1], [0, -90, 90, 0, 0, 0]
    ctargets = [[round(sign[i] * q[i] + zero[i], 6) for i in range(6)] for q in targets[:250]]
    cref = compensate(rcal, ctrl_model, ctargets, work, "ctrl")
    p = RtProc(rt, ["--model", ctrl_model])
    check(any("mapped to the model's" in e for e in p.err), "the controller member is said: %s" % p.err)
    c = Ctrl(p.port)
    run_path(c, ctargets, cref, 400000, label="controller axes")
    rep = p.stop()
    check(rep["faults"].get("bad_target", 1) == 0, "controller axes: no setpoint refused (%s)" % rep["faults"])

    if FAILS:
        print("%d failure(s)" % len(FAILS))
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
