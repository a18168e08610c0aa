/* SPDX-License-Identifier: MIT */
/* rc_solve.c - LM, LTLM and the paper's variants over streamed normal equations. */
#include "rc_solve.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "rc_ident.h"
#include "rc_linalg.h"
#include "rc_rand.h"

/* What a pass over the samples may use besides the samples: it evaluates them
 * with rc_meas_prepared (the model's sines once per pass), the readings'
 * sines from the tables sin_q, cos_q ((n x 6) each, rc_qtrig_fill; both
 * NULL: per sample), and rc_normal_eq's row blocks in jblk (NE_BLOCK x nf;
 * NULL: row by row). */
typedef struct {
    const double *sin_q, *cos_q;
    double *jblk;
} passbuf;

static const double *tab_row(const double *t, size_t k) { return t != NULL ? t + (size_t)RC_NJ * k : NULL; }

static rc_status cost_tab(double *cost_mm2, const rc_model *m, const rc_sample *samples, passbuf t, size_t n)
{
    rc_meas_prep p;
    double sum = 0.0;
    RC_ASSERT(cost_mm2 != NULL && m != NULL && (samples != NULL || n == 0));
    rc_meas_prepare(&p, m);
    for (size_t i = 0; i < n; ++i) {
        double l;
        rc_status st = rc_meas_prepared(&l, NULL, m, &p, &samples[i], tab_row(t.sin_q, i), tab_row(t.cos_q, i));
        if (st != RC_OK)
            return st;
        const double r = (l - samples[i].len_mm) * rc_sample_weight(&samples[i]);
        sum += r * r;
    }
    *cost_mm2 = sum;
    return isfinite(sum) ? RC_OK : RC_ERR_NUMERIC;
}

rc_status rc_cost(double *cost_mm2, const rc_model *m, const rc_sample *samples, size_t n)
{
    const passbuf none = {NULL, NULL, NULL};
    return cost_tab(cost_mm2, m, samples, none, n);
}

rc_status rc_cost_tab(double *cost_mm2, const rc_model *m, const rc_sample *samples, const double *sin_q,
                      const double *cos_q, size_t n)
{
    const passbuf t = {sin_q && cos_q ? sin_q : NULL, sin_q && cos_q ? cos_q : NULL, NULL};
    return cost_tab(cost_mm2, m, samples, t, n);
}

/* Samples per block of the normal-equation update: A += Jb^T Jb with NE_BLOCK
 * rows at a time reads and writes A once per block instead of once per row.
 * The rows are added one after the other (left to right), so the sums are
 * those of the row-by-row update to the last bit. */
#define NE_BLOCK 4

/* The rows of samples [s0, s0 + NE_BLOCK) (zero rows past n) into jb
 * (NE_BLOCK x nf, free parameters only) and their residuals into rb. */
static rc_status block_rows(double *jb, double rb[NE_BLOCK], double *sum, double *jrow, const rc_model *m,
                            const rc_meas_prep *p, const uint16_t *idx, unsigned nf, const rc_sample *samples,
                            passbuf t, size_t s0, size_t n)
{
    for (unsigned b = 0; b < NE_BLOCK; ++b) {
        const size_t s = s0 + b;
        double *row = jb + (size_t)b * nf, l;
        if (s >= n) { /* past the last sample: a zero row adds nothing */
            rb[b] = 0.0;
            memset(row, 0, nf * sizeof row[0]);
            continue;
        }
        rc_status st = rc_meas_prepared(&l, jrow, m, p, &samples[s], tab_row(t.sin_q, s), tab_row(t.cos_q, s));
        if (st != RC_OK)
            return st;
        const double wt = rc_sample_weight(&samples[s]);
        rb[b] = (l - samples[s].len_mm) * wt;
        *sum += rb[b] * rb[b];
        for (unsigned i = 0; i < nf; ++i)
            row[i] = jrow[idx[i]] * wt;
    }
    return RC_OK;
}

/* A (nf x nf, upper triangle) += Jb^T Jb, g += Jb^T rb for the NE_BLOCK rows
 * j0..j3 (nf each), a symmetric rank-NE_BLOCK update; restrict: A, g and the
 * rows never overlap, so the inner loop vectorises. */
static void rank_block_update(double *restrict A, double *restrict g, const double *restrict j0,
                              const double *restrict j1, const double *restrict j2, const double *restrict j3,
                              const double rb[NE_BLOCK], unsigned nf)
{
    const double r0 = rb[0], r1 = rb[1], r2 = rb[2], r3 = rb[3];
    uint16_t nz[RC_MAX_PARAMS]; /* the columns not zero in all four rows: the others add exactly nothing (a
                                   group offset's 47 of 48 columns) */
    size_t nn = 0;
    for (size_t i = 0; i < nf; ++i)
        if (j0[i] != 0.0 || j1[i] != 0.0 || j2[i] != 0.0 || j3[i] != 0.0)
            nz[nn++] = (uint16_t)i;
    for (size_t u = 0; u < nn; ++u) {
        const size_t i = nz[u];
        const double a0 = j0[i], a1 = j1[i], a2 = j2[i], a3 = j3[i];
        g[i] = g[i] + a0 * r0 + a1 * r1 + a2 * r2 + a3 * r3;
        double *restrict Ai = A + i * nf;
        if (nn == nf - i + u) { /* dense from i on: the contiguous loop */
            for (size_t k = i; k < nf; ++k)
                Ai[k] = Ai[k] + a0 * j0[k] + a1 * j1[k] + a2 * j2[k] + a3 * j3[k];
            continue;
        }
        for (size_t v = u; v < nn; ++v) {
            const size_t k = nz[v];
            Ai[k] = Ai[k] + a0 * j0[k] + a1 * j1[k] + a2 * j2[k] + a3 * j3[k];
        }
    }
}

