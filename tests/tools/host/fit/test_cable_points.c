/* SPDX-License-Identifier: MIT */
/* test_cable_points.c - the cable hooked in turn on three points of a tool
 * plate (RC_EFF_CABLE_POINTS, `rcal calibrate --cable-point`), on cable
 * files written here from the tests' own kinematics (rct_indep.h): one
 * outlet, the IRB120 with 0.3 mm / 0.05 deg DH errors, 0.01 mm noise, the
 * plate's points off their drawing by 0.02 mm (sd; the prior says 0.05).
 *   - three points, 120 poses each: the tool point (50, 0, 150) of the
 *     calibrated model within 0.1 mm RMS of the true robot's over 300 new
 *     poses (after the best rigid motion: no sensor sees the cell frame),
 *     and at most a third of what the same 360 rows with the cable on one
 *     point (the default attachment vector) give;
 *   - a target column without --cable-point, a point beyond those given, a
 *     point given but never used: refused, naming the file and line. */
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
#include "rch_comp.h"
#include "rct_indep.h"
#include "rct_irb120.h"
#include "sens_gen.h"

#define PI 3.14159265358979323846
#define N_ROWS 360
#define N_EVAL 300

static double truth[6][4];
static double plate_nom[3][3], plate_true[3][3];
static const double outlet[3] = {650.0, -380.0, 40.0};
static const double tcp[3] = {50.0, 0.0, 150.0};

static void random_q(double q[6], rct_rng *g)
{
    for (int j = 0; j < 6; ++j) {
        const double lo = rct_irb120_lim_deg[j][0] * 0.8, hi = rct_irb120_lim_deg[j][1] * 0.8;
        q[j] = (lo + (hi - lo) * rct_u01(g)) * PI / 180.0;
    }
}

/* The true robot's point t (flange frame) at q. */
static void true_point(double p[3], const double q[6], const double t[3])
{
    double o[3], R[9];
    rct_pose(o, R, truth, q);
    for (int r = 0; r < 3; ++r)
        p[r] = o[r] + R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2];
}

/* points 3: every pose on each point in turn (N_ROWS / 3 poses); points 1:
 * N_ROWS poses on point 0, no target column. max_target: the largest
 * target written (a wrong file when above 2). */
static void write_file(const char *path, int points, int max_target)
{
    rct_rng g = {11};
    rct_irb120_dh(truth);
    for (int i = 0; i < 6; ++i) {
        truth[i][0] += 0.3 * rct_gauss(&g);
        truth[i][1] += 0.3 * rct_gauss(&g);
        truth[i][2] += 0.05 * PI / 180.0 * rct_gauss(&g);
        truth[i][3] += 0.05 * PI / 180.0 * rct_gauss(&g);
    }
    for (int k = 0; k < 3; ++k) {
        plate_nom[k][0] = 60.0 * cos(2.0 * PI * k / 3.0);
        plate_nom[k][1] = 60.0 * sin(2.0 * PI * k / 3.0);
        plate_nom[k][2] = 20.0;
        for (int c = 0; c < 3; ++c)
            plate_true[k][c] = plate_nom[k][c] + 0.02 * rct_gauss(&g);
    }
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, points > 1 ? "q1,q2,q3,q4,q5,q6,L,target\n" : "q1,q2,q3,q4,q5,q6,L\n");
    for (int i = 0; i < N_ROWS / points; ++i) {
        double q[6], p[3];
        random_q(q, &g);
        for (int k = 0; k < points; ++k) {
            true_point(p, q, plate_true[k]);
            const int tg = k == 2 && i == 7 ? max_target : k;
            fprintf(f, "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f", q[0] * 180.0 / PI, q[1] * 180.0 / PI, q[2] * 180.0 / PI,
                    q[3] * 180.0 / PI, q[4] * 180.0 / PI, q[5] * 180.0 / PI, rct_dist(p, outlet) + 0.01 * rct_gauss(&g));
            if (points > 1)
                fprintf(f, ",%d", tg);
            fprintf(f, "\n");
        }
    }
    assert_int_equal(fclose(f), 0);
}

/* rch_calib_run on a file of `points` (see write_file) with n_told points
 * told; rc and the message. */
static int run(rch_calib_result *r, int points, int max_target, unsigned n_told, rch_diag *d)
{
    char path[64];
    snprintf(path, sizeof path, "cable_points_%ld.csv", (long)getpid());
    write_file(path, points, max_target);
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.data_path = path;
    cfg.robot_path = RCAL_SOURCE_DIR "/data/irb120.json";
    cfg.test_fraction = 0.0;
    cfg.n_cable_points = n_told;
    for (unsigned k = 0; k < n_told; ++k)
        memcpy(cfg.cable_points_mm[k], plate_nom[k], sizeof plate_nom[k]);
    const int rc = rch_calib_run(r, &cfg, d);
    unlink(path);
    return rc;
}

