/* SPDX-License-Identifier: MIT */
/* test_jumps.c - length jumps found at the right rows with the right sizes,
 * and no jump invented on data without one; joint angles recovered from
 * reported positions. Data from tests/common/rct_indep.h (own FK, own
 * random numbers); the noise level, the jump rows and sizes are drawn here
 * and never passed to the code under test. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rc_solve.h"
#include "rch_start.h"
#include "rch_dequant.h"
#include "rch_jumps.h"
#include "rch_robot.h"
#include "rct_indep.h"

static rch_robot nom;
static rc_solve_work *W;

static int setup(void **state)
{
    (void)state;
    rch_diag d;
    W = malloc(sizeof *W);
    return (W && rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d) == 0) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    free(W);
    return 0;
}

/* A robot with random DH errors; n samples; n_jumps jumps at random rows. */
static void make(rc_sample *s, size_t n, rct_rng *g, double noise, unsigned n_jumps, size_t *at, double *size)
{
    double dh[6][4];
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            dh[i][k] = nom.model.x[4 * i + k] + (k < 2 ? 0.5 * rct_gauss(g) : 1e-3 * rct_gauss(g));
    double e[3] = {250 + 80 * rct_gauss(g), -450 + 80 * rct_gauss(g), 30 * rct_gauss(g)};
    for (unsigned k = 0; k < n_jumps; ++k) {
        int ok;
        do { /* rows at least 20 apart and 20 from the ends */
            at[k] = 20 + (size_t)(rct_u01(g) * (double)(n - 40));
            ok = 1;
            for (unsigned j = 0; j < k; ++j)
                ok &= at[k] > at[j] + 20 || at[j] > at[k] + 20;
        } while (!ok);
        double mag = noise * (8.0 + 40.0 * rct_u01(g));
        size[k] = rct_u01(g) < 0.5 ? -mag : mag;
    }
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < 6; ++j) {
            double lo = nom.model.q_min_rad[j] * 0.8, hi = nom.model.q_max_rad[j] * 0.8;
            s[i].q_rad[j] = lo + (hi - lo) * rct_u01(g);
        }
        double p[3];
        rct_flange(p, dh, s[i].q_rad);
        s[i].value = rct_dist(p, e) + noise * rct_gauss(g);
        for (unsigned k = 0; k < n_jumps; ++k)
            if (i >= at[k])
                s[i].value += size[k];
        s[i].t = (double)i / (double)(n - 1);
        s[i].group = 0;
        s[i].outlet = 0;
    }
}

static void test_finds_jumps(void **state)
{
    (void)state;
    rct_rng g = {2024};
    unsigned exact = 0, total = 0, seeds = 20;
    for (unsigned seed = 0; seed < seeds; ++seed) {
        size_t n = 400, at[3];
        double size[3], noise = 0.002 + 0.05 * rct_u01(&g);
        unsigned nj = 1 + (unsigned)(rct_u01(&g) * 3.0);
        rc_sample *s = calloc(n, sizeof *s);
        make(s, n, &g, noise, nj, at, size);
        rc_model start;
        rch_diag d;
        assert_int_equal(rch_calib_start(&start, W, &nom, s, n, &d), 0);
        rch_jumps j;
        char err[200];
        assert_int_equal(rch_jumps_find(&j, &start, NULL, s, n, NULL, W, err, sizeof err), 0);
        assert_int_equal(j.n_jumps, nj);
        for (unsigned k = 0; k < nj; ++k) {
            /* match each true jump to a found one */
            unsigned best = 0;
            for (unsigned q = 1; q < j.n_jumps; ++q)
                if (labs((long)j.at[q] - (long)at[k]) < labs((long)j.at[best] - (long)at[k]))
                    best = q;
            total++;
            exact += j.at[best] == at[k];
            assert_true(labs((long)j.at[best] - (long)at[k]) <= 2);
            assert_true(fabs(j.size_mm[best] - size[k]) <= 4.0 * j.se_mm[best] + 1e-9);
        }
        assert_true(j.rms_after_mm < 1.5 * noise);
        free(s);
    }
    print_message("%u of %u jumps found at the exact row, all within 2 rows and 4 standard errors\n", exact, total);
    assert_true(exact * 10 >= total * 9);
}

static void test_no_false_jumps(void **state)
{
    (void)state;
    rct_rng g = {77};
    unsigned false_alarms = 0, seeds = 20;
    for (unsigned seed = 0; seed < seeds; ++seed) {
        size_t n = 300, at[1];
        double size[1], noise = 0.002 + 0.05 * rct_u01(&g);
        rc_sample *s = calloc(n, sizeof *s);
        make(s, n, &g, noise, 0, at, size);
        rc_model start;
        rch_diag d;
        assert_int_equal(rch_calib_start(&start, W, &nom, s, n, &d), 0);
        rch_jumps j;
        char err[200];
        assert_int_equal(rch_jumps_find(&j, &start, NULL, s, n, NULL, W, err, sizeof err), 0);
        false_alarms += j.n_jumps > 0;
        free(s);
    }
    print_message("controls: %u of %u data sets without a jump got one\n", false_alarms, seeds);
    assert_true(false_alarms <= 1);
}

static void test_dequant(void **state)
{
    (void)state;
    rct_rng g = {5};
    size_t n = 200;
    rc_sample *s = calloc(n, sizeof *s);
    double (*xyz)[3] = calloc(n, sizeof *xyz), dh[6][4], worst_before = 0, worst_after = 0;
    const double step = 0.1 * 3.14159265358979323846 / 180.0;
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            dh[i][k] = nom.model.x[4 * i + k];
    double qtrue[200][6];
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < 6; ++j) {
            double lo = nom.model.q_min_rad[j] * 0.8, hi = nom.model.q_max_rad[j] * 0.8;
            qtrue[i][j] = lo + (hi - lo) * rct_u01(&g);
            s[i].q_rad[j] = step * round(qtrue[i][j] / step); /* the file's rounding */
        }
        rct_flange(xyz[i], dh, qtrue[i]);
        for (int c = 0; c < 3; ++c)
            xyz[i][c] = 0.1 * round(xyz[i][c] / 0.1); /* reported at 0.1 mm */
    }
    xyz[17][2] += 99.0; /* a typo */
    uint8_t *ref = calloc(n, 1);
    rch_dequant_result r;
    assert_int_equal(rch_dequant(&r, ref, s, n, (const double(*)[3])xyz, &nom.model, 0), 0);
    assert_int_equal(ref[17], 1);
    print_message("dequantize: %zu of %zu refused\n", r.n_refused, n);
    assert_true(r.n_refused <= n / 10);
    for (size_t i = 0; i < n; ++i) {
        if (ref[i])
            continue;
        double pb[3], pa[3], qr[6];
        for (int j = 0; j < 6; ++j)
            qr[j] = step * round(qtrue[i][j] / step);
        rct_flange(pb, dh, qr);
        rct_flange(pa, dh, s[i].q_rad);
        double tp[3];
        rct_flange(tp, dh, qtrue[i]);
        worst_before = fmax(worst_before, rct_dist(pb, tp));
        worst_after = fmax(worst_after, rct_dist(pa, tp));
    }
    print_message("dequantize: flange error of the rounded angles max %.3f mm, recovered %.3f mm; %zu refused\n",
                  worst_before, worst_after, r.n_refused);
    assert_true(worst_after < 0.15 && worst_after < worst_before / 4);
    free(s);
    free(xyz);
    free(ref);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_finds_jumps),
        cmocka_unit_test(test_no_false_jumps),
        cmocka_unit_test(test_dequant),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
