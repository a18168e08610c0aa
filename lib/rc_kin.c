/* SPDX-License-Identifier: MIT */
/* rc_kin.c - forward kinematics and joint Jacobian of the compiled model, in rc_real.
 *
 * The link transform is rc_chain.inc's, the one rc_model.c's chain expands
 * too, so that a double build gives the solver model's numbers bit for bit;
 * only the cosines and sines of the link twists are taken from the table
 * instead of being recomputed. */
#include "rc_kin.h"

#include <string.h>

#define RC_CHAIN_T rc_real
#define RC_CHAIN_LINK kin_link
#include "rc_chain.inc" /* the one link transform (also rc_model.c's) */

/* Chain of nj links: o[k], R[k] frame k (o[0], R[0] the base). */
static void kin_chain(rc_real (*o)[3], rc_real (*R)[9], const rc_kin_link *lk, const rc_real *theta_rad,
                      unsigned nj)
{
    static const rc_real eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(R[0], eye, sizeof eye);
    o[0][0] = o[0][1] = o[0][2] = RC_REAL_C(0.0);
    for (unsigned i = 0; i < nj; ++i)
        kin_link(R[i + 1], o[i + 1], R[i], o[i], lk[i].a_mm, lk[i].d_mm, rc_rcos(theta_rad[i]), rc_rsin(theta_rad[i]),
                 lk[i].cos_alpha, lk[i].sin_alpha, lk[i].tilt_cm1_rad, lk[i].tilt_sin, 1);
}

