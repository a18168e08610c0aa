/* SPDX-License-Identifier: MIT */
/* test_calib.c - the calibration pipeline behind `rcal calibrate`, in process
 * (rch_calib_run, the BC model, --fix, random poses, statistics) and through
 * the binary (a data path with '"' and '\' gives valid JSON on stdout and in
 * the model file; --out naming an input is refused; no output file when the
 * fit fails). */
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

#include "rc_ident.h"
#include "rch_calib.h"
#include "rch_start.h"
#include "rch_data.h"
#include "rch_json.h"
#include "rch_sim.h"
#include "rch_stats.h"

#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define DEMO RCAL_SOURCE_DIR "/data/sim_irb120.csv"

static rch_calib_cfg demo_cfg(void)
{
    rch_calib_cfg c;
    memset(&c, 0, sizeof c);
    c.data_path = DEMO;
    c.robot_path = ROBOT;
    c.test_fraction = 0.1;
    c.seed = 1;
    return c;
}

/* The pipeline in process: the split, the fit, held-out figures that agree
 * with rc_eval and rch_stats computed here, and the BC model of rch_calib_bc. */
static void test_run_demo(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    const rch_calib_cfg cfg = demo_cfg();
    assert_int_equal(rch_calib_run(&r, &cfg, &d), 0);
    assert_int_equal(r.n_data, 600);
    assert_int_equal(r.n_test, 60);
    assert_int_equal(r.n_train, 540);
    assert_true(r.after_ok && r.finite && r.have_ident);
    assert_true(r.after_m.rmse_mm < 0.1 * r.before_m.rmse_mm);
    assert_int_equal(r.ident.n_params, r.model.n_params); /* 27 and the axis tilt of the parallel joints 2, 3 */
    assert_true(r.ident.rank < r.ident.n_params); /* alpha6 at least */
    /* the held-out figures from the residuals, through rch_stats */
    rch_data data;
    assert_int_equal(rch_data_load(&data, DEMO, 0, &d), 0);
    size_t *idx = malloc(data.n * sizeof *idx);
    assert_non_null(idx);
    rch_split(idx, data.n, 1);
    rch_stats st;
    memset(&st, 0, sizeof st);
    for (size_t i = 0; i < r.n_test; ++i) {
        double l;
        assert_int_equal(rc_meas(&l, NULL, &r.model, &data.s[idx[i]]), RC_OK);
        rch_stats_add(&st, l - data.s[idx[i]].value);
    }
    rc_metrics m;
    rch_stats_metrics(&m, &st);
    assert_int_equal(m.n, r.after_m.n);
    assert_true(fabs(m.rmse_mm - r.after_m.rmse_mm) < 1e-12);
    assert_true(fabs(m.mean_abs_mm - r.after_m.mean_abs_mm) < 1e-12);
    assert_true(fabs(m.sd_mm - r.after_m.sd_mm) < 1e-12);
    assert_true(fabs(m.max_mm - r.after_m.max_mm) < 1e-12);
    /* BC: the same model from the training samples */
    rc_sample *train = rch_data_pick(data.s, idx + r.n_test, r.n_train);
    rc_solve_work *w = malloc(sizeof *w);
    assert_non_null(train);
    assert_non_null(w);
    rc_model bc;
    assert_int_equal(rch_calib_bc(&bc, w, &r.robot.model, 0, train, r.n_train, &d), 0);
    for (unsigned k = 0; k < bc.n_params; ++k)
        assert_true(bc.x[k] == r.before.x[k]);
    for (unsigned k = 0; k < RC_N_DH; ++k) /* geometry nominal, encoder fitted */
        assert_true(bc.x[k] == r.robot.model.x[k]);
    free(w);
    free(train);
    free(idx);
    rch_data_free(&data);
}

/* The two routes to identifiability agree at the demo's solution: the SVD of
 * the scaled Jacobian (rch_ident, LAPACK) and the eigen-decomposition of the
 * normal matrix (rc_ident_normal, the core's route for solvers and planning):
 * same rank, same weak count, same parameter classes, O1 and log det close. */
