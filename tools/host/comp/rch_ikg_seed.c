/* SPDX-License-Identifier: MIT */
/* rch_ikg_seed.c - starts for the general IK from a closed form (rch_ikg.h):
 * the arm's DH table idealised (twists within RCH_IKG_IDEAL_DEG of a
 * multiple of 90 deg set to it, lengths below RCH_IKG_IDEAL_MM set to 0) is
 * matched against two classes with a closed form,
 *   spherical: rch_ik.h's (axes 2 and 3 parallel, spherical wrist: ABB,
 *              KUKA, Fanuc, a calibrated one of them);
 *   offset:    UR's (axes 2, 3 and 4 parallel, a4 = a5 = a6 = 0, alpha1,
 *              alpha4 and alpha5 +-90 deg, alpha6 = 0: every UR, a
 *              calibrated one),
 * and the idealised arm's eight solutions are Newton's starts on the real
 * one: each a few steps from a solution of its own branch. */
#include <math.h>
#include <string.h>

#include "rch_ik.h"
#include "rch_ikg.h"
#include "rch_ikg_int.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
/* A pose up to this fraction beyond a boundary of the idealised arm (the shoulder's cylinder, the wrist's
 * and the elbow's cosines past 1) still gets its starts, SEED_SPREAD rad (and more) apart on either side of
 * the boundary: a calibrated arm reaches a little beyond its idealised twin there. */
#define SEED_NEAR 0.02
#define SEED_SPREAD 0.02

static double ideal_angle(double a)
{
    const double k = floor(a / (M_PI / 2) + 0.5);
    return fabs(a - k * M_PI / 2) <= RCH_IKG_IDEAL_DEG * DEG ? k * M_PI / 2 : a;
}

void rch_ikg_seed_init(rch_ikg *ik, const rc_model *m)
{
    double dh[RC_NJ][4];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        for (unsigned k = 0; k < 2; ++k) {
            const double v = m->x[4 * i + k];
            dh[i][k] = fabs(v) < RCH_IKG_IDEAL_MM ? 0.0 : v;
        }
        dh[i][2] = ideal_angle(m->x[RC_P_ALPHA(i)]);
        dh[i][3] = m->x[RC_P_THETA(i)];
    }
    memcpy(ik->ideal, dh, sizeof dh);
    ik->cls = RCH_IKG_CLS_NONE;
    const double enc[3] = {0, 0, 0};
    if (rc_model_init(&ik->ideal_model, (const double(*)[4])dh, enc) != RC_OK)
        return;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        ik->ideal_model.q_min_rad[i] = -4 * M_PI;
        ik->ideal_model.q_max_rad[i] = 4 * M_PI;
    }
    if (rch_ik_supported(&ik->ideal_model, NULL, 0) == 0) {
        ik->cls = RCH_IKG_CLS_SPHERICAL;
        return;
    }
    const double s1 = sin(dh[0][2]), s4 = sin(dh[3][2]), s5 = sin(dh[4][2]);
    if (fabs(fabs(s1) - 1) < 1e-12 && fabs(fabs(s4) - 1) < 1e-12 && fabs(fabs(s5) - 1) < 1e-12 &&
        fabs(sin(dh[1][2])) < 1e-12 && cos(dh[1][2]) > 0 && fabs(sin(dh[2][2])) < 1e-12 && cos(dh[2][2]) > 0 &&
        fabs(sin(dh[5][2])) < 1e-12 && cos(dh[5][2]) > 0 && dh[3][0] == 0 && dh[4][0] == 0 && dh[5][0] == 0 &&
        dh[1][0] != 0 && dh[2][0] != 0)
        ik->cls = RCH_IKG_CLS_OFFSET;
}

/* T = Rz(th) Tz(d) Tx(a) Rx(al): R (9), p (3) */
static void dh_T(double R[9], double p[3], double th, const double row[4])
{
    const double c = cos(th), s = sin(th), ca = cos(row[2]), sa = sin(row[2]);
    const double T[9] = {c, -s * ca, s * sa, s, c * ca, -c * sa, 0, sa, ca};
    memcpy(R, T, sizeof T);
    p[0] = row[0] * c;
    p[1] = row[0] * s;
    p[2] = row[1];
}

