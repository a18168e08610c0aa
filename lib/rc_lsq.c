/* SPDX-License-Identifier: MIT */
/* rc_lsq.c - the problem's passes (cost, normal equations, the prior block)
 * and the solver on them: LM, LTLM and the paper's variants (rc_problem.h).
 * Knows nothing of robots: rows come from the blocks' callbacks. */
#include "rc_problem.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "rc_ident.h"
#include "rc_linalg.h"
#include "rc_rand.h"

size_t rc_problem_rows(const rc_problem *p)
{
    size_t n = 0;
    RC_ASSERT(p != NULL);
    for (unsigned b = 0; b < p->n_blocks; ++b)
        n += p->blocks[b].n * p->blocks[b].dim;
    return n;
}

static rc_status prepare(const rc_problem *p, const double *x)
{
    return p->prepare != NULL ? p->prepare(p->prepare_ctx, x) : RC_OK;
}

rc_status rc_problem_cost(double *cost, const rc_problem *p, const double *x)
{
    double sum = 0.0;
    RC_ASSERT(cost != NULL && p != NULL && x != NULL);
    rc_status st = prepare(p, x);
    if (st != RC_OK)
        return st;
    for (unsigned b = 0; b < p->n_blocks; ++b) {
        const rc_block *bl = &p->blocks[b];
        RC_ASSERT(bl->dim >= 1 && bl->dim <= RC_MAX_BLOCK_DIM);
        for (size_t i = 0; i < bl->n; ++i) {
            double r[RC_MAX_BLOCK_DIM];
            st = bl->rows(r, NULL, bl->ctx, bl->first + i);
            if (st != RC_OK)
                return st;
            for (unsigned d = 0; d < bl->dim; ++d)
                sum += r[d] * r[d];
        }
    }
    *cost = sum;
    return isfinite(sum) ? RC_OK : RC_ERR_NUMERIC;
}

static int has_prior(const rc_problem *p)
{
    return p->prior.mean != NULL && p->prior.sd != NULL && p->prior.noise > 0.0;
}

/* The weight (noise / sd)^2 of parameter k's prior row, 0 when it has none. */
static double prior_weight(const rc_problem *p, unsigned k)
{
    if (!has_prior(p))
        return 0.0;
    const double sd = p->prior.sd[k];
    if (!(sd > 0.0) || !isfinite(sd))
        return 0.0;
    const double r = p->prior.noise / sd;
    return r * r;
}

double rc_problem_prior_cost(const rc_problem *p, const double *x)
{
    double c = 0.0;
    RC_ASSERT(p != NULL && x != NULL);
    if (!has_prior(p))
        return 0.0;
    for (unsigned k = 0; k < p->n_params; ++k) {
        if (p->fixed != NULL && p->fixed[k] != 0)
            continue;
        const double w = prior_weight(p, k), r = x[k] - p->prior.mean[k];
        if (w > 0.0)
            c += w * r * r;
    }
    return c;
}

void rc_problem_prior_normal_eq(double *A, double *g, double *cost, const rc_problem *p, const double *x,
                                const uint16_t *idx, unsigned nf)
{
    RC_ASSERT(p != NULL);
    if (!has_prior(p))
        return;
    /* the rows s_k (x_k - mean_k), s_k = noise / sd_k, of a diagonal
     * Jacobian: J^T J = s_k^2 on the diagonal, J^T r = s_k^2 (x_k - mean_k) */
    for (unsigned i = 0; i < nf; ++i) {
        const unsigned k = idx[i];
        const double w = prior_weight(p, k), r = x[k] - p->prior.mean[k];
        if (w == 0.0)
            continue;
        A[(size_t)i * nf + i] += w;
        g[i] += w * r;
        *cost += w * r * r;
    }
}

/* Rows per block of the normal-equation update: A += Jb^T Jb with NE_BLOCK
 * rows at a time reads and writes A once per block instead of once per row.
 * The rows are added one after the other (left to right), so the sums are
 * those of the row-by-row update to the last bit. */
