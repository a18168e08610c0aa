/* SPDX-License-Identifier: MIT */
/* test_diag_fdist_gsl.c - the own F distribution (rch_stats: the tail
 * rch_f_sf, an incomplete beta by continued fraction, used by diagnose's
 * F-tests; its inverse rch_f_isf and the Hotelling factor
 * rch_t2_ratio95_3d, used by the cluster-robust covariance) against GSL.
 *
 * Test only: GSL is GPL-3, so it is linked into this test binary (never
 * installed, never shipped) and nowhere else. The product keeps its own code.
 *
 * Grid: the degrees of freedom diagnose meets (d1 = effect parameters, d2 =
 * residual degrees of freedom), f at fixed values and at the quantiles of p
 * from 0.999 down to 1e-250 (from gsl_cdf_fdist_Qinv, or, where that fails,
 * by bisection in log f on gsl_cdf_fdist_Q). Where GSL's Q > 1e-290 the
 * relative error must stay below TOL; below, both must be below 1e-280 (a
 * p-value beyond what is printed, never a misleading one). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <float.h>
#include <math.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>

#include "rch_diagnose.h"
#include "rch_stats.h"

/* Measured worst (GSL 2.7, glibc lgamma): 7.1e-10 at f = 2.7056 (p = 0.1),
 * d1 = 1, d2 = 1e5; the limit is lgamma(a + b) - lgamma(a) at a = d2/2 =
 * 5e4 (a few ulp of 5e5), times (1 - p)/p on the complement branch. */
#define TOL 1e-9

static const double D1[] = {1, 2, 3, 4, 6, 10, 30};
static const double D2[] = {1, 2, 5, 10, 30, 100, 1000, 10000, 1e5};
static const double FIXED[] = {0.01, 0.1, 0.5, 1, 2, 5, 10, 100, 1e3, 1e4, 1e6};

/* f with GSL's Q(f) = p: Qinv when it gives a finite f whose Q is p, else
 * bisection in log f on GSL's Q (decreasing in f). *fallback counts those. */
static double f_at(double p, double d1, double d2, int *fallback)
{
    const double f = gsl_cdf_fdist_Qinv(p, d1, d2);
    if (isfinite(f) && f > 0.0 && fabs(gsl_cdf_fdist_Q(f, d1, d2) - p) <= 1e-6 * p)
        return f;
    ++*fallback;
    double lo = log(1e-300), hi = log(1e300);
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (gsl_cdf_fdist_Q(exp(mid), d1, d2) > p)
            lo = mid;
        else
            hi = mid;
    }
    return exp(0.5 * (lo + hi));
}

static void test_against_gsl(void **state)
{
    (void)state;
    gsl_set_error_handler_off();
    double p[48];
    size_t np = 0;
    const double head[] = {0.999, 0.99, 0.9, 0.5, 0.1, 0.05, 0.01};
    for (size_t i = 0; i < sizeof head / sizeof head[0]; ++i)
        p[np++] = head[i];
    for (int e = 3; e <= 20; ++e)
        p[np++] = pow(10.0, -e);
    for (int e = 30; e <= 250; e += 10)
        p[np++] = pow(10.0, -e);

    double worst = 0.0, wf = 0.0, wd1 = 0.0, wd2 = 0.0;
    int n_rel = 0, n_tiny = 0, n_bad = 0, fallback = 0;
    for (size_t i = 0; i < sizeof D1 / sizeof D1[0]; ++i)
        for (size_t j = 0; j < sizeof D2 / sizeof D2[0]; ++j) {
            const double d1 = D1[i], d2 = D2[j];
            const size_t nfix = sizeof FIXED / sizeof FIXED[0];
            for (size_t k = 0; k < nfix + np; ++k) {
                const double f = k < nfix ? FIXED[k] : f_at(p[k - nfix], d1, d2, &fallback);
                const double g = gsl_cdf_fdist_Q(f, d1, d2);
                const double o = rch_f_sf(f, d1, d2);
                if (!(o >= 0.0 && o <= 1.0)) {
                    print_error("f=%.17g d1=%g d2=%g: own %.17g outside [0, 1]\n", f, d1, d2, o);
                    ++n_bad;
                } else if (g > 1e-290) {
                    const double rel = fabs(o - g) / g;
                    ++n_rel;
                    if (rel > worst) {
                        worst = rel;
                        wf = f;
                        wd1 = d1;
                        wd2 = d2;
                    }
                    if (!(rel < TOL)) {
                        print_error("f=%.17g d1=%g d2=%g: own %.17g gsl %.17g rel %.3e\n", f, d1, d2, o, g,
                                    rel);
                        ++n_bad;
                    }
                } else {
                    ++n_tiny;
                    if (!(o <= 1e-280)) {
                        print_error("f=%.17g d1=%g d2=%g: own %.17g where gsl %.3g\n", f, d1, d2, o, g);
                        ++n_bad;
                    }
                }
            }
        }
    print_message("diag_fdist_gsl: %d points compared (relative), %d below 1e-290 (both tiny), "
                  "%d quantiles by bisection\n",
                  n_rel, n_tiny, fallback);
    print_message("diag_fdist_gsl: worst relative error %.3e at f=%.17g d1=%g d2=%g (tolerance %.0e)\n", worst,
                  wf, wd1, wd2, TOL);
    assert_int_equal(n_bad, 0);
    assert_true(n_rel > 3000);
}

