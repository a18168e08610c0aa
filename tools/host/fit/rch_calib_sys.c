/* SPDX-License-Identifier: MIT */
/* rch_calib_sys.c - the systematic length errors the default run weighs
 * (issue 47): a display zeroed wrong (a length offset, each outlet's own)
 * and a drift over the run (linear in acquisition order). A cable fitted
 * across either has its geometry bent to absorb it: every length 5 mm short
 * put the demo robot's model 2.14 mm off the truth where the clean one is
 * 0.005 mm.
 *
 * The test is the attachment's (rch_calib_fit.c, choose_attachment): the
 * Laplace evidence of the model with the effect against the model without.
 * At the fit at hand the score (Lagrange multiplier) statistic of the
 * effect's columns, g' S^-1 g / sigma^2 with g = C' r and S = C'C -
 * C'J (J'J + P)^-1 J'C (J the fit's rows, P its prior's), is the gain in
 * chi-square the effect would bring (exact for a linear model); its Occam
 * penalty is 2 sum ln(prior sd / posterior sd), the prior the effect's
 * plausible range as 3 sd (the table's limit, as every physical effect's).
 * The effect is worth a refit when the score beats the penalty; the caller
 * refits and keeps the refit only when its profile likelihood gain still
 * beats it. Costs one Jacobian pass and a p x p Cholesky at the fit at hand.
 *
 * Depends on: the core (rc_model), rch_jac, rch_jumps (segments), rch_calib.
 * Memory: scratch freed before return. Errors: -1 with err set. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_linalg.h"
#include "rch_calib.h"
#include "rch_calib_int.h"
#include "rch_jac.h"

/* The columns of a candidate (n x k, row-major) for the samples s: the
 * length offset of each outlet (k = n_out) or a linear drift (k = 1), each
 * times the row's weight as the Jacobian's rows are. */
static void candidate_columns(double *C, unsigned k, int drift, const rc_sample *s, size_t n)
{
    memset(C, 0, n * k * sizeof *C);
    for (size_t i = 0; i < n; ++i) {
        if (s[i].sensor != RC_SENSOR_LENGTH)
            continue;
        const double w = rc_sample_weight(&s[i]);
        if (drift)
            C[i * k] = w * s[i].t;
        else if (s[i].outlet < k)
            C[i * k + s[i].outlet] = w;
    }
}

/* The score statistic and Occam penalty of the candidate columns C (n x k)
 * at the rows J (n x nf, residuals r) with the normal matrix's Cholesky
 * factor in A (nf x nf, already factored by rcu_chol_solve's convention:
 * solved column by column). 0, or -1 when the candidate is absorbed by the
 * model's own columns (not testable). */
static int score_of(double *score, double *occam, double *size_mm, const rch_jac *jac, const double *A,
                    const double *Ah, const double *C, unsigned k, double noise_mm, double prior_sd)
{
    const unsigned nf = jac->nf;
    const size_t n = jac->n;
    double *V = calloc((size_t)nf * k + 1, sizeof *V), *Am = malloc(((size_t)nf * nf + 1) * sizeof *Am),
           *x = malloc((nf + 1) * sizeof *x);
    double S[RC_MAX_OUTLETS * RC_MAX_OUTLETS], g[RC_MAX_OUTLETS], CC[RC_MAX_OUTLETS * RC_MAX_OUTLETS];
    int rc = -1;
    if (!V || !Am || !x || k > RC_MAX_OUTLETS)
        goto done;
    memset(CC, 0, sizeof CC);
    memset(g, 0, sizeof g);
    for (size_t i = 0; i < n; ++i) {
        const double *c = C + i * k, *row = jac->J + i * nf;
        for (unsigned a = 0; a < k; ++a) {
            if (c[a] == 0.0)
                continue;
            g[a] += c[a] * jac->r[i];
            for (unsigned b = 0; b < k; ++b)
                CC[a * k + b] += c[a] * c[b];
            for (unsigned p = 0; p < nf; ++p)
                V[a * nf + p] += c[a] * row[p];
        }
    }
    /* S = C'C - V A^-1 V' */
    for (unsigned a = 0; a < k; ++a) {
        memcpy(Am, A, (size_t)nf * nf * sizeof *Am);
        memcpy(x, V + a * nf, nf * sizeof *x);
        if (rcu_chol_solve(Am, x, nf) != RC_OK)
            goto done;
        for (unsigned b = 0; b < k; ++b) {
            double v = 0.0;
            for (unsigned p = 0; p < nf; ++p)
                v += V[b * nf + p] * x[p];
            S[a * k + b] = CC[a * k + b] - v;
        }
    }
    for (unsigned a = 0; a < k; ++a) /* the score where the model's own parameters are at their optimum */
        for (unsigned p = 0; p < nf; ++p)
            g[a] -= V[a * nf + p] * Ah[p];
    for (unsigned a = 0; a < k; ++a)
        if (!(S[a * k + a] > 1e-9 * CC[a * k + a]) || !(CC[a * k + a] > 0.0))
            goto done; /* absorbed: the model's columns already hold it */
    /* score = g' S^-1 g / noise^2; the posterior sd of each component sqrt((S^-1)_aa) noise */
    double Sinv[RC_MAX_OUTLETS * RC_MAX_OUTLETS], e[RC_MAX_OUTLETS];
    for (unsigned a = 0; a < k; ++a) {
        double Sc[RC_MAX_OUTLETS * RC_MAX_OUTLETS];
        memcpy(Sc, S, (size_t)k * k * sizeof *Sc);
        for (unsigned b = 0; b < k; ++b)
            e[b] = a == b;
        if (rcu_chol_solve(Sc, e, k) != RC_OK)
            goto done;
        for (unsigned b = 0; b < k; ++b)
            Sinv[b * k + a] = e[b];
    }
    double sc = 0.0, oc = 0.0, big = 0.0;
    for (unsigned a = 0; a < k; ++a) {
        double ga = 0.0;
        for (unsigned b = 0; b < k; ++b)
            ga += Sinv[a * k + b] * g[b];
        sc += g[a] * ga;
        if (fabs(ga) > fabs(big))
            big = -ga; /* the step that removes the residual's part: model - measured + b = 0 */
        oc += 2.0 * log(prior_sd / (noise_mm * sqrt(Sinv[a * k + a])));
    }
    *score = sc / (noise_mm * noise_mm);
    *occam = oc;
    *size_mm = big;
    rc = 0;
done:
    free(V);
    free(Am);
    free(x);
    return rc;
}