#define NE_BLOCK 4

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

/* One row r with its Jacobian row jr (n_params) into the normal equations:
 * row by row (jblk NULL) or into the row block (*nb rows held). */
static void add_row(double *A, double *g, double *jblk, double *rb, unsigned *nb, double r, const double *jr,
                    const uint16_t *idx, unsigned nf)
{
    if (jblk == NULL) {
        for (unsigned i = 0; i < nf; ++i) {
            const double ji = jr[idx[i]];
            if (ji == 0.0)
                continue;
            g[i] += ji * r;
            double *Ai = &A[(size_t)i * nf];
            for (unsigned k = i; k < nf; ++k)
                Ai[k] += ji * jr[idx[k]];
        }
        return;
    }
    double *row = jblk + (size_t)*nb * nf;
    for (unsigned i = 0; i < nf; ++i)
        row[i] = jr[idx[i]];
    rb[*nb] = r;
    if (++*nb == NE_BLOCK) {
        rank_block_update(A, g, jblk, jblk + nf, jblk + 2 * nf, jblk + 3 * nf, rb, nf);
        *nb = 0;
    }
}

rc_status rc_problem_normal_eq(double *A, double *g, double *cost, double *jrow, double *jblk, const rc_problem *p,
                               const double *x, const uint16_t *idx, unsigned nf)
{
    double sum = 0.0, rb[NE_BLOCK];
    unsigned nb = 0;
    RC_ASSERT(A != NULL && g != NULL && cost != NULL && jrow != NULL && p != NULL && x != NULL && idx != NULL);
    rc_status st = prepare(p, x);
    if (st != RC_OK)
        return st;
    memset(A, 0, (size_t)nf * nf * sizeof A[0]);
    memset(g, 0, nf * sizeof g[0]);
    for (unsigned b = 0; b < p->n_blocks; ++b) {
        const rc_block *bl = &p->blocks[b];
        RC_ASSERT(bl->dim >= 1 && bl->dim <= RC_MAX_BLOCK_DIM);
        for (size_t it = 0; it < bl->n; ++it) {
            double r[RC_MAX_BLOCK_DIM];
            st = bl->rows(r, jrow, bl->ctx, bl->first + it);
            if (st != RC_OK)
                return st;
            for (unsigned d = 0; d < bl->dim; ++d) {
                sum += r[d] * r[d];
                add_row(A, g, jblk, rb, &nb, r[d], jrow + (size_t)d * p->n_params, idx, nf);
            }
        }
    }
    if (nb > 0) { /* the last rows, padded with zero rows (they add nothing) */
        for (unsigned k = nb; k < NE_BLOCK; ++k) {
            rb[k] = 0.0;
            memset(jblk + (size_t)k * nf, 0, nf * sizeof jblk[0]);
        }
        rank_block_update(A, g, jblk, jblk + nf, jblk + 2 * nf, jblk + 3 * nf, rb, nf);
    }
    for (unsigned i = 0; i < nf; ++i)
        for (unsigned k = 0; k < i; ++k)
            A[(size_t)i * nf + k] = A[(size_t)k * nf + i];
    *cost = sum;
    return isfinite(sum) ? RC_OK : RC_ERR_NUMERIC;
}

/* What one solve carries besides the workspace: the problem, its rows, the
 * matrices and the options. */
typedef struct lsq {
    const rc_problem *p;
    const rc_solve_opts *cfg;
    rc_lsq_work *w;
    double *A, *V, *jblk;
    size_t n;      /* data rows */
    unsigned np;   /* parameters */
} lsq;

static rc_status ne_at(const lsq *L, double *cost, const double *x, unsigned nf)
{
    return rc_problem_normal_eq(L->A, L->w->g, cost, L->w->jrow, L->jblk, L->p, x, L->w->idx, nf);
}

/* trial = base + D^-1 * dx on the free parameters. */
static void apply_step(double *trial, const double *base, const lsq *L, unsigned nf, const double *dx)
{
    memcpy(trial, base, L->np * sizeof trial[0]);
    for (unsigned i = 0; i < nf; ++i)
        trial[L->w->idx[i]] += dx[i] / L->w->D[i];
}

