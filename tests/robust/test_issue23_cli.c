/* SPDX-License-Identifier: MIT */
/* test_issue23_cli.c - issue 23 ("Nothing lost, nothing silently wrong"),
 * through the built binaries as a hostile user would run them, class by
 * class: closed standard descriptors, unchecked writes to standard output,
 * outputs that name each other, outputs through links / read-only / killed,
 * reads of paths the user did not give, data no sensor produces, options cut
 * silently. Each case asserts the exit status, the message (the reason named)
 * and what is on disk afterwards (files unchanged, absent, or equal to what
 * a clean run writes). The streaming check of rch_comp_lines is also run
 * in-process (an output that fills up after a few lines). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "rc_comp.h"
#include "rch_comp.h"
#include "rch_robot.h"
#include "rch_sha256.h"

#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define RCAL_RT RCAL_BINARY_DIR "/firmware_host/rcal-rt"
#define R "timeout 60 '" RCAL "'"
#define RT "timeout 60 '" RCAL_RT "'"
#define DEMO RCAL_SOURCE_DIR "/data/sim_irb120.csv"
#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"

static char g_dir[64];
static char g_out[1 << 16], g_err[1 << 14];

/* ---- files in the temporary directory ---- */
static void path_in(char *p, size_t n, const char *name)
{
    snprintf(p, n, "%s/%s", g_dir, name);
}

static int exists(const char *name)
{
    char p[512];
    struct stat st;
    path_in(p, sizeof p, name);
    return lstat(p, &st) == 0;
}

static void hash(char hex[65], const char *name)
{
    char p[512];
    path_in(p, sizeof p, name);
    if (rch_sha256_file(hex, p) != 0)
        strcpy(hex, "absent");
}

static void assert_same_file(const char *a, const char *b)
{
    char ha[65], hb[65];
    hash(ha, a);
    hash(hb, b);
    assert_string_not_equal(ha, "absent");
    if (strcmp(ha, hb) != 0)
        fail_msg("%s and %s differ", a, b);
}

static size_t slurp(char *buf, size_t cap, const char *name)
{
    char p[512];
    size_t n = 0;
    FILE *f;
    path_in(p, sizeof p, name);
    f = fopen(p, "rb");
    if (f) {
        n = fread(buf, 1, cap - 1, f);
        fclose(f);
    }
    buf[n] = '\0';
    return n;
}

/* "cd DIR && ( CMD )", its stdout and stderr to files unless CMD redirects
 * them itself (then to g_out / g_err what reached the files); exit status,
 * 128 + signal for a signal. */
