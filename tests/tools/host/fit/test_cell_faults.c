/* SPDX-License-Identifier: MIT */
/* test_cell_faults.c - the commonest slips of a real cell (issue 47) never
 * become a model in silence, on cable files written here from the tests'
 * own kinematics (rct_indep.h): one outlet, the IRB120 with 0.3 mm / 0.05
 * deg DH errors, 0.01 mm noise, 600 poses in acquisition order. Judged by
 * behaviour: the flange of the model against the true robot's over 300 new
 * poses after the best rigid motion (no sensor sees the cell frame).
 *   - clean: the judge passes it (noise near the sensor's floor), no length
 *     offset or drift fitted;
 *   - every length 5 mm short (a display zeroed off the outlet), and a 2 mm
 *     drift over the run: the effect fitted and said, the flange within 2 x
 *     the clean model's error (it was 2.14 and 1.05 mm);
 *   - a 3 mm jump at row 300 plus a 10 mm misread at row 450: the jump
 *     found, the row named, the flange within 2 x clean;
 *   - q5 in another controller's sign convention: the model is not written,
 *     the message names q5 and the fix; --force writes it;
 *   - a plate's three points told in another order than the target column's:
 *     not written, the message names the order. */
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

#include "rch_calib.h"
#include "rct_indep.h"
#include "rct_irb120.h"
#include "sens_gen.h"

#define PI 3.14159265358979323846
#define N_ROWS 600
#define N_EVAL 300

enum { F_CLEAN, F_OFFSET, F_DRIFT, F_JUMP_MISREAD, F_Q5_SIGN, F_PLATE_ORDER };

static double truth[6][4];
static const double outlet[3] = {650.0, -380.0, 40.0};
static double plate[3][3];

static void random_q(double q[6], rct_rng *g)
{
    for (int j = 0; j < 6; ++j) {
        const double lo = rct_irb120_lim_deg[j][0] * 0.8, hi = rct_irb120_lim_deg[j][1] * 0.8;
        q[j] = (lo + (hi - lo) * rct_u01(g)) * PI / 180.0;
    }
}

static void true_point(double p[3], const double q[6], const double t[3])
{
    double o[3], R[9];
    rct_pose(o, R, truth, q);
    for (int r = 0; r < 3; ++r)
        p[r] = o[r] + R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2];
}

/* The file of fault f at path. */
static void write_file(const char *path, int fault)
{
    rct_rng g = {29};
    rct_irb120_dh(truth);
    for (int i = 0; i < 6; ++i) {
        truth[i][0] += 0.3 * rct_gauss(&g);
        truth[i][1] += 0.3 * rct_gauss(&g);
        truth[i][2] += 0.05 * PI / 180.0 * rct_gauss(&g);
        truth[i][3] += 0.05 * PI / 180.0 * rct_gauss(&g);
    }
    for (int k = 0; k < 3; ++k) {
        plate[k][0] = 60.0 * cos(2.0 * PI * k / 3.0);
        plate[k][1] = 60.0 * sin(2.0 * PI * k / 3.0);
        plate[k][2] = 20.0;
    }
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    const int points = fault == F_PLATE_ORDER ? 3 : 1;
    fprintf(f, points > 1 ? "q1,q2,q3,q4,q5,q6,L,target\n" : "q1,q2,q3,q4,q5,q6,L\n");
    static const double zero[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < N_ROWS / points; ++i) {
        double q[6], p[3];
        random_q(q, &g);
        for (int k = 0; k < points; ++k) {
            true_point(p, q, points > 1 ? plate[k] : zero);
            const int row = i * points + k;
            double L = rct_dist(p, outlet) + 0.01 * rct_gauss(&g);
            if (fault == F_OFFSET)
                L -= 5.0;
            if (fault == F_DRIFT)
                L += 2.0 * row / (N_ROWS - 1.0);
            if (fault == F_JUMP_MISREAD)
                L += (row >= 300 ? 3.0 : 0.0) + (row == 450 ? 10.0 : 0.0);
            const double q5 = fault == F_Q5_SIGN ? -q[4] : q[4];
            fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f", q[0] * 180.0 / PI, q[1] * 180.0 / PI, q[2] * 180.0 / PI,
                    q[3] * 180.0 / PI, q5 * 180.0 / PI, q[5] * 180.0 / PI, L);
            if (points > 1)
                fprintf(f, ",%d", k);
            fprintf(f, "\n");
        }
    }
    assert_int_equal(fclose(f), 0);
}

/* rch_calib_run on the file of fault f; the plate's points told in the
 * order `order` (NULL: none told). */
static int run(rch_calib_result *r, int fault, const int *order, char *path, size_t len, rch_diag *d)
{
    snprintf(path, len, "cell_fault_%d_%ld.csv", fault, (long)getpid());
    write_file(path, fault);
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.data_path = path;
    cfg.robot_path = RCAL_SOURCE_DIR "/data/irb120.json";
    if (order) {
        cfg.n_cable_points = 3;
        for (unsigned k = 0; k < 3; ++k)
            memcpy(cfg.cable_points_mm[k], plate[order[k]], sizeof plate[k]);
    }
    return rch_calib_run(r, &cfg, d);
}

