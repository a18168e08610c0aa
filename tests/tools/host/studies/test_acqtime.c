/* SPDX-License-Identifier: MIT */
/* test_acqtime.c - rcal's own time per pose over the controller link (rch_acqtime, issue 48): the
 * definition on a made-up clock (AT to the next command, less --settle-ms and the display's stability
 * window; a sleep past the settle counts as rcal's), only poses whose sample was kept, the statistics. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "rch_acqtime.h"

#define SETTLE 20.0

/* One pose: NEXT at t, AT after move ms, settled after settle_real ms, the sample after disp ms, the next
 * command after own ms more; cpu advances by cpu_ms over the pose. Returns the time of the next command. */
static double pose(rch_acqtime *t, double t0, double move, double settle_real, double disp, double own, double *cpu,
                   double cpu_ms, int kept)
{
    double now = t0;
    rch_acqtime_mark(t, RCH_ACQTIME_CMD, now, *cpu);
    now += move;
    rch_acqtime_mark(t, RCH_ACQTIME_AT, now, *cpu);
    now += settle_real;
    rch_acqtime_mark(t, RCH_ACQTIME_SETTLED, now, *cpu);
    now += disp;
    rch_acqtime_mark(t, RCH_ACQTIME_SAMPLE, now, *cpu);
    if (kept)
        rch_acqtime_mark(t, RCH_ACQTIME_KEPT, now, *cpu);
    *cpu += cpu_ms;
    return now + own;
}

static void test_definition(void **state)
{
    rch_acqtime t;
    rch_acqtime_stats s;
    double cpu = 0.0, now = 1000.0;
    (void)state;
    assert_int_equal(rch_acqtime_init(&t, 8, SETTLE), 0);
    now = pose(&t, now, 30.0, SETTLE, 5.0, 1.5, &cpu, 0.5, 1);       /* own 1.5 */
    now = pose(&t, now, 40.0, SETTLE + 3.0, 6.0, 2.0, &cpu, 0.7, 1); /* slept 3 ms long: own 5.0 */
    now = pose(&t, now, 25.0, SETTLE, 7.0, 9.0, &cpu, 0.6, 0);       /* refused (no sample kept): not timed */
    now = pose(&t, now, 35.0, SETTLE, 4.0, 12.0, &cpu, 0.9, 1);      /* own 12 */
    rch_acqtime_mark(&t, RCH_ACQTIME_CMD, now, cpu);                  /* STOP */
    assert_int_equal(t.n, 3);
    assert_true(fabs(t.own_ms[0] - 1.5) < 1e-9);
    assert_true(fabs(t.own_ms[1] - 5.0) < 1e-9);
    assert_true(fabs(t.own_ms[2] - 12.0) < 1e-9);
    assert_true(fabs(t.display_ms[1] - 6.0) < 1e-9);
    assert_true(fabs(t.move_ms[2] - 35.0) < 1e-9);
    assert_true(fabs(t.cpu_ms[0] - 0.5) < 1e-9);
    assert_true(fabs(t.cpu_ms[2] - 0.9) < 1e-9);
    assert_int_equal(rch_acqtime_stats_of(&s, &t), 0);
    assert_int_equal(s.n, 3);
    assert_true(fabs(s.own_ms_median - 5.0) < 1e-9);
    assert_true(fabs(s.own_ms_max - 12.0) < 1e-9);
    assert_true(fabs(s.own_ms_p95 - 12.0) < 1e-9);
    assert_true(fabs(s.display_ms_median - 5.0) < 1e-9);
    assert_true(fabs(s.move_ms_max - 40.0) < 1e-9);
    assert_true(fabs(s.cpu_ms_median - 0.7) < 1e-9);
    rch_acqtime_free(&t);
}

/* A kept sample before any command (nothing to time from) and the capacity: never past cap. */
static void test_bounds(void **state)
{
    rch_acqtime t;
    rch_acqtime_stats s;
    double cpu = 0.0, now = 0.0;
    (void)state;
    assert_int_equal(rch_acqtime_init(&t, 2, SETTLE), 0);
    rch_acqtime_mark(&t, RCH_ACQTIME_SAMPLE, 1.0, 0.0);
    rch_acqtime_mark(&t, RCH_ACQTIME_KEPT, 1.0, 0.0);
    assert_int_equal(rch_acqtime_stats_of(&s, &t), 0);
    assert_int_equal(s.n, 0);
    assert_true(s.own_ms_median == 0.0 && s.own_ms_max == 0.0);
    for (int i = 0; i < 5; ++i)
        now = pose(&t, now, 10.0, SETTLE, 2.0, 1.0 + i, &cpu, 0.1, 1);
    rch_acqtime_mark(&t, RCH_ACQTIME_CMD, now, cpu);
    assert_int_equal(t.n, 2);
    /* 20 values 1..20: median 10.5, nearest-rank 95th percentile the 19th */
    rch_acqtime_free(&t);
    assert_int_equal(rch_acqtime_init(&t, 20, SETTLE), 0);
    now = 0.0;
    for (int i = 20; i >= 1; --i)
        now = pose(&t, now, 10.0, SETTLE, 2.0, (double)i, &cpu, 0.1, 1);
    rch_acqtime_mark(&t, RCH_ACQTIME_CMD, now, cpu);
    assert_int_equal(rch_acqtime_stats_of(&s, &t), 0);
    assert_int_equal(s.n, 20);
    assert_true(fabs(s.own_ms_median - 10.5) < 1e-9);
    assert_true(fabs(s.own_ms_p95 - 19.0) < 1e-9);
    assert_true(fabs(s.own_ms_max - 20.0) < 1e-9);
    rch_acqtime_free(&t);
}

/* The real clocks: monotonic and CPU time move forward. */
static void test_clocks(void **state)
{
    const double t0 = rch_acqtime_clock_ms(), c0 = rch_acqtime_cpu_ms();
    volatile double x = 0.0;
    (void)state;
    for (long i = 0; i < 3000000; ++i)
        x += 1e-9 * (double)i;
    assert_true(rch_acqtime_clock_ms() > t0);
    assert_true(rch_acqtime_cpu_ms() >= c0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_definition),
        cmocka_unit_test(test_bounds),
        cmocka_unit_test(test_clocks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