static void ident_routes(const char *path)
{
    static rch_calib_result r;
    rch_diag d;
    rch_calib_cfg cfg = demo_cfg();
    cfg.data_path = path;
    cfg.no_prior = 1; /* the routes of the data's own identifiability, without the attachment vector */
    cfg.no_dequantize = 1; /* the samples as this test reads them again below */
    assert_int_equal(rch_calib_run(&r, &cfg, &d), 0);
    rch_data data;
    assert_int_equal(rch_data_load(&data, path, 0, &d), 0);
    size_t *idx = malloc(data.n * sizeof *idx);
    assert_non_null(idx);
    rch_split(idx, data.n, 1);
    rc_sample *train = rch_data_pick(data.s, idx + r.n_test, r.n_train);
    rc_solve_work *w = malloc(sizeof *w);
    const unsigned np = r.model.n_params;
    double *V = malloc((size_t)np * np * sizeof *V), *work = malloc(rc_ident_work_size(np) * sizeof *work);
    assert_true(train && w && V && work);
    double cost;
    for (unsigned i = 0; i < np; ++i)
        w->lsq.idx[i] = (uint16_t)i;
    assert_int_equal(rc_normal_eq(w->A, w->lsq.g, &cost, w->lsq.jrow, &r.model, w->lsq.idx, np, train, r.n_train), RC_OK);
    rc_ident id;
    assert_int_equal(rc_ident_normal(&id, V, work, w->A, np, r.n_train), RC_OK);
    const rc_ident *ref = &r.ident.core;
    print_message("rank %u (svd %u), weak %u (svd %u), O1 %.6g (svd %.6g)\n", id.rank, ref->rank, id.n_weak,
                  ref->n_weak, id.observability, ref->observability);
    assert_int_equal(id.rank, ref->rank);
    assert_int_equal(id.n_weak, ref->n_weak);
    assert_int_equal(ref->rank, r.ident.rank);
    for (unsigned i = 0; i < np; ++i)
        assert_int_equal(id.param_class[i], ref->param_class[i]);
    assert_true(fabs(id.observability / ref->observability - 1.0) < 1e-6);
    assert_true(fabs(id.log_det - ref->log_det) < 1e-6 * fabs(ref->log_det));
    free(V);
    free(work);
    free(w);
    free(train);
    free(idx);
    rch_data_free(&data);
}

static void test_ident_routes(void **state)
{
    (void)state;
    ident_routes(DEMO);
    if (access(RCAL_SHARED_DATA, R_OK) == 0)
        ident_routes(RCAL_SHARED_DATA);
    else
        print_message("skipped the real data: %s is absent\n", RCAL_SHARED_DATA);
}

/* The default run's text on the real file, which jumps. */
static char *real_text(rch_calib_result *r)
{
    rch_calib_cfg cfg = demo_cfg();
    cfg.data_path = RCAL_SHARED_DATA;
    rch_diag d;
    assert_int_equal(rch_calib_run(r, &cfg, &d), 0);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    rch_calib_print(f, r);
    assert_int_equal(fclose(f), 0);
    return text;
}

/* The jump check counts the steps far above the residual, the fit takes
 * every step the search found: the note says both, and the number it says
 * are fitted is the "N found" of the jumps' own line (the real file: 2 of
 * 3, then 3). */