static double rms_of(double cost, size_t n) { return sqrt(cost / (double)n); }

static void ltlm_report(const lsq *L, unsigned iter, rc_ltlm_point kind, unsigned mi, double n_m, const double *x,
                        double cost)
{
    rc_lsq_event ev;
    if (L->p->on_ltlm == NULL)
        return;
    ev.iter = iter;
    ev.kind = kind;
    ev.m = mi;
    ev.n_m = n_m;
    ev.x = x;
    ev.cost = cost;
    L->p->on_ltlm(L->p->cb_ctx, &ev);
}

/* N_0 of the scalar chaotic sequence: the caller's, or drawn from the seed. */
static double ltlm_n0(const rc_solve_opts *cfg)
{
    rc_rng g;
    if (cfg->chaos_n0 > 0.0 && cfg->chaos_n0 < 1.0)
        return cfg->chaos_n0;
    rc_rng_seed(&g, cfg->seed ^ 0x4C544C4Dull);
    return 0.05 + 0.9 * rc_rng_u01(&g);
}

static int method_is_paper(rc_method mt)
{
    const rc_method_desc *d = rc_method_describe((unsigned)mt);
    return d != NULL && d->paper;
}

/* Algorithm I steps 9-15. In: x_k (xk), x1 with its cost c1, x2 on the free
 * parameters (w->lt_x2, nf), the sequence state *chaos_n (N_{m-1}).
 * Forms a and b (w->lt_a, w->lt_b), continues the sequence by M values and
 * evaluates xl(m) = x1 - (x1 - a) N_m and xr(m) = x1 + (x2 - b) N_m in the
 * order xl(1), xr(1), xl(2), ...; best (cost *best_cost) = the strict
 * minimum of {x1, xl, xr} (ties keep the earlier point). skip_flat: do not
 * evaluate a segment of zero length (its candidates all equal x1).
 * Returns 1 when a candidate beat x1. */
static int ltlm_segments(double *best, double *best_cost, const double *xk, const double *x1, double c1,
                         const lsq *L, unsigned nf, double *chaos_n, unsigned iter, int skip_flat, unsigned *evals)
{
    rc_lsq_work *w = L->w;
    const rc_solve_opts *cfg = L->cfg;
    const unsigned M = cfg->n_candidates ? cfg->n_candidates : 10u;
    const double r = cfg->chaos_r > 0.0 ? cfg->chaos_r : 0.5;
    int won = 0, flat_l = 1, flat_r = 1;
    for (unsigned i = 0; i < nf; ++i) {
        const double v1 = x1[w->idx[i]];
        w->lt_a[i] = 0.5 * (xk[w->idx[i]] + v1);
        w->lt_b[i] = 0.5 * (v1 + w->lt_x2[i]);
        flat_l &= w->lt_a[i] == v1;
        flat_r &= w->lt_b[i] == v1;
    }
    if (L->p->on_ltlm != NULL) {
        const double *pts[3] = {w->lt_x2, w->lt_a, w->lt_b};
        static const rc_ltlm_point kinds[3] = {RC_LTLM_X2, RC_LTLM_A, RC_LTLM_B};
        ltlm_report(L, iter, RC_LTLM_X1, 0, 0.0, x1, c1);
        for (unsigned q = 0; q < 3; ++q) {
            memcpy(w->cand, x1, L->np * sizeof w->cand[0]);
            for (unsigned i = 0; i < nf; ++i)
                w->cand[w->idx[i]] = pts[q][i];
            ltlm_report(L, iter, kinds[q], 0, 0.0, w->cand, -1.0);
        }
    }
    memcpy(best, x1, L->np * sizeof best[0]);
    *best_cost = c1;
    for (unsigned mi = 1; mi <= M; ++mi) {
        const double nm = rc_lt_map(*chaos_n, r);
        *chaos_n = nm;
        for (unsigned side = 0; side < 2; ++side) {
            if (skip_flat && (side == 0 ? flat_l : flat_r))
                continue;
            double *t = w->cand;
            memcpy(t, x1, L->np * sizeof t[0]);
            for (unsigned i = 0; i < nf; ++i) {
                const double v1 = x1[w->idx[i]];
                t[w->idx[i]] = side == 0 ? v1 - (v1 - w->lt_a[i]) * nm /* Eq. 16 */
                                         : v1 + (w->lt_x2[i] - w->lt_b[i]) * nm; /* Eq. 17 */
            }
            double c;
            ++*evals;
            const int ok = rc_problem_cost(&c, L->p, t) == RC_OK;
            if (ok && !method_is_paper(cfg->method))
                c += rc_problem_prior_cost(L->p, t);
            ltlm_report(L, iter, side == 0 ? RC_LTLM_XL : RC_LTLM_XR, mi, nm, t, ok ? c : -1.0);
            if (ok && c < *best_cost) { /* Eq. 18 */
                *best_cost = c;
                memcpy(best, t, L->np * sizeof best[0]);
                won = 1;
            }
        }
    }
    ltlm_report(L, iter, RC_LTLM_CHOSEN, 0, 0.0, best, *best_cost);
    return won;
}

