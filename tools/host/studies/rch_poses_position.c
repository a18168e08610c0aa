/* SPDX-License-Identifier: MIT */
/* rch_poses_position.c - the position criterion of rch_poses_plan
 * (RCH_POSES_POSITION, issue 20; the default) and rch_poses_predict: the
 * model `rcal calibrate` fits for K outlets, the candidates' scaled rows,
 * the I-optimal greedy design and its exchange passes (phi = mean trace of
 * the point's position covariance over workspace poses), and the predicted
 * 3-D accuracy (the 95 % radius, rch_uncert_radius95) of the plan and of
 * random poses.
 * Depends on: rc_model, rc_rand, rc_meas; rch_prior, rch_uncert
 * (rch_uncert_point_sens), rch_stats, rch_ident; LAPACKE (dpotrf, dpotri,
 * dposv). Memory: heap for the work (pos_work), freed before return; the
 * plan's rows in the result (rch_poses_free). Errors: -1 with d set. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <lapacke.h>

#include "rc_rand.h"
#include "rch_ident.h"
#include "rch_poses_int.h"
#include "rch_stats.h"
#include "rch_uncert.h"

/* The model `rcal calibrate` fits for these outlets: m's geometry, the
 * encoder at outlet 0, Hayati's tilt of each nominally parallel axis, one
 * outlet effect per further place. */
static int plan_model(rc_model *out, const rc_model *m, const rch_poses_config *c, unsigned *K, rch_diag *d)
{
    *out = *m;
    *K = c->n_outlets ? c->n_outlets : 1u;
    if (*K > RC_MAX_OUTLETS) {
        rch_diag_set(d, "", 0, 0, "%u outlets: at most %d", *K, RC_MAX_OUTLETS);
        return -1;
    }
    if (c->n_outlets)
        memcpy(&out->x[RC_P_ENC], c->outlet_mm[0], 3 * sizeof(double));
    for (unsigned i = 1; i + 1 < RC_NJ; ++i) {
        int have = 0;
        for (unsigned e = 0; e < out->n_effects; ++e)
            have |= out->effects[e].kind == RC_EFF_AXIS_TILT && out->effects[e].joint == i;
        if (!have && fabs(sin(out->x[RC_P_ALPHA(i)])) < 1e-6 &&
            rc_model_add_effect(out, RC_EFF_AXIS_TILT, i, 0) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "cannot add the axis tilt of row %u (RC_MAX_PARAMS)", i + 1);
            return -1;
        }
    }
    for (unsigned k = 1; k < *K; ++k) {
        if (rc_model_add_effect(out, RC_EFF_OUTLET, k, 0) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "cannot add outlet %u (RC_MAX_PARAMS or RC_MAX_EFFECTS)", k);
            return -1;
        }
        memcpy(&out->x[out->effects[out->n_effects - 1].first], c->outlet_mm[k], 3 * sizeof(double));
    }
    if (c->n_points > 0) { /* the plate's points at their drawing, with the plate's prior */
        if (c->n_points > RC_MAX_TARGETS || rc_model_add_effect(out, RC_EFF_CABLE_POINTS, 0, 3u * c->n_points) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "cannot add %u cable points (at most %d; RC_MAX_PARAMS)", c->n_points,
                         RC_MAX_TARGETS);
            return -1;
        }
        memcpy(&out->x[out->effects[out->n_effects - 1].first], c->points_mm, 3u * c->n_points * sizeof(double));
    }
    return 0;
}

typedef struct pos_work {
    rc_model m, mp;           /* the planning model; the point model (m with the tool, or m) */
    unsigned K, nf, rows_per; /* outlets; free parameters; rows per candidate ((K, or 1 with split) x P) */
    unsigned P;               /* cable points (1: the flange or attachment point) */
    int split;                /* each pose from one outlet */
    unsigned fi[RC_MAX_PARAMS]; /* (nf) the free parameters' indices in x */
    double sc[RC_MAX_PARAMS];   /* (nf) their scale: prior sd (RCH_POSES_OUTLET_SD_MM for the outlets) */
    double noise;
    size_t n, n_pose, n_cand;   /* poses to plan; candidate poses; candidates */
    rc_sample *pose;            /* (n_pose) */
    size_t *cand_pose;          /* (n_cand) */
    uint8_t *cand_outlet;       /* (n_cand) the outlet of a split candidate (0 otherwise) */
    double *X;                  /* (n_cand x rows_per x nf) scaled rows g_j sc_j / noise */
    double *Q, *M, *C, *B, *T;  /* (nf x nf) */
    double *u, *v;              /* (rows_per x nf) */
    size_t *design, *rnd;       /* (n) candidates */
    uint8_t *in_design, *pose_used;
} pos_work;

