/* SPDX-License-Identifier: MIT */
/* rch_jumps.c - change-point detection of length jumps (see rch_jumps.h). */
#include "rch_jumps.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_jac.h"
#include "rch_uncert.h"

unsigned rch_jumps_segment(const rch_jumps *j, double t)
{
    unsigned k = 0;
    while (k < j->n_jumps && j->at_t[k] <= t)
        ++k;
    return k;
}

/* A fit at change points from_at (from_m) whose solution starts another:
 * its geometry, and each new segment the offset of the old segment its first
 * row lay in (a new change point splits one old segment into two equal
 * ones; a dropped one merges two into the first's). */
typedef struct warm_from {
    const rc_model *model; /* start's parameters, then the from_m + 1 offsets when from_m > 0 */
    const size_t *at;
    unsigned m;
} warm_from;

static void warm_start(rc_model *mdl, const rc_model *start, const warm_from *wf, const size_t *at, unsigned m)
{
    memcpy(mdl->x, wf->model->x, start->n_params * sizeof mdl->x[0]);
    if (m == 0 || wf->m == 0)
        return;
    const unsigned nf = mdl->effects[mdl->n_effects - 1].first, of = wf->model->effects[wf->model->n_effects - 1].first;
    for (unsigned j = 0; j <= m; ++j) {
        const size_t first = j ? at[j - 1] : 0;
        unsigned old = 0;
        while (old < wf->m && wf->at[old] <= first)
            ++old;
        mdl->x[nf + j] = wf->model->x[of + old] - wf->model->x[of];
    }
}

/* Model = start + segment offsets (first held at 0), fitted on s labelled
 * by the change points at[0..m-1] (indices into s), from start or (wf not
 * NULL) warm from an earlier fit. */
static int fit_segments(rc_model *out, double *ssr, const rc_model *start, const uint8_t *fixed, rc_sample *s,
                        size_t n, const size_t *at, unsigned m, const rc_solve_config *base, rc_solve_work *w,
                        rch_fit_counts *counts, const warm_from *wf)
{
    rc_model mdl = *start;
    unsigned seg = 0;
    for (size_t i = 0; i < n; ++i) {
        while (seg < m && at[seg] <= i)
            ++seg;
        s[i].group = (uint16_t)seg;
    }
    uint8_t fx[RC_MAX_PARAMS];
    memset(fx, 0, sizeof fx);
    if (fixed)
        memcpy(fx, fixed, start->n_params);
    if (m > 0) {
        if (rc_model_add_effect(&mdl, RC_EFF_GROUP_OFFSET, 0, m + 1) != RC_OK)
            return -1;
        fx[mdl.effects[mdl.n_effects - 1].first] = 1; /* first segment: the reference */
    }
    const int warm = wf && wf->model && wf->model->n_params >= start->n_params;
    if (warm)
        warm_start(&mdl, start, wf, at, m);
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    if (base)
        cfg = *base;
    cfg.fixed = fx;
    if (warm) /* from an earlier fit: near the optimum (a MAP fit then starts undamped) */
        rc_solve_config_warm(&cfg);
    rc_solve_result res;
    memset(&res, 0, sizeof res);
    const rc_status st = rc_solve(&mdl, &res, w, &cfg, s, n);
    if (counts) {
        counts->fits++;
        counts->jac_passes += res.cost_evals;
    }
    if (st != RC_OK)
        return -1;
    if (rc_cost(ssr, &mdl, s, n) != RC_OK)
        return -1;
    *out = mdl;
    return 0;
}

/* The linearised search at a fit: the geometry's free columns J (n x p)
 * and residuals r at the fit (model - measured, weighted), the prior's
 * diagonal weights (noise / sd)^2 and gradient W (x - mean) on them, and the
 * steps s_j = [i >= at_j] (times the row weight) as columns without a prior.
 * Every candidate set is solved on these, so the search costs one Jacobian
 * pass and the fits at the points it keeps, not a fit per candidate. */