/* RMS (mm) of the model's flange against the true one over N_EVAL new
 * poses after the best rigid motion. */
static double flange_rms(const rc_model *fit)
{
    static double a[N_EVAL][3], b[N_EVAL][3];
    static const double zero[3] = {0.0, 0.0, 0.0};
    rct_rng g = {404};
    rc_model m = *fit;
    m.n_effects = 0; /* the flange centre: no attachment, no length-side effect */
    for (int i = 0; i < N_EVAL; ++i) {
        double q[6];
        random_q(q, &g);
        rc_fk(a[i], NULL, &m, q);
        true_point(b[i], q, zero);
    }
    double R[9], T[3], ss = 0.0;
    sg_kabsch(R, T, (const double(*)[3])a, (const double(*)[3])b, N_EVAL, NULL);
    for (int i = 0; i < N_EVAL; ++i)
        for (int r = 0; r < 3; ++r) {
            const double v = R[3 * r] * a[i][0] + R[3 * r + 1] * a[i][1] + R[3 * r + 2] * a[i][2] + T[r] - b[i][r];
            ss += v * v;
        }
    return sqrt(ss / N_EVAL);
}

static rch_calib_result res;
static double clean_mm;

static void test_clean(void **state)
{
    (void)state;
    char path[80];
    rch_diag d;
    assert_int_equal(run(&res, F_CLEAN, NULL, path, sizeof path, &d), 0);
    unlink(path);
    assert_true(res.judge.done);
    assert_false(res.judge.beyond);
    assert_false(res.judge.worse_than_nominal);
    assert_true(res.judge.ratio < 2.0);
    assert_true(res.sys.tested);
    assert_false(res.sys.offset_fitted);
    assert_false(res.sys.drift_fitted);
    clean_mm = flange_rms(&res.model);
    assert_true(clean_mm < 0.05);
}

static void expect_fitted(int fault)
{
    char path[80];
    rch_diag d;
    assert_int_equal(run(&res, fault, NULL, path, sizeof path, &d), 0);
    unlink(path);
    assert_false(res.judge.beyond);
    const double e = flange_rms(&res.model);
    print_message("fault %d: flange %.4f mm from the truth (clean %.4f)\n", fault, e, clean_mm);
    assert_true(e < 2.0 * clean_mm + 0.005);
}

static void test_offset_fitted(void **state)
{
    (void)state;
    expect_fitted(F_OFFSET);
    assert_true(res.sys.offset_fitted);
    assert_false(res.sys.drift_fitted);
}

static void test_drift_fitted(void **state)
{
    (void)state;
    expect_fitted(F_DRIFT);
    assert_true(res.sys.drift_fitted);
    assert_false(res.sys.offset_fitted);
}

static void test_jump_and_misread(void **state)
{
    (void)state;
    expect_fitted(F_JUMP_MISREAD);
    assert_true(res.have_jumps);
    assert_true(res.jumps.n_jumps >= 1);
    int named = 0;
    for (unsigned k = 0; k < res.screen.n_named; ++k)
        named |= res.screen.row[k].line == 452; /* row 450 after the header */
    assert_true(named);
}

static void test_q5_sign_not_written(void **state)
{
    (void)state;
    char path[80];
    rch_diag d;
    assert_int_equal(run(&res, F_Q5_SIGN, NULL, path, sizeof path, &d), 0);
    unlink(path);
    assert_true(res.judge.beyond);
    assert_true(res.judge.cause_found);
    assert_non_null(strstr(res.judge.cause, "q5"));
    char out[80];
    snprintf(out, sizeof out, "cell_fault_model_%ld.json", (long)getpid());
    assert_int_not_equal(rch_calib_save_model(&res, out, &d), 0);
    assert_non_null(strstr(d.msg, "not written"));
    assert_non_null(strstr(d.msg, "negate the q5"));
    assert_int_not_equal(access(out, F_OK), 0);
    res.cfg.force = 1;
    assert_int_equal(rch_calib_save_model(&res, out, &d), 0);
    unlink(out);
}

static void test_plate_order_not_written(void **state)
{
    (void)state;
    char path[80];
    rch_diag d;
    static const int reversed[3] = {0, 2, 1};
    assert_int_equal(run(&res, F_PLATE_ORDER, reversed, path, sizeof path, &d), 0);
    unlink(path);
    assert_true(res.judge.beyond);
    assert_true(res.judge.cause_found);
    assert_non_null(strstr(res.judge.cause, "order"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clean),
        cmocka_unit_test(test_offset_fitted),
        cmocka_unit_test(test_drift_fitted),
        cmocka_unit_test(test_jump_and_misread),
        cmocka_unit_test(test_q5_sign_not_written),
        cmocka_unit_test(test_plate_order_not_written),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
