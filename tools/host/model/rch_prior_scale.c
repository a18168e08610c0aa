/* SPDX-License-Identifier: MIT */
/* rch_prior_scale.c - the prior's scale from the data, type-II maximum
 * likelihood (see rch_prior_scale.h). */
#include "rch_prior_scale.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_solve.h"
#include "rch_stats.h"

int rch_prior_scale_type(unsigned k)
{
    if (k >= RC_N_DH)
        return -1;
    switch (k % 4) {
    case 0:
    case 1:
        return RCH_PS_LENGTH;
    case 2:
        return RCH_PS_TWIST;
    default:
        return RCH_PS_OFFSET;
    }
}

typedef struct {
    unsigned nf;
    uint16_t idx[RC_MAX_PARAMS];
    double A[RC_MAX_PARAMS * RC_MAX_PARAMS]; /* (nf x nf) J^T J / s^2 */
    double H[RC_MAX_PARAMS * RC_MAX_PARAMS];
    double S[RC_MAX_PARAMS * RC_MAX_PARAMS]; /* (nf x nf) the posterior covariance */
    double jrow[RC_MAX_PARAMS], g[RC_MAX_PARAMS];
} ps_work;

/* Sigma = (A + diag(p))^-1 into w->S; p (nf) the prior precisions. */
static int posterior(ps_work *w, const double *p)
{
    const unsigned nf = w->nf;
    for (unsigned a = 0; a < nf; ++a) {
        for (unsigned b = 0; b < nf; ++b) {
            w->H[a * nf + b] = w->A[a * nf + b];
            w->S[a * nf + b] = a == b;
        }
        /* without a prior, a ridge far below any information keeps H definite */
        w->H[a * nf + a] += p[a] > 0.0 ? p[a] : 1e-12 * (w->A[a * nf + a] > 0.0 ? w->A[a * nf + a] : 1.0);
    }
    return LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)nf, (lapack_int)nf, w->H, (lapack_int)nf, w->S,
                         (lapack_int)nf) == 0
               ? 0
               : -1;
}

/* One fixed-point update of the factors c (RCH_PS_TYPES) into out; 1 when
 * every factor moved by less than 1e-5 (relative). */
static int update(rch_prior_scale *out, double *c, ps_work *w, const double *dx, const double *p0, const double *pf,
                  const int *type)
{
    const unsigned nf = w->nf;
    double p[RC_MAX_PARAMS], step[RC_MAX_PARAMS], del[RC_MAX_PARAMS];
    for (unsigned a = 0; a < nf; ++a)
        p[a] = type[a] >= 0 ? p0[a] / (c[type[a]] * c[type[a]]) : pf[a];
    if (posterior(w, p) != 0)
        return -1;
    /* the MAP under p from the one under pf (the prior m was fitted under): x - Sigma (P - Pf)(x - mu)
     * (exact when linear) */
    for (unsigned a = 0; a < nf; ++a)
        step[a] = (p[a] - pf[a]) * dx[a];
    for (unsigned a = 0; a < nf; ++a) {
        double s = 0.0;
        for (unsigned b = 0; b < nf; ++b)
            s += w->S[a * nf + b] * step[b];
        del[a] = dx[a] - s;
    }
    double ss[RCH_PS_TYPES] = {0}, gam[RCH_PS_TYPES] = {0};
    for (unsigned a = 0; a < nf; ++a)
        if (type[a] >= 0) {
            ss[type[a]] += del[a] * del[a] * p0[a];
            gam[type[a]] += 1.0 - p[a] * w->S[a * nf + a];
        }
    int done = 1;
    for (int t = 0; t < RCH_PS_TYPES; ++t) {
        out->gamma[t] = gam[t];
        if (out->n[t] == 0 || gam[t] < RCH_PRIOR_SCALE_MIN_GAMMA) {
            out->fallback[t] = 1;
            continue;
        }
        out->fallback[t] = 0;
        const double ml = sqrt(ss[t] / gam[t]);
        out->factor_ml[t] = ml;
        const double lo = t == RCH_PS_OFFSET ? RCH_PRIOR_SCALE_MIN_FIT : 1.0; /* (factor_fit's bounds) */
        const double cn = fmin(fmax(ml, lo), RCH_PRIOR_SCALE_MAX);
        done &= fabs(cn / c[t] - 1.0) < 1e-5;
        c[t] = cn;
    }
    return done;
}

