/* SPDX-License-Identifier: MIT */
/* rch_est.c - the seven methods behind one call; see rch_est.h. */
#include "rch_est.h"

#include "rc_rand.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* One row of RCH_EST_METHODS. */
typedef struct est_row {
    const char *name;
    int row, solve, est;
} est_row;
#define RCH_EST_ROW_(id, name, row, solve, est) {name, row, solve, est},
static const est_row est_table[RCH_EST_ALL] = {RCH_EST_METHODS(RCH_EST_ROW_)};
#undef RCH_EST_ROW_

const char *rch_est_name(rch_est_id id)
{
    return (unsigned)id < RCH_EST_ALL ? est_table[id].name : "unknown";
}

int rch_est_paper_row(rch_est_id id)
{
    return (unsigned)id < RCH_EST_ALL ? est_table[id].row : 7;
}

int rch_est_is_solve(rch_est_id id)
{
    return (unsigned)id < RCH_EST_ALL && est_table[id].solve >= 0;
}

void rch_est_solve_config(rc_solve_config *cfg, rch_est_id id, uint64_t seed, const rch_est_opts *opts)
{
    static const rch_est_opts defaults;
    if (!opts)
        opts = &defaults;
    memset(cfg, 0, sizeof *cfg);
    cfg->method = rch_est_is_solve(id) ? (rc_method)est_table[id].solve : RC_METHOD_LM;
    cfg->max_iter = opts->max_iter;
    cfg->seed = seed;
    cfg->fixed = opts->fixed;
    if (id == RCH_EST_LM || id == RCH_EST_LTLM) { /* the paper variants ignore a prior */
        cfg->prior_mean = opts->prior_mean;
        cfg->prior_sd = opts->prior_sd;
        cfg->prior_noise_mm = opts->prior_noise_mm;
    }
}

static int ieq(const char *a, const char *b)
{
    for (; *a && *b; ++a, ++b)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return 0;
    return *a == *b;
}

int rch_est_parse(const char *name)
{
    if (!name)
        return -1;
    for (int i = 0; i < RCH_EST_ALL; ++i) {
        char m[4] = {'m', (char)('1' + i), 0, 0};
        if (ieq(name, est_table[i].name) || (i < RCH_EST_COUNT && ieq(name, m)))
            return i;
    }
    return -1;
}

void rch_curve_free(rch_curve *c)
{
    if (!c)
        return;
    free(c->rms_mm);
    memset(c, 0, sizeof *c);
}

static void curve_push(rch_curve *c, double v)
{
    if (!c || c->failed)
        return;
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 64;
        double *r = realloc(c->rms_mm, cap * sizeof *r);
        if (!r) {
            c->failed = 1;
            return;
        }
        c->rms_mm = r;
        c->cap = cap;
    }
    c->rms_mm[c->n++] = v;
}

static void curve_cb(void *ctx, unsigned iter, double rms_mm, const rc_model *m)
{
    (void)iter;
    (void)m;
    curve_push(ctx, rms_mm);
}

rch_est_ws *rch_est_ws_new(void) { return malloc(sizeof(rch_est_ws)); }
void rch_est_ws_free(rch_est_ws *ws) { free(ws); }

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

