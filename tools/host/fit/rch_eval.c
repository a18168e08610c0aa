/* SPDX-License-Identifier: MIT */
/* rch_eval.c - the held-out split; see rch_eval.h. */
#include "rch_eval.h"

#include <stdlib.h>

#include "rch_data.h"

int rch_holdout_draw(rch_holdout *h, size_t *idx, const rc_sample *s, size_t n, size_t n_draw, size_t n_test,
                     unsigned long long seed)
{
    h->train = h->test = NULL;
    h->n_train = h->n_test = 0;
    if (n_draw > n || n_test > n_draw)
        return -1;
    rch_split(idx, n, seed);
    h->test = rch_data_pick(s, idx, n_test);
    h->train = rch_data_pick(s, idx + n_test, n_draw - n_test);
    if (!h->test || !h->train) {
        rch_holdout_free(h);
        return -1;
    }
    h->n_test = n_test;
    h->n_train = n_draw - n_test;
    return 0;
}

void rch_holdout_free(rch_holdout *h)
{
    free(h->train);
    free(h->test);
    h->train = h->test = NULL;
    h->n_train = h->n_test = 0;
}
