/* SPDX-License-Identifier: MIT */
/* rch_poses_length.c - the length criterion of rch_poses_plan
 * (RCH_POSES_LENGTH, one outlet): D-optimal on the cable lengths, log
 * det(X^T X) over the directions lib/rc_ident calls identifiable, a greedy
 * start and Fedorov exchange passes, reported by the observability index O1
 * (rch_ident) of the plan beside N random candidates.
 * Depends on: lib/rc_ident, rc_rand, rc_meas; rch_ident; LAPACKE (dpotrf).
 * Memory: heap for the candidates and the design, freed before return.
 * Errors: -1 with d set (limits, unreachable length range, out of memory). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <lapacke.h>

#include "rc_ident.h"
#include "rc_rand.h"
#include "rch_ident.h"
#include "rch_poses_int.h"

/* Cholesky of the r x r matrix A (row-major) into L (LAPACK; the lower
 * triangle and the diagonal are read); log det or -inf. */
static double chol(double *L, const double *A, unsigned r)
{
    double ld = 0;
    memcpy(L, A, (size_t)r * r * sizeof *L);
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'L', (lapack_int)r, L, (lapack_int)r) != 0)
        return -INFINITY;
    for (unsigned i = 0; i < r; ++i)
        ld += 2.0 * log(L[i * r + i]);
    return ld;
}

/* x^T A^-1 x with A = L L^T: |L^-1 x|^2. tmp: (r). */
static double quad(const double *L, const double *x, double *tmp, unsigned r)
{
    double q = 0;
    for (unsigned i = 0; i < r; ++i) {
        double s = x[i];
        for (unsigned k = 0; k < i; ++k)
            s -= L[i * r + k] * tmp[k];
        tmp[i] = s / L[i * r + i];
        q += tmp[i] * tmp[i];
    }
    return q;
}

static double observability(const rc_model *m, const rc_sample *c, const size_t *idx, size_t n, unsigned *rank)
{
    rc_sample *s = malloc((n ? n : 1) * sizeof *s);
    rch_ident *id = calloc(1, sizeof *id);
    double o = -1;
    if (s && id) {
        for (size_t i = 0; i < n; ++i)
            s[i] = c[idx[i]];
        if (rch_ident_compute(id, m, s, n) == 0) {
            o = id->observability;
            *rank = id->rank;
        }
    }
    free(s);
    free(id);
    return o;
}

typedef struct plan_work {
    size_t n, n_cand;
    unsigned P, r;
    rc_sample *cand;       /* (n_cand) */
    double *G;             /* (n_cand x P) Jacobian rows */
    double *scale;         /* (P) column norms of the candidates' Jacobian (rc_ident_scale) */
    double *X, *A, *L, *tmp;
    size_t *design, *rnd;  /* (n) */
    unsigned char *in_design; /* (n_cand) */
} plan_work;

static void work_free(plan_work *w)
{
    free(w->cand);
    free(w->G);
    free(w->scale);
    free(w->X);
    free(w->A);
    free(w->L);
    free(w->tmp);
    free(w->design);
    free(w->rnd);
    free(w->in_design);
}

/* 1-2: candidates inside the limits and the length range, with their rows */
static int draw_candidates(plan_work *w, rch_poses_result *res, const rc_model *m, const rch_poses_config *c,
                           rch_diag *d)
{
    size_t got = 0, tries = 0;
    const double mg = c->margin_deg * PI_ / 180.0;
    rc_rng g;
    rc_rng_seed(&g, c->seed);
    while (got < w->n_cand) {
        rc_sample s;
        double len;
        if (++tries > 1000 * w->n_cand) {
            char why[256];
            rch_poses_dropped_str(why, sizeof why, res);
            rch_diag_set(d, "", 0, 0, "only %zu of %zu candidate poses have a cable length within [%g, %g] mm and "
                         "are safe for the cable and the cell (dropped: %s); check --encoder, the length range and "
                         "--clearance-mm", got, w->n_cand, c->len_min_mm, c->len_max_mm, why);
            return -1;
        }
        memset(&s, 0, sizeof s);
        for (int j = 0; j < RC_NJ; ++j) {
            double lo = m->q_min_rad[j] + mg, hi = m->q_max_rad[j] - mg;
            double q = lo + (hi - lo) * rc_rng_u01(&g);
            double qr = round(q * 180.0 / PI_ * 100.0) / 100.0 * PI_ / 180.0; /* 0.01 deg */
            if (qr < lo || qr > hi) /* rounding left the range: move one step back in */
                qr = (qr < lo ? ceil(q * 180.0 / PI_ * 100.0) : floor(q * 180.0 / PI_ * 100.0)) / 100.0 * PI_ / 180.0;
            s.q_rad[j] = qr;
        }
        if (rc_meas(&len, w->G + got * w->P, m, &s) != RC_OK || !(len >= c->len_min_mm && len <= c->len_max_mm))
            continue;
        if (!rch_poses_safe(res, m, c, &s, 0))
            continue;
        w->cand[got++] = s;
    }
    return 0;
}

