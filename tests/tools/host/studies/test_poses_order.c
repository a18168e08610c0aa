/* SPDX-License-Identifier: MIT */
/* test_poses_order.c - a plan ordered for travel (rch_poses_order, issue 48
 * item 5): the result is a permutation of the rows (every row kept, its
 * outlet and target, its robot pose by FK), a wrapping joint differs by
 * whole turns only and stays inside the limits less the margin, the other
 * joints are unchanged, the rows of one pose on each plate point stay
 * together, the travel (recomputed here by the test's own loop) is not worse
 * than the input order and below 0.6 of a random order, and a pose whose q6
 * alternates between +-350 deg takes the branch that avoids the full turn. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rc_model.h"
#include "rch_poses.h"
#include "rct_irb120.h"

#define PI 3.14159265358979323846
#define MARGIN_DEG 5.0

static void irb120(rc_model *m)
{
    double dh[6][4];
    const double enc[3] = {250, -460, 10};
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(m, (const double(*)[4])dh, enc), RC_OK);
    for (int j = 0; j < RC_NJ; ++j) {
        m->q_min_rad[j] = rct_irb120_lim_deg[j][0] * PI / 180.0;
        m->q_max_rad[j] = rct_irb120_lim_deg[j][1] * PI / 180.0;
    }
}

static double urand(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* n_pose random poses inside the limits less the margin, each on n_t plate points, from n_o outlets (every
 * pose from each, outlet-major, the points of a pose consecutive: the planner's layout). */
static rc_sample *random_plan(size_t *n, const rc_model *m, size_t n_pose, unsigned n_o, unsigned n_t,
                              unsigned long long seed)
{
    rc_sample *r = calloc(n_pose * n_o * n_t, sizeof *r);
    double(*q)[RC_NJ] = malloc(n_pose * sizeof *q);
    assert_non_null(r);
    assert_non_null(q);
    for (size_t i = 0; i < n_pose; ++i)
        for (int j = 0; j < RC_NJ; ++j) {
            const double lo = m->q_min_rad[j] + MARGIN_DEG * PI / 180, hi = m->q_max_rad[j] - MARGIN_DEG * PI / 180;
            q[i][j] = lo + (hi - lo) * urand(&seed);
        }
    *n = 0;
    for (unsigned k = 0; k < n_o; ++k)
        for (size_t i = 0; i < n_pose; ++i)
            for (unsigned t = 0; t < n_t; ++t) {
                memcpy(r[*n].q_rad, q[i], sizeof q[i]);
                r[*n].outlet = (uint8_t)k;
                r[*n].target = (uint8_t)t;
                r[*n].value = (double)*n; /* a tag: which input row this is */
                ++*n;
            }
    free(q);
    return r;
}

/* The test's own travel: per (outlet, target) session, from home (q = 0 here: inside every IRB120 limit),
 * the largest joint move per move, degrees. */
static double travel(const rc_sample *r, size_t n)
{
    double sum = 0.0;
    for (unsigned o = 0; o < 8; ++o)
        for (unsigned t = 0; t < 8; ++t) {
            double prev[RC_NJ] = {0};
            for (size_t i = 0; i < n; ++i) {
                if (r[i].outlet != o || r[i].target != t)
                    continue;
                double mx = 0.0;
                for (int j = 0; j < RC_NJ; ++j)
                    mx = fmax(mx, fabs(r[i].q_rad[j] - prev[j]));
                sum += mx * 180.0 / PI;
                memcpy(prev, r[i].q_rad, sizeof prev);
            }
        }
    return sum;
}

/* out is a permutation of in (by the tag in len_mm), each row's pose the same. */
static void check_permutation(const rc_sample *in, const rc_sample *out, size_t n, const rc_model *m)
{
    unsigned char *seen = calloc(n, 1);
    assert_non_null(seen);
    for (size_t i = 0; i < n; ++i) {
        const size_t k = (size_t)out[i].value;
        assert_true(k < n);
        assert_false(seen[k]);
        seen[k] = 1;
        assert_int_equal(out[i].outlet, in[k].outlet);
        assert_int_equal(out[i].target, in[k].target);
        for (int j = 0; j < RC_NJ; ++j) {
            const double turns = (out[i].q_rad[j] - in[k].q_rad[j]) / (2.0 * PI);
            assert_true(fabs(turns - round(turns)) < 1e-9);
            if (m->q_max_rad[j] - m->q_min_rad[j] - 2 * MARGIN_DEG * PI / 180 <= 2.0 * PI)
                assert_true(out[i].q_rad[j] == in[k].q_rad[j]); /* no other branch within its range */
            assert_true(out[i].q_rad[j] >= m->q_min_rad[j] + MARGIN_DEG * PI / 180 - 1e-9);
            assert_true(out[i].q_rad[j] <= m->q_max_rad[j] - MARGIN_DEG * PI / 180 + 1e-9);
        }
        double p0[3], r0[9], p1[3], r1[9];
        rc_fk(p0, r0, m, in[k].q_rad);
        rc_fk(p1, r1, m, out[i].q_rad);
        for (int c = 0; c < 3; ++c)
            assert_true(fabs(p0[c] - p1[c]) < 1e-9);
        for (int c = 0; c < 9; ++c)
            assert_true(fabs(r0[c] - r1[c]) < 1e-12);
    }
    free(seen);
}

