/* SPDX-License-Identifier: MIT */
/* test_row_weights.c - a tracker's stated sigma_mm as the row weight
 * (rc_sample.weight, issue 31 item 2 / issue 32 item 5), on a positions file
 * written here from the tests' own kinematics (rct_indep.h): 40 poses x 3
 * targets, the tracker frame turned 68 deg and 1.7 m away, every second pose
 * measured 30 x noisier (0.005 mm and 0.15 mm sd, each row's stated sd in
 * its sigma_mm column, the noise drawn with it).
 *   - weighted, the targets the model places over 300 new poses are closer
 *     to the true robot's (after the best rigid motion) than with the same
 *     rows weighed equally (the file without its sigma_mm column): at most
 *     0.6 x;
 *   - the noise estimate is the median row's (0.005 .. 0.15 mm: a row at
 *     the files' median sd), and a file whose rows all state the same sd
 *     fits as the one without the column, to the last digit. */
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

#define NPOSE 40
#define NTG 3
#define DEG (3.14159265358979323846 / 180.0)

static double g_dh[6][4];
static const double g_tg[NTG][3] = {{0, 0, 45}, {40, 0, 80}, {-30, 50, 60}};
static char g_truth[64];

static void random_q(double q_deg[6], rct_rng *g)
{
    for (int j = 0; j < 6; ++j) {
        const double lo = rct_irb120_lim_deg[j][0] * 0.7, hi = rct_irb120_lim_deg[j][1] * 0.7;
        q_deg[j] = floor((lo + (hi - lo) * rct_u01(g)) * 1e4 + 0.5) / 1e4;
    }
}

/* The truth as a model file (rcal-model/1) for rch_calib_cfg.truth_path. */
static void write_truth(void)
{
    snprintf(g_truth, sizeof g_truth, "row_weights_truth_%ld.json", (long)getpid());
    assert_int_equal(rct_write_truth(g_truth, "row weights truth", g_dh), 0);
}

/* The positions file into path: sigma column: 0 none, 1 each row's own sd,
 * 2 every row the same sd (the noise as drawn). */
static void write_positions(const char *path, int sigma)
{
    rct_rng g = {77};
    const double th = 68.0 * DEG, T[3] = {1700.0, -300.0, 120.0};
    const double Rt[9] = {cos(th), -sin(th), 0, sin(th), cos(th), 0, 0, 0, 1};
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "q1,q2,q3,q4,q5,q6,x,y,z,target%s\n", sigma ? ",sigma_mm" : "");
    for (unsigned i = 0; i < NPOSE; ++i) {
        double q_deg[6], q[6], o[3], R6[9];
        random_q(q_deg, &g);
        for (int j = 0; j < 6; ++j)
            q[j] = q_deg[j] * DEG;
        rct_pose(o, R6, g_dh, q);
        const double sd = i % 2 ? 0.15 : 0.005;
        for (unsigned t = 0; t < NTG; ++t) {
            double a[3], p[3];
            for (int c = 0; c < 3; ++c)
                a[c] = o[c] + R6[3 * c] * g_tg[t][0] + R6[3 * c + 1] * g_tg[t][1] + R6[3 * c + 2] * g_tg[t][2];
            for (int c = 0; c < 3; ++c)
                p[c] = Rt[3 * c] * a[0] + Rt[3 * c + 1] * a[1] + Rt[3 * c + 2] * a[2] + T[c] + sd * rct_gauss(&g);
            fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f,%u", q_deg[0], q_deg[1], q_deg[2], q_deg[3],
                    q_deg[4], q_deg[5], p[0], p[1], p[2], t);
            if (sigma)
                fprintf(f, ",%g", sigma == 1 ? sd : 0.05);
            fprintf(f, "\n");
        }
    }
    assert_int_equal(fclose(f), 0);
}

/* RMS distance (mm) between the targets the fitted model places and the true
 * ones over 300 new poses, after the best rigid motion. */
