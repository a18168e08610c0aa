/* SPDX-License-Identifier: MIT */
/* rc_solve.c - the robot's problem: the model supplies the data blocks
 * (rc_model_problem), the configuration the prior block; the solver is
 * rc_problem's (rc_lsq.c). The robot's passes (rc_cost, rc_normal_eq,
 * rc_eval) and workspace sizes. */
#include "rc_solve.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Rows of the normal equations rc_problem_normal_eq updates at a time. */
#define NE_BLOCK 4

static const double *tab_row(const double *t, size_t k) { return t != NULL ? t + (size_t)RC_NJ * k : NULL; }

static rc_status model_prepare(void *ctx, const double *x)
{
    rc_model_rows *r = ctx;
    if (r->scratch != NULL) {
        memcpy(r->scratch->x, x, r->scratch->n_params * sizeof x[0]);
        r->eval = r->scratch;
    }
    RC_ASSERT(x == r->eval->x || r->scratch != NULL);
    rc_meas_prepare(&r->prep, r->eval);
    return RC_OK;
}

/* The rows of sample s: r[0] its weighted residual, jac (n_params) its
 * weighted Jacobian row or NULL. */
static rc_status sample_row(double *r, double *jac, const rc_model_rows *mr, size_t s)
{
    const rc_sample *smp = &mr->samples[s];
    double l;
    const rc_status st = rc_meas_prepared(&l, jac, mr->eval, &mr->prep, smp, tab_row(mr->sin_q, s),
                                          tab_row(mr->cos_q, s));
    if (st != RC_OK)
        return st;
    const double wt = rc_sample_weight(smp);
    r[0] = (l - smp->value) * wt;
    if (jac != NULL && wt != 1.0)
        for (unsigned k = 0; k < mr->eval->n_params; ++k)
            jac[k] *= wt;
    return RC_OK;
}

/* A block of dimension 1: item = sample. */
static rc_status rows_single(double *r, double *jac, void *ctx, size_t item)
{
    const rc_model_block *b = ctx;
    return sample_row(r, jac, b->owner, item);
}

/* A block of tracker positions: item k = the three samples from s0 + 3k. */
static rc_status rows_position(double *r, double *jac, void *ctx, size_t item)
{
    const rc_model_block *b = ctx;
    const size_t s = b->s0 + 3 * item, np = b->owner->eval->n_params;
    for (unsigned d = 0; d < 3; ++d) {
        const rc_status st = sample_row(r + d, jac != NULL ? jac + d * np : NULL, b->owner, s + d);
        if (st != RC_OK)
            return st;
    }
    return RC_OK;
}

/* Samples k.. k+2 are one tracker position (x, y, z of one target at one pose). */
static int is_position(const rc_sample *s, size_t k, size_t n)
{
    if (k + 3 > n || s[k].sensor != RC_SENSOR_TRACKER_X || s[k + 1].sensor != RC_SENSOR_TRACKER_Y ||
        s[k + 2].sensor != RC_SENSOR_TRACKER_Z)
        return 0;
    if (s[k + 1].target != s[k].target || s[k + 2].target != s[k].target)
        return 0;
    for (int j = 0; j < RC_NJ; ++j)
        if (s[k + 1].q_rad[j] != s[k].q_rad[j] || s[k + 2].q_rad[j] != s[k].q_rad[j])
            return 0;
    return 1;
}

/* The blocks of samples (n): runs of one sensor in order; 0 when there would
 * be more than RC_MODEL_MAX_BLOCKS. */
static unsigned model_blocks(rc_model_rows *r, const rc_sample *samples, size_t n, unsigned max_dim)
{
    unsigned nb = 0;
    for (size_t k = 0; k < n;) {
        const int pos = max_dim >= 3 && is_position(samples, k, n);
        size_t e = k + (pos ? 3 : 1);
        while (e < n && (pos ? is_position(samples, e, n) : !(max_dim >= 3 && is_position(samples, e, n))))
            e += pos ? 3 : 1;
        if (nb == RC_MODEL_MAX_BLOCKS)
            return 0;
        rc_block *b = &r->blocks[nb];
        r->blk[nb].owner = r;
        r->blk[nb].s0 = k;
        b->ctx = &r->blk[nb];
        b->rows = pos ? rows_position : rows_single;
        b->first = pos ? 0 : k;
        b->n = pos ? (e - k) / 3 : e - k;
        b->dim = pos ? 3u : 1u;
        b->unit = rc_sensor_unit(samples[k].sensor);
        ++nb;
        k = e;
    }
    return nb;
}

