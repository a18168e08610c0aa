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

#include "rch_start.h"
#include "rch_chaos.h"
#include "rch_eval.h"
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
    int run[RCH_EST_ALL];
    rch_diag d;
    (void)state;
    assert_int_equal(rch_compare_methods(run, "lm,M7", &d), 0);
    for (int i = 0; i < RCH_EST_ALL; ++i)
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


/* --literal: the paper's rows are rc_solve's paper variants run from the
 * case's BC start with the case's seed (LTLM-paper's model of case 1 is
 * Algorithm I's, bit for bit), each row labelled with the paper's method
 * number; the JSON carries the paper's Table 6 as published. */
static void test_literal_rows(void **state)
{
    rch_compare_config cfg;
    rch_compare_result a;
    rch_diag d;
    (void)state;
    rch_compare_defaults(&cfg);
    cfg.cases = 1;
    cfg.samples = 70;
    cfg.test_fraction = 0.2;
    cfg.seed = 3;
    for (int i = 0; i < RCH_EST_ALL; ++i)
        cfg.run[i] = i == RCH_EST_LM || i == RCH_EST_LTLM || i >= RCH_EST_COUNT;
    assert_int_equal(rch_compare_run(&a, &cfg, &g_robot, g_s, NS, NULL, &d), 0);
    assert_false(rch_compare_any_failed(&a));
    assert_string_equal(rch_compare_row_name(RCH_EST_LTLM_PAPER + 1), "LTLM-paper");
    assert_int_equal(rch_est_paper_row(RCH_EST_LTLM_PAPER_DEG), 7);
    assert_int_equal(rch_est_paper_row(RCH_EST_LM_PAPER), 1);
    /* the same fit by hand: BC start of the case, Algorithm I, the case's seed */
    {
        size_t idx[NS];
        rch_holdout h;
        rc_model start, m;
        rc_solve_config sc;
        rc_solve_work *w = malloc(sizeof *w);
        assert_non_null(w);
        assert_int_equal(rch_holdout_draw(&h, idx, g_s, NS, 70, 14, cfg.seed * 1000003ull), 0);
        assert_int_equal(rch_calib_start(&start, w, &g_robot, h.train, h.n_train, &d), 0);
        static const rc_method mt[4] = {RC_METHOD_LM_PAPER, RC_METHOD_LM_PAPER_DEG, RC_METHOD_LTLM_PAPER,
                                        RC_METHOD_LTLM_PAPER_DEG};
        for (int k = 0; k < 4; ++k) {
            memset(&sc, 0, sizeof sc);
            sc.method = mt[k];
            sc.seed = cfg.seed * 1000003ull;
            m = start;
            assert_int_equal(rc_solve(&m, NULL, w, &sc, h.train, h.n_train), RC_OK);
            const rc_model *cm = &a.model_case1[RCH_EST_LM_PAPER + k + 1];
            for (unsigned p = 0; p < m.n_params; ++p)
                if (m.x[p] != cm->x[p])
                    fail_msg("%s parameter %u: compare %.17g, rc_solve %.17g", rch_compare_row_name(RCH_EST_LM_PAPER + k + 1),
                             p, cm->x[p], m.x[p]);
            assert_int_equal(a.cell[RCH_EST_LM_PAPER + k + 1].iterations, 50u); /* K = 50, no early exit here */
        }
        /* and differs from the robust row (the literal mode is not a relabelling) */
        unsigned differ = 0;
        for (unsigned p = 0; p < m.n_params; ++p)
            differ += fabs(a.model_case1[RCH_EST_LTLM + 1].x[p] - m.x[p]) > 1e-6;
        assert_true(differ > 3);
        rch_holdout_free(&h);
        free(w);
    }
    {
        char *buf = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&buf, &len);
        assert_non_null(f);
        assert_int_equal(rch_compare_json(f, &a, &cfg, "sim", 0, NULL), 0);
        fclose(f);
        rch_json *j = rch_json_parse(buf, len, "compare", &d);
        if (!j)
            fail_msg("not JSON: %s\n%s", d.msg, buf);
        const rch_json *t6 = rch_json_get(j, "paper_table6");
        assert_non_null(t6);
        assert_int_equal(t6->n, 8);
        assert_string_equal(rch_json_get(t6->items[7], "name")->str, "M7 LTLM");
        assert_true(fabs(rch_json_get(t6->items[7], "rmse_mm")->num - 0.32) < 1e-12);
        assert_true(fabs(rch_json_get(t6->items[1], "max_mm")->num - 0.91) < 1e-12);
        const rch_json *ms = rch_json_get(j, "methods");
        assert_int_equal(ms->n, 7); /* BC, LM, LTLM and the four paper variants */
        assert_string_equal(rch_json_get(ms->items[6], "name")->str, "LTLM-paper-deg");
        assert_int_equal((int)rch_json_get(ms->items[6], "paper_row")->num, 7);
        rch_json_free(j);
        free(buf);
    }
    rch_compare_free(&a);
}

