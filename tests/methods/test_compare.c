/* SPDX-License-Identifier: MIT */
/* test_compare.c - the compare protocol and the chaos study in-process,
 * through their host-library calls (rch_compare_run, rch_chaos_run): sizes
 * and bookkeeping of the result, the ordering of errors on simulated data,
 * determinism, refused configurations (empty or unknown method lists, too
 * few rows, absurd chaos cost), and JSON without nan. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_chaos.h"
#include "rch_compare.h"
#include "rch_json.h"
#include "rch_robot.h"
#include "rch_sim.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define NS 80

static rch_robot g_robot;
static rc_sample g_s[NS];

static int setup(void **state)
{
    rch_diag d;
    rch_sim_config c;
    rc_rng g;
    rc_model truth;
    const double enc[3] = {250.0, -460.0, 10.0};
    (void)state;
    if (rch_robot_load(&g_robot, ROBOT, &d) != 0)
        return -1;
    memset(&c, 0, sizeof c);
    c.group_size = 10;
    rch_sim_defaults(&c);
    rc_rng_seed(&g, 5);
    rch_sim_truth(&truth, &g_robot.model, enc, &c, &g);
    return rch_sim_samples(g_s, NULL, NS, &truth, &c, &g) == 0 ? 0 : -1;
}

static void test_methods_list(void **state)
{
    int run[RCH_EST_COUNT];
    rch_diag d;
    (void)state;
    assert_int_equal(rch_compare_methods(run, "lm,M7", &d), 0);
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        assert_int_equal(run[i], i == RCH_EST_LM || i == RCH_EST_LTLM);
    static const char *const bad[] = {"", ",", "lm,", "lm,,ekf", "foo", "lm,foo"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        memset(&d, 0, sizeof d);
        if (rch_compare_methods(run, bad[k], &d) != -1 || !strstr(d.msg, "--methods"))
            fail_msg("--methods '%s' accepted or not named: %s", bad[k], d.msg);
    }
}

static void test_compare_run(void **state)
{
    rch_compare_config cfg;
    rch_compare_result a, b;
    rch_diag d;
    (void)state;
    rch_compare_defaults(&cfg);
    cfg.cases = 2;
    cfg.samples = 70;
    cfg.test_fraction = 0.2;
    cfg.seed = 3;
    cfg.curves = 1;
    cfg.run[RCH_EST_PF] = cfg.run[RCH_EST_SCA] = cfg.run[RCH_EST_QIBAS] = 0; /* the slow ones */
    assert_int_equal(rch_compare_run(&a, &cfg, &g_robot, g_s, NS, NULL, &d), 0);
    assert_int_equal(a.n_test, 14);
    assert_int_equal(a.n_train, 56);
    assert_int_equal(a.rows_in_data, NS);
    assert_false(rch_compare_any_failed(&a));
    for (int r = 0; r < RCH_COMPARE_ROWS; ++r) {
        const int want = r == 0 || cfg.run[r - 1];
        assert_int_equal(a.row[r].used, want);
        if (!want)
            continue;
        assert_int_equal(a.row[r].rmse_mm.n, 2);
        /* the per-case table is what the statistics were built from */
        const double m = 0.5 * (a.cell[r].held_out.rmse_mm + a.cell[RCH_COMPARE_ROWS + (size_t)r].held_out.rmse_mm);
        assert_true(fabs(m - a.row[r].rmse_mm.mean) < 1e-12);
        assert_true(a.row[r].mean_abs_mm.mean <= a.row[r].rmse_mm.mean + 1e-12);
        assert_true(a.row[r].max_mm.mean >= a.row[r].rmse_mm.mean - 1e-12);
        if (r > 0) {
            assert_true(a.curve[r - 1].n > 1);
            assert_true(isfinite(a.err_case1_mm[(size_t)r * a.n_test]));
        }
    }
    assert_false(a.cell[RCH_EST_PF + 1].ok); /* not run */
    assert_int_equal(a.row[RCH_EST_PF + 1].failed, 0);
    const double bc = a.row[0].rmse_mm.mean;
    assert_true(bc > 0.2);
    assert_true(a.row[RCH_EST_LM + 1].rmse_mm.mean < 0.5 * bc);
    assert_true(a.row[RCH_EST_LTLM + 1].rmse_mm.mean < 0.5 * bc);
    assert_int_equal(a.n_ltlm, 2);
    assert_true(fabs(rch_compare_lm_time_ms(&a) - a.row[RCH_EST_LM + 1].time_ms.mean) < 1e-12);
    /* same seed, same figures (timings aside) */
    cfg.curves = 0;
    assert_int_equal(rch_compare_run(&b, &cfg, &g_robot, g_s, NS, NULL, &d), 0);
    for (size_t k = 0; k < 2 * RCH_COMPARE_ROWS; ++k)
        assert_true(a.cell[k].ok == b.cell[k].ok && a.cell[k].held_out.rmse_mm == b.cell[k].held_out.rmse_mm &&
                    a.cell[k].held_out.max_mm == b.cell[k].held_out.max_mm &&
                    a.cell[k].iterations == b.cell[k].iterations);
    assert_int_equal(b.curve[RCH_EST_LM].n, 0);
    /* JSON: valid, every method run present */
    {
        char *buf = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&buf, &len);
        assert_non_null(f);
        rch_compare_json(f, &a, &cfg, "a \"quoted\\ path", 0, NULL);
        fclose(f);
        rch_json *j = rch_json_parse(buf, len, "compare", &d);
        if (!j)
            fail_msg("not JSON: %s\n%s", d.msg, buf);
        assert_string_equal(rch_json_get(j, "data")->str, "a \"quoted\\ path");
        assert_int_equal(rch_json_get(j, "methods")->n, 5);
        rch_json_free(j);
        free(buf);
    }
    rch_compare_free(&a);
    rch_compare_free(&b);
}

