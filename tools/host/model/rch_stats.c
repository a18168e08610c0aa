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

/* Continued fraction of the incomplete beta function (modified Lentz). */
static double betacf(double a, double b, double x)
{
    const double tiny = 1e-300, eps = 1e-15;
    double qab = a + b, qap = a + 1.0, qam = a - 1.0;
    double c = 1.0, dd = 1.0 - qab * x / qap;
    if (fabs(dd) < tiny)
        dd = tiny;
    dd = 1.0 / dd;
    double h = dd;
    for (int m = 1; m <= 500; ++m) {
        const double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        dd = 1.0 + aa * dd;
        if (fabs(dd) < tiny)
            dd = tiny;
        c = 1.0 + aa / c;
        if (fabs(c) < tiny)
            c = tiny;
        dd = 1.0 / dd;
        h *= dd * c;
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        dd = 1.0 + aa * dd;
        if (fabs(dd) < tiny)
            dd = tiny;
        c = 1.0 + aa / c;
        if (fabs(c) < tiny)
            c = tiny;
        dd = 1.0 / dd;
        const double del = dd * c;
        h *= del;
        if (fabs(del - 1.0) < eps)
            break;
    }
    return h;
}

/* Own code, on purpose: the Debian libraries with an F/incomplete-beta tail
 * are GSL (GPL-3) and R's libRmath (GPL-2+), and rcal and its binaries are
 * MIT. The test diag_fdist_gsl (test binary only, never shipped) checks
 * rch_f_sf against GSL's gsl_cdf_fdist_Q over d1 1..30, d2 1..1e5,
 * p 0.999..1e-250: worst relative error 7.1e-10 (f = 2.71, d1 = 1,
 * d2 = 1e5; the cancellation in lgamma(a + b) - lgamma(a) at a = 5e4).
 *
 * Regularized incomplete beta I_x(a, b); y = 1 - x, given by the caller
 * without cancellation (1.0 - x loses digits when x is near 1). */
static double incbeta(double a, double b, double x, double y)
{
    if (x <= 0.0)
        return 0.0;
    if (y <= 0.0)
        return 1.0;
    const double lx = x > 0.5 ? log1p(-y) : log(x), ly = y > 0.5 ? log1p(-x) : log(y);
    const double lbt = lgamma(a + b) - lgamma(a) - lgamma(b) + a * lx + b * ly;
    if (x < (a + 1.0) / (a + b + 2.0))
        return exp(lbt) * betacf(a, b, x) / a;
    return 1.0 - exp(lbt) * betacf(b, a, y) / b;
}

double rch_f_sf(double f, double d1, double d2)
{
    if (!(f > 0.0) || !(d1 > 0.0) || !(d2 > 0.0))
        return 1.0;
    if (!isfinite(f))
        return 0.0;
    const double s = d2 + d1 * f;
    return incbeta(0.5 * d2, 0.5 * d1, d2 / s, d1 * f / s);
}

double rch_f_isf(double p, double d1, double d2)
{
    if (!(p > 0.0 && p < 1.0) || !(d1 > 0.0) || !(d2 > 0.0))
        return NAN;
    /* rch_f_sf falls from 1 at f = 0 to 0: bracket in log f, then bisect */
    double lo = -1.0, hi = 1.0;
    for (int k = 0; k < 2000 && rch_f_sf(exp(lo), d1, d2) < p; ++k)
        lo -= 1.0;
    for (int k = 0; k < 2000 && rch_f_sf(exp(hi), d1, d2) > p; ++k)
        hi += 1.0;
    for (int k = 0; k < 200 && hi - lo > 1e-13; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (rch_f_sf(exp(mid), d1, d2) > p)
            lo = mid;
        else
            hi = mid;
    }
    return exp(0.5 * (lo + hi));
}

double rch_t2_ratio95_3d(double nu)
{
    if (isinf(nu) && nu > 0.0)
        return 1.0;
    if (!(nu >= 4.0))
        return INFINITY;
    const double chi2_3_95 = 7.814727903251178;
    return nu * 3.0 / (nu - 2.0) * rch_f_isf(0.05, 3.0, nu - 2.0) / chi2_3_95;
}

double rch_sd_se(double sd, double dof)
{
    return dof > 0.0 ? sd / sqrt(2.0 * dof) : NAN;
}

double rch_mad_sd(double *v, size_t n)
{
    if (n == 0)
        return 0.0;
    double med, mx;
    rch_median_max(&med, &mx, v, n);
    for (size_t i = 0; i < n; ++i)
        v[i] = fabs(v[i] - med);
    rch_median_max(&med, &mx, v, n);
    return 1.4826 * med;
}
