/* SPDX-License-Identifier: MIT */
/* test_comp_orient.c - issue 47: whether compensation corrects the
 * orientation is weighed (rch_comp_orient_decide: the calibrated-vs-nominal
 * tilt of the tool's axis against the correction's predicted error), the
 * options still force either, and the command says which; a model without an
 * uncertainty reports its u95 as unknown (nan, "n/a"), never 0, and a
 * --max-uncertainty-mm the user sets then acts on every target. In-process
 * (rch_comp_orient_decide on data/irb120.json with a covariance made here)
 * and through the built rcal binary. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rch_comp.h"
#include "rch_prior.h"
#include "rch_robot.h"

#define DEG (3.14159265358979323846 / 180.0)
#define RCAL RCAL_BINARY_DIR "/tools/rcal"

static char dir[64];
static rch_robot nom;

static int setup(void **state)
{
    (void)state;
    strcpy(dir, "/tmp/rcal_comp_orient_XXXXXX");
    assert_non_null(mkdtemp(dir));
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static int run(const char *cmd)
{
    int st = system(cmd);
    assert_true(st != -1);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static char *slurp(const char *path)
{
    static char buf[1 << 16];
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* A posterior over the 24 DH parameters: every one determined with a tiny
 * sd, parameter k with sd_k (rad) and prior class cls_k. */
static void make_unc(rch_model_unc *u, unsigned k, double sd_k, rch_prior_class cls_k)
{
    memset(u, 0, sizeof *u);
    u->present = 1;
    u->has_prior = 1;
    u->n = RC_N_DH;
    for (unsigned i = 0; i < RC_N_DH; ++i) {
        u->cls[i] = RCH_PARAM_IDENTIFIABLE;
        u->prior_cls[i] = RCH_PRIOR_CLASS_DETERMINED;
        u->se[i] = i == k ? sd_k : 1e-9;
        u->prior_sd[i] = 1.0;
        u->cov_dh[i * RC_N_DH + i] = u->se[i] * u->se[i];
    }
    u->prior_cls[k] = (uint8_t)cls_k;
}

/* alpha6 tilts the flange z axis by itself at every pose (it turns the
 * flange about its x axis after the last translation: the flange point does
 * not move, so position-only compensation moves no joint); its uncertainty
 * is all tilt too: the decision is |d alpha6| against its sd. */
static void test_decide_weighs_tilt_against_uncertainty(void **state)
{
    (void)state;
    rc_model det = nom.model;
    const double d_rad = 0.3 * DEG;
    det.x[RC_P_ALPHA(5)] += d_rad;
    rch_model_unc u;
    rch_comp_orient o;

    make_unc(&u, RC_P_ALPHA(5), 0.2 * DEG, RCH_PRIOR_CLASS_DETERMINED);
    rch_comp_orient_decide(&o, &u, &det, &nom.model, NULL);
    assert_true(o.known);
    if (fabs(o.uncorr_deg - 0.3) > 1e-6 || fabs(o.unc_deg - 0.2) > 1e-6)
        fail_msg("tilt %.9f deg (expected 0.3), its predicted error %.9f deg (expected 0.2)", o.uncorr_deg, o.unc_deg);
    assert_true(o.correct);
    assert_int_equal(rch_comp_position_only(&o, 0, 0, 1, 0), 0);

    make_unc(&u, RC_P_ALPHA(5), 0.4 * DEG, RCH_PRIOR_CLASS_DETERMINED);
    rch_comp_orient_decide(&o, &u, &det, &nom.model, NULL);
    assert_true(o.known && !o.correct && !o.tie);
    assert_true(fabs(o.unc_deg - 0.4) < 1e-6);
    /* 0.3 against 0.29: closer by 3 %, within the margin: a tie, position only */
    make_unc(&u, RC_P_ALPHA(5), 0.29 * DEG, RCH_PRIOR_CLASS_DETERMINED);
    rch_comp_orient_decide(&o, &u, &det, &nom.model, NULL);
    assert_true(o.known && !o.correct && o.tie);
    assert_int_equal(rch_comp_position_only(&o, 0, 0, 1, 1), 1); /* the file's flag no longer decides */
    /* the options still force either */
    assert_int_equal(rch_comp_position_only(&o, 0, 1, 1, 0), 0);
    make_unc(&u, RC_P_ALPHA(5), 0.2 * DEG, RCH_PRIOR_CLASS_DETERMINED);
    rch_comp_orient_decide(&o, &u, &det, &nom.model, NULL);
    assert_int_equal(rch_comp_position_only(&o, 1, 0, 1, 1), 1);

    /* a parameter the data left to the prior: its estimate sits at the
     * drawing's value whatever is chosen, it does not weigh */
    make_unc(&u, RC_P_ALPHA(5), 0.4 * DEG, RCH_PRIOR_CLASS_PRIOR_ONLY);
    rch_comp_orient_decide(&o, &u, &det, &nom.model, NULL);
    assert_true(o.unc_deg < 1e-5 && o.correct);
}