/* RMS distance (mm) between the model's point pt (flange frame) and the
 * true one over N_EVAL new poses, after the best rigid motion between the
 * two point sets. */
static double point_rms(const rc_model *fit, const double pt[3])
{
    static double a[N_EVAL][3], b[N_EVAL][3];
    rc_model m;
    rch_comp_point_model(&m, fit, pt);
    rct_rng g = {404};
    for (int i = 0; i < N_EVAL; ++i) {
        double q[6];
        random_q(q, &g);
        rc_fk(a[i], NULL, &m, q);
        true_point(b[i], q, pt);
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

static double tcp_rms(const rc_model *fit)
{
    return point_rms(fit, tcp);
}

static void test_three_points_see_the_orientation(void **state)
{
    (void)state;
    static rch_calib_result r3, r1;
    rch_diag d;
    if (run(&r3, 3, 2, 3, &d) != 0)
        fail_msg("calibrate, 3 points: %s", d.msg);
    if (run(&r1, 1, 0, 0, &d) != 0)
        fail_msg("calibrate, 1 point: %s", d.msg);
    const double e3 = tcp_rms(&r3.model), e1 = tcp_rms(&r1.model);
    int pf = -1;
    for (unsigned e = 0; e < r3.model.n_effects; ++e)
        if (r3.model.effects[e].kind == RC_EFF_CABLE_POINTS)
            pf = (int)r3.model.effects[e].first;
    assert_true(pf >= 0);
    double worst = 0.0; /* the fitted points against the true plate */
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c)
            worst = fmax(worst, fabs(r3.model.x[pf + 3 * k + c] - plate_true[k][c]));
    print_message("tool point (50, 0, 150), RMS over %d new poses: 3 points %.4f mm, 1 point %.4f mm; fitted points "
                  "within %.4f mm of the true plate (drawing off by 0.02 sd)\n", N_EVAL, e3, e1, worst);
    assert_true(e3 < 0.1);
    assert_true(e3 < e1 / 3.0);
    assert_true(worst < 0.1);
}

/* One point 60 mm off the flange centre: a6, d6 and the attachment are one
 * direction for the lengths, so the flange centre is the prior's unless the
 * user says where the cable is hooked (one --cable-point, no target column:
 * the drawing's point, true within 0.02 mm sd, told to 0.05). */
static void test_one_point_told_places_the_flange(void **state)
{
    (void)state;
    static rch_calib_result told, untold;
    rch_diag d;
    if (run(&told, 1, 0, 1, &d) != 0)
        fail_msg("calibrate, the point told: %s", d.msg);
    if (run(&untold, 1, 0, 0, &d) != 0)
        fail_msg("calibrate, the point not told: %s", d.msg);
    static const double centre[3] = {0.0, 0.0, 0.0};
    const double e_told = point_rms(&told.model, centre), e_untold = point_rms(&untold.model, centre);
    double nom[6][4];
    rct_irb120_dh(nom);
    const double a6 = truth[5][0] - nom[5][0], d6 = truth[5][1] - nom[5][1];
    print_message("flange centre, RMS over %d new poses: the point told %.4f mm, not told %.4f mm (true a6 %+.3f, "
                  "d6 %+.3f mm off the drawing); flange headline %s\n", N_EVAL, e_told, e_untold, a6, d6,
                  told.flange_prior_only ? "prior only" : "determined");
    assert_true(e_told < 0.1);
    assert_true(e_untold > 0.5 * hypot(a6, d6)); /* not told: the prior's nominal a6, d6 */
    assert_true(e_told < e_untold / 3.0);
    assert_true(!told.flange_prior_only && untold.flange_prior_only);
}

static void test_points_refused(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    assert_int_not_equal(run(&r, 3, 2, 0, &d), 0); /* a target column, no --cable-point */
    print_message("no points told: %s (line %u)\n", d.msg, d.line);
    assert_non_null(strstr(d.msg, "--cable-point"));
    assert_true(d.line > 1);
    assert_int_not_equal(run(&r, 3, 5, 3, &d), 0); /* point 5 of 3 */
    print_message("point 5 of 3: %s (line %u)\n", d.msg, d.line);
    assert_non_null(strstr(d.msg, "point 5"));
    assert_true(d.line == 2 + 7 * 3 + 2);
    assert_int_not_equal(run(&r, 1, 0, 3, &d), 0); /* told 3, the file never names them */
    print_message("points told, none used: %s\n", d.msg);
    assert_non_null(strstr(d.msg, "do not use"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_three_points_see_the_orientation),
        cmocka_unit_test(test_one_point_told_places_the_flange),
        cmocka_unit_test(test_points_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