rc_status rch_est_run(rc_model *m, rch_est_out *out, rch_curve *curve, rch_est_ws *ws,
                      rch_est_id id, uint64_t seed, const rch_est_opts *opts,
                      const rc_sample *train, size_t n)
{
    static const rch_est_opts defaults;
    rc_status st;
    double t0;
    if (!opts)
        opts = &defaults;
    memset(out, 0, sizeof *out);
    if (!ws)
        return RC_ERR_CAPACITY;
    if (curve) {
        double c0;
        if (rc_cost(&c0, m, train, n) == RC_OK && n > 0)
            curve_push(curve, sqrt(c0 / (double)n));
    }
    if (rch_est_is_solve(id)) {
        rc_solve_config cfg;
        rc_solve_result res;
        rch_est_solve_config(&cfg, id, seed, opts);
        cfg.on_iter = curve ? curve_cb : NULL;
        cfg.cb_ctx = curve;
        t0 = now_ms();
        st = rc_solve(m, &res, &ws->solve, &cfg, train, n);
        out->time_ms = now_ms() - t0;
        out->iterations = res.iterations;
        out->cost_evals = res.cost_evals;
        out->rms_start_mm = res.rms_start_mm;
        out->rms_final_mm = res.rms_final_mm;
        out->n_moved = res.rank ? res.rank : res.n_free; /* the paper variants move every free parameter */
        return st;
    }
    {
        rc_est_config cfg;
        rc_est_result res;
        if ((unsigned)id >= RCH_EST_ALL || est_table[id].est < 0)
            return RC_ERR_ARG;
        memset(&cfg, 0, sizeof cfg);
        cfg.method = (rc_est_method)est_table[id].est;
        cfg.max_iter = opts->max_iter;
        cfg.pop = opts->pop;
        cfg.bound_len_mm = opts->bound_len_mm;
        cfg.bound_ang_rad = opts->bound_ang_rad;
        cfg.bound_enc_mm = opts->bound_enc_mm;
        cfg.bound_other = opts->bound_other;
        cfg.fixed = opts->fixed;
        cfg.keep_all = opts->same_set;
        cfg.prior_mean = opts->prior_mean; /* every method takes the prior (rc_est.h) */
        cfg.prior_sd = opts->prior_sd;
        cfg.prior_noise_mm = opts->prior_noise_mm;
        cfg.seed = seed;
        cfg.on_iter = curve ? curve_cb : NULL;
        cfg.cb_ctx = curve;
        t0 = now_ms();
        st = rc_est_solve(m, &res, &ws->est, &cfg, train, n);
        out->time_ms = now_ms() - t0;
        out->iterations = res.iterations;
        out->cost_evals = res.cost_evals;
        out->rms_start_mm = res.rms_start_mm;
        out->rms_final_mm = res.rms_final_mm;
        out->n_moved = res.n_moved;
        return st;
    }
}

/* ---- chaos study ---------------------------------------------------------- */

double rch_chaos_sd(unsigned *counts, double r, double n0, unsigned points, unsigned bins)
{
    unsigned local[1024];
    unsigned *c = counts;
    double x = n0, ss = 0.0;
    if (bins == 0 || points == 0)
        return 0.0;
    if (!c) {
        if (bins > sizeof local / sizeof local[0])
            return NAN;
        c = local;
    }
    memset(c, 0, bins * sizeof c[0]);
    for (unsigned k = 0; k < points; ++k) {
        x = rc_lt_map(x, r);
        unsigned b = (unsigned)(x * (double)bins);
        if (!(x >= 0.0) || b >= bins) /* NaN or 1.0: last bin; cannot happen for x in [0,1) */
            b = bins - 1;
        c[b]++;
    }
    for (unsigned b = 0; b < bins; ++b) {
        const double dv = (double)c[b] - (double)points / (double)bins;
        ss += dv * dv;
    }
    return bins > 1 ? sqrt(ss / (double)(bins - 1)) : 0.0; /* Eq. 12: N - 1 in the denominator */
}

double rch_chaos_sd_avg(double *se, double r, unsigned points, unsigned bins, unsigned n_starts,
                        uint64_t seed)
{
    rc_rng g;
    double sum = 0.0, sq = 0.0, mean;
    if (n_starts == 0)
        n_starts = 1;
    rc_rng_seed(&g, seed);
    for (unsigned i = 0; i < n_starts; ++i) {
        const double v = rch_chaos_sd(NULL, r, 0.01 + 0.98 * rc_rng_u01(&g), points, bins);
        sum += v;
        sq += v * v;
    }
    mean = sum / (double)n_starts;
    if (se) {
        const double var = n_starts > 1 ? (sq - (double)n_starts * mean * mean) / (double)(n_starts - 1) : 0.0;
        *se = var > 0.0 ? sqrt(var / (double)n_starts) : 0.0;
    }
    return mean;
}

double rch_chaos_sd_iid(unsigned points, unsigned bins)
{
    if (bins == 0)
        return 0.0;
    /* E[sum (c - mean)^2] = points (1 - 1/bins) for independent draws; over bins - 1 (Eq. 12) */
    return bins > 1 ? sqrt((double)points / (double)bins) : 0.0;
}