static void cross3(rc_real out[3], const rc_real a[3], const rc_real b[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static rc_real dot3(const rc_real a[3], const rc_real b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Gravity lever (m) of joint j from a reference geometry (rc_gravity_lever_m). */
static rc_real kin_lever(rc_kin_data *d, const rc_kin_ref *ref, unsigned j, const rc_real q_rad[RC_NJ])
{
    static const rc_real down[3] = {RC_REAL_C(0.0), RC_REAL_C(0.0), RC_REAL_C(-1.0)};
    rc_real th[4], v[3], w[3];
    for (unsigned i = 0; i < 4; ++i)
        th[i] = q_rad[i] + ref->link[i].theta_off_rad;
    kin_chain(d->lo, d->lR, ref->link, th, 4);
    const rc_real z[3] = {d->lR[j][2], d->lR[j][5], d->lR[j][8]};
    for (int r = 0; r < 3; ++r)
        v[r] = d->lo[4][r] - d->lo[j][r];
    cross3(w, v, down);
    return dot3(z, w) * RC_REAL_C(1e-3);
}

/* Effective joint angles into d->theta_rad (rc_model_theta). */
static void kin_theta(rc_kin_data *d, const rc_kin *k, const rc_real q_rad[RC_NJ])
{
    rc_real *th = d->theta_rad;
    for (unsigned i = 0; i < RC_NJ; ++i)
        th[i] = q_rad[i] + k->link[i].theta_off_rad;
    for (unsigned i = 0; i < k->n_jeff; ++i) {
        const rc_kin_jeffect *e = &k->jeff[i];
        const rc_real *p = e->c;
        const rc_real q = q_rad[e->joint];
        if (e->kind == RC_KIN_JE_COMPLIANCE)
            th[e->joint] += p[0] * kin_lever(d, &k->ref[e->ref], e->joint, q_rad);
        else if (e->kind == RC_KIN_JE_PERIODIC)
            th[e->joint] += p[0] * rc_rsin(q) + p[1] * rc_rcos(q) + p[2] * rc_rsin(RC_REAL_C(2.0) * q) +
                            p[3] * rc_rcos(RC_REAL_C(2.0) * q);
    }
}

/* Central-difference step of the compliance lever's derivative: 1e-6 rad in
 * double (as rc_model.c); about the cube root of epsilon in float, where
 * 1e-6 would leave only rounding noise. It scales the Jacobian only. */
#if RC_REAL_IS_FLOAT
#define KIN_LEVER_STEP RC_REAL_C(5e-3)
#else
#define KIN_LEVER_STEP 1e-6
#endif

/* dtheta/dq into d->D (6 x 6, row = theta index, column = q index). */
static void kin_theta_dq(rc_kin_data *d, const rc_kin *k, const rc_real q_rad[RC_NJ])
{
    rc_real *D = d->D;
    memset(D, 0, 36 * sizeof D[0]);
    for (unsigned i = 0; i < RC_NJ; ++i)
        D[7 * i] = RC_REAL_C(1.0);
    for (unsigned i = 0; i < k->n_jeff; ++i) {
        const rc_kin_jeffect *e = &k->jeff[i];
        const rc_real *p = e->c;
        const unsigned j = e->joint;
        const rc_real q = q_rad[j];
        if (e->kind == RC_KIN_JE_PERIODIC) {
            D[7 * j] += p[0] * rc_rcos(q) - p[1] * rc_rsin(q) + RC_REAL_C(2.0) * p[2] * rc_rcos(RC_REAL_C(2.0) * q) -
                        RC_REAL_C(2.0) * p[3] * rc_rsin(RC_REAL_C(2.0) * q);
        } else if (e->kind == RC_KIN_JE_COMPLIANCE && p[0] != RC_REAL_C(0.0)) {
            rc_real qq[RC_NJ];
            const rc_real h = KIN_LEVER_STEP;
            memcpy(qq, q_rad, sizeof qq);
            for (unsigned c = 0; c < 4; ++c) {
                const rc_real q0 = qq[c];
                qq[c] = q0 + h;
                const rc_real fp = kin_lever(d, &k->ref[e->ref], j, qq);
                qq[c] = q0 - h;
                const rc_real fm = kin_lever(d, &k->ref[e->ref], j, qq);
                qq[c] = q0;
                D[6 * j + c] += p[0] * (fp - fm) / (RC_REAL_C(2.0) * h);
            }
        }
    }
}

/* Chain at q into d; pos (3) gets the measured point. */
static void kin_model_chain(rc_real pos[3], rc_kin_data *d, const rc_kin *k, const rc_real q_rad[RC_NJ])
{
    kin_theta(d, k, q_rad);
    kin_chain(d->o, d->R, k->link, d->theta_rad, RC_NJ);
    for (unsigned r = 0; r < 3; ++r) {
        pos[r] = d->o[RC_NJ][r];
        if (k->has_tool) {
            const rc_real *t = k->tool_mm;
            const rc_real *R = d->R[RC_NJ];
            pos[r] += R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2];
        }
    }
}

void rc_kin_fk(rc_real pos_mm[3], rc_real rot[9], rc_kin_data *d, const rc_kin *k, const rc_real q_rad[RC_NJ])
{
    RC_ASSERT(pos_mm != NULL && d != NULL && k != NULL && q_rad != NULL);
    kin_model_chain(pos_mm, d, k, q_rad);
    if (rot != NULL)
        memcpy(rot, d->R[RC_NJ], 9 * sizeof rot[0]);
}

void rc_kin_fk_jac(rc_real pos_mm[3], rc_real rot[9], rc_real jac[36], rc_kin_data *d, const rc_kin *k,
                   const rc_real q_rad[RC_NJ])
{
    rc_real p[3];
    RC_ASSERT(pos_mm != NULL && jac != NULL && d != NULL && k != NULL && q_rad != NULL);
    kin_model_chain(p, d, k, q_rad);
    /* Jacobian with respect to theta into jac; with joint-side effects it is
     * then multiplied by dtheta/dq (d->D), else dtheta/dq is the identity. */
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rc_real z[3] = {d->R[i][2], d->R[i][5], d->R[i][8]};
        rc_real v[3], w[3];
        for (int r = 0; r < 3; ++r)
            v[r] = p[r] - d->o[i][r];
        cross3(w, z, v);
        for (unsigned r = 0; r < 3; ++r) {
            jac[6 * r + i] = w[r];
            jac[6 * (r + 3) + i] = z[r];
        }
    }
    if (k->n_jeff > 0) {
        kin_theta_dq(d, k, q_rad);
        for (int r = 0; r < 6; ++r) {
            rc_real row[RC_NJ];
            memcpy(row, &jac[6 * r], sizeof row);
            for (int c = 0; c < 6; ++c) {
                rc_real s = RC_REAL_C(0.0);
                for (int i = 0; i < 6; ++i)
                    s += row[i] * d->D[6 * i + c];
                jac[6 * r + c] = s;
            }
        }
    }
    memcpy(pos_mm, p, 3 * sizeof pos_mm[0]);
    if (rot != NULL)
        memcpy(rot, d->R[RC_NJ], 9 * sizeof rot[0]);
}

void rc_kin_fk_dh_jac(rc_real pos_mm[3], rc_real rot[9], rc_real *jp, rc_real *jr, rc_kin_data *d, const rc_kin *k,
                      const rc_real q_rad[RC_NJ])
{
    rc_real p[3];
    RC_ASSERT(pos_mm != NULL && d != NULL && k != NULL && q_rad != NULL);
    kin_model_chain(p, d, k, q_rad);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rc_real z[3] = {d->R[i][2], d->R[i][5], d->R[i][8]};
        rc_real x1[3] = {d->R[i + 1][0], d->R[i + 1][3], d->R[i + 1][6]};
        rc_real v[3], wt[3], wa[3];
        const rc_real cm1 = k->link[i].tilt_cm1_rad, sb = k->link[i].tilt_sin;
        if (cm1 != RC_REAL_C(0.0) || sb != RC_REAL_C(0.0)) /* a, alpha act along x before the tilt */
            for (int r = 0; r < 3; ++r)
                x1[r] = x1[r] + cm1 * x1[r] + sb * d->R[i + 1][3 * r + 2];
        for (int r = 0; r < 3; ++r)
            v[r] = p[r] - d->o[i][r];
        cross3(wt, z, v);
        for (int r = 0; r < 3; ++r)
            v[r] = p[r] - d->o[i + 1][r];
        cross3(wa, x1, v);
        for (unsigned r = 0; r < 3; ++r) {
            rc_real *P = jp != NULL ? jp + r * RC_N_DH + RC_DH_PER_JOINT * i : NULL;
            rc_real *W = jr != NULL ? jr + r * RC_N_DH + RC_DH_PER_JOINT * i : NULL;
            if (P != NULL) { /* a, d, alpha, theta */
                P[0] = x1[r];
                P[1] = z[r];
                P[2] = wa[r];
                P[3] = wt[r];
            }
            if (W != NULL) {
                W[0] = RC_REAL_C(0.0);
                W[1] = RC_REAL_C(0.0);
                W[2] = x1[r];
                W[3] = z[r];
            }
        }
    }
    memcpy(pos_mm, p, 3 * sizeof pos_mm[0]);
    if (rot != NULL)
        memcpy(rot, d->R[RC_NJ], 9 * sizeof rot[0]);
}

