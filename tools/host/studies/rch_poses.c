/* SPDX-License-Identifier: MIT */
/* rch_poses.c - D-optimal pose planning (see rch_poses.h). Moved from
 * tools/cmd_poses.c; the identifiable part now comes from lib/rc_ident. */
#include "rch_poses.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <lapacke.h>

#include "rc_rand.h"
#include "rc_ident.h"
#include "rch_cost.h"
#include "rch_ident.h"
#include "rch_stats.h"
#include "rch_uncert.h"

#define PI_ 3.14159265358979323846

void rch_poses_estimate(double *first_s, double *all_s, size_t n, size_t n_cand, unsigned nf, unsigned long passes,
                        int length_criterion)
{
    const double phase = (double)n * (double)n_cand * (double)nf * (double)nf * (length_criterion ? 0.3e-9 : 0.8e-9);
    const double fixed = length_criterion ? 20e-6 * (double)n_cand : 0.0;
    *first_s = fixed + phase * (passes ? 2.0 : 1.0);
    *all_s = fixed + phase * (1.0 + (double)passes);
}

/* The estimate printed (over 10 s) and checked against the limit before the
 * work starts: 0, or -1 with d set (above --max-minutes). */
static int plan_cost(const rch_poses_config *c, FILE *progress, size_t n, size_t n_cand, unsigned nf, int length,
                     rch_diag *d)
{
    double first, all;
    char a[32], b[32];
    const double lim_min = c->max_minutes > 0.0 ? c->max_minutes : 60.0;
    rch_poses_estimate(&first, &all, n, n_cand, nf, c->passes, length);
    if (all > 60.0 * lim_min) {
        rch_diag_set(d, "", 0, 0,
                     "a plan of %zu poses from %zu candidates with %lu exchange passes would take about %s (at most %s): "
                     "above the limit of %g min; lower --count, --candidates or --passes, or raise --max-minutes",
                     n, n_cand, c->passes, rch_cost_human(a, sizeof a, first), rch_cost_human(b, sizeof b, all),
                     lim_min);
        return -1;
    }
    if (progress && all > 10.0)
        fprintf(progress, "rcal poses: %zu poses from %zu candidates: about %s with one exchange pass, at most %s "
                          "with all %lu\n",
                n, n_cand, rch_cost_human(a, sizeof a, first), rch_cost_human(b, sizeof b, all), c->passes);
    return 0;
}

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

