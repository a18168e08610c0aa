/* SPDX-License-Identifier: MIT */
/* Tracker positions on the host side (rch_positions.h): the closed-form
 * start recovers a known frame and targets, a held-out split keeps every
 * pose whole, the 3-D errors and ISO 9283 AP/RP on a hand-made case, the
 * targets grown with the known ones kept, and rch_pos_evaluate keeping or
 * fitting the frame. The samples are the model's own predictions (the
 * accuracy study with an independent generator is tests/system/sim/tracker_study.py). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rc_rand.h"
#include "rc_sensor.h"
#include "rch_data.h"
#include "rch_positions.h"
#include "rch_robot.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"

static rc_model nominal_with_tracker(unsigned n_targets)
{
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, ROBOT, &d), 0);
    rc_model m = r.model;
    assert_int_equal(rch_pos_add_effects(&m, n_targets), 0);
    return m;
}

static void set_truth(rc_model *m)
{
    const double frame[6] = {1200.0, -900.0, 350.0, 0.4, -0.7, 0.9}; /* a 71 deg turn */
    unsigned nt = 0;
    assert_int_equal(rch_pos_set_frame(m, frame), 0);
    const int kf = rch_pos_effect_at(m, RC_EFF_TRACKER_TARGETS, &nt);
    for (unsigned k = 0; k < nt; ++k)
        m->x[kf + (int)k] = (k % 3 == 2 ? 30.0 : 50.0) * (k % 2 ? -1.0 : 1.0) + 7.0 * (double)(k / 3);
}

/* Samples of n poses x nt targets predicted by m: three rows each, t the pose number. */
static rc_sample *make(size_t *n_out, const rc_model *m, unsigned nt, size_t poses, unsigned long seed)
{
    rc_rng g;
    rc_rng_seed(&g, seed);
    rc_sample *s = calloc(poses * nt * 3, sizeof *s);
    size_t n = 0;
    assert_non_null(s);
    for (size_t p = 0; p < poses; ++p) {
        double q[RC_NJ];
        for (int j = 0; j < RC_NJ; ++j)
            q[j] = (2.0 * rc_rng_u01(&g) - 1.0) * (j == 2 ? 1.0 : 1.5);
        for (unsigned k = 0; k < nt; ++k)
            for (unsigned c = 0; c < 3; ++c) {
                memcpy(s[n].q_rad, q, sizeof q);
                s[n].sensor = (uint8_t)(RC_SENSOR_TRACKER_X + c);
                s[n].target = (uint8_t)k;
                s[n].t = (double)p;
                assert_int_equal(rc_meas(&s[n].value, NULL, m, &s[n]), RC_OK);
                ++n;
            }
    }
    *n_out = n;
    return s;
}

static void test_start_recovers_frame(void **state)
{
    (void)state;
    rc_model truth = nominal_with_tracker(3);
    set_truth(&truth);
    size_t n;
    rc_sample *s = make(&n, &truth, 3, 20, 1);
    rc_model m = nominal_with_tracker(3);
    assert_false(rch_pos_frame_given(&m));
    assert_int_equal(rch_pos_start(&m, s, n, 0), 0);
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        if (!(fabs(m.x[k] - truth.x[k]) < 1e-6)) {
            print_error("param %u: %.9g, truth %.9g\n", k, m.x[k], truth.x[k]);
            fail();
        }
    rch_pos_err e;
    assert_int_equal(rch_pos_errors(&e, &m, s, n), 0);
    assert_int_equal(e.points, 60);
    assert_true(e.max_mm < 1e-6);
    assert_int_equal(e.repeated, 0);
    assert_true(isnan(e.ap_max_mm));
    /* the frame given: only the targets are placed */
    rc_model k = truth;
    memset(&k.x[rch_pos_effect_at(&k, RC_EFF_TRACKER_TARGETS, NULL)], 0, 9 * sizeof k.x[0]);
    assert_true(rch_pos_frame_given(&k));
    assert_int_equal(rch_pos_start(&k, s, n, 1), 0);
    for (unsigned j = RC_N_BASE; j < k.n_params; ++j)
        assert_true(fabs(k.x[j] - truth.x[j]) < 1e-6);
    free(s);
}

