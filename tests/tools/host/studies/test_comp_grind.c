/* SPDX-License-Identifier: MIT */
/* test_comp_grind.c - the grinding experiment on a simulated truth: with the
 * true model as the calibrated one, the compensated path is on the programmed
 * one where the uncompensated path is off by about a millimetre; every
 * surface runs; the plots are written; bad specs are usage errors. In-process
 * through rch_grind (surface parsing, base alignment, the run and its
 * statistics) and end to end through the built rcal. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <math.h>

#include "rc_rand.h"
#include "rch_grind.h"
#include "rch_robot.h"

#define DEG (3.14159265358979323846 / 180.0)
#define RCAL RCAL_BINARY_DIR "/tools/rcal"

static char dir[64], truth_path[128], model_path[128];
static rc_model g_nom, g_truth;

static int run(const char *cmd)
{
    int st = system(cmd);
    assert_true(st != -1);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int setup(void **state)
{
    (void)state;
    strcpy(dir, "/tmp/rcal_comp_grind_XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(truth_path, sizeof truth_path, "%s/truth.json", dir);
    snprintf(model_path, sizeof model_path, "%s/model.json", dir);
    rch_robot nom;
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    rc_model truth = nom.model;
    rc_rng g;
    rc_rng_seed(&g, 21);
    for (int k = 0; k < RC_N_DH; ++k)
        truth.x[k] += (k % 4 < 2 ? 0.3 : 0.05 * DEG) * rc_rng_normal(&g);
    FILE *f = fopen(truth_path, "w");
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "truth", &truth, &nom.model, NULL), 0);
    fclose(f);
    f = fopen(model_path, "w"); /* a perfect calibration: the truth itself */
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "calibrated", &truth, &nom.model, NULL), 0);
    fclose(f);
    g_nom = nom.model;
    g_truth = truth;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* value of "key": in the JSON object of case name */
static double json_num(const char *txt, const char *case_name, const char *key)
{
    const char *c = strstr(txt, case_name);
    assert_non_null(c);
    const char *k = strstr(c, key);
    assert_non_null(k);
    const char *colon = strchr(k + strlen(key), ':');
    assert_non_null(colon);
    return strtod(colon + 1, NULL);
}

static void test_perfect_calibration(void **state)
{
    (void)state;
    static const char *const surfaces[] = {"tilted", "plane", "cylinder", "saddle:k=15", "sine:amp=5,wl=80"};
    for (size_t s = 0; s < sizeof surfaces / sizeof surfaces[0]; ++s) {
        char cmd[768], out[160];
        snprintf(out, sizeof out, "%s/out.json", dir);
        snprintf(cmd, sizeof cmd, "'%s' grind --model '%s' --truth '%s' --surface '%s' --json > '%s'", RCAL,
                 model_path, truth_path, surfaces[s], out);
        assert_int_equal(run(cmd), 0);
        FILE *f = fopen(out, "r");
        assert_non_null(f);
        static char txt[8192];
        size_t n = fread(txt, 1, sizeof txt - 1, f);
        txt[n] = '\0';
        fclose(f);
        const double unc = json_num(txt, "\"uncompensated\"", "\"mean_mm\"");
        const double cal_max = json_num(txt, "\"compensated_calibrated\"", "\"max_mm\"");
        const double tru_max = json_num(txt, "\"compensated_true\"", "\"max_mm\"");
        if (!(unc > 0.3 && cal_max < 0.05 && tru_max < 1e-3))
            fail_msg("%s: uncompensated mean %.4f, compensated max %.4f / %.4f", surfaces[s], unc, cal_max, tru_max);
        assert_non_null(strstr(txt, "\"not_converged\": 0"));
    }
}

static void test_plots(void **state)
{
    (void)state;
    char cmd[768], p[200];
    snprintf(cmd, sizeof cmd, "'%s' grind --model '%s' --truth '%s' --plots '%s/plots' > /dev/null", RCAL, model_path,
             truth_path, dir);
    assert_int_equal(run(cmd), 0);
    static const char *const files[] = {"grind_path.svg", "grind_deviation.svg", "grind_points.csv"};
    for (size_t i = 0; i < 3; ++i) {
        snprintf(p, sizeof p, "%s/plots/%s", dir, files[i]);
        FILE *f = fopen(p, "r");
        assert_non_null(f);
        static char txt[1 << 18];
        size_t n = fread(txt, 1, sizeof txt - 1, f);
        txt[n] = '\0';
        fclose(f);
        assert_true(n > 1000);
        if (i < 2)
            assert_non_null(strstr(txt, "</svg>"));
        else
            assert_true(strncmp(txt, "k,x,y,z,q1", 10) == 0);
    }
    snprintf(p, sizeof p, "%s/plots/grind_path.svg", dir);
    FILE *f = fopen(p, "r");
    static char svg[1 << 18];
    size_t n = fread(svg, 1, sizeof svg - 1, f);
    svg[n] = '\0';
    fclose(f);
    assert_non_null(strstr(svg, "P3 "));
    assert_non_null(strstr(svg, "compensated (calibrated model)"));
}

