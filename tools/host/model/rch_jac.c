/* SPDX-License-Identifier: MIT */
/* rch_jac.c - the Jacobian at a solution (see rch_jac.h). */
#include "rch_jac.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rch_jac_free(rch_jac *j)
{
    free(j->J);
    free(j->r);
    j->J = j->r = NULL;
    j->n = 0;
    j->nf = 0;
}

int rch_jac_eval(rch_jac *out, const rc_model *m, const uint16_t *idx, unsigned nf, const rc_sample *s, size_t n,
                 char *err, size_t errlen)
{
    double jrow[RC_MAX_PARAMS];
    memset(out, 0, sizeof *out);
    if (idx == NULL)
        nf = m->n_params;
    if (nf == 0 || nf > RC_MAX_PARAMS || n == 0 || (s == NULL)) {
        snprintf(err, errlen, "no parameter or no sample for the Jacobian");
        return -1;
    }
    for (unsigned k = 0; k < nf; ++k) {
        out->idx[k] = idx ? idx[k] : (uint16_t)k;
        if (out->idx[k] >= m->n_params) {
            snprintf(err, errlen, "column %u names parameter %u of %u", k, out->idx[k], m->n_params);
            return -1;
        }
    }
    out->J = malloc(n * nf * sizeof *out->J);
    out->r = malloc(n * sizeof *out->r);
    if (!out->J || !out->r) {
        rch_jac_free(out);
        snprintf(err, errlen, "out of memory (Jacobian of %zu rows x %u columns)", n, nf);
        return -1;
    }
    out->n = n;
    out->nf = nf;
    for (size_t i = 0; i < n; ++i) {
        double l;
        if (rc_meas(&l, jrow, m, &s[i]) != RC_OK || !isfinite(l)) {
            rch_jac_free(out);
            snprintf(err, errlen, "sample %zu has no defined length derivative (the flange on the outlet?)", i + 1);
            return -2;
        }
        const double wt = rc_sample_weight(&s[i]); /* the fit's rows: weighed as the solver weighs them */
        out->r[i] = (l - s[i].value) * wt;
        for (unsigned k = 0; k < nf; ++k) {
            const double v = jrow[out->idx[k]] * wt;
            out->J[i * nf + k] = v;
            out->norm2[k] += v * v;
        }
    }
    return 0;
}

void rch_jac_scale_columns(rch_jac *j, double *scale)
{
    for (unsigned k = 0; k < j->nf; ++k) {
        double d = sqrt(j->norm2[k]);
        if (!(d > 0.0))
            d = 1.0; /* a column of zeros: the parameter has no effect at all */
        scale[k] = d;
        for (size_t i = 0; i < j->n; ++i)
            j->J[i * j->nf + k] /= d;
    }
}