static void pos_free(pos_work *w)
{
    free(w->pose);
    free(w->cand_pose);
    free(w->cand_outlet);
    free(w->X);
    free(w->Q);
    free(w->M);
    free(w->C);
    free(w->B);
    free(w->T);
    free(w->u);
    free(w->v);
    free(w->design);
    free(w->rnd);
    free(w->in_design);
    free(w->pose_used);
}

/* The model, its free parameters and their scales; the point model. */
static int pos_setup(pos_work *w, const rc_model *m, const rch_poses_config *c, rch_diag *d)
{
    double mean[RC_MAX_PARAMS], sd[RC_MAX_PARAMS];
    rch_prior_cfg pd;
    if (plan_model(&w->m, m, c, &w->K, d) != 0)
        return -1;
    if (!c->prior)
        rch_prior_defaults(&pd);
    rch_prior_fill(mean, sd, &w->m, &w->m, c->prior ? c->prior : &pd);
    w->nf = 0;
    for (unsigned k = 0; k < w->m.n_params; ++k) {
        if (k == RC_P_THETA(0) || k == RC_P_D(0)) /* the gauge */
            continue;
        w->fi[w->nf] = k;
        w->sc[w->nf++] = sd[k] > 0.0 ? sd[k] : RCH_POSES_OUTLET_SD_MM;
    }
    w->P = c->n_points ? c->n_points : 1u;
    w->split = c->split && w->K > 1;
    w->rows_per = (c->split ? 1u : w->K) * w->P;
    w->noise = c->noise_mm > 0.0 ? c->noise_mm : RCH_POSES_NOISE_MM;
    w->mp = w->m;
    if (c->has_tool) {
        if (rc_model_add_effect(&w->mp, RC_EFF_TOOL_OFFSET, 0, 0) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "cannot add the tool point (RC_MAX_PARAMS or RC_MAX_EFFECTS)");
            return -1;
        }
        memcpy(&w->mp.x[w->mp.effects[w->mp.n_effects - 1].first], c->tool_mm, 3 * sizeof(double));
    }
    return 0;
}

/* One pose's scaled rows: row k P + p (nf) for outlet k and cable point p;
 * len (K) each outlet's shortest and longest length to the points, lo and
 * hi. 0, or -1 when a length cannot be computed. */
static int pose_rows(double *rows, double *lo, double *hi, const pos_work *w, const rc_sample *q)
{
    double g[RC_MAX_PARAMS];
    for (unsigned k = 0; k < w->K; ++k) {
        lo[k] = 1e300;
        hi[k] = -1e300;
        for (unsigned p = 0; p < w->P; ++p) {
            rc_sample s = *q;
            double l;
            s.outlet = (uint8_t)k;
            s.target = (uint8_t)p;
            if (rc_meas(&l, g, &w->m, &s) != RC_OK)
                return -1;
            lo[k] = l < lo[k] ? l : lo[k];
            hi[k] = l > hi[k] ? l : hi[k];
            for (unsigned j = 0; rows && j < w->nf; ++j)
                rows[(k * w->P + p) * w->nf + j] = g[w->fi[j]] * w->sc[j] / w->noise;
        }
    }
    return 0;
}

/* Which outlets pose s is safe from (safe, K; rch_poses_safe): every one
 * (all poses from every outlet) or, with split, each reaching one; *reach
 * the reaching outlets that are safe. 0: a candidate, -1: dropped. */