/* (R, p) = (A, a)^-1 (B, b) */
static void inv_mul(double R[9], double p[3], const double A[9], const double a[3], const double B[9],
                    const double b[3])
{
    double T[9], t[3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            T[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
        t[i] = A[i] * (b[0] - a[0]) + A[3 + i] * (b[1] - a[1]) + A[6 + i] * (b[2] - a[2]);
    }
    memcpy(R, T, sizeof T);
    memcpy(p, t, sizeof t);
}

/* (R, p) = (A, a) (B, b)^-1 */
static void mul_inv(double R[9], double p[3], const double A[9], const double a[3], const double B[9],
                    const double b[3])
{
    double T[9], t[3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            T[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] + A[3 * i + 2] * B[3 * j + 2];
    for (int i = 0; i < 3; ++i)
        t[i] = a[i] - (T[3 * i] * b[0] + T[3 * i + 1] * b[1] + T[3 * i + 2] * b[2]);
    memcpy(R, T, sizeof T);
    memcpy(p, t, sizeof t);
}

/* UR's closed form on the idealised table; flange pose (R6, p6). Returns
 * the number of solutions (q, joint readings). */
static int offset_all(double out[8][RC_NJ], const double r[RC_NJ][4], const double R6[9], const double p6[3])
{
    const double s1 = sin(r[0][2]), s4 = sin(r[3][2]), s5 = sin(r[4][2]);
    const double D = r[1][1] + r[2][1] + r[3][1]; /* along axes 2, 3, 4 */
    /* o5 = p6 - d6 z6 (alpha6 = 0, a6 = 0: z5 = z6) */
    const double z6[3] = {R6[2], R6[5], R6[8]};
    double o5[3];
    for (int k = 0; k < 3; ++k)
        o5[k] = p6[k] - r[5][1] * z6[k];
    const double rr = hypot(o5[0], o5[1]);
    if (!(rr >= fabs(D) * (1.0 - SEED_NEAR)) || rr == 0.0)
        return 0; /* (at the shoulder singularity rr = |D|: one axis-1 angle, twice) */
    /* Just inside the idealised arm's shoulder boundary (a calibrated arm's pose next to its own, issue 51):
     * no solution of the idealised arm, two of the real one on either side of the double root, about
     * sqrt(2 (|D| - rr) / |D|) away; the two starts are put there, not on the root (where Newton picks a
     * side at random and the other branch had no start: NO_BRANCH) */
    const double v = D / (s1 * rr);
    const double phi = atan2(o5[1], o5[0]);
    const double as = fabs(v) <= 1.0 + 1e-9 ? asin(fmax(-1.0, fmin(1.0, v)))
                                     : copysign(M_PI / 2 - sqrt(2.0 * (fabs(D) - rr) / fabs(D)) - SEED_SPREAD, v);
    int n = 0;
    for (int i1 = 0; i1 < 2; ++i1) {
        const double th1 = i1 == 0 ? phi + as : phi + M_PI - as;
        const double z1[3] = {s1 * sin(th1), -s1 * cos(th1), 0.0};
        const double c5 = -(z6[0] * z1[0] + z6[1] * z1[1]) / (s4 * s5);
        if (fabs(c5) > 1.0 + SEED_NEAR)
            continue;
        for (int i5 = 0; i5 < 2; ++i5) {
            /* beyond the idealised wrist's singularity: the two starts apart, on either side of it */
            const double a5 = fabs(c5) <= 1.0 + 1e-12 ? acos(fmax(-1.0, fmin(1.0, c5)))
                              : c5 > 0           ? SEED_SPREAD
                                                 : M_PI - SEED_SPREAD;
            const double th5 = (i5 ? -1.0 : 1.0) * a5;
            /* theta6 from z1 in the flange frame */
            const double w[3] = {R6[0] * z1[0] + R6[3] * z1[1], R6[1] * z1[0] + R6[4] * z1[1],
                                 R6[2] * z1[0] + R6[5] * z1[1]};
            const double a = s4 * sin(th5);
            const double th6 = fabs(a) > 1e-12 ? atan2(-w[1] / a, w[0] / a) : 0.0;
            /* frame 4 in frame 1: T01^-1 T06 T56^-1 T45^-1 */
            double R01[9], p01[3], R45[9], p45[3], R56[9], p56[3], R[9], p[3];
            dh_T(R01, p01, th1, r[0]);
            dh_T(R45, p45, th5, r[4]);
            dh_T(R56, p56, th6, r[5]);
            inv_mul(R, p, R01, p01, R6, p6);
            mul_inv(R, p, R, p, R56, p56);
            mul_inv(R, p, R, p, R45, p45);
            const double th234 = atan2(R[3], R[0]);
            const double a2 = r[1][0], a3 = r[2][0];
            const double c3 = (p[0] * p[0] + p[1] * p[1] - a2 * a2 - a3 * a3) / (2 * a2 * a3);
            /* (past the idealised elbow's reach, however far: next to the wrist's singularity theta6, and so
             * the elbow's target, is ill-determined on the idealised arm; the scan along the wrist's
             * self-motion, rch_ikg.c, starts from here) */
            for (int i3 = 0; i3 < 2; ++i3) {
                /* the arm stretched or folded beyond the idealised arm's reach: the starts on either side */
                const double a3c = fabs(c3) <= 1.0 + 1e-9 ? acos(fmax(-1.0, fmin(1.0, c3)))
                                   : c3 > 0          ? SEED_SPREAD
                                                     : M_PI - SEED_SPREAD;
                const double th3 = (i3 ? -1.0 : 1.0) * a3c;
                const double th2 = atan2(p[1], p[0]) - atan2(a3 * sin(th3), a2 + a3 * cos(th3));
                const double th[RC_NJ] = {th1, th2, th3, th234 - th2 - th3, th5, th6};
                for (int j = 0; j < RC_NJ; ++j)
                    out[n][j] = th[j] - r[j][3];
                ++n;
            }
        }
    }
    return n;
}

int rch_ikg_seeds(double out[8][RC_NJ], const rch_ikg *ik, const double pt[3], const double Rt[9])
{
    if (ik->cls == RCH_IKG_CLS_NONE)
        return 0;
    /* the flange of the TCP target */
    double p6[3];
    const double *t = ik->kin.tool_mm;
    for (int k = 0; k < 3; ++k)
        p6[k] = pt[k] - (ik->kin.has_tool ? Rt[3 * k] * t[0] + Rt[3 * k + 1] * t[1] + Rt[3 * k + 2] * t[2] : 0.0);
    if (ik->cls == RCH_IKG_CLS_OFFSET)
        return offset_all(out, (const double(*)[4])ik->ideal, Rt, p6);
    /* rch_ik takes ABB's tool0: the flange turned RCH_IK_TOOL0_RZ_DEG about z */
    const double c = cos(RCH_IK_TOOL0_RZ_DEG * DEG), s = sin(RCH_IK_TOOL0_RZ_DEG * DEG);
    double R0[9], quat[4];
    for (int i = 0; i < 3; ++i) {
        R0[3 * i] = Rt[3 * i] * c + Rt[3 * i + 1] * s;
        R0[3 * i + 1] = -Rt[3 * i] * s + Rt[3 * i + 1] * c;
        R0[3 * i + 2] = Rt[3 * i + 2];
    }
    rch_ik_rot_to_quat(quat, R0);
    int n = rch_ik_all(out, &ik->ideal_model, p6, quat, NULL);
    /* Just beyond the idealised arm's elbow reach (stretched, or folded past its inner bound) where the
     * calibrated arm still reaches (issue 51): no closed-form solution, so no start, and the generic starts
     * found some branches and not others. The target is moved towards (then away from) the shoulder by
     * SEED_SHIFT_MM[k] until the idealised arm has solutions: each a few steps from the real arm's. */
    static const double shift_mm[] = {1.0, -1.0, 4.0, -4.0, 12.0, -12.0};
    const double sh[3] = {0.0, 0.0, ik->ideal[0][1]}; /* on axis 1 at the shoulder's height */
    for (unsigned k = 0; n == 0 && k < sizeof shift_mm / sizeof shift_mm[0]; ++k) {
        double v[3], len = 0.0, p[3];
        for (int i = 0; i < 3; ++i) {
            v[i] = sh[i] - p6[i];
            len += v[i] * v[i];
        }
        len = sqrt(len);
        if (!(len > 2.0 * fabs(shift_mm[k])))
            break;
        for (int i = 0; i < 3; ++i)
            p[i] = p6[i] + shift_mm[k] * v[i] / len;
        n = rch_ik_all(out, &ik->ideal_model, p, quat, NULL);
    }
    return n;
}