/* The Table 8 form in-process: BC's five signed deviations recomputed from
 * the true FK at the nominal targets and the tilted plane's own outward
 * normal; Mean and SD with n - 1; the truth as a model and the floor row at
 * zero; the whole-path statistics those of the single-model run. */
static void test_table8_inprocess(void **state)
{
    (void)state;
    rch_grind_config cfg;
    rch_grind_result res;
    static rch_grind_table t;
    rch_diag d;
    rch_grind_defaults(&cfg);
    rc_model shifted = g_truth;
    shifted.x[RC_P_D(1)] += 0.5; /* a model 0.5 mm off in d2 */
    const rc_model *models[3] = {&g_nom, &g_truth, &shifted};
    const char *names[3] = {"nominal", "truth", "shifted"};
    assert_int_equal(rch_grind_table8(&t, &cfg, models, names, 3, &g_truth, &g_nom, &d), 0);
    assert_int_equal(t.n_rows, 5);
    assert_string_equal(t.row[0].name, "BC");
    assert_string_equal(t.row[2].name, "truth");
    assert_string_equal(t.row[4].name, "true model");
    assert_int_equal(rch_grind_run(&res, &cfg, &g_nom, &g_truth, &g_nom, &d), 0);
    /* the tilted default: z = z0 + tan(15 deg) (x - cx); outward normal */
    const double tx = tan(15.0 * DEG), nl = sqrt(1.0 + tx * tx);
    const double n_out[3] = {-tx / nl, 0.0, 1.0 / nl};
    double sum = 0.0, v[5];
    for (int m = 0; m < 5; ++m) {
        const rch_grind_point *p = &res.pts[res.named[m]];
        double pt[3];
        rc_fk(pt, NULL, &g_truth, p->q_nom_rad);
        v[m] = (pt[0] - p->p_mm[0]) * n_out[0] + (pt[1] - p->p_mm[1]) * n_out[1] + (pt[2] - p->p_mm[2]) * n_out[2];
        assert_true(fabs(t.row[0].p_mm[m] - v[m]) < 1e-9);
        sum += v[m];
    }
    double ss = 0.0;
    for (int m = 0; m < 5; ++m)
        ss += (v[m] - sum / 5.0) * (v[m] - sum / 5.0);
    assert_true(fabs(t.row[0].mean_mm - sum / 5.0) < 1e-9);
    assert_true(fabs(t.row[0].sd_mm - sqrt(ss / 4.0)) < 1e-9);
    assert_true(fabs(t.row[0].path_mm.mean - res.cases[RCH_GRIND_UNCOMP].dev_mm.mean) < 1e-12);
    assert_true(t.row[0].path_mm.mean > 0.2); /* the errors are visible before compensation */
    /* the truth as a model and the floor: on the path */
    for (int m = 0; m < 5; ++m) {
        assert_true(fabs(t.row[2].p_mm[m]) < 1e-3);
        assert_true(fabs(t.row[4].p_mm[m]) < 1e-3);
    }
    assert_true(t.row[2].path_mm.max_abs < 1e-3);
    /* a wrong model leaves a deviation; the signed value never exceeds the 3-D one */
    assert_true(t.row[3].path_mm.mean > 0.01);
    for (size_t r = 0; r < t.n_rows; ++r)
        for (int m = 0; m < 5; ++m)
            assert_true(fabs(t.row[r].p_mm[m]) <= t.row[r].path_mm.max_abs + 1e-9);
    rch_grind_free(&res);
    /* 0 or too many models: refused */
    assert_int_equal(rch_grind_table8(&t, &cfg, models, names, 0, &g_truth, &g_nom, &d), -1);
}

/* End to end: several --model, --models DIR with the names rcal compare
 * writes; a directory without models is an error. */