typedef struct lin_search {
    size_t n;
    unsigned p;
    rch_jac jac;
    double *wt;              /* (n) row weights */
    double *s2;              /* (n + 1) suffix sums of wt^2 */
    double wd[RC_MAX_PARAMS];/* (p) prior weights */
    double gp[RC_MAX_PARAMS];/* (p) prior gradient */
    double *G;               /* (p^2) J^T J, lower triangle */
    double g[RC_MAX_PARAMS]; /* (p) J^T r */
    double *sj;              /* ((n + 1) x p) suffix sums of the rows of J times the row weight: J^T s_k */
    double *sr;              /* (n + 1) suffix sums of r times the row weight: s_k^T r */
    double *b1;              /* (n x p) the rows of J whitened by the geometry block: L11^-1 J_i, with
                                L11 L11^T = J^T J + W the leading block of every N's factor */
    double *N;               /* ((p + M)^2) normal matrix, then its Cholesky factor (lower, row-major) */
    double *rl;              /* (n) linear residuals of the last solve */
    double z[RC_MAX_PARAMS + RCH_JUMPS_MAX]; /* the last solve: dx (p), step sizes (m) */
    double *u, *v;           /* (p + M) scratch */
    double ssr;              /* data part of the last solve's objective */
} lin_search;

static void lin_free(lin_search *L)
{
    rch_jac_free(&L->jac);
    free(L->wt);
    free(L->s2);
    free(L->G);
    free(L->sj);
    free(L->sr);
    free(L->b1);
    free(L->N);
    free(L->rl);
    free(L->u);
    free(L->v);
    memset(L, 0, sizeof *L);
}

/* The rows of the geometry mdl (no offsets) at s; 0 or -1. */
static int lin_init(lin_search *L, const rc_model *mdl, const uint8_t *fixed, const rc_solve_config *base,
                    const rc_sample *s, size_t n)
{
    memset(L, 0, sizeof *L);
    uint16_t idx[RC_MAX_PARAMS];
    unsigned p = 0;
    for (unsigned k = 0; k < mdl->n_params; ++k)
        if (!(fixed && fixed[k]))
            idx[p++] = (uint16_t)k;
    char err[160];
    const size_t M = (size_t)p + RCH_JUMPS_MAX;
    L->n = n;
    L->p = p;
    L->wt = malloc(n * sizeof *L->wt);
    L->s2 = malloc((n + 1) * sizeof *L->s2);
    L->N = malloc(M * M * sizeof *L->N);
    L->rl = malloc(n * sizeof *L->rl);
    L->u = malloc(M * sizeof *L->u);
    L->v = malloc(M * sizeof *L->v);
    if (p == 0 || n <= p || !L->wt || !L->s2 || !L->N || !L->rl || !L->u || !L->v ||
        rch_jac_eval(&L->jac, mdl, idx, p, s, n, err, sizeof err) != 0) {
        lin_free(L);
        return -1;
    }
    L->G = calloc((size_t)p * p, sizeof *L->G);
    L->sj = malloc((n + 1) * p * sizeof *L->sj);
    L->sr = malloc((n + 1) * sizeof *L->sr);
    if (!L->G || !L->sj || !L->sr) {
        lin_free(L);
        return -1;
    }
    const double *J = L->jac.J, *r = L->jac.r;
    L->s2[n] = L->sr[n] = 0.0;
    memset(&L->sj[n * p], 0, p * sizeof *L->sj);
    for (size_t i = n; i-- > 0;) {
        const double wi = rc_sample_weight(&s[i]), *ji = &J[i * p];
        L->wt[i] = wi;
        L->s2[i] = L->s2[i + 1] + wi * wi;
        L->sr[i] = L->sr[i + 1] + wi * r[i];
        for (unsigned a = 0; a < p; ++a) {
            L->sj[i * p + a] = L->sj[(i + 1) * p + a] + wi * ji[a];
            L->g[a] += ji[a] * r[i];
            for (unsigned b = 0; b <= a; ++b)
                L->G[(size_t)a * p + b] += ji[a] * ji[b];
        }
    }
    const int prior = base && base->prior_mean && base->prior_sd && base->prior_noise_mm > 0.0;
    for (unsigned c = 0; c < p; ++c) {
        const unsigned k = idx[c];
        const double sd = prior ? base->prior_sd[k] : 0.0;
        L->wd[c] = prior && sd > 0.0 && isfinite(sd) ? (base->prior_noise_mm / sd) * (base->prior_noise_mm / sd) : 0.0;
        L->gp[c] = L->wd[c] * (mdl->x[k] - (prior ? base->prior_mean[k] : 0.0));
    }
    /* the geometry block of N and its factor (lin_solve forms the same block: its factor's leading part) */
    for (unsigned a = 0; a < p; ++a)
        L->G[(size_t)a * p + a] += L->wd[a] + 1e-12 * (L->G[(size_t)a * p + a] + 1e-300);
    double *F = malloc((size_t)p * p * sizeof *F);
    L->b1 = malloc(n * p * sizeof *L->b1);
    if (!F || !L->b1) {
        free(F);
        lin_free(L);
        return -1;
    }
    memcpy(F, L->G, (size_t)p * p * sizeof *F);
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'L', (lapack_int)p, F, (lapack_int)p) != 0) {
        free(F);
        lin_free(L);
        return -1;
    }
    for (size_t i = 0; i < n; ++i) {
        const double *ji = &J[i * p];
        double *bi = &L->b1[i * p];
        for (unsigned a = 0; a < p; ++a) {
            double t = ji[a];
            for (unsigned b = 0; b < a; ++b)
                t -= F[(size_t)a * p + b] * bi[b];
            bi[a] = t / F[(size_t)a * p + a];
        }
    }
    free(F);
    return 0;
}

