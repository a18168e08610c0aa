/* SPDX-License-Identifier: MIT */
/* rch_krl_kin.c - KUKA's conventions (see rch_krl.h): {X,Y,Z,A,B,C} as
 * Trans Rz(A) Ry(B) Rx(C); Status and Turn of controller joints; the
 * inverse kinematics on the branch a Status and Turn name (the general
 * solver's solutions, rch_ikg_all, sorted by KUKA's bits).
 * Memory: none. Errors: -1 with why set. */
#include "rch_krl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define KDEG (M_PI / 180.0)

void rch_krl_frame_to_pose(double p[3], double R[9], const rch_krl_frame *f)
{
    const double a = f->v[3] * KDEG, b = f->v[4] * KDEG, c = f->v[5] * KDEG;
    const double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
    const double T[9] = {ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc,
                         sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc,
                         -sb,     cb * sc,                cb * cc};
    memcpy(R, T, sizeof T);
    p[0] = f->v[0];
    p[1] = f->v[1];
    p[2] = f->v[2];
}

void rch_krl_pose_to_frame(rch_krl_frame *f, const double p[3], const double R[9])
{
    const double cb = sqrt(R[0] * R[0] + R[3] * R[3]);
    f->v[0] = p[0];
    f->v[1] = p[1];
    f->v[2] = p[2];
    f->v[4] = atan2(-R[6], cb) / KDEG;
    if (cb > 1e-12) {
        f->v[3] = atan2(R[3], R[0]) / KDEG;
        f->v[5] = atan2(R[7], R[8]) / KDEG;
    } else { /* B = +-90 deg: C folded into A */
        f->v[3] = atan2(-R[1], R[4]) / KDEG;
        f->v[5] = 0.0;
    }
}

/* Frames 0..3 of the pure DH table at model joints q: o[k] origins, z[k]
 * axes, x1 the x axis of frame 1 (frame 0 coordinates). */
static void chain(double o[4][3], double z[4][3], const rc_model *m, const double q[RC_NJ])
{
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, p[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        o[k][0] = p[0];
        o[k][1] = p[1];
        o[k][2] = p[2];
        z[k][0] = R[2];
        z[k][1] = R[5];
        z[k][2] = R[8];
        const double a = m->x[RC_P_A(k)], d = m->x[RC_P_D(k)], al = m->x[RC_P_ALPHA(k)];
        const double th = q[k] + m->x[RC_P_THETA(k)];
        const double ct = cos(th), st = sin(th), ca = cos(al), sa = sin(al);
        const double A[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0, sa, ca};
        double Rn[9];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                Rn[3 * i + j] = R[3 * i] * A[j] + R[3 * i + 1] * A[3 + j] + R[3 * i + 2] * A[6 + j];
        const double t[3] = {a * ct, a * st, d};
        for (int i = 0; i < 3; ++i)
            p[i] += R[3 * i] * t[0] + R[3 * i + 1] * t[1] + R[3 * i + 2] * t[2];
        memcpy(R, Rn, sizeof R);
    }
    o[3][0] = p[0];
    o[3][1] = p[1];
    o[3][2] = p[2];
    z[3][0] = R[2];
    z[3][1] = R[5];
    z[3][2] = R[8];
}

/* The shoulder (x of the wrist centre in the A1 coordinate system) and
 * elbow (side of the line through A2 and A3) factors at model joints q. */
static void factors(double *xa1, double *elbow, const rc_model *m, const double q[RC_NJ])
{
    double o[4][3], z[4][3];
    chain(o, z, m, q);
    const double d4 = m->x[RC_P_D(3)];
    double E[3], u[3], v[3];
    for (int i = 0; i < 3; ++i) {
        E[i] = o[3][i] + d4 * z[3][i]; /* the wrist centre: on axis 4 at its common normal to axis 5 */
        u[i] = o[2][i] - o[1][i];
        v[i] = E[i] - o[2][i];
    }
    /* the A1 coordinate system: the root frame turned with axis 1 about z0 */
    *xa1 = E[0] * cos(q[0]) + E[1] * sin(q[0]);
    const double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    *elbow = c[0] * z[1][0] + c[1] * z[1][1] + c[2] * z[1][2];
}

static double wrap180(double a)
{
    a = fmod(a, 360.0);
    if (a > 180.0)
        a -= 360.0;
    else if (a <= -180.0)
        a += 360.0;
    return a;
}

