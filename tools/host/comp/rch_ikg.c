/* SPDX-License-Identifier: MIT */
/* rch_ikg.c - the general inverse kinematics (rch_ikg.h): damped Newton on
 * rc_kin's forward kinematics and Jacobian from several starts, each
 * solution classified into a branch. */
#include "rch_ikg.h"

#include "rch_ikg_int.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define IKG_MAX_IT 60          /* Newton steps of one start */
#define IKG_GIVE_UP_IT 15      /* a start still this far off after so many steps is abandoned */
#define IKG_GIVE_UP_MM 1.0
#define IKG_W_ROT_MM 1000.0    /* a radian weighed as this many mm in the damped step */
#define IKG_MAX_STEP_RAD 0.6   /* largest joint change of one step */
#define IKG_SAME_RAD 1e-6      /* two solutions closer than this (each joint, modulo 2 pi) are one */
#define IKG_FACTOR_ZERO 1e-9   /* |factor| / scale below this at q = 0: the reference side is taken positive */

const char *rch_ikg_strerror(rch_ikg_status s)
{
    switch (s) {
    case RCH_IKG_OK:
        return "ok";
    case RCH_IKG_ARG:
        return "bad argument (target not finite, rotation not orthonormal, or branch not 0..7)";
    case RCH_IKG_UNREACHABLE:
        return "out of reach: no joint solution reaches this pose";
    case RCH_IKG_NO_BRANCH:
        return "reachable, but no solution in the branch asked for (a singular or boundary pose)";
    case RCH_IKG_LIMITS:
        return "the branch's solution is outside the joint limits";
    }
    return "unknown rch_ikg status";
}

static double wrap_pi(double a)
{
    a = fmod(a, 2.0 * M_PI);
    if (a > M_PI)
        a -= 2.0 * M_PI;
    else if (a <= -M_PI)
        a += 2.0 * M_PI;
    return a;
}