static void test_real_jump_counts(void **state)
{
    (void)state;
    if (access(RCAL_SHARED_DATA, R_OK) != 0) {
        print_message("skipped the real data: %s is absent\n", RCAL_SHARED_DATA);
        return;
    }
    static rch_calib_result r;
    char *text = real_text(&r);
    assert_true(r.jumps_auto && r.have_jumps);
    assert_true(r.jumps_found >= 1 && r.jumps_found < r.jump_check_steps);
    assert_true(r.jumps.n_jumps >= r.jump_check_steps); /* the fit with them may find one more */
    char note[256], found[160], after[48] = "";
    if (r.jumps.n_jumps != r.jump_check_steps)
        snprintf(after, sizeof after, " (%u after the fit with them)", r.jumps.n_jumps);
    snprintf(note, sizeof note, "note: the lengths jump in acquisition order: %u of the %u steps the change-point "
             "search found are far above the residual (8 x its robust sd %.4f mm; largest %.3f mm), so all %u are "
             "fitted as nuisance%s", r.jumps_found, r.jump_check_steps, r.jump_check_scale_mm, r.jump_check_max_mm,
             r.jump_check_steps, after);
    snprintf(found, sizeof found, "length jumps in acquisition order (nuisance, not used at a new pose): %u found;",
             r.jumps.n_jumps);
    if (!strstr(text, note) || !strstr(text, found))
        fail_msg("expected '%s' and '%s' in:\n%s", note, found, text);
    print_message("real file: %u of %u steps far above the residual, %u fitted\n", r.jumps_found,
                  r.jump_check_steps, r.jumps.n_jumps);
    free(text);
}

/* The text report ends with the summary: held-out RMSE before -> after and
 * the predicted 3-D accuracy (the figures of the run, as the lines above
 * print them), then the next step when the report names one (the real
 * file: one line naming the command). */
static void test_summary_last(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    const rch_calib_cfg cfg = demo_cfg();
    assert_int_equal(rch_calib_run(&r, &cfg, &d), 0);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    rch_calib_print(f, &r);
    assert_int_equal(fclose(f), 0);
    char want[1024];
    snprintf(want, sizeof want,
             "\nsummary:\n  held-out RMSE %.4f mm before -> %.4f mm after calibration (%zu samples the fit never "
             "saw)\n  predicted 3-D accuracy after compensation (95 %%) at the flange centre: +-%.4f mm (median over the "
             "data's poses; max %.4f), whole workspace +-%.4f mm (median over 2000 random poses; max %.4f)\n",
             r.before_m.rmse_mm, r.after_m.rmse_mm, r.n_test, r.seen_median_mm, r.seen_max_mm,
             r.unc.map.work_median_mm, r.unc.map.work_max_mm);
    const size_t n = strlen(want);
    if (len < n || strcmp(text + len - n, want) != 0) /* the very end: no next step on the demo */
        fail_msg("expected the report to end with:\n%s\ngot:\n%s", want, len > 600 ? text + len - 600 : text);
    free(text);
    if (access(RCAL_SHARED_DATA, R_OK) != 0)
        return;
    text = real_text(&r);
    len = strlen(text);
    const char *sum = strstr(text, "\nsummary:\n");
    assert_non_null(sum);
    /* the next step (more poses, or the diagnosis with what the run fitted), one line, the last */
    const char *next = strstr(sum, "  next: rcal ");
    if (!next || strchr(next, '\n') != text + len - 1)
        fail_msg("the real file's report should end with the next step:\n%s", sum);
    free(text);
}

/* --fix holds the named parameters at nominal; an unknown name is a request
 * error (-2), not a failure of the work. */
static void test_fix(void **state)
{
    (void)state;
    static rch_calib_result r;
    rch_diag d;
    rch_calib_cfg cfg = demo_cfg();
    cfg.fix = "a1,theta6,,d3";
    assert_int_equal(rch_calib_run(&r, &cfg, &d), 0);
    assert_true(r.model.x[RC_P_A(0)] == r.robot.model.x[RC_P_A(0)]);
    assert_true(r.model.x[RC_P_THETA(5)] == r.robot.model.x[RC_P_THETA(5)]);
    assert_true(r.model.x[RC_P_D(2)] == r.robot.model.x[RC_P_D(2)]);
    assert_true(r.model.x[RC_P_A(1)] != r.robot.model.x[RC_P_A(1)]);
    cfg.fix = "a1,nosuch";
    assert_int_equal(rch_calib_run(&r, &cfg, &d), -2);
    assert_non_null(strstr(d.msg, "nosuch"));
    cfg = demo_cfg();
    cfg.data_path = RCAL_SOURCE_DIR "/data/no-such-file.csv";
    assert_int_equal(rch_calib_run(&r, &cfg, &d), -1);
}