/* --params common: every method moves the one set (rc_est_subset at the
 * case's start), no parameter outside it; the model files of case 1 are
 * written (rcal-model/2) and read back. */
static void test_common_set_and_models(void **state)
{
    rch_compare_config cfg;
    rch_compare_result a;
    rch_diag d;
    char dir[64] = "/tmp/rcal_cmp_models_XXXXXX";
    (void)state;
    assert_non_null(mkdtemp(dir));
    rch_compare_defaults(&cfg);
    cfg.cases = 1;
    cfg.samples = 70;
    cfg.test_fraction = 0.2;
    cfg.seed = 4;
    cfg.run[RCH_EST_PF] = cfg.run[RCH_EST_SCA] = cfg.run[RCH_EST_QIBAS] = 0; /* the slow ones (valgrind) */
    cfg.params = RCH_PARAMS_COMMON;
    cfg.models_dir = dir;
    assert_int_equal(rch_compare_run(&a, &cfg, &g_robot, g_s, NS, NULL, &d), 0);
    assert_int_equal(a.params, RCH_PARAMS_COMMON);
    assert_int_equal(a.n_common.n, 1);
    const unsigned nc = (unsigned)a.n_common.mean;
    assert_true(nc > 10 && nc < a.n_params);
    for (int id = 0; id < RCH_EST_COUNT; ++id) {
        if (!cfg.run[id])
            continue;
        const rch_compare_cell *e = &a.cell[id + 1];
        assert_true(e->ok);
        if (id == RCH_EST_LM || id == RCH_EST_LTLM)
            assert_true(e->n_moved <= nc); /* the rank they found inside the set */
        else
            assert_int_equal(e->n_moved, nc);
    }
    /* the files: read back, each the fit of its row; outside the set = BC */
    rch_robot bc, mr;
    char path[160], name[64];
    rch_compare_model_file(name, sizeof name, 0);
    assert_string_equal(name, "BC.json");
    snprintf(path, sizeof path, "%s/%s", dir, name);
    assert_int_equal(rch_robot_load(&bc, path, &d), 0);
    unsigned same_all = 0;
    for (int r = 1; r < RCH_COMPARE_ROWS; ++r) {
        if (!cfg.run[r - 1])
            continue;
        rch_compare_model_file(name, sizeof name, r);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        if (rch_robot_load(&mr, path, &d) != 0)
            fail_msg("%s: %s", path, d.msg);
        assert_true(mr.unc.present); /* rcal-model/2 */
        rc_metrics met;
        assert_int_equal(rc_eval(&met, &mr.model, g_s, NS), RC_OK);
        unsigned moved = 0;
        for (unsigned k = 0; k < RC_N_DH + 3; ++k)
            moved += fabs(mr.model.x[k] - bc.model.x[k]) > 1e-9;
        assert_true(moved >= 1 && moved <= nc); /* never outside the common set */
        same_all += moved == nc;
    }
    assert_true(same_all >= 1);
    rch_compare_free(&a);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void test_compare_refused(void **state)
{
    rch_compare_config cfg;
    rch_compare_result r;
    rch_diag d;
    (void)state;
    rch_compare_defaults(&cfg);
    cfg.samples = NS + 1; /* more rows than the data has */
    assert_int_equal(rch_compare_run(&r, &cfg, &g_robot, g_s, NS, NULL, &d), -1);
    assert_non_null(strstr(d.msg, "rows"));
    rch_compare_free(&r);
    cfg.samples = 20; /* 18 training rows: fewer than the base parameters */
    assert_int_equal(rch_compare_run(&r, &cfg, &g_robot, g_s, NS, NULL, &d), -1);
    assert_non_null(strstr(d.msg, "training samples"));
    rch_compare_free(&r);
    rch_compare_defaults(&cfg);
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        cfg.run[i] = 0; /* nothing to run is an error, not an empty success */
    assert_int_equal(rch_compare_run(&r, &cfg, &g_robot, g_s, NS, NULL, &d), -1);
    rch_compare_free(&r);
}

static void test_chaos(void **state)
{
    rch_chaos_config cfg;
    rch_chaos_result r;
    rch_diag d;
    (void)state;
    rch_chaos_defaults(&cfg);
    cfg.points = 100000000ul; /* issue 12: --points 1e8 --starts 1e5 */
    cfg.starts = 100000ul;
    assert_int_equal(rch_chaos_check(&cfg, &d), -1);
    assert_non_null(strstr(d.msg, "limit of 1e+09"));
    assert_int_equal(rch_chaos_run(&r, &cfg, NULL, &d), -1);
    rch_chaos_free(&r);
    rch_chaos_defaults(&cfg);
    assert_true(rch_chaos_cost(&cfg) <= RCH_CHAOS_MAX_ITERATES);
    cfg.starts = 10;
    cfg.step = 0.3; /* r = 0.5 is not on the grid: its figures are absent, not nan */
    assert_int_equal(rch_chaos_run(&r, &cfg, NULL, &d), 0);
    assert_int_equal(r.nr, 14); /* 0, 0.3, ..., 3.9, 4 */
    assert_true(r.r[r.nr - 1] == 4.0);
    assert_true(isnan(r.sd_at_05));
    double sum = 0.0;
    for (size_t k = 0; k < r.nr; ++k)
        assert_true(r.sd[k] >= r.sd[r.best]);
    for (unsigned long b = 0; b < cfg.bins; ++b)
        sum += r.hist[b];
    assert_true(sum == 10.0 * 1000.0);
    assert_true(r.r_hist == r.r[r.best]);
    {
        char *buf = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&buf, &len);
        assert_non_null(f);
        rch_chaos_json(f, &r, &cfg, 0, NULL);
        fclose(f);
        assert_null(strstr(buf, "nan"));
        assert_null(strstr(buf, "inf"));
        rch_json *j = rch_json_parse(buf, len, "chaos", &d);
        if (!j)
            fail_msg("not JSON: %s\n%s", d.msg, buf);
        assert_int_equal(rch_json_get(j, "sd_at_0_5")->type, RCH_JNULL);
        rch_json_free(j);
        free(buf);
    }
    rch_chaos_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_methods_list),
        cmocka_unit_test(test_compare_run),
        cmocka_unit_test(test_common_set_and_models),
        cmocka_unit_test(test_compare_refused),
        cmocka_unit_test(test_chaos),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