static double targets_rms(const rc_model *m)
{
    enum { NE = 300 };
    static double a[NE * NTG][3], b[NE * NTG][3];
    int kf = -1;
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == RC_EFF_TRACKER_TARGETS)
            kf = (int)m->effects[e].first;
    assert_true(kf >= 0);
    rct_rng g = {909};
    for (unsigned i = 0; i < NE; ++i) {
        double q_deg[6], q[6], o[3], R[9], ot[3], Rt[9];
        random_q(q_deg, &g);
        for (int j = 0; j < 6; ++j)
            q[j] = q_deg[j] * DEG;
        rc_fk(o, R, m, q);
        rct_pose(ot, Rt, g_dh, q);
        for (unsigned t = 0; t < NTG; ++t) {
            const double *x = &m->x[kf + 3 * (int)t];
            for (int c = 0; c < 3; ++c) {
                a[i * NTG + t][c] = o[c] + R[3 * c] * x[0] + R[3 * c + 1] * x[1] + R[3 * c + 2] * x[2];
                b[i * NTG + t][c] = ot[c] + Rt[3 * c] * g_tg[t][0] + Rt[3 * c + 1] * g_tg[t][1] + Rt[3 * c + 2] * g_tg[t][2];
            }
        }
    }
    double Rk[9], Tk[3], ss = 0.0;
    sg_kabsch(Rk, Tk, (const double(*)[3])a, (const double(*)[3])b, NE * NTG, NULL);
    for (unsigned i = 0; i < NE * NTG; ++i)
        for (int r = 0; r < 3; ++r) {
            const double v = Rk[3 * r] * a[i][0] + Rk[3 * r + 1] * a[i][1] + Rk[3 * r + 2] * a[i][2] + Tk[r] - b[i][r];
            ss += v * v;
        }
    return sqrt(ss / (NE * NTG));
}

static void calibrate(rch_calib_result *r, int sigma)
{
    char path[64];
    snprintf(path, sizeof path, "row_weights_%ld_%d.csv", (long)getpid(), sigma);
    write_positions(path, sigma);
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    const char *paths[1] = {path};
    cfg.robot_path = RCAL_SOURCE_DIR "/data/irb120.json";
    cfg.truth_path = g_truth;
    cfg.test_fraction = 0.0;
    cfg.positions_paths = paths;
    cfg.n_positions_paths = 1;
    rch_diag d;
    const int rc = rch_calib_run(r, &cfg, &d);
    unlink(path);
    if (rc != 0)
        fail_msg("calibrate (sigma column %d): %s", sigma, d.msg);
}

static void test_weights(void **state)
{
    (void)state;
    rct_rng g = {5};
    rct_irb120_dh(g_dh);
    for (int i = 0; i < 6; ++i) {
        g_dh[i][0] += 0.3 * rct_gauss(&g);
        g_dh[i][1] += 0.3 * rct_gauss(&g);
        g_dh[i][2] += 0.05 * DEG * rct_gauss(&g);
        g_dh[i][3] += 0.05 * DEG * rct_gauss(&g);
    }
    write_truth();
    static rch_calib_result w, u, same;
    calibrate(&w, 1);
    calibrate(&u, 0);
    calibrate(&same, 2);
    unlink(g_truth);
    const double ew = targets_rms(&w.model), eu = targets_rms(&u.model);
    print_message("targets vs truth (RMS over 300 new poses, rigidly aligned): weighted %.4f mm, equal weights %.4f "
                  "mm; noise estimates %.4f / %.4f mm (the median row's sd: 0.15)\n",
                  ew, eu, w.noise_mm, u.noise_mm);
    assert_true(ew < 0.6 * eu);
    assert_true(w.noise_mm > 0.002 && w.noise_mm < 0.2);
    /* a stated sd the same on every row weighs nothing differently */
    assert_true(same.truth_after_rms_mm == u.truth_after_rms_mm);
    for (unsigned k = 0; k < u.model.n_params; ++k)
        assert_true(same.model.x[k] == u.model.x[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_weights),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
