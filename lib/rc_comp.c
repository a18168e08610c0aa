/* rc_comp.c - damped Gauss-Newton compensation and inverse kinematics. */
#include "rc_comp.h"

#include <math.h>
#include <string.h>

#include "rc_linalg.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Resolved configuration (defaults filled in). */
typedef struct {
    unsigned max_iter;
    double tol_mm, tol_rad, w_rot, lam2_min, max_step, max_dev;
    int want_rot;
} comp_params;

/* One evaluated iterate. */
typedef struct {
    double q[RC_NJ];   /* (6) joints, rad */
    double p[3];       /* (3) flange point, mm */
    double R[9];       /* (3 x 3) flange rotation */
    double J[36];      /* (6 x 6) geometric Jacobian */
    double e[6];       /* (6) residual: p* - p (mm), log(R* R^T) (rad) */
    double pos_err;    /* |e[0..2]| mm */
    double rot_err;    /* rotation angle, rad */
    double cost;       /* weighted squared error of the current phase */
} comp_point;

#define LAM2_MAX 1e12 /* (mm/rad)^2: beyond this a step is negligible */

const char *rc_comp_exit_str(rc_comp_exit e)
{
    switch (e) {
    case RC_COMP_CONVERGED: return "converged";
    case RC_COMP_POSITION_ONLY: return "position matched, orientation best effort";
    case RC_COMP_MAX_ITER: return "iteration limit";
    case RC_COMP_NO_DESCENT: return "no further descent (bound or singularity)";
    case RC_COMP_BAD_INPUT: return "target or seed not finite or outside the joint limits";
    case RC_COMP_NONFINITE: return "model produced non-finite values";
    }
    return "unknown";
}

static void params_resolve(comp_params *p, const rc_comp_config *cfg, double dev_default, int has_rot)
{
    static const rc_comp_config zero;
    if (cfg == NULL)
        cfg = &zero;
    p->max_iter = cfg->max_iter > 0 ? cfg->max_iter : 12u;
    p->tol_mm = cfg->tol_mm > 0.0 ? cfg->tol_mm : 1e-5;
    p->tol_rad = cfg->tol_rad > 0.0 ? cfg->tol_rad : 1e-8;
    p->w_rot = cfg->w_rot_mm > 0.0 ? cfg->w_rot_mm : 100.0;
    const double lam = cfg->lambda_mm > 0.0 ? cfg->lambda_mm : 0.01;
    p->lam2_min = lam * lam;
    p->max_step = cfg->max_step_rad > 0.0 ? cfg->max_step_rad : 0.2;
    p->max_dev = cfg->max_dev_rad > 0.0 ? cfg->max_dev_rad : dev_default;
    p->want_rot = has_rot && (cfg->flags & RC_COMP_FLAG_POSITION_ONLY) == 0u;
}