/* Solve the linear problem with the steps at (m): L->z, L->rl, L->ssr and
 * the Cholesky factor in L->N. 0, or -1 when singular. */
static int lin_solve(lin_search *L, const size_t *at, unsigned m)
{
    const unsigned p = L->p, q = p + m;
    const size_t n = L->n;
    const double *J = L->jac.J, *r = L->jac.r;
    double *N = L->N, *z = L->z;
    memset(N, 0, (size_t)q * q * sizeof *N);
    for (unsigned a = 0; a < p; ++a) {
        memcpy(&N[(size_t)a * q], &L->G[(size_t)a * p], (a + 1) * sizeof *N);
        z[a] = -L->g[a];
    }
    for (unsigned j = 0; j < m; ++j) { /* the steps' cross terms: suffix sums from their first rows */
        memcpy(&N[(size_t)(p + j) * q], &L->sj[at[j] * p], p * sizeof *N);
        z[p + j] = -L->sr[at[j]];
    }
    for (unsigned j = 0; j < m; ++j)
        for (unsigned k = 0; k <= j; ++k)
            N[(size_t)(p + j) * q + p + k] = L->s2[at[j] > at[k] ? at[j] : at[k]];
    for (unsigned a = 0; a < p; ++a) /* (the prior and the ridge are in G) */
        z[a] -= L->gp[a];
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'L', (lapack_int)q, N, (lapack_int)q) != 0)
        return -1;
    for (unsigned a = 0; a < q; ++a) { /* L y = rhs */
        double t = z[a];
        for (unsigned b = 0; b < a; ++b)
            t -= N[(size_t)a * q + b] * z[b];
        z[a] = t / N[(size_t)a * q + a];
    }
    for (unsigned a = q; a-- > 0;) { /* L^T z = y */
        double t = z[a];
        for (unsigned b = a + 1; b < q; ++b)
            t -= N[(size_t)b * q + a] * z[b];
        z[a] = t / N[(size_t)a * q + a];
    }
    double ssr = 0.0, step = 0.0;
    unsigned next = 0;
    for (size_t i = 0; i < n; ++i) {
        while (next < m && at[next] <= i)
            step += z[p + next++];
        const double *ji = &J[i * p];
        double e = r[i] + L->wt[i] * step;
        for (unsigned a = 0; a < p; ++a)
            e += ji[a] * z[a];
        L->rl[i] = e;
        ssr += e * e;
    }
    L->ssr = ssr;
    return 0;
}

/* Best new change point for the last lin_solve at at (m): the candidate k
 * (at least min_seg rows from the ends and every point in at) whose step
 * reduces the linear objective most, (s_k^T r)^2 / (s_k^T s_k - u^T N^-1 u),
 * u = [J; S]^T s_k by suffix sums. 0 when none. */
