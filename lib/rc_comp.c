/* SPDX-License-Identifier: MIT */
/* rc_comp.c - damped Gauss-Newton compensation and inverse kinematics on
 * compiled tables (rc_kin), in rc_real, with every intermediate in the
 * caller's rc_comp_work. The rc_model wrappers are in rc_comp_model.c. */
#include "rc_comp.h"

#include <string.h>

#define RC_PI RC_REAL_C(3.14159265358979323846)

/* Resolved configuration (defaults filled in). */
typedef struct {
    unsigned max_iter;
    rc_real tol_mm, tol_rad, w_rot, lam2_min, max_step, max_dev;
    int want_rot;
} comp_params;

#define LAM2_MAX RC_REAL_C(1e12) /* (mm/rad)^2: beyond this a step is negligible */

const char *rc_comp_exit_str(rc_comp_exit e)
{
    switch (e) {
    case RC_COMP_CONVERGED: return "converged";
    case RC_COMP_POSITION_ONLY: return "position matched, orientation best effort";
    case RC_COMP_MAX_ITER: return "iteration limit";
    case RC_COMP_NO_DESCENT: return "no further descent (singular pose)";
    case RC_COMP_BAD_INPUT: return "target or seed not finite or outside the joint limits";
    case RC_COMP_NONFINITE: return "model produced non-finite values";
    case RC_COMP_JOINT_LIMIT: return "a joint limit is in the way";
    case RC_COMP_MAX_DEV: return "the correction needed exceeds the largest allowed (max_dev)";
    }
    return "unknown";
}

static void params_resolve(comp_params *p, const rc_comp_config *cfg, rc_real dev_default, int has_rot)
{
    static const rc_comp_config zero;
    if (cfg == NULL)
        cfg = &zero;
    p->max_iter = cfg->max_iter > 0 ? cfg->max_iter : 12u;
    p->tol_mm = cfg->tol_mm > RC_REAL_C(0.0) ? cfg->tol_mm : RC_COMP_TOL_MM;
    p->tol_rad = cfg->tol_rad > RC_REAL_C(0.0) ? cfg->tol_rad : RC_COMP_TOL_RAD;
    p->w_rot = cfg->w_rot_mm > RC_REAL_C(0.0) ? cfg->w_rot_mm : RC_REAL_C(100.0);
    const rc_real lam = cfg->lambda_mm > RC_REAL_C(0.0) ? cfg->lambda_mm : RC_REAL_C(0.01);
    p->lam2_min = lam * lam;
    p->max_step = cfg->max_step_rad > RC_REAL_C(0.0) ? cfg->max_step_rad : RC_REAL_C(0.2);
    p->max_dev = cfg->max_dev_rad > RC_REAL_C(0.0) ? cfg->max_dev_rad : dev_default;
    p->want_rot = has_rot && (cfg->flags & RC_COMP_FLAG_POSITION_ONLY) == 0u;
}