/* --jumps with every method: a 4 mm jump put into the simulated lengths
 * half way through the acquisition is found by every rc_solve method's own
 * search (the method is honoured: LM and LTLM-paper-deg end at different
 * models) and given to EKF and SSLM, and every row predicts the held-out
 * rows far better than without --jumps. */
static void test_jumps_every_method(void **state)
{
    rch_compare_config cfg;
    rch_compare_result a, b;
    rch_diag d;
    rc_sample s[NS];
    (void)state;
    memcpy(s, g_s, sizeof s);
    for (size_t i = NS / 2; i < NS; ++i)
        s[i].value += 4.0; /* t ascends with i */
    rch_compare_defaults(&cfg);
    cfg.cases = 1;
    cfg.samples = NS;
    cfg.test_fraction = 0.2;
    cfg.seed = 5;
    for (int i = 0; i < RCH_EST_ALL; ++i)
        cfg.run[i] = i == RCH_EST_LM || i == RCH_EST_EKF || i == RCH_EST_SSLM || i == RCH_EST_LTLM ||
                     i == RCH_EST_LTLM_PAPER_DEG;
    assert_int_equal(rch_compare_run(&b, &cfg, &g_robot, s, NS, NULL, &d), 0); /* without */
    cfg.jumps = 1;
    if (rch_compare_run(&a, &cfg, &g_robot, s, NS, NULL, &d) != 0)
        fail_msg("%s", d.msg);
    assert_int_equal(a.jumps, 1);
    for (int id = 0; id < RCH_EST_ALL; ++id) {
        if (!cfg.run[id])
            continue;
        const rch_compare_cell *e = &a.cell[id + 1], *e0 = &b.cell[id + 1];
        assert_true(e->ok && e0->ok);
        if (e->n_jumps != 1)
            fail_msg("%s: %u jumps", rch_est_name((rch_est_id)id), e->n_jumps);
        if (!(e->held_out.rmse_mm < 0.5 * e0->held_out.rmse_mm))
            fail_msg("%s: held-out %.4f with --jumps, %.4f without", rch_est_name((rch_est_id)id),
                     e->held_out.rmse_mm, e0->held_out.rmse_mm);
    }
    unsigned differ = 0;
    for (unsigned p = 0; p < RC_N_DH; ++p)
        differ += fabs(a.model_case1[RCH_EST_LM + 1].x[p] - a.model_case1[RCH_EST_LTLM_PAPER_DEG + 1].x[p]) > 1e-9;
    assert_true(differ > 3);
    rch_compare_free(&a);
    rch_compare_free(&b);
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
        cmocka_unit_test(test_literal_rows),
        cmocka_unit_test(test_jumps_every_method),
        cmocka_unit_test(test_compare_refused),
        cmocka_unit_test(test_chaos),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
