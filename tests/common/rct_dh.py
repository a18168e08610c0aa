# SPDX-License-Identifier: MIT
"""rct_dh.py - the tests' own kinematics in plain Python (no numpy, nothing
of rcal's): standard DH with theta_i = q_i + theta_off_i, points in the
flange frame, random poses, and the files the tests generate from a model's
"dh" rows (cable lengths to points, tracker positions)."""
import math

DEG = math.pi / 180.0


def matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def fk(dh, q_deg):
    """the flange frame (4 x 4) of the DH rows at joints q (deg)"""
    T = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    for row, q in zip(dh, q_deg):
        th = (q + row["theta_deg"]) * DEG
        al = row["alpha_deg"] * DEG
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        T = matmul(T, [[ct, -st * ca, st * sa, row["a_mm"] * ct],
                       [st, ct * ca, -ct * sa, row["a_mm"] * st],
                       [0.0, sa, ca, row["d_mm"]],
                       [0.0, 0.0, 0.0, 1.0]])
    return T


def point(dh, q_deg, t):
    """flange + R6 t in the base frame"""
    T = fk(dh, q_deg)
    return [T[i][3] + sum(T[i][k] * t[k] for k in range(3)) for i in range(3)]


def dist(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


def draw_q(rng, lim=((-160, 160), (-100, 100), (-100, 60), (-150, 150), (-110, 110), (-300, 300))):
    """a random pose (deg) inside lim, away from the wrist singularity"""
    while True:
        q = [rng.uniform(lo, hi) for lo, hi in lim]
        if abs(math.sin(q[4] * DEG)) > 0.15:
            return q


def qtext(q):
    return ",".join("%.6f" % v for v in q)


def write_lengths(path, dh, enc, t, rng, n, noise=0.01):
    """cable lengths from enc to flange + R6 t at n random poses"""
    with open(path, "w") as f:
        f.write("q1,q2,q3,q4,q5,q6,L\n")
        for _ in range(n):
            q = draw_q(rng)
            f.write("%s,%.4f\n" % (qtext(q), dist(point(dh, q, t), enc) + rng.gauss(0, noise)))


def median(v):
    s = sorted(v)
    n = len(s)
    return s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2])
