/* rch_eval.h - summary statistics and the held-out split shared by the
 * evaluation protocols of rcal (compare, grind).
 *
 * rch_stat: a running summary of a series (count, mean, sample standard
 * deviation by Welford's update, min, max, root mean square); one definition
 * instead of a hand-written loop per command.
 * rch_holdout: a seeded draw of rows split into a held-out and a training
 * set, the protocol of rcal compare (rch_split order: the first n_test
 * indices of the permutation are held out).
 *
 * Depends on: rch_data (rch_split, rch_data_pick), rc_model (rc_sample).
 * Memory: rch_holdout allocates both sets; rch_holdout_free releases them.
 * Thread safety: no shared state. Errors: -1 on allocation failure.
 */
#ifndef RCH_EVAL_H
#define RCH_EVAL_H

#include <stddef.h>

#include "rc_model.h"

typedef struct rch_stat {
    double n;        /* values added */
    double mean;
    double m2;       /* sum of squared deviations from the running mean */
    double sumsq;    /* sum of squares (for rms) */
    double min, max; /* of the values added; 0 when none */
} rch_stat;

void rch_stat_init(rch_stat *s);
void rch_stat_add(rch_stat *s, double v);
/* Sample standard deviation (n - 1); 0 with fewer than two values. */
double rch_stat_sd(const rch_stat *s);
/* Root mean square; 0 when empty. */
double rch_stat_rms(const rch_stat *s);

/* A held-out split of n_draw rows of s (n) drawn by the permutation of
 * rch_split(seed): test = its first n_test rows, train = the next
 * n_draw - n_test. idx: (n) scratch. Sets are malloc'd copies. 0 or -1. */
typedef struct rch_holdout {
    rc_sample *train; /* (n_train) */
    rc_sample *test;  /* (n_test) */
    size_t n_train, n_test;
} rch_holdout;

int rch_holdout_draw(rch_holdout *h, size_t *idx, const rc_sample *s, size_t n, size_t n_draw, size_t n_test,
                     unsigned long long seed);
void rch_holdout_free(rch_holdout *h);

#endif
