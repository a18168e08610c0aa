/* SPDX-License-Identifier: MIT */
/* test_prior_scale.c - the prior's scale from the data (rch_prior_scale,
 * through rch_calib_run) on cable files written here from the tests' own
 * kinematics (rct_indep.h): three outlets, 400 poses, 0.01 mm noise.
 *   - a robot built three times looser than the stated prior (DH errors of
 *     1.5 mm and 0.3 deg sd): the length and twist factors found between
 *     1.5 and 6, with a relative standard error that says how well;
 *   - a robot built within a tenth of it: the type-II ML factors below 1,
 *     the uncertainty's factors kept at 1 (never narrower than stated), the
 *     estimate's joint zeros narrowed within [RCH_PRIOR_SCALE_MIN_FIT, 1)
 *     and the final fit made under them;
 *   - --prior-stated and a robot file with its own prior: nothing scaled.
 * What the wider prior does to u95's coverage is measured by
 * tests/system/sim/truth_study.py --errors wide (robots it never saw). */
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

#define N_POSES 400
#define PI 3.14159265358979323846

static double truth[6][4];

/* A 3-outlet length file of a robot whose DH errors have sd len_mm, ang_deg
 * (lengths; twists and zeros) into path. */
static void write_file(const char *path, double len_mm, double ang_deg, uint64_t seed)
{
    rct_rng g = {seed};
    rct_irb120_dh(truth);
    for (int i = 0; i < 6; ++i) {
        truth[i][0] += len_mm * rct_gauss(&g);
        truth[i][1] += len_mm * rct_gauss(&g);
        truth[i][2] += ang_deg * PI / 180.0 * rct_gauss(&g);
        truth[i][3] += ang_deg * PI / 180.0 * rct_gauss(&g);
    }
    static const double out[3][3] = {{600.0, -400.0, 0.0}, {-300.0, -650.0, 250.0}, {200.0, 700.0, 400.0}};
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "q1,q2,q3,q4,q5,q6,L,outlet\n");
    for (int i = 0; i < N_POSES; ++i) {
        double q[6], p[3];
        for (int j = 0; j < 6; ++j) {
            const double lo = rct_irb120_lim_deg[j][0] * 0.8, hi = rct_irb120_lim_deg[j][1] * 0.8;
            q[j] = (lo + (hi - lo) * rct_u01(&g)) * PI / 180.0;
        }
        rct_flange(p, truth, q);
        for (int o = 0; o < 3; ++o)
            fprintf(f, "%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%d\n", q[0] * 180.0 / PI, q[1] * 180.0 / PI,
                    q[2] * 180.0 / PI, q[3] * 180.0 / PI, q[4] * 180.0 / PI, q[5] * 180.0 / PI,
                    rct_dist(p, out[o]) + 0.01 * rct_gauss(&g), o + 1);
    }
    assert_int_equal(fclose(f), 0);
}

static void run(rch_calib_result *r, double len_mm, double ang_deg, int stated, const char *robot)
{
    char path[64];
    snprintf(path, sizeof path, "prior_scale_%ld.csv", (long)getpid());
    write_file(path, len_mm, ang_deg, 7);
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.data_path = path;
    cfg.robot_path = robot ? robot : RCAL_SOURCE_DIR "/data/irb120.json";
    cfg.test_fraction = 0.0;
    cfg.prior_stated = stated;
    rch_diag d;
    const int rc = rch_calib_run(r, &cfg, &d);
    unlink(path);
    if (rc != 0)
        fail_msg("calibrate: %s", d.msg);
}

