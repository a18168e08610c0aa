/* SPDX-License-Identifier: MIT */
/* test_inputs_dequant.c - the default run's automatic dequantization
 * (rch_inputs_load): files written here from the tests' own kinematics
 * (rct_indep.h), not from the code under test.
 *   - joints rounded to 0.1 deg, x, y, z the FK of the unrounded angles:
 *     dequantized automatically, the joints recovered to the rounding's
 *     reach of the truth, the decision said;
 *   - the same file with no_dequantize: the joints as read;
 *   - x, y, z the FK of the rounded joints (nothing to recover), joints at
 *     full resolution (no display step), x, y, z of another kind (20 % of
 *     rows moved 3 mm: not the controller's FK): the joints as read, with the
 *     reason;
 *   - forced without x, y, z columns: refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "rch_calib_cfg.h"
#include "rch_inputs.h"
#include "rct_indep.h"
#include "rct_irb120.h"

#define N_ROWS 120
#define PI 3.14159265358979323846

enum { XYZ_FINE, XYZ_ROUNDED, XYZ_OTHER, JOINTS_FINE, NO_XYZ };

static double qtrue[N_ROWS][6];

/* A length file of N_ROWS poses into path; how its x, y, z and joints are made. */
static void write_file(const char *path, int kind)
{
    double dh[6][4];
    rct_irb120_dh(dh);
    rct_rng g = {11};
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, kind == NO_XYZ ? "q1,q2,q3,q4,q5,q6,L\n" : "x,y,z,q1,q2,q3,q4,q5,q6,L\n");
    const double e[3] = {400.0, -300.0, 50.0};
    for (int i = 0; i < N_ROWS; ++i) {
        double qf[6], p[3];
        for (int j = 0; j < 6; ++j) {
            const double lo = rct_irb120_lim_deg[j][0] * 0.7, hi = rct_irb120_lim_deg[j][1] * 0.7;
            qtrue[i][j] = lo + (hi - lo) * rct_u01(&g);
            qf[j] = kind == JOINTS_FINE ? qtrue[i][j] : 0.1 * round(qtrue[i][j] / 0.1);
        }
        double qr[6];
        for (int j = 0; j < 6; ++j)
            qr[j] = (kind == XYZ_ROUNDED ? qf[j] : qtrue[i][j]) * PI / 180.0;
        rct_flange(p, dh, qr);
        if (kind == XYZ_OTHER && i % 5 == 0)
            p[0] += 3.0;
        double qt[6];
        for (int j = 0; j < 6; ++j)
            qt[j] = qtrue[i][j] * PI / 180.0;
        double pt[3];
        rct_flange(pt, dh, qt);
        const double len = rct_dist(pt, e);
        if (kind != NO_XYZ)
            fprintf(f, "%.4f,%.4f,%.4f,", p[0], p[1], p[2]);
        fprintf(f, kind == JOINTS_FINE ? "%.7f,%.7f,%.7f,%.7f,%.7f,%.7f,%.4f\n" : "%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%.4f\n",
                qf[0], qf[1], qf[2], qf[3], qf[4], qf[5], len);
    }
    assert_int_equal(fclose(f), 0);
}

static int load(rch_inputs *in, int kind, int forced, int off, rch_diag *d)
{
    char path[64];
    snprintf(path, sizeof path, "dequant_auto_%d_%ld.csv", kind, (long)getpid());
    write_file(path, kind);
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.data_path = path;
    cfg.robot_path = RCAL_SOURCE_DIR "/data/irb120.json";
    cfg.dequantize = forced;
    cfg.no_dequantize = off;
    const int rc = rch_inputs_load(in, &cfg, d);
    unlink(path);
    return rc;
}

static void test_auto_applied(void **state)
{
    (void)state;
    static rch_inputs in;
    rch_diag d;
    assert_int_equal(load(&in, XYZ_FINE, 0, 0, &d), 0);
    assert_true(in.have_dequant);
    assert_true(in.dequant.automatic);
    assert_true(fabs(in.dequant.q_step_deg - 0.1) < 1e-12);
    assert_int_equal(in.dequant.n_refused, 0);
    assert_non_null(strstr(in.dequant.why, "automatic: the joints sit on a 0.1 deg step"));
    double worst = 0.0; /* the recovered joints against the truth: within the rounding, and closer */
    for (size_t i = 0; i < in.data.n; ++i)
        for (int j = 0; j < 6; ++j)
            worst = fmax(worst, fabs(in.data.s[i].q_rad[j] * 180.0 / PI - qtrue[i][j]));
    print_message("automatic: %zu rows corrected, |FK - xyz| %.4f -> %.6f mm, worst joint error %.4f deg\n",
                  in.dequant.n_corrected, in.dequant.fk_rms_before_mm, in.dequant.fk_rms_after_mm, worst);
    assert_true(worst <= 0.06);
    rch_inputs_free(&in);

    assert_int_equal(load(&in, XYZ_FINE, 0, 1, &d), 0); /* --no-dequantize-joints */
    assert_false(in.have_dequant);
    for (size_t i = 0; i < in.data.n; ++i) /* the joints as written: on the 0.1 deg grid */
        for (int j = 0; j < 6; ++j) {
            const double u = in.data.s[i].q_rad[j] * 180.0 / PI / 0.1;
            assert_true(fabs(u - round(u)) < 1e-6);
        }
    rch_inputs_free(&in);
}

static void test_auto_kept(void **state)
{
    (void)state;
    static rch_inputs in;
    rch_diag d;
    static const struct {
        int kind;
        const char *why;
    } cases[] = {
        {XYZ_ROUNDED, "agree with the rounded joints already"},
        {JOINTS_FINE, "no display step"},
        {XYZ_OTHER, "not the nominal FK"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        assert_int_equal(load(&in, cases[c].kind, 0, 0, &d), 0);
        print_message("kind %d: %s\n", cases[c].kind, in.dequant.why);
        assert_false(in.have_dequant);
        assert_int_equal(in.data.n, N_ROWS); /* no row dropped */
        assert_non_null(strstr(in.dequant.why, cases[c].why));
        if (cases[c].kind != JOINTS_FINE) /* the joints as read */
            for (int j = 0; j < 6; ++j)
                assert_true(fabs(in.data.s[7].q_rad[j] * 180.0 / PI - 0.1 * round(qtrue[7][j] / 0.1)) < 1e-9);
        rch_inputs_free(&in);
    }
    assert_int_equal(load(&in, NO_XYZ, 0, 0, &d), 0); /* nothing to recover from: read as written */
    assert_false(in.have_dequant);
    rch_inputs_free(&in);
    assert_int_equal(load(&in, NO_XYZ, 1, 0, &d), -1); /* forced: refused, saying why */
    assert_non_null(strstr(d.msg, "needs the x, y, z columns"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_auto_applied),
        cmocka_unit_test(test_auto_kept),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