/* 3: the identifiable subspace (rc_ident, the one definition): the
 * candidates' information matrix G^T G, scaled by its column norms, split
 * into directions; the rank directions that are not null span what the data
 * can identify. X (n_cand x r) = the scaled rows in those directions, times
 * sqrt(n_cand) so that a column's RMS over the candidates is its singular
 * value over sqrt(n_cand) (the ridge of the greedy start stays small). */
static int ident_subspace(plan_work *w, rch_diag *d)
{
    const unsigned P = w->P;
    double *AtA = calloc((size_t)P * P, sizeof *AtA), *V = malloc((size_t)P * P * sizeof *V);
    double *work = malloc(rc_ident_work_size(P) * sizeof *work), *diag = malloc(P * sizeof *diag);
    rc_ident *id = calloc(1, sizeof *id);
    int rc = -1;
    if (!AtA || !V || !work || !diag || !id) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto out;
    }
    for (size_t i = 0; i < w->n_cand; ++i) {
        const double *g = w->G + i * P;
        for (unsigned j = 0; j < P; ++j)
            for (unsigned k = 0; k <= j; ++k)
                AtA[j * P + k] += g[j] * g[k];
    }
    for (unsigned j = 0; j < P; ++j)
        for (unsigned k = 0; k < j; ++k)
            AtA[k * P + j] = AtA[j * P + k];
    if (rc_ident_normal(id, V, work, AtA, P, w->n_cand) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "the identifiability analysis of the candidates failed");
        goto out;
    }
    rc_ident_scale(w->scale, AtA, P, (size_t)P + 1);
    w->r = id->rank;
    w->X = calloc((w->n_cand ? w->n_cand : 1) * (w->r ? w->r : 1), sizeof *w->X);
    if (!w->X) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto out;
    }
    for (unsigned j = 0; j < P; ++j)
        diag[j] = w->scale[j] > 0 ? sqrt((double)w->n_cand) / w->scale[j] : 0.0;
    for (size_t i = 0; i < w->n_cand; ++i)
        for (unsigned j = 0; j < P; ++j) {
            const double gj = w->G[i * P + j] * diag[j];
            if (gj != 0.0)
                for (unsigned k = 0; k < w->r; ++k)
                    w->X[i * w->r + k] += gj * V[j * P + k];
        }
    rc = 0;
out:
    free(AtA);
    free(V);
    free(work);
    free(diag);
    free(id);
    return rc;
}

/* The candidate outside the design with the largest x^T A^-1 x (A = L L^T
 * in w->L): its index (none_idx when there is none) and *bq that value (-1). */
static size_t best_candidate(plan_work *w, size_t none_idx, double *bq)
{
    const unsigned r = w->r;
    size_t best = none_idx;
    *bq = -1;
    for (size_t i = 0; i < w->n_cand; ++i) {
        double q;
        if (w->in_design[i])
            continue;
        q = quad(w->L, w->X + i * r, w->tmp, r);
        if (q > *bq) {
            *bq = q;
            best = i;
        }
    }
    return best;
}

/* 4a: greedy D-optimal start (a tiny ridge keeps A invertible early on) */
static void greedy(plan_work *w, FILE *progress)
{
    const unsigned r = w->r;
    const double ridge = 1e-6;
    for (unsigned k = 0; k < r; ++k)
        w->A[k * r + k] = ridge;
    for (size_t t = 0; t < w->n; ++t) {
        double bq;
        size_t best;
        chol(w->L, w->A, r);
        best = best_candidate(w, 0, &bq);
        w->design[t] = best;
        w->in_design[best] = 1;
        rch_poses_add_outer(w->A, w->X + best * r, 1.0, r);
        rch_poses_progress(progress, "greedy design, pose", t, w->n);
    }
}