static void test_loose_robot(void **state)
{
    (void)state;
    static rch_calib_result r;
    run(&r, 1.5, 0.3, 0, NULL);
    const rch_prior_scale *ps = &r.prior_scale;
    assert_true(r.prior_scaled);
    print_message("loose robot: lengths x %.2f +- %.0f %% (%.1f of %u determined), twists x %.2f +- %.0f %% (%.1f), "
                  "zeros x %.2f%s\n", ps->factor[0], 100 * ps->rel_se[0], ps->gamma[0], ps->n[0], ps->factor[1],
                  100 * ps->rel_se[1], ps->gamma[1], ps->factor[2], ps->fallback[2] ? " (fallback)" : "");
    assert_false(ps->fallback[RCH_PS_LENGTH]);
    assert_true(ps->factor[RCH_PS_LENGTH] >= 1.5 && ps->factor[RCH_PS_LENGTH] <= 6.0);
    assert_true(ps->rel_se[RCH_PS_LENGTH] > 0.0 && ps->rel_se[RCH_PS_LENGTH] < 0.5);
    if (!ps->fallback[RCH_PS_TWIST])
        assert_true(ps->factor[RCH_PS_TWIST] >= 1.5 && ps->factor[RCH_PS_TWIST] <= 6.0);
    /* the 95 % figures read the estimated scale as Student-t with min(gamma, 3) dof: t(3, 0.975) = 3.182
     * at gamma 10, t(2.5, 0.975) at 2.5 (a heavy-tailed spread from few values) */
    rch_prior_scale t = *ps;
    t.gamma[RCH_PS_LENGTH] = 10.0;
    assert_true(fabs(rch_prior_scale_predictive(&t, RCH_PS_LENGTH) - 3.182446 / 1.959964) < 1e-4);
    t.gamma[RCH_PS_LENGTH] = 2.5;
    assert_true(fabs(rch_prior_scale_predictive(&t, RCH_PS_LENGTH) - 3.574655 / 1.959964) < 1e-3);
    t.factor[RCH_PS_LENGTH] = 1.0; /* kept at the stated sd: Gaussian */
    assert_true(rch_prior_scale_predictive(&t, RCH_PS_LENGTH) == 1.0);
    /* the fit's prior is the wider one */
    assert_true(fabs(r.prior_sd[RC_P_A(1)] - 0.5 * ps->factor[RCH_PS_LENGTH]) < 1e-12);
    static rch_calib_result s;
    run(&s, 1.5, 0.3, 1, NULL); /* --prior-stated */
    assert_false(s.prior_scaled);
    assert_true(fabs(s.prior_sd[RC_P_A(1)] - 0.5) < 1e-12);
}

static void test_tight_robot(void **state)
{
    (void)state;
    static rch_calib_result r;
    run(&r, 0.05, 0.01, 0, NULL);
    const rch_prior_scale *ps = &r.prior_scale;
    print_message("tight robot: lengths ML x %.2f -> %.2f, twists ML x %.2f -> %.2f\n", ps->factor_ml[0],
                  ps->factor[0], ps->factor_ml[1], ps->factor[1]);
    assert_true(r.prior_scaled);
    for (int t = 0; t < RCH_PS_TYPES; ++t)
        assert_true(ps->factor[t] == 1.0);
    assert_false(ps->fallback[RCH_PS_LENGTH]);
    assert_true(ps->factor_ml[RCH_PS_LENGTH] < 1.0);
    /* the estimate: only the joint zeros narrow, never below the floor; the uncertainty keeps the stated sd */
    assert_true(ps->factor_fit[RCH_PS_LENGTH] == 1.0 && ps->factor_fit[RCH_PS_TWIST] == 1.0);
    assert_false(ps->fallback[RCH_PS_OFFSET]);
    assert_true(ps->factor_fit[RCH_PS_OFFSET] < 1.0 && ps->factor_fit[RCH_PS_OFFSET] >= RCH_PRIOR_SCALE_MIN_FIT);
    const unsigned k = RC_P_THETA(5);
    assert_true(fabs(r.prior_sd_fit[k] - r.prior_sd[k] * ps->factor_fit[RCH_PS_OFFSET]) < 1e-15);
    assert_true(fabs(r.prior_sd[k] - 1.0 * PI / 180.0) < 1e-12);
}

static void test_file_prior_kept(void **state)
{
    (void)state;
    char robot[64];
    snprintf(robot, sizeof robot, "prior_scale_robot_%ld.json", (long)getpid());
    FILE *in = fopen(RCAL_SOURCE_DIR "/data/irb120.json", "r");
    assert_non_null(in);
    char buf[16384];
    const size_t len = fread(buf, 1, sizeof buf - 1, in);
    fclose(in);
    buf[len] = 0;
    char *brace = strrchr(buf, '}'); /* the robot file with a stated prior */
    assert_non_null(brace);
    *brace = 0;
    FILE *out = fopen(robot, "w");
    assert_non_null(out);
    fprintf(out, "%s, \"prior\": {\"length_mm\": 0.5, \"twist_deg\": 0.1, \"offset_deg\": 1.0}}\n", buf);
    assert_int_equal(fclose(out), 0);
    static rch_calib_result r;
    run(&r, 1.5, 0.3, 0, robot);
    unlink(robot);
    assert_true(r.robot.prior.from_file);
    assert_false(r.prior_scaled);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_loose_robot),
        cmocka_unit_test(test_tight_robot),
        cmocka_unit_test(test_file_prior_kept),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
