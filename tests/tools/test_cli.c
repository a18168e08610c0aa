/* SPDX-License-Identifier: MIT */
/* test_cli.c - rcal compare and rcal chaos end to end on small simulated
 * data: strict JSON out, every method present, the expected ordering of
 * errors, SVG files written, usage errors. Skips (with a message) when the
 * rcal binary has not been built. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rch_data.h"
#include "rch_json.h"
#include "rch_robot.h"
#include "rch_sim.h"

#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"

static char g_dir[64];
static char g_csv[128];

static int setup(void **state)
{
    rch_robot r;
    rch_diag d;
    rch_sim_config c;
    rc_rng g;
    rc_model truth;
    static rc_sample s[80];
    const double enc[3] = {250.0, -460.0, 10.0};
    FILE *f;
    (void)state;
    strcpy(g_dir, "/tmp/rcal_meth_XXXXXX");
    if (!mkdtemp(g_dir))
        return -1;
    snprintf(g_csv, sizeof g_csv, "%s/sim.csv", g_dir);
    if (rch_robot_load(&r, ROBOT, &d) != 0)
        return -1;
    memset(&c, 0, sizeof c);
    c.group_size = 10;
    rch_sim_defaults(&c);
    rc_rng_seed(&g, 5);
    rch_sim_truth(&truth, &r.model, enc, &c, &g);
    if (rch_sim_samples(s, NULL, 80, &truth, &c, &g) != 0)
        return -1;
    f = fopen(g_csv, "w");
    if (!f || rch_data_write(f, s, 80, &r.model) != 0)
        return -1;
    fclose(f);
    return 0;
}

static int teardown(void **state)
{
    char cmd[256];
    (void)state;
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Run a shell command; stdout into *out (malloc'd). Returns the exit code. */
static int run(const char *cmd, char **out)
{
    FILE *p = popen(cmd, "r");
    size_t len = 0, cap = 4096;
    char *buf = malloc(cap);
    int st;
    assert_non_null(p);
    assert_non_null(buf);
    for (;;) {
        size_t k;
        if (len + 1024 > cap) {
            cap *= 2;
            buf = realloc(buf, cap);
            assert_non_null(buf);
        }
        k = fread(buf + len, 1, cap - len - 1, p);
        if (k == 0)
            break;
        len += k;
    }
    buf[len] = '\0';
    st = pclose(p);
    *out = buf;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int have_rcal(void)
{
    if (access(RCAL, X_OK) != 0) {
        print_message("SKIP: %s not built (build the rcal target first)\n", RCAL);
        return 0;
    }
    return 1;
}

static double method_num(const rch_json *methods, const char *name, const char *key)
{
    for (size_t i = 0; i < methods->n; ++i) {
        const rch_json *m = methods->items[i];
        const rch_json *n = rch_json_get(m, "name");
        if (n && n->type == RCH_JSTR && strcmp(n->str, name) == 0) {
            const rch_json *v = rch_json_get(m, key);
            assert_non_null(v);
            assert_int_equal(v->type, RCH_JNUM);
            return v->num;
        }
    }
    fail_msg("method %s missing from the JSON", name);
    return NAN;
}

static void test_compare_json_and_plots(void **state)
{
    char cmd[1024], *out = NULL, plots[128], path[256];
    rch_diag d;
    rch_json *j;
    static const char *const names[] = {"BC", "LM", "EKF", "PF", "SCA", "QIBAS", "SSLM", "LTLM"};
    struct stat sb;
    (void)state;
    if (!have_rcal())
        skip();
    snprintf(plots, sizeof plots, "%s/plots", g_dir);
    snprintf(cmd, sizeof cmd,
             "'%s' compare --data '%s' --robot '%s' --cases 2 --samples 70 --test-fraction 0.2 "
             "--seed 3 --json --plots '%s'",
             RCAL, g_csv, ROBOT, plots);
    assert_int_equal(run(cmd, &out), 0);
    j = rch_json_parse(out, strlen(out), "compare", &d);
    if (!j)
        fail_msg("compare --json is not valid JSON: %s\n%s", d.msg, out);
    {
        const rch_json *m = rch_json_get(j, "methods");
        assert_non_null(m);
        assert_int_equal(m->type, RCH_JARR);
        assert_int_equal(m->n, 8);
        for (size_t i = 0; i < 8; ++i) {
            const rch_json *n = rch_json_get(m->items[i], "name");
            assert_string_equal(n->str, names[i]);
            assert_true(method_num(m, names[i], "rmse_mm") >= 0.0);
            assert_true(method_num(m, names[i], "rmse_std_mm") >= 0.0);
            assert_true(method_num(m, names[i], "mean_abs_mm") <= method_num(m, names[i], "rmse_mm") + 1e-9);
            assert_true(method_num(m, names[i], "max_mm") >= method_num(m, names[i], "rmse_mm") - 1e-9);
            assert_true(method_num(m, names[i], "time_ms") >= 0.0);
        }
        /* simulated truth with 0.1 deg joint rounding: LM, SSLM, LTLM and
         * EKF must beat BC clearly; nothing may be worse than BC by much */
        const double bc = method_num(m, "BC", "rmse_mm");
        assert_true(bc > 0.2);
        assert_true(method_num(m, "LM", "rmse_mm") < 0.5 * bc);
        assert_true(method_num(m, "LTLM", "rmse_mm") < 0.5 * bc);
        assert_true(method_num(m, "SSLM", "rmse_mm") < 0.5 * bc);
        assert_true(method_num(m, "EKF", "rmse_mm") < 0.5 * bc);
        assert_true(fabs(method_num(m, "LM", "time_ratio_lm") - 1.0) < 1e-9);
        assert_int_equal((int)rch_json_get(j, "n_test")->num, 14);
        assert_int_equal((int)rch_json_get(j, "n_train")->num, 56);
        assert_int_equal(rch_json_get(j, "cases_rmse_mm")->n, 2);
        assert_non_null(rch_json_get(j, "ltlm_parameters"));
    }
    rch_json_free(j);
    free(out);
    {
        static const char *const files[] = {"convergence.svg", "convergence_zoom.svg", "rmse_bars.svg",
                                            "time_bars.svg", "per_sample.svg"};
        for (size_t i = 0; i < 5; ++i) {
            FILE *f;
            char head[128] = {0};
            snprintf(path, sizeof path, "%s/%s", plots, files[i]);
            assert_int_equal(stat(path, &sb), 0);
            assert_true(sb.st_size > 500);
            f = fopen(path, "r");
            assert_non_null(f);
            assert_true(fread(head, 1, sizeof head - 1, f) > 0);
            fclose(f);
            assert_non_null(strstr(head, "<svg"));
        }
    }
}

/* --params both: two tables, the models of case 1 under DIR/paper and
 * DIR/common; --json takes one set. */
static void test_compare_params_both(void **state)
{
    char cmd[1024], dir[64] = "/tmp/rcal_cli_params_XXXXXX", *out = NULL;
    (void)state;
    if (!have_rcal())
        skip();
    assert_non_null(mkdtemp(dir));
    snprintf(cmd, sizeof cmd,
             "'%s' compare --data '%s' --robot '%s' --cases 1 --samples 50 --methods lm,ekf,sslm --params both "
             "--models '%s/m' --plots '%s/p' 2>/dev/null",
             RCAL, g_csv, ROBOT, dir, dir);
    assert_int_equal(run(cmd, &out), 0);
    assert_non_null(strstr(out, "parameter set: paper"));
    assert_non_null(strstr(out, "parameter set: common"));
    free(out);
    static const char *const files[] = {"m/paper/BC.json", "m/paper/M1-LM.json", "m/common/M6-SSLM.json",
                                        "m/common/M2-EKF.json", "p/common/convergence_curves.csv"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; ++k) {
        char path[160];
        snprintf(path, sizeof path, "%s/%s", dir, files[k]);
        FILE *f = fopen(path, "r");
        if (!f)
            fail_msg("%s not written", path);
        fclose(f);
    }
    snprintf(cmd, sizeof cmd, "grep -c '^EKF,' '%s/p/common/convergence_curves.csv' >/dev/null", dir);
    assert_int_equal(system(cmd), 0); /* the EKF's curve is there */
    snprintf(cmd, sizeof cmd, "'%s' compare --data '%s' --robot '%s' --params both --json 2>/dev/null", RCAL, g_csv,
             ROBOT);
    assert_int_equal(run(cmd, &out), 2);
    free(out);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void test_compare_human_and_errors(void **state)
{
    char cmd[1024], *out = NULL;
    (void)state;
    if (!have_rcal())
        skip();
    snprintf(cmd, sizeof cmd,
             "'%s' compare --data '%s' --robot '%s' --cases 1 --samples 50 --methods lm,M7 2>/dev/null",
             RCAL, g_csv, ROBOT);
    assert_int_equal(run(cmd, &out), 0);
    assert_non_null(strstr(out, "BC "));
    assert_non_null(strstr(out, "LM "));
    assert_non_null(strstr(out, "LTLM "));
    assert_null(strstr(out, "QIBAS"));
    assert_non_null(strstr(out, "Table 7"));
    free(out);
    snprintf(cmd, sizeof cmd, "'%s' compare --data '%s' --methods foo 2>/dev/null", RCAL, g_csv);
    assert_int_equal(run(cmd, &out), 2);
    free(out);
    snprintf(cmd, sizeof cmd, "'%s' compare --data '%s' --robot '%s' --samples 100000 2>/dev/null", RCAL, g_csv,
             ROBOT);
    assert_int_equal(run(cmd, &out), 2);
    free(out);
    snprintf(cmd, sizeof cmd, "'%s' compare 2>/dev/null", RCAL);
    assert_int_equal(run(cmd, &out), 2);
    free(out);
    snprintf(cmd, sizeof cmd, "'%s' compare --data /nonexistent.csv --robot '%s' 2>/dev/null", RCAL, ROBOT);
    assert_int_equal(run(cmd, &out), 1);
    free(out);
}

static void test_chaos(void **state)
{
    char cmd[512], *out = NULL, path[256];
    rch_diag d;
    rch_json *j;
    struct stat sb;
    (void)state;
    if (!have_rcal())
        skip();
    snprintf(cmd, sizeof cmd, "'%s' chaos --starts 10 --step 0.05 --json --plots '%s/chaos'", RCAL, g_dir);
    assert_int_equal(run(cmd, &out), 0);
    j = rch_json_parse(out, strlen(out), "chaos", &d);
    if (!j)
        fail_msg("chaos --json is not valid JSON: %s", d.msg);
    {
        const double iid = rch_json_get(j, "sd_iid")->num;
        const double best = rch_json_get(j, "sd_best")->num;
        const double rb = rch_json_get(j, "r_best")->num;
        const rch_json *curve = rch_json_get(j, "curve");
        const rch_json *hist = rch_json_get(j, "histogram");
        double sum = 0.0;
        assert_true(fabs(iid - sqrt(20.0)) < 1e-6); /* Eq. 12 with N - 1: points / bins for independent draws */
        assert_true(rb >= 0.0 && rb <= 4.0);
        assert_int_equal(curve->n, 81); /* 0, 0.05, ..., 4 */
        assert_int_equal(hist->n, 50);
        for (size_t b = 0; b < hist->n; ++b)
            sum += hist->items[b]->num;
        assert_true(fabs(sum - 10.0 * 1000.0) < 0.5);
        /* the minimum is the minimum of the curve */
        for (size_t k = 0; k < curve->n; ++k)
            assert_true(curve->items[k]->items[1]->num >= best - 1e-12);
        /* r = 4 is the logistic map (arcsine density): far less uniform */
        assert_true(curve->items[80]->items[1]->num > 2.0 * iid);
    }
    rch_json_free(j);
    free(out);
    snprintf(path, sizeof path, "%s/chaos/chaos_sd.svg", g_dir);
    assert_int_equal(stat(path, &sb), 0);
    snprintf(path, sizeof path, "%s/chaos/chaos_hist.svg", g_dir);
    assert_int_equal(stat(path, &sb), 0);
    snprintf(cmd, sizeof cmd, "'%s' chaos --r 5 2>/dev/null", RCAL);
    assert_int_equal(run(cmd, &out), 2);
    free(out);
}

/* --encoder X,Y,Z of rcal simulate and rcal poses (rcal_opt_triple): three
 * finite numbers or exit 2 with a message naming the option; blanks around
 * the numbers are fine. */
static void test_encoder_option(void **state)
{
    static const char *const bad[] = {"1e999,0,0", "0,-1e999,0", "nan,0,0", "1,2",   "1,2,3,4",
                                      "1,2,3x",    "1,,3",       "x,y,z",   "1;2;3", ""};
    char cmd[512], *out = NULL;
    (void)state;
    if (!have_rcal())
        skip();
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        snprintf(cmd, sizeof cmd, "'%s' simulate --encoder '%s' --samples 5 --out '%s/enc.csv' 2>&1", RCAL, bad[k],
                 g_dir);
        if (run(cmd, &out) != 2 || !strstr(out, "--encoder"))
            fail_msg("simulate --encoder '%s': expected exit 2 and a message naming --encoder, got: %s", bad[k], out);
        free(out);
        snprintf(cmd, sizeof cmd, "'%s' poses --encoder '%s' --count 5 --out '%s/enc_poses.csv' 2>&1", RCAL, bad[k],
                 g_dir);
        if (run(cmd, &out) != 2 || !strstr(out, "--encoder"))
            fail_msg("poses --encoder '%s': expected exit 2 and a message naming --encoder, got: %s", bad[k], out);
        free(out);
    }
    snprintf(cmd, sizeof cmd, "'%s' simulate --encoder ' 250, -460 ,10 ' --samples 5 --out '%s/enc.csv' 2>&1", RCAL,
             g_dir);
    assert_int_equal(run(cmd, &out), 0);
    free(out);
}

/* Issue 12 regressions for compare, chaos and grind: every number checked
 * against its stated range (no wrap, no "0 means default"), an empty method
 * list refused, an absurd chaos request refused naming the limit, no nan in
 * the JSON, --opt=value and -h accepted. Each case: exit code and a word the
 * message must contain. */
static void test_issue12_options(void **state)
{
    static const struct {
        const char *args;
        int rc;
        const char *needle;
    } cases[] = {
        {"compare --data '%s' --methods ''", 2, "--methods"},
        {"compare --data '%s' --methods 'lm,'", 2, "--methods"},
        {"compare --data '%s' --methods=,", 2, "--methods"},
        {"compare --data '%s' --cases 4294967297", 2, "--cases"},
        {"compare --data '%s' --cases 0", 2, "--cases"},
        {"compare --data '%s' --seed ' -1'", 2, "--seed"},
        {"compare --data '%s' --test-fraction 1", 2, "--test-fraction"},
        {"compare --data '%s' --test-fraction 0x1p-2", 2, "--test-fraction"},
        {"compare --data='%s' --samples=40 --cases=1 --methods=LM --test-fraction=0.25", 0, "LM "},
        {"compare -h", 0, "--methods"},
        {"chaos --points 1e8 --starts 1e5", 2, "10000000"},
        {"chaos --points 100000000 --starts 100000", 2, "10000000"},
        {"chaos --points 10000000 --starts 100000", 2, "limit of 1e+09"},
        {"chaos --starts 0", 2, "--starts"},
        {"chaos --bins 4294967298", 2, "--bins"},
        {"chaos --r 4.5", 2, "--r"},
        {"chaos --step=0.3 --starts=5 --json", 0, "\"sd_at_0_5\": null"},
        {"chaos -h", 0, "1e9"},
        {"grind -h", 0, "--surface"},
        {"grind --model a --truth b --max-dev-deg 0", 2, "--max-dev-deg"},
        {"grind --model a --truth b --max-dev-deg -1", 2, "--max-dev-deg"},
        {"grind --model a", 2, "--truth"},
        {"grind --model a --truth b --surface plane:ds=0.05,step=0.2,h=100", 2, "limit of 200000"},
    };
    char cmd[1024], args[512], *out = NULL;
    (void)state;
    if (!have_rcal())
        skip();
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        snprintf(args, sizeof args, cases[k].args, g_csv);
        if (strncmp(args, "compare --data", 14) == 0)
            snprintf(cmd, sizeof cmd, "'%s' %s --robot '%s' 2>&1", RCAL, args, ROBOT);
        else
            snprintf(cmd, sizeof cmd, "'%s' %s 2>&1", RCAL, args);
        const int rc = run(cmd, &out);
        if (rc != cases[k].rc || !strstr(out, cases[k].needle))
            fail_msg("rcal %s: expected exit %d and '%s', got %d: %s", args, cases[k].rc, cases[k].needle, rc, out);
        assert_null(strstr(out, "nan,"));
        free(out);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_compare_json_and_plots),
        cmocka_unit_test(test_compare_human_and_errors),
        cmocka_unit_test(test_compare_params_both),
        cmocka_unit_test(test_chaos),
        cmocka_unit_test(test_encoder_option),
        cmocka_unit_test(test_issue12_options),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