static int pose_safety(uint8_t *safe, unsigned *reach, rch_poses_result *res, const pos_work *w,
                       const rch_poses_config *c, const rc_sample *s, const double *llo, const double *lhi)
{
    *reach = 0;
    for (unsigned k = 0; k < w->K; ++k) {
        safe[k] = 0;
        if (!(llo[k] >= c->len_min_mm && lhi[k] <= c->len_max_mm))
            continue;
        safe[k] = (uint8_t)rch_poses_safe(res, &w->m, c, s, k);
        *reach += safe[k];
        if (!safe[k] && !c->split)
            return -1; /* measured from every outlet: one unsafe cable drops the pose */
    }
    return *reach ? 0 : -1;
}

/* 1-2: candidate poses inside the limits whose lengths are in range: every
 * outlet's (all poses from every outlet), or one candidate per reaching
 * outlet (split). */
static int pos_candidates(pos_work *w, rch_poses_result *res, const rch_poses_config *c, rch_diag *d)
{
    const unsigned nf = w->nf, K = w->K;
    const double mg = c->margin_deg * PI_ / 180.0;
    size_t tries = 0, cap = w->n_pose * (c->split ? K : 1u);
    if (K == 0 || nf == 0 || cap == 0) {
        rch_diag_set(d, "", 0, 0, "no outlet, parameter or pose to plan");
        return -1;
    }
    const unsigned P = w->P;
    double *rows = malloc((size_t)K * P * nf * sizeof *rows), llo[RC_MAX_OUTLETS], lhi[RC_MAX_OUTLETS];
    rc_rng g;
    rc_rng_seed(&g, c->seed);
    w->pose = malloc(w->n_pose * sizeof *w->pose);
    w->cand_pose = malloc(cap * sizeof *w->cand_pose);
    w->cand_outlet = calloc(cap, 1);
    w->X = malloc(cap * w->rows_per * nf * sizeof *w->X);
    if (!rows || !w->pose || !w->cand_pose || !w->cand_outlet || !w->X) {
        free(rows);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    size_t got = 0;
    w->n_cand = 0;
    while (got < w->n_pose) {
        rc_sample s;
        if (++tries > 1000 * w->n_pose) {
            char why[256];
            free(rows);
            rch_poses_dropped_str(why, sizeof why, res);
            rch_diag_set(d, "", 0, 0, "only %zu of %zu candidate poses have a cable length within [%g, %g] mm from "
                         "%s and are safe for the cable and the cell (dropped: %s); check --outlet/--encoder, the "
                         "length range and --clearance-mm", got, w->n_pose, c->len_min_mm, c->len_max_mm,
                         c->split ? "any outlet" : "every outlet", why);
            return -1;
        }
        memset(&s, 0, sizeof s);
        for (int j = 0; j < RC_NJ; ++j) {
            const double lo = w->m.q_min_rad[j] + mg, hi = w->m.q_max_rad[j] - mg;
            const double q = lo + (hi - lo) * rc_rng_u01(&g);
            double qr = round(q * 180.0 / PI_ * 100.0) / 100.0 * PI_ / 180.0; /* 0.01 deg */
            if (qr < lo || qr > hi)
                qr = (qr < lo ? ceil(q * 180.0 / PI_ * 100.0) : floor(q * 180.0 / PI_ * 100.0)) / 100.0 * PI_ / 180.0;
            s.q_rad[j] = qr;
        }
        if (pose_rows(rows, llo, lhi, w, &s) != 0)
            continue;
        unsigned reach = 0;
        uint8_t safe[RC_MAX_OUTLETS];
        for (unsigned k = 0; k < K; ++k)
            reach += llo[k] >= c->len_min_mm && lhi[k] <= c->len_max_mm;
        if (c->split ? reach == 0 : reach < K)
            continue;
        if (pose_safety(safe, &reach, res, w, c, &s, llo, lhi) != 0)
            continue;
        for (unsigned k = 0; k < K; ++k) {
            if (!(llo[k] >= c->len_min_mm && lhi[k] <= c->len_max_mm) || !safe[k])
                continue;
            if (!c->split) {
                memcpy(w->X + w->n_cand * w->rows_per * nf, rows, (size_t)K * P * nf * sizeof *rows);
                w->cand_pose[w->n_cand] = got;
                w->cand_outlet[w->n_cand++] = 0;
                break;
            }
            memcpy(w->X + w->n_cand * w->rows_per * nf, rows + (size_t)k * P * nf, (size_t)P * nf * sizeof *rows);
            w->cand_pose[w->n_cand] = got;
            w->cand_outlet[w->n_cand++] = (uint8_t)k;
        }
        w->pose[got++] = s;
    }
    free(rows);
    return 0;
}

/* C = M^-1 (M symmetric positive definite, nf x nf; either storage). 0 or -1. */
int rch_poses_spd_inverse(double *C, const double *M, unsigned nf)
{
    memcpy(C, M, (size_t)nf * nf * sizeof *C);
    if (LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', (lapack_int)nf, C, (lapack_int)nf) != 0 ||
        LAPACKE_dpotri(LAPACK_COL_MAJOR, 'L', (lapack_int)nf, C, (lapack_int)nf) != 0)
        return -1;
    for (unsigned j = 0; j < nf; ++j) /* column j, rows i > j hold the lower triangle */
        for (unsigned i = j + 1; i < nf; ++i)
            C[(size_t)i * nf + j] = C[(size_t)j * nf + i];
    return 0;
}

int rch_poses_refresh(double *C, double *B, double *T, const double *M, const double *Q, unsigned nf)
{
    if (rch_poses_spd_inverse(C, M, nf) != 0)
        return -1;
    for (unsigned i = 0; i < nf; ++i) /* T = Q C */
        for (unsigned j = 0; j < nf; ++j) {
            double s = 0.0;
            for (unsigned k = 0; k < nf; ++k)
                s += Q[(size_t)i * nf + k] * C[(size_t)k * nf + j];
            T[(size_t)i * nf + j] = s;
        }
    for (unsigned i = 0; i < nf; ++i) /* B = C T */
        for (unsigned j = 0; j < nf; ++j) {
            double s = 0.0;
            for (unsigned k = 0; k < nf; ++k)
                s += C[(size_t)i * nf + k] * T[(size_t)k * nf + j];
            B[(size_t)i * nf + j] = s;
        }
    return 0;
}

static int pos_refresh(pos_work *w)
{
    return rch_poses_refresh(w->C, w->B, w->T, w->M, w->Q, w->nf);
}

static void add_rows(double *M, const double *X, unsigned r, unsigned nf, double sign)
{
    for (unsigned j = 0; j < r; ++j)
        rch_poses_add_outer(M, X + (size_t)j * nf, sign, nf);
}

/* How much the r rows X (r x nf) lower phi = trace(Q M^-1):
 * trace((I + X^T C X)^-1 X^T B X). */
static double pos_gain(pos_work *w, const double *X, unsigned r)
{
    const unsigned nf = w->nf;
    double S[RC_MAX_OUTLETS * RC_MAX_OUTLETS] = {0}, D[RC_MAX_OUTLETS * RC_MAX_OUTLETS] = {0};
    if (r == 0 || r > RC_MAX_OUTLETS)
        return 0.0;
    for (unsigned j = 0; j < r; ++j) {
        const double *x = X + (size_t)j * nf;
        double *u = w->u + (size_t)j * nf, *v = w->v + (size_t)j * nf;
        for (unsigned a = 0; a < nf; ++a) {
            const double *ca = w->C + (size_t)a * nf, *ba = w->B + (size_t)a * nf;
            double su = 0.0, sv = 0.0;
            for (unsigned b = 0; b < nf; ++b) {
                su += ca[b] * x[b];
                sv += ba[b] * x[b];
            }
            u[a] = su;
            v[a] = sv;
        }
    }
    for (unsigned j = 0; j < r; ++j)
        for (unsigned l = 0; l < r; ++l) {
            const double *x = X + (size_t)j * nf, *u = w->u + (size_t)l * nf, *v = w->v + (size_t)l * nf;
            double su = 0.0, sv = 0.0;
            for (unsigned a = 0; a < nf; ++a) {
                su += x[a] * u[a];
                sv += x[a] * v[a];
            }
            S[j * r + l] = su + (j == l);
            D[j * r + l] = sv;
        }
    if (r == 1)
        return D[0] / S[0];
    if (LAPACKE_dposv(LAPACK_COL_MAJOR, 'L', (lapack_int)r, (lapack_int)r, S, (lapack_int)r, D, (lapack_int)r) != 0)
        return -1.0;
    double t = 0.0;
    for (unsigned j = 0; j < r; ++j)
        t += D[j * r + j];
    return t;
}

static int pos_available(const pos_work *w, size_t i)
{
    return !w->in_design[i] && !w->pose_used[w->cand_pose[i]];
}

/* The available candidate that lowers phi most (none_idx: none); with
 * split, among those of design slot t's outlet (slot t is outlet t mod K). */
static size_t pos_best(pos_work *w, size_t none_idx, double *bg, size_t t)
{
    size_t best = none_idx;
    *bg = -1.0;
    for (size_t i = 0; i < w->n_cand; ++i) {
        if (!pos_available(w, i) || (w->split && w->cand_outlet[i] != t % w->K))
            continue;
        const double g = pos_gain(w, w->X + i * w->rows_per * w->nf, w->rows_per);
        if (g > *bg) {
            *bg = g;
            best = i;
        }
    }
    return best;
}

static void pos_take(pos_work *w, size_t t, size_t i, int take)
{
    const double *X = w->X + i * w->rows_per * w->nf;
    add_rows(w->M, X, w->rows_per, w->nf, take ? 1.0 : -1.0);
    w->in_design[i] = (uint8_t)take;
    w->pose_used[w->cand_pose[i]] = (uint8_t)take;
    if (take)
        w->design[t] = i;
}

void rch_poses_prior_info(double *M, unsigned nf)
{
    memset(M, 0, (size_t)nf * nf * sizeof *M);
    for (unsigned k = 0; k < nf; ++k)
        M[(size_t)k * nf + k] = 1.0;
}

/* J = the point's sensitivity to the scaled free parameters at q: J[i][a] = Jp[i][col[a]] sc[a] (0 where
 * col[a] < 0). */
static void point_sens(double J[3][RC_MAX_PARAMS], const rch_poses_point *pt, const double q[RC_NJ])
{
    double Jp[3][RC_MAX_PARAMS];
    rch_uncert_point_sens(Jp, pt->mp, q);
    for (int i = 0; i < 3; ++i)
        for (unsigned a = 0; a < pt->nf; ++a)
            J[i][a] = pt->col[a] >= 0 ? Jp[i][pt->col[a]] * pt->sc[a] : 0.0;
}

/* joints uniform in the limits of m */
static void workspace_pose(double q[RC_NJ], const rc_model *m, rc_rng *g)
{
    for (int j = 0; j < RC_NJ; ++j)
        q[j] = m->q_min_rad[j] + (m->q_max_rad[j] - m->q_min_rad[j]) * rc_rng_u01(g);
}

void rch_poses_workspace_q(double *Q, const rch_poses_point *pt, size_t n, unsigned long long seed)
{
    const unsigned nf = pt->nf;
    rc_rng g;
    rc_rng_seed(&g, seed);
    memset(Q, 0, (size_t)nf * nf * sizeof *Q);
    for (size_t t = 0; t < n; ++t) {
        double q[RC_NJ], J[3][RC_MAX_PARAMS];
        workspace_pose(q, pt->m, &g);
        point_sens(J, pt, q);
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = 0; b < nf; ++b)
                Q[(size_t)a * nf + b] += (J[0][a] * J[0][b] + J[1][a] * J[1][b] + J[2][a] * J[2][b]) / (double)n;
    }
}

