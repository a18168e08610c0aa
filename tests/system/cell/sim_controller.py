#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A simulated robot controller speaking rcal-link/1, written from docs/controller-link.md alone (it shares
no code with rcal). It holds the plan (pose, q1..q6 deg), connects to rcal acquire --controller, moves in time
at a joint speed limit, writes 'INDEX q1..q6' to --follow on arrival (the simulated display follows the
simulated robot), reports AT with the plan's joints plus a small servo error rounded to the controller's
precision, and injects faults at chosen poses:

  disconnect@K   close the connection half way through the move to K, connect again
  stall@K        ignore the first command to K (stand still, report nothing)
  offset@K       arrive at K the first time with q3 off by --offset-deg
  garbage@K      send a garbage line (and one longer than 255 bytes) before reporting K
  duplicate@K    report K twice
  order@K        report another pose (not yet visited) before K
  second@K       a second controller connects while K is being moved to
  slow@K         from K on, every line leaves after --slow-ms (a slow network)
  quit@K         say BYE when told to go to K and end (the cell stopped; rcal stops, a rerun resumes)

Loopback only; bounded by --max-seconds. Writes a JSON summary (--log): every AT sent, the FAULT lines
received by name, connections made.
"""
import argparse
import csv
import json
import os
import random
import re
import socket
import sys
import time

VERSION = "rcal-link/1"


def read_plan(path):
    plan = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            plan[int(row["pose"])] = [float(row["q%d" % j]) for j in range(1, 7)]
    return plan


class Link:
    def __init__(self, port, slow_s):
        self.port = port
        self.slow_s = slow_s
        self.sock = None
        self.buf = b""
        self.last_tx = 0.0

    def connect(self, deadline):
        while time.monotonic() < deadline:
            try:
                s = socket.create_connection(("127.0.0.1", self.port), timeout=1.0)
                s.settimeout(None)
                self.sock, self.buf = s, b""
                return True
            except OSError:
                time.sleep(0.1)
        return False

    def close(self):
        if self.sock:
            self.sock.close()
        self.sock = None

    def send(self, line):
        if self.slow_s[0] > 0:
            time.sleep(self.slow_s[0])
        self.sock.sendall(line.encode() + b"\n")
        self.last_tx = time.monotonic()

    def recv_line(self, timeout):
        """One line, or None on timeout; raises ConnectionError when closed."""
        end = time.monotonic() + timeout
        while b"\n" not in self.buf:
            left = end - time.monotonic()
            if left <= 0:
                return None
            self.sock.settimeout(min(left, 0.2))
            try:
                chunk = self.sock.recv(4096)
            except socket.timeout:
                if time.monotonic() - self.last_tx >= 1.0:  # heartbeat after 1 s without sending
                    self.send("HB")
                continue
            if not chunk:
                raise ConnectionError("closed by rcal")
            self.buf += chunk
        line, self.buf = self.buf.split(b"\n", 1)
        return line.decode().rstrip("\r")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int)
    ap.add_argument("--port-from", help="rcal's stderr: wait for 'listening on 127.0.0.1:PORT'")
    ap.add_argument("--poses", required=True)
    ap.add_argument("--outlet", type=int, default=-1)
    ap.add_argument("--point", type=int, default=-1)
    ap.add_argument("--follow")
    ap.add_argument("--speed-deg-s", type=float, default=400.0)
    ap.add_argument("--decimals", type=int, default=5, help="the controller's precision")
    ap.add_argument("--servo-deg", type=float, default=0.004, help="largest servo error per joint")
    ap.add_argument("--offset-deg", type=float, default=0.5)
    ap.add_argument("--slow-ms", type=float, default=300.0)
    ap.add_argument("--fault", action="append", default=[])
    ap.add_argument("--tcp", action="store_true", help="report a TCP x y z too")
    ap.add_argument("--log", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-seconds", type=float, default=60.0)
    a = ap.parse_args()
    t_end = time.monotonic() + a.max_seconds
    rng = random.Random(a.seed)
    plan = read_plan(a.poses)
    faults = {}
    for f in a.fault:
        kind, k = f.split("@")
        faults.setdefault(int(k), set()).add(kind)

    port = a.port
    if a.port_from:
        while port is None and time.monotonic() < t_end:
            try:
                m = re.search(r"listening on 127\.0\.0\.1:(\d+)", open(a.port_from).read())
            except OSError:
                m = None
            if m:
                port = int(m.group(1))
            else:
                time.sleep(0.05)
    if port is None:
        sys.exit("sim_controller: no port")

    slow = [0.0]
    link = Link(port, slow)
    log = {"at": [], "faults": {}, "connections": 0, "busy_seen": 0, "stop": None, "commands": []}
    here = list(plan[min(plan)])  # the arm's joints
    done_faults = set()

    def once(kind, k):
        if kind in faults.get(k, ()) and (kind, k) not in done_faults:
            done_faults.add((kind, k))
            return True
        return False

    def report(k, q):
        line = "AT %d %d %d " % (k, a.outlet, a.point) + " ".join("%.*f" % (a.decimals, v) for v in q)
        if a.tcp:
            line += " 0.0 0.0 0.0"
        link.send(line)
        log["at"].append({"pose": k, "q": [round(v, a.decimals) for v in q]})

    def arrive(k, q):
        nonlocal here
        here = q
        if a.follow:
            tmp = a.follow + ".ctl.tmp"
            with open(tmp, "w") as f:
                f.write("%d %s\n" % (k, " ".join("%.4f" % v for v in plan[k])))
            os.replace(tmp, a.follow)

    def move(k, half=False):
        """Move toward plan pose k at the speed limit (heartbeats meanwhile); the reached joints."""
        target = [v + rng.uniform(-a.servo_deg, a.servo_deg) for v in plan[k]]
        if once("offset", k):
            target[2] += a.offset_deg
        dur = max(abs(t - h) for t, h in zip(target, here)) / a.speed_deg_s
        if half:
            dur /= 2
        t0 = time.monotonic()
        while time.monotonic() - t0 < dur:
            time.sleep(min(0.2, dur))
            if time.monotonic() - link.last_tx >= 1.0:
                link.send("HB")
        return target

    def second_controller():
        try:
            s = socket.create_connection(("127.0.0.1", port), timeout=2.0)
            s.sendall(("HELLO %s intruder\n" % VERSION).encode())
            s.settimeout(2.0)
            data = b""
            while b"\n" not in data:
                c = s.recv(256)
                if not c:
                    break
                data += c
            if data.startswith(b"FAULT BUSY"):
                log["busy_seen"] += 1
            s.close()
        except OSError:
            pass

    pending = None  # the command in force (name, pose)
    connected = False
    while time.monotonic() < t_end:
        if not connected:
            if not link.connect(min(t_end, time.monotonic() + 15)):
                break
            log["connections"] += 1
            link.send("HELLO %s simctl" % VERSION)
            connected = True
        try:
            line = link.recv_line(7.0)
            if line is None:  # WAIT overran or rcal silent: the link is lost
                link.close()
                connected = False
                continue
            f = line.split()
            if not f:
                continue
            if f[0] == "FAULT":
                log["faults"][f[1]] = log["faults"].get(f[1], 0) + 1
                continue
            if f[0] in ("WELCOME", "HB", "WAIT"):
                continue
            if f[0] == "STOP":
                log["stop"] = f[1] if len(f) > 1 else ""
                break
            if f[0] in ("NEXT", "BACK", "AGAIN"):
                k = int(f[1])
                pending = (f[0], k)
                log["commands"].append(line)
                if once("quit", k):
                    link.send("BYE")
                    log["stop"] = "quit"
                    break
                if "slow" in faults.get(k, ()):
                    slow[0] = a.slow_ms / 1000.0
                if once("stall", k):
                    continue  # stands still; rcal names STALLED and asks again
                if once("second", k):
                    second_controller()
                if once("disconnect", k):
                    move(k, half=True)
                    link.close()
                    connected = False
                    time.sleep(0.3)
                    continue
                q = here if f[0] == "AGAIN" else move(k)
                arrive(k, q)
                if once("garbage", k):
                    link.send("\x01#%&garbage")
                    link.send("X" * 300)
                if once("order", k):
                    later = [p for p in sorted(plan) if p > k]
                    if later:
                        report(later[-1], plan[later[-1]])
                report(k, q)
                if once("duplicate", k):
                    report(k, q)
        except (ConnectionError, OSError):
            link.close()
            connected = False
            time.sleep(0.2)
    link.close()
    with open(a.log, "w") as f:
        json.dump(log, f)
    sys.exit(0 if log["stop"] is not None else 1)


if __name__ == "__main__":
    main()