static int all_finite(const rc_real *v, unsigned n)
{
    for (unsigned i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Rotation vector of Rd R^T (base frame) into e (3); returns its angle. */
static rc_real rot_log(rc_real e[3], const rc_real Rd[9], const rc_real R[9])
{
    rc_real E[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            E[3 * r + c] = Rd[3 * r] * R[3 * c] + Rd[3 * r + 1] * R[3 * c + 1] + Rd[3 * r + 2] * R[3 * c + 2];
    const rc_real v[3] = {RC_REAL_C(0.5) * (E[7] - E[5]), RC_REAL_C(0.5) * (E[2] - E[6]),
                          RC_REAL_C(0.5) * (E[3] - E[1])};
    const rc_real s = rc_rsqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const rc_real c = RC_REAL_C(0.5) * (E[0] + E[4] + E[8] - RC_REAL_C(1.0));
    const rc_real th = rc_ratan2(s, c);
    if (s > RC_REAL_C(1e-9)) {
        const rc_real k = th / s;
        for (int i = 0; i < 3; ++i)
            e[i] = v[i] * k;
    } else if (c > RC_REAL_C(0.0)) {
        for (int i = 0; i < 3; ++i)
            e[i] = v[i];
    } else { /* half a turn: the axis from the symmetric part E = 2 a a^T - I */
        int k = 0;
        if (E[4] > E[0])
            k = 1;
        if (E[8] > E[4 * k])
            k = 2;
        const rc_real ak = rc_rsqrt(rc_rfmax(RC_REAL_C(0.0), RC_REAL_C(0.5) * (E[4 * k] + RC_REAL_C(1.0))));
        for (int i = 0; i < 3; ++i)
            e[i] = (i == k) ? RC_PI * ak : RC_PI * (E[3 * k + i] + E[3 * i + k]) / (RC_REAL_C(4.0) * ak);
    }
    return th;
}

/* Residual of pt (p, R set) against the target (pd, Rd or NULL). Returns 0
 * on non-finite. */
static int point_residual(rc_comp_point *pt, const rc_real pd[3], const rc_real *Rd, const comp_params *pp,
                          int use_rot)
{
    for (int i = 0; i < 3; ++i)
        pt->e[i] = pd[i] - pt->p[i];
    pt->pos_err = rc_rsqrt(pt->e[0] * pt->e[0] + pt->e[1] * pt->e[1] + pt->e[2] * pt->e[2]);
    if (Rd != NULL) {
        pt->rot_err = rot_log(&pt->e[3], Rd, pt->R);
    } else {
        pt->e[3] = pt->e[4] = pt->e[5] = RC_REAL_C(0.0);
        pt->rot_err = RC_REAL_C(0.0);
    }
    pt->cost = pt->pos_err * pt->pos_err;
    if (use_rot)
        pt->cost += pp->w_rot * pp->w_rot * pt->rot_err * pt->rot_err;
    return isfinite(pt->cost) && all_finite(pt->R, 9);
}

/* Evaluate FK, Jacobian and residual at pt->q. Returns 0 on non-finite. */
static int point_eval(rc_comp_point *pt, rc_kin_data *kd, const rc_kin *k, const rc_real pd[3], const rc_real *Rd,
                      const comp_params *pp, int use_rot)
{
    rc_kin_fk_jac(pt->p, pt->R, pt->J, kd, k, pt->q);
    return point_residual(pt, pd, Rd, pp, use_rot) && all_finite(pt->J, 36);
}

/* Damped step with box constraints by an active set. dq: (6) output;
 * mask: joints put on a bound. A, b: (6 x 6), (6) scratch. Returns 0 when
 * the step is zero or the system could not be solved. */
static int step_solve(rc_real dq[RC_NJ], unsigned *mask, rc_real A[36], rc_real b[RC_NJ], const rc_comp_point *pt,
                      const rc_real lo[RC_NJ], const rc_real hi[RC_NJ], const comp_params *pp, int use_rot,
                      rc_real lam2)
{
    rc_real er[6], wr[6];
    unsigned fixed = 0;
    const unsigned nrow = use_rot ? 6u : 3u;
    for (unsigned r = 0; r < 6; ++r)
        wr[r] = r < 3 ? RC_REAL_C(1.0) : pp->w_rot;
    for (unsigned pass = 0; pass <= RC_NJ; ++pass) {
        /* residual left for the free joints */
        for (unsigned r = 0; r < nrow; ++r) {
            rc_real s = pt->e[r];
            for (unsigned i = 0; i < RC_NJ; ++i)
                if (fixed & (1u << i))
                    s -= pt->J[6 * r + i] * dq[i];
            er[r] = s * wr[r];
        }
        for (unsigned i = 0; i < RC_NJ; ++i) {
            rc_real s = RC_REAL_C(0.0);
            for (unsigned r = 0; r < nrow; ++r)
                s += pt->J[6 * r + i] * wr[r] * er[r];
            b[i] = s;
            for (unsigned k = i; k < RC_NJ; ++k) {
                rc_real a = RC_REAL_C(0.0);
                for (unsigned r = 0; r < nrow; ++r)
                    a += pt->J[6 * r + i] * pt->J[6 * r + k] * wr[r] * wr[r];
                A[6 * i + k] = A[6 * k + i] = a;
            }
        }
        /* Damping at least 2^6 epsilons of the largest diagonal entry: the
         * factorisation must succeed in the working precision (in double
         * this floor is ~1e-9 (mm/rad)^2, far below lam2_min, so it only
         * acts in float). */
        rc_real dmax = RC_REAL_C(0.0);
        for (unsigned i = 0; i < RC_NJ; ++i)
            dmax = rc_rfmax(dmax, A[7 * i]);
        const rc_real lam2_eff = rc_rfmax(lam2, dmax * RC_REAL_EPS * RC_REAL_C(64.0));
        for (unsigned i = 0; i < RC_NJ; ++i)
            A[7 * i] += lam2_eff;
        for (unsigned i = 0; i < RC_NJ; ++i) {
            if ((fixed & (1u << i)) == 0u)
                continue;
            for (unsigned k = 0; k < RC_NJ; ++k)
                A[6 * i + k] = A[6 * k + i] = RC_REAL_C(0.0);
            A[7 * i] = RC_REAL_C(1.0);
            b[i] = dq[i];
        }
        if (rc_kin_chol6(A, b) != RC_OK || !all_finite(b, RC_NJ))
            return 0;
        rc_real big = RC_REAL_C(0.0);
        for (unsigned i = 0; i < RC_NJ; ++i)
            if ((fixed & (1u << i)) == 0u && rc_rfabs(b[i]) > big)
                big = rc_rfabs(b[i]);
        const rc_real scale = big > pp->max_step ? pp->max_step / big : RC_REAL_C(1.0);
        unsigned added = 0;
        for (unsigned i = 0; i < RC_NJ; ++i) {
            if (fixed & (1u << i))
                continue;
            dq[i] = b[i] * scale;
            if (pt->q[i] + dq[i] < lo[i]) {
                dq[i] = lo[i] - pt->q[i];
                added |= 1u << i;
            } else if (pt->q[i] + dq[i] > hi[i]) {
                dq[i] = hi[i] - pt->q[i];
                added |= 1u << i;
            }
        }
        if (added == 0u)
            break;
        fixed |= added;
    }
    *mask = fixed;
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (dq[i] != RC_REAL_C(0.0))
            return 1;
    return 0;
}

static rc_real clampr(rc_real v, rc_real lo, rc_real hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* Bits of the joints of q on a bound of [lo, hi], and (limit) on k's limits. */
static unsigned on_bounds(const rc_real q[RC_NJ], const rc_real lo[RC_NJ], const rc_real hi[RC_NJ])
{
    unsigned m = 0;
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (q[i] <= lo[i] || q[i] >= hi[i])
            m |= 1u << i;
    return m;
}

/* The solver: start at seed (inside [lo, hi]), target (pd, Rd). */
static rc_status comp_solve(rc_real q_out[RC_NJ], rc_comp_result *res, rc_comp_work *w, const rc_kin *k,
                            const rc_real pd[3], const rc_real *Rd, const rc_real seed[RC_NJ],
                            const rc_real lo[RC_NJ], const rc_real hi[RC_NJ], const comp_params *pp)
{
    rc_comp_point *cur = &w->pt[0], *trial = &w->pt[1];
    unsigned iters = 0, pushed = 0;
    int no_descent = 0;
    memcpy(cur->q, seed, sizeof cur->q);
    memcpy(q_out, seed, RC_NJ * sizeof q_out[0]);
    res->iterations = 0;
    res->bound_mask = res->limit_mask = 0;
    if (!point_eval(cur, &w->kd, k, pd, Rd, pp, pp->want_rot)) {
        res->exit = RC_COMP_NONFINITE;
        res->pos_err_mm = res->rot_err_rad = RC_REAL_C(0.0);
        return RC_ERR_NUMERIC;
    }
    for (int phase = 0; phase < 2; ++phase) {
        const int use_rot = phase == 0 && pp->want_rot;
        const unsigned budget = iters + (phase == 0 ? pp->max_iter : (pp->max_iter + 1u) / 2u);
        rc_real lam2 = pp->lam2_min;
        if (phase == 1) {
            if (!pp->want_rot || cur->pos_err <= pp->tol_mm)
                break;
            cur->cost = cur->pos_err * cur->pos_err;
            no_descent = 0;
            pushed = 0;
        }
        for (;;) {
            if (cur->pos_err <= pp->tol_mm && (!use_rot || cur->rot_err <= pp->tol_rad))
                break;
            if (iters >= budget)
                break;
            rc_real dq[RC_NJ] = {0};
            unsigned fmask = 0;
            const int moved = step_solve(dq, &fmask, w->A, w->b, cur, lo, hi, pp, use_rot, lam2);
            pushed |= fmask;
            if (!moved) {
                no_descent = 1;
                break;
            }
            for (unsigned i = 0; i < RC_NJ; ++i)
                trial->q[i] = clampr(cur->q[i] + dq[i], lo[i], hi[i]);
            ++iters;
            if (point_eval(trial, &w->kd, k, pd, Rd, pp, use_rot) && trial->cost < cur->cost) {
                rc_comp_point *t = cur;
                cur = trial;
                trial = t;
                lam2 = rc_rfmax(lam2 * RC_REAL_C(0.1), pp->lam2_min);
            } else {
                lam2 *= RC_REAL_C(10.0);
                if (lam2 > LAM2_MAX) {
                    no_descent = 1;
                    break;
                }
            }
        }
    }
    memcpy(q_out, cur->q, sizeof cur->q);
    res->iterations = iters;
    res->pos_err_mm = cur->pos_err;
    res->rot_err_rad = cur->rot_err;
    res->bound_mask = on_bounds(cur->q, lo, hi);
    res->limit_mask = on_bounds(cur->q, k->q_min_rad, k->q_max_rad);
    if (cur->pos_err <= pp->tol_mm) {
        res->exit = (!pp->want_rot || cur->rot_err <= pp->tol_rad) ? RC_COMP_CONVERGED : RC_COMP_POSITION_ONLY;
        return RC_OK;
    }
    /* Name the cause: a bound that steps of the last phase pushed against
     * and the joint still sits on (a joint limit first), else the iteration
     * limit or the damping. */
    pushed &= res->bound_mask;
    if (pushed & res->limit_mask)
        res->exit = RC_COMP_JOINT_LIMIT;
    else if (pushed != 0u)
        res->exit = RC_COMP_MAX_DEV;
    else
        res->exit = no_descent ? RC_COMP_NO_DESCENT : RC_COMP_MAX_ITER;
    return RC_ERR_NOCONV;
}

static int within_limits(const rc_kin *k, const rc_real q[RC_NJ])
{
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (!isfinite(q[i]) || q[i] < k->q_min_rad[i] || q[i] > k->q_max_rad[i])
            return 0;
    return 1;
}

static void bad_input(rc_real q_out[RC_NJ], rc_comp_result *res, const rc_real *q)
{
    for (unsigned i = 0; i < RC_NJ; ++i)
        q_out[i] = (q != NULL && all_finite(q, RC_NJ)) ? q[i] : RC_REAL_C(0.0);
    memset(res, 0, sizeof *res);
    res->exit = RC_COMP_BAD_INPUT;
}

static rc_real corr_max(const rc_real a[RC_NJ], const rc_real b[RC_NJ])
{
    rc_real m = RC_REAL_C(0.0);
    for (unsigned i = 0; i < RC_NJ; ++i)
        m = rc_rfmax(m, rc_rfabs(a[i] - b[i]));
    return m;
}

rc_status rc_comp_kin_pose(rc_real q_out_rad[RC_NJ], rc_comp_result *res, rc_comp_work *w, const rc_kin *k,
                           const rc_real pos_mm[3], const rc_real rot[9], const rc_real seed_rad[RC_NJ],
                           const rc_comp_config *cfg)
{
    rc_comp_result tmp;
    comp_params pp;
    rc_real lo[RC_NJ], hi[RC_NJ];
    RC_ASSERT(q_out_rad != NULL && w != NULL && k != NULL && pos_mm != NULL && seed_rad != NULL);
    if (res == NULL)
        res = &tmp;
    if (!within_limits(k, seed_rad) || !all_finite(pos_mm, 3) || (rot != NULL && !all_finite(rot, 9))) {
        bad_input(q_out_rad, res, seed_rad);
        if (all_finite(seed_rad, RC_NJ))
            for (unsigned i = 0; i < RC_NJ; ++i)
                q_out_rad[i] = clampr(seed_rad[i], k->q_min_rad[i], k->q_max_rad[i]);
        return RC_ERR_RANGE;
    }
    params_resolve(&pp, cfg, RC_REAL_HUGE, rot != NULL);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        lo[i] = rc_rfmax(k->q_min_rad[i], seed_rad[i] - pp.max_dev);
        hi[i] = rc_rfmin(k->q_max_rad[i], seed_rad[i] + pp.max_dev);
    }
    memcpy(w->pd, pos_mm, sizeof w->pd);
    if (rot != NULL)
        memcpy(w->Rd, rot, sizeof w->Rd);
    rc_status st = comp_solve(q_out_rad, res, w, k, w->pd, pp.want_rot ? w->Rd : NULL, seed_rad, lo, hi, &pp);
    res->corr_max_rad = corr_max(q_out_rad, seed_rad);
    return st;
}

/* rc_comp_kin_joint with the resolved parameters; leaves the target in w. */
static rc_status joint_solve(rc_real q_out_rad[RC_NJ], rc_comp_result *res, rc_comp_work *w, const rc_kin *cal,
                             const rc_kin *nom, const rc_real q_rad[RC_NJ], const rc_real seed_rad[RC_NJ],
                             const comp_params *pp)
{
    rc_real lo[RC_NJ], hi[RC_NJ], seed[RC_NJ];
    rc_kin_fk(w->pd, w->Rd, &w->kd, nom, q_rad);
    if (!all_finite(w->pd, 3) || !all_finite(w->Rd, 9)) {
        memcpy(q_out_rad, q_rad, RC_NJ * sizeof q_rad[0]);
        memset(res, 0, sizeof *res);
        res->exit = RC_COMP_NONFINITE;
        return RC_ERR_NUMERIC;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        lo[i] = rc_rfmax(cal->q_min_rad[i], q_rad[i] - pp->max_dev);
        hi[i] = rc_rfmin(cal->q_max_rad[i], q_rad[i] + pp->max_dev);
        seed[i] = clampr(seed_rad != NULL ? seed_rad[i] : q_rad[i], lo[i], hi[i]);
    }
    rc_status st = comp_solve(q_out_rad, res, w, cal, w->pd, pp->want_rot ? w->Rd : NULL, seed, lo, hi, pp);
    if (st == RC_ERR_NUMERIC)
        memcpy(q_out_rad, q_rad, RC_NJ * sizeof q_rad[0]);
    res->corr_max_rad = corr_max(q_out_rad, q_rad);
    return st;
}

rc_status rc_comp_kin_joint(rc_real q_out_rad[RC_NJ], rc_comp_result *res, rc_comp_work *w, const rc_kin *cal,
                            const rc_kin *nom, const rc_real q_rad[RC_NJ], const rc_real seed_rad[RC_NJ],
                            const rc_comp_config *cfg)
{
    rc_comp_result tmp;
    comp_params pp;
    RC_ASSERT(q_out_rad != NULL && w != NULL && cal != NULL && nom != NULL && q_rad != NULL);
    if (res == NULL)
        res = &tmp;
    if (!within_limits(cal, q_rad) || (seed_rad != NULL && !all_finite(seed_rad, RC_NJ))) {
        bad_input(q_out_rad, res, q_rad);
        return RC_ERR_RANGE;
    }
    params_resolve(&pp, cfg, RC_REAL_C(0.1), 1);
    return joint_solve(q_out_rad, res, w, cal, nom, q_rad, seed_rad, &pp);
}

rc_status rc_comp_stream_init_kin(rc_comp_stream *s, const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg)
{
    RC_ASSERT(s != NULL && cal != NULL && nom != NULL);
    memset(s, 0, sizeof *s);
    s->cal = cal;
    s->nom = nom;
    if (cfg != NULL)
        s->cfg = *cfg;
    return RC_OK;
}

static void count(uint32_t *c) { *c = (uint32_t)(*c + 1u); } /* modulo 2^32 by definition */

static rc_status stream_fail(rc_comp_stream *s, rc_status st)
{
    count(&s->n_fail);
    if (s->fail_run < UINT32_MAX)
        s->fail_run++;
    return st;
}

rc_status rc_comp_stream_step(rc_comp_stream *s, rc_real q_out_rad[RC_NJ], rc_comp_result *res,
                              const rc_real q_rad[RC_NJ])
{
    rc_comp_result tmp;
    comp_params pp;
    rc_real seed[RC_NJ];
    RC_ASSERT(s != NULL && q_out_rad != NULL && q_rad != NULL);
    if (res == NULL)
        res = &tmp;
#if RC_COMP_STREAM_OWN_MODELS
    const rc_kin *cal = s->cal != NULL ? s->cal : &s->own[0];
    const rc_kin *nom = s->nom != NULL ? s->nom : &s->own[1];
#else
    const rc_kin *cal = s->cal, *nom = s->nom;
#endif
    if (!within_limits(cal, q_rad)) {
        bad_input(q_out_rad, res, q_rad);
        return stream_fail(s, RC_ERR_RANGE);
    }
    if (s->model_status != RC_OK) {
        memcpy(q_out_rad, q_rad, RC_NJ * sizeof q_rad[0]);
        memset(res, 0, sizeof *res);
        res->exit = RC_COMP_NONFINITE;
        return stream_fail(s, RC_ERR_NUMERIC);
    }
    int warm = s->have_dq;
    for (unsigned i = 0; warm && i < RC_NJ; ++i)
        warm = rc_rfabs(q_rad[i] - s->q_prev_rad[i]) <= RC_COMP_WARM_RAD;
    for (unsigned i = 0; i < RC_NJ; ++i)
        seed[i] = q_rad[i] + (warm ? s->dq_rad[i] : RC_REAL_C(0.0));
    params_resolve(&pp, &s->cfg, RC_REAL_C(0.1), 1);
    rc_status st = joint_solve(q_out_rad, res, &s->work, cal, nom, q_rad, seed, &pp);
    if (st == RC_OK) {
        for (unsigned i = 0; i < RC_NJ; ++i) {
            s->dq_rad[i] = q_out_rad[i] - q_rad[i];
            s->q_prev_rad[i] = q_rad[i];
        }
        s->have_dq = 1;
        count(&s->n_ok);
        s->fail_run = 0;
        return RC_OK;
    }
    res->held_last = 0;
    if (st == RC_ERR_NOCONV && warm) {
        /* On a path: output the target plus the last good correction (a
         * continuous command), and describe that output (not the best
         * iterate) in res. A jump keeps the solver's closest point inside
         * the bounds: the last correction belongs to another pose and may
         * land further off than the target itself (measured: 76 mm off
         * where the target was 16 mm, tests/system/sim/truth_study.py --errors
         * wide); the closest point is never worse than the target. */
        res->held_last = 1;
        rc_comp_work *w = &s->work;
        rc_comp_point *pt = &w->pt[0];
        for (unsigned i = 0; i < RC_NJ; ++i) {
            q_out_rad[i] = clampr(q_rad[i] + s->dq_rad[i], cal->q_min_rad[i], cal->q_max_rad[i]);
        }
        res->corr_max_rad = corr_max(q_out_rad, q_rad);
        rc_kin_fk(pt->p, pt->R, &w->kd, cal, q_out_rad);
        if (point_residual(pt, w->pd, pp.want_rot ? w->Rd : NULL, &pp, pp.want_rot)) {
            res->pos_err_mm = pt->pos_err;
            res->rot_err_rad = pt->rot_err;
        }
        res->limit_mask = on_bounds(q_out_rad, cal->q_min_rad, cal->q_max_rad);
    }
    return stream_fail(s, st);
}