static void test_split_keeps_poses(void **state)
{
    (void)state;
    rc_model truth = nominal_with_tracker(2);
    set_truth(&truth);
    size_t n;
    rc_sample *pos = make(&n, &truth, 2, 20, 2);
    const size_t nl = 10, total = n + nl;
    rc_sample *s = calloc(total, sizeof *s); /* ten lengths first, then the positions */
    assert_non_null(s);
    for (size_t i = 0; i < nl; ++i)
        s[i].value = 500.0 + (double)i;
    memcpy(s + nl, pos, n * sizeof *s);
    assert_int_equal(rch_pos_count_lengths(s, total), nl);
    assert_int_equal(rch_pos_count_tracker(s, total), n);
    size_t *idx = malloc(total * sizeof *idx);
    assert_non_null(idx);
    rch_split(idx, total, 7);
    const size_t held = rch_pos_split(idx, s, total, 30);
    assert_true(held >= 30 && held < 30 + 6); /* a pose is 6 samples */
    uint8_t *side = calloc(total, 1), seen[20] = {0};
    for (size_t i = 0; i < total; ++i) {
        assert_int_equal(side[idx[i]], 0); /* a permutation */
        side[idx[i]] = (uint8_t)(i < held ? 1 : 2);
    }
    for (size_t i = nl; i < total; ++i) { /* every pose on one side */
        const unsigned p = (unsigned)s[i].t;
        if (!seen[p])
            seen[p] = side[i];
        assert_int_equal(seen[p], side[i]);
    }
    free(side);
    free(idx);
    free(s);
    free(pos);
}

static void test_errors_iso(void **state)
{
    (void)state;
    rc_model m = nominal_with_tracker(1);
    set_truth(&m);
    size_t n;
    rc_sample *base = make(&n, &m, 1, 2, 3); /* two poses, one target */
    rc_sample s[9];
    memcpy(s, base, 3 * sizeof *s);     /* pose 0, +0.1 mm in x */
    memcpy(s + 3, base, 3 * sizeof *s); /* pose 0 again, -0.1 mm in x */
    memcpy(s + 6, base + 3, 3 * sizeof *s);
    s[0].value += 0.1;
    s[3].value -= 0.1;
    s[6].value += 0.3; /* pose 1: (0.3, 0.4, 0) off */
    s[7].value += 0.4;
    rch_pos_err e;
    assert_int_equal(rch_pos_errors(&e, &m, s, 9), 0);
    assert_int_equal(e.points, 3);
    assert_true(fabs(e.rms_mm - sqrt((0.01 + 0.01 + 0.25) / 3.0)) < 1e-9);
    assert_true(fabs(e.mean_mm - (0.1 + 0.1 + 0.5) / 3.0) < 1e-9);
    assert_true(fabs(e.max_mm - 0.5) < 1e-9);
    assert_int_equal(e.repeated, 1);
    assert_true(fabs(e.ap_max_mm) < 1e-9); /* the repeats' mean is the model's point */
    assert_true(fabs(e.rp_max_mm - 0.1) < 1e-9); /* l = 0.1 both, s_l = 0 */
    free(base);
}

static void test_targets_grow(void **state)
{
    (void)state;
    rc_model m = nominal_with_tracker(1);
    set_truth(&m);
    unsigned nt = 0;
    const double t0[3] = {m.x[rch_pos_effect_at(&m, RC_EFF_TRACKER_TARGETS, NULL)],
                          m.x[rch_pos_effect_at(&m, RC_EFF_TRACKER_TARGETS, NULL) + 1],
                          m.x[rch_pos_effect_at(&m, RC_EFF_TRACKER_TARGETS, NULL) + 2]};
    const unsigned effects = m.n_effects;
    assert_int_equal(rch_pos_add_effects(&m, 3), 0);
    assert_int_equal(m.n_effects, effects); /* rebuilt, not added beside */
    const int kf = rch_pos_effect_at(&m, RC_EFF_TRACKER_TARGETS, &nt);
    assert_int_equal(nt, 9);
    assert_memory_equal(&m.x[kf], t0, sizeof t0);
    assert_true(m.x[kf + 3] == 0.0 && m.x[kf + 8] == 0.0);
    assert_int_equal(rch_pos_add_effects(&m, 2), 0); /* fewer: unchanged */
    rch_pos_effect_at(&m, RC_EFF_TRACKER_TARGETS, &nt);
    assert_int_equal(nt, 9);
}