static rc_status normal_eq_tab(double *A, double *g, double *cost_mm2, double *jrow, const rc_model *m,
                               const uint16_t *idx, unsigned nf, const rc_sample *samples, passbuf t, size_t n)
{
    double sum = 0.0;
    rc_meas_prep p;
    RC_ASSERT(A != NULL && g != NULL && cost_mm2 != NULL && jrow != NULL && m != NULL && idx != NULL);
    RC_ASSERT(samples != NULL || n == 0);
    rc_meas_prepare(&p, m);
    memset(A, 0, (size_t)nf * nf * sizeof A[0]);
    memset(g, 0, nf * sizeof g[0]);
    for (size_t s = 0; s < n && t.jblk == NULL; ++s) { /* row by row */
        double l;
        rc_status st = rc_meas_prepared(&l, jrow, m, &p, &samples[s], tab_row(t.sin_q, s), tab_row(t.cos_q, s));
        if (st != RC_OK)
            return st;
        const double wt = rc_sample_weight(&samples[s]), r = (l - samples[s].len_mm) * wt;
        sum += r * r;
        for (unsigned i = 0; i < nf; ++i) {
            const double ji = jrow[idx[i]] * wt;
            if (ji == 0.0)
                continue;
            g[i] += ji * r;
            double *Ai = &A[(size_t)i * nf];
            for (unsigned k = i; k < nf; ++k)
                Ai[k] += ji * jrow[idx[k]] * wt;
        }
    }
    for (size_t s0 = 0; s0 < n && t.jblk != NULL; s0 += NE_BLOCK) {
        double rb[NE_BLOCK];
        rc_status st = block_rows(t.jblk, rb, &sum, jrow, m, &p, idx, nf, samples, t, s0, n);
        if (st != RC_OK)
            return st;
        rank_block_update(A, g, t.jblk, t.jblk + nf, t.jblk + 2 * nf, t.jblk + 3 * nf, rb, nf);
    }
    for (unsigned i = 0; i < nf; ++i)
        for (unsigned k = 0; k < i; ++k)
            A[(size_t)i * nf + k] = A[(size_t)k * nf + i];
    *cost_mm2 = sum;
    return isfinite(sum) ? RC_OK : RC_ERR_NUMERIC;
}

rc_status rc_normal_eq(double *A, double *g, double *cost_mm2, double *jrow, const rc_model *m,
                       const uint16_t *idx, unsigned nf, const rc_sample *samples, size_t n)
{
    const passbuf none = {NULL, NULL, NULL};
    return normal_eq_tab(A, g, cost_mm2, jrow, m, idx, nf, samples, none, n);
}

static int method_is_paper(rc_method mt);

/* The weight (noise / sd)^2 of parameter k's prior row, 0 when it has none. */
static double prior_weight(const rc_solve_config *cfg, unsigned k)
{
    if (cfg == NULL || cfg->prior_mean == NULL || cfg->prior_sd == NULL || !(cfg->prior_noise_mm > 0.0))
        return 0.0;
    const double sd = cfg->prior_sd[k];
    if (!(sd > 0.0) || !isfinite(sd))
        return 0.0;
    const double r = cfg->prior_noise_mm / sd;
    return r * r;
}

static int has_prior(const rc_solve_config *cfg)
{
    return cfg != NULL && cfg->prior_mean != NULL && cfg->prior_sd != NULL && cfg->prior_noise_mm > 0.0;
}

double rc_prior_cost(const rc_model *m, const rc_solve_config *cfg)
{
    double c = 0.0;
    RC_ASSERT(m != NULL);
    if (!has_prior(cfg))
        return 0.0;
    for (unsigned k = 0; k < m->n_params; ++k) {
        if (cfg->fixed != NULL && cfg->fixed[k] != 0)
            continue;
        const double w = prior_weight(cfg, k), r = m->x[k] - cfg->prior_mean[k];
        if (w > 0.0)
            c += w * r * r;
    }
    return c;
}