/* Random poses stay within the limits shrunk by the margin and cover them. */
static void test_random_poses(void **state)
{
    (void)state;
    rch_robot robot;
    rch_diag d;
    assert_int_equal(rch_robot_load(&robot, ROBOT, &d), 0);
    rc_rng g;
    rc_rng_seed(&g, 3);
    const double margin = 0.1;
    double lo[RC_NJ], hi[RC_NJ];
    for (unsigned j = 0; j < RC_NJ; ++j) {
        lo[j] = 1e9;
        hi[j] = -1e9;
    }
    static rc_sample s[2000];
    rch_sim_poses(s, 2000, &robot.model, margin, &g);
    for (size_t i = 0; i < 2000; ++i)
        for (unsigned j = 0; j < RC_NJ; ++j) {
            const double q = s[i].q_rad[j];
            assert_true(q >= robot.model.q_min_rad[j] + margin && q <= robot.model.q_max_rad[j] - margin);
            lo[j] = q < lo[j] ? q : lo[j];
            hi[j] = q > hi[j] ? q : hi[j];
            assert_true(s[i].value == 0.0 && s[i].group == 0);
        }
    for (unsigned j = 0; j < RC_NJ; ++j) { /* 2000 draws reach within 1 % of each end */
        const double span = robot.model.q_max_rad[j] - robot.model.q_min_rad[j] - 2 * margin;
        assert_true(lo[j] < robot.model.q_min_rad[j] + margin + 0.01 * span);
        assert_true(hi[j] > robot.model.q_max_rad[j] - margin - 0.01 * span);
    }
}

/* Statistics against their definitions on a small series. */
static void test_stats(void **state)
{
    (void)state;
    const double v[5] = {1.0, -2.0, 3.0, -4.0, 0.5};
    rch_stats s;
    rch_stats_of(&s, v, 5);
    assert_int_equal(s.n, 5);
    assert_true(fabs(rch_stats_rms(&s) - sqrt((1 + 4 + 9 + 16 + 0.25) / 5.0)) < 1e-15);
    assert_true(fabs(rch_stats_mean_abs(&s) - 10.5 / 5.0) < 1e-15);
    const double mean = -1.5 / 5.0;
    double ss = 0.0;
    for (int i = 0; i < 5; ++i)
        ss += (v[i] - mean) * (v[i] - mean);
    assert_true(fabs(rch_stats_sd(&s) - sqrt(ss / 4.0)) < 1e-14);
    assert_true(fabs(s.mean - mean) < 1e-15);
    assert_true(s.max_abs == 4.0);
    assert_true(rch_rms(v, 5) == rch_stats_rms(&s));
    rch_stats_of(&s, v, 0);
    assert_true(rch_stats_rms(&s) == 0.0 && rch_stats_sd(&s) == 0.0 && rch_stats_mean_abs(&s) == 0.0);
}

/* ---------------------------------------------------------------- CLI */

static char dir[64];

