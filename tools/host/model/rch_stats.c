/* SPDX-License-Identifier: MIT */
/* rch_stats.c - summary statistics (see rch_stats.h). */
#include "rch_stats.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

void rch_stats_add(rch_stats *s, double e)
{
    const double a = fabs(e);
    s->n++;
    s->sum_sq += e * e;
    s->sum_abs += a;
    const double d = e - s->mean;
    s->mean += d / (double)s->n;
    s->m2 += d * (e - s->mean);
    if (a > s->max_abs)
        s->max_abs = a;
}

void rch_stats_of(rch_stats *s, const double *v, size_t n)
{
    memset(s, 0, sizeof *s);
    for (size_t i = 0; i < n; ++i)
        rch_stats_add(s, v[i]);
}

double rch_stats_rms(const rch_stats *s)
{
    return s->n ? sqrt(s->sum_sq / (double)s->n) : 0.0;
}

double rch_stats_mean_abs(const rch_stats *s)
{
    return s->n ? s->sum_abs / (double)s->n : 0.0;
}

double rch_stats_sd(const rch_stats *s)
{
    return s->n > 1 ? sqrt(s->m2 / (double)(s->n - 1)) : 0.0;
}

void rch_stats_metrics(rc_metrics *out, const rch_stats *s)
{
    memset(out, 0, sizeof *out);
    out->n = s->n;
    out->rmse_mm = rch_stats_rms(s);
    out->mean_abs_mm = rch_stats_mean_abs(s);
    out->sd_mm = rch_stats_sd(s);
    out->mean_mm = s->mean;
    out->max_mm = s->max_abs;
}

double rch_rms(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
        s += v[i] * v[i];
    return n ? sqrt(s / (double)n) : 0.0;
}

/* v reordered so that v[k] is the k-th smallest, v[i] <= v[k] for i < k and
 * v[i] >= v[k] for i > k: Wirth's FIND (Hoare), pivot v[k]. */
static void select_kth(double *v, ptrdiff_t n, ptrdiff_t k)
{
    ptrdiff_t l = 0, r = n - 1;
    while (l < r) {
        const double x = v[k];
        ptrdiff_t i = l, j = r;
        do {
            while (v[i] < x)
                ++i;
            while (x < v[j])
                --j;
            if (i <= j) {
                const double t = v[i];
                v[i] = v[j];
                v[j] = t;
                ++i;
                --j;
            }
        } while (i <= j);
        if (j < k)
            l = i;
        if (k < i)
            r = j;
    }
}

void rch_median_max(double *med, double *max, double *v, size_t n)
{
    if (n == 0) {
        *med = *max = NAN;
        return;
    }
    double mx = v[0];
    for (size_t i = 1; i < n; ++i)
        mx = v[i] > mx ? v[i] : mx;
    *max = mx;
    const size_t k = n / 2;
    select_kth(v, (ptrdiff_t)n, (ptrdiff_t)k);
    if (n % 2) {
        *med = v[k];
        return;
    }
    double lo = v[0]; /* the (k-1)-th smallest: the largest below k */
    for (size_t i = 1; i < k; ++i)
        lo = v[i] > lo ? v[i] : lo;
    *med = 0.5 * (lo + v[k]);
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

double rch_quantile(double *v, size_t n, double p)
{
    if (n == 0)
        return NAN;
    qsort(v, n, sizeof *v, cmp_double);
    const double h = (double)(n - 1) * (p < 0 ? 0 : p > 1 ? 1 : p);
    const size_t lo = (size_t)floor(h);
    const size_t hi = lo + 1 < n ? lo + 1 : lo;
    return v[lo] + (h - (double)lo) * (v[hi] - v[lo]);
}