/* Eq. 10 in the variables u = D x: dx (nf, in u) = -(A_s + mu I)^-1 g_s with
 * A_s = D^-1 A D^-1, g_s = D^-1 g (A, g are overwritten). */
static rc_status paper_step(double *dx, const lsq *L, unsigned nf, double mu)
{
    rc_lsq_work *w = L->w;
    for (unsigned i = 0; i < nf; ++i) {
        for (unsigned k = 0; k < nf; ++k)
            L->A[(size_t)i * nf + k] /= w->D[i] * w->D[k];
        L->A[(size_t)i * nf + i] += mu;
        dx[i] = -w->g[i] / w->D[i];
    }
    return rcu_chol_solve(L->A, dx, nf);
}

static rc_status solve_paper(double *x, rc_solve_result *res, const lsq *L, unsigned nf)
{
    rc_lsq_work *w = L->w;
    const rc_solve_opts *cfg = L->cfg;
    const rc_method_desc *md = rc_method_describe((unsigned)cfg->method);
    const double mu = cfg->mu0 > 0.0 ? cfg->mu0 : 5.0;
    const unsigned max_iter = cfg->max_iter ? cfg->max_iter : 50u;
    const int ltlm = md->ltlm, deg = md->deg;
    const size_t n = L->n;
    double cost = 0.0, chaos_n = ltlm ? ltlm_n0(cfg) : 0.0;
    /* raw units, as Eq. 10 is written; the -deg variants count angles in degrees */
    for (unsigned i = 0; i < nf; ++i)
        w->D[i] = deg && L->p->unit != NULL && L->p->unit[w->idx[i]] == 1 ? 180.0 / 3.14159265358979323846 : 1.0;
    res->exit = RC_EXIT_MAX_ITER;
    for (unsigned it = 0; it < max_iter; ++it) {
        rc_status st = ne_at(L, &cost, x, nf);
        ++res->cost_evals;
        if (st != RC_OK) {
            res->exit = RC_EXIT_NONFINITE;
            return RC_OK;
        }
        if (it == 0)
            res->rms_start_mm = rms_of(cost, n);
        if (paper_step(w->dx, L, nf, mu) != RC_OK) { /* Eq. 13 */
            res->exit = RC_EXIT_NONFINITE;
            break;
        }
        apply_step(w->trial, x, L, nf, w->dx); /* x1 */
        double c2;
        if (ltlm) {
            double c1;
            /* Eq. 14: a new Jacobian at x1, the same fixed mu */
            st = ne_at(L, &c1, w->trial, nf);
            ++res->cost_evals;
            if (st != RC_OK || paper_step(w->lt_x2, L, nf, mu) != RC_OK) {
                memcpy(x, w->trial, L->np * sizeof x[0]);
                res->iterations = it + 1;
                res->exit = RC_EXIT_NONFINITE;
                return RC_OK;
            }
            for (unsigned i = 0; i < nf; ++i)
                w->lt_x2[i] = w->trial[w->idx[i]] + w->lt_x2[i] / w->D[i];
            if (ltlm_segments(w->best, &c2, x, w->trial, c1, L, nf, &chaos_n, it + 1, 0, &res->cost_evals))
                ++res->ltlm_wins;
            memcpy(x, w->best, L->np * sizeof x[0]); /* no acceptance test: x_k is not among the candidates */
        } else {
            memcpy(x, w->trial, L->np * sizeof x[0]); /* no acceptance test: Eq. 10 as written */
            if (rc_problem_cost(&c2, L->p, x) != RC_OK) {
                res->iterations = it + 1;
                res->exit = RC_EXIT_NONFINITE;
                return RC_OK;
            }
            ++res->cost_evals;
        }
        res->iterations = it + 1;
        res->rms_final_mm = rms_of(c2, n);
        if (L->p->on_iter)
            L->p->on_iter(L->p->cb_ctx, it + 1, res->rms_final_mm, x);
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
static rc_status lm_subspace(unsigned *rank_out, double *gnorm_out, const lsq *L, unsigned nf, double cost,
                             double rcond, double snr_min)
{
    rc_lsq_work *w = L->w;
    double *A = L->A, *V = L->V;
    const size_t n = L->n;
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
static double lm_subspace_step(double *dx, const rc_lsq_work *w, const double *V, unsigned nf, unsigned rank,
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

/* The cost of trial with the prior's (the polish's and the candidates' test). */
static int map_cost(double *c, const lsq *L, const double *x)
{
    if (rc_problem_cost(c, L->p, x) != RC_OK)
        return 0;
    *c += rc_problem_prior_cost(L->p, x);
    return 1;
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
static void map_polish(double *x, rc_solve_result *res, const lsq *L, unsigned nf, int have_ne, double cost_at_m)
{
    rc_lsq_work *w = L->w;
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
            if (ne_at(L, &cost, x, nf) != RC_OK)
                return;
            rc_problem_prior_normal_eq(L->A, w->g, &cost, L->p, x, w->idx, nf);
        }
        /* every direction with a positive eigenvalue: the prior determines
         * what the data do not (no null truncation, no significance rule) */
        if (lm_subspace(&rank, &gnorm, L, nf, cost, 1e-300, 0.0) != RC_OK || gnorm == 0.0)
            return;
        /* a step that promises less than the stop rule's decrease ends the
         * polish here (at an optimum it would only be halved to nothing) */
        if (!(lm_subspace_step(w->dx, w, L->V, nf, rank, 0.0) > 1e-12 * cost))
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
            apply_step(w->trial, x, L, nf, w->dx);
            ++res->cost_evals;
            ok = map_cost(&cnew, L, w->trial) && cnew < cost;
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
            apply_step(w->trial, x, L, nf, w->dx);
            ++res->cost_evals;
            ok = map_cost(&cnew, L, w->trial) && cnew < cost;
        }
        if (!ok)
            return;
        t_prev = t;
        memcpy(x, w->trial, L->np * sizeof x[0]);
        const double data_cost = cnew - rc_problem_prior_cost(L->p, x);
        res->rms_final_mm = rms_of(data_cost > 0.0 ? data_cost : 0.0, L->n);
        if (cost - cnew <= 1e-12 * cost)
            return;
    }
}

/* The robust LM's settings, read once from the options. */
typedef struct lm_opts {
    unsigned max_iter;
    double tau, tol_step, tol_cost;
    double rcond;   /* 0: rc_ident's rule */
    double snr_min;
    int ltlm;
} lm_opts;

static void lm_opts_from(lm_opts *o, const rc_solve_opts *cfg, int prior)
{
    o->max_iter = cfg->max_iter ? cfg->max_iter : 100u;
    o->tau = cfg->mu0 > 0.0 ? cfg->mu0 : 1e-3;
    o->tol_step = cfg->tol_step > 0.0 ? cfg->tol_step : 1e-9;
    o->tol_cost = cfg->tol_cost > 0.0 ? cfg->tol_cost : 1e-4;
    o->rcond = cfg->rcond > 0.0 ? cfg->rcond : 0.0;
    o->snr_min = prior ? 0.0 : cfg->snr_min > 0.0 ? cfg->snr_min : (cfg->snr_min < 0.0 ? 0.0 : 1.0);
    o->ltlm = cfg->method == RC_METHOD_LTLM;
}

/* What the LM loop carries from one iteration to the next. */
typedef struct lm_state {
    unsigned nf;      /* free parameters (w->idx, w->D) */
    unsigned rank;    /* directions stepped in (lm_subspace) */
    double cost, mu, nu, gnorm, chaos_n;
    int have_eig;     /* the decomposition at x is already in w (LTLM kept x1) */
    int have_ne;      /* A, w->g hold the normal equations at x */
} lm_state;

/* Fixed scaling from the starting normal equations A (nf x nf), w->g:
 * D_i = column norm. A column that is zero (a parameter the data cannot move
 * at all) keeps D = 1 and falls in the null space. A parameter the problem
 * marks inert (it can never move a row while its column is zero: a robot's
 * alpha6 turns the flange about x6 after the last translation) is dropped
 * from the free set when its column is zero (A, w->g, w->idx compacted,
 * *nf lowered) and keeps its value exactly. Other zero columns stay free
 * (a robot's theta6 while a6 = 0 becomes identifiable as soon as a6 moves),
 * and the eigen-truncation keeps them still while they are null. */
static rc_status lm_scale(const lsq *L, unsigned *nf_io)
{
    rc_lsq_work *w = L->w;
    double *A = L->A;
    unsigned nf = *nf_io, keep = 0;
    uint16_t kept[RC_MAX_PARAMS];
    double dmax = 0.0;
    for (unsigned i = 0; i < nf; ++i) {
        const double a = A[(size_t)i * nf + i];
        if (a > dmax)
            dmax = a;
    }
    /* rc_ident's zero column: squared norm at most RC_IDENT_ZERO_COL^2 of the largest */
    const double zero_col = RC_IDENT_ZERO_COL * RC_IDENT_ZERO_COL * dmax;
    for (unsigned i = 0; i < nf; ++i) {
        const int inert = L->p->inert != NULL && L->p->inert[w->idx[i]] != 0;
        if (!inert || A[(size_t)i * nf + i] > zero_col)
            kept[keep++] = (uint16_t)i;
    }
    if (keep == 0)
        return RC_ERR_RANK;
    for (unsigned a = 0; a < keep; ++a) {
        const unsigned ia = kept[a];
        for (unsigned b = 0; b < keep; ++b)
            A[(size_t)a * keep + b] = A[(size_t)ia * nf + kept[b]];
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
static rc_status lm_start(lm_state *s, rc_solve_result *res, const lsq *L, const double *x, const lm_opts *o)
{
    rc_lsq_work *w = L->w;
    rc_status st = ne_at(L, &s->cost, x, s->nf);
    ++res->cost_evals;
    if (st != RC_OK)
        return st;
    rc_problem_prior_normal_eq(L->A, w->g, &s->cost, L->p, x, w->idx, s->nf);
    const double prior0 = rc_problem_prior_cost(L->p, x); /* the figures are the data's RMS, without the prior */
    res->rms_start_mm = res->rms_final_mm = rms_of(s->cost - prior0 > 0.0 ? s->cost - prior0 : 0.0, L->n);
    st = lm_scale(L, &s->nf);
    if (st != RC_OK)
        return st;
    s->mu = 0.0;
    s->nu = 2.0;
    s->chaos_n = o->ltlm ? ltlm_n0(L->cfg) : 0.0;
    s->rank = 0;
    s->gnorm = 0.0;
    s->have_eig = 0;
    /* A trial point is evaluated with its normal equations (one pass gives
     * the cost, the Jacobian and J^T J, the cost to the last bit as
     * rc_problem_cost's: same rows, same order, same sum), so an accepted
     * step leaves in A, w->g the normal equations the next iteration needs
     * and its pass is saved; a rejected one costs the Jacobian for nothing
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
static double lm_ltlm(lm_state *s, const double *x, rc_solve_result *res, const lsq *L, const lm_opts *o,
                      double cnew, unsigned it)
{
    rc_lsq_work *w = L->w;
    const unsigned nf = s->nf;
    double c1 = cnew, cbest;
    if (lm_subspace(&s->rank, &s->gnorm, L, nf, c1, o->rcond, o->snr_min) != RC_OK)
        return cnew;
    if (s->gnorm > 0.0)
        (void)lm_subspace_step(w->lt_x2, w, L->V, nf, s->rank, s->mu);
    else
        memset(w->lt_x2, 0, nf * sizeof w->lt_x2[0]);
    for (unsigned i = 0; i < nf; ++i)
        w->lt_x2[i] = w->trial[w->idx[i]] + w->lt_x2[i] / w->D[i];
    if (ltlm_segments(w->best, &cbest, x, w->trial, cnew, L, nf, &s->chaos_n, it + 1, 1, &res->cost_evals)) {
        ++res->ltlm_wins;
        memcpy(w->trial, w->best, L->np * sizeof w->trial[0]);
        return cbest;
    }
    s->have_eig = 1; /* x1 kept: its decomposition serves the next iteration */
    return c1;
}

/* One damped trial step of iteration it from x at damping s->mu: 1 when it
 * was accepted (x moved, the damping lowered), else 0 (the damping raised).
 * *done: the step or the cost change fell below its tolerance (res->exit). */
static int lm_trial(int *done, lm_state *s, double *x, rc_solve_result *res, const lsq *L, const lm_opts *o,
                    unsigned it)
{
    rc_lsq_work *w = L->w;
    const unsigned nf = s->nf;
    double xs = 0.0, ds = 0.0;
    const double pred = lm_subspace_step(w->dx, w, L->V, nf, s->rank, s->mu);
    for (unsigned i = 0; i < nf; ++i) {
        ds += w->dx[i] * w->dx[i];
        xs += (x[w->idx[i]] * w->D[i]) * (x[w->idx[i]] * w->D[i]);
    }
    apply_step(w->trial, x, L, nf, w->dx);
    double cnew = 0.0; /* set by the pass when it succeeds */
    ++res->cost_evals;
    const rc_status st = ne_at(L, &cnew, w->trial, nf);
    if (st == RC_OK)
        rc_problem_prior_normal_eq(L->A, w->g, &cnew, L->p, w->trial, w->idx, nf);
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
        cnew = lm_ltlm(s, x, res, L, o, cnew, it);
    s->have_ne = !o->ltlm; /* LTLM: A is decomposed (x1 kept: have_eig) or x is a candidate */
    const double rel = (s->cost - cnew) / (s->cost + 1e-300);
    memcpy(x, w->trial, L->np * sizeof x[0]);
    s->cost = cnew;
    if (sqrt(ds) <= o->tol_step * (sqrt(xs) + o->tol_step) || rel < o->tol_cost) {
        res->exit = sqrt(ds) <= o->tol_step * (sqrt(xs) + o->tol_step) ? RC_EXIT_SMALL_STEP : RC_EXIT_SMALL_COST;
        *done = 1;
    }
    return 1;
}

/* The decomposition at x for iteration it (the normal equations first when
 * the last step did not leave them). */
static rc_status lm_decompose(lm_state *s, const double *x, rc_solve_result *res, const lsq *L, const lm_opts *o)
{
    if (!s->have_ne) {
        const rc_status st = ne_at(L, &s->cost, x, s->nf);
        ++res->cost_evals;
        if (st != RC_OK)
            return st;
        rc_problem_prior_normal_eq(L->A, L->w->g, &s->cost, L->p, x, L->w->idx, s->nf);
    }
    return lm_subspace(&s->rank, &s->gnorm, L, s->nf, s->cost, o->rcond, o->snr_min);
}

/* The robust LM / LTLM loop (methods RC_METHOD_LM, _LTLM) from s (lm_start)
 * on x. */
static rc_status lm_loop(lm_state *s, double *x, rc_solve_result *res, const lsq *L, const lm_opts *o)
{
    rc_lsq_work *w = L->w;
    res->exit = RC_EXIT_MAX_ITER;
    for (unsigned it = 0; it < o->max_iter; ++it) {
        if (!s->have_eig) {
            const rc_status st = lm_decompose(s, x, res, L, o);
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
            accepted = lm_trial(&done, s, x, res, L, o, it);
        res->iterations = it + 1;
        {
            const double data_cost = s->cost - rc_problem_prior_cost(L->p, x);
            res->rms_final_mm = rms_of(data_cost > 0.0 ? data_cost : 0.0, L->n);
        }
        if (L->p->on_iter)
            L->p->on_iter(L->p->cb_ctx, it + 1, res->rms_final_mm, x);
        if (!accepted && !done) {
            res->exit = RC_EXIT_NO_DESCENT;
            break;
        }
        if (done)
            break;
    }
    return RC_OK;
}

rc_status rc_problem_solve_in(double *x, rc_solve_result *res, rc_lsq_work *w, double *A, double *V, double *jblk,
                              const rc_solve_opts *opts, const rc_problem *p)
{
    static const rc_solve_opts defaults;
    rc_solve_result local;
    RC_ASSERT(x != NULL && w != NULL && A != NULL && V != NULL && p != NULL);
    if (opts == NULL)
        opts = &defaults;
    if (res == NULL)
        res = &local;
    memset(res, 0, sizeof *res);
    const lsq L = {p, opts, w, A, V, jblk, rc_problem_rows(p), p->n_params};
    if (L.n == 0 || p->n_params == 0 || p->n_params > RC_MAX_PARAMS)
        return RC_ERR_ARG;
    unsigned nf = 0;
    for (unsigned k = 0; k < p->n_params; ++k)
        if (p->fixed == NULL || p->fixed[k] == 0)
            w->idx[nf++] = (uint16_t)k;
    res->n_free = nf;
    if (nf == 0)
        return RC_ERR_RANK;
    if (method_is_paper(opts->method))
        return solve_paper(x, res, &L, nf);
    if (opts->method != RC_METHOD_LM && opts->method != RC_METHOD_LTLM)
        return RC_ERR_ARG;
    lm_opts o;
    lm_state s;
    lm_opts_from(&o, opts, has_prior(p));
    s.nf = nf;
    rc_status st = lm_start(&s, res, &L, x, &o);
    if (st == RC_OK)
        st = lm_loop(&s, x, res, &L, &o);
    if (st != RC_OK)
        return st;
    if (has_prior(p))
        map_polish(x, res, &L, s.nf, s.have_ne, s.cost);
    return RC_OK;
}

size_t rc_problem_work_size(unsigned n_params)
{
    if (n_params == 0 || n_params > RC_MAX_PARAMS)
        return 0;
    const size_t np = n_params;
    return sizeof(rc_lsq_work) + (2 * np * np + NE_BLOCK * np) * sizeof(double);
}

rc_status rc_problem_solve(double *x, rc_solve_result *res, void *work, size_t work_bytes, const rc_solve_opts *opts,
                           const rc_problem *p)
{
    RC_ASSERT(x != NULL && work != NULL && p != NULL);
    const size_t need = rc_problem_work_size(p->n_params);
    if (need == 0 || (uintptr_t)work % sizeof(double) != 0)
        return RC_ERR_ARG;
    if (work_bytes < need)
        return RC_ERR_CAPACITY;
    const size_t np = p->n_params;
    rc_lsq_work *w = (rc_lsq_work *)work;
    double *A = (double *)(w + 1), *V = A + np * np, *jblk = V + np * np;
    return rc_problem_solve_in(x, res, w, A, V, jblk, opts, p);
}