static size_t lin_best(lin_search *L, const size_t *at, unsigned m, size_t min_seg)
{
    const unsigned p = L->p, q = p + m;
    const size_t n = L->n;
    const double *N = L->N;
    double *v = L->v, sr = 0.0, best_red = 0.0;
    size_t best = 0;
    memset(v, 0, p * sizeof *v);
    for (size_t k = n; k-- > 1;) {
        const double w = L->wt[k];
        sr += w * L->rl[k];
        double vv = 0.0;
        for (unsigned c = 0; c < p; ++c) { /* L11^-1 J^T s_k: suffix sums of the whitened rows */
            v[c] += w * L->b1[k * p + c];
            vv += v[c] * v[c];
        }
        if (k < min_seg || n - k < min_seg)
            continue;
        int near = 0;
        for (unsigned j = 0; j < m; ++j)
            near |= (k + min_seg > at[j]) && (k < at[j] + min_seg);
        if (near)
            continue;
        for (unsigned i = p; i < q; ++i) { /* the steps' rows of L v = u */
            const unsigned j = i - p;
            double t = L->s2[at[j] > k ? at[j] : k];
            for (unsigned b = 0; b < i; ++b)
                t -= N[(size_t)i * q + b] * v[b];
            v[i] = t / N[(size_t)i * q + i];
            vv += v[i] * v[i];
        }
        const double den = L->s2[k] - vv;
        if (!(den > 1e-9 * L->s2[k]))
            continue;
        const double red = sr * sr / den;
        if (red > best_red) {
            best_red = red;
            best = k;
        }
    }
    return best;
}

static int cmp_size(const void *x, const void *y)
{
    size_t a = *(const size_t *)x, b = *(const size_t *)y;
    return (a > b) - (a < b);
}

/* Jump sizes and standard errors from the segment offsets of j->model. */
static void jump_sizes(rch_jumps *j, const rc_sample *s, size_t n, int with_se)
{
    if (j->n_jumps == 0)
        return;
    const rc_effect *e = &j->model.effects[j->model.n_effects - 1];
    rch_uncert u;
    char err[128];
    uint8_t fx[RC_MAX_PARAMS];
    memset(fx, 0, sizeof fx);
    fx[e->first] = 1;
    int have = with_se && rch_uncert_compute(&u, &j->model, fx, s, n, 0, err, sizeof err) == 0;
    for (unsigned k = 0; k < j->n_jumps; ++k) {
        unsigned a = e->first + k, b = e->first + k + 1;
        j->size_mm[k] = j->model.x[b] - j->model.x[a];
        j->se_mm[k] = NAN;
        if (have) {
            size_t np = u.n_params;
            double v = u.cov[b * np + b] + u.cov[a * np + a] - 2.0 * u.cov[a * np + b];
            j->se_mm[k] = sqrt(fmax(v, 0.0));
        }
    }
    if (have)
        rch_uncert_free(&u);
}

/* The result of a fit cur (SSR ssr) at the change points at (m): the model,
 * the points, the geometry without the nuisance offsets, and the sizes with
 * their standard errors (c: the samples' copy, relabelled here). */
static void finish(rch_jumps *out, const rc_model *cur, double ssr, const rc_sample *s, rc_sample *c, size_t n,
                   const size_t *at, unsigned m, rch_fit_counts *cnt, int with_se)
{
    out->n_jumps = m;
    out->model = *cur;
    out->rms_after_mm = sqrt(ssr / (double)n);
    for (unsigned k = 0; k < m; ++k) {
        out->at[k] = at[k];
        out->at_t[k] = s[at[k]].t;
    }
    out->geometry = *cur;
    if (m > 0) {
        out->geometry.n_effects--;
        out->geometry.n_params = (uint16_t)cur->effects[cur->n_effects - 1].first;
    }
    for (size_t i = 0; i < n; ++i)
        c[i].group = (uint16_t)rch_jumps_segment(out, c[i].t);
    jump_sizes(out, c, n, with_se);
    if (cnt && m > 0 && with_se)
        cnt->jac_passes++; /* the sizes' covariance */
}

/* The fit's model for the change points at (m) from the linear solution of
 * L at the geometry geo: geo's free parameters moved by dx, the segment
 * offsets the sums of the steps before each (the first 0). wm: start's
 * layout plus the offsets when m > 0. */
static int lin_warm(rc_model *wm, const rc_model *start, const rc_model *geo, const uint8_t *fixed,
                    const lin_search *L, unsigned m)
{
    *wm = *start;
    if (m > 0 && rc_model_add_effect(wm, RC_EFF_GROUP_OFFSET, 0, m + 1) != RC_OK)
        return -1;
    memcpy(wm->x, geo->x, start->n_params * sizeof wm->x[0]);
    unsigned c = 0;
    for (unsigned k = 0; k < start->n_params; ++k)
        if (!(fixed && fixed[k]))
            wm->x[k] += L->z[c++];
    if (m > 0) {
        const unsigned of = wm->effects[wm->n_effects - 1].first;
        wm->x[of] = 0.0;
        for (unsigned j = 0; j < m; ++j)
            wm->x[of + j + 1] = wm->x[of + j] + L->z[L->p + j];
    }
    return 0;
}

