/* SPDX-License-Identifier: MIT */
/* test_ltmap.c - properties of the logistic-tent map (paper Eq. 11) and of
 * the uniformity measure of the chaos study (Eq. 12). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_est.h"

/* Eq. 11 by hand, for comparison. */
static double eq11(double n, double r)
{
    double v = n < 0.5 ? r * n * (1 - n) + (4 - r) * n / 2 : r * n * (1 - n) + (4 - r) * (1 - n) / 2;
    return v - floor(v);
}

static void test_map_definition(void **state)
{
    rc_rng g;
    (void)state;
    rc_rng_seed(&g, 3);
    for (int k = 0; k < 2000; ++k) {
        const double n = rc_rng_u01(&g), r = 4.0 * rc_rng_u01(&g);
        const double v = rc_lt_map(n, r);
        assert_true(v >= 0.0 && v < 1.0);
        assert_true(fabs(v - eq11(n, r)) < 1e-12);
    }
    /* r = 4: the logistic map 4 n (1 - n); r = 0: the tent map with slope 2 */
    assert_true(fabs(rc_lt_map(0.3, 4.0) - 4.0 * 0.3 * 0.7) < 1e-15);
    assert_true(fabs(rc_lt_map(0.2, 0.0) - 0.4) < 1e-15);
    assert_true(fabs(rc_lt_map(0.8, 0.0) - 0.4) < 1e-15);
}

/* Distance on the circle [0, 1) (the map is taken mod 1). */
static double circ(double a, double b)
{
    const double d = fabs(a - b);
    return d < 0.5 ? d : 1.0 - d;
}

/* The library's map is continuous on the circle, across the branch switch
 * at 0.5 too (both branches give r/4 + (4 - r)/4 = 1 -> 0 mod 1): its slope
 * is at most |r (1 - 2N)| + (4 - r)/2 <= 2 + r/2. */
static void test_map_continuity(void **state)
{
    (void)state;
    for (int ri = 0; ri <= 8; ++ri) {
        const double r = 0.5 * ri;
        const double at = rc_lt_map(0.5, r), left = rc_lt_map(0.5 - 1e-12, r);
        assert_true(circ(at, 0.0) < 1e-9);
        assert_true(circ(left, at) < 1e-9);
        /* consecutive points of a fine grid over the whole circle */
        double prev = rc_lt_map(0.0, r);
        for (int k = 1; k <= 100000; ++k) {
            const double v = rc_lt_map(k < 100000 ? k * 1e-5 : 0.0, r);
            assert_true(circ(v, prev) <= (2.0 + r / 2) * 1e-5 * 1.001 + 1e-15);
            prev = v;
        }
    }
}

/* Doubles: the tent map x -> 2x mod 1 loses one bit per step and reaches 0
 * within 64 steps; the chaos study reports that artefact at r = 0. */
static void test_tent_collapse(void **state)
{
    double x = 0.123456789;
    int k;
    (void)state;
    for (k = 0; k < 80 && x != 0.0; ++k)
        x = rc_lt_map(x, 0.0);
    assert_true(x == 0.0 && k <= 64);
    /* for r > 0 no such collapse from a generic start */
    x = 0.123456789;
    for (k = 0; k < 10000; ++k)
        x = rc_lt_map(x, 0.5);
    assert_true(x > 0.0 && x < 1.0);
}

static void test_uniformity_measure(void **state)
{
    unsigned counts[50];
    double se;
    (void)state;
    /* all points in one bin: sd = sqrt(((M - M/K)^2 + (K-1)(M/K)^2) / (K - 1)), Eq. 12 with N - 1 */
    {
        const double M = 1000, K = 50;
        const double want = sqrt(((M - M / K) * (M - M / K) + (K - 1) * (M / K) * (M / K)) / (K - 1));
        assert_true(fabs(rch_chaos_sd(counts, 0.0, 0.0, 1000, 50) - want) < 1e-9);
        assert_int_equal(counts[0], 1000);
    }
    /* counts add up; deterministic */
    {
        unsigned total = 0;
        const double a = rch_chaos_sd(counts, 0.5, 0.37, 1000, 50);
        for (int b = 0; b < 50; ++b)
            total += counts[b];
        assert_int_equal(total, 1000);
        assert_true(a == rch_chaos_sd(NULL, 0.5, 0.37, 1000, 50));
    }
    /* small r is about as uniform as independent draws; r = 4 (logistic,
     * arcsine density) much less, and the averaged curve rises from 1 to 4 */
    {
        const double iid = rch_chaos_sd_iid(1000, 50);
        const double s05 = rch_chaos_sd_avg(&se, 0.5, 1000, 50, 40, 1);
        const double s1 = rch_chaos_sd_avg(NULL, 1.0, 1000, 50, 40, 1);
        const double s4 = rch_chaos_sd_avg(NULL, 4.0, 1000, 50, 40, 1);
        assert_true(se > 0.0 && se < 0.5);
        assert_true(fabs(s05 - iid) < 0.25 * iid);
        assert_true(s1 < s4);
        assert_true(s4 > 2.5 * iid);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_map_definition),
        cmocka_unit_test(test_map_continuity),
        cmocka_unit_test(test_tent_collapse),
        cmocka_unit_test(test_uniformity_measure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