int rch_krl_status(const rc_model *m, const rch_ctrl *ctl, const double a_deg[RC_NJ])
{
    static const double home[RC_NJ] = {0, -90 * KDEG, 90 * KDEG, 0, 0, 0}; /* KUKA's home: the wrist in front */
    double a[RC_NJ], q[RC_NJ], qh[RC_NJ], xa1, el, xh, elh;
    for (int i = 0; i < RC_NJ; ++i)
        a[i] = a_deg[i] * KDEG;
    rch_ctrl_to_model(q, ctl, a);
    rch_ctrl_to_model(qh, ctl, home);
    factors(&xa1, &el, m, q);
    factors(&xh, &elh, m, qh);
    int s = 0;
    if (xa1 < 0.0)
        s |= 1;
    if ((el >= 0.0) == (elh >= 0.0))
        s |= 2;
    if (wrap180(a_deg[4]) < 0.0)
        s |= 4;
    return s;
}

int rch_krl_turn(const double a_deg[RC_NJ])
{
    int t = 0;
    for (int i = 0; i < RC_NJ; ++i)
        if (a_deg[i] < 0.0)
            t |= 1 << i;
    return t;
}

void rch_krl_fk(double p[3], double R[9], const rc_model *m, const rch_ctrl *ctl, const double a_deg[RC_NJ])
{
    double a[RC_NJ], q[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        a[i] = a_deg[i] * KDEG;
    rch_ctrl_to_model(q, ctl, a);
    rch_ctrl_fk(p, R, ctl, m, q);
}

int rch_krl_ik(double a_deg[RC_NJ], const rch_ikg *ik, const rc_model *m, const rch_ctrl *ctl, const double p[3],
               const double R[9], int s, int t, char *why, size_t why_len)
{
    /* the last DH frame: B^-1 X F^-1 */
    double p1[3], R1[9], pd[3], Rd[9];
    for (int i = 0; i < 3; ++i) {
        p1[i] = 0.0;
        for (int j = 0; j < 3; ++j) {
            p1[i] += ctl->base_R[3 * j + i] * (p[j] - ctl->base_mm[j]);
            R1[3 * i + j] = ctl->base_R[i] * R[j] + ctl->base_R[3 + i] * R[3 + j] + ctl->base_R[6 + i] * R[6 + j];
        }
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            Rd[3 * i + j] = R1[3 * i] * ctl->flange_R[3 * j] + R1[3 * i + 1] * ctl->flange_R[3 * j + 1] +
                            R1[3 * i + 2] * ctl->flange_R[3 * j + 2];
        pd[i] = p1[i];
        for (int j = 0; j < 3; ++j)
            pd[i] -= Rd[3 * i + j] * ctl->flange_mm[j];
    }
    double qs[RCH_IKG_MAX_SOL][RC_NJ];
    const int n = rch_ikg_all(qs, NULL, ik, pd, Rd);
    if (n == 0) {
        snprintf(why, why_len, "out of reach (no inverse kinematics solution)");
        return -1;
    }
    int n_s = 0;
    for (int k = 0; k < n; ++k) {
        double a[RC_NJ], c[RC_NJ], q[RC_NJ];
        rch_ctrl_from_model(a, ctl, qs[k]);
        for (int i = 0; i < RC_NJ; ++i)
            c[i] = wrap180(a[i] / KDEG);
        if (rch_krl_status(m, ctl, c) != s)
            continue;
        ++n_s;
        for (int i = 0; i < RC_NJ; ++i) {
            const int neg = (t >> i) & 1;
            if (neg && c[i] >= 0.0)
                c[i] -= 360.0;
            else if (!neg && c[i] < 0.0)
                c[i] += 360.0;
            a[i] = c[i] * KDEG;
        }
        rch_ctrl_to_model(q, ctl, a);
        int inside = 1;
        for (int i = 0; i < RC_NJ; ++i)
            inside = inside && q[i] >= m->q_min_rad[i] - 1e-9 && q[i] <= m->q_max_rad[i] + 1e-9;
        if (inside) {
            memcpy(a_deg, c, sizeof c);
            return 0;
        }
    }
    if (n_s == 0)
        snprintf(why, why_len, "no inverse kinematics solution with Status S %d (%d solutions, none of that branch)",
                 s, n);
    else
        snprintf(why, why_len, "the solution with Status S %d and Turn T %d is outside the joint limits", s, t);
    return -1;
}