static void test_evaluate_keeps_or_fits(void **state)
{
    (void)state;
    rc_model truth = nominal_with_tracker(2);
    set_truth(&truth);
    rch_pos p;
    memset(&p, 0, sizeof p);
    p.s = make(&p.n, &truth, 2, 15, 4);
    p.rows = p.n / 3;
    p.poses = 15;
    p.n_targets = 2;
    rc_model known = nominal_with_tracker(1); /* the frame and target 0 of the truth, target 1 unknown */
    set_truth(&known);
    rc_solve_work *w = malloc(sizeof *w);
    rch_pos_eval *r = malloc(sizeof *r);
    char err[128];
    assert_non_null(w);
    assert_non_null(r);
    assert_int_equal(rch_pos_evaluate(r, &known, &p, 0, w, err, sizeof err), 0);
    assert_false(r->frame_fitted);
    assert_int_equal(r->targets_known, 1);
    assert_int_equal(r->targets_fitted, 1);
    assert_true(r->err.rms_mm < 1e-5);
    rch_robot rob;
    rch_diag d;
    assert_int_equal(rch_robot_load(&rob, ROBOT, &d), 0); /* a model of no tracker: frame and targets fitted */
    assert_int_equal(rch_pos_evaluate(r, &rob.model, &p, 0, w, err, sizeof err), 0);
    assert_true(r->frame_fitted);
    assert_int_equal(r->targets_fitted, 2);
    assert_true(r->err.rms_mm < 1e-5);
    assert_true(fabs(r->frame[0] - 1200.0) < 1e-3 && fabs(r->frame[5] - 0.9) < 1e-6);
    free(w);
    free(r);
    free(p.s);
}

/* The reader: three samples a row, pose numbers shared by a pose's targets,
 * bad fields with line and column. */
static void test_load(void **state)
{
    (void)state;
    char path[] = "/tmp/rcal_test_positionsXXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs("q1,q2,q3,q4,q5,q6,target,x,y,z,sigma_mm\n"
          "0,10,-20,30,40,50,0,1000,-200,300,0.02\n"
          "0,10,-20,30,40,50,1,1010,-200,300,0.04\n"
          "5,10,-20,30,40,50,0,1001,-201,302,0.02\n",
          f);
    fclose(f);
    rch_pos p;
    rch_diag d;
    const char *paths[1] = {path};
    assert_int_equal(rch_pos_load(&p, paths, 1, 0.0, NULL, &d), 0);
    assert_int_equal(p.n, 9);
    assert_int_equal(p.rows, 3);
    assert_int_equal(p.poses, 2);
    assert_int_equal(p.n_targets, 2);
    assert_true(p.has_sigma && p.sigma_mm == 0.02);
    assert_true(p.s[3].t == 0.0 && p.s[6].t == 1.0 && p.s[4].target == 1 && p.s[5].sensor == RC_SENSOR_TRACKER_Z);
    assert_true(p.s[4].value == -200.0 && p.line[8] == 4);
    rch_pos_free(&p);
    f = fopen(path, "w");
    fputs("q1,q2,q3,q4,q5,q6,x,y,z\n0,10,-20,30,40,50,1000,-2x0,300\n", f);
    fclose(f);
    assert_int_equal(rch_pos_load(&p, paths, 1, 0.0, NULL, &d), -1);
    assert_int_equal(d.line, 2);
    assert_int_equal(d.col, 24);
    assert_non_null(strstr(d.msg, "field 'y'"));
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_start_recovers_frame), cmocka_unit_test(test_split_keeps_poses),
        cmocka_unit_test(test_errors_iso),           cmocka_unit_test(test_targets_grow),
        cmocka_unit_test(test_evaluate_keeps_or_fits), cmocka_unit_test(test_load),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