rc_status rc_kin_chol6(rc_real A[36], rc_real b[RC_NJ])
{
    const unsigned n = RC_NJ;
    RC_ASSERT(A != NULL && b != NULL);
    for (unsigned j = 0; j < n; ++j) {
        rc_real d = A[j * n + j];
        for (unsigned k = 0; k < j; ++k)
            d -= A[j * n + k] * A[j * n + k];
        if (!(d > RC_REAL_C(0.0)) || !isfinite(d))
            return RC_ERR_NUMERIC;
        d = rc_rsqrt(d);
        A[j * n + j] = d;
        for (unsigned i = j + 1; i < n; ++i) {
            rc_real s = A[i * n + j];
            for (unsigned k = 0; k < j; ++k)
                s -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = s / d;
        }
    }
    for (unsigned i = 0; i < n; ++i) { /* L y = b */
        rc_real s = b[i];
        for (unsigned k = 0; k < i; ++k)
            s -= A[i * n + k] * b[k];
        b[i] = s / A[i * n + i];
    }
    for (unsigned i = n; i-- > 0;) { /* L^T x = y */
        rc_real s = b[i];
        for (unsigned k = i + 1; k < n; ++k)
            s -= A[k * n + i] * b[k];
        b[i] = s / A[i * n + i];
    }
    return RC_OK;
}
