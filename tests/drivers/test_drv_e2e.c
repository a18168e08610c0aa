/* SPDX-License-Identifier: MIT */
/* test_drv_e2e.c - end to end: rcal_simdisplay on a pty, `rcal acquire`
 * through the POSIX backend, the file calibrated with `rcal calibrate`.
 *  - clean ASCII stream with noise: the file calibrates to the truth;
 *  - STX, polled, with dropped/corrupted bytes, garbage and silences: every
 *    pose recorded, every length the true one;
 *  - Modbus with faults, interrupted by a disconnect mid-frame and by a
 *    crash mid-write, then resumed: the same file as an uninterrupted run
 *    (the wall-clock column t_unix_ms excluded).
 * The truth comes from `rcal simulate`, the pose plan from `rcal poses`. */
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "rc_model.h"
#include "rch_data.h"
#include "rch_robot.h"

#define NPOSES 40

static char g_dir[256];
static double g_true_len[NPOSES];

static int run(const char *fmt, ...)
{
    char cmd[4096];
    va_list ap;
    int r;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    r = system(cmd);
    return WIFEXITED(r) ? WEXITSTATUS(r) : -1;
}

typedef struct simproc {
    pid_t pid;
    FILE *out;
    char pty[128];
} simproc;

/* Start the simulated display with extra options; wait for its pty path. */
static void sim_start(simproc *s, const char *opts)
{
    int fd[2];
    char cmd[4096];
    assert_int_equal(pipe(fd), 0);
    snprintf(cmd, sizeof cmd, "exec %s --truth %s/truth.json --poses %s/plan.csv --follow %s/announce "
             "--max-seconds 300 %s 2>>%s/sim.log", SIMDISPLAY_EXE, g_dir, g_dir, g_dir, opts, g_dir);
    s->pid = fork();
    assert_true(s->pid >= 0);
    if (s->pid == 0) {
        dup2(fd[1], 1);
        close(fd[0]);
        close(fd[1]);
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    s->out = fdopen(fd[0], "r");
    assert_non_null(s->out);
    assert_non_null(fgets(s->pty, sizeof s->pty, s->out));
    s->pty[strcspn(s->pty, "\n")] = '\0';
    assert_true(strncmp(s->pty, "/dev/", 5) == 0);
}

static void sim_stop(simproc *s)
{
    int st;
    if (s->pid > 0) {
        kill(s->pid, SIGTERM);
        waitpid(s->pid, &st, 0);
    }
    if (s->out)
        fclose(s->out);
    s->pid = 0;
    s->out = NULL;
}

static int acquire(const simproc *s, const char *protocol, const char *out, const char *extra)
{
    return run("%s acquire --backend posix --port %s --protocol %s --poses %s/plan.csv --out %s/%s "
               "--announce %s/announce --settle-ms 150 --read-timeout-ms 300 --pose-timeout-s 20 "
               "--reconnect-s 1 --poll-interval-ms 20 --quiet %s >>%s/acquire.log 2>&1",
               RCAL_EXE, s->pty, protocol, g_dir, g_dir, out, g_dir, extra, g_dir);
}

/* Load an acquisition file; check that it holds every pose once, in order,
 * with L within tol_mm of the truth. */
/* Every sample within tol_mm of the truth, the last within last_tol_mm (a
 * display that froze may have frozen within the follow tolerance of a pose). */
static void check_file_prefix(const char *name, int n_expected, double tol_mm, double last_tol_mm)
{
    char path[512], line[512];
    FILE *f;
    int n = 0;
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(line, sizeof line, f));
    assert_true(strncmp(line, "pose,q1,q2,q3,q4,q5,q6,L,", 25) == 0);
    while (fgets(line, sizeof line, f)) {
        int pose;
        double q[6], L;
        assert_int_equal(sscanf(line, "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &pose, &q[0], &q[1], &q[2], &q[3], &q[4], &q[5], &L), 8);
        assert_int_equal(pose, n);
        const double t = n + 1 == n_expected ? last_tol_mm : tol_mm;
        if (!(L > g_true_len[n] - t && L < g_true_len[n] + t))
            fail_msg("%s pose %d: L %.4f, truth %.4f", name, n, L, g_true_len[n]);
        ++n;
    }
    fclose(f);
    assert_int_equal(n, n_expected);
}

static void check_file(const char *name, double tol_mm)
{
    check_file_prefix(name, NPOSES, tol_mm, tol_mm);
}

/* The file without its last column (the wall clock). */
static char *strip_time(const char *name)
{
    char path[512], line[512];
    FILE *f;
    size_t cap = 1 << 16, len = 0;
    char *s = malloc(cap);
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(s);
    while (fgets(line, sizeof line, f)) {
        char *c = strrchr(line, ',');
        if (c)
            *c = '\0';
        len += (size_t)snprintf(s + len, cap - len, "%s\n", line);
        assert_true(len < cap);
    }
    fclose(f);
    return s;
}

static int setup(void **state)
{
    rch_robot *r = calloc(1, sizeof *r);
    rch_data d;
    rch_diag dg;
    char path[512];
    (void)state;
    snprintf(g_dir, sizeof g_dir, "%s/drv_e2e_XXXXXX", RCAL_BINARY_DIR);
    if (!mkdtemp(g_dir) || !r)
        return -1;
    /* the truth from `rcal simulate`, the plan from `rcal poses` */
    if (run("%s simulate --robot %s/data/irb120.json --out %s/sim.csv --truth-out %s/truth.json "
            "--samples 10 --seed 5 >%s/simulate.log 2>&1",
            RCAL_EXE, RCAL_SOURCE_DIR, g_dir, g_dir, g_dir) != 0)
        return -1;
    if (run("%s poses --robot %s/data/irb120.json --count %d --seed 5 --out %s/plan.csv >%s/poses.log 2>&1",
            RCAL_EXE, RCAL_SOURCE_DIR, NPOSES, g_dir, g_dir) != 0)
        return -1;
    snprintf(path, sizeof path, "%s/truth.json", g_dir);
    if (rch_robot_load(r, path, &dg) != 0)
        return -1;
    snprintf(path, sizeof path, "%s/plan.csv", g_dir);
    if (rch_data_load(&d, path, RCH_DATA_NO_LEN, &dg) != 0 || d.n != NPOSES)
        return -1;
    for (size_t i = 0; i < d.n; ++i) {
        rc_sample s = d.s[i];
        s.t = (double)i / (double)(d.n - 1);
        if (rc_meas(&g_true_len[i], NULL, &r->model, &s) != RC_OK)
            return -1;
    }
    rch_data_free(&d);
    free(r);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    if (getenv("RCAL_KEEP_TMP") == NULL)
        run("rm -rf %s", g_dir);
    return 0;
}

static double json_num(const char *js, const char *obj, const char *key)
{
    const char *p = strstr(js, obj);
    double v = -1;
    if (!p)
        return -1;
    p = strstr(p, key);
    if (!p || !(p = strchr(p, ':')) || sscanf(p + 1, "%lf", &v) != 1)
        return -1;
    return v;
}

/* Clean ASCII stream with 3 um noise: recorded L within 10 um of the truth,
 * and `rcal calibrate` fits the file to the display's resolution and moves
 * the flange towards the truth. */
static void test_ascii_acquire_calibrate(void **state)
{
    simproc s = {0};
    char path[512], *js;
    FILE *f;
    long len;
    double fit, before, after;
    (void)state;
    sim_start(&s, "--protocol ascii --rate-hz 100 --noise-mm 0.003 --settle-ms 100 --seed 1");
    assert_int_equal(acquire(&s, "ascii", "ascii.csv", "--stable-mm 0.03"), 0);
    sim_stop(&s);
    check_file("ascii.csv", 0.01);
    /* the default method (robust LM) */
    assert_int_equal(run("%s calibrate --robot %s/data/irb120.json --data %s/ascii.csv --truth %s/truth.json "
                         "--test-fraction 0 --json >%s/calib.json 2>>%s/acquire.log",
                         RCAL_EXE, RCAL_SOURCE_DIR, g_dir, g_dir, g_dir, g_dir), 0);
    snprintf(path, sizeof path, "%s/calib.json", g_dir);
    f = fopen(path, "r");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    fseek(f, 0, SEEK_SET);
    js = calloc(1, (size_t)len + 1);
    assert_int_equal(fread(js, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    fit = json_num(js, "\"train_after\"", "\"rmse_mm\"");
    before = json_num(js, "\"truth_flange\"", "\"before_rms_mm\"");
    after = json_num(js, "\"truth_flange\"", "\"after_rms_mm\"");
    print_message("calibrate on acquired data: fit rms %.4f mm; flange vs truth %.4f -> %.4f mm\n", fit, before, after);
    assert_true(fit >= 0 && fit < 0.01);
    assert_true(after >= 0 && after < 0.05 && after < before / 10);
    free(js);
}

/* STX polled with every fault but disconnects: no pose lost, no wrong L. */
static void test_stx_faults(void **state)
{
    simproc s = {0};
    (void)state;
    sim_start(&s, "--protocol stx --rate-hz 50 --settle-ms 100 --drop 0.01 --corrupt 0.01 --garbage 0.2 "
                  "--silence-every 50 --silence-ms 500 --reply-delay-ms 2 --seed 2");
    assert_int_equal(acquire(&s, "stx", "stx.csv", "--stable-mm 0.0005"), 0);
    sim_stop(&s);
    check_file("stx.csv", 0.0005 + 1e-9);
}

/* Modbus with faults: an uninterrupted run, and a run cut by a disconnect
 * mid-frame and by a crash mid-write, resumed on a new device: same file. */
static void test_modbus_resume_identical(void **state)
{
    static const char *faults = "--protocol modbus --rate-hz 50 --mb-decimals 3 --mb-order cdab --settle-ms 100 "
                                "--drop 0.005 --corrupt 0.005 --garbage 0.1 --silence-every 60 --silence-ms 400";
    static const char *mb = "--mb-decimals 3 --mb-order cdab --stable-mm 0.0005";
    simproc s = {0};
    char opts[1024], path[512], *a, *b;
    FILE *f;
    (void)state;
    snprintf(opts, sizeof opts, "%s --seed 3", faults);
    sim_start(&s, opts);
    assert_int_equal(acquire(&s, "modbus", "mb_a.csv", mb), 0);
    sim_stop(&s);
    check_file("mb_a.csv", 0.0005 + 1e-9);

    /* interrupted: the display goes away mid-frame after 60 frames */
    snprintf(opts, sizeof opts, "%s --seed 4 --disconnect-after 60", faults);
    sim_start(&s, opts);
    assert_int_equal(acquire(&s, "modbus", "mb_b.csv", mb), 1);
    sim_stop(&s);
    /* a crash mid-write leaves half a line */
    snprintf(path, sizeof path, "%s/mb_b.csv", g_dir);
    f = fopen(path, "a");
    assert_non_null(f);
    fputs("17,-12.3000,45.6", f);
    fclose(f);
    /* resumed on a new device */
    snprintf(opts, sizeof opts, "%s --seed 5", faults);
    sim_start(&s, opts);
    assert_int_equal(acquire(&s, "modbus", "mb_b.csv", mb), 0);
    sim_stop(&s);
    check_file("mb_b.csv", 0.0005 + 1e-9);
    a = strip_time("mb_a.csv");
    b = strip_time("mb_b.csv");
    assert_string_equal(a, b);
    free(a);
    free(b);
    /* a third run has nothing to do */
    sim_start(&s, opts);
    assert_int_equal(acquire(&s, "modbus", "mb_b.csv", mb), 0);
    sim_stop(&s);
}

static int count_samples(const char *name)
{
    char path[512], line[512];
    int rows = -1; /* the header */
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    f = fopen(path, "r");
    if (!f)
        return 0;
    while (fgets(line, sizeof line, f))
        ++rows;
    fclose(f);
    return rows < 0 ? 0 : rows;
}

/* Issue 12: a display that freezes (HOLD pressed, firmware hung) and another
 * device that appears on the port's path after a reconnect (254 mm off) are
 * refused by the follow check, the run stops (exit 1), and none of their
 * readings is recorded: every sample in the file is the truth. */
static void test_frozen_and_foreign_refused(void **state)
{
    simproc s = {0};
    int n;
    (void)state;
    run("rm -f %s/frozen.csv %s/foreign.csv %s/acquire.log", g_dir, g_dir, g_dir);
    sim_start(&s, "--protocol ascii --rate-hz 100 --settle-ms 100 --freeze-after 150 --seed 7");
    assert_int_equal(acquire(&s, "ascii", "frozen.csv", "--stable-mm 0.03 --retries 3"), 1);
    sim_stop(&s);
    n = count_samples("frozen.csv");
    print_message("frozen display: %d of %d poses recorded before it froze, then refused\n", n, NPOSES);
    run("grep 'rcal acquire' %s/acquire.log | tail -4", g_dir);
    assert_true(n < NPOSES);
    assert_int_equal(run("grep -q 'REFUSED' %s/acquire.log", g_dir), 0);
    assert_int_equal(run("grep -q 'frozen' %s/acquire.log", g_dir), 0);
    check_file_prefix("frozen.csv", n, 0.03, 10.0);

    {
        char link[300], opts[600];
        snprintf(link, sizeof link, "%s/display", g_dir);
        snprintf(opts, sizeof opts, "--protocol ascii --rate-hz 100 --settle-ms 100 --disconnect-after 400 "
                 "--reconnect-ms 300 --foreign-offset-mm 254 --link %s --seed 8", link);
        sim_start(&s, opts);
        assert_int_equal(run("%s acquire --backend posix --port %s --protocol ascii --poses %s/plan.csv "
                             "--out %s/foreign.csv --announce %s/announce --settle-ms 150 --read-timeout-ms 300 "
                             "--pose-timeout-s 20 --reconnect-s 3 --retries 3 --stable-mm 0.03 --quiet "
                             ">>%s/acquire.log 2>&1", RCAL_EXE, link, g_dir, g_dir, g_dir, g_dir), 1);
        sim_stop(&s);
        struct stat ls;
        assert_int_equal(lstat(link, &ls), -1); /* stopped by SIGTERM, the display removed its link */
    }
    n = count_samples("foreign.csv");
    print_message("foreign device after a reconnect: %d of %d poses recorded before, then refused\n", n, NPOSES);
    run("grep 'rcal acquire' %s/acquire.log | tail -4", g_dir);
    assert_true(n >= 1 && n < NPOSES);
    assert_int_equal(run("grep -q 'another device' %s/acquire.log", g_dir), 0);
    check_file_prefix("foreign.csv", n, 0.03, 0.03);
}

/* `rcal poses`: a plan inside the joint limits that beats a random plan. */
static void test_poses_plan(void **state)
{
    char path[512], line[512];
    FILE *f;
    double ratio = 0;
    int rows = 0;
    (void)state;
    snprintf(path, sizeof path, "%s/poses.log", g_dir);
    f = fopen(path, "r");
    assert_non_null(f);
    while (fgets(line, sizeof line, f)) {
        const char *p = strstr(line, "ratio ");
        if (p)
            ratio = atof(p + 6);
    }
    fclose(f);
    print_message("rcal poses: O1 planned / random = %.2f\n", ratio);
    assert_true(ratio > 1.1);
    snprintf(path, sizeof path, "%s/plan.csv", g_dir);
    f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "pose,q1,q2,q3,q4,q5,q6\n");
    while (fgets(line, sizeof line, f)) {
        static const double lim[6] = {165, 110, 110, 160, 120, 400};
        double q[6];
        int k;
        assert_int_equal(sscanf(line, "%d,%lf,%lf,%lf,%lf,%lf,%lf", &k, &q[0], &q[1], &q[2], &q[3], &q[4], &q[5]), 7);
        for (int j = 0; j < 6; ++j)
            assert_true(fabs(q[j]) <= lim[j]);
        assert_true(q[2] <= 70.0); /* joint 3: [-110, 70] */
        assert_true(g_true_len[rows] > 240 && g_true_len[rows] < 810);
        ++rows;
    }
    fclose(f);
    assert_int_equal(rows, NPOSES);
}

/* rcal_simdisplay refuses a malformed or out-of-range number option with a
 * message naming it (exit 2, before any pty is opened), and a --script file
 * with a line that is not one finite number (exit 1, file:line). */
static void test_simdisplay_bad_numbers(void **state)
{
    static const char *const bad[][2] = {
        {"--value", "12x"},     {"--value", "1e999"},       {"--noise-mm", "-1"},  {"--decimals", "7"},
        {"--decimals", "x"},    {"--rate-hz", "nan"},       {"--baud", "-9600"},   {"--mb-addr", "300"},
        {"--mb-reg", "0x10000"}, {"--mb-decimals", "3.5"},  {"--drop", "2"},       {"--garbage", ""},
        {"--reconnect-ms", "-5"}, {"--seed", "99999999999999999999999"},           {"--max-seconds", "inf"},
    };
    char path[512];
    FILE *f;
    (void)state;
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        if (run("%s --protocol ascii --value 500 %s '%s' >/dev/null 2>%s/sim_opt.err", SIMDISPLAY_EXE, bad[k][0],
                bad[k][1], g_dir) != 2)
            fail_msg("simdisplay %s '%s': expected exit 2", bad[k][0], bad[k][1]);
        assert_int_equal(run("grep -q -e '%s' %s/sim_opt.err", bad[k][0], g_dir), 0);
    }
    snprintf(path, sizeof path, "%s/script.txt", g_dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("# mm\n500.1\n\n501.2x\n", f);
    fclose(f);
    assert_int_equal(run("%s --value 1 --script %s >/dev/null 2>%s/sim_opt.err", SIMDISPLAY_EXE, path, g_dir), 1);
    assert_int_equal(run("grep -q 'script.txt:4: not a number' %s/sim_opt.err", g_dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poses_plan),
        cmocka_unit_test(test_simdisplay_bad_numbers),
        cmocka_unit_test(test_ascii_acquire_calibrate),
        cmocka_unit_test(test_stx_faults),
        cmocka_unit_test(test_modbus_resume_identical),
        cmocka_unit_test(test_frozen_and_foreign_refused),
    };
    signal(SIGPIPE, SIG_IGN);
    return cmocka_run_group_tests_name("drv_e2e", tests, setup, teardown);
}