static void check_order(size_t n_pose, unsigned n_o, unsigned n_t, unsigned long long seed)
{
    rc_model m;
    rch_poses_travel tr;
    rch_diag d;
    size_t n;
    irb120(&m);
    rc_sample *in = random_plan(&n, &m, n_pose, n_o, n_t, seed);
    rc_sample *out = malloc(n * sizeof *out);
    assert_non_null(out);
    memcpy(out, in, n * sizeof *out);
    assert_int_equal(rch_poses_order(out, n, &m, MARGIN_DEG, &tr, &d), 0);
    check_permutation(in, out, n, &m);
    assert_true(fabs(tr.before_deg - travel(in, n)) < 1e-6 * tr.before_deg);
    assert_true(fabs(tr.after_deg - travel(out, n)) < 1e-6 * tr.before_deg);
    assert_true(fabs(tr.after_deg - rch_poses_travel_deg(out, n, &m, MARGIN_DEG)) < 1e-9 * tr.before_deg);
    assert_true(tr.after_deg <= tr.before_deg);
    assert_true(tr.after_deg <= 0.6 * tr.before_deg); /* a random order: a tour is far shorter */
    /* the rows of one pose stay together, its points in their order, and every point follows the same tour */
    for (size_t i = 0; i < n; i += n_t)
        for (unsigned t = 0; t < n_t; ++t) {
            assert_int_equal(out[i + t].target, t);
            assert_memory_equal(out[i + t].q_rad, out[i].q_rad, sizeof out[i].q_rad);
        }
    /* ordering an ordered plan does not make it worse */
    rch_poses_travel tr2;
    rc_sample *again = malloc(n * sizeof *again);
    assert_non_null(again);
    memcpy(again, out, n * sizeof *again);
    assert_int_equal(rch_poses_order(again, n, &m, MARGIN_DEG, &tr2, &d), 0);
    assert_true(fabs(tr2.before_deg - tr.after_deg) < 1e-9 * tr.before_deg);
    assert_true(tr2.after_deg <= tr2.before_deg);
    check_permutation(in, again, n, &m);
    free(again);
    free(in);
    free(out);
}

static void test_one_outlet(void **st)
{
    (void)st;
    check_order(60, 1, 1, 1);
    check_order(300, 1, 1, 2);
}

static void test_outlets_and_points(void **st)
{
    (void)st;
    check_order(60, 3, 1, 3);
    check_order(40, 2, 3, 4);
}

/* q6 alternating between +350 and -350 deg (the same wrist twice 20 deg apart): the tour takes the branch
 * that moves 20 deg, never the full turn; without a wrapping joint the joints stay as they were. */
static void test_branch(void **st)
{
    (void)st;
    rc_model m;
    rch_poses_travel tr;
    rch_diag d;
    irb120(&m);
    rc_sample r[8];
    memset(r, 0, sizeof r);
    for (int i = 0; i < 8; ++i) {
        r[i].q_rad[0] = (10.0 * i) * PI / 180.0;
        r[i].q_rad[5] = (i % 2 ? -350.0 : 350.0) * PI / 180.0;
        r[i].value = i;
    }
    rc_sample in[8];
    memcpy(in, r, sizeof r);
    assert_int_equal(rch_poses_order(r, 8, &m, MARGIN_DEG, &tr, &d), 0);
    check_permutation(in, r, 8, &m);
    for (int i = 1; i < 8; ++i) {
        double mx = 0.0;
        for (int j = 0; j < RC_NJ; ++j)
            mx = fmax(mx, fabs(r[i].q_rad[j] - r[i - 1].q_rad[j]) * 180.0 / PI);
        assert_true(mx < 20.0 + 1e-6); /* q1 steps 10 deg, q6 at most 20 */
    }
    assert_true(tr.after_deg < 0.2 * tr.before_deg);
    /* q6 limited to +-180: no other branch, so no joint changes */
    m.q_min_rad[5] = -PI;
    m.q_max_rad[5] = PI;
    for (int i = 0; i < 8; ++i)
        in[i].q_rad[5] = r[i].q_rad[5] = (i % 2 ? -170.0 : 170.0) * PI / 180.0;
    memcpy(r, in, sizeof r);
    assert_int_equal(rch_poses_order(r, 8, &m, MARGIN_DEG, &tr, &d), 0);
    check_permutation(in, r, 8, &m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_outlet),
        cmocka_unit_test(test_outlets_and_points),
        cmocka_unit_test(test_branch),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
