/* SPDX-License-Identifier: MIT */
/* test_uncert.c - the reported standard errors against the spread of the
 * estimates: coverage of the 95 % intervals over 50 simulated robots, at two
 * noise levels. The data come from this file's own forward kinematics and
 * random numbers (not rcal's simulator); the noise level is drawn here and
 * never passed to the code under test. */
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
#include "rch_robot.h"
#include "rch_uncert.h"
#include "rct_indep.h"

static rct_rng G;
#define u01() rct_u01(&G)
#define gauss() rct_gauss(&G)

typedef struct {
    unsigned checked, covered;
    double ratio_sum; /* mean of |error| / se */
} tally;

static void one_robot(tally *t, const rch_robot *nom, double noise_mm, size_t n, int grouped, rc_solve_work *w)
{
    double dh[6][4], truth[27];
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k) {
            double nomv = nom->model.x[4 * i + k];
            dh[i][k] = nomv + (k < 2 ? 0.3 * gauss() : 0.05 * 0.017453292519943295 * gauss());
            truth[4 * i + k] = dh[i][k];
        }
    double enc[3] = {300 + 50 * gauss(), -450 + 50 * gauss(), 20 * gauss()};
    memcpy(&truth[24], enc, sizeof enc);
    rc_sample *s = calloc(n, sizeof *s);
    assert_non_null(s);
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < 6; ++j) {
            double lo = nom->model.q_min_rad[j] * 0.9, hi = nom->model.q_max_rad[j] * 0.9;
            s[i].q_rad[j] = lo + (hi - lo) * u01();
        }
        double p[3];
        rct_flange(p, dh, s[i].q_rad);
        s[i].value = sqrt((p[0] - enc[0]) * (p[0] - enc[0]) + (p[1] - enc[1]) * (p[1] - enc[1]) +
                           (p[2] - enc[2]) * (p[2] - enc[2])) +
                      noise_mm * gauss();
        s[i].group = grouped ? (uint16_t)(i / 10) : 0;
        s[i].outlet = 0;
        s[i].t = (double)i / (double)(n - 1);
    }
    rc_model start, fit;
    rch_diag d;
    assert_int_equal(rch_calib_start(&start, w, nom, s, n, &d), 0);
    fit = start;
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.snr_min = -1.0; /* plain least squares: the covariance describes it */
    assert_int_equal(rc_solve(&fit, NULL, w, &cfg, s, n), RC_OK);
    rch_uncert u;
    char err[256];
    assert_int_equal(rch_uncert_compute(&u, &fit, NULL, s, n, grouped, err, sizeof err), 0);
    assert_int_equal(u.kind, grouped ? RCH_COV_CLUSTER : RCH_COV_CLASSICAL);
    for (unsigned k = 0; k < 27; ++k) {
        if (u.cls[k] != RCH_PARAM_IDENTIFIABLE || u.null_share[k] > 1e-6 || u.weak_share[k] > 1e-6)
            continue;
        double e = fit.x[k] - truth[k];
        if (rc_param_unit(&fit, k) == 1) /* angles: compare modulo 2 pi */
            e = remainder(e, 6.283185307179586);
        t->checked++;
        t->covered += fabs(e) <= 1.959963984540054 * u.se[k];
        t->ratio_sum += fabs(e) / u.se[k];
    }
    rch_uncert_free(&u);
    free(s);
}

static void coverage(const char *label, double noise_lo, double noise_hi, int grouped)
{
    rch_robot nom;
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    rc_solve_work *w = malloc(sizeof *w);
    assert_non_null(w);
    tally t = {0, 0, 0};
    G.s = 12345u + (uint64_t)(noise_lo * 1e6) + (uint64_t)grouped;
    for (int seed = 0; seed < 50; ++seed) {
        double noise = noise_lo + (noise_hi - noise_lo) * u01();
        one_robot(&t, &nom, noise, 300, grouped, w);
    }
    double cov = (double)t.covered / (double)t.checked;
    print_message("%s: %u parameter estimates over 50 robots, 95 %% intervals cover %.1f %%, mean |error|/se %.3f\n",
                  label, t.checked, 100.0 * cov, t.ratio_sum / t.checked);
    assert_true(t.checked >= 50 * 10);
    assert_true(cov >= 0.90 && cov <= 0.99);
    free(w);
}

static void test_coverage_default_noise(void **state)
{
    (void)state;
    coverage("noise 0.005-0.015 mm, classical", 0.005, 0.015, 0);
}

static void test_coverage_ten_times_noise(void **state)
{
    (void)state;
    coverage("noise 0.05-0.15 mm, classical", 0.05, 0.15, 0);
}

static void test_coverage_cluster(void **state)
{
    (void)state;
    coverage("noise 0.005-0.015 mm, cluster-robust (30 groups of 10)", 0.005, 0.015, 1);
}

/* The closed-form sensitivity columns (DH rows, tool offset, axis tilts) and
 * the zero ones (encoder, length side) against central differences of the
 * model's own forward kinematics rc_fk, on a model that carries them all. */
static void test_point_sens_closed_form(void **state)
{
    (void)state;
    rch_robot nom;
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    rc_model m = nom.model;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_AXIS_TILT, 1, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_AXIS_TILT, 2, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 3, 0), RC_OK);
    G.s = 777u;
    for (unsigned k = 0; k < m.n_params; ++k) /* every parameter off zero, the tilts of a few mrad */
        m.x[k] += (k >= RC_N_BASE ? (rc_param_unit(&m, k) == 1 ? 0.003 : 20.0) : 0.0) * (u01() - 0.5);
    double worst = 0.0;
    for (int pose = 0; pose < 20; ++pose) {
        double q[RC_NJ], Jp[3][RC_MAX_PARAMS];
        for (int j = 0; j < RC_NJ; ++j)
            q[j] = m.q_min_rad[j] * 0.9 + (m.q_max_rad[j] - m.q_min_rad[j]) * 0.9 * u01();
        rch_uncert_point_sens(Jp, &m, q);
        for (unsigned k = 0; k < m.n_params; ++k) {
            const double h = rc_param_unit(&m, k) == 1 ? 1e-6 : 1e-4;
            rc_model t = m;
            double pp[3], pm[3];
            t.x[k] = m.x[k] + h;
            rc_fk(pp, NULL, &t, q);
            t.x[k] = m.x[k] - h;
            rc_fk(pm, NULL, &t, q);
            for (int i = 0; i < 3; ++i) {
                const double fd = (pp[i] - pm[i]) / (2.0 * h), e = fabs(Jp[i][k] - fd);
                if (e > 1e-5 * (1.0 + fabs(fd)))
                    fail_msg("parameter %u row %d pose %d: %.9g against the FK's %.9g", k, i, pose, Jp[i][k], fd);
                worst = fmax(worst, e / (1.0 + fabs(fd)));
            }
        }
    }
    print_message("point sensitivity of %u parameters at 20 poses: largest relative difference from rc_fk's "
                  "central differences %.2g\n", (unsigned)m.n_params, worst);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_coverage_default_noise),
        cmocka_unit_test(test_coverage_ten_times_noise),
        cmocka_unit_test(test_coverage_cluster),
        cmocka_unit_test(test_point_sens_closed_form),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
