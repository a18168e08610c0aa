/* SPDX-License-Identifier: MIT */
/* test_calib_plan.c - issue 50: the calibration as a plan of stages
 * (rch_calib_plan_run, rch_calib_int.h): stages run in order, a stage's
 * RCH_PLAN_AGAIN starts the table again (bounded), a failing stage stops it
 * with its code, each stage's own time is booked once in the timing record
 * (a stage that runs a plan is booked without the inner stages); and on a
 * calibration: the record says every stage the run made, the default run's
 * jump check re-runs the fit through the plan (the start stage twice, no
 * recursion) when the lengths jump. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "rch_calib.h"
#include "rch_calib_int.h"

typedef struct {
    char order[32]; /* the stages' letters in the order they ran */
    unsigned n;
    int again_left; /* how often stage b asks for the table again */
    int fail_at_c;  /* stage c's code */
    rch_calib_timing *inner_t;
} toy;

static void spin_ms(double ms)
{
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    do
        clock_gettime(CLOCK_MONOTONIC, &b);
    while ((double)(b.tv_sec - a.tv_sec) * 1e3 + (double)(b.tv_nsec - a.tv_nsec) / 1e6 < ms);
}

static int st_a(void *run, rch_calib_result *r, rch_diag *d)
{
    (void)r, (void)d;
    toy *t = run;
    t->order[t->n++] = 'a';
    return 0;
}
static int st_b(void *run, rch_calib_result *r, rch_diag *d)
{
    (void)r, (void)d;
    toy *t = run;
    t->order[t->n++] = 'b';
    if (t->again_left > 0) {
        t->again_left--;
        return RCH_PLAN_AGAIN;
    }
    return 0;
}
static int st_c(void *run, rch_calib_result *r, rch_diag *d)
{
    (void)r, (void)d;
    toy *t = run;
    t->order[t->n++] = 'c';
    return t->fail_at_c;
}
static int st_slow(void *run, rch_calib_result *r, rch_diag *d)
{
    (void)r, (void)d;
    toy *t = run;
    t->order[t->n++] = 's';
    spin_ms(30.0);
    return 0;
}
static const rch_calib_stage inner[] = {{RCH_STAGE_MAP, st_slow}};
static int st_outer(void *run, rch_calib_result *r, rch_diag *d)
{
    toy *t = run;
    t->order[t->n++] = 'o';
    return rch_calib_plan_run(inner, 1, run, r, t->inner_t, d);
}

static const rch_calib_stage abc[] = {
    {RCH_STAGE_START, st_a}, {RCH_STAGE_JUMP_CHECK, st_b}, {RCH_STAGE_UNCERTAINTY, st_c}};

static void test_order_again_fail(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    toy t;
    rch_calib_timing tm;
    memset(&t, 0, sizeof t);
    memset(&tm, 0, sizeof tm);
    t.again_left = 1;
    assert_int_equal(rch_calib_plan_run(abc, 3, &t, &r, &tm, &d), 0);
    assert_string_equal(t.order, "ababc"); /* the table again from its first stage, once */
    assert_int_equal(tm.runs[RCH_STAGE_START], 2);
    assert_int_equal(tm.runs[RCH_STAGE_JUMP_CHECK], 2);
    assert_int_equal(tm.runs[RCH_STAGE_UNCERTAINTY], 1);
    assert_int_equal(tm.runs[RCH_STAGE_MAP], 0);
    /* a stage that keeps asking: at most RCH_PLAN_MAX_AGAIN restarts, then the table goes on */
    memset(&t, 0, sizeof t);
    memset(&tm, 0, sizeof tm);
    t.again_left = 100;
    assert_int_equal(rch_calib_plan_run(abc, 3, &t, &r, &tm, &d), 0);
    assert_int_equal(tm.runs[RCH_STAGE_START], 1 + RCH_PLAN_MAX_AGAIN);
    assert_int_equal(t.order[t.n - 1], 'c');
    /* a failing stage stops the table with its code */
    memset(&t, 0, sizeof t);
    memset(&tm, 0, sizeof tm);
    t.fail_at_c = -2;
    static const rch_calib_stage cab[] = {{RCH_STAGE_START, st_a}, {RCH_STAGE_UNCERTAINTY, st_c}, {RCH_STAGE_MAP, st_b}};
    assert_int_equal(rch_calib_plan_run(cab, 3, &t, &r, &tm, &d), -2);
    assert_string_equal(t.order, "ac");
    assert_int_equal(tm.runs[RCH_STAGE_MAP], 0);
}

/* A stage running a plan into the same record is booked without the inner stage's time: the sum of the
 * stages is the total, and the slow inner stage holds the time. */