/* 4b: one exchange pass; the number of swaps */
static unsigned exchange(plan_work *w)
{
    const unsigned r = w->r;
    unsigned swaps = 0;
    for (size_t t = 0; t < w->n; ++t) {
        double ld_now = chol(w->L, w->A, r), ld_minus;
        size_t best;
        double bq;
        rch_poses_add_outer(w->A, w->X + w->design[t] * r, -1.0, r);
        ld_minus = chol(w->L, w->A, r);
        if (!isfinite(ld_minus)) {
            rch_poses_add_outer(w->A, w->X + w->design[t] * r, 1.0, r);
            continue;
        }
        best = best_candidate(w, w->n_cand, &bq);
        /* det(A- + x x^T) = det(A-) (1 + x^T A-^-1 x) */
        if (best < w->n_cand && ld_minus + log1p(bq) > ld_now + 1e-9) {
            w->in_design[w->design[t]] = 0;
            w->design[t] = best;
            w->in_design[best] = 1;
            ++swaps;
        }
        rch_poses_add_outer(w->A, w->X + w->design[t] * r, 1.0, r);
    }
    return swaps;
}

int rch_poses_plan_length(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                          rch_diag *d)
{
    plan_work w;
    int rc = -1;
    memset(res, 0, sizeof *res);
    memset(&w, 0, sizeof w);
    if (rch_poses_check_config(m, c, &w.n_cand, d) != 0)
        return -1;
    w.n = c->count;
    w.P = m->n_params;
    w.cand = malloc(w.n_cand * sizeof *w.cand);
    w.G = malloc(w.n_cand * w.P * sizeof *w.G);
    w.scale = calloc(w.P, sizeof *w.scale);
    w.design = malloc(w.n * sizeof *w.design);
    w.rnd = malloc(w.n * sizeof *w.rnd);
    w.in_design = calloc(w.n_cand, 1);
    if (!w.cand || !w.G || !w.scale || !w.design || !w.rnd || !w.in_design) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    if (rch_poses_plan_cost(c, progress, w.n, w.n_cand, w.P < 20u ? w.P : 20u, 1, d) != 0)
        goto done;
    if (draw_candidates(&w, res, m, c, d) != 0)
        goto done;
    if (ident_subspace(&w, d) != 0)
        goto done;
    w.A = calloc((size_t)w.r * w.r, sizeof *w.A);
    w.L = calloc((size_t)w.r * w.r, sizeof *w.L);
    w.tmp = malloc((w.r ? w.r : 1) * sizeof *w.tmp);
    if (!w.A || !w.L || !w.tmp) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    greedy(&w, w.n >= 200 ? progress : NULL);
    for (unsigned long pass = 0; pass < c->passes; ++pass) {
        if (progress && w.n >= 200)
            fprintf(progress, "rcal poses: exchange pass %lu/%lu\n", pass + 1, c->passes);
        if (!exchange(&w))
            break;
    }
    /* O1 of the plan and of a random plan of the same size */
    {
        rc_rng g2;
        rc_rng_seed(&g2, c->seed ^ 0x9E3779B97F4A7C15ull);
        memset(w.in_design, 0, w.n_cand);
        for (size_t t = 0; t < w.n; ++t) { /* n distinct random candidates */
            size_t i;
            do
                i = rc_rng_below(&g2, (uint32_t)w.n_cand);
            while (w.in_design[i]);
            w.in_design[i] = 1;
            w.rnd[t] = i;
        }
        res->o1_plan = observability(m, w.cand, w.design, w.n, &res->rank_plan);
        res->o1_random = observability(m, w.cand, w.rnd, w.n, &res->rank_random);
    }
    res->poses = malloc((w.n ? w.n : 1) * sizeof *res->poses);
    if (!res->poses) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    for (size_t t = 0; t < w.n; ++t)
        res->poses[t] = w.cand[w.design[t]];
    res->n = w.n;
    res->n_candidates = w.n_cand;
    res->n_ident = w.r;
    res->n_params = w.P;
    res->n_outlets = 1;
    res->n_distinct = w.n;
    res->rows_per_outlet[0] = w.n;
    rc = 0;
done:
    work_free(&w);
    return rc;
}
