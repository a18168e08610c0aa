/* SPDX-License-Identifier: MIT */
/* rch_eval.h - the held-out split of an evaluation protocol: a seeded draw
 * of rows split into a held-out and a training set (rcal compare draws one
 * per case; the same rule as rcal calibrate's split: the permutation of
 * rch_split(seed), its first n_test indices held out, the next ones for
 * training).
 *
 * Summary statistics are rch_stats (rch_stats.h), not here.
 *
 * Depends on: rch_data (rch_split, rch_data_pick), rc_model (rc_sample).
 * Memory: rch_holdout_draw allocates both sets; rch_holdout_free releases
 * them. Thread safety: no shared state. Errors: -1 on a bad size or an
 * allocation failure.
 */
#ifndef RCH_EVAL_H
#define RCH_EVAL_H

#include <stddef.h>

#include "rc_model.h"

typedef struct rch_holdout {
    rc_sample *train; /* (n_train) copies */
    rc_sample *test;  /* (n_test) copies */
    size_t n_train, n_test;
} rch_holdout;

/* n_draw rows of s (n) drawn by the permutation of rch_split(seed): test =
 * its first n_test rows, train = the next n_draw - n_test. idx: (n) scratch.
 * 0, or -1 (n_draw > n, n_test > n_draw, out of memory; h then empty). */
int rch_holdout_draw(rch_holdout *h, size_t *idx, const rc_sample *s, size_t n, size_t n_draw, size_t n_test,
                     unsigned long long seed);
void rch_holdout_free(rch_holdout *h);

#endif