int rch_poses_point_accuracy(rch_poses_accuracy *acc, const rch_poses_point *pt, const double *M, size_t n_eval,
                             unsigned long long seed)
{
    const unsigned nf = pt->nf;
    double *C = malloc(((size_t)nf * nf + 1) * sizeof *C), *r = malloc((n_eval ? n_eval : 1) * sizeof *r);
    int rc = -1;
    memset(acc, 0, sizeof *acc);
    if (!C || !r || rch_poses_spd_inverse(C, M, nf) != 0)
        goto out;
    rc_rng g;
    rc_rng_seed(&g, seed);
    double phi = 0.0;
    for (size_t t = 0; t < n_eval; ++t) {
        double q[RC_NJ], J[3][RC_MAX_PARAMS], P[9];
        workspace_pose(q, pt->m, &g);
        point_sens(J, pt, q);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double s = 0.0;
                for (unsigned a = 0; a < nf; ++a) {
                    if (J[i][a] == 0.0)
                        continue;
                    double ta = 0.0;
                    for (unsigned b = 0; b < nf; ++b)
                        ta += C[(size_t)a * nf + b] * J[j][b];
                    s += J[i][a] * ta;
                }
                P[i * 3 + j] = s;
            }
        phi += P[0] + P[4] + P[8];
        r[t] = rch_uncert_radius95(P);
    }
    acc->phi_mm2 = n_eval ? phi / (double)n_eval : NAN;
    acc->median_mm = rch_quantile(r, n_eval, 0.5);
    acc->p95_mm = rch_quantile(r, n_eval, 0.95);
    rc = 0;