/* theta6 turns the flange about its own z axis (a6 is 0: the flange point
 * does not move): the tool's axis does not tilt, so however sure the model
 * is of it, correcting gains the axis nothing (a full-rotation rule would
 * have corrected it). */
static void test_decide_roll_is_not_tilt(void **state)
{
    (void)state;
    rc_model det = nom.model;
    det.x[RC_P_THETA(5)] += 0.5 * DEG;
    rch_model_unc u;
    rch_comp_orient o;
    make_unc(&u, RC_P_ALPHA(3), 0.01 * DEG, RCH_PRIOR_CLASS_DETERMINED);
    rch_comp_orient_decide(&o, &u, &det, &nom.model, NULL);
    assert_true(o.known);
    if (!(o.uncorr_deg < 1e-6))
        fail_msg("a roll about the flange z axis tilts it by %.9f deg", o.uncorr_deg);
    assert_false(o.correct);
    /* without a covariance: not decided here, the file's flag decides */
    rch_comp_orient_decide(&o, NULL, &det, &nom.model, NULL);
    assert_false(o.known);
    assert_int_equal(rch_comp_position_only(&o, 0, 0, 1, 0), 1);
    assert_int_equal(rch_comp_position_only(&o, 0, 0, 0, 0), 0); /* a bare model: full pose, as before */
}

/* The command on a calibrated model with a posterior: --summary names the
 * mode and the figures; --json carries them; the options force either. */
static void test_command_says_which(void **state)
{
    (void)state;
    char mp[128], in[128], out[128], err[128], js[128], cmd[1024];
    snprintf(mp, sizeof mp, "%s/sim_model.json", dir);
    snprintf(in, sizeof in, "%s/targets.csv", dir);
    snprintf(out, sizeof out, "%s/out.csv", dir);
    snprintf(err, sizeof err, "%s/err.txt", dir);
    snprintf(js, sizeof js, "%s/summary.json", dir);
    snprintf(cmd, sizeof cmd, "'%s' calibrate --data '%s/data/sim_irb120.csv' --out '%s' > /dev/null", RCAL,
             RCAL_SOURCE_DIR, mp);
    assert_int_equal(run(cmd), 0);
    FILE *f = fopen(in, "w");
    assert_non_null(f);
    fputs("10,20,30,40,50,50\n-30,40,10,20,-50,90\n", f);
    fclose(f);
    rch_robot cal;
    rch_diag d;
    assert_int_equal(rch_robot_load(&cal, mp, &d), 0);
    rc_model det;
    rch_model_unc unc;
    int v1;
    char held[256];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, &cal, &cal.nominal);
    rc_model nom_pt; /* the run's point models: the flange (no --tool), without the cable attachment */
    rch_comp_point_model(&det, &det, NULL);
    rch_comp_point_model(&nom_pt, &cal.nominal, NULL);
    rch_comp_orient o;
    rch_comp_orient_decide(&o, &unc, &det, &nom_pt, NULL);
    assert_true(o.known);

    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --summary 2> '%s'", RCAL, mp, in, out,
             err);
    assert_int_equal(run(cmd), 0);
    const char *txt = slurp(err);
    char want[256];
    snprintf(want, sizeof want, "orientation %s: position only, the calibrated model leaves the tool's axis (the "
                                "flange z axis) %.4f deg off the nominal one",
             o.correct ? "corrected" : "not corrected", o.uncorr_deg);
    if (!strstr(txt, want))
        fail_msg("--summary lacks \"%s\":\n%s", want, txt);
    assert_non_null(strstr(txt, o.correct ? "mode position and orientation" : "mode position only"));

    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --json > '%s' 2> /dev/null", RCAL, mp,
             in, out, js);
    assert_int_equal(run(cmd), 0);
    txt = slurp(js);
    snprintf(want, sizeof want, "\"orientation\":{\"corrected\":%s,\"chosen_by\":\"uncertainty\"",
             o.correct ? "true" : "false");
    if (!strstr(txt, want))
        fail_msg("--json lacks %s:\n%s", want, txt);

    const char *force[2] = {"--position-only", "--full-pose"};
    for (int k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --summary %s 2> '%s'", RCAL, mp,
                 in, out, force[k], err);
        assert_int_equal(run(cmd), 0);
        snprintf(want, sizeof want, "orientation %s (forced by %s)", k ? "corrected" : "not corrected", force[k]);
        if (!strstr(slurp(err), want))
            fail_msg("%s: --summary lacks \"%s\"", force[k], want);
    }
}