int rch_prior_scale_estimate(rch_prior_scale *out, const rc_model *m, const double *mean, const double *sd,
                             const double *sd_fit, const uint8_t *fixed, const rc_sample *s, size_t n,
                             double noise_mm, char *err, size_t errlen)
{
    if (!sd_fit)
        sd_fit = sd;
    memset(out, 0, sizeof *out);
    for (int t = 0; t < RCH_PS_TYPES; ++t)
        out->factor[t] = out->factor_fit[t] = out->factor_ml[t] = 1.0;
    if (!(noise_mm > 0.0) || !isfinite(noise_mm) || n == 0) {
        snprintf(err, errlen, "the prior's scale needs samples and a positive noise (got %zu, %g mm)", n, noise_mm);
        return -1;
    }
    ps_work *w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int type[RC_MAX_PARAMS];
    double dx[RC_MAX_PARAMS], p0[RC_MAX_PARAMS], pf[RC_MAX_PARAMS];
    for (unsigned k = 0; k < RC_MAX_PARAMS; ++k) { /* every entry defined (those of held parameters unused) */
        type[k] = -1;
        dx[k] = p0[k] = pf[k] = 0.0;
    }
    for (unsigned k = 0; k < m->n_params; ++k)
        if (!fixed || !fixed[k]) {
            const unsigned a = w->nf++;
            w->idx[a] = (uint16_t)k;
            p0[a] = sd[k] > 0.0 ? 1.0 / (sd[k] * sd[k]) : 0.0;
            pf[a] = sd_fit[k] > 0.0 ? 1.0 / (sd_fit[k] * sd_fit[k]) : 0.0;
            dx[a] = sd[k] > 0.0 ? m->x[k] - mean[k] : 0.0;
            type[a] = sd[k] > 0.0 ? rch_prior_scale_type(k) : -1;
            if (type[a] >= 0)
                out->n[type[a]]++;
        }
    double cost;
    int rc = -1;
    if (w->nf == 0 || rc_normal_eq(w->A, w->g, &cost, w->jrow, m, w->idx, w->nf, s, n) != RC_OK) {
        snprintf(err, errlen, "the prior's scale: no free parameter or a degenerate sample");
        goto done;
    }
    const double s2 = noise_mm * noise_mm;
    for (unsigned a = 0; a < w->nf * w->nf; ++a)
        w->A[a] /= s2;
    double c[RCH_PS_TYPES] = {1.0, 1.0, 1.0};
    for (out->iterations = 1; out->iterations <= 200; ++out->iterations) {
        const int u = update(out, c, w, dx, p0, pf, type);
        if (u < 0) {
            snprintf(err, errlen, "the prior's scale: the posterior is not definite");
            goto done;
        }
        if (u) {
            out->converged = 1;
            break;
        }
    }
    for (int t = 0; t < RCH_PS_TYPES; ++t) {
        out->factor_fit[t] = out->fallback[t] ? 1.0 : c[t];
        out->factor[t] = fmax(out->factor_fit[t], 1.0); /* the uncertainty: never below the stated sd */
        out->rel_se[t] = out->gamma[t] > 0.0 ? 1.0 / sqrt(2.0 * out->gamma[t]) : INFINITY;
    }
    rc = 0;
done:
    free(w);
    return rc;
}

void rch_prior_scale_apply(double *sd_out, const double *sd, unsigned n_params, const rch_prior_scale *ps)
{
    for (unsigned k = 0; k < n_params; ++k) {
        const int t = rch_prior_scale_type(k);
        sd_out[k] = t >= 0 && sd[k] > 0.0 ? sd[k] * ps->factor[t] : sd[k];
    }
}

void rch_prior_scale_apply_fit(double *sd_out, const double *sd, unsigned n_params, const rch_prior_scale *ps)
{
    for (unsigned k = 0; k < n_params; ++k) {
        const int t = rch_prior_scale_type(k);
        sd_out[k] = t >= 0 && sd[k] > 0.0 ? sd[k] * ps->factor_fit[t] : sd[k];
    }
}

double rch_prior_scale_predictive(const rch_prior_scale *ps, int type)
{
    if (type < 0 || type >= RCH_PS_TYPES || ps->fallback[type] || !(ps->factor[type] > 1.0) ||
        !(ps->gamma[type] >= RCH_PRIOR_SCALE_MIN_GAMMA))
        return 1.0;
    const double f = rch_f_isf(0.05, 1.0, fmin(ps->gamma[type], RCH_PRIOR_SCALE_TAIL_DOF)); /* t_{nu, 0.975}^2 = F_{1, nu} upper 5 % */
    return isfinite(f) && f > 0.0 ? fmax(1.0, sqrt(f) / 1.959963984540054) : 1.0;
}

void rch_prior_scale_apply_predictive(double *sd_out, const double *sd, unsigned n_params,
                                      const rch_prior_scale *ps)
{
    for (unsigned k = 0; k < n_params; ++k)
        sd_out[k] = sd[k] * rch_prior_scale_predictive(ps, rch_prior_scale_type(k));
}