out:
    free(C);
    free(r);
    return rc;
}

/* the point's description of w's design */
static rch_poses_point pos_point(const pos_work *w, int *col)
{
    for (unsigned a = 0; a < w->nf; ++a)
        col[a] = (int)w->fi[a];
    const rch_poses_point pt = {&w->m, &w->mp, w->nf, col, w->sc};
    return pt;
}

#define SEED_WORK 0x5851F42D4C957F2Dull
#define SEED_EVAL 0x2545F4914F6CDD1Dull

static int pos_alloc(pos_work *w)
{
    const unsigned nf = w->nf;
    const size_t mm = (size_t)nf * nf;
    w->Q = malloc(mm * sizeof *w->Q);
    w->M = malloc(mm * sizeof *w->M);
    w->C = malloc(mm * sizeof *w->C);
    w->B = malloc(mm * sizeof *w->B);
    w->T = malloc(mm * sizeof *w->T);
    w->u = malloc((size_t)w->rows_per * nf * sizeof *w->u);
    w->v = malloc((size_t)w->rows_per * nf * sizeof *w->v);
    w->design = malloc((w->n ? w->n : 1) * sizeof *w->design);
    w->rnd = malloc((w->n ? w->n : 1) * sizeof *w->rnd);
    w->in_design = calloc(w->n_cand ? w->n_cand : 1, 1);
    w->pose_used = calloc(w->n_pose ? w->n_pose : 1, 1);
    return w->Q && w->M && w->C && w->B && w->T && w->u && w->v && w->design && w->rnd && w->in_design &&
                   w->pose_used
               ? 0
               : -1;
}