void rc_model_problem(rc_problem *p, rc_model_rows *r, const rc_model *m, rc_model *scratch, const rc_sample *samples,
                      size_t n, const double *sin_q, const double *cos_q, const rc_solve_config *cfg,
                      unsigned max_dim)
{
    RC_ASSERT(p != NULL && r != NULL && m != NULL && (samples != NULL || n == 0));
    memset(p, 0, sizeof *p);
    r->eval = m;
    r->scratch = scratch;
    if (scratch != NULL && scratch != m)
        *scratch = *m;
    r->samples = samples;
    r->sin_q = sin_q != NULL && cos_q != NULL ? sin_q : NULL;
    r->cos_q = sin_q != NULL && cos_q != NULL ? cos_q : NULL;
    p->n_params = m->n_params;
    p->n_blocks = model_blocks(r, samples, n, max_dim);
    if (p->n_blocks == 0 && n > 0) { /* sensors interleaved: one block, a sample a row */
        r->blk[0].owner = r;
        r->blk[0].s0 = 0;
        r->blocks[0] = (rc_block){rows_single, &r->blk[0], 0, n, 1u, rc_sensor_unit(samples[0].sensor)};
        p->n_blocks = 1;
    }
    p->blocks = r->blocks;
    p->prepare = model_prepare;
    p->prepare_ctx = r;
    for (unsigned k = 0; k < m->n_params && k < RC_MAX_PARAMS; ++k) {
        r->inert[k] = k == RC_P_ALPHA(RC_NJ - 1);
        r->unit[k] = rc_param_unit(m, k) == 1;
    }
    p->inert = r->inert;
    p->unit = r->unit;
    if (cfg != NULL) {
        p->fixed = cfg->fixed;
        p->prior.mean = cfg->prior_mean;
        p->prior.sd = cfg->prior_sd;
        p->prior.noise = cfg->prior_noise_mm;
    }
}

static rc_status cost_tab(double *cost_mm2, const rc_model *m, const rc_sample *samples, const double *sin_q,
                          const double *cos_q, size_t n)
{
    rc_problem p;
    rc_model_rows r;
    RC_ASSERT(cost_mm2 != NULL && m != NULL && (samples != NULL || n == 0));
    rc_model_problem(&p, &r, m, NULL, samples, n, sin_q, cos_q, NULL, 1);
    return rc_problem_cost(cost_mm2, &p, m->x);
}

rc_status rc_cost(double *cost_mm2, const rc_model *m, const rc_sample *samples, size_t n)
{
    return cost_tab(cost_mm2, m, samples, NULL, NULL, n);
}

rc_status rc_cost_tab(double *cost_mm2, const rc_model *m, const rc_sample *samples, const double *sin_q,
                      const double *cos_q, size_t n)
{
    return cost_tab(cost_mm2, m, samples, sin_q, cos_q, n);
}

rc_status rc_normal_eq(double *A, double *g, double *cost_mm2, double *jrow, const rc_model *m,
                       const uint16_t *idx, unsigned nf, const rc_sample *samples, size_t n)
{
    rc_problem p;
    rc_model_rows r;
    RC_ASSERT(A != NULL && g != NULL && cost_mm2 != NULL && jrow != NULL && m != NULL && idx != NULL);
    RC_ASSERT(samples != NULL || n == 0);
    rc_model_problem(&p, &r, m, NULL, samples, n, NULL, NULL, NULL, 1);
    return rc_problem_normal_eq(A, g, cost_mm2, jrow, NULL, &p, m->x, idx, nf);
}

/* The prior block of cfg over m's parameters (fixed ones from cfg). */
static void prior_problem(rc_problem *p, const rc_model *m, const rc_solve_config *cfg)
{
    memset(p, 0, sizeof *p);
    p->n_params = m->n_params;
    if (cfg != NULL) {
        p->fixed = cfg->fixed;
        p->prior.mean = cfg->prior_mean;
        p->prior.sd = cfg->prior_sd;
        p->prior.noise = cfg->prior_noise_mm;
    }
}

double rc_prior_cost(const rc_model *m, const rc_solve_config *cfg)
{
    rc_problem p;
    RC_ASSERT(m != NULL);
    prior_problem(&p, m, cfg);
    return rc_problem_prior_cost(&p, m->x);
}

