/* SPDX-License-Identifier: MIT */
/* The stability rule (rc_stable): readings in one at a time, one sample out. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rc_stable.h"

static rc_stable_config cfg(unsigned n, double tol)
{
    rc_stable_config c;
    rc_stable_config_default(&c);
    c.n = n;
    c.tol_mm = tol;
    return c;
}

static void test_config_checked(void **state)
{
    rc_stable s;
    rc_stable_config c = cfg(5, 0.05);
    (void)state;
    assert_int_equal(rc_stable_init(&s, &c), RC_OK);
    c.n = 0;
    assert_int_equal(rc_stable_init(&s, &c), RC_ERR_ARG);
    c.n = RC_STABLE_MAX_N + 1;
    assert_int_equal(rc_stable_init(&s, &c), RC_ERR_ARG);
    c = cfg(5, -0.1);
    assert_int_equal(rc_stable_init(&s, &c), RC_ERR_ARG);
    c = cfg(5, NAN);
    assert_int_equal(rc_stable_init(&s, &c), RC_ERR_ARG);
    c = cfg(5, 0.05);
    c.min_mm = c.max_mm;
    assert_int_equal(rc_stable_init(&s, &c), RC_ERR_ARG);
    assert_int_equal(rc_stable_init(NULL, &c), RC_ERR_ARG);
}

/* n readings that agree give their mean and spread; fewer say "keep reading" */
static void test_steady(void **state)
{
    const double r[] = {500.01, 500.03, 500.02};
    rc_stable s;
    rc_stable_result res;
    rc_stable_config c = cfg(3, 0.05);
    (void)state;
    assert_int_equal(rc_stable_init(&s, &c), RC_OK);
    assert_int_equal(rc_stable_push(&s, &res, r[0], 0), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, r[1], 100), RC_ERR_INCOMPLETE);
    memset(&res, 0, sizeof res);
    assert_int_equal(rc_stable_push(&s, &res, r[2], 200), RC_OK);
    assert_true(fabs(res.mean_mm - (r[0] + r[1] + r[2]) / 3.0) < 1e-12);
    assert_true(fabs(res.spread_mm - (r[1] - r[0])) < 1e-12);
    assert_int_equal(res.count, 3);
    assert_int_equal(s.restarts, 0);
}

/* a drifting value: only the tail that agrees with the newest reading counts */
static void test_drift_keeps_agreeing_tail(void **state)
{
    rc_stable s;
    rc_stable_result res;
    rc_stable_config c = cfg(3, 0.05);
    (void)state;
    assert_int_equal(rc_stable_init(&s, &c), RC_OK);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 0), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 500.2, 1), RC_ERR_INCOMPLETE);
    assert_int_equal(s.restarts, 1);
    assert_int_equal(s.nw, 1);
    assert_int_equal(rc_stable_push(&s, &res, 500.22, 2), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 500.24, 3), RC_OK);
    assert_true(fabs(res.mean_mm - 500.22) < 1e-9);
    assert_true(fabs(res.spread_mm - 0.04) < 1e-9);
    /* 500.2, 500.26 disagree (0.06 > 0.05): 500.26 keeps only itself */
    assert_int_equal(rc_stable_push(&s, &res, 500.2, 4), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 500.26, 5), RC_ERR_INCOMPLETE);
    assert_int_equal(s.nw, 1);
    assert_int_equal(s.restarts, 2);
}

/* out-of-range and non-finite readings are rejected and clear the window */
static void test_range(void **state)
{
    rc_stable s;
    rc_stable_result res;
    rc_stable_config c = cfg(2, 0.05);
    (void)state;
    assert_int_equal(rc_stable_init(&s, &c), RC_OK);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 0), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 0.5, 1), RC_ERR_RANGE);
    assert_int_equal(s.nw, 0);
    assert_int_equal(rc_stable_push(&s, &res, NAN, 2), RC_ERR_RANGE);
    assert_int_equal(rc_stable_push(&s, &res, 30000.0, 3), RC_ERR_RANGE);
    assert_int_equal(s.range_rejects, 3);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 4), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 5), RC_OK);
}

/* the pose gives up timeout_ms after its first reading, also across a wrap
 * of the 32-bit millisecond counter */
static void test_timeout_and_wrap(void **state)
{
    rc_stable s;
    rc_stable_result res;
    rc_stable_config c = cfg(3, 0.01);
    const uint32_t t0 = UINT32_MAX - 500u;
    (void)state;
    c.timeout_ms = 1000;
    assert_int_equal(rc_stable_init(&s, &c), RC_OK);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, t0), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 501.0, t0 + 600u), RC_ERR_INCOMPLETE); /* wrapped: 99 */
    assert_int_equal(rc_stable_push(&s, &res, 501.0, t0 + 1000u), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 502.0, t0 + 1001u), RC_ERR_TIMEOUT);
    rc_stable_restart(&s);
    assert_int_equal(s.pushed, 0);
    assert_int_equal(rc_stable_push(&s, &res, 502.0, 5000u), RC_ERR_INCOMPLETE);
}

/* a window cleared after a reconnect needs n fresh readings */
static void test_clear_window(void **state)
{
    rc_stable s;
    rc_stable_result res;
    rc_stable_config c = cfg(2, 0.05);
    (void)state;
    assert_int_equal(rc_stable_init(&s, &c), RC_OK);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 0), RC_ERR_INCOMPLETE);
    rc_stable_clear_window(&s);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 1), RC_ERR_INCOMPLETE);
    assert_int_equal(rc_stable_push(&s, &res, 500.0, 2), RC_OK);
    assert_int_equal(res.count, 2);
    assert_true(res.spread_mm == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_config_checked),  cmocka_unit_test(test_steady),
        cmocka_unit_test(test_drift_keeps_agreeing_tail), cmocka_unit_test(test_range),
        cmocka_unit_test(test_timeout_and_wrap), cmocka_unit_test(test_clear_window),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