void rc_prior_normal_eq(double *A, double *g, double *cost, const rc_model *m, const uint16_t *idx, unsigned nf,
                        const rc_solve_config *cfg)
{
    if (!has_prior(cfg))
        return;
    for (unsigned i = 0; i < nf; ++i) {
        const unsigned k = idx[i];
        const double w = prior_weight(cfg, k), r = m->x[k] - cfg->prior_mean[k];
        if (w == 0.0)
            continue;
        A[(size_t)i * nf + i] += w;
        g[i] += w * r;
        *cost += w * r * r;
    }
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
        const double e = l - samples[i].len_mm;
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

/* trial = base + D^-1 * dx on the free parameters. */
static void apply_step(rc_model *trial, const rc_model *base, const rc_solve_work *w, unsigned nf,
                       const double *dx)
{
    *trial = *base;
    for (unsigned i = 0; i < nf; ++i)
        trial->x[w->idx[i]] += dx[i] / w->D[i];
}

static double rms_of(double cost, size_t n) { return sqrt(cost / (double)n); }

static void ltlm_report(const rc_solve_config *cfg, unsigned iter, rc_ltlm_point kind, unsigned mi,
                        double n_m, const rc_model *x, double cost)
{
    rc_ltlm_event ev;
    if (cfg->on_ltlm == NULL)
        return;
    ev.iter = iter;
    ev.kind = kind;
    ev.m = mi;
    ev.n_m = n_m;
    ev.x = x;
    ev.cost_mm2 = cost;
    cfg->on_ltlm(cfg->cb_ctx, &ev);
}

/* N_0 of the scalar chaotic sequence: the caller's, or drawn from the seed. */
static double ltlm_n0(const rc_solve_config *cfg)
{
    rc_rng g;
    if (cfg->chaos_n0 > 0.0 && cfg->chaos_n0 < 1.0)
        return cfg->chaos_n0;
    rc_rng_seed(&g, cfg->seed ^ 0x4C544C4Dull);
    return 0.05 + 0.9 * rc_rng_u01(&g);
}

/* Algorithm I steps 9-15. In: x_k (xk), x1 with its cost c1, x2 on the free
 * parameters (w->lt_x2, nf), the sequence state *chaos_n (N_{m-1}).
 * Forms a and b (w->lt_a, w->lt_b), continues the sequence by M values and
 * evaluates xl(m) = x1 - (x1 - a) N_m and xr(m) = x1 + (x2 - b) N_m in the
 * order xl(1), xr(1), xl(2), ...; *best (cost *best_cost) = the strict
 * minimum of {x1, xl, xr} (ties keep the earlier point). skip_flat: do not
 * evaluate a segment of zero length (its candidates all equal x1).
 * Returns 1 when a candidate beat x1. */
static int ltlm_segments(rc_model *best, double *best_cost, const rc_model *xk, const rc_model *x1,
                         double c1, rc_solve_work *w, unsigned nf, const rc_solve_config *cfg,
                         double *chaos_n, unsigned iter, int skip_flat, const rc_sample *samples,
                         size_t n, unsigned *evals)
{
    const unsigned M = cfg->n_candidates ? cfg->n_candidates : 10u;
    const double r = cfg->chaos_r > 0.0 ? cfg->chaos_r : 0.5;
    int won = 0, flat_l = 1, flat_r = 1;
    for (unsigned i = 0; i < nf; ++i) {
        const double v1 = x1->x[w->idx[i]];
        w->lt_a[i] = 0.5 * (xk->x[w->idx[i]] + v1);
        w->lt_b[i] = 0.5 * (v1 + w->lt_x2[i]);
        flat_l &= w->lt_a[i] == v1;
        flat_r &= w->lt_b[i] == v1;
    }
    if (cfg->on_ltlm != NULL) {
        const double *pts[3] = {w->lt_x2, w->lt_a, w->lt_b};
        static const rc_ltlm_point kinds[3] = {RC_LTLM_X2, RC_LTLM_A, RC_LTLM_B};
        ltlm_report(cfg, iter, RC_LTLM_X1, 0, 0.0, x1, c1);
        for (unsigned p = 0; p < 3; ++p) {
            w->cand = *x1;
            for (unsigned i = 0; i < nf; ++i)
                w->cand.x[w->idx[i]] = pts[p][i];
            ltlm_report(cfg, iter, kinds[p], 0, 0.0, &w->cand, -1.0);
        }
    }
    *best = *x1;
    *best_cost = c1;
    for (unsigned mi = 1; mi <= M; ++mi) {
        const double nm = rc_lt_map(*chaos_n, r);
        *chaos_n = nm;
        for (unsigned side = 0; side < 2; ++side) {
            if (skip_flat && (side == 0 ? flat_l : flat_r))
                continue;
            rc_model *t = &w->cand;
            *t = *x1;
            for (unsigned i = 0; i < nf; ++i) {
                const double v1 = x1->x[w->idx[i]];
                t->x[w->idx[i]] = side == 0 ? v1 - (v1 - w->lt_a[i]) * nm /* Eq. 16 */
                                            : v1 + (w->lt_x2[i] - w->lt_b[i]) * nm; /* Eq. 17 */
            }
            double c;
            ++*evals;
            const int ok = rc_cost(&c, t, samples, n) == RC_OK;
            if (ok && !method_is_paper(cfg->method))
                c += rc_prior_cost(t, cfg);
            ltlm_report(cfg, iter, side == 0 ? RC_LTLM_XL : RC_LTLM_XR, mi, nm, t, ok ? c : -1.0);
            if (ok && c < *best_cost) { /* Eq. 18 */
                *best_cost = c;
                *best = *t;
                won = 1;
            }
        }
    }
    ltlm_report(cfg, iter, RC_LTLM_CHOSEN, 0, 0.0, best, *best_cost);
    return won;
}

/* Eq. 10 in the variables u = D x: dx (nf, in u) = -(A_s + mu I)^-1 g_s with
 * A_s = D^-1 A D^-1, g_s = D^-1 g (A, g are overwritten). */
static rc_status paper_step(double *dx, rc_solve_work *w, unsigned nf, double mu)
{
    for (unsigned i = 0; i < nf; ++i) {
        for (unsigned k = 0; k < nf; ++k)
            w->A[(size_t)i * nf + k] /= w->D[i] * w->D[k];
        w->A[(size_t)i * nf + i] += mu;
        dx[i] = -w->g[i] / w->D[i];
    }
    return rcu_chol_solve(w->A, dx, nf);
}

static int method_is_paper(rc_method mt)
{
    return mt == RC_METHOD_LM_PAPER || mt == RC_METHOD_LTLM_PAPER || mt == RC_METHOD_LM_PAPER_DEG ||
           mt == RC_METHOD_LTLM_PAPER_DEG;
}

static rc_status solve_paper(rc_model *m, rc_solve_result *res, rc_solve_work *w,
                             const rc_solve_config *cfg, unsigned nf, const rc_sample *samples,
                             size_t n)
{
    const double mu = cfg->mu0 > 0.0 ? cfg->mu0 : 5.0;
    const unsigned max_iter = cfg->max_iter ? cfg->max_iter : 50u;
    const int ltlm = cfg->method == RC_METHOD_LTLM_PAPER || cfg->method == RC_METHOD_LTLM_PAPER_DEG;
    const int deg = cfg->method == RC_METHOD_LM_PAPER_DEG || cfg->method == RC_METHOD_LTLM_PAPER_DEG;
    double cost = 0.0, chaos_n = ltlm ? ltlm_n0(cfg) : 0.0;
    /* raw units, as Eq. 10 is written; the -deg variants count angles in degrees */
    for (unsigned i = 0; i < nf; ++i)
        w->D[i] = deg && rc_param_unit(m, w->idx[i]) == 1 ? 180.0 / 3.14159265358979323846 : 1.0;
    res->exit = RC_EXIT_MAX_ITER;
    for (unsigned it = 0; it < max_iter; ++it) {
        rc_status st = rc_normal_eq(w->A, w->g, &cost, w->jrow, m, w->idx, nf, samples, n);
        ++res->cost_evals;
        if (st != RC_OK) {
            res->exit = RC_EXIT_NONFINITE;
            return RC_OK;
        }
        if (it == 0)
            res->rms_start_mm = rms_of(cost, n);
        if (paper_step(w->dx, w, nf, mu) != RC_OK) { /* Eq. 13 */
            res->exit = RC_EXIT_NONFINITE;
            break;
        }
        apply_step(&w->trial, m, w, nf, w->dx); /* x1 */
        double c2;
        if (ltlm) {
            double c1;
            /* Eq. 14: a new Jacobian at x1, the same fixed mu */
            st = rc_normal_eq(w->A, w->g, &c1, w->jrow, &w->trial, w->idx, nf, samples, n);
            ++res->cost_evals;
            if (st != RC_OK || paper_step(w->lt_x2, w, nf, mu) != RC_OK) {
                *m = w->trial;
                res->iterations = it + 1;
                res->exit = RC_EXIT_NONFINITE;
                return RC_OK;
            }
            for (unsigned i = 0; i < nf; ++i)
                w->lt_x2[i] = w->trial.x[w->idx[i]] + w->lt_x2[i] / w->D[i];
            if (ltlm_segments(&w->best, &c2, m, &w->trial, c1, w, nf, cfg, &chaos_n, it + 1, 0, samples,
                              n, &res->cost_evals))
                ++res->ltlm_wins;
            *m = w->best; /* no acceptance test: x_k is not among the candidates */
        } else {
            *m = w->trial; /* no acceptance test: Eq. 10 as written */
            if (rc_cost(&c2, m, samples, n) != RC_OK) {
                res->iterations = it + 1;
                res->exit = RC_EXIT_NONFINITE;
                return RC_OK;
            }
            ++res->cost_evals;
        }
        res->iterations = it + 1;
        res->rms_final_mm = rms_of(c2, n);
        if (cfg->on_iter)
            cfg->on_iter(cfg->cb_ctx, it + 1, res->rms_final_mm, m);
        double step = 0.0;
        for (unsigned i = 0; i < nf; ++i)
            step += w->dx[i] * w->dx[i];
        if (sqrt(step) < (cfg->tol_step > 0.0 ? cfg->tol_step : 1e-9)) {
            res->exit = RC_EXIT_SMALL_STEP;
            break;
        }
    }
    return RC_OK;
}

/* Robust LM, the subspace: scale the normal equations at the current point
 * (A, w->g unscaled, cost) by D, take the eigen-decomposition (w->ev,
 * V) and keep the directions rc_ident does not call null (rcond > 0: the
 * eigenvalues above rcond * largest; *rank of them) whose Gauss-Newton step
 * is significant: w->c[k] = v_k^T g_s for those, 0 for the others; *gnorm =
 * sum of the kept c^2. */
static rc_status lm_subspace(unsigned *rank_out, double *gnorm_out, rc_solve_work *w, double *A, double *V,
                             unsigned nf, double cost, size_t n, double rcond, double snr_min)
{
    /* scale: A_s = D^-1 A D^-1, g_s = D^-1 g */
    for (unsigned i = 0; i < nf; ++i) {
        w->g[i] /= w->D[i];
        for (unsigned k = 0; k < nf; ++k)
            A[(size_t)i * nf + k] /= w->D[i] * w->D[k];
    }
    rc_status st = rcu_eig_sym(w->ev, V, A, nf, 0);
    if (st == RC_ERR_NUMERIC)
        return st;
    const double lmax = w->ev[0];
    if (!(lmax > 0.0))
        return RC_ERR_RANK;
    unsigned rank = 0;
    double gnorm = 0.0, gn_gain = 0.0;
    for (unsigned k = 0; k < nf; ++k) {
        /* The identifiable subspace is rc_ident's: a direction is null when
         * its relative singular value s_k / s_max is below RC_IDENT_NULL_REL;
         * the eigenvalues of the scaled J^T J are the squared singular
         * values, so in them the cut is lambda_k / lambda_max <
         * RC_IDENT_NULL_REL^2 (1e-12), decided by rc_ident_eig_is_null as
         * rc_ident_classify_eig decides it. rcond > 0 (a caller's own cut,
         * on the eigenvalues) replaces it. */
        if (rcond > 0.0 ? w->ev[k] <= rcond * lmax : rc_ident_eig_is_null(w->ev[k], lmax))
            break;
        ++rank;
        double c = 0.0;
        for (unsigned i = 0; i < nf; ++i)
            c += V[(size_t)i * nf + k] * w->g[i];
        w->c[k] = c;
        gn_gain += c * c / w->ev[k];
    }
    /* Significance: the Gauss-Newton step along v_k is -c/lambda with
     * standard error sigma/sqrt(lambda); below snr_min standard errors the
     * data cannot resolve it from noise, so it is not taken. sigma^2 is
     * the residual the full Gauss-Newton step predicts, per degree of
     * freedom (the current residual would overstate it far from the
     * solution and stop a small data set at its first iteration). */
    const double resid = cost - gn_gain > 1e-12 * cost ? cost - gn_gain : 1e-12 * cost;
    const double sigma2 = n > rank ? resid / (double)(n - rank) : 0.0;
    for (unsigned k = 0; k < rank; ++k) {
        if (snr_min > 0.0 && sigma2 > 0.0 && w->c[k] * w->c[k] < snr_min * snr_min * sigma2 * w->ev[k])
            w->c[k] = 0.0;
        gnorm += w->c[k] * w->c[k];
    }
    *rank_out = rank;
    *gnorm_out = gnorm;
    return RC_OK;
}

/* Robust LM, the damped step in the kept subspace: dx (nf, scaled) =
 * sum_k -c_k / (lambda_k + mu) v_k; returns the predicted cost decrease. */
static double lm_subspace_step(double *dx, const rc_solve_work *w, const double *V, unsigned nf, unsigned rank,
                               double mu)
{
    double pred = 0.0;
    for (unsigned i = 0; i < nf; ++i)
        dx[i] = 0.0;
    for (unsigned k = 0; k < rank; ++k) {
        const double lam = w->ev[k], coef = -w->c[k] / (lam + mu);
        pred += -2.0 * coef * w->c[k] - lam * coef * coef;
        for (unsigned i = 0; i < nf; ++i)
            dx[i] += coef * V[(size_t)i * nf + k];
    }
    return pred;
}

/* With a prior, the directions the data do not see are held only by the
 * prior rows, whose eigenvalues can be 1e-8 of the largest: LM's damping
 * (relative to the largest) all but freezes them, and the cost test ends the
 * iterations long before they reach the posterior mode (the cable
 * attachment shared half and half with a6 instead of staying in the
 * attachment). Undamped Gauss-Newton steps on the whole posterior (it is
 * positive definite) finish them: each accepted only when the MAP cost falls
 * (halved up to RC_MAP_POLISH_HALVINGS times), at most RC_MAP_POLISH_ITER. */
#define RC_MAP_POLISH_ITER 60
#define RC_MAP_POLISH_HALVINGS 12
static void map_polish(rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A, double *V, passbuf tab,
                       const rc_solve_config *cfg, unsigned nf, const rc_sample *samples, size_t n, int have_ne,
                       double cost_at_m)
{
    /* Where the residuals are large, Gauss-Newton lacks their curvature and
     * converges linearly along the prior-held directions, with a rate that
     * the steps show: moving x by t d leaves the next step d' = (1 - (1 -
     * rho) t) d there, rho the rate. The step length that would finish that
     * direction, t' = t / (1 - q) with q = d'.d / d.d (a secant on the
     * step), is tried first (1 to 8 x the step); refused when it does not
     * lower the cost, then the plain step and its halvings. */
    double prev[RC_MAX_PARAMS] = {0}, t_prev = 1.0, pp = 0.0;
    for (unsigned k = 0; k < RC_MAP_POLISH_ITER; ++k) {
        double cost = cost_at_m, gnorm = 0.0, cnew = 0.0;
        unsigned rank = 0;
        if (!(k == 0 && have_ne)) { /* (the LM's last accepted step left them in A, w->g) */
            ++res->cost_evals;
            if (normal_eq_tab(A, w->g, &cost, w->jrow, m, w->idx, nf, samples, tab, n) != RC_OK)
                return;
            rc_prior_normal_eq(A, w->g, &cost, m, w->idx, nf, cfg);
        }
        /* every direction with a positive eigenvalue: the prior determines
         * what the data do not (no null truncation, no significance rule) */
        if (lm_subspace(&rank, &gnorm, w, A, V, nf, cost, n, 1e-300, 0.0) != RC_OK || gnorm == 0.0)
            return;
        /* a step that promises less than the stop rule's decrease ends the
         * polish here (at an optimum it would only be halved to nothing) */
        if (!(lm_subspace_step(w->dx, w, V, nf, rank, 0.0) > 1e-12 * cost))
            return;
        double t = 1.0;
        if (pp > 0.0) {
            double dq = 0.0;
            for (unsigned i = 0; i < nf; ++i)
                dq += w->dx[i] * prev[i];
            const double q = dq / pp, tn = t_prev / (1.0 - q);
            if (q < 1.0 && tn > 1.0)
                t = tn < 8.0 ? tn : 8.0;
        }
        memcpy(prev, w->dx, nf * sizeof prev[0]);
        pp = 0.0;
        for (unsigned i = 0; i < nf; ++i)
            pp += w->dx[i] * w->dx[i];
        int ok = 0;
        if (t > 1.0) {
            for (unsigned i = 0; i < nf; ++i)
                w->dx[i] *= t;
            apply_step(&w->trial, m, w, nf, w->dx);
            ++res->cost_evals;
            if (cost_tab(&cnew, &w->trial, samples, tab, n) == RC_OK) {
                cnew += rc_prior_cost(&w->trial, cfg);
                ok = cnew < cost;
            }
            if (!ok) {
                memcpy(w->dx, prev, nf * sizeof prev[0]);
                t = 1.0;
            }
        }
        /* the near-null directions are rotations of the last frames traded
         * against the attachment: far from linear over tens of mm, so the
         * step is halved until the cost falls */
        for (unsigned h = 0; h < RC_MAP_POLISH_HALVINGS && !ok; ++h) {
            if (h > 0) {
                for (unsigned i = 0; i < nf; ++i)
                    w->dx[i] *= 0.5;
                t *= 0.5;
            }
            apply_step(&w->trial, m, w, nf, w->dx);
            ++res->cost_evals;
            if (cost_tab(&cnew, &w->trial, samples, tab, n) != RC_OK)
                continue;
            cnew += rc_prior_cost(&w->trial, cfg);
            ok = cnew < cost;
        }
        if (!ok)
            return;
        t_prev = t;
        *m = w->trial;
        const double data_cost = cnew - rc_prior_cost(m, cfg);
        res->rms_final_mm = rms_of(data_cost > 0.0 ? data_cost : 0.0, n);
        if (cost - cnew <= 1e-12 * cost)
            return;
    }
}

/* The robust LM's settings, read once from the configuration. */
typedef struct lm_opts {
    unsigned max_iter;
    double tau, tol_step, tol_cost;
    double rcond;   /* 0: rc_ident's rule */
    double snr_min;
    int ltlm;
} lm_opts;

static void lm_opts_from(lm_opts *o, const rc_solve_config *cfg)
{
    o->max_iter = cfg->max_iter ? cfg->max_iter : 100u;
    o->tau = cfg->mu0 > 0.0 ? cfg->mu0 : 1e-3;
    o->tol_step = cfg->tol_step > 0.0 ? cfg->tol_step : 1e-9;
    o->tol_cost = cfg->tol_cost > 0.0 ? cfg->tol_cost : 1e-4;
    o->rcond = cfg->rcond > 0.0 ? cfg->rcond : 0.0;
    o->snr_min = has_prior(cfg) ? 0.0 : cfg->snr_min > 0.0 ? cfg->snr_min : (cfg->snr_min < 0.0 ? 0.0 : 1.0);
    o->ltlm = cfg->method == RC_METHOD_LTLM;
}

/* What the LM loop carries from one iteration to the next. */
typedef struct lm_state {
    unsigned nf;      /* free parameters (w->idx, w->D) */
    unsigned rank;    /* directions stepped in (lm_subspace) */
    double cost, mu, nu, gnorm, chaos_n;
    int have_eig;     /* the decomposition at m is already in w (LTLM kept x1) */
    int have_ne;      /* A, w->g hold the normal equations at m */
} lm_state;

/* Fixed scaling from the starting normal equations A (nf x nf), w->g:
 * D_i = column norm. A column that is zero (a parameter the data cannot move
 * at all) keeps D = 1 and falls in the null space. alpha6 turns the flange
 * about x6 after the last translation: it can never move the cable length,
 * so it is dropped from the free set (A, w->g, w->idx compacted, *nf
 * lowered) and keeps its value exactly. (theta6 also has a zero column while
 * a6 = 0, but becomes identifiable as soon as a6 moves: it stays free, and
 * the eigen-truncation keeps it still while it is null.) */
static rc_status lm_scale(rc_solve_work *w, double *A, unsigned *nf_io)
{
    unsigned nf = *nf_io, keep = 0;
    double dmax = 0.0;
    for (unsigned i = 0; i < nf; ++i) {
        const double a = A[(size_t)i * nf + i];
        if (a > dmax)
            dmax = a;
    }
    /* rc_ident's zero column: squared norm at most RC_IDENT_ZERO_COL^2 of the largest */
    const double zero_col = RC_IDENT_ZERO_COL * RC_IDENT_ZERO_COL * dmax;
    for (unsigned i = 0; i < nf; ++i) {
        if (w->idx[i] != RC_P_ALPHA(RC_NJ - 1) || A[(size_t)i * nf + i] > zero_col)
            w->D[keep++] = (double)i;
    }
    if (keep == 0)
        return RC_ERR_RANK;
    for (unsigned a = 0; a < keep; ++a) {
        const unsigned ia = (unsigned)w->D[a];
        for (unsigned b = 0; b < keep; ++b)
            A[(size_t)a * keep + b] = A[(size_t)ia * nf + (unsigned)w->D[b]];
        w->g[a] = w->g[ia];
        w->idx[a] = w->idx[ia];
    }
    nf = keep;
    for (unsigned i = 0; i < nf; ++i) {
        const double a = A[(size_t)i * nf + i];
        w->D[i] = a > zero_col ? sqrt(a) : 1.0;
    }
    *nf_io = nf;
    return RC_OK;
}

/* The normal equations at the start (A, w->g), the starting RMS and the
 * scaling (lm_scale): s ready for the first iteration. */
static rc_status lm_start(lm_state *s, rc_solve_result *res, rc_solve_work *w, double *A, passbuf tab,
                          const rc_model *m, const lm_opts *o, const rc_solve_config *cfg, const rc_sample *samples,
                          size_t n)
{
    rc_status st = normal_eq_tab(A, w->g, &s->cost, w->jrow, m, w->idx, s->nf, samples, tab, n);
    ++res->cost_evals;
    if (st != RC_OK)
        return st;
    rc_prior_normal_eq(A, w->g, &s->cost, m, w->idx, s->nf, cfg);
    const double prior0 = rc_prior_cost(m, cfg); /* the figures are the data's RMS, without the prior */
    res->rms_start_mm = res->rms_final_mm = rms_of(s->cost - prior0 > 0.0 ? s->cost - prior0 : 0.0, n);
    st = lm_scale(w, A, &s->nf);
    if (st != RC_OK)
        return st;
    s->mu = 0.0;
    s->nu = 2.0;
    s->chaos_n = o->ltlm ? ltlm_n0(cfg) : 0.0;
    s->rank = 0;
    s->gnorm = 0.0;
    s->have_eig = 0;
    /* A trial point is evaluated with its normal equations (one pass gives
     * the cost, the Jacobian and J^T J, the cost to the last bit as
     * cost_tab's: same samples, same order, same sum), so an accepted step
     * leaves in A, w->g the normal equations the next iteration needs and
     * its pass is saved; a rejected one costs the Jacobian for nothing
     * (rare: damping is tuned for acceptance). A and w->g are free during
     * the trials: the step comes from w->ev, w->c and V. */
    s->have_ne = 1;
    return RC_OK;
}

/* Algorithm I on the accepted x1 (w->trial, cost cnew; A, w->g its normal
 * equations): x2 is the robust LM's own next step from x1 (new normal
 * equations, the updated damping, the same truncation), so both segments
 * lie in subspaces the robust LM steps in. w->trial becomes the best point
 * found; its cost is returned. */
static double lm_ltlm(lm_state *s, const rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A, double *V,
                      const lm_opts *o, const rc_solve_config *cfg, double cnew, unsigned it,
                      const rc_sample *samples, size_t n)
{
    const unsigned nf = s->nf;
    double c1 = cnew, cbest;
    if (lm_subspace(&s->rank, &s->gnorm, w, A, V, nf, c1, n, o->rcond, o->snr_min) != RC_OK)
        return cnew;
    if (s->gnorm > 0.0)
        (void)lm_subspace_step(w->lt_x2, w, V, nf, s->rank, s->mu);
    else
        memset(w->lt_x2, 0, nf * sizeof w->lt_x2[0]);
    for (unsigned i = 0; i < nf; ++i)
        w->lt_x2[i] = w->trial.x[w->idx[i]] + w->lt_x2[i] / w->D[i];
    if (ltlm_segments(&w->best, &cbest, m, &w->trial, cnew, w, nf, cfg, &s->chaos_n, it + 1, 1, samples, n,
                      &res->cost_evals)) {
        ++res->ltlm_wins;
        w->trial = w->best;
        return cbest;
    }
    s->have_eig = 1; /* x1 kept: its decomposition serves the next iteration */
    return c1;
}

/* One damped trial step of iteration it from m at damping s->mu: 1 when it
 * was accepted (m moved, the damping lowered), else 0 (the damping raised).
 * *done: the step or the cost change fell below its tolerance (res->exit). */
static int lm_trial(int *done, lm_state *s, rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A,
                    double *V, passbuf tab, const lm_opts *o, const rc_solve_config *cfg, unsigned it,
                    const rc_sample *samples, size_t n)
{
    const unsigned nf = s->nf;
    double xs = 0.0, ds = 0.0;
    const double pred = lm_subspace_step(w->dx, w, V, nf, s->rank, s->mu);
    for (unsigned i = 0; i < nf; ++i) {
        ds += w->dx[i] * w->dx[i];
        xs += (m->x[w->idx[i]] * w->D[i]) * (m->x[w->idx[i]] * w->D[i]);
    }
    apply_step(&w->trial, m, w, nf, w->dx);
    double cnew = 0.0; /* set by normal_eq_tab when it succeeds */
    ++res->cost_evals;
    const rc_status st = normal_eq_tab(A, w->g, &cnew, w->jrow, &w->trial, w->idx, nf, samples, tab, n);
    if (st == RC_OK)
        rc_prior_normal_eq(A, w->g, &cnew, &w->trial, w->idx, nf, cfg);
    const double rho = (st == RC_OK && pred > 0.0) ? (s->cost - cnew) / pred : -1.0;
    if (!(rho > 0.0)) {
        if (sqrt(ds) <= o->tol_step * (sqrt(xs) + o->tol_step)) {
            res->exit = RC_EXIT_SMALL_STEP;
            *done = 1;
            return 0;
        }
        s->mu *= s->nu;
        s->nu *= 2.0;
        return 0;
    }
    const double t = 2.0 * rho - 1.0;
    double f = 1.0 - t * t * t;
    s->mu *= f > 1.0 / 3.0 ? f : 1.0 / 3.0;
    s->nu = 2.0;
    if (o->ltlm)
        cnew = lm_ltlm(s, m, res, w, A, V, o, cfg, cnew, it, samples, n);
    s->have_ne = !o->ltlm; /* LTLM: A is decomposed (x1 kept: have_eig) or m is a candidate */
    const double rel = (s->cost - cnew) / (s->cost + 1e-300);
    *m = w->trial;
    s->cost = cnew;
    if (sqrt(ds) <= o->tol_step * (sqrt(xs) + o->tol_step) || rel < o->tol_cost) {
        res->exit = sqrt(ds) <= o->tol_step * (sqrt(xs) + o->tol_step) ? RC_EXIT_SMALL_STEP : RC_EXIT_SMALL_COST;
        *done = 1;
    }
    return 1;
}

/* The decomposition at m for iteration it (the normal equations first when
 * the last step did not leave them). */
static rc_status lm_decompose(lm_state *s, rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A,
                              double *V, passbuf tab, const lm_opts *o, const rc_solve_config *cfg,
                              const rc_sample *samples, size_t n)
{
    if (!s->have_ne) {
        const rc_status st = normal_eq_tab(A, w->g, &s->cost, w->jrow, m, w->idx, s->nf, samples, tab, n);
        ++res->cost_evals;
        if (st != RC_OK)
            return st;
        rc_prior_normal_eq(A, w->g, &s->cost, m, w->idx, s->nf, cfg);
    }
    return lm_subspace(&s->rank, &s->gnorm, w, A, V, s->nf, s->cost, n, o->rcond, o->snr_min);
}

/* The robust LM / LTLM loop (rc_solve's methods RC_METHOD_LM, _LTLM) from
 * s (lm_start) on m. */
static rc_status lm_loop(lm_state *s, rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A, double *V,
                         passbuf tab, const lm_opts *o, const rc_solve_config *cfg, const rc_sample *samples,
                         size_t n)
{
    res->exit = RC_EXIT_MAX_ITER;
    for (unsigned it = 0; it < o->max_iter; ++it) {
        if (!s->have_eig) {
            const rc_status st = lm_decompose(s, m, res, w, A, V, tab, o, cfg, samples, n);
            if (st != RC_OK)
                return st;
        }
        s->have_eig = s->have_ne = 0;
        const double lmax = w->ev[0];
        res->rank = s->rank;
        res->cond = sqrt(lmax / w->ev[s->rank - 1]);
        if (s->gnorm == 0.0 || sqrt(s->gnorm) <= 1e-14 * (s->cost + 1e-300)) {
            res->exit = RC_EXIT_SMALL_GRAD;
            break;
        }
        if (it == 0)
            s->mu = o->tau * lmax;
        int accepted = 0, done = 0;
        for (unsigned tries = 0; tries < 60 && !accepted && !done; ++tries)
            accepted = lm_trial(&done, s, m, res, w, A, V, tab, o, cfg, it, samples, n);
        res->iterations = it + 1;
        {
            const double data_cost = s->cost - rc_prior_cost(m, cfg);
            res->rms_final_mm = rms_of(data_cost > 0.0 ? data_cost : 0.0, n);
        }
        if (cfg->on_iter)
            cfg->on_iter(cfg->cb_ctx, it + 1, res->rms_final_mm, m);
        if (!accepted && !done) {
            res->exit = RC_EXIT_NO_DESCENT;
            break;
        }
        if (done)
            break;
    }
    return RC_OK;
}

/* rc_solve on w's small fields and the matrices A, V ((nf x nf) each, n_params^2
 * entries of room) and the sample tables t. */
static rc_status solve_core(rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A, double *V, passbuf tab,
                            const rc_solve_config *cfg, const rc_sample *samples, size_t n)
{
    static const rc_solve_config defaults;
    rc_solve_result local;
    RC_ASSERT(m != NULL && w != NULL);
    if (cfg == NULL)
        cfg = &defaults;
    if (res == NULL)
        res = &local;
    memset(res, 0, sizeof *res);
    if (samples == NULL || n == 0 || m == NULL || w == NULL)
        return RC_ERR_ARG;
    if (m->n_params > RC_MAX_PARAMS || m->n_params < RC_N_BASE)
        return RC_ERR_ARG;

    unsigned nf = 0;
    for (unsigned k = 0; k < m->n_params; ++k)
        if (cfg->fixed == NULL || cfg->fixed[k] == 0)
            w->idx[nf++] = (uint16_t)k;
    res->n_free = nf;
    if (nf == 0)
        return RC_ERR_RANK;

    if (method_is_paper(cfg->method)) {
        const rc_status sp = solve_paper(m, res, w, cfg, nf, samples, n);
        rc_model_wrap_angles(m);
        return sp;
    }
    if (cfg->method != RC_METHOD_LM && cfg->method != RC_METHOD_LTLM)
        return RC_ERR_ARG;

    lm_opts o;
    lm_state s;
    lm_opts_from(&o, cfg);
    s.nf = nf;
    rc_status st = lm_start(&s, res, w, A, tab, m, &o, cfg, samples, n);
    if (st == RC_OK)
        st = lm_loop(&s, m, res, w, A, V, tab, &o, cfg, samples, n);
    if (st != RC_OK)
        return st;
    if (has_prior(cfg))
        map_polish(m, res, w, A, V, tab, cfg, s.nf, samples, n, s.have_ne, s.cost);
    rc_model_wrap_angles(m);
    return RC_OK;
}

/* solve_core after filling the sample tables sin_q, cos_q ((n x 6) each, or
 * both NULL: none); jblk (NE_BLOCK x n_params) or NULL. */
static rc_status solve_with(rc_model *m, rc_solve_result *res, rc_solve_work *w, double *A, double *V,
                            double *sin_q, double *cos_q, double *jblk, const rc_solve_config *cfg,
                            const rc_sample *samples, size_t n)
{
    passbuf tab = {NULL, NULL, jblk};
    if (sin_q != NULL && cos_q != NULL) {
        rc_qtrig_fill(sin_q, cos_q, samples, n);
        tab.sin_q = sin_q;
        tab.cos_q = cos_q;
    }
    return solve_core(m, res, w, A, V, tab, cfg, samples, n);
}

void rc_solve_config_warm(rc_solve_config *cfg)
{
    RC_ASSERT(cfg != NULL);
    if (!(cfg->mu0 > 0.0) && (cfg->method == RC_METHOD_LM || cfg->method == RC_METHOD_LTLM) && has_prior(cfg))
        cfg->mu0 = RC_SOLVE_MU0_WARM;
}

rc_status rc_solve(rc_model *m, rc_solve_result *res, rc_solve_work *w, const rc_solve_config *cfg,
                   const rc_sample *samples, size_t n)
{
    RC_ASSERT(m != NULL && w != NULL);
    double *sin_q = NULL, *cos_q = NULL, *jblk = NULL;
    /* In the unused tails of A and V (beyond n_params^2 entries), when they
     * fit: the row blocks and sin_q in A's, cos_q in V's. (n_params out of
     * range: solve_core refuses it.) */
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