void rc_prior_normal_eq(double *A, double *g, double *cost, const rc_model *m, const uint16_t *idx, unsigned nf,
                        const rc_solve_config *cfg)
{
    rc_problem p;
    prior_problem(&p, m, cfg);
    rc_problem_prior_normal_eq(A, g, cost, &p, m->x, idx, nf);
}

rc_status rc_eval(rc_metrics *out, const rc_model *m, const rc_sample *samples, size_t n)
{
    double mean = 0.0, m2 = 0.0, sq = 0.0, abs_sum = 0.0, mx = 0.0;
    rc_meas_prep p;
    RC_ASSERT(out != NULL && m != NULL);
    memset(out, 0, sizeof *out);
    if (n == 0)
        return RC_ERR_ARG;
    rc_meas_prepare(&p, m);
    for (size_t i = 0; i < n; ++i) {
        double l;
        rc_status st = rc_meas_prepared(&l, NULL, m, &p, &samples[i], NULL, NULL);
        if (st != RC_OK)
            return st;
        const double e = l - samples[i].value;
        const double d = e - mean;
        mean += d / (double)(i + 1);
        m2 += d * (e - mean);
        sq += e * e;
        abs_sum += fabs(e);
        if (fabs(e) > mx)
            mx = fabs(e);
    }
    out->n = n;
    out->rmse_mm = sqrt(sq / (double)n);
    out->mean_abs_mm = abs_sum / (double)n;
    out->sd_mm = n > 1 ? sqrt(m2 / (double)(n - 1)) : 0.0;
    out->mean_mm = mean;
    out->max_mm = mx;
    return isfinite(out->rmse_mm) ? RC_OK : RC_ERR_NUMERIC;
}

/* The caller's callbacks, which see models: the point copied into a model. */
typedef struct model_cb {
    const rc_solve_config *cfg;
    rc_model *at;
} model_cb;

static void on_iter_model(void *ctx, unsigned iter, double rms, const double *x)
{
    const model_cb *c = ctx;
    memcpy(c->at->x, x, c->at->n_params * sizeof x[0]);
    c->cfg->on_iter(c->cfg->cb_ctx, iter, rms, c->at);
}

static void on_ltlm_model(void *ctx, const rc_lsq_event *e)
{
    const model_cb *c = ctx;
    rc_ltlm_event ev;
    memcpy(c->at->x, e->x, c->at->n_params * sizeof e->x[0]);
    ev.iter = e->iter;
    ev.kind = e->kind;
    ev.m = e->m;
    ev.n_m = e->n_m;
    ev.x = c->at;
    ev.cost_mm2 = e->cost;
    c->cfg->on_ltlm(c->cfg->cb_ctx, &ev);
}

static void opts_from(rc_solve_opts *o, const rc_solve_config *cfg)
{
    o->method = cfg->method;
    o->max_iter = cfg->max_iter;
    o->mu0 = cfg->mu0;
    o->tol_step = cfg->tol_step;
    o->tol_cost = cfg->tol_cost;
    o->rcond = cfg->rcond;
    o->snr_min = cfg->snr_min;
    o->n_candidates = cfg->n_candidates;
    o->chaos_r = cfg->chaos_r;
    o->chaos_n0 = cfg->chaos_n0;
    o->seed = cfg->seed;
}

/* rc_solve on w's small fields and the matrices A, V ((nf x nf) each,
 * n_params^2 entries of room), the sample tables sin_q, cos_q (or NULL) and
 * the row blocks jblk (or NULL). */