static int sh(const char *fmt, ...)
{
    char cmd[4096], full[4400];
    va_list ap;
    int st;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    snprintf(full, sizeof full, "cd '%s' && { %s ; } > cmd.out 2> cmd.err", g_dir, cmd);
    st = system(full);
    slurp(g_out, sizeof g_out, "cmd.out");
    slurp(g_err, sizeof g_err, "cmd.err");
    assert_true(st != -1);
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

/* The exit status is rc (or, when rc < 0, any non-zero one) and stderr says
 * each needle. */
static void expect(int got, int rc, const char *cmd, const char *const *needles)
{
    if (rc >= 0 ? got != rc : got == 0)
        fail_msg("%s: exit %d, expected %s%d\n  stderr: %s", cmd, got, rc >= 0 ? "" : "non-zero, not ", rc >= 0 ? rc : 0,
                 g_err);
    for (size_t k = 0; needles && needles[k]; ++k)
        if (!strstr(g_err, needles[k]))
            fail_msg("%s: stderr does not say '%s': %s", cmd, needles[k], g_err);
}

#define NEED(...) ((const char *const[]){__VA_ARGS__, NULL})
#define RUN(rc, needles, ...)                                                                                         \
    do {                                                                                                              \
        char c_[2048];                                                                                                \
        snprintf(c_, sizeof c_, __VA_ARGS__);                                                                         \
        expect(sh("%s", c_), rc, c_, needles);                                                                        \
    } while (0)

/* ---- fixtures ---- */
static int setup(void **state)
{
    char cmd[2048];
    (void)state;
    strcpy(g_dir, "/tmp/rcal_i23_XXXXXX");
    if (!mkdtemp(g_dir))
        return -1;
    if (access(RCAL, X_OK) != 0 || access(RCAL_RT, X_OK) != 0) {
        print_message("rcal or rcal-rt not built\n");
        return -1;
    }
    snprintf(cmd, sizeof cmd,
             "cd '%s' && cp '%s' d.csv && cp '%s' r.json && %s calibrate --data d.csv --robot r.json --out m.json "
             "--json > cal.json 2>/dev/null && %s poses --robot r.json --count 4 --seed 5 --out plan.csv >/dev/null",
             g_dir, DEMO, ROBOT, R, R);
    if (system(cmd) != 0)
        return -1;
    /* 20 000 targets inside the limits */
    {
        char p[512];
        path_in(p, sizeof p, "t.csv");
        FILE *f = fopen(p, "w");
        if (!f)
            return -1;
        fputs("q1,q2,q3,q4,q5,q6\n", f);
        for (int i = 0; i < 20000; ++i)
            fprintf(f, "%d.5,%d.25,%d.75,%d,%d.5,%d\n", i % 50 - 25, i % 40 - 10, i % 30 - 15, i % 60 - 30,
                    i % 50 + 10, i % 90 - 45);
        if (fclose(f) != 0)
            return -1;
    }
    snprintf(cmd, sizeof cmd, "cd '%s' && %s compensate --model m.json --in t.csv --out t_ref.csv 2>/dev/null", g_dir,
             R);
    return system(cmd) == 0 ? 0 : -1;
}

static int teardown(void **state)
{
    char cmd[128];
    (void)state;
    if (getenv("RCAL_KEEP_TMP"))
        return 0;
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* ---- class 1: a closed standard descriptor never becomes a file ---- */
static void test_closed_descriptors(void **state)
{
    (void)state;
    /* stdout and stderr closed: the output is what a clean run writes (no
     * warning, no progress line inside), nothing to say so nothing fails */
    RUN(0, NULL, R " compensate --model m.json --in t.csv --out t1.csv >&- 2>&-");
    assert_same_file("t1.csv", "t_ref.csv");
    /* the plan is the plan; its summary on the closed stdout is reported */
    RUN(1, NEED("standard output", "closed"), R " poses --robot r.json --count 4 --seed 5 --out p1.csv >&-");
    assert_same_file("p1.csv", "plan.csv");
    RUN(0, NULL, R " poses --robot r.json --count 4 --seed 5 --out p2.csv 2>&- >/dev/null");
    assert_same_file("p2.csv", "plan.csv");
    /* calibrate with both closed: its model is a model file */
    RUN(-1, NULL, R " calibrate --data d.csv --robot r.json --out m1.json >&- 2>&-");
    {
        static rch_robot rob;
        rch_diag d;
        char p[512];
        path_in(p, sizeof p, "m1.json");
        assert_int_equal(rch_robot_load(&rob, p, &d), 0);
    }
    /* stdin closed: a read error, not an empty input; nothing written */
    RUN(1, NEED("Bad file descriptor"), R " compensate --model m.json --out never1.csv <&-");
    assert_false(exists("never1.csv"));
    /* rcal-rt's tables on a closed stdout */
    RUN(1, NEED("closed"), RT " --emit-c m.json >&-");
}

/* ---- class 2: every write to standard output is checked ---- */
static void test_stdout_checked(void **state)
{
    (void)state;
    RUN(1, NEED("No space left on device", "stopped"), R " compensate --model m.json --in t.csv > /dev/full");
    RUN(1, NEED("Bad file descriptor", "stopped"), R " compensate --model m.json --in t.csv >&-");
    /* a closed pipe: killed by SIGPIPE, or, with SIGPIPE ignored, "Broken pipe" */
    RUN(1, NEED("Broken pipe"),
        "trap '' PIPE; { sleep 0.3; " R " compensate --model m.json --in t.csv 2>cmd.err2; echo $? > st; } | true; "
        "cat cmd.err2 >&2; exit $(cat st)");
    RUN(141, NULL, "{ sleep 0.3; " R " compensate --model m.json --in t.csv; echo $? > st; } | true; exit $(cat st)");
    RUN(1, NEED("write error on standard output", "No space left on device"),
        R " calibrate --data d.csv --robot r.json > /dev/full");
    RUN(1, NEED("No space left on device"), R " calibrate --data d.csv --robot r.json --json > /dev/full");
    RUN(1, NEED("write error on standard output", "closed"), R " diagnose --data d.csv --robot r.json >&-");
    RUN(1, NEED("No space left on device"), R " --version > /dev/full");
    RUN(1, NEED("No space left on device"), RT " --emit-c m.json > /dev/full");
    /* stderr full: the message is lost, the status is not */
    RUN(-1, NULL, R " calibrate --data no-such.csv 2>/dev/full");
}

/* In-process: an output that takes 300 bytes and then fails; the stream
 * stops at the first failed line with the reason, not after the input. */
static void test_stream_stops(void **state)
{
    (void)state;
    static rch_robot robot;
    static rc_comp_stream s;
    rch_diag d;
    char p[512], buf[300];
    path_in(p, sizeof p, "m.json");
    assert_int_equal(rch_robot_load(&robot, p, &d), 0);
    assert_int_equal(rc_comp_stream_init(&s, &robot.model, &robot.nominal, NULL), RC_OK);
    path_in(p, sizeof p, "t.csv");
    FILE *in = fopen(p, "r"), *out = fmemopen(buf, sizeof buf, "w");
    assert_non_null(in);
    assert_non_null(out);
    setvbuf(out, NULL, _IONBF, 0);
    rch_comp_result r;
    memset(&r, 0, sizeof r);
    assert_int_equal(rch_comp_lines(out, &r, in, "t.csv", &s, &robot.model, RCH_COMP_AUTO, NULL, &d), -1);
    fclose(in);
    fclose(out);
    if (r.n > 10)
        fail_msg("%u targets compensated after the output failed", (unsigned)r.n);
    assert_non_null(strstr(d.msg, "write failed"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_descriptors),
        cmocka_unit_test(test_stdout_checked),
        cmocka_unit_test(test_stream_stops),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