static int setup_dir(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/rcal_calib_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown_dir(void **state)
{
    (void)state;
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static int copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    char buf[4096];
    size_t k;
    int ok = a && b;
    while (ok && (k = fread(buf, 1, sizeof buf, a)) > 0)
        ok = fwrite(buf, 1, k, b) == k;
    if (a)
        fclose(a);
    if (b && fclose(b) != 0)
        ok = 0;
    return ok ? 0 : -1;
}

/* Run rcal with argv (no shell: the paths hold quotes); stdout to out_path.
 * Returns the exit status. */
static int run_rcal(const char *const argv[], const char *out_path)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        if (!freopen(out_path, "w", stdout) || !freopen("/dev/null", "w", stderr))
            _exit(127);
        execv(RCAL, (char *const *)argv);
        _exit(127);
    }
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) != pid)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static void test_cli_quotes_json(void **state)
{
    (void)state;
    char data[256], out[256], model[256];
    snprintf(data, sizeof data, "%s/da\"ta\\x.csv", dir);
    snprintf(out, sizeof out, "%s/stdout.json", dir);
    snprintf(model, sizeof model, "%s/model.json", dir);
    assert_int_equal(copy_file(DEMO, data), 0);
    const char *argv[] = {RCAL, "calibrate", "--data", data, "--robot=" ROBOT, "--json", "--out", model, NULL};
    assert_int_equal(run_rcal(argv, out), 0);
    rch_diag d;
    rch_json *j = rch_json_load(out, &d);
    assert_non_null(j);
    const rch_json *v = rch_json_get(j, "data");
    assert_non_null(v);
    assert_int_equal(v->type, RCH_JSTR);
    assert_string_equal(v->str, data);
    rch_json_free(j);
    /* the model file: the project's own loader reads it, its calibration member names the path */
    rch_robot back;
    assert_int_equal(rch_robot_load(&back, model, &d), 0);
    assert_true(back.has_nominal && back.has_encoder);
    j = rch_json_load(model, &d);
    assert_non_null(j);
    const rch_json *cal = rch_json_get(j, "calibration");
    assert_non_null(cal);
    v = rch_json_get(cal, "data");
    assert_non_null(v);
    assert_string_equal(v->str, data);
    rch_json_free(j);
}

static void test_cli_out_refused(void **state)
{
    (void)state;
    char data[256], robot[256], out[256], spelled[300];
    snprintf(data, sizeof data, "%s/d.csv", dir);
    snprintf(robot, sizeof robot, "%s/r.json", dir);
    snprintf(out, sizeof out, "%s/stdout.txt", dir);
    snprintf(spelled, sizeof spelled, "%s/./r.json", dir);
    assert_int_equal(copy_file(DEMO, data), 0);
    assert_int_equal(copy_file(ROBOT, robot), 0);
    struct stat before, after;
    assert_int_equal(stat(data, &before), 0);
    const char *a1[] = {RCAL, "calibrate", "--data", data, "--robot", robot, "--out", data, NULL};
    assert_int_equal(run_rcal(a1, out), 2);
    const char *a3[] = {RCAL, "calibrate", "--data", data, "--robot", robot, "--out", spelled, NULL};
    assert_int_equal(run_rcal(a3, out), 2);
    assert_int_equal(stat(data, &after), 0);
    assert_true(before.st_size == after.st_size && before.st_mtime == after.st_mtime);
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, robot, &d), 0); /* the robot file is intact */
}

static void test_cli_no_output_on_failure(void **state)
{
    (void)state;
    char data[256], out[256], model[256];
    snprintf(data, sizeof data, "%s/short.csv", dir);
    snprintf(out, sizeof out, "%s/stdout.txt", dir);
    snprintf(model, sizeof model, "%s/never.json", dir);
    /* 20 rows: too few for 27 parameters */
    FILE *in = fopen(DEMO, "r"), *f = fopen(data, "w");
    assert_non_null(in);
    assert_non_null(f);
    char line[512];
    for (int i = 0; i < 21 && fgets(line, sizeof line, in); ++i)
        fputs(line, f);
    fclose(in);
    fclose(f);
    const char *argv[] = {RCAL, "calibrate", "--data", data, "--robot", ROBOT, "--out", model, NULL};
    assert_int_equal(run_rcal(argv, out), 1);
    assert_false(exists(model));
    const char *bad[] = {RCAL, "calibrate", "--data", DEMO, "--test-fraction=1.5", "--out", model, NULL};
    assert_int_equal(run_rcal(bad, out), 2);
    assert_false(exists(model));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_demo),
        cmocka_unit_test(test_ident_routes),
        cmocka_unit_test(test_real_jump_counts),
        cmocka_unit_test(test_summary_last),
        cmocka_unit_test(test_fix),
        cmocka_unit_test(test_random_poses),
        cmocka_unit_test(test_stats),
        cmocka_unit_test_setup_teardown(test_cli_quotes_json, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_cli_out_refused, setup_dir, teardown_dir),
        cmocka_unit_test_setup_teardown(test_cli_no_output_on_failure, setup_dir, teardown_dir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