static rc_status solve_with(rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A, double *V,
                            double *sin_q, double *cos_q, double *jblk, const rc_solve_config *cfg,
                            const rc_sample *samples, size_t n)
{
    static const rc_solve_config defaults;
    rc_solve_result local;
    rc_solve_opts o;
    rc_problem p;
    RC_ASSERT(m != NULL && w != NULL);
    if (cfg == NULL)
        cfg = &defaults;
    if (res == NULL)
        res = &local;
    memset(res, 0, sizeof *res);
    if (samples == NULL || n == 0)
        return RC_ERR_ARG;
    if (m->n_params > RC_MAX_PARAMS || m->n_params < RC_N_BASE)
        return RC_ERR_ARG;
    if (sin_q != NULL && cos_q != NULL)
        rc_qtrig_fill(sin_q, cos_q, samples, n);
    else
        sin_q = cos_q = NULL;
    rc_model_rows rows; /* the problem's storage (small beside the workspace) */
    rc_model_problem(&p, &rows, m, &w->at, samples, n, sin_q, cos_q, cfg, RC_MAX_BLOCK_DIM);
    model_cb cb = {cfg, &w->at}; /* (a pass copies its point into w->at anew) */
    if (cfg->on_iter != NULL)
        p.on_iter = on_iter_model;
    if (cfg->on_ltlm != NULL)
        p.on_ltlm = on_ltlm_model;
    p.cb_ctx = &cb;
    opts_from(&o, cfg);
    const rc_status st = rc_problem_solve_in(m->x, res, &w->lsq, A, V, jblk, &o, &p);
    rc_model_wrap_angles(m);
    return st;
}

void rc_solve_config_warm(rc_solve_config *cfg)
{
    RC_ASSERT(cfg != NULL);
    const int prior = cfg->prior_mean != NULL && cfg->prior_sd != NULL && cfg->prior_noise_mm > 0.0;
    if (!(cfg->mu0 > 0.0) && (cfg->method == RC_METHOD_LM || cfg->method == RC_METHOD_LTLM) && prior)
        cfg->mu0 = RC_SOLVE_MU0_WARM;
}

rc_status rc_solve(rc_model *m, rc_solve_result *res, rc_solve_work *w, const rc_solve_config *cfg,
                   const rc_sample *samples, size_t n)
{
    RC_ASSERT(m != NULL && w != NULL);
    double *sin_q = NULL, *cos_q = NULL, *jblk = NULL;
    /* In the unused tails of A and V (beyond n_params^2 entries), when they
     * fit: the row blocks and sin_q in A's, cos_q in V's. (n_params out of
     * range: solve_with refuses it.) */
    if (m->n_params <= RC_MAX_PARAMS) {
        const size_t cap = sizeof w->A / sizeof w->A[0], np = m->n_params;
        size_t room = cap - np * np;
        double *tail = w->A + np * np;
        if (room >= NE_BLOCK * np) {
            jblk = tail;
            tail += NE_BLOCK * np;
            room -= NE_BLOCK * np;
        }
        if (samples != NULL && n <= room / RC_NJ) {
            sin_q = tail;
            cos_q = w->V + np * np;
        }
    }
    return solve_with(m, res, w, w->A, w->V, sin_q, cos_q, jblk, cfg, samples, n);
}

size_t rc_solve_work_size(unsigned n_params, size_t n_samples)
{
    if (n_params < RC_N_BASE || n_params > RC_MAX_PARAMS)
        return 0;
    const size_t np = n_params, fixed = 2 * np * np + NE_BLOCK * np;
    if (n_samples > (SIZE_MAX / sizeof(double) - fixed - offsetof(rc_solve_work, A)) / (2 * RC_NJ))
        return 0;
    return offsetof(rc_solve_work, A) + (fixed + 2 * RC_NJ * n_samples) * sizeof(double);
}

rc_status rc_solve_buf(rc_model *m, rc_solve_result *res, void *work, size_t work_bytes,
                       const rc_solve_config *cfg, const rc_sample *samples, size_t n)
{
    RC_ASSERT(m != NULL && work != NULL);
    const size_t need = rc_solve_work_size(m->n_params, 0);
    if (need == 0)
        return RC_ERR_ARG;
    if ((uintptr_t)work % sizeof(double) != 0)
        return RC_ERR_ARG;
    if (work_bytes < need)
        return RC_ERR_CAPACITY;
    /* the prefix of rc_solve_work up to A, then A, V, the row blocks and the
     * tables */
    const size_t np = m->n_params;
    rc_solve_work *w = (rc_solve_work *)work;
    double *A = w->A; /* at offsetof(rc_solve_work, A): inside the buffer */
    double *V = A + np * np, *jblk = V + np * np;
    double *sin_q = NULL, *cos_q = NULL;
    const size_t full = rc_solve_work_size(m->n_params, n);
    if (samples != NULL && full != 0 && work_bytes >= full) {
        sin_q = jblk + NE_BLOCK * np;
        cos_q = sin_q + (size_t)RC_NJ * n;
    }
    return solve_with(m, res, w, A, V, sin_q, cos_q, jblk, cfg, samples, n);
}