/* Greedy additions, then exchange passes (each design pose swapped for the
 * candidate that lowers phi most, while one does). 0 or -1 (numeric). */
static int pos_design(pos_work *w, const rch_poses_config *c, FILE *progress)
{
    rch_poses_prior_info(w->M, w->nf);
    for (size_t t = 0; t < w->n; ++t) {
        double bg;
        if (pos_refresh(w) != 0)
            return -1;
        const size_t best = pos_best(w, w->n_cand, &bg, t);
        if (best >= w->n_cand)
            return -1;
        pos_take(w, t, best, 1);
        rch_poses_progress(w->n >= 200 ? progress : NULL, "greedy design, pose", t, w->n);
    }
    for (unsigned long pass = 0; pass < c->passes; ++pass) {
        unsigned swaps = 0;
        if (progress && w->n >= 200)
            fprintf(progress, "rcal poses: exchange pass %lu/%lu\n", pass + 1, c->passes);
        for (size_t t = 0; t < w->n; ++t) {
            const size_t cur = w->design[t];
            double bg;
            pos_take(w, t, cur, 0);
            if (pos_refresh(w) != 0)
                return -1;
            const double gc = pos_gain(w, w->X + cur * w->rows_per * w->nf, w->rows_per);
            const size_t best = pos_best(w, w->n_cand, &bg, t);
            if (best < w->n_cand && best != cur && bg > gc * (1.0 + 1e-9) + 1e-300) {
                pos_take(w, t, best, 1);
                ++swaps;
            } else {
                pos_take(w, t, cur, 1);
            }
        }
        if (!swaps)
            break;
    }
    return 0;
}