/* The contract of rch_f_sf at the edges: f <= 0, and any NaN or
 * non-positive argument, give 1 (no evidence); f = +inf gives 0. */
static void test_edges(void **state)
{
    (void)state;
    const double nan_ = (double)NAN, inf = (double)INFINITY;
    assert_true(rch_f_sf(0.0, 3, 30) == 1.0);
    assert_true(rch_f_sf(-0.0, 3, 30) == 1.0);
    assert_true(rch_f_sf(-1.0, 3, 30) == 1.0);
    assert_true(rch_f_sf(-inf, 3, 30) == 1.0);
    assert_true(rch_f_sf(inf, 3, 30) == 0.0);
    assert_true(rch_f_sf(inf, 1, 1e5) == 0.0);
    assert_true(rch_f_sf(nan_, 3, 30) == 1.0);
    assert_true(rch_f_sf(2.0, nan_, 30) == 1.0);
    assert_true(rch_f_sf(2.0, 3, nan_) == 1.0);
    assert_true(rch_f_sf(inf, nan_, 30) == 1.0);
    assert_true(rch_f_sf(2.0, 0.0, 30) == 1.0);
    assert_true(rch_f_sf(2.0, 3, -1.0) == 1.0);
    /* d1 f overflows: the tail is 0, not NaN */
    assert_true(rch_f_sf(DBL_MAX, 30, 1) == 0.0);
    /* f so small that 1 - x is below the resolution of x: the tail is 1 */
    assert_true(fabs(rch_f_sf(1e-300, 1, 1e5) - 1.0) < 1e-15);
    assert_true(fabs(rch_f_sf(DBL_MIN, 30, 1) - 1.0) < 1e-15);
}

/* The inverse and the Hotelling T^2 over chi2 ratio of the cluster-robust
 * covariance (nu = G - 1 degrees of freedom, G >= 5 groups) against GSL's
 * quantiles. */
static void test_quantiles(void **state)
{
    (void)state;
    gsl_set_error_handler_off();
    static const double P[] = {0.5, 0.1, 0.05, 0.01, 1e-4};
    double worst = 0.0;
    for (size_t i = 0; i < sizeof D1 / sizeof D1[0]; ++i)
        for (size_t j = 0; j < sizeof D2 / sizeof D2[0]; ++j)
            for (size_t k = 0; k < sizeof P / sizeof P[0]; ++k) {
                int fb = 0;
                const double e = f_at(P[k], D1[i], D2[j], &fb), o = rch_f_isf(P[k], D1[i], D2[j]);
                const double rel = fabs(o / e - 1.0);
                worst = rel > worst ? rel : worst;
                assert_true(rel < 1e-8);
            }
    print_message("diag_fdist_gsl: rch_f_isf worst relative error %.3e\n", worst);
    for (double nu = 4; nu <= 1e5; nu = nu < 40 ? nu + 1 : nu * 1.5) {
        const double exact = 3.0 * nu / (nu - 2.0) * f_at(0.05, 3.0, nu - 2.0, &(int){0}) /
                             gsl_cdf_chisq_Qinv(0.05, 3.0);
        assert_true(fabs(rch_t2_ratio95_3d(nu) / exact - 1.0) < 1e-8);
    }
    assert_true(fabs(rch_t2_ratio95_3d(14.0) - 1.5632) < 1e-4);
    assert_true(rch_t2_ratio95_3d((double)INFINITY) == 1.0);
    assert_true(isinf(rch_t2_ratio95_3d(3.0)));
    assert_true(isinf(rch_t2_ratio95_3d((double)NAN)));
    assert_true(isnan(rch_f_isf(0.0, 3, 10)) && isnan(rch_f_isf(1.0, 3, 10)) && isnan(rch_f_isf(0.05, 0, 10)));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_gsl),
        cmocka_unit_test(test_quantiles),
        cmocka_unit_test(test_edges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