/* A model without an uncertainty (rcal-model/1): u95 unknown, never 0. */
static void test_u95_unknown_not_zero(void **state)
{
    (void)state;
    char mp[128], in[128], out[128], uo[128], err[128], cmd[1024];
    snprintf(mp, sizeof mp, "%s/v1_model.json", dir);
    snprintf(in, sizeof in, "%s/v1_targets.csv", dir);
    snprintf(out, sizeof out, "%s/v1_out.csv", dir);
    snprintf(uo, sizeof uo, "%s/v1_u95.csv", dir);
    snprintf(err, sizeof err, "%s/v1_err.txt", dir);
    rc_model cal = nom.model;
    cal.x[RC_P_A(1)] += 0.4;
    cal.x[RC_P_THETA(2)] += 0.1 * DEG;
    FILE *f = fopen(mp, "w");
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "v1 calibrated", &cal, &nom.model, NULL), 0);
    fclose(f);
    f = fopen(in, "w");
    assert_non_null(f);
    fputs("10,20,30,40,50,50\n-30,40,10,20,-50,90\n", f);
    fclose(f);

    /* no limit set: compensated, every u95 "nan" in --uncertainty-out, "n/a" in the summary */
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --uncertainty-out '%s' --summary 2> '%s'",
             RCAL, mp, in, out, uo, err);
    assert_int_equal(run(cmd), 0);
    const char *u = slurp(uo);
    if (strcmp(u, "line,u95_mm\n1,nan\n2,nan\n") != 0)
        fail_msg("--uncertainty-out of a model without an uncertainty:\n%s", u);
    assert_non_null(strstr(slurp(err), "largest 95 % position uncertainty at a compensated target n/a"));
    assert_null(strstr(slurp(err), "compensated target 0.0000 mm"));
    f = fopen(out, "r");
    assert_non_null(f);
    double q[6];
    assert_int_equal(fscanf(f, "%lf,%lf,%lf,%lf,%lf,%lf", &q[0], &q[1], &q[2], &q[3], &q[4], &q[5]), 6);
    fclose(f);
    assert_true(fabs(q[1] - 20.0) > 1e-4 || fabs(q[2] - 30.0) > 1e-4); /* corrected */

    /* a limit the user sets cannot be met: skip leaves every target as it was, with a warning */
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --max-uncertainty-mm 1 2> '%s'", RCAL,
             mp, in, out, err);
    assert_int_equal(run(cmd), 1);
    assert_string_equal(slurp(out), "10.000000,20.000000,30.000000,40.000000,50.000000,50.000000\n"
                                    "-30.000000,40.000000,10.000000,20.000000,-50.000000,90.000000\n");
    assert_non_null(strstr(slurp(err), ":2: warning: target left uncompensated: the model's 95 % position uncertainty "
                                       "here is unknown (the model carries no uncertainty), above 1.0000 mm"));
    /* refuse: nothing written, the line named */
    snprintf(cmd, sizeof cmd,
             "rm -f '%s'; '%s' compensate --model '%s' --in '%s' --out '%s' --max-uncertainty-mm 1 --u95-policy refuse "
             "2> '%s'",
             out, RCAL, mp, in, out, err);
    assert_int_equal(run(cmd), 1);
    assert_int_equal(access(out, F_OK), -1);
    assert_non_null(strstr(slurp(err), "v1_targets.csv:1: the model's 95 % position uncertainty at the compensated "
                                       "point is unknown"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_decide_weighs_tilt_against_uncertainty),
        cmocka_unit_test(test_decide_roll_is_not_tilt),
        cmocka_unit_test(test_command_says_which),
        cmocka_unit_test(test_u95_unknown_not_zero),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