static int all_finite(const double *v, unsigned n)
{
    for (unsigned i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Rotation vector of Rd R^T (base frame) into e (3); returns its angle. */
static double rot_log(double e[3], const double Rd[9], const double R[9])
{
    double E[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            E[3 * r + c] = Rd[3 * r] * R[3 * c] + Rd[3 * r + 1] * R[3 * c + 1] + Rd[3 * r + 2] * R[3 * c + 2];
    const double v[3] = {0.5 * (E[7] - E[5]), 0.5 * (E[2] - E[6]), 0.5 * (E[3] - E[1])};
    const double s = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const double c = 0.5 * (E[0] + E[4] + E[8] - 1.0);
    const double th = atan2(s, c);
    if (s > 1e-9) {
        const double k = th / s;
        for (int i = 0; i < 3; ++i)
            e[i] = v[i] * k;
    } else if (c > 0.0) {
        for (int i = 0; i < 3; ++i)
            e[i] = v[i];
    } else { /* half a turn: the axis from the symmetric part E = 2 a a^T - I */
        int k = 0;
        if (E[4] > E[0])
            k = 1;
        if (E[8] > E[4 * k])
            k = 2;
        const double ak = sqrt(fmax(0.0, 0.5 * (E[4 * k] + 1.0)));
        for (int i = 0; i < 3; ++i)
            e[i] = (i == k) ? M_PI * ak : M_PI * (E[3 * k + i] + E[3 * i + k]) / (4.0 * ak);
    }
    return th;
}

/* Evaluate FK, Jacobian and residual at pt->q. Returns 0 on non-finite. */
static int point_eval(comp_point *pt, const rc_model *m, const double pd[3], const double *Rd,
                      const comp_params *pp, int use_rot)
{
    rc_fk_jac(pt->p, pt->R, pt->J, m, pt->q);
    for (int i = 0; i < 3; ++i)
        pt->e[i] = pd[i] - pt->p[i];
    pt->pos_err = sqrt(pt->e[0] * pt->e[0] + pt->e[1] * pt->e[1] + pt->e[2] * pt->e[2]);
    if (Rd != NULL) {
        pt->rot_err = rot_log(&pt->e[3], Rd, pt->R);
    } else {
        pt->e[3] = pt->e[4] = pt->e[5] = 0.0;
        pt->rot_err = 0.0;
    }
    pt->cost = pt->pos_err * pt->pos_err;
    if (use_rot)
        pt->cost += pp->w_rot * pp->w_rot * pt->rot_err * pt->rot_err;
    return isfinite(pt->cost) && all_finite(pt->J, 36) && all_finite(pt->R, 9);
}

/* Damped step with box constraints by an active set. dq: (6) output;
 * mask: joints put on a bound. Returns 0 when the step is zero or the system
 * could not be solved. */
static int step_solve(double dq[RC_NJ], unsigned *mask, const comp_point *pt, const double lo[RC_NJ],
                      const double hi[RC_NJ], const comp_params *pp, int use_rot, double lam2)
{
    double A[36], b[RC_NJ], er[6], wr[6];
    unsigned fixed = 0;
    const unsigned nrow = use_rot ? 6u : 3u;
    for (unsigned r = 0; r < 6; ++r)
        wr[r] = r < 3 ? 1.0 : pp->w_rot;
    for (unsigned pass = 0; pass <= RC_NJ; ++pass) {
        /* residual left for the free joints */
        for (unsigned r = 0; r < nrow; ++r) {
            double s = pt->e[r];
            for (unsigned i = 0; i < RC_NJ; ++i)
                if (fixed & (1u << i))
                    s -= pt->J[6 * r + i] * dq[i];
            er[r] = s * wr[r];
        }
        for (unsigned i = 0; i < RC_NJ; ++i) {
            double s = 0.0;
            for (unsigned r = 0; r < nrow; ++r)
                s += pt->J[6 * r + i] * wr[r] * er[r];
            b[i] = s;
            for (unsigned k = i; k < RC_NJ; ++k) {
                double a = 0.0;
                for (unsigned r = 0; r < nrow; ++r)
                    a += pt->J[6 * r + i] * pt->J[6 * r + k] * wr[r] * wr[r];
                A[6 * i + k] = A[6 * k + i] = a;
            }
            A[7 * i] += lam2;
        }
        for (unsigned i = 0; i < RC_NJ; ++i) {
            if ((fixed & (1u << i)) == 0u)
                continue;
            for (unsigned k = 0; k < RC_NJ; ++k)
                A[6 * i + k] = A[6 * k + i] = 0.0;
            A[7 * i] = 1.0;
            b[i] = dq[i];
        }
        if (rcu_chol_solve(A, b, RC_NJ) != RC_OK || !all_finite(b, RC_NJ))
            return 0;
        double big = 0.0;
        for (unsigned i = 0; i < RC_NJ; ++i)
            if ((fixed & (1u << i)) == 0u && fabs(b[i]) > big)
                big = fabs(b[i]);
        const double scale = big > pp->max_step ? pp->max_step / big : 1.0;
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
        if (dq[i] != 0.0)
            return 1;
    return 0;
}

static double clampd(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* The solver: start at seed (inside [lo, hi]), target (pd, Rd). */
static rc_status comp_solve(double q_out[RC_NJ], rc_comp_result *res, const rc_model *m, const double pd[3],
                            const double *Rd, const double seed[RC_NJ], const double lo[RC_NJ],
                            const double hi[RC_NJ], const comp_params *pp)
{
    comp_point cur, trial;
    unsigned iters = 0;
    int no_descent = 0;
    memcpy(cur.q, seed, sizeof cur.q);
    memcpy(q_out, seed, RC_NJ * sizeof q_out[0]);
    res->iterations = 0;
    res->bound_mask = 0;
    if (!point_eval(&cur, m, pd, Rd, pp, pp->want_rot)) {
        res->exit = RC_COMP_NONFINITE;
        res->pos_err_mm = res->rot_err_rad = 0.0;
        return RC_ERR_NUMERIC;
    }
    for (int phase = 0; phase < 2; ++phase) {
        const int use_rot = phase == 0 && pp->want_rot;
        const unsigned budget = iters + (phase == 0 ? pp->max_iter : (pp->max_iter + 1u) / 2u);
        double lam2 = pp->lam2_min;
        if (phase == 1) {
            if (!pp->want_rot || cur.pos_err <= pp->tol_mm)
                break;
            cur.cost = cur.pos_err * cur.pos_err;
            no_descent = 0;
        }
        for (;;) {
            if (cur.pos_err <= pp->tol_mm && (!use_rot || cur.rot_err <= pp->tol_rad))
                break;
            if (iters >= budget)
                break;
            double dq[RC_NJ] = {0};
            unsigned fmask = 0;
            if (!step_solve(dq, &fmask, &cur, lo, hi, pp, use_rot, lam2)) {
                no_descent = 1;
                break;
            }
            for (unsigned i = 0; i < RC_NJ; ++i)
                trial.q[i] = clampd(cur.q[i] + dq[i], lo[i], hi[i]);
            ++iters;
            if (point_eval(&trial, m, pd, Rd, pp, use_rot) && trial.cost < cur.cost) {
                cur = trial;
                lam2 = fmax(lam2 * 0.1, pp->lam2_min);
            } else {
                lam2 *= 10.0;
                if (lam2 > LAM2_MAX) {
                    no_descent = 1;
                    break;
                }
            }
        }
    }
    memcpy(q_out, cur.q, sizeof cur.q);
    res->iterations = iters;
    res->pos_err_mm = cur.pos_err;
    res->rot_err_rad = cur.rot_err;
    res->bound_mask = 0;
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (cur.q[i] <= lo[i] || cur.q[i] >= hi[i])
            res->bound_mask |= 1u << i;
    if (cur.pos_err <= pp->tol_mm) {
        res->exit = (!pp->want_rot || cur.rot_err <= pp->tol_rad) ? RC_COMP_CONVERGED : RC_COMP_POSITION_ONLY;
        return RC_OK;
    }
    res->exit = no_descent ? RC_COMP_NO_DESCENT : RC_COMP_MAX_ITER;
    return RC_ERR_NOCONV;
}

static int within_limits(const rc_model *m, const double q[RC_NJ])
{
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (!isfinite(q[i]) || q[i] < m->q_min_rad[i] || q[i] > m->q_max_rad[i])
            return 0;
    return 1;
}

static void bad_input(double q_out[RC_NJ], rc_comp_result *res, const double *q)
{
    for (unsigned i = 0; i < RC_NJ; ++i)
        q_out[i] = (q != NULL && all_finite(q, RC_NJ)) ? q[i] : 0.0;
    memset(res, 0, sizeof *res);
    res->exit = RC_COMP_BAD_INPUT;
}

rc_status rc_comp_pose(double q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *m,
                       const double pos_mm[3], const double rot[9], const double seed_rad[RC_NJ],
                       const rc_comp_config *cfg)
{
    rc_comp_result tmp;
    comp_params pp;
    double lo[RC_NJ], hi[RC_NJ];
    RC_ASSERT(q_out_rad != NULL && m != NULL && pos_mm != NULL && seed_rad != NULL);
    if (res == NULL)
        res = &tmp;
    if (!within_limits(m, seed_rad) || !all_finite(pos_mm, 3) || (rot != NULL && !all_finite(rot, 9))) {
        bad_input(q_out_rad, res, seed_rad);
        if (all_finite(seed_rad, RC_NJ))
            for (unsigned i = 0; i < RC_NJ; ++i)
                q_out_rad[i] = clampd(seed_rad[i], m->q_min_rad[i], m->q_max_rad[i]);
        return RC_ERR_RANGE;
    }
    params_resolve(&pp, cfg, HUGE_VAL, rot != NULL);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        lo[i] = fmax(m->q_min_rad[i], seed_rad[i] - pp.max_dev);
        hi[i] = fmin(m->q_max_rad[i], seed_rad[i] + pp.max_dev);
    }
    rc_status st = comp_solve(q_out_rad, res, m, pos_mm, pp.want_rot ? rot : NULL, seed_rad, lo, hi, &pp);
    res->corr_max_rad = 0.0;
    for (unsigned i = 0; i < RC_NJ; ++i)
        res->corr_max_rad = fmax(res->corr_max_rad, fabs(q_out_rad[i] - seed_rad[i]));
    return st;
}

rc_status rc_comp_joint(double q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *cal,
                        const rc_model *nom, const double q_rad[RC_NJ], const double seed_rad[RC_NJ],
                        const rc_comp_config *cfg)
{
    rc_comp_result tmp;
    comp_params pp;
    double lo[RC_NJ], hi[RC_NJ], pd[3], Rd[9], seed[RC_NJ];
    RC_ASSERT(q_out_rad != NULL && cal != NULL && nom != NULL && q_rad != NULL);
    if (res == NULL)
        res = &tmp;
    if (!within_limits(cal, q_rad) || (seed_rad != NULL && !all_finite(seed_rad, RC_NJ))) {
        bad_input(q_out_rad, res, q_rad);
        return RC_ERR_RANGE;
    }
    params_resolve(&pp, cfg, 0.1, 1);
    rc_fk(pd, Rd, nom, q_rad);
    if (!all_finite(pd, 3) || !all_finite(Rd, 9)) {
        memcpy(q_out_rad, q_rad, RC_NJ * sizeof q_rad[0]);
        memset(res, 0, sizeof *res);
        res->exit = RC_COMP_NONFINITE;
        return RC_ERR_NUMERIC;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        lo[i] = fmax(cal->q_min_rad[i], q_rad[i] - pp.max_dev);
        hi[i] = fmin(cal->q_max_rad[i], q_rad[i] + pp.max_dev);
        seed[i] = clampd(seed_rad != NULL ? seed_rad[i] : q_rad[i], lo[i], hi[i]);
    }
    rc_status st = comp_solve(q_out_rad, res, cal, pd, pp.want_rot ? Rd : NULL, seed, lo, hi, &pp);
    if (st == RC_ERR_NUMERIC)
        memcpy(q_out_rad, q_rad, RC_NJ * sizeof q_rad[0]);
    res->corr_max_rad = 0.0;
    for (unsigned i = 0; i < RC_NJ; ++i)
        res->corr_max_rad = fmax(res->corr_max_rad, fabs(q_out_rad[i] - q_rad[i]));
    return st;
}

rc_status rc_comp_stream_init(rc_comp_stream *s, const rc_model *cal, const rc_model *nom,
                              const rc_comp_config *cfg)
{
    RC_ASSERT(s != NULL && cal != NULL && nom != NULL);
    memset(s, 0, sizeof *s);
    s->cal = cal;
    s->nom = nom;
    if (cfg != NULL)
        s->cfg = *cfg;
    return RC_OK;
}

rc_status rc_comp_stream_step(rc_comp_stream *s, double q_out_rad[RC_NJ], rc_comp_result *res,
                              const double q_rad[RC_NJ])
{
    rc_comp_result tmp;
    double seed[RC_NJ];
    RC_ASSERT(s != NULL && q_out_rad != NULL && q_rad != NULL);
    if (res == NULL)
        res = &tmp;
    for (unsigned i = 0; i < RC_NJ; ++i)
        seed[i] = q_rad[i] + (s->have_dq ? s->dq_rad[i] : 0.0);
    rc_status st = rc_comp_joint(q_out_rad, res, s->cal, s->nom, q_rad, seed, &s->cfg);
    if (st == RC_OK) {
        for (unsigned i = 0; i < RC_NJ; ++i)
            s->dq_rad[i] = q_out_rad[i] - q_rad[i];
        s->have_dq = 1;
        s->n_ok++;
        s->fail_run = 0;
        return RC_OK;
    }
    s->n_fail++;
    s->fail_run++;
    if (st == RC_ERR_NOCONV) {
        res->corr_max_rad = 0.0;
        for (unsigned i = 0; i < RC_NJ; ++i) {
            const double dq = s->have_dq ? s->dq_rad[i] : 0.0;
            q_out_rad[i] = clampd(q_rad[i] + dq, s->cal->q_min_rad[i], s->cal->q_max_rad[i]);
            res->corr_max_rad = fmax(res->corr_max_rad, fabs(q_out_rad[i] - q_rad[i]));
        }
    }
    return st;
}
