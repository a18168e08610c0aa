/* SPDX-License-Identifier: MIT */
/* rch_jac.h - the Jacobian at a solution: the one place the host library
 * forms the stacked rows of a model over samples, for every analysis made
 * at the fit (the posterior covariance and the identifiability classes of
 * rch_uncert, the SVD report of rch_ident, the change-point search of
 * rch_jumps). The rows are the sensors' (rc_meas: one scalar residual per
 * sample, whatever it measures), so a new sensor reaches every analysis
 * through lib/rc_model.c alone.
 *
 * Host side (prefix rch_jac_): heap. */
#ifndef RCH_JAC_H
#define RCH_JAC_H

#include <stddef.h>
#include <stdint.h>

#include "rc_model.h"

typedef struct rch_jac {
    double *J;                    /* (n x nf) row-major: d(model - measured)_i / d x_idx[k], times the row's
                                     weight (rc_sample_weight) as the solver weighs it */
    double *r;                    /* (n) residuals, model - measured (mm), times the row's weight */
    double norm2[RC_MAX_PARAMS];  /* (nf) squared column norms */
    uint16_t idx[RC_MAX_PARAMS];  /* (nf) the parameter of each column */
    unsigned nf;
    size_t n;
} rch_jac;

/* The rows of m over s (n), columns idx (nf; NULL: every parameter of m, in
 * order). 0; -1 out of memory or bad arguments (err set); -2 when a sample
 * has no defined prediction or derivative (the flange on the outlet): err
 * names the sample. out is left empty on failure. */
int rch_jac_eval(rch_jac *out, const rc_model *m, const uint16_t *idx, unsigned nf, const rc_sample *s, size_t n,
                 char *err, size_t errlen);
/* Columns divided by their norms (scale (nf): the divisors; a zero column
 * is left as it is, its divisor 1). */
void rch_jac_scale_columns(rch_jac *j, double *scale);
void rch_jac_free(rch_jac *j);

#endif