static void test_booking_exclusive(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    toy t;
    rch_calib_timing tm;
    memset(&t, 0, sizeof t);
    memset(&tm, 0, sizeof tm);
    t.inner_t = &tm;
    static const rch_calib_stage outer[] = {{RCH_STAGE_SPLIT, st_outer}};
    assert_int_equal(rch_calib_plan_run(outer, 1, &t, &r, &tm, &d), 0);
    assert_string_equal(t.order, "os");
    assert_true(tm.wall_ms[RCH_STAGE_MAP] >= 30.0);
    assert_true(tm.wall_ms[RCH_STAGE_SPLIT] < 10.0); /* not the inner stage's 30 ms again */
    double sum = 0.0, cpu = 0.0;
    for (unsigned k = 0; k < RCH_STAGE_N; ++k) {
        sum += tm.wall_ms[k];
        cpu += tm.cpu_ms[k];
    }
    assert_true(fabs(sum - tm.total_wall_ms) < 1e-9 * (1.0 + sum));
    assert_true(fabs(cpu - tm.total_cpu_ms) < 1e-9 * (1.0 + cpu));
    assert_true(tm.cpu_ms[RCH_STAGE_MAP] > 0.0);
    assert_string_equal(rch_calib_stage_name(RCH_STAGE_JUMP_CHECK), "jump_check");
    assert_string_equal(rch_calib_stage_name(RCH_STAGE_N), "?");
}

static rch_calib_cfg sim_cfg(const char *data)
{
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.robot_path = RCAL_SOURCE_DIR "/data/irb120.json";
    cfg.data_path = data;
    cfg.method = RC_METHOD_LM;
    cfg.seed = 1;
    cfg.test_fraction = 0.1;
    return cfg;
}

/* The default run's record: every stage of the plan ran once (no jumps: the jumps stage had nothing to do),
 * the sum of the stages is the total, the identification's time is the MAP to jumps stages'. */
static void test_calibration_record(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    rch_calib_cfg cfg = sim_cfg(RCAL_SOURCE_DIR "/data/sim_irb120.csv");
    assert_int_equal(rch_calib_run(&r, &cfg, &d), 0);
    const rch_calib_timing *t = &r.timing;
    assert_int_equal(t->runs[RCH_STAGE_READ], 1);
    assert_int_equal(t->runs[RCH_STAGE_START], 1);
    assert_int_equal(t->runs[RCH_STAGE_MAP], 2); /* the check's first pass, then the loop */
    assert_int_equal(t->runs[RCH_STAGE_JUMP_CHECK], 1);
    assert_int_equal(t->runs[RCH_STAGE_UNCERTAINTY], 1);
    assert_int_equal(t->runs[RCH_STAGE_OUTPUTS], 1);
    assert_false(r.jumps_auto);
    double sum = 0.0, ident = 0.0;
    for (unsigned k = 0; k < RCH_STAGE_N; ++k)
        sum += t->wall_ms[k];
    for (unsigned k = RCH_STAGE_MAP; k <= RCH_STAGE_JUMPS; ++k)
        ident += t->wall_ms[k];
    assert_true(t->total_wall_ms > 0.0 && fabs(sum - t->total_wall_ms) < 1e-6 * sum);
    assert_true(r.time_ms > 0.0 && fabs(r.time_ms - ident) < 1e-6 * ident);
    assert_true(t->wall_ms[RCH_STAGE_READ] > 0.0);
}

/* Lengths that jump (+3 mm from the 301st row on): the check finds them and the fit's plan starts again with
 * them as nuisance (the start stage twice, the check once: the second pass does not check again); the
 * model is the geometry with the jumps, the request's cfg.jumps untouched. */
static void test_jump_rerun(void **state)
{
    (void)state;
    char path[] = "/tmp/rcal-plan-XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *in = fopen(RCAL_SOURCE_DIR "/data/sim_irb120.csv", "r"), *out = fdopen(fd, "w");
    assert_non_null(in);
    assert_non_null(out);
    char line[512];
    unsigned row = 0;
    while (fgets(line, sizeof line, in)) {
        if (row++ > 300) { /* the last column is L */
            char *c = strrchr(line, ',');
            assert_non_null(c);
            const double len = atof(c + 1) + 3.0;
            sprintf(c + 1, "%.4f\n", len);
        }
        fputs(line, out);
    }
    fclose(in);
    assert_int_equal(fclose(out), 0);
    static rch_calib_result r;
    rch_diag d;
    rch_calib_cfg cfg = sim_cfg(path);
    const int rc = rch_calib_run(&r, &cfg, &d);
    unlink(path);
    assert_int_equal(rc, 0);
    assert_true(r.jumps_auto && r.have_jumps && r.jumps.n_jumps >= 1);
    assert_false(r.cfg.jumps); /* the request as given: the decision is the result's jumps_auto */
    assert_int_equal(r.timing.runs[RCH_STAGE_START], 2);
    assert_int_equal(r.timing.runs[RCH_STAGE_JUMP_CHECK], 2); /* (the second: nothing to check with jumps) */
    assert_true(r.timing.wall_ms[RCH_STAGE_JUMPS] > 0.0);
    assert_true(r.after_ok && r.after_m.rmse_mm < 0.05);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_order_again_fail),
        cmocka_unit_test(test_booking_exclusive),
        cmocka_unit_test(test_calibration_record),
        cmocka_unit_test(test_jump_rerun),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
