# SPDX-License-Identifier: MIT
"""URScript's conventions written apart from rcal (issue 51): standard DH forward kinematics from a robot
file's table, rotation vectors (Rodrigues), UR's closed-form inverse kinematics of the nominal arm (Hawkins,
"Analytic inverse kinematics for the Universal Robots UR-5/UR-10 arms", 2013) and the controller's choice of
the solution nearest the current joints. numpy only."""
import json
import math

import numpy as np


def load_dh(path):
    with open(path) as f:
        m = json.load(f)
    dh = [(r["a_mm"], r["d_mm"], math.radians(r["alpha_deg"]), math.radians(r.get("theta_deg", 0.0)))
          for r in m["dh"]]
    lim = [tuple(math.radians(v) for v in l) for l in m["joint_limits_deg"]]
    return dh, lim


def dh_mat(a, d, alpha, theta):
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct],
                     [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


def fk(dh, q):
    """The flange (last DH frame) in the base, 4 x 4, mm."""
    T = np.eye(4)
    for (a, d, al, th), qi in zip(dh, q):
        T = T @ dh_mat(a, d, al, qi + th)
    return T


def rotvec_to_mat(w):
    w = np.asarray(w, float)
    th = np.linalg.norm(w)
    if th < 1e-15:
        return np.eye(3)
    k = w / th
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K


def mat_to_rotvec(R):
    c = max(-1.0, min(1.0, (np.trace(R) - 1) / 2))
    th = math.acos(c)
    if th < 1e-12:
        return np.zeros(3)
    if th > math.pi - 1e-6:  # near a half turn: from the symmetric part
        B = (R + np.eye(3)) / 2
        k = np.sqrt(np.maximum(np.diag(B), 0))
        i = int(np.argmax(k))
        k = B[i] / k[i]
        k /= np.linalg.norm(k)
        if np.dot([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]], k) < 0:
            k = -k
        return k * th
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (2 * math.sin(th))
    return v * th


def pose_to_mat(p):
    """p[x, y, z, rx, ry, rz] (m, rad) -> 4 x 4 (mm)."""
    T = np.eye(4)
    T[:3, :3] = rotvec_to_mat(p[3:6])
    T[:3, 3] = np.asarray(p[:3], float) * 1000.0
    return T


def mat_to_pose(T):
    return list(T[:3, 3] / 1000.0) + list(mat_to_rotvec(T[:3, :3]))


def rot_angle(R1, R2):
    c = max(-1.0, min(1.0, (np.trace(R1.T @ R2) - 1) / 2))
    return math.acos(c) if c < 1 - 1e-12 else np.linalg.norm(mat_to_rotvec(R1.T @ R2))


def ur_ik(dh, T):
    """Every solution of UR's arm (theta offsets 0, alpha = 90, 0, 0, 90, -90, 0 deg) for the flange pose T."""
    d1, a2, a3, d4, d5, d6 = dh[0][1], dh[1][0], dh[2][0], dh[3][1], dh[4][1], dh[5][1]
    p05 = T @ np.array([0, 0, -d6, 1.0])
    r = math.hypot(p05[0], p05[1])
    if r < abs(d4):
        return []
    psi = math.atan2(p05[1], p05[0])
    phi = math.acos(d4 / r)
    sols = []
    Ti = np.linalg.inv(T)
    for t1 in (psi + phi + math.pi / 2, psi - phi + math.pi / 2):
        s1, c1 = math.sin(t1), math.cos(t1)
        c5 = (T[0, 3] * s1 - T[1, 3] * c1 - d4) / d6
        if abs(c5) > 1:
            continue
        for t5 in (math.acos(c5), -math.acos(c5)):
            s5 = math.sin(t5)
            if abs(s5) < 1e-12:
                continue
            t6 = math.atan2((-Ti[1, 0] * s1 + Ti[1, 1] * c1) / s5, (Ti[0, 0] * s1 - Ti[0, 1] * c1) / s5)
            T01 = dh_mat(dh[0][0], d1, dh[0][2], t1)
            T45 = dh_mat(dh[4 - 1 + 1][0], d5, dh[4][2], t5)
            T56 = dh_mat(dh[5][0], d6, dh[5][2], t6)
            T14 = np.linalg.inv(T01) @ T @ np.linalg.inv(T45 @ T56)
            p13 = T14 @ np.array([0, -d4, 0, 1.0])
            p13 = p13[:3]
            n13 = np.linalg.norm(p13)
            c3 = (n13 ** 2 - a2 ** 2 - a3 ** 2) / (2 * a2 * a3)
            if abs(c3) > 1:
                continue
            for t3 in (math.acos(c3), -math.acos(c3)):
                t2 = -math.atan2(p13[1], -p13[0]) + math.asin(a3 * math.sin(t3) / n13)
                T12 = dh_mat(a2, 0, dh[1][2], t2)
                T23 = dh_mat(a3, 0, dh[2][2], t3)
                T34 = np.linalg.inv(T12 @ T23) @ T14
                t4 = math.atan2(T34[1, 0], T34[0, 0])
                q = [t1, t2, t3, t4, t5, t6]
                q = [math.atan2(math.sin(v), math.cos(v)) for v in q]
                sols.append(q)
    ur_ik.raw = len(sols)
    # keep the ones that meet the pose (a self-check of the closed form)
    good = []
    for q in sols:
        F = fk(dh, q)
        if np.linalg.norm(F[:3, 3] - T[:3, 3]) < 1e-6 and rot_angle(F[:3, :3], T[:3, :3]) < 1e-9:
            good.append(q)
    return good


def nearest(sols, seed, lim):
    """UR's choice: of every solution, each joint in the turn nearest the seed inside the limits, the one
    nearest the seed (Euclidean in joint space)."""
    best, bd = None, float("inf")
    for q in sols:
        x = []
        for qi, si, (lo, hi) in zip(q, seed, lim):
            v = qi + 2 * math.pi * round((si - qi) / (2 * math.pi))
            if v > hi:
                v -= 2 * math.pi
            if v < lo:
                v += 2 * math.pi
            if not lo <= v <= hi:
                x = None
                break
            x.append(v)
        if x is None:
            continue
        dd = math.dist(x, seed)
        if dd < bd:
            best, bd = x, dd
    return best