static void test_table8_cli(void **state)
{
    (void)state;
    char cmd[1024], mdir[160], buf[8192];
    snprintf(cmd, sizeof cmd, "'%s' grind --model '%s' --model '%s' --truth '%s' > '%s/t8.txt'", RCAL, truth_path,
             model_path, truth_path, dir);
    assert_int_equal(run(cmd), 0);
    snprintf(mdir, sizeof mdir, "%s/t8.txt", dir);
    FILE *f = fopen(mdir, "r");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    assert_non_null(strstr(buf, "Table 8"));
    assert_non_null(strstr(buf, "BC "));
    assert_non_null(strstr(buf, "true model"));
    snprintf(mdir, sizeof mdir, "%s/models", dir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s' && cp '%s' '%s/M1-LM.json' && cp '%s' '%s/M7-LTLM.json'", mdir,
             model_path, mdir, model_path, mdir);
    assert_int_equal(run(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s' grind --models '%s' --truth '%s' --json > '%s/t8.json'", RCAL, mdir, truth_path,
             dir);
    assert_int_equal(run(cmd), 0);
    snprintf(mdir, sizeof mdir, "%s/t8.json", dir);
    f = fopen(mdir, "r");
    assert_non_null(f);
    n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    assert_non_null(strstr(buf, "\"M1 LM\""));
    assert_non_null(strstr(buf, "\"M7 LTLM\""));
    assert_null(strstr(buf, "M2 EKF"));
    snprintf(cmd, sizeof cmd, "'%s' grind --models '%s' --truth '%s' >/dev/null 2>&1", RCAL, dir, truth_path);
    assert_int_equal(run(cmd), 1);
    snprintf(cmd, sizeof cmd, "'%s' grind --truth '%s' >/dev/null 2>&1", RCAL, truth_path);
    assert_int_equal(run(cmd), 2);
}

static void test_bad_specs(void **state)
{
    (void)state;
    static const char *const specs[] = {"cone", "plane:w=-1", "tilted:ax=x", "sine:foo=1", "plane:w"};
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; ++i) {
        char cmd[768];
        snprintf(cmd, sizeof cmd, "'%s' grind --model '%s' --truth '%s' --surface '%s' > /dev/null 2>&1", RCAL,
                 model_path, truth_path, specs[i]);
        assert_int_equal(run(cmd), 2);
    }
    char cmd[768];
    /* issue 12: the nominal model as the "calibrated" one is named as such */
    snprintf(cmd, sizeof cmd, "'%s' grind --model '%s/data/irb120.json' --truth '%s' | grep -q 'not calibrated'", RCAL,
             RCAL_SOURCE_DIR, truth_path);
    assert_int_equal(run(cmd), 0);
    /* unreachable patch: a clear failure, not a wrong table */
    snprintf(cmd, sizeof cmd, "'%s' grind --model '%s' --truth '%s' --surface 'plane:cx=2000' > /dev/null 2>&1", RCAL,
             model_path, truth_path);
    assert_int_equal(run(cmd), 1);
}