int rch_calib_sys_score(rch_calib_sys *out, const struct rch_calib_result *r, const uint8_t *fixed,
                        const rc_sample *s, size_t n, char *err, size_t errlen)
{
    const rc_model *m = r->have_jumps ? &r->jumps.model : &r->model;
    rc_sample *c = malloc((n ? n : 1) * sizeof *c);
    double *C = NULL, *A = NULL, *Ah = NULL, *Ac = NULL;
    rch_jac jac;
    memset(&jac, 0, sizeof jac);
    int rc = -1;
    if (!c) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    memcpy(c, s, n * sizeof *c);
    if (r->have_jumps) /* the jumps' segment offsets act through the samples' group */
        for (size_t i = 0; i < n; ++i)
            c[i].group = (uint16_t)rch_jumps_segment(&r->jumps, c[i].t);
    uint8_t fx[RC_MAX_PARAMS];
    memcpy(fx, fixed, sizeof fx);
    if (r->have_jumps && m->n_effects > 0 && m->effects[m->n_effects - 1].kind == RC_EFF_GROUP_OFFSET)
        fx[m->effects[m->n_effects - 1].first] = 1; /* the first segment: the reference */
    uint16_t idx[RC_MAX_PARAMS];
    unsigned nf = 0;
    const double *sd = r->prior_scaled ? r->prior_sd_fit : r->prior_sd;
    for (unsigned p = 0; p < m->n_params; ++p)
        if (!fx[p])
            idx[nf++] = (uint16_t)p;
    if (rch_jac_eval(&jac, m, idx, nf, c, n, err, errlen) != 0)
        goto done;
    A = calloc((size_t)nf * nf + 1, sizeof *A);
    Ah = calloc((size_t)nf + 1, sizeof *Ah);
    Ac = malloc(((size_t)nf * nf + 1) * sizeof *Ac);
    const unsigned k_off = r->n_outlets > 1 ? r->n_outlets : 1;
    C = calloc(n * k_off + 1, sizeof *C);
    if (!A || !C || !Ah || !Ac) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        const double *row = jac.J + i * nf;
        for (unsigned a = 0; a < nf; ++a)
            if (row[a] != 0.0) {
                Ah[a] += row[a] * jac.r[i];
                for (unsigned b = 0; b <= a; ++b)
                    A[a * nf + b] += row[a] * row[b];
            }
    }
    const double nz = r->noise_mm;
    for (unsigned a = 0; a < nf; ++a) {
        for (unsigned b = 0; b < a; ++b)
            A[b * nf + a] = A[a * nf + b];
        const unsigned p = idx[a];
        if (r->prior_on && p < RC_MAX_PARAMS && sd[p] > 0.0) {
            A[a * nf + a] += nz * nz / (sd[p] * sd[p]);
            Ah[a] += nz * nz / (sd[p] * sd[p]) * (m->x[p] - r->prior_mean[p]);
        }
        A[a * nf + a] *= 1.0 + 1e-12; /* (a ridge below round-off: a gauge direction stays solvable) */
    }
    /* A^-1 h: the step that would bring the model's own parameters to their optimum on these rows */
    memcpy(Ac, A, (size_t)nf * nf * sizeof *Ac);
    if (rcu_chol_solve(Ac, Ah, nf) != RC_OK) {
        snprintf(err, errlen, "the fit's normal equations are singular");
        goto done;
    }
    const rc_effect_desc *d_off = rc_effect_describe(RC_EFF_LENGTH_OFFSET),
                         *d_dr = rc_effect_describe(RC_EFF_TIME_DRIFT);
    const double sd_off = d_off->limit / 3.0, sd_dr = d_dr->limit / 3.0;
    out->n_offsets = k_off;
    candidate_columns(C, k_off, 0, c, n);
    out->offset_testable =
        score_of(&out->offset_score, &out->offset_occam, &out->offset_size_mm, &jac, A, Ah, C, k_off, nz, sd_off) == 0;
    candidate_columns(C, 1, 1, c, n);
    out->drift_testable =
        score_of(&out->drift_score, &out->drift_occam, &out->drift_size_mm, &jac, A, Ah, C, 1, nz, sd_dr) == 0;
    rc = 0;
done:
    rch_jac_free(&jac);
    free(A);
    free(Ah);
    free(Ac);
    free(C);
    free(c);
    return rc;
}