/* One round of the linearised search at the geometry geo (no offsets),
 * from the change points at (m, updated): forward, the best step while it
 * beats the penalty; backward, the smallest step below factor x the RMS
 * residual dropped. L is left solved at the points returned. 0, or -1 when
 * the rows cannot be formed. */
static int lin_round(lin_search *L, size_t *at, unsigned *m_io, const rc_model *geo, const uint8_t *fixed,
                     const rc_solve_config *base, const rc_sample *c, size_t n, size_t min_seg, unsigned max_j,
                     double factor)
{
    unsigned m = *m_io;
    if (lin_init(L, geo, fixed, base, c, n) != 0 || lin_solve(L, at, m) != 0)
        return -1;
    const double pen = 3.0 * log((double)n);
    double ssr = L->ssr;
    while (m < max_j) {
        const size_t k = lin_best(L, at, m, min_seg);
        if (k == 0)
            break;
        size_t trial[RCH_JUMPS_MAX + 1];
        memcpy(trial, at, m * sizeof *at);
        trial[m] = k;
        qsort(trial, m + 1, sizeof *trial, cmp_size);
        if (lin_solve(L, trial, m + 1) != 0 || !((double)n * log(ssr / L->ssr) > pen)) {
            lin_solve(L, at, m); /* the points kept */
            break;
        }
        memcpy(at, trial, (m + 1) * sizeof *at);
        ++m;
        ssr = L->ssr;
    }
    while (m > 0) {
        const double rms = sqrt(ssr / (double)n);
        double smallest = INFINITY;
        unsigned drop = m;
        for (unsigned k = 0; k < m; ++k) {
            const double size = fabs(L->z[L->p + k]);
            if (size < factor * rms && size < smallest) {
                smallest = size;
                drop = k;
            }
        }
        if (drop == m)
            break;
        memmove(&at[drop], &at[drop + 1], (m - drop - 1) * sizeof *at);
        --m;
        if (lin_solve(L, at, m) != 0)
            return -1;
        ssr = L->ssr;
    }
    *m_io = m;
    return 0;
}

