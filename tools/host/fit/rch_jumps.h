/* SPDX-License-Identifier: MIT */
/* rch_jumps.h - length jumps at change points in acquisition order.
 *
 * A draw-wire encoder that loses or gains counts, or a display re-zeroed
 * between two readings, shifts every later length by the same amount: the
 * lengths carry a piecewise-constant offset in acquisition order. The jumps
 * are nuisance parameters: they are fitted with the geometry so that the
 * geometry is estimated honestly, and are not used to predict a new pose.
 *
 * Detection (greedy binary segmentation on the linearised problem):
 *  1. fit the geometry (and the offsets of the segments found so far: the
 *     RC_EFF_GROUP_OFFSET effect on segment labels, the first segment's
 *     offset held at 0);
 *  2. for every candidate row k (at least min_seg rows from the ends and
 *     from every change point already found), the step s_k = [i >= k] with
 *     the column space of the Jacobian projected out: the reduction of the
 *     residual sum of squares it would bring, (s_k^T r_perp)^2 / |s_k,perp|^2,
 *     all candidates in O(n p) with suffix sums;
 *  3. the best candidate is refitted and kept while the information it
 *     adds beats a penalty of 3 ln n (size and location of the jump: a
 *     modified BIC), up to max_jumps;
 *  4. backward: while some jump is smaller than size_factor times the final
 *     RMS residual, the smallest is dropped and the rest refitted (a jump the
 *     size of the noise is not a sensor event but a description of the noise).
 * Where the samples come in set-ups (the wrist fixed for a run of poses), a
 * step at a set-up change is confounded with anything that depends on the
 * set-up; rcal diagnose therefore takes the jumps as a sensor event only when
 * one lies inside a set-up.
 *
 * Host side (prefix rch_): heap, LAPACKE. */
#ifndef RCH_JUMPS_H
#define RCH_JUMPS_H

#include <stddef.h>

#include "rc_solve.h"

#define RCH_JUMPS_MAX 32

/* The work a fit pipeline did, counted by whoever is handed one (no
 * global): solver runs and residual-and-Jacobian passes over the samples
 * (the solver's normal equations, a Jacobian for a search or a covariance). */
typedef struct rch_fit_counts {
    unsigned fits;        /* rc_solve runs */
    unsigned jac_passes;  /* passes computing residuals and Jacobian rows */
} rch_fit_counts;

typedef struct rch_jumps_config {
    size_t min_seg;       /* rows between change points, 0: 5 */
    unsigned max_jumps;   /* 0: min(RCH_JUMPS_MAX, n / 20) */
    double size_factor;   /* 0: 3 */
    /* The solver set-up of every fit (method, prior, iteration cap; its
     * fixed member is replaced by the search's own), NULL: robust LM. A
     * prior's arrays must cover RC_MAX_PARAMS entries, 0 (no prior) past
     * the start model's parameters: the segment offsets are added there. */
    const rc_solve_config *solve;
    rch_fit_counts *counts; /* NULL, or where the search adds its fits and passes */
    /* NULL (start from start, offsets 0), or an earlier fit the first fit
     * starts from: rch_jumps_refit, a fit at the same change points (its
     * model: start's parameters and the m + 1 segment offsets, or start's
     * alone when m is 0; a noise pass after another moves the optimum
     * little); rch_jumps_find, a fit of start's parameters alone (the
     * geometry fit the search begins with, e.g. the caller's fit at hand). */
    const rc_model *warm;
    /* What rch_jumps_find's warm is (rch_jumps_refit reads only warm):
     * RCH_WARM_START a point the geometry fit starts from; RCH_WARM_OPTIMUM
     * that fit itself, at this solve set-up (the caller's fit at hand: no
     * geometry fit is made, its RMS is rms_before_mm); RCH_WARM_LINEARISE a
     * fit at other change points (its offsets, if any, are dropped): the
     * search's first round is linearised at its geometry and no geometry
     * fit is made (rms_before_mm NAN: the caller keeps an earlier one). */
    int warm_role;
    /* 1: the jumps' standard errors are not computed (se_mm NAN): a fit
     * whose sizes are an intermediate (a noise pass, a comparison's bound)
     * saves the covariance pass. */
    int skip_se;
} rch_jumps_config;

enum { RCH_WARM_START = 0, RCH_WARM_OPTIMUM = 1, RCH_WARM_LINEARISE = 2 };

typedef struct rch_jumps {
    unsigned n_jumps;
    size_t at[RCH_JUMPS_MAX];         /* (n_jumps) index (in s) of the first sample after the jump */
    double at_t[RCH_JUMPS_MAX];       /* (n_jumps) its acquisition time t, ascending */
    double size_mm[RCH_JUMPS_MAX];    /* (n_jumps) length change at that sample */
    double se_mm[RCH_JUMPS_MAX];      /* (n_jumps) its standard error (classical) */
    double rms_before_mm;             /* training RMS of the geometry alone */
    double rms_after_mm;              /* training RMS with the jumps */
    rc_model model;                   /* geometry + segment offsets (RC_EFF_GROUP_OFFSET) */
    rc_model geometry;                /* the same geometry without the nuisance offsets */
} rch_jumps;

/* Find the jumps in samples s (n, in acquisition order: t ascending)
 * starting from the model start (no group-offset effect). fixed
 * (start->n_params, may be NULL) holds geometric parameters fixed. The
 * samples' group fields are not read. 0, or -1 with err[errlen] set. */
int rch_jumps_find(rch_jumps *out, const rc_model *start, const uint8_t *fixed, const rc_sample *s, size_t n,
                   const rch_jumps_config *cfg, rc_solve_work *w, char *err, size_t errlen);

/* Segment of a sample at acquisition time t: the number of jumps at or
 * before t. Relabel samples with it (group = segment) to evaluate
 * j->model on rows the detection did not see. */
unsigned rch_jumps_segment(const rch_jumps *j, double t);

/* The fit of rch_jumps_find at given change points at (m, ascending
 * indices into s, each inside 1..n-1): geometry and segment offsets, the
 * sizes and standard errors; no search (rms_before_mm is the fit's). For
 * refits where the change points are known (the noise passes of a MAP fit,
 * the second model of a comparison). 0, or -1 with err set. */
int rch_jumps_refit(rch_jumps *out, const rc_model *start, const uint8_t *fixed, const rc_sample *s, size_t n,
                    const size_t *at, unsigned m, const rch_jumps_config *cfg, rc_solve_work *w, char *err,
                    size_t errlen);

#endif
