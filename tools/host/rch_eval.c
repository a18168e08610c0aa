/* rch_eval.c - summary statistics and the held-out split; see rch_eval.h. */
#include "rch_eval.h"

#include <math.h>
#include <stdlib.h>

#include "rch_data.h"

void rch_stat_init(rch_stat *s)
{
    s->n = s->mean = s->m2 = s->sumsq = s->min = s->max = 0.0;
}

void rch_stat_add(rch_stat *s, double v)
{
    const double d = v - s->mean;
    if (s->n == 0.0 || v < s->min)
        s->min = v;
    if (s->n == 0.0 || v > s->max)
        s->max = v;
    s->n += 1.0;
    s->mean += d / s->n;
    s->m2 += d * (v - s->mean);
    s->sumsq += v * v;
}

double rch_stat_sd(const rch_stat *s) { return s->n > 1.0 ? sqrt(s->m2 / (s->n - 1.0)) : 0.0; }

double rch_stat_rms(const rch_stat *s) { return s->n > 0.0 ? sqrt(s->sumsq / s->n) : 0.0; }

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
