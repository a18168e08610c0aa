/* SPDX-License-Identifier: MIT */
/* rch_chaos.h - the LTLM paper's uniformity study of its logistic-tent map
 * (its Figs. 2-3 and Eq. 12): the study behind `rcal chaos`.
 *
 * For r = 0, step, ..., 4: the standard deviation of the histogram bin counts
 * of `points` iterates of rc_lt_map (lower = more uniform), averaged over
 * `starts` initial values drawn from a fixed seed (rch_chaos_sd_avg; one
 * initial value makes the curve as noisy as the differences it is meant to
 * show). Results: the minimising r, the yardstick of independent uniform
 * draws (rch_chaos_sd_iid), which r lie within two standard errors of that
 * yardstick (or below it), and the histogram at the chosen r (r_hist, else
 * the minimiser) summed over the same initial values.
 *
 * Cost: (number of r values + 1) x starts x points map iterations; a
 * request above RCH_CHAOS_MAX_ITERATES is refused (rch_chaos_check).
 *
 * Depends on: rch_est (rch_chaos_sd*), rc_rand (core), rch_plot, rch_jw.
 * Memory: rch_chaos_run allocates inside the result; rch_chaos_free
 * releases it (also after a failed run). Errors: 0, or -1 with d set.
 */
#ifndef RCH_CHAOS_H
#define RCH_CHAOS_H

#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"
#include "rch_plot.h"

/* The most map iterations one study may take (about 8 s on one core). */
#define RCH_CHAOS_MAX_ITERATES 1000000000.0

typedef struct rch_chaos_config {
    unsigned long points;    /* iterates per initial value, >= 1 */
    unsigned long bins;      /* 2..1024 */
    unsigned long starts;    /* initial values, >= 1 */
    unsigned long long seed; /* of the initial values */
    double step;             /* r step, in [1e-4, 4] */
    double r_hist;           /* r of the histogram in [0, 4]; NaN: the minimiser */
} rch_chaos_config;

/* 1000 points, 50 bins, 100 starts, seed 1, step 0.01, r_hist NaN. */
void rch_chaos_defaults(rch_chaos_config *cfg);

/* Map iterations the study would take. */
double rch_chaos_cost(const rch_chaos_config *cfg);

/* Ranges and cost; 0, or -1 with d naming the limit that is exceeded. */
int rch_chaos_check(const rch_chaos_config *cfg, rch_diag *d);

typedef struct rch_chaos_result {
    size_t nr;            /* r values: 0, step, ..., 4 */
    double *r, *sd, *se;  /* (nr) r, mean sd of the bin counts, its standard error */
    size_t best;          /* index of the minimum of sd */
    double sd_iid;        /* independent uniform draws */
    double r_hist;        /* r of the histogram */
    unsigned *hist;       /* (bins) counts summed over the starts */
    size_t n_band;        /* r values within two standard errors of sd_iid, or below it */
    double band_lo, band_hi; /* lowest and highest of them (NaN when none) */
    double sd_at_05, se_at_05; /* at r = 0.5 when on the grid, else NaN */
} rch_chaos_result;

/* progress (may be NULL) gets a line per tenth of the r values when the
 * study costs more than 2e8 iterations. */
int rch_chaos_run(rch_chaos_result *res, const rch_chaos_config *cfg, FILE *progress, rch_diag *d);
void rch_chaos_free(rch_chaos_result *res);

void rch_chaos_report(FILE *f, const rch_chaos_result *res, const rch_chaos_config *cfg);
/* One JSON object (rch_jw: null where a figure is absent, never nan).
 * 0, or -1 on a write error. */
int rch_chaos_json(FILE *f, const rch_chaos_result *res, const rch_chaos_config *cfg, int argc, char **argv);
/* chaos_sd.svg and chaos_hist.svg into pd->dir (created when missing). 0,
 * or -1 with d set. */
int rch_chaos_plots(const rch_chaos_result *res, const rch_chaos_config *cfg, const rch_plot_dir *pd, rch_diag *d);

#endif