static void cross(double c[3], const double a[3], const double b[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The shoulder and elbow factors of the chain in d (rch_ikg.h). */
static void factors(double f[2], const rc_kin_data *d, double d4_mm)
{
    const double z0[3] = {d->R[0][2], d->R[0][5], d->R[0][8]};
    const double z1[3] = {d->R[1][2], d->R[1][5], d->R[1][8]};
    const double z3[3] = {d->R[3][2], d->R[3][5], d->R[3][8]};
    double v[3], u[3], w[3], c[3];
    for (int k = 0; k < 3; ++k)
        v[k] = d->o[5][k] - d->o[0][k];
    cross(c, v, z1);
    f[0] = dot(c, z0);
    for (int k = 0; k < 3; ++k) {
        u[k] = d->o[2][k] - d->o[1][k];
        w[k] = d->o[3][k] + d4_mm * z3[k] - d->o[2][k];
    }
    cross(c, u, w);
    f[1] = dot(c, z1);
}

rch_ikg_status rch_ikg_init(rch_ikg *ik, const rc_model *m, const double *tool_mm)
{
    memset(ik, 0, sizeof *ik);
    if (rc_kin_compile(&ik->kin, m) != RC_OK)
        return RCH_IKG_ARG;
    ik->kin.has_tool = tool_mm != NULL;
    for (int k = 0; k < 3; ++k)
        ik->kin.tool_mm[k] = tool_mm ? tool_mm[k] : 0.0;
    double reach = tool_mm ? sqrt(dot(tool_mm, tool_mm)) : 0.0;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double a = m->x[RC_P_A(i)], dd = m->x[RC_P_D(i)];
        reach += sqrt(a * a + dd * dd);
        ik->q_min_rad[i] = m->q_min_rad[i];
        ik->q_max_rad[i] = m->q_max_rad[i];
    }
    ik->reach_mm = reach;
    rch_ikg_seed_init(ik, m);
    ik->d4_mm = m->x[RC_P_D(3)];
    /* the zero position's sides (joint-side effects included) */
    rc_kin_data d;
    double p[3];
    const double q0[RC_NJ] = {0};
    rc_kin_fk(p, NULL, &d, &ik->kin, q0);
    double f[2];
    factors(f, &d, ik->d4_mm);
    const double scale = reach * reach + 1.0;
    for (int k = 0; k < 2; ++k)
        ik->ref_sign[k] = fabs(f[k]) <= IKG_FACTOR_ZERO * scale ? 1.0 : (f[k] > 0 ? 1.0 : -1.0);
    return RCH_IKG_OK;
}

void rch_ikg_fk(double pos_mm[3], double rot[9], const rch_ikg *ik, const double q_rad[RC_NJ])
{
    rc_kin_data d;
    rc_kin_fk(pos_mm, rot, &d, &ik->kin, q_rad);
}

static int branch_of(const rch_ikg *ik, const rc_kin_data *d, const double q_rad[RC_NJ])
{
    double f[2];
    factors(f, d, ik->d4_mm);
    return 4 * (f[0] * ik->ref_sign[0] < 0) + 2 * (f[1] * ik->ref_sign[1] < 0) +
           (sin(q_rad[4] + ik->kin.link[4].theta_off_rad) < 0);
}

static int boundary_of(const rch_ikg *ik, const rc_kin_data *d, const double q_rad[RC_NJ], double tol)
{
    double f[2];
    factors(f, d, ik->d4_mm);
    double u[3], w[3];
    const double z3[3] = {d->R[3][2], d->R[3][5], d->R[3][8]};
    for (int k = 0; k < 3; ++k) {
        u[k] = d->o[2][k] - d->o[1][k];
        w[k] = d->o[3][k] + ik->d4_mm * z3[k] - d->o[2][k];
    }
    const double uw = sqrt(dot(u, u) * dot(w, w));
    return 4 * (fabs(f[0]) <= tol * ik->reach_mm) + 2 * (fabs(f[1]) <= tol * uw) +
           (fabs(sin(q_rad[4] + ik->kin.link[4].theta_off_rad)) <= tol);
}

int rch_ikg_on_boundary(const rch_ikg *ik, const double q_rad[RC_NJ], double tol)
{
    rc_kin_data d;
    double p[3];
    rc_kin_fk(p, NULL, &d, &ik->kin, q_rad);
    return boundary_of(ik, &d, q_rad, tol);
}

int rch_ikg_branch(const rch_ikg *ik, const double q_rad[RC_NJ])
{
    rc_kin_data d;
    double p[3];
    rc_kin_fk(p, NULL, &d, &ik->kin, q_rad);
    return branch_of(ik, &d, q_rad);
}

/* The rotation vector of E = Rt R^T (base frame): the rotation from R to Rt. */
static void rot_err(double w[3], const double Rt[9], const double R[9])
{
    double E[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            E[3 * i + j] = Rt[3 * i] * R[3 * j] + Rt[3 * i + 1] * R[3 * j + 1] + Rt[3 * i + 2] * R[3 * j + 2];
    const double v[3] = {0.5 * (E[7] - E[5]), 0.5 * (E[2] - E[6]), 0.5 * (E[3] - E[1])};
    const double s = sqrt(dot(v, v));
    const double c = 0.5 * (E[0] + E[4] + E[8] - 1.0);
    if (c > 0.0 || s > 1e-6) {
        const double th = atan2(s, c);
        const double f = s > 1e-300 ? th / s : 1.0;
        for (int k = 0; k < 3; ++k)
            w[k] = f * v[k];
        return;
    }
    /* about pi: the axis from the diagonal of (E + I) / 2 */
    int a = 0;
    for (int k = 1; k < 3; ++k)
        if (E[4 * k] > E[4 * a])
            a = k;
    double ax[3];
    for (int k = 0; k < 3; ++k)
        ax[k] = 0.5 * (E[3 * k + a] + E[3 * a + k]) + (k == a ? 0.0 : 0.0);
    ax[a] = 0.5 * (E[4 * a] + 1.0);
    const double n = sqrt(dot(ax, ax));
    for (int k = 0; k < 3; ++k)
        w[k] = n > 0 ? M_PI * ax[k] / n : 0.0;
}

/* Solve J x = b (6 x 6, partial pivoting); 0, or -1 when a pivot is below
 * tiny. J and b are destroyed. */
static int lu6(double x[6], double J[36], double b[6], double tiny)
{
    for (int c = 0; c < 6; ++c) {
        int p = c;
        for (int r = c + 1; r < 6; ++r)
            if (fabs(J[6 * r + c]) > fabs(J[6 * p + c]))
                p = r;
        if (!(fabs(J[6 * p + c]) > tiny))
            return -1;
        if (p != c) {
            for (int k = 0; k < 6; ++k) {
                const double t = J[6 * c + k];
                J[6 * c + k] = J[6 * p + k];
                J[6 * p + k] = t;
            }
            const double t = b[c];
            b[c] = b[p];
            b[p] = t;
        }
        for (int r = c + 1; r < 6; ++r) {
            const double f = J[6 * r + c] / J[6 * c + c];
            for (int k = c; k < 6; ++k)
                J[6 * r + k] -= f * J[6 * c + k];
            b[r] -= f * b[c];
        }
    }
    for (int r = 5; r >= 0; --r) {
        double s = b[r];
        for (int k = r + 1; k < 6; ++k)
            s -= J[6 * r + k] * x[k];
        x[r] = s / J[6 * r + r];
    }
    return 0;
}

typedef struct {
    double pt[3], Rt[9];
} target;

/* The error at q: e (6: mm, rad), its weighted cost; J (36) when jac. */
static double eval(double e[6], double J[36], rc_kin_data *d, const rc_kin *kin, const target *t,
                   const double q[RC_NJ])
{
    double p[3], R[9];
    rc_kin_fk_jac(p, R, J, d, kin, q);
    for (int k = 0; k < 3; ++k)
        e[k] = t->pt[k] - p[k];
    rot_err(&e[3], t->Rt, R);
    return dot(e, e) + IKG_W_ROT_MM * IKG_W_ROT_MM * dot(&e[3], &e[3]);
}

/* Met to the goal (RCH_IKG_TOL_*): only such a solution lying on a boundary answers either label (a run
 * stalled next to a singularity may stop on the boundary between two solutions, solving neither side). */
static int converged(double err_mm, double err_rad)
{
    return err_mm <= RCH_IKG_TOL_MM && err_rad <= RCH_IKG_TOL_RAD;
}

/* A run that stops converging (no step pays, or out of steps): a solution when within RCH_IKG_ACCEPT_*
 * (next to a singularity the Jacobian's conditioning, not the method, bounds the last digits). */
static int stalled_ok(double err_mm, double err_rad)
{
    return err_mm <= RCH_IKG_ACCEPT_MM && err_rad <= RCH_IKG_ACCEPT_RAD;
}

/* How one Newton run goes: the branch it keeps to (-1: none; the scan's polish), the joint it holds (-1:
 * none; the scan along a self-motion), its steps. */
typedef struct {
    const rch_ikg *ik;
    int keep, fix;
    unsigned max_it;
} newton_opt;

/* Newton (Levenberg-Marquardt where a step does not pay) from q; 1 when
 * converged (q the solution, d its chain), 0 not. */
static int newton_kin(double q[RC_NJ], double *err_mm, double *err_rad, unsigned *iters, rc_kin_data *d,
                      const rc_kin *kin, double reach_mm, const target *t, const newton_opt *o)
{
    double e[6], J[36], qa[RC_NJ], ea[6], Ja[36];
    double cost = eval(e, J, d, kin, t, q);
    double lambda = 0.0;
    const double tiny = 1e-10 * (reach_mm + 1.0);
    for (unsigned it = 0; it < o->max_it; ++it) {
        *err_mm = sqrt(dot(e, e));
        *err_rad = sqrt(dot(&e[3], &e[3]));
        if (*err_mm <= RCH_IKG_TOL_MM && *err_rad <= RCH_IKG_TOL_RAD)
            return 1;
        if (!isfinite(cost) || (it >= IKG_GIVE_UP_IT && *err_mm > IKG_GIVE_UP_MM))
            return 0;
        ++*iters;
        double dq[6];
        int ok = -1;
        if (lambda == 0.0 && o->fix < 0) {
            double A[36], b[6];
            memcpy(A, J, sizeof A);
            memcpy(b, e, sizeof b);
            ok = lu6(dq, A, b, tiny);
        }
        if (ok != 0) { /* damped: (Jw^T Jw + lambda I) dq = Jw^T ew */
            double A[36], b[6];
            double dmax = 0.0;
            for (int i = 0; i < 6; ++i) {
                b[i] = 0.0;
                for (int r = 0; r < 6; ++r) {
                    const double w2 = r < 3 ? 1.0 : IKG_W_ROT_MM * IKG_W_ROT_MM;
                    b[i] += w2 * J[6 * r + i] * e[r];
                }
                for (int j = 0; j < 6; ++j) {
                    double s = 0.0;
                    for (int r = 0; r < 6; ++r)
                        s += (r < 3 ? 1.0 : IKG_W_ROT_MM * IKG_W_ROT_MM) * J[6 * r + i] * J[6 * r + j];
                    A[6 * i + j] = s;
                }
                dmax = fmax(dmax, A[7 * i]);
            }
            if (lambda == 0.0)
                lambda = 1e-6 * dmax;
            for (int i = 0; i < 6; ++i)
                A[7 * i] += lambda;
            if (o->fix >= 0) { /* the held joint's row and column: dq = 0 there */
                for (int i = 0; i < 6; ++i)
                    A[6 * i + o->fix] = A[6 * o->fix + i] = 0.0;
                A[7 * o->fix] = 1.0;
                b[o->fix] = 0.0;
            }
            if (rc_kin_chol6(A, b) != RC_OK)
                return stalled_ok(*err_mm, *err_rad);
            memcpy(dq, b, sizeof dq);
        }
        double big = 0.0;
        for (int i = 0; i < 6; ++i)
            big = fmax(big, fabs(dq[i]));
        const double sc = big > IKG_MAX_STEP_RAD ? IKG_MAX_STEP_RAD / big : 1.0;
        for (int i = 0; i < 6; ++i)
            qa[i] = q[i] + sc * dq[i];
        const double ca = eval(ea, Ja, d, kin, t, qa);
        if (ca < cost && (o->keep < 0 || branch_of(o->ik, d, qa) == o->keep)) {
            memcpy(q, qa, sizeof qa);
            memcpy(e, ea, sizeof ea);
            memcpy(J, Ja, sizeof Ja);
            cost = ca;
            lambda = lambda > 0.0 ? lambda * 0.1 : 0.0;
            if (lambda > 0.0 && lambda < 1e-3)
                lambda = 0.0;
        } else {
            double dmax = 1.0;
            for (int i = 0; i < 6; ++i)
                dmax = fmax(dmax, fabs(J[7 * i]));
            lambda = lambda > 0.0 ? lambda * 10.0 : 1e-4 * dmax * dmax;
            if (lambda > 1e12 * (dmax * dmax + 1.0))
                return stalled_ok(*err_mm, *err_rad);
            eval(e, J, d, kin, t, q); /* d back to q */
        }
    }
    *err_mm = sqrt(dot(e, e));
    *err_rad = sqrt(dot(&e[3], &e[3]));
    return stalled_ok(*err_mm, *err_rad);
}

static int newton(double q[RC_NJ], double *err_mm, double *err_rad, unsigned *iters, rc_kin_data *d,
                  const rch_ikg *ik, const target *t)
{
    const newton_opt o = {ik, -1, -1, IKG_MAX_IT};
    return newton_kin(q, err_mm, err_rad, iters, d, &ik->kin, ik->reach_mm, t, &o);
}


/* Continuation from the idealised arm's closed-form solution q (exact
 * there): the DH rows moved from the idealised table to the real one in
 * IKG_HOMOTOPY steps, Newton at each from the step before, so that the
 * solution keeps the branch it had where a start of the real arm would slip
 * into the neighbouring one (next to a singularity). 1 when converged (q, d
 * at the real arm). */
#define IKG_HOMOTOPY 8
static int homotopy(double q[RC_NJ], double *err_mm, double *err_rad, unsigned *iters, rc_kin_data *d,
                    const rch_ikg *ik, const target *t)
{
    rc_kin k = ik->kin;
    const newton_opt o = {ik, -1, -1, IKG_MAX_IT};
    for (unsigned s = 1; s <= IKG_HOMOTOPY; ++s) {
        const double f = (double)s / IKG_HOMOTOPY;
        for (unsigned i = 0; i < RC_NJ; ++i) {
            const rc_kin_link *r = &ik->kin.link[i];
            const double ar = atan2(r->sin_alpha, r->cos_alpha), ai = ik->ideal[i][2];
            const double al = ai + f * remainder(ar - ai, 2.0 * M_PI);
            k.link[i].a_mm = ik->ideal[i][0] + f * (r->a_mm - ik->ideal[i][0]);
            k.link[i].d_mm = ik->ideal[i][1] + f * (r->d_mm - ik->ideal[i][1]);
            k.link[i].cos_alpha = cos(al);
            k.link[i].sin_alpha = sin(al);
            k.link[i].theta_off_rad = ik->ideal[i][3] + f * (r->theta_off_rad - ik->ideal[i][3]);
        }
        if (!newton_kin(q, err_mm, err_rad, iters, d, s == IKG_HOMOTOPY ? &ik->kin : &k, ik->reach_mm, t, &o))
            return 0;
    }
    return 1;
}

/* The scan along a self-motion. Next to the wrist's singularity (a UR's axes 2, 3, 4 and 6 parallel, a
 * spherical wrist's 4 and 6 aligned) or the shoulder's (the wrist point on axis 1), the solutions of a
 * calibrated arm lie on a curve along which the pose hardly changes (the idealised arm's self-motion): a
 * start's joints along it are ill-determined (a closed-form start of the right branch may be a radian off),
 * the Jacobian is ill-conditioned there, and Newton from the start slides to another solution on the curve,
 * of another branch, or stalls in the flat valley. Here joint j is held at IKG_SCAN + 1 values over a turn
 * from q0 and the other five fitted (damped steps, each from the value before: the curve followed; with j
 * held the five are well conditioned). At each the residual left is along the one direction the five
 * columns of the Jacobian do not span: its component along their generalized cross product (continuous
 * along the curve) is a signed function g of the held value, zero at each solution. Each sign change is
 * bracketed and its root found (regula falsi, Illinois), then polished by Newton on all six; the roots are
 * taken until one is of `branch`. 1 then (q, d, errors). */
#define IKG_SCAN 48
#define IKG_SCAN_IT 6
#define IKG_ROOT_IT 40

/* The determinant of a 5 x 5 matrix (row-major, destroyed; partial pivoting). */
static double det5(double M[25])
{
    double det = 1.0;
    for (int c = 0; c < 5; ++c) {
        int p = c;
        for (int r = c + 1; r < 5; ++r)
            if (fabs(M[5 * r + c]) > fabs(M[5 * p + c]))
                p = r;
        if (M[5 * p + c] == 0.0)
            return 0.0;
        if (p != c) {
            for (int k = 0; k < 5; ++k) {
                const double tmp = M[5 * c + k];
                M[5 * c + k] = M[5 * p + k];
                M[5 * p + k] = tmp;
            }
            det = -det;
        }
        det *= M[6 * c];
        for (int r = c + 1; r < 5; ++r) {
            const double f = M[5 * r + c] / M[6 * c];
            for (int k = c; k < 5; ++k)
                M[5 * r + k] -= f * M[5 * c + k];
        }
    }
    return det;
}

/* q[j] = s, the other five fitted from q; returns g (above). */
static double fit_held(double q[RC_NJ], unsigned *iters, rc_kin_data *d, const rch_ikg *ik, const target *t,
                       int j, double s, unsigned it)
{
    const newton_opt hold = {ik, -1, j, it};
    double em, er, e[6], J[36];
    q[j] = s;
    newton_kin(q, &em, &er, iters, d, &ik->kin, ik->reach_mm, t, &hold);
    eval(e, J, d, &ik->kin, t, q);
    double n[6], nn = 0.0, g = 0.0;
    for (int i = 0; i < 6; ++i) { /* n_i = (-1)^i det(the weighted columns but j, row i left out) */
        double M[25];
        int r = 0;
        for (int row = 0; row < 6; ++row) {
            if (row == i)
                continue;
            const double w = row < 3 ? 1.0 : IKG_W_ROT_MM;
            int c = 0;
            for (int col = 0; col < 6; ++col)
                if (col != j)
                    M[5 * r + c++] = w * J[6 * row + col];
            ++r;
        }
        n[i] = (i & 1 ? -1.0 : 1.0) * det5(M);
        nn += n[i] * n[i];
        g += n[i] * e[i] * (i < 3 ? 1.0 : IKG_W_ROT_MM);
    }
    return nn > 0.0 && isfinite(g) ? g / sqrt(nn) : 0.0;
}

/* A solution of the branch next to the asked one across a boundary it lies within RCH_IKG_NEAR_BOUNDARY
 * of (rch_ikg.h: returned when the asked branch has none found). */
typedef struct {
    int have, branch;
    double q[RC_NJ], err_mm, err_rad;
} near_sol;

static void near_offer(near_sol *ns, const rch_ikg *ik, const rc_kin_data *d, const double q[RC_NJ], int b,
                       int branch, double em, double er)
{
    if (ns == NULL || ns->have || branch == RCH_IKG_ANY_BRANCH || b == branch ||
        ((b ^ branch) & ~boundary_of(ik, d, q, RCH_IKG_NEAR_BOUNDARY)) != 0)
        return;
    ns->have = 1;
    ns->branch = b;
    memcpy(ns->q, q, sizeof ns->q);
    ns->err_mm = em;
    ns->err_rad = er;
}

/* The root of g in [a, b] (signs differ there) from x at a (regula falsi, Illinois), then Newton on all
 * six kept to the branch where it is in it; 1 when a solution of `branch` (q, d, errors). */
static int held_root(double q[RC_NJ], double *err_mm, double *err_rad, unsigned *iters, rc_kin_data *d,
                     const rch_ikg *ik, const target *t, int j, int branch, near_sol *ns, const double x0[RC_NJ],
                     double a, double b, double ga, double gb)
{
    double x[RC_NJ];
    memcpy(x, x0, sizeof x);
    int side = 0;
    for (int it = 0; it < IKG_ROOT_IT && ga != 0.0 && b - a > 1e-13; ++it) {
        const double c = (a * gb - b * ga) / (gb - ga);
        const double gc = fit_held(x, iters, d, ik, t, j, c, IKG_SCAN_IT);
        if (gc == 0.0)
            break;
        if ((gc > 0.0) == (gb > 0.0)) {
            b = c;
            gb = gc;
            if (side == -1)
                ga *= 0.5;
            side = -1;
        } else {
            a = c;
            ga = gc;
            if (side == 1)
                gb *= 0.5;
            side = 1;
        }
    }
    const newton_opt o = {ik, rch_ikg_branch(ik, x) == branch ? branch : -1, -1, 4 * IKG_MAX_IT};
    if (!newton_kin(x, err_mm, err_rad, iters, d, &ik->kin, ik->reach_mm, t, &o))
        return 0;
    const int bx = branch_of(ik, d, x);
    if (bx == branch ||
        (converged(*err_mm, *err_rad) && ((bx ^ branch) & ~boundary_of(ik, d, x, RCH_IKG_BOUNDARY)) == 0)) {
        memcpy(q, x, sizeof x);
        return 1;
    }
    near_offer(ns, ik, d, x, bx, branch, *err_mm, *err_rad);
    return 0;
}

/* g at n + 1 held values s0 + k h from x0; each sign change to held_root; where |g| has a local minimum
 * without one (two roots in a step: a pair next to a fold or the boundary), the two steps around it again,
 * IKG_SUB times finer, depth more times. */
#define IKG_SUB 16
#define IKG_SCAN_NEAR 0.1 /* a scan starts where a factor is within this of its boundary (rch_ikg_on_boundary) */
#define IKG_MET 4 /* solutions of other branches a solve keeps as the scans' starts */
#define IKG_SUB_MIN 2   /* minima refined per level */
#define IKG_SUB_DEPTH 5 /* levels: a step of 2 pi / 48 / 8^5 (4e-6 rad) at the finest */
static int scan_range(double q[RC_NJ], double *err_mm, double *err_rad, unsigned *iters, rc_kin_data *d,
                      const rch_ikg *ik, const target *t, int j, int branch, near_sol *ns, const double x0[RC_NJ],
                      double s0, double h, int n, int depth)
{
    double qs[IKG_SCAN + 1][RC_NJ], g[IKG_SCAN + 1], x[RC_NJ];
    memcpy(x, x0, sizeof x);
    for (int k = 0; k <= n; ++k) {
        g[k] = fit_held(x, iters, d, ik, t, j, s0 + h * k, IKG_SCAN_IT);
        memcpy(qs[k], x, sizeof x);
    }
    for (int k = 0; k < n; ++k)
        if (((g[k] <= 0.0 && g[k + 1] > 0.0) || (g[k] >= 0.0 && g[k + 1] < 0.0)) &&
            held_root(q, err_mm, err_rad, iters, d, ik, t, j, branch, ns, qs[k], s0 + h * k, s0 + h * (k + 1), g[k],
                      g[k + 1]))
            return 1;
    if (depth == 0)
        return 0;
    /* the IKG_SUB_MIN smallest such minima, smallest first */
    int mins[IKG_SUB_MIN], nm = 0;
    for (int k = 1; k < n; ++k) {
        if (!(fabs(g[k]) <= fabs(g[k - 1]) && fabs(g[k]) <= fabs(g[k + 1]) && (g[k - 1] > 0.0) == (g[k] > 0.0) &&
              (g[k + 1] > 0.0) == (g[k] > 0.0)))
            continue;
        if (nm < IKG_SUB_MIN)
            mins[nm++] = k;
        else if (fabs(g[k]) < fabs(g[mins[nm - 1]]))
            mins[nm - 1] = k;
        else
            continue;
        for (int i = nm - 1; i > 0 && fabs(g[mins[i]]) < fabs(g[mins[i - 1]]); --i) {
            const int tmp = mins[i];
            mins[i] = mins[i - 1];
            mins[i - 1] = tmp;
        }
    }
    for (int i = 0; i < nm; ++i) {
        const int k = mins[i];
        if (scan_range(q, err_mm, err_rad, iters, d, ik, t, j, branch, ns, qs[k - 1], s0 + h * (k - 1),
                       2.0 * h / IKG_SUB, IKG_SUB, depth - 1))
            return 1;
    }
    return 0;
}

static int scan(double q[RC_NJ], double *err_mm, double *err_rad, unsigned *iters, rc_kin_data *d,
                const rch_ikg *ik, const target *t, const double q0[RC_NJ], int j, int branch, near_sol *ns)
{
    return scan_range(q, err_mm, err_rad, iters, d, ik, t, j, branch, ns, q0, q0[j], 2.0 * M_PI / IKG_SCAN, IKG_SCAN,
                      IKG_SUB_DEPTH);
}

/* Starts: axis 1 towards the target (and away), the arm's two elbow sides
 * and the wrist's two; k counts them. */
#define IKG_N_START 16
static void start_of(double q[RC_NJ], unsigned k, const rch_ikg *ik, const target *t)
{
    const double phi = atan2(t->pt[1], t->pt[0]) - ik->kin.link[0].theta_off_rad;
    static const double q23[4][2] = {{-0.5, 1.0}, {0.5, -1.0}, {-1.2, -0.6}, {1.0, 0.8}};
    q[0] = wrap_pi(phi + ((k & 1) ? M_PI : 0.0));
    q[1] = q23[(k >> 1) & 3][0];
    q[2] = q23[(k >> 1) & 3][1];
    q[3] = 0.3;
    q[4] = (k & 8) ? -1.2 : 1.2;
    q[5] = 0.0;
}

/* q moved by whole turns nearest ref (or into (-pi, pi]), then into the
 * limits when a turn fits; 1 inside the limits. */
static int place(double q[RC_NJ], const rch_ikg *ik, const double *ref)
{
    int inside = 1;
    for (int i = 0; i < RC_NJ; ++i) {
        double v = ref ? ref[i] + wrap_pi(q[i] - ref[i]) : wrap_pi(q[i]);
        if (v < ik->q_min_rad[i] - 1e-12 || v > ik->q_max_rad[i] + 1e-12) {
            double best = v, bd = HUGE_VAL;
            for (int n = -3; n <= 3; ++n) {
                const double w = v + 2.0 * M_PI * n;
                if (w >= ik->q_min_rad[i] - 1e-12 && w <= ik->q_max_rad[i] + 1e-12) {
                    const double dd = ref ? fabs(w - ref[i]) : fabs(w);
                    if (dd < bd) {
                        bd = dd;
                        best = w;
                    }
                }
            }
            if (bd == HUGE_VAL)
                inside = 0;
            v = best;
        }
        q[i] = v;
    }
    return inside;
}

static double dist(const double a[RC_NJ], const double b[RC_NJ])
{
    double s = 0.0;
    for (int i = 0; i < RC_NJ; ++i)
        s += (a[i] - b[i]) * (a[i] - b[i]);
    return s;
}

static double dist_turns(const double a[RC_NJ], const double b[RC_NJ])
{
    double s = 0.0;
    for (int i = 0; i < RC_NJ; ++i) {
        const double e = wrap_pi(a[i] - b[i]);
        s += e * e;
    }
    return s;
}

static int target_of(target *t, const double pos_mm[3], const double rot[9])
{
    for (int k = 0; k < 3; ++k) {
        if (!isfinite(pos_mm[k]))
            return -1;
        t->pt[k] = pos_mm[k];
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const double g = rot[i] * rot[j] + rot[3 + i] * rot[3 + j] + rot[6 + i] * rot[6 + j];
            if (!(fabs(g - (i == j)) <= 1e-6))
                return -1;
        }
    memcpy(t->Rt, rot, sizeof t->Rt);
    return 0;
}

/* The closed-form starts (rch_ikg_seeds) in the order they are tried:
 * those of the branch first (by their branch on the real arm), nearest the
 * seed first. Returns how many. */
static int closed_starts(double cs[8][RC_NJ], int order[8], const rch_ikg *ik, const double pos_mm[3],
                         const double rot[9], int branch, const double *seed_rad)
{
    const int ncs = rch_ikg_seeds(cs, ik, pos_mm, rot);
    double key[8];
    for (int k = 0; k < ncs; ++k) {
        order[k] = k;
        key[k] = seed_rad ? dist_turns(cs[k], seed_rad) : 0.0;
        if (branch != RCH_IKG_ANY_BRANCH && rch_ikg_branch(ik, cs[k]) != branch)
            key[k] += 1e6;
    }
    for (int i = 1; i < ncs; ++i) /* insertion sort: 8 at most */
        for (int j = i; j > 0 && key[order[j]] < key[order[j - 1]]; --j) {
            const int tmp = order[j];
            order[j] = order[j - 1];
            order[j - 1] = tmp;
        }
    return ncs;
}

rch_ikg_status rch_ikg_solve(double q_rad[RC_NJ], rch_ikg_info *info, const rch_ikg *ik, const double pos_mm[3],
                             const double rot[9], int branch, const double *seed_rad)
{
    rch_ikg_info inf = {0, 0, HUGE_VAL, HUGE_VAL, -1};
    target t;
    rch_ikg_status st = RCH_IKG_OK;
    if (target_of(&t, pos_mm, rot) != 0 || branch < RCH_IKG_ANY_BRANCH || branch > 7) {
        st = RCH_IKG_ARG;
        goto out;
    }
    if (sqrt(dot(pos_mm, pos_mm)) > ik->reach_mm + 1e-6) {
        st = RCH_IKG_UNREACHABLE;
        goto out;
    }
    if (seed_rad)
        for (int i = 0; i < RC_NJ; ++i)
            if (!isfinite(seed_rad[i])) {
                st = RCH_IKG_ARG;
                goto out;
            }
    double best[RC_NJ], best_d = HUGE_VAL;
    int found = 0, reached = 0, in_branch = 0;
    /* the closed-form starts, those of the branch first (by their branch on
     * the real arm) or nearest the seed first */
    double cs[8][RC_NJ];
    int order[8] = {0};
    int ncs = -1; /* computed when the seed's own run did not do */
    double conv_q[8][RC_NJ]; /* solutions of another branch met on the way (for the wrist's reflections) */
    near_sol ns = {0, -1, {0}, 0.0, 0.0};
    unsigned n_conv = 0, n_refl = 0;
    double met[IKG_MET][RC_NJ]; /* solutions of other branches met (the scans start from them too) */
    int n_met = 0;
    for (unsigned k = seed_rad ? 0u : 1u; ncs < 0 || k < 1u + 2u * (unsigned)ncs + IKG_N_START + 2u * n_refl;
         ++k) {
        double q[RC_NJ], em, er;
        rc_kin_data d;
        if (k >= 1 && ncs < 0)
            ncs = closed_starts(cs, order, ik, pos_mm, rot, branch, seed_rad);
        const unsigned k_refl = 1u + 2u * (unsigned)(ncs < 0 ? 0 : ncs); /* where the reflections start */
        if (k == 0)
            memcpy(q, seed_rad, sizeof q);
        else if (k <= (unsigned)ncs)
            memcpy(q, cs[order[k - 1]], sizeof q);
        else {
            if (found || in_branch)
                break; /* the closed-form starts found it (or it outside the limits): no generic ones */
            if (k <= 2u * (unsigned)ncs) { /* then each carried from the idealised arm */
                memcpy(q, cs[order[k - 1 - (unsigned)ncs]], sizeof q);
                if (k == 2u * (unsigned)ncs && branch != RCH_IKG_ANY_BRANCH)
                    n_refl = n_conv; /* next: the other wrist side of each solution met */
            } else if (k < k_refl + 2u * n_refl) {
                /* a solution of the other wrist side reflected: q5 -> -q5 (an offset wrist's pair next to its
                 * singularity), and with q4, q6 half a turn on (a spherical wrist's flip) */
                const unsigned r = k - k_refl;
                memcpy(q, conv_q[r / 2], sizeof q);
                const double th5 = q[4] + ik->kin.link[4].theta_off_rad;
                q[4] = -th5 - ik->kin.link[4].theta_off_rad;
                if (r % 2) {
                    q[3] += M_PI;
                    q[5] += M_PI;
                }
            } else
                start_of(q, k - k_refl - 2u * n_refl, ik, &t);
        }
        ++inf.starts;
        const int conv = k > (unsigned)ncs && k <= 2u * (unsigned)ncs
                             ? homotopy(q, &em, &er, &inf.iterations, &d, ik, &t)
                             : newton(q, &em, &er, &inf.iterations, &d, ik, &t);
        if (!conv) {
            if (!reached && em < inf.err_mm) {
                inf.err_mm = em;
                inf.err_rad = er;
            }
            continue;
        }
        reached = 1;
        int b = branch_of(ik, &d, q);
        if (branch != RCH_IKG_ANY_BRANCH && b != branch && converged(em, er) &&
            ((b ^ branch) & ~boundary_of(ik, &d, q, RCH_IKG_BOUNDARY)) == 0)
            b = branch; /* on the boundary of the bits that differ: on both sides (rch_ikg.h) */
        if (branch != RCH_IKG_ANY_BRANCH && b != branch) {
            near_offer(&ns, ik, &d, q, b, branch, em, er);
            if (n_met < IKG_MET)
                memcpy(met[n_met++], q, sizeof q);
            if ((b ^ branch) == 1 && n_conv < 8 && n_refl == 0)
                memcpy(conv_q[n_conv++], q, sizeof q);
            continue;
        }
        in_branch = 1;
        if (!place(q, ik, seed_rad))
            continue;
        const double dd = seed_rad ? dist(q, seed_rad) : 0.0;
        if (dd < best_d) {
            best_d = dd;
            memcpy(best, q, sizeof best);
            inf.err_mm = em;
            inf.err_rad = er;
            inf.branch = b;
            found = 1;
        }
        /* no seed: the first will do; a seed's own run: the nearest */
        if (!seed_rad || k == 0)
            break;
    }
    /* none of the branch: the scans along the self-motions (q6 held: the wrist's, q1: the shoulder's),
     * across the elbow's fold (q3 held: the pair of solutions either side of it), then along the wrist's
     * self-motion by q2 and q4 (a UR's axes 2, 3, 4 and 6 parallel: any of them follows the curve, and q2
     * or q4 held where the elbow is folded or stretched as well, the five then not singular) from each
     * closed-form start and each solution met, those of the branch first */
    static const int held[5] = {5, 0, 2, 1, 3};
    for (int jj = 0; branch != RCH_IKG_ANY_BRANCH && !in_branch && jj < 5; ++jj)
        for (int i = 0, j = held[jj]; !in_branch && i < ncs + n_met; ++i) {
            double q[RC_NJ], em, er;
            rc_kin_data d;
            const double *x0 = i < ncs ? cs[order[i]] : met[i - ncs];
            rc_kin_fk(q, NULL, &d, &ik->kin, x0);
            if (!boundary_of(ik, &d, x0, IKG_SCAN_NEAR))
                continue; /* far from every singularity: the starts found what there is */
            ++inf.starts;
            if (!scan(q, &em, &er, &inf.iterations, &d, ik, &t, x0, j, branch, &ns))
                continue;
            reached = in_branch = 1;
            if (!place(q, ik, seed_rad))
                continue;
            memcpy(best, q, sizeof best);
            inf.err_mm = em;
            inf.err_rad = er;
            inf.branch = branch;
            found = 1;
        }
    /* none of the branch found, but one of the branch across a boundary it lies next to (rch_ikg.h) */
    if (!found && ns.have) {
        double q[RC_NJ];
        memcpy(q, ns.q, sizeof q);
        if (place(q, ik, seed_rad)) {
            memcpy(best, q, sizeof best);
            inf.err_mm = ns.err_mm;
            inf.err_rad = ns.err_rad;
            inf.branch = ns.branch;
            found = 1;
        }
    }
    /* any branch, and none found (or every one outside the limits): each branch asked in turn (its scans find
     * the solutions next to a singularity the starts slid past), the one nearest the seed */
    for (int b = 0; branch == RCH_IKG_ANY_BRANCH && !found && b < 8; ++b) {
        double q[RC_NJ];
        rch_ikg_info ib;
        const rch_ikg_status sb = rch_ikg_solve(q, &ib, ik, pos_mm, rot, b, seed_rad);
        inf.starts += ib.starts;
        inf.iterations += ib.iterations;
        reached |= sb != RCH_IKG_UNREACHABLE;
        in_branch |= sb == RCH_IKG_OK || sb == RCH_IKG_LIMITS;
        if (sb != RCH_IKG_OK)
            continue;
        const double dd = seed_rad ? dist(q, seed_rad) : 0.0;
        if (dd < best_d) {
            best_d = dd;
            memcpy(best, q, sizeof best);
            inf.err_mm = ib.err_mm;
            inf.err_rad = ib.err_rad;
            inf.branch = ib.branch;
        }
        found = 1;
    }
    if (found)
        memcpy(q_rad, best, sizeof best);
    else
        st = !reached ? RCH_IKG_UNREACHABLE : !in_branch ? RCH_IKG_NO_BRANCH : RCH_IKG_LIMITS;
out:
    if (info)
        *info = inf;
    return st;
}

int rch_ikg_all(double q_rad[RCH_IKG_MAX_SOL][RC_NJ], int branch[RCH_IKG_MAX_SOL], const rch_ikg *ik,
                const double pos_mm[3], const double rot[9])
{
    target t;
    if (target_of(&t, pos_mm, rot) != 0 || sqrt(dot(pos_mm, pos_mm)) > ik->reach_mm + 1e-6)
        return 0;
    int n = 0;
    double cs[8][RC_NJ];
    const int ncs = rch_ikg_seeds(cs, ik, pos_mm, rot);
    /* the closed-form starts, the generic ones, then each generic one with
     * axes 4 and 6 turned half a turn and axis 3 mirrored */
    for (unsigned k = 0; k < (unsigned)ncs + 2 * IKG_N_START && n < RCH_IKG_MAX_SOL; ++k) {
        double q[RC_NJ], em, er;
        unsigned it = 0;
        rc_kin_data d;
        if (k < (unsigned)ncs)
            memcpy(q, cs[k], sizeof q);
        else {
            const unsigned g = k - (unsigned)ncs;
            start_of(q, g % IKG_N_START, ik, &t);
            if (g >= IKG_N_START) {
                q[3] += M_PI;
                q[5] += M_PI;
                q[2] = -q[2];
            }
        }
        if (!newton(q, &em, &er, &it, &d, ik, &t))
            continue;
        const int b = branch_of(ik, &d, q);
        for (int i = 0; i < RC_NJ; ++i)
            q[i] = wrap_pi(q[i]);
        int j;
        for (j = 0; j < n; ++j) {
            int i;
            for (i = 0; i < RC_NJ; ++i)
                if (fabs(wrap_pi(q[i] - q_rad[j][i])) > IKG_SAME_RAD)
                    break;
            if (i == RC_NJ)
                break;
        }
        if (j < n)
            continue;
        memcpy(q_rad[n], q, sizeof q_rad[n]);
        if (branch)
            branch[n] = b;
        ++n;
    }
    return n;
}