static void add_outer(double *A, const double *x, double w, unsigned r)
{
    for (unsigned i = 0; i < r; ++i)
        for (unsigned j = 0; j < r; ++j)
            A[i * r + j] += w * x[i] * x[j];
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
static int draw_candidates(plan_work *w, const rc_model *m, const rch_poses_config *c, rch_diag *d)
{
    size_t got = 0, tries = 0;
    const double mg = c->margin_deg * PI_ / 180.0;
    rc_rng g;
    rc_rng_seed(&g, c->seed);
    while (got < w->n_cand) {
        rc_sample s;
        double len;
        if (++tries > 1000 * w->n_cand) {
            rch_diag_set(d, "", 0, 0, "only %zu of %zu candidate poses have a cable length within [%g, %g] mm; "
                         "check --encoder and the length range", got, w->n_cand, c->len_min_mm, c->len_max_mm);
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

static void progress_line(FILE *f, const char *what, size_t k, size_t n)
{
    if (f && n >= 10 && (k + 1) % (n / 10) == 0) {
        fprintf(f, "rcal poses: %s %zu/%zu\n", what, k + 1, n);
        fflush(f);
    }
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
        add_outer(w->A, w->X + best * r, 1.0, r);
        progress_line(progress, "greedy design, pose", t, w->n);
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
        add_outer(w->A, w->X + w->design[t] * r, -1.0, r);
        ld_minus = chol(w->L, w->A, r);
        if (!isfinite(ld_minus)) {
            add_outer(w->A, w->X + w->design[t] * r, 1.0, r);
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
        add_outer(w->A, w->X + w->design[t] * r, 1.0, r);
    }
    return swaps;
}

static int check_config(const rc_model *m, const rch_poses_config *c, size_t *n_cand, rch_diag *d)
{
    if (c->count < 1 || c->count > RCH_POSES_MAX_COUNT) {
        rch_diag_set(d, "", 0, 0, "--count %zu: a plan has 1..%u poses (the cost grows as poses x candidates x "
                     "passes: rcal poses says its estimate before it starts)", c->count, RCH_POSES_MAX_COUNT);
        return -1;
    }
    *n_cand = c->candidates ? c->candidates : (c->count * 40 > 2000 ? c->count * 40 : 2000);
    if (*n_cand < c->count || *n_cand > RCH_POSES_MAX_CANDIDATES) {
        rch_diag_set(d, "", 0, 0, "--candidates %zu: must be between --count (%zu) and %u", *n_cand, c->count,
                     RCH_POSES_MAX_CANDIDATES);
        return -1;
    }
    if (!(c->len_min_mm < c->len_max_mm) || !(c->margin_deg >= 0)) {
        rch_diag_set(d, "", 0, 0, "need --len-min-mm < --len-max-mm and --margin-deg >= 0");
        return -1;
    }
    for (int j = 0; j < RC_NJ; ++j) {
        const double mg = c->margin_deg * PI_ / 180.0;
        if (!(m->q_min_rad[j] + mg < m->q_max_rad[j] - mg)) {
            rch_diag_set(d, "", 0, 0, "--margin-deg %g leaves no room inside joint %d's limits [%.2f, %.2f] deg",
                         c->margin_deg, j + 1, m->q_min_rad[j] * 180.0 / PI_, m->q_max_rad[j] * 180.0 / PI_);
            return -1;
        }
    }
    return 0;
}

static int plan_length(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                       rch_diag *d)
{
    plan_work w;
    int rc = -1;
    memset(res, 0, sizeof *res);
    memset(&w, 0, sizeof w);
    if (check_config(m, c, &w.n_cand, d) != 0)
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
    if (plan_cost(c, progress, w.n, w.n_cand, w.P < 20u ? w.P : 20u, 1, d) != 0)
        goto done;
    if (draw_candidates(&w, m, c, d) != 0)
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

/* ---- the position criterion (issue 20) ----------------------------------- */

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
    return 0;
}

typedef struct pos_work {
    rc_model m, mp;           /* the planning model; the point model (m with the tool, or m) */
    unsigned K, nf, rows_per; /* outlets; free parameters; rows per candidate (K, or 1 with split) */
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
    w->rows_per = c->split ? 1u : w->K;
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

/* One pose's scaled rows: row j (nf) for outlet j; len (K) the lengths.
 * 0, or -1 when a length cannot be computed. */
static int pose_rows(double *rows, double *len, const pos_work *w, const rc_sample *q)
{
    double g[RC_MAX_PARAMS];
    for (unsigned k = 0; k < w->K; ++k) {
        rc_sample s = *q;
        s.outlet = (uint8_t)k;
        if (rc_meas(&len[k], g, &w->m, &s) != RC_OK)
            return -1;
        for (unsigned j = 0; rows && j < w->nf; ++j)
            rows[k * w->nf + j] = g[w->fi[j]] * w->sc[j] / w->noise;
    }
    return 0;
}

/* 1-2: candidate poses inside the limits whose lengths are in range: every
 * outlet's (all poses from every outlet), or one candidate per reaching
 * outlet (split). */
static int pos_candidates(pos_work *w, const rch_poses_config *c, rch_diag *d)
{
    const unsigned nf = w->nf, K = w->K;
    const double mg = c->margin_deg * PI_ / 180.0;
    size_t tries = 0, cap = w->n_pose * (c->split ? K : 1u);
    if (K == 0 || nf == 0 || cap == 0) {
        rch_diag_set(d, "", 0, 0, "no outlet, parameter or pose to plan");
        return -1;
    }
    double *rows = malloc((size_t)K * nf * sizeof *rows), len[RC_MAX_OUTLETS];
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
            free(rows);
            rch_diag_set(d, "", 0, 0, "only %zu of %zu candidate poses have a cable length within [%g, %g] mm from "
                         "%s; check --outlet/--encoder and the length range", got, w->n_pose, c->len_min_mm,
                         c->len_max_mm, c->split ? "any outlet" : "every outlet");
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
        if (pose_rows(rows, len, w, &s) != 0)
            continue;
        unsigned reach = 0;
        for (unsigned k = 0; k < K; ++k)
            reach += len[k] >= c->len_min_mm && len[k] <= c->len_max_mm;
        if (c->split ? reach == 0 : reach < K)
            continue;
        for (unsigned k = 0; k < K; ++k) {
            if (!(len[k] >= c->len_min_mm && len[k] <= c->len_max_mm))
                continue;
            if (!c->split) {
                memcpy(w->X + w->n_cand * w->rows_per * nf, rows, (size_t)K * nf * sizeof *rows);
                w->cand_pose[w->n_cand] = got;
                w->cand_outlet[w->n_cand++] = 0;
                break;
            }
            memcpy(w->X + w->n_cand * nf, rows + (size_t)k * nf, nf * sizeof *rows);
            w->cand_pose[w->n_cand] = got;
            w->cand_outlet[w->n_cand++] = (uint8_t)k;
        }
        w->pose[got++] = s;
    }
    free(rows);
    return 0;
}

/* C = M^-1 (M symmetric positive definite, nf x nf; either storage). 0 or -1. */
static int spd_inverse(double *C, const double *M, unsigned nf)
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

/* C = M^-1 and B = C Q C. 0 or -1. */
static int pos_refresh(pos_work *w)
{
    const unsigned nf = w->nf;
    if (spd_inverse(w->C, w->M, nf) != 0)
        return -1;
    for (unsigned i = 0; i < nf; ++i) /* T = Q C */
        for (unsigned j = 0; j < nf; ++j) {
            double s = 0.0;
            for (unsigned k = 0; k < nf; ++k)
                s += w->Q[(size_t)i * nf + k] * w->C[(size_t)k * nf + j];
            w->T[(size_t)i * nf + j] = s;
        }
    for (unsigned i = 0; i < nf; ++i) /* B = C T */
        for (unsigned j = 0; j < nf; ++j) {
            double s = 0.0;
            for (unsigned k = 0; k < nf; ++k)
                s += w->C[(size_t)i * nf + k] * w->T[(size_t)k * nf + j];
            w->B[(size_t)i * nf + j] = s;
        }
    return 0;
}

static void add_rows(double *M, const double *X, unsigned r, unsigned nf, double sign)
{
    for (unsigned j = 0; j < r; ++j)
        add_outer(M, X + (size_t)j * nf, sign, nf);
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
        if (!pos_available(w, i) || (w->rows_per == 1 && w->K > 1 && w->cand_outlet[i] != t % w->K))
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

/* The prior in scaled coordinates: the identity. */
static void prior_info(double *M, unsigned nf)
{
    memset(M, 0, (size_t)nf * nf * sizeof *M);
    for (unsigned k = 0; k < nf; ++k)
        M[(size_t)k * nf + k] = 1.0;
}

/* Q = mean over n workspace poses (uniform in the joint limits, seed) of
 * Jps^T Jps, Jps the point's sensitivity to the scaled free parameters. */
static void workspace_q(double *Q, const pos_work *w, size_t n, unsigned long long seed)
{
    const unsigned nf = w->nf;
    rc_rng g;
    rc_rng_seed(&g, seed);
    memset(Q, 0, (size_t)nf * nf * sizeof *Q);
    for (size_t t = 0; t < n; ++t) {
        double q[RC_NJ], Jp[3][RC_MAX_PARAMS], J[3][RC_MAX_PARAMS];
        for (int j = 0; j < RC_NJ; ++j)
            q[j] = w->m.q_min_rad[j] + (w->m.q_max_rad[j] - w->m.q_min_rad[j]) * rc_rng_u01(&g);
        rch_uncert_point_sens(Jp, &w->mp, q);
        for (int i = 0; i < 3; ++i)
            for (unsigned a = 0; a < nf; ++a)
                J[i][a] = Jp[i][w->fi[a]] * w->sc[a];
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = 0; b < nf; ++b)
                Q[(size_t)a * nf + b] += (J[0][a] * J[0][b] + J[1][a] * J[1][b] + J[2][a] * J[2][b]) / (double)n;
    }
}

/* The predicted accuracy of the design whose information is M: the 95 %
 * radius at n_eval workspace poses (their own seed). */
static int pos_accuracy(rch_poses_accuracy *acc, const pos_work *w, const double *M, size_t n_eval,
                        unsigned long long seed)
{
    const unsigned nf = w->nf;
    double *C = malloc((size_t)nf * nf * sizeof *C), *r = malloc((n_eval ? n_eval : 1) * sizeof *r);
    int rc = -1;
    memset(acc, 0, sizeof *acc);
    if (!C || !r || spd_inverse(C, M, nf) != 0)
        goto out;
    rc_rng g;
    rc_rng_seed(&g, seed);
    double phi = 0.0;
    for (size_t t = 0; t < n_eval; ++t) {
        double q[RC_NJ], Jp[3][RC_MAX_PARAMS], J[3][RC_MAX_PARAMS], P[9];
        for (int j = 0; j < RC_NJ; ++j)
            q[j] = w->m.q_min_rad[j] + (w->m.q_max_rad[j] - w->m.q_min_rad[j]) * rc_rng_u01(&g);
        rch_uncert_point_sens(Jp, &w->mp, q);
        for (int i = 0; i < 3; ++i)
            for (unsigned a = 0; a < nf; ++a)
                J[i][a] = Jp[i][w->fi[a]] * w->sc[a];
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
    prior_info(w->M, w->nf);
    for (size_t t = 0; t < w->n; ++t) {
        double bg;
        if (pos_refresh(w) != 0)
            return -1;
        const size_t best = pos_best(w, w->n_cand, &bg, t);
        if (best >= w->n_cand)
            return -1;
        pos_take(w, t, best, 1);
        progress_line(w->n >= 200 ? progress : NULL, "greedy design, pose", t, w->n);
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
    prior_info(M, w->nf);
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
            if (w->rows_per == 1 && w->K > 1 && w->cand_outlet[i] != k)
                continue;
            rc_sample s = w->pose[w->cand_pose[i]];
            s.outlet = (uint8_t)k;
            res->poses[res->n++] = s;
            res->rows_per_outlet[k]++;
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
    return 0;
}

static int plan_position(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                         rch_diag *d)
{
    pos_work *w = calloc(1, sizeof *w);
    int rc = -1;
    size_t n_pose = 0;
    if (!w) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    if (check_config(m, c, &n_pose, d) != 0 || check_position(c, d) != 0 || pos_setup(w, m, c, d) != 0)
        goto done;
    w->n = c->count;
    w->n_pose = n_pose;
    if (plan_cost(c, progress, w->n, w->n_pose * w->K, w->nf, 0, d) != 0)
        goto done;
    if (pos_candidates(w, c, d) != 0)
        goto done;
    if (w->n_cand < w->n) {
        rch_diag_set(d, "", 0, 0, "only %zu candidates for %zu poses: raise --candidates", w->n_cand, w->n);
        goto done;
    }
    if (pos_alloc(w) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    workspace_q(w->Q, w, c->n_work ? c->n_work : 300, c->seed ^ SEED_WORK);
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
            while ((used[w->cand_pose[i]] || (w->rows_per == 1 && w->K > 1 && w->cand_outlet[i] != t % w->K)) &&
                   ++guard < 1000000u);
            used[w->cand_pose[i]] = 1;
            w->rnd[t] = i;
        }
        free(used);
    }
    const size_t n_eval = c->n_eval ? c->n_eval : 1000;
    design_info(w->M, w, w->design, w->n);
    if (pos_accuracy(&res->plan, w, w->M, n_eval, c->seed ^ SEED_EVAL) != 0)
        goto numeric;
    design_info(w->M, w, w->rnd, w->n);
    if (pos_accuracy(&res->random, w, w->M, n_eval, c->seed ^ SEED_EVAL) != 0)
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
                        rs[nr++].outlet = (uint8_t)(w->rows_per == 1 ? w->cand_outlet[idx[t]] : j);
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

int rch_poses_plan(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                   rch_diag *d)
{
    memset(res, 0, sizeof *res);
    if (c->criterion == RCH_POSES_LENGTH) {
        if (c->n_outlets > 1 || c->split) {
            rch_diag_set(d, "", 0, 0, "--criterion length plans for one outlet; several outlets need --criterion "
                                      "position");
            return -1;
        }
        if (c->n_outlets == 1) {
            rc_model one = *m;
            memcpy(&one.x[RC_P_ENC], c->outlet_mm[0], 3 * sizeof(double));
            return plan_length(res, &one, c, progress, d);
        }
        return plan_length(res, m, c, progress, d);
    }
    return plan_position(res, m, c, progress, d);
}

int rch_poses_predict(rch_poses_accuracy *acc, const rc_model *m, const rch_poses_config *c, const rc_sample *rows,
                      size_t n, rch_diag *d)
{
    pos_work *w = calloc(1, sizeof *w);
    double *M = NULL, *X = NULL, len[RC_MAX_OUTLETS];
    int rc = -1;
    if (!w) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    if (check_position(c, d) != 0 || pos_setup(w, m, c, d) != 0)
        goto out;
    M = malloc((size_t)w->nf * w->nf * sizeof *M);
    X = malloc((size_t)w->K * w->nf * sizeof *X);
    if (!M || !X) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto out;
    }
    prior_info(M, w->nf);
    for (size_t i = 0; i < n; ++i) {
        if (rows[i].outlet >= w->K) {
            rch_diag_set(d, "", 0, 0, "row %zu: outlet %u, but %u outlet(s) given", i, rows[i].outlet, w->K);
            goto out;
        }
        if (pose_rows(X, len, w, &rows[i]) != 0) {
            rch_diag_set(d, "", 0, 0, "row %zu: the cable length cannot be computed (the point is at an outlet)", i);
            goto out;
        }
        add_outer(M, X + (size_t)rows[i].outlet * w->nf, 1.0, w->nf);
    }
    if (pos_accuracy(acc, w, M, c->n_eval ? c->n_eval : 1000, c->seed ^ SEED_EVAL) != 0) {
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

/* One combination's figure: a greedy plan (no exchange) for those places. */
static int combo_eval(rch_poses_combo *cb, const rc_model *m, const rch_poses_config *c, const double (*cand)[3],
                      unsigned k, rch_diag *d)
{
    rch_poses_config cc = *c;
    rch_poses_result r;
    double pos[RC_MAX_OUTLETS][3];
    memset(&r, 0, sizeof r);
    cc.n_outlets = k;
    cc.passes = 0;
    cb->k = k;
    if (k < 2)
        cc.split = 0;
    for (unsigned j = 0; j < k; ++j) {
        memcpy(cc.outlet_mm[j], cand[cb->idx[j]], sizeof cc.outlet_mm[j]);
        memcpy(pos[j], cand[cb->idx[j]], sizeof pos[j]);
    }
    cb->span = rch_prior_outlet_span(NULL, (const double(*)[3])pos, k);
    if (plan_position(&r, m, &cc, NULL, d) != 0)
        return -1;
    cb->acc = r.plan;
    rch_poses_free(&r);
    return 0;
}

static int better(const rch_poses_accuracy *a, const rch_poses_accuracy *b)
{
    return a->median_mm < b->median_mm || (a->median_mm == b->median_mm && a->p95_mm < b->p95_mm);
}

/* The number of k-combinations of n, saturated at limit + 1. */
static size_t n_choose(unsigned n, unsigned k, size_t limit)
{
    double c = 1.0;
    for (unsigned i = 0; i < k; ++i)
        c = c * (double)(n - i) / (double)(i + 1);
    return c > (double)limit ? limit + 1 : (size_t)(c + 0.5);
}

int rch_poses_choose_outlets(rch_poses_choice *out, const rc_model *m, const rch_poses_config *c,
                             const double (*cand_mm)[3], unsigned n, unsigned k, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    out->k = k;
    out->n_cand = n;
    if (k < 1 || k > n || k > RC_MAX_OUTLETS || n > RCH_POSES_MAX_CANDIDATE_PLACES) {
        rch_diag_set(d, "", 0, 0, "--choose-outlets %u of %u --candidate places: need 1 <= K <= the candidates "
                     "(at most %u) and K <= %d", k, n, RCH_POSES_MAX_CANDIDATE_PLACES, RC_MAX_OUTLETS);
        return -1;
    }
    out->exhaustive = n_choose(n, k, RCH_POSES_MAX_COMBOS) <= RCH_POSES_MAX_COMBOS;
    if (out->exhaustive) {
        unsigned idx[RC_MAX_OUTLETS];
        for (unsigned j = 0; j < k; ++j)
            idx[j] = j;
        for (;;) {
            rch_poses_combo *cb = &out->combos[out->n_combos];
            memcpy(cb->idx, idx, sizeof idx);
            if (combo_eval(cb, m, c, cand_mm, k, d) != 0)
                return -1;
            if (out->n_combos == 0 || better(&cb->acc, &out->combos[out->best].acc))
                out->best = out->n_combos;
            out->n_combos++;
            int j = (int)k - 1; /* next combination in lexicographic order */
            while (j >= 0 && idx[j] == n - k + (unsigned)j)
                --j;
            if (j < 0)
                break;
            idx[j]++;
            for (unsigned l = (unsigned)j + 1; l < k; ++l)
                idx[l] = idx[l - 1] + 1;
        }
        return 0;
    }
    unsigned chosen[RC_MAX_OUTLETS] = {0};
    for (unsigned size = 1; size <= k; ++size) { /* greedy: add the place that helps most */
        size_t best = (size_t)-1;
        for (unsigned p = 0; p < n; ++p) {
            int taken = 0;
            for (unsigned j = 0; j + 1 < size; ++j)
                taken |= chosen[j] == p;
            if (taken)
                continue;
            rch_poses_combo *cb = &out->combos[out->n_combos];
            memcpy(cb->idx, chosen, sizeof chosen);
            cb->idx[size - 1] = p;
            if (combo_eval(cb, m, c, cand_mm, size, d) != 0)
                return -1;
            if (best == (size_t)-1 || better(&cb->acc, &out->combos[best].acc))
                best = out->n_combos;
            out->n_combos++;
        }
        chosen[size - 1] = out->combos[best].idx[size - 1];
        out->best = best;
    }
    return 0;
}

/* ---- the plan as a RAPID module ----------------------------------------- */

int rch_poses_write_rapid(FILE *f, const rc_sample *rows, const unsigned char *outlet_label, size_t n,
                          double settle_s, const char *comment)
{
    unsigned char seen[256] = {0};
    unsigned n_out = 0;
    for (size_t i = 0; i < n; ++i) {
        const unsigned o = outlet_label ? outlet_label[i] : 0u;
        if (!seen[o]) { /* a flag, not a count: 256 poses of one outlet must not wrap it */
            seen[o] = 1;
            ++n_out;
        }
    }
    fprintf(f, "MODULE rcal_plan\n");
    if (comment)
        fprintf(f, "    ! %s\n", comment);
    fprintf(f, "    ! %zu poses; at each: MoveAbsJ (fine), a message on the pendant, WaitTime %.3g s while rcal "
               "acquire reads the cable length\n", n, settle_s);
    for (size_t i = 0; i < n; ++i) {
        fprintf(f, "    CONST jointtarget rcal_p%zu:=[[", i);
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(f, "%s%.4f", j ? "," : "", rows[i].q_rad[j] * 180.0 / PI_);
        fprintf(f, "],[9E9,9E9,9E9,9E9,9E9,9E9]];\n");
    }
    fprintf(f, "    CONST num rcal_settle_s:=%.3g;\n\n", settle_s);
    for (unsigned o = 0; o < 256; ++o) {
        if (!seen[o])
            continue;
        fprintf(f, "    PROC rcal_outlet%u()\n", o);
        for (size_t i = 0; i < n; ++i) {
            if ((outlet_label ? outlet_label[i] : 0u) != o)
                continue;
            fprintf(f, "        MoveAbsJ rcal_p%zu\\NoEOffs, v100, fine, tool0;\n", i);
            fprintf(f, "        TPWrite \"rcal pose %zu outlet %u\";\n", i, o);
            fprintf(f, "        WaitTime rcal_settle_s;\n");
        }
        fprintf(f, "    ENDPROC\n\n");
    }
    fprintf(f, "    PROC main()\n");
    if (n_out <= 1) {
        for (unsigned o = 0; o < 256; ++o)
            if (seen[o])
                fprintf(f, "        rcal_outlet%u;\n", o);
    } else {
        fprintf(f, "        VAR num k;\n");
        fprintf(f, "        TPReadNum k, \"rcal: the encoder stands at which outlet?\";\n");
        fprintf(f, "        TEST k\n");
        for (unsigned o = 0; o < 256; ++o)
            if (seen[o])
                fprintf(f, "        CASE %u:\n            rcal_outlet%u;\n", o, o);
        fprintf(f, "        DEFAULT:\n            TPWrite \"rcal: no such outlet in this plan\";\n");
        fprintf(f, "        ENDTEST\n");
    }
    fprintf(f, "    ENDPROC\nENDMODULE\n");
    return ferror(f) ? -1 : 0;
}

void rch_poses_free(rch_poses_result *res)
{
    free(res->poses);
    memset(res, 0, sizeof *res);
}
