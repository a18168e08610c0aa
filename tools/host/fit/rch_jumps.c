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
    if (wf && wf->model && wf->model->n_params >= start->n_params)
        warm_start(&mdl, start, wf, at, m);
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    if (base)
        cfg = *base;
    cfg.fixed = fx;
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

/* Best new change point for the model mdl: index or 0 when none. */
static size_t best_candidate(const rc_model *mdl, const uint8_t *fixed, const rc_sample *s, size_t n, const size_t *at,
                             unsigned m, size_t min_seg)
{
    unsigned p = 0;
    uint16_t idx[RC_MAX_PARAMS];
    unsigned first_off = mdl->n_effects ? mdl->effects[mdl->n_effects - 1].first : mdl->n_params;
    for (unsigned k = 0; k < mdl->n_params; ++k)
        if (!((k < RC_P_ENC + 3 && fixed && fixed[k]) || k == first_off))
            idx[p++] = (uint16_t)k;
    if (p == 0 || n <= p)
        return 0;
    rch_jac jac;
    char err[160];
    double *Q = NULL, *r = NULL, *tau = malloc(p * sizeof *tau);
    double *a = calloc(p, sizeof *a);
    size_t best = 0;
    memset(&jac, 0, sizeof jac);
    if (!tau || !a || rch_jac_eval(&jac, mdl, idx, p, s, n, err, sizeof err) != 0) /* the Jacobian at the fit */
        goto done;
    Q = jac.J;
    r = jac.r;
    if (LAPACKE_dgeqrf(LAPACK_ROW_MAJOR, (lapack_int)n, (lapack_int)p, Q, (lapack_int)p, tau) != 0 ||
        LAPACKE_dorgqr(LAPACK_ROW_MAJOR, (lapack_int)n, (lapack_int)p, (lapack_int)p, Q, (lapack_int)p, tau) != 0)
        goto done;
    /* r_perp = r - Q Q^T r */
    for (unsigned k = 0; k < p; ++k) {
        double c = 0.0;
        for (size_t i = 0; i < n; ++i)
            c += Q[i * p + k] * r[i];
        for (size_t i = 0; i < n; ++i)
            r[i] -= c * Q[i * p + k];
    }
    double best_red = 0.0, sr = 0.0;
    for (size_t k = n; k-- > 1;) {
        sr += r[k];
        double aa = 0.0;
        for (unsigned c = 0; c < p; ++c) {
            a[c] += Q[k * p + c];
            aa += a[c] * a[c];
        }
        if (k < min_seg || n - k < min_seg)
            continue;
        int near = 0;
        for (unsigned j = 0; j < m; ++j)
            near |= (k + min_seg > at[j]) && (k < at[j] + min_seg);
        double v = (double)(n - k) - aa;
        if (near || v < 1e-9)
            continue;
        double red = sr * sr / v;
        if (red > best_red) {
            best_red = red;
            best = k;
        }
    }
done:
    rch_jac_free(&jac);
    free(tau);
    free(a);
    return best;
}

static int cmp_size(const void *x, const void *y)
{
    size_t a = *(const size_t *)x, b = *(const size_t *)y;
    return (a > b) - (a < b);
}

/* Jump sizes and standard errors from the segment offsets of j->model. */
static void jump_sizes(rch_jumps *j, const rc_sample *s, size_t n)
{
    if (j->n_jumps == 0)
        return;
    const rc_effect *e = &j->model.effects[j->model.n_effects - 1];
    rch_uncert u;
    char err[128];
    uint8_t fx[RC_MAX_PARAMS];
    memset(fx, 0, sizeof fx);
    fx[e->first] = 1;
    int have = rch_uncert_compute(&u, &j->model, fx, s, n, 0, err, sizeof err) == 0;
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
                   const size_t *at, unsigned m, rch_fit_counts *cnt)
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
    jump_sizes(out, c, n);
    if (cnt && m > 0)
        cnt->jac_passes++; /* the sizes' covariance */
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
    if (fit_segments(&cur, &ssr, start, fixed, c, n, at, 0, base, w, cnt, NULL) != 0) {
        snprintf(err, errlen, "the geometric fit failed");
        free(c);
        return -1;
    }
    out->geometry = cur;
    out->rms_before_mm = sqrt(ssr / (double)n);
    double pen = 3.0 * log((double)n);
    /* forward: add the best change point while the penalised fit improves */
    while (m < max_j) {
        size_t k = best_candidate(&cur, fixed, c, n, at, m, min_seg);
        if (cnt)
            cnt->jac_passes++; /* the Jacobian at the fit */
        if (k == 0)
            break;
        size_t trial[RCH_JUMPS_MAX + 1];
        memcpy(trial, at, m * sizeof *at);
        trial[m] = k;
        qsort(trial, m + 1, sizeof *trial, cmp_size);
        rc_model nm;
        double ssr2;
        const warm_from wf = {&cur, at, m}; /* the fit at hand: the new segment's offset starts at its parent's */
        if (fit_segments(&nm, &ssr2, start, fixed, c, n, trial, m + 1, base, w, cnt, &wf) != 0)
            break;
        if (!((double)n * log(ssr / ssr2) > pen))
            break;
        memcpy(at, trial, (m + 1) * sizeof *at);
        ++m;
        cur = nm;
        ssr = ssr2;
    }
    /* backward: a jump smaller than size_factor x the final RMS residual is
     * not told apart from the noise: drop the smallest such, refit, repeat */
    while (m > 0) {
        const rc_effect *e = &cur.effects[cur.n_effects - 1];
        double rms = sqrt(ssr / (double)n), smallest = INFINITY;
        unsigned drop = m;
        for (unsigned k = 0; k < m; ++k) {
            double size = fabs(cur.x[e->first + k + 1] - cur.x[e->first + k]);
            if (size < factor * rms && size < smallest) {
                smallest = size;
                drop = k;
            }
        }
        if (drop == m)
            break;
        size_t old_at[RCH_JUMPS_MAX + 1];
        const rc_model old = cur;
        memcpy(old_at, at, m * sizeof *at);
        const warm_from wf = {&old, old_at, m};
        memmove(&at[drop], &at[drop + 1], (m - drop - 1) * sizeof *at);
        --m;
        if (fit_segments(&cur, &ssr, start, fixed, c, n, at, m, base, w, cnt, &wf) != 0) {
            snprintf(err, errlen, "refit without a jump failed");
            free(c);
            return -1;
        }
    }
    finish(out, &cur, ssr, s, c, n, at, m, cnt);
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
    finish(out, &cur, ssr, s, c, n, at, m, cnt);
    out->rms_before_mm = out->rms_after_mm;
    free(c);
    return 0;
}