/* The information of the design idx (n candidates) into M. */
static void design_info(double *M, const pos_work *w, const size_t *idx, size_t n)
{
    rch_poses_prior_info(M, w->nf);
    for (size_t t = 0; t < n; ++t)
        add_rows(M, w->X + idx[t] * w->rows_per * w->nf, w->rows_per, w->nf, 1.0);
}

/* The plan's rows, by outlet: outlet 0's poses, then outlet 1's, ... */
static int pos_rows_out(rch_poses_result *res, const pos_work *w)
{
    const size_t rows = w->n * w->rows_per;
    res->poses = malloc((rows ? rows : 1) * sizeof *res->poses);
    if (!res->poses)
        return -1;
    res->n = 0;
    for (unsigned k = 0; k < w->K; ++k) {
        res->rows_per_outlet[k] = 0;
        for (size_t t = 0; t < w->n; ++t) {
            const size_t i = w->design[t];
            if (w->split && w->cand_outlet[i] != k)
                continue;
            for (unsigned p = 0; p < w->P; ++p) { /* the pose on each cable point in turn */
                rc_sample s = w->pose[w->cand_pose[i]];
                s.outlet = (uint8_t)k;
                s.target = (uint8_t)p;
                res->poses[res->n++] = s;
                res->rows_per_outlet[k]++;
            }
        }
    }
    return 0;
}

static int check_position(const rch_poses_config *c, rch_diag *d)
{
    if (c->n_outlets > RC_MAX_OUTLETS) {
        rch_diag_set(d, "", 0, 0, "%u outlets: at most %d", c->n_outlets, RC_MAX_OUTLETS);
        return -1;
    }
    if (c->split && c->n_outlets < 2) {
        rch_diag_set(d, "", 0, 0, "--split needs at least two --outlet places");
        return -1;
    }
    if (c->n_points > RC_MAX_TARGETS) {
        rch_diag_set(d, "", 0, 0, "%u cable points: at most %d", c->n_points, RC_MAX_TARGETS);
        return -1;
    }
    return 0;
}

