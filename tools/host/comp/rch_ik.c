/* SPDX-License-Identifier: MIT */
/* rch_ik.c - closed-form inverse kinematics of a 6R arm with a spherical
 * wrist, and ABB's confdata and tool0 (rch_ik.h). */
#include "rch_ik.h"

#include "rch_ikg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

typedef struct {
    double a, d, ca, sa, off;
} row;

static void rows_of(row r[RC_NJ], const rc_model *m)
{
    for (unsigned i = 0; i < RC_NJ; ++i) {
        r[i].a = m->x[RC_P_A(i)];
        r[i].d = m->x[RC_P_D(i)];
        r[i].ca = cos(m->x[RC_P_ALPHA(i)]);
        r[i].sa = sin(m->x[RC_P_ALPHA(i)]);
        r[i].off = m->x[RC_P_THETA(i)];
    }
}

/* R = A B (3 x 3 row-major) */
static void mul3(double R[9], const double A[9], const double B[9])
{
    double T[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            T[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
    memcpy(R, T, sizeof T);
}

/* R = A^T B */
static void tmul3(double R[9], const double A[9], const double B[9])
{
    double At[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            At[3 * i + j] = A[3 * j + i];
    mul3(R, At, B);
}

/* Rz(th) Rx(alpha) of one row */
static void rot_row(double R[9], double th, double ca, double sa)
{
    const double c = cos(th), s = sin(th);
    const double T[9] = {c, -s * ca, s * sa, s, c * ca, -c * sa, 0, sa, ca};
    memcpy(R, T, sizeof T);
}

static void rot_z(double R[9], double th)
{
    rot_row(R, th, 1.0, 0.0);
}

static void rot_x(double R[9], double al)
{
    const double c = cos(al), s = sin(al);
    const double T[9] = {1, 0, 0, 0, c, -s, 0, s, c};
    memcpy(R, T, sizeof T);
}

/* Frames of the first three joints: o1 (axis 2's origin), o2 (axis 3's),
 * z1 (axis 2's direction), the wrist centre w and R03. */
static void chain3(double o1[3], double o2[3], double z1[3], double w[3], double R03[9], const row r[RC_NJ],
                   const double q[RC_NJ])
{
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, o[3] = {0, 0, 0};
    for (unsigned i = 0; i < 3; ++i) {
        double A[9];
        rot_row(A, q[i] + r[i].off, r[i].ca, r[i].sa);
        /* o += R (Rz(th) (a, 0, d)) : the new origin */
        const double c = cos(q[i] + r[i].off), s = sin(q[i] + r[i].off);
        const double t[3] = {r[i].a * c, r[i].a * s, r[i].d};
        for (int k = 0; k < 3; ++k)
            o[k] += R[3 * k] * t[0] + R[3 * k + 1] * t[1] + R[3 * k + 2] * t[2];
        mul3(R, R, A);
        if (i == 0) {
            memcpy(o1, o, sizeof o);
            z1[0] = R[2];
            z1[1] = R[5];
            z1[2] = R[8];
        } else if (i == 1)
            memcpy(o2, o, sizeof o);
    }
    for (int k = 0; k < 3; ++k)
        w[k] = o[k] + R[3 * k + 2] * r[3].d;
    memcpy(R03, R, sizeof R);
}

int rch_ik_supported(const rc_model *m, char *why, size_t why_len)
{
    row r[RC_NJ];
    rows_of(r, m);
    const char *bad = NULL;
    for (unsigned e = 0; e < m->n_effects && !bad; ++e) {
        const rc_effect_desc *ds = rc_effect_describe(m->effects[e].kind);
        if (ds && (ds->side == RC_SIDE_JOINT || ds->side == RC_SIDE_GEOMETRY || ds->side == RC_SIDE_POINT))
            bad = "the nominal model has an effect that moves the flange (the IK is of a pure DH table)";
    }
    if (bad) {
    } else if (fabs(r[1].sa) > 1e-12 || r[1].ca < 0)
        bad = "axes 2 and 3 are not parallel (alpha2 != 0)";
    else if (fabs(r[0].sa) < 1e-6)
        bad = "axes 1 and 2 are parallel (alpha1 = 0)";
    else if (fabs(r[3].a) > 1e-9 || fabs(r[4].a) > 1e-9 || fabs(r[4].d) > 1e-9 || fabs(r[5].a) > 1e-9)
        bad = "the wrist is not spherical (a4, a5, d5 and a6 must be 0)";
    else if (fabs(r[3].ca) > 1e-12 || fabs(r[4].ca) > 1e-12)
        bad = "wrist axes 4, 5, 6 are not at right angles (alpha4, alpha5 must be +-90 deg)";
    else if (fabs(r[1].a) < 1e-9)
        bad = "a2 is 0";
    if (bad) {
        if (why_len)
            snprintf(why, why_len, "the nominal model is not a 6R arm with a spherical wrist: %s", bad);
        return -1;
    }
    return 0;
}

void rch_ik_quat_to_rot(double R[9], const double qin[4])
{
    const double n = sqrt(qin[0] * qin[0] + qin[1] * qin[1] + qin[2] * qin[2] + qin[3] * qin[3]);
    const double w = qin[0] / n, x = qin[1] / n, y = qin[2] / n, z = qin[3] / n;
    const double T[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    memcpy(R, T, sizeof T);
}

void rch_ik_rot_to_quat(double q[4], const double R[9])
{
    const double tr = R[0] + R[4] + R[8];
    double w, x, y, z;
    if (tr > R[0] && tr > R[4] && tr > R[8]) {
        const double s = 2.0 * sqrt(1.0 + tr);
        w = 0.25 * s;
        x = (R[7] - R[5]) / s;
        y = (R[2] - R[6]) / s;
        z = (R[3] - R[1]) / s;
    } else if (R[0] >= R[4] && R[0] >= R[8]) {
        const double s = 2.0 * sqrt(1.0 + R[0] - R[4] - R[8]);
        w = (R[7] - R[5]) / s;
        x = 0.25 * s;
        y = (R[1] + R[3]) / s;
        z = (R[2] + R[6]) / s;
    } else if (R[4] >= R[8]) {
        const double s = 2.0 * sqrt(1.0 + R[4] - R[0] - R[8]);
        w = (R[2] - R[6]) / s;
        x = (R[1] + R[3]) / s;
        y = 0.25 * s;
        z = (R[5] + R[7]) / s;
    } else {
        const double s = 2.0 * sqrt(1.0 + R[8] - R[0] - R[4]);
        w = (R[3] - R[1]) / s;
        x = (R[2] + R[6]) / s;
        y = (R[5] + R[7]) / s;
        z = 0.25 * s;
    }
    const double n = sqrt(w * w + x * x + y * y + z * z), sg = w < 0 ? -1.0 : 1.0;
    q[0] = sg * w / n;
    q[1] = sg * x / n;
    q[2] = sg * y / n;
    q[3] = sg * z / n;
}

static int quadrant(double q_rad)
{
    return (int)floor(q_rad / DEG / 90.0 + 1e-12);
}

void rch_ik_confdata(int cf[4], const rc_model *m, const double q[RC_NJ])
{
    if (rch_ik_supported(m, NULL, 0) != 0) { /* any other arm: the general IK's branch (rch_ikg.h) */
        rch_ikg ik;
        cf[0] = quadrant(q[0]);
        cf[1] = quadrant(q[3]);
        cf[2] = quadrant(q[5]);
        cf[3] = rch_ikg_init(&ik, m, NULL) == RCH_IKG_OK ? rch_ikg_branch(&ik, q) : 0;
        return;
    }
    row r[RC_NJ];
    rows_of(r, m);
    double o1[3], o2[3], z1[3], w[3], R[9], h1[3], h2[3], hz[3], hw[3];
    const double q0[RC_NJ] = {q[0], 0, 0, 0, 0, 0};
    chain3(o1, o2, z1, w, R, r, q);
    chain3(h1, h2, hz, hw, R, r, q0);
    /* in front of axis 1: on the side of the zero position's wrist centre */
    const int behind1 = w[0] * hw[0] + w[1] * hw[1] < 0;
    /* in front of the lower arm (axis 2 -> axis 3): the zero position's side */
    double u[3], v[3], c[3], uh[3], vh[3], ch[3];
    for (int k = 0; k < 3; ++k) {
        u[k] = o2[k] - o1[k];
        v[k] = w[k] - o1[k];
        uh[k] = h2[k] - h1[k];
        vh[k] = hw[k] - h1[k];
    }
    c[0] = u[1] * v[2] - u[2] * v[1];
    c[1] = u[2] * v[0] - u[0] * v[2];
    c[2] = u[0] * v[1] - u[1] * v[0];
    ch[0] = uh[1] * vh[2] - uh[2] * vh[1];
    ch[1] = uh[2] * vh[0] - uh[0] * vh[2];
    ch[2] = uh[0] * vh[1] - uh[1] * vh[0];
    const double s = c[0] * z1[0] + c[1] * z1[1] + c[2] * z1[2];
    const double sh = ch[0] * hz[0] + ch[1] * hz[1] + ch[2] * hz[2];
    const int behind_arm = s * sh < 0;
    cf[0] = quadrant(q[0]);
    cf[1] = quadrant(q[3]);
    cf[2] = quadrant(q[5]);
    cf[3] = 4 * behind1 + 2 * behind_arm + (q[4] < 0);
}

void rch_ik_fk(double pos_mm[3], double quat[4], int cf[4], const rc_model *m, const double q_rad[RC_NJ],
               const double *tool_mm)
{
    double p[3], R[9], Rz[9];
    rc_fk(p, R, m, q_rad);
    if (tool_mm)
        for (int k = 0; k < 3; ++k)
            p[k] += R[3 * k] * tool_mm[0] + R[3 * k + 1] * tool_mm[1] + R[3 * k + 2] * tool_mm[2];
    memcpy(pos_mm, p, sizeof p);
    rot_z(Rz, RCH_IK_TOOL0_RZ_DEG * DEG);
    mul3(R, R, Rz);
    rch_ik_rot_to_quat(quat, R);
    if (cf)
        rch_ik_confdata(cf, m, q_rad);
}

static double wrap(double a)
{
    a = fmod(a, 2.0 * M_PI);
    if (a > M_PI)
        a -= 2.0 * M_PI;
    else if (a <= -M_PI)
        a += 2.0 * M_PI;
    return a;
}

/* The flange rotation R6 and the wrist centre of a TCP pose. */
static void flange_of(double R6[9], double wc[3], const row r[RC_NJ], const double pos[3], const double quat[4],
                      const double *tool)
{
    double Rt[9], Rz[9], p6[3];
    rch_ik_quat_to_rot(Rt, quat);
    rot_z(Rz, -RCH_IK_TOOL0_RZ_DEG * DEG);
    mul3(R6, Rt, Rz);
    for (int k = 0; k < 3; ++k)
        p6[k] = pos[k] - (tool ? R6[3 * k] * tool[0] + R6[3 * k + 1] * tool[1] + R6[3 * k + 2] * tool[2] : 0.0);
    /* wc = p6 - d6 z5, z5 = R6 Rx(-alpha6) e_z = R6 (0, sin alpha6, cos alpha6) */
    for (int k = 0; k < 3; ++k)
        wc[k] = p6[k] - r[5].d * (R6[3 * k + 1] * r[5].sa + R6[3 * k + 2] * r[5].ca);
}

/* Solutions with q4 = q4_hint where the wrist is singular (sin q5 = 0).
 * Returns the count; *singular 1 when the wrist was. */
static int solve_all(double out[8][RC_NJ], int *singular, const rc_model *m, const double pos[3],
                     const double quat[4], const double *tool, double q4_hint)
{
    row r[RC_NJ];
    rows_of(r, m);
    double R6[9], W[3];
    flange_of(R6, W, r, pos, quat, tool);
    *singular = 0;
    const double h = r[1].d + r[2].d + r[2].ca * r[3].d;
    const double rho = hypot(W[0], W[1]);
    const double C = (h - r[0].ca * (W[2] - r[0].d)) / r[0].sa;
    if (rho < 1e-9) {
        *singular = 2; /* the wrist centre on axis 1: axis 1 is not determined */
        return 0;
    }
    if (fabs(C) > rho)
        return 0; /* out of reach of axis 1's offset */
    const double psi = atan2(W[1], W[0]), as = asin(C / rho);
    const double b3 = -r[2].sa * r[3].d, L3 = hypot(r[2].a, b3), phi = atan2(b3, r[2].a);
    int n = 0;
    for (int i1 = 0; i1 < 2; ++i1) {
        const double th1 = i1 == 0 ? psi + as : psi + M_PI - as;
        const double c1 = cos(th1), s1 = sin(th1);
        const double vx = c1 * W[0] + s1 * W[1] - r[0].a, vy = -s1 * W[0] + c1 * W[1], vz = W[2] - r[0].d;
        const double w1x = vx, w1y = r[0].ca * vy + r[0].sa * vz;
        const double r2 = w1x * w1x + w1y * w1y;
        double K = (r2 - r[1].a * r[1].a - L3 * L3) / (2.0 * r[1].a * L3);
        if (fabs(K) > 1.0 + 1e-12)
            continue; /* out of the arm's reach */
        K = K > 1.0 ? 1.0 : K < -1.0 ? -1.0 : K;
        const double ac = acos(K);
        for (int i3 = 0; i3 < 2; ++i3) {
            const double th3 = i3 == 0 ? -phi + ac : -phi - ac;
            if (i3 == 1 && ac == 0.0)
                continue;
            const double ux = r[1].a + r[2].a * cos(th3) - b3 * sin(th3), uy = r[2].a * sin(th3) + b3 * cos(th3);
            const double th2 = atan2(w1y, w1x) - atan2(uy, ux);
            double q[RC_NJ] = {th1 - r[0].off, th2 - r[1].off, th3 - r[2].off, 0, 0, 0};
            double o1[3], o2[3], z1[3], wc[3], R03[9], M[9], Ra6[9];
            chain3(o1, o2, z1, wc, R03, r, q);
            rot_x(Ra6, -atan2(r[5].sa, r[5].ca));
            tmul3(M, R03, R6);
            mul3(M, M, Ra6); /* M = Rz(th4) Rx(al4) Rz(th5) Rx(al5) Rz(th6) */
            /* alpha4, alpha5 = +-90 deg: M[8] = -sa4 sa5 cos th5 and
             * (M[2], M[5]) = Rz(th4) (sa5 sin th5, 0), so |sin th5| is
             * their length: th5 by atan2, well conditioned at 0 as well */
            const double c5 = -M[8] / (r[3].sa * r[4].sa), s5 = hypot(M[2], M[5]);
            for (int i5 = 0; i5 < 2; ++i5) {
                const double th5 = i5 == 0 ? atan2(s5, c5) : -atan2(s5, c5);
                double th4;
                if (s5 < 1e-12) {
                    *singular = 1;
                    if (i5 == 1)
                        continue; /* one solution family: q4 from the hint */
                    th4 = q4_hint + r[3].off;
                } else
                    th4 = atan2(M[5], M[2]) - atan2(0.0, r[4].sa * sin(th5));
                /* Rz(th6) = Rx(-al5) Rz(-th5) Rx(-al4) Rz(-th4) M */
                double N[9], T[9];
                rot_z(T, -th4);
                mul3(N, T, M);
                rot_x(T, -atan2(r[3].sa, r[3].ca));
                mul3(N, T, N);
                rot_z(T, -th5);
                mul3(N, T, N);
                rot_x(T, -atan2(r[4].sa, r[4].ca));
                mul3(N, T, N);
                const double th6 = atan2(N[3], N[0]);
                double *o = out[n++];
                memcpy(o, q, 3 * sizeof q[0]);
                o[3] = th4 - r[3].off;
                o[4] = th5 - r[4].off;
                o[5] = th6 - r[5].off;
                for (unsigned k = 0; k < RC_NJ; ++k)
                    o[k] = wrap(o[k]);
            }
        }
    }
    return n;
}

int rch_ik_all(double q_rad[8][RC_NJ], const rc_model *m, const double pos_mm[3], const double quat[4],
               const double *tool_mm)
{
    int sing;
    return solve_all(q_rad, &sing, m, pos_mm, quat, tool_mm, 0.0);
}

/* q (rad) turned by whole turns into quadrant cf (within the tolerance):
 * 0, or -1. */
static int to_quadrant(double *q, int cf)
{
    const double lo = 90.0 * cf, hi = lo + 90.0, tol = RCH_IK_QUADRANT_TOL_DEG;
    const double qd = *q / DEG;
    const double k = floor((lo + 45.0 - qd) / 360.0 + 0.5);
    const double v = qd + 360.0 * k;
    if (v < lo - tol || v > hi + tol)
        return -1;
    *q = v * DEG;
    return 0;
}

/* Appends to why the confdata [cf1,cf4,cf6,cfx] of the pose's solutions
 * within m's joint limits, whole turns of axes 1, 4 and 6 included (an
 * IRB120's axis 6 spans +-400 deg: cf6 = 2 or -3 are real), those with cfx
 * first, so that a refused target names what would be accepted. */
static void append_solutions(char *why, size_t why_len, const rc_model *m, const double pos_mm[3],
                             const double quat[4], const double *tool_mm, int cfx)
{
    enum { MAX_LISTED = 16 };
    static const int turned[3] = {0, 3, 5};
    double sol[8][RC_NJ];
    const int n = rch_ik_all(sol, m, pos_mm, quat, tool_mm);
    int got[MAX_LISTED][4], n_got = 0;
    static const int turns[5] = {0, -1, 1, -2, 2};
    /* the solutions as solved first (axes in (-180, 180] deg), then their
     * whole turns; within each, those with cfx first */
    for (int pass = 0; pass < 4; ++pass)
        for (int k = 0; k < n; ++k)
            for (int t = pass < 2 ? 0 : 1; t < (pass < 2 ? 1 : 125) && n_got < MAX_LISTED; ++t) {
                double q[RC_NJ];
                int c[4], j, dup = 0;
                memcpy(q, sol[k], sizeof q);
                for (int a = 0, rest = t; a < 3; ++a, rest /= 5)
                    q[turned[a]] += 2.0 * M_PI * (double)turns[rest % 5];
                for (j = 0; j < RC_NJ; ++j)
                    if (q[j] < m->q_min_rad[j] - 1e-12 || q[j] > m->q_max_rad[j] + 1e-12)
                        break;
                if (j < RC_NJ)
                    continue;
                rch_ik_confdata(c, m, q);
                if ((c[3] == cfx) != (pass % 2 == 0))
                    continue;
                for (int i = 0; i < n_got; ++i)
                    dup |= memcmp(got[i], c, sizeof c) == 0;
                if (!dup)
                    memcpy(got[n_got++], c, sizeof c);
            }
    size_t at = strlen(why);
    if (at + 1 >= why_len)
        return;
    if (n_got == 0) {
        snprintf(why + at, why_len - at, "; no solution of this pose is within the joint limits");
        return;
    }
    at += (size_t)snprintf(why + at, why_len - at, "; solutions exist with [cf1,cf4,cf6,cfx] =");
    for (int i = 0; i < n_got && at + 1 < why_len; ++i)
        at += (size_t)snprintf(why + at, why_len - at, "%s [%d,%d,%d,%d]", i ? "," : "", got[i][0], got[i][1],
                               got[i][2], got[i][3]);
    if (at + 1 < why_len)
        snprintf(why + at, why_len - at, " (write one of them as the robtarget's confdata)");
}

/* rch_ik_solve for an arm outside the closed form's class: the general IK
 * (rch_ikg.h) of the branch cfx (its bits the same sides as ABB's), axes 1,
 * 4 and 6 then turned into their quadrants. */
static int solve_general(double q_rad[RC_NJ], const rc_model *m, const double pos_mm[3], const double quat[4],
                         const int cf[4], const double *tool_mm, char *why, size_t why_len)
{
    rch_ikg ik;
    if (rch_ikg_init(&ik, m, tool_mm) != RCH_IKG_OK) {
        snprintf(why, why_len, "the nominal model does not compile for the inverse kinematics");
        return -1;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) { /* quadrants and limits below */
        ik.q_min_rad[i] = -4.0 * M_PI;
        ik.q_max_rad[i] = 4.0 * M_PI;
    }
    double Rt[9], Rz[9], R6[9];
    rch_ik_quat_to_rot(Rt, quat);
    rot_z(Rz, -RCH_IK_TOOL0_RZ_DEG * DEG);
    mul3(R6, Rt, Rz);
    double q[RC_NJ];
    rch_ikg_info inf;
    const rch_ikg_status st = rch_ikg_solve(q, &inf, &ik, pos_mm, R6, cf[3], NULL);
    if (st != RCH_IKG_OK) {
        snprintf(why, why_len, "general inverse kinematics, cfx = %d: %s", cf[3], rch_ikg_strerror(st));
        return -1;
    }
    static const int axis[3] = {0, 3, 5};
    for (int a = 0; a < 3; ++a)
        if (to_quadrant(&q[axis[a]], cf[a]) != 0) {
            snprintf(why, why_len, "the solution with cfx = %d has axis %d at %.4f deg, outside the quadrant "
                     "cf%d = %d", cf[3], axis[a] + 1, q[axis[a]] / DEG, axis[a] + 1, cf[a]);
            return -1;
        }
    for (int j = 0; j < RC_NJ; ++j)
        if (q[j] < m->q_min_rad[j] - 1e-12 || q[j] > m->q_max_rad[j] + 1e-12) {
            snprintf(why, why_len, "the solution with this confdata has axis %d = %.4f deg, outside its limits "
                     "[%g, %g] deg", j + 1, q[j] / DEG, m->q_min_rad[j] / DEG, m->q_max_rad[j] / DEG);
            return -1;
        }
    memcpy(q_rad, q, sizeof q);
    return 0;
}

int rch_ik_solve(double q_rad[RC_NJ], const rc_model *m, const double pos_mm[3], const double quat[4],
                 const int cf[4], const double *tool_mm, char *why, size_t why_len)
{
    const double qn = sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]);
    if (!(fabs(qn - 1.0) <= 1e-3)) {
        snprintf(why, why_len, "the quaternion's norm is %.6g, not 1", qn);
        return -1;
    }
    if (cf[3] < 0 || cf[3] > 7) {
        snprintf(why, why_len, "cfx = %d: it must be 0..7", cf[3]);
        return -1;
    }
    if (rch_ik_supported(m, NULL, 0) != 0) {
        const double qu[4] = {quat[0] / qn, quat[1] / qn, quat[2] / qn, quat[3] / qn};
        return solve_general(q_rad, m, pos_mm, qu, cf, tool_mm, why, why_len);
    }
    /* where the wrist is singular only q4 + q6 (or q4 - q6) is fixed: q4 is
     * tried across its quadrant until q6 meets its own */
    const double q4_lo = cf[1] >= 0 ? 90.0 * cf[1] : 90.0 * (cf[1] + 1);
    int n_cfx = 0, last_bad = -1;
    double bad_deg = 0.0;
    for (int step = 0; step <= 90; ++step) {
        const double hint = (cf[1] >= 0 ? q4_lo + step : q4_lo - step) * DEG;
        double sol[8][RC_NJ];
        int sing;
        const int n = solve_all(sol, &sing, m, pos_mm, quat, tool_mm, wrap(hint));
        if (n == 0) {
            snprintf(why, why_len, sing == 2 ? "singular: the wrist centre is on axis 1 (shoulder singularity), "
                                               "axis 1 is not determined"
                                             : "out of reach: no joint solution reaches this pose");
            return -1;
        }
        for (int k = 0; k < n; ++k) {
            int c[4];
            rch_ik_confdata(c, m, sol[k]);
            if (c[3] != cf[3])
                continue;
            ++n_cfx;
            double q[RC_NJ];
            memcpy(q, sol[k], sizeof q);
            static const int axis[3] = {0, 3, 5};
            int a;
            for (a = 0; a < 3; ++a)
                if (to_quadrant(&q[axis[a]], cf[a]) != 0)
                    break;
            if (a < 3) {
                last_bad = axis[a];
                bad_deg = q[axis[a]] / DEG;
                continue;
            }
            int j;
            for (j = 0; j < RC_NJ; ++j)
                if (q[j] < m->q_min_rad[j] - 1e-12 || q[j] > m->q_max_rad[j] + 1e-12)
                    break;
            if (j < RC_NJ) {
                snprintf(why, why_len, "the solution with this confdata has axis %d = %.4f deg, outside its limits "
                         "[%g, %g] deg", j + 1, q[j] / DEG, m->q_min_rad[j] / DEG, m->q_max_rad[j] / DEG);
                append_solutions(why, why_len, m, pos_mm, quat, tool_mm, cf[3]);
                return -1;
            }
            memcpy(q_rad, q, sizeof q);
            return 0;
        }
        if (sing != 1)
            break;
    }
    if (n_cfx == 0)
        snprintf(why, why_len, "no solution with cfx = %d reaches this pose (a singular or boundary pose)", cf[3]);
    else
        snprintf(why, why_len, "the solution with cfx = %d has axis %d outside the quadrant cf%d = %d (axis %d at "
                 "%.4f deg: cf%d = %d)", cf[3], last_bad + 1, last_bad + 1,
                 cf[last_bad == 0 ? 0 : last_bad == 3 ? 1 : 2], last_bad + 1, bad_deg, last_bad + 1,
                 quadrant(bad_deg * DEG));
    append_solutions(why, why_len, m, pos_mm, quat, tool_mm, cf[3]);
    return -1;
}
