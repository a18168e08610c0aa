/* SPDX-License-Identifier: MIT */
/* test_diag_stats.c - the statistics helpers of rch_diagnose. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>

#include "rch_diagnose.h"
#include "rch_stats.h"
#include "rch_dequant.h"

/* Upper tail of F against tabulated 5 % and 1 % critical values. */
static void test_f_tail(void **state)
{
    (void)state;
    assert_true(fabs(rch_f_sf(4.9646, 1, 10) - 0.05) < 2e-4);
    assert_true(fabs(rch_f_sf(3.4928, 2, 20) - 0.05) < 2e-4);
    assert_true(fabs(rch_f_sf(4.4307, 4, 20) - 0.01) < 1e-4);
    assert_true(fabs(rch_f_sf(2.3808, 4, 1000) - 0.05) < 5e-4);
    assert_true(fabs(rch_f_sf(1.0, 10, 10) - 0.5) < 1e-9); /* symmetric case */
    assert_true(rch_f_sf(0.0, 3, 30) == 1.0);
    assert_true(rch_f_sf(1e6, 3, 300) < 1e-100);
}

/* Display-step detection picks the coarsest grid every value sits on. */
static void test_detect_step(void **state)
{
    (void)state;
    const double q[] = {33.9, -30.8, 0.0, 80.5, -59.7, 12.3};
    assert_true(fabs(rch_dequant_detect_step(q, 6) - 0.1) < 1e-12);
    const double l[] = {509.19, 498.04, 487.45, 495.14};
    assert_true(fabs(rch_dequant_detect_step(l, 4) - 0.01) < 1e-12);
    const double r[] = {500.004, 500.008, 499.996};
    assert_true(fabs(rch_dequant_detect_step(r, 3) - 0.004) < 1e-12);
    const double h[] = {1.0, 2.5, 3.0};
    assert_true(fabs(rch_dequant_detect_step(h, 3) - 0.5) < 1e-12);
    const double none[] = {0.123456789, 1.0};
    assert_true(rch_dequant_detect_step(none, 2) == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_f_tail),
        cmocka_unit_test(test_detect_step),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