int rch_poses_plan_position(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                            rch_diag *d)
{
    pos_work *w = calloc(1, sizeof *w);
    int rc = -1;
    size_t n_pose = 0;
    if (!w) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    if (rch_poses_check_config(m, c, &n_pose, d) != 0 || check_position(c, d) != 0 || pos_setup(w, m, c, d) != 0)
        goto done;
    w->n = c->count;
    w->n_pose = n_pose;
    if (rch_poses_plan_cost(c, progress, w->n, w->n_pose * w->K * w->P, w->nf, 0, d) != 0)
        goto done;
    if (pos_candidates(w, res, c, d) != 0)
        goto done;
    if (w->n_cand < w->n) {
        rch_diag_set(d, "", 0, 0, "only %zu candidates for %zu poses: raise --candidates", w->n_cand, w->n);
        goto done;
    }
    if (pos_alloc(w) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    int col[RC_MAX_PARAMS];
    const rch_poses_point pt = pos_point(w, col);
    rch_poses_workspace_q(w->Q, &pt, c->n_work ? c->n_work : 300, c->seed ^ SEED_WORK);
    if (pos_design(w, c, progress) != 0) {
        rch_diag_set(d, "", 0, 0, "the design's information matrix is not positive definite (numeric failure)");
        goto done;
    }
    { /* n random candidates of distinct poses */
        rc_rng g2;
        rc_rng_seed(&g2, c->seed ^ 0x9E3779B97F4A7C15ull);
        uint8_t *used = calloc(w->n_pose, 1);
        if (!used) {
            rch_diag_set(d, "", 0, 0, "out of memory");
            goto done;
        }
        for (size_t t = 0; t < w->n; ++t) {
            size_t i;
            unsigned guard = 0;
            do
                i = rc_rng_below(&g2, (uint32_t)w->n_cand);
            while ((used[w->cand_pose[i]] || (w->split && w->cand_outlet[i] != t % w->K)) &&
                   ++guard < 1000000u);
            used[w->cand_pose[i]] = 1;
            w->rnd[t] = i;
        }
        free(used);
    }
    const size_t n_eval = c->n_eval ? c->n_eval : 1000;
    design_info(w->M, w, w->design, w->n);
    if (rch_poses_point_accuracy(&res->plan, &pt, w->M, n_eval, c->seed ^ SEED_EVAL) != 0)
        goto numeric;
    design_info(w->M, w, w->rnd, w->n);
    if (rch_poses_point_accuracy(&res->random, &pt, w->M, n_eval, c->seed ^ SEED_EVAL) != 0)
        goto numeric;
    if (pos_rows_out(res, w) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    res->n_candidates = w->n_pose;
    res->n_params = w->m.n_params;
    res->n_ident = w->nf;
    res->n_outlets = w->K;
    res->n_distinct = w->n;
    res->rows_advised = w->nf + 3u + RCH_POSES_ROWS_SPARE;
    {   /* O1 (rch_ident) of the plan's rows and of the random ones, as for the length criterion */
        rc_sample *rs = w->n > 0 && w->rows_per > 0 ? malloc(w->n * w->rows_per * sizeof *rs) : NULL;
        rch_ident *id = calloc(1, sizeof *id);
        if (rs && id) {
            for (int pass = 0; pass < 2; ++pass) {
                const size_t *idx = pass ? w->rnd : w->design;
                size_t nr = 0;
                for (size_t t = 0; t < w->n; ++t)
                    for (unsigned j = 0; j < w->rows_per; ++j) {
                        rs[nr] = w->pose[w->cand_pose[idx[t]]];
                        rs[nr].target = (uint8_t)(j % w->P);
                        rs[nr++].outlet = (uint8_t)(w->split ? w->cand_outlet[idx[t]] : j / w->P);
                    }
                if (rch_ident_compute(id, &w->m, rs, nr) == 0) {
                    *(pass ? &res->o1_random : &res->o1_plan) = id->observability;
                    *(pass ? &res->rank_random : &res->rank_plan) = id->rank;
                }
            }
        }
        free(rs);
        free(id);
    }
    rc = 0;
    goto done;
numeric:
    rch_diag_set(d, "", 0, 0, "the predicted accuracy could not be computed (numeric failure)");
done:
    if (rc != 0)
        rch_poses_free(res);
    pos_free(w);
    free(w);
    return rc;
}

int rch_poses_predict(rch_poses_accuracy *acc, const rc_model *m, const rch_poses_config *c, const rc_sample *rows,
                      size_t n, rch_diag *d)
{
    pos_work *w = calloc(1, sizeof *w);
    double *M = NULL, *X = NULL, lo[RC_MAX_OUTLETS], hi[RC_MAX_OUTLETS];
    int rc = -1;
    if (!w) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    if (check_position(c, d) != 0 || pos_setup(w, m, c, d) != 0)
        goto out;
    M = malloc(((size_t)w->nf * w->nf + 1) * sizeof *M);
    X = malloc(((size_t)w->K * w->P * w->nf + 1) * sizeof *X);
    if (!M || !X) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto out;
    }
    rch_poses_prior_info(M, w->nf);
    for (size_t i = 0; i < n; ++i) {
        if (rows[i].outlet >= w->K) {
            rch_diag_set(d, "", 0, 0, "row %zu: outlet %u, but %u outlet(s) given", i, rows[i].outlet, w->K);
            goto out;
        }
        if (rows[i].target >= w->P) {
            rch_diag_set(d, "", 0, 0, "row %zu: cable point %u, but %u point(s) given", i, rows[i].target, w->P);
            goto out;
        }
        if (pose_rows(X, lo, hi, w, &rows[i]) != 0) {
            rch_diag_set(d, "", 0, 0, "row %zu: the cable length cannot be computed (the point is at an outlet)", i);
            goto out;
        }
        rch_poses_add_outer(M, X + ((size_t)rows[i].outlet * w->P + rows[i].target) * w->nf, 1.0, w->nf);
    }
    int col[RC_MAX_PARAMS];
    const rch_poses_point pt = pos_point(w, col);
    if (rch_poses_point_accuracy(acc, &pt, M, c->n_eval ? c->n_eval : 1000, c->seed ^ SEED_EVAL) != 0) {
        rch_diag_set(d, "", 0, 0, "the predicted accuracy could not be computed (numeric failure)");
        goto out;
    }
    rc = 0;
out:
    free(M);
    free(X);
    free(w);
    return rc;
}