static void test_surface_parse(void **state)
{
    rch_surface s;
    rch_diag d;
    (void)state;
    assert_int_equal(rch_surface_parse(&s, NULL, &d), 0);
    assert_int_equal(s.kind, RCH_SURF_TILTED);
    assert_true(s.cx == 400 && s.z0 == 300 && s.w == 200 && s.h == 120);
    assert_int_equal(rch_surface_parse(&s, "sine:amp=5,wl=80,cx=350", &d), 0);
    assert_int_equal(s.kind, RCH_SURF_SINE);
    assert_true(s.amp == 5 && s.wl == 80 && s.cx == 350 && s.w == 200);
    assert_true(fabs(rch_surface_z(&s, 350 + 20, 0) - (300 + 5)) < 1e-9); /* a quarter wave: the crest */
    static const char *const bad[][2] = {{"cone", "unknown surface"}, {"plane:w=-1", "positive"},
                                         {"tilted:ax=x", "not a number"},
                                         {"tilted:ax=0x1p3", "not a number"}, {"plane:w= 100", "not a number"},
                                         {"plane:w=inf", "not a number"}, {"sine:foo=1", "unknown surface key"},
                                         {"plane:w", "key=value"},         {"plane:ds=0.01", "5000 points"},
                                         {"plane:ds=0.05,step=0.2,h=100", "limit of 200000"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        memset(&d, 0, sizeof d);
        if (rch_surface_parse(&s, bad[i][0], &d) != -1 || !strstr(d.msg, bad[i][1]))
            fail_msg("surface '%s': expected a message with '%s', got '%s'", bad[i][0], bad[i][1], d.msg);
    }
}

/* A calibrated model whose base is turned by 0.01 rad and lowered by 0.5 mm
 * gets exactly that back from the alignment. */
static void test_align_base(void **state)
{
    rc_model cal = g_truth;
    double phi, dz;
    (void)state;
    cal.x[RC_P_THETA(0)] -= 0.01;
    cal.x[RC_P_D(0)] -= 0.5;
    rch_grind_align_base(&phi, &dz, &cal, &g_truth);
    assert_true(fabs(phi - 0.01) < 1e-9);
    assert_true(fabs(dz - 0.5) < 1e-9);
    rch_grind_align_base(&phi, &dz, &g_truth, &g_truth);
    assert_true(fabs(phi) < 1e-12 && fabs(dz) < 1e-12);
}

static void test_run_inprocess(void **state)
{
    rch_grind_config cfg;
    rch_grind_result res;
    rch_diag d;
    (void)state;
    rch_grind_defaults(&cfg);
    assert_int_equal(rch_surface_parse(&cfg.surface, "plane:w=100,h=40", &d), 0);
    assert_int_equal(rch_grind_run(&res, &cfg, &g_truth, &g_truth, &g_nom, &d), 0);
    assert_int_equal(res.nx, 21);
    assert_int_equal(res.ny, 5);
    assert_int_equal(res.n, 105);
    assert_int_equal(res.named[0], 0); /* P1: the path start */
    assert_true(res.pts[res.named[2]].p_mm[0] == 400 && res.pts[res.named[2]].p_mm[1] == 0);
    const rch_stats *u = &res.cases[RCH_GRIND_UNCOMP].dev_mm, *c = &res.cases[RCH_GRIND_COMP_CAL].dev_mm;
    assert_true(u->n == 105 && u->mean > 0.3 && u->max_abs >= u->mean);
    assert_true(c->max_abs < 1e-3);
    assert_int_equal(res.cases[RCH_GRIND_COMP_CAL].n_flag, 0);
    /* the statistics are those of the per-point deviations */
    double s = 0.0;
    for (size_t k = 0; k < res.n; ++k)
        s += res.pts[k].dev_mm[RCH_GRIND_UNCOMP];
    assert_true(fabs(s / 105.0 - u->mean) < 1e-12);
    assert_false(res.model_is_nominal);
    assert_true(res.align_only_mm.n == 105);
    rch_grind_free(&res);
    /* issue 12: a nominal model is not credited with what the alignment
     * (taken from the truth) removes: it is flagged, and the alignment alone
     * accounts for all of its gain */
    assert_int_equal(rch_grind_run(&res, &cfg, &g_nom, &g_truth, &g_nom, &d), 0);
    assert_true(res.model_is_nominal);
    assert_true(fabs(res.align_only_mm.mean - res.cases[RCH_GRIND_COMP_CAL].dev_mm.mean) < 1e-12);
    rch_grind_free(&res);
    cfg.align = 0;
    assert_int_equal(rch_grind_run(&res, &cfg, &g_nom, &g_truth, &g_nom, &d), 0);
    assert_true(res.align_only_mm.n == 0);
    /* nominal compensated by nominal: the joints do not move, the deviation stays */
    assert_true(fabs(res.cases[RCH_GRIND_COMP_CAL].dev_mm.mean - res.cases[RCH_GRIND_UNCOMP].dev_mm.mean) < 1e-6);
    rch_grind_free(&res);
    cfg.align = 1;
    /* unreachable: refused with the reason */
    assert_int_equal(rch_surface_parse(&cfg.surface, "plane:cx=2000", &d), 0);
    assert_int_equal(rch_grind_run(&res, &cfg, &g_truth, &g_truth, &g_nom, &d), -1);
    assert_non_null(strstr(d.msg, "cannot reach"));
    rch_grind_free(&res);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_surface_parse),
        cmocka_unit_test(test_align_base),
        cmocka_unit_test(test_run_inprocess),
        cmocka_unit_test(test_perfect_calibration),
        cmocka_unit_test(test_plots),
        cmocka_unit_test(test_bad_specs),
        cmocka_unit_test(test_table8_inprocess),
        cmocka_unit_test(test_table8_cli),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