int rch_jumps_find(rch_jumps *out, const rc_model *start, const uint8_t *fixed, const rc_sample *s, size_t n,
                   const rch_jumps_config *cfg, rc_solve_work *w, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    size_t min_seg = cfg && cfg->min_seg ? cfg->min_seg : 5;
    unsigned max_j = cfg && cfg->max_jumps ? cfg->max_jumps : (unsigned)(n / 20);
    double factor = cfg && cfg->size_factor > 0 ? cfg->size_factor : 3.0;
    const rc_solve_config *base = cfg ? cfg->solve : NULL;
    rch_fit_counts *cnt = cfg ? cfg->counts : NULL;
    if (max_j > RCH_JUMPS_MAX)
        max_j = RCH_JUMPS_MAX;
    if (n < 2 * min_seg + 30) {
        snprintf(err, errlen, "jump detection needs at least %zu samples (have %zu)", 2 * min_seg + 30, n);
        return -1;
    }
    rc_sample *c = malloc(n * sizeof *c);
    if (!c) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    memcpy(c, s, n * sizeof *c);
    size_t at[RCH_JUMPS_MAX + 1] = {0};
    unsigned m = 0;
    double ssr;
    rc_model cur;
    /* the geometry alone; from cfg->warm when it is a fit of start's parameters (the caller's fit at hand) */
    const int role = cfg && cfg->warm ? cfg->warm_role : RCH_WARM_START;
    const warm_from w0 = {cfg ? cfg->warm : NULL, at, 0};
    const int warm0 = w0.model && w0.model->n_params == start->n_params;
    if (role == RCH_WARM_LINEARISE && w0.model->n_params >= start->n_params) {
        cur = *start; /* the fit at hand's geometry; no fit: the first round starts from no point there */
        memcpy(cur.x, w0.model->x, start->n_params * sizeof cur.x[0]);
        ssr = NAN;
    } else if (role == RCH_WARM_OPTIMUM && warm0) {
        cur = *w0.model;
        for (size_t i = 0; i < n; ++i)
            c[i].group = 0;
        if (rc_cost(&ssr, &cur, c, n) != RC_OK) {
            snprintf(err, errlen, "the geometric fit failed");
            free(c);
            return -1;
        }
    } else if (fit_segments(&cur, &ssr, start, fixed, c, n, at, 0, base, w, cnt, warm0 ? &w0 : NULL) != 0) {
        snprintf(err, errlen, "the geometric fit failed");
        free(c);
        return -1;
    }
    out->geometry = cur;
    out->rms_before_mm = sqrt(ssr / (double)n);
    /* Rounds of the linearised search (lin_round), each at the geometry of
     * the last fit: the points it keeps are fitted (from the linear
     * solution), and the search is made again at that fit until the points
     * no longer change (at most 3 rounds; the first from no point). */
    rc_model geo = cur;
    for (unsigned round = 0; round < 4; ++round) {
        lin_search L;
        size_t tat[RCH_JUMPS_MAX + 1] = {0};
        unsigned tm = 0; /* every round from no point: the search is a function of where it is linearised */
        const int lr = lin_round(&L, tat, &tm, &geo, fixed, base, c, n, min_seg, max_j, factor);
        if (cnt)
            cnt->jac_passes++; /* the Jacobian at the fit */
        if (lr != 0) {
            lin_free(&L);
            break; /* the points of the last fit */
        }
        const int same = tm == m && memcmp(tat, at, m * sizeof *at) == 0;
        if (same) {
            lin_free(&L);
            break;
        }
        rc_model wm, nm;
        double ssr2;
        const warm_from wf = {&wm, tat, tm};
        const int ok = lin_warm(&wm, start, &geo, fixed, &L, tm) == 0 &&
                       fit_segments(&nm, &ssr2, start, fixed, c, n, tat, tm, base, w, cnt, &wf) == 0;
        if (!ok) {
            lin_free(&L);
            if (m == 0 && tm > 0)
                break; /* no fit with jumps: the geometry alone */
            snprintf(err, errlen, "the fit at the change points failed");
            free(c);
            return -1;
        }
        lin_free(&L);
        cur = nm;
        ssr = ssr2;
        m = tm;
        memcpy(at, tat, sizeof at);
        geo = cur;
        if (m > 0) {
            geo.n_effects--;
            geo.n_params = (uint16_t)cur.effects[cur.n_effects - 1].first;
        }
    }
    if (isnan(ssr)) { /* linearised at a fit at hand and no point kept: the geometry alone, fitted from there */
        const rc_model g = cur;
        const warm_from wg = {&g, at, 0};
        m = 0;
        if (fit_segments(&cur, &ssr, start, fixed, c, n, at, 0, base, w, cnt, &wg) != 0) {
            snprintf(err, errlen, "the geometric fit failed");
            free(c);
            return -1;
        }
        out->rms_before_mm = sqrt(ssr / (double)n);
    }
    finish(out, &cur, ssr, s, c, n, at, m, cnt, !(cfg && cfg->skip_se));
    free(c);
    return 0;
}

int rch_jumps_refit(rch_jumps *out, const rc_model *start, const uint8_t *fixed, const rc_sample *s, size_t n,
                    const size_t *at, unsigned m, const rch_jumps_config *cfg, rc_solve_work *w, char *err,
                    size_t errlen)
{
    const rc_solve_config *base = cfg ? cfg->solve : NULL;
    rch_fit_counts *cnt = cfg ? cfg->counts : NULL;
    if (m > RCH_JUMPS_MAX) {
        snprintf(err, errlen, "more than %d jumps", RCH_JUMPS_MAX);
        return -1;
    }
    for (unsigned k = 0; k < m; ++k)
        if (at[k] == 0 || at[k] >= n || (k > 0 && at[k] <= at[k - 1])) {
            snprintf(err, errlen, "change points must be ascending inside the samples");
            return -1;
        }
    rc_sample *c = malloc((n ? n : 1) * sizeof *c);
    if (!c) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    memcpy(c, s, n * sizeof *c);
    memset(out, 0, sizeof *out);
    double ssr;
    rc_model cur;
    warm_from wf = {cfg ? cfg->warm : NULL, at, m};
    if (wf.model && wf.model->n_params != start->n_params + (m ? m + 1 : 0))
        wf.model = NULL; /* not a fit at these change points */
    if (fit_segments(&cur, &ssr, start, fixed, c, n, at, m, base, w, cnt, wf.model ? &wf : NULL) != 0) {
        snprintf(err, errlen, "the fit at the given change points failed");
        free(c);
        return -1;
    }
    finish(out, &cur, ssr, s, c, n, at, m, cnt, !(cfg && cfg->skip_se));
    out->rms_before_mm = out->rms_after_mm;
    free(c);
    return 0;
}
