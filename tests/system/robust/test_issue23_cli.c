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
#include "rch_calib.h"
#include "rch_data.h"
#include "rch_comp.h"
#include "rch_compare.h"
#include "rch_report.h"
#include "rch_robot.h"
#include "rch_sha256.h"
#include "rch_text.h"

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

static void write_text(const char *name, const char *text)
{
    char p[512];
    FILE *f;
    path_in(p, sizeof p, name);
    f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fputs(text, f) >= 0, 1);
    assert_int_equal(fclose(f), 0);
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

static void assert_unchanged(const char *name, const char *before)
{
    char h[65];
    hash(h, name);
    if (strcmp(h, before) != 0)
        fail_msg("%s changed", name);
}


/* Leftover temporaries ("NAME.tmpXXXXXX") of any output in the directory. */
static int temporaries(void)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "ls -a '%s' | grep -c '\\.tmp' > '%s/tmp.count'", g_dir, g_dir);
    (void)system(cmd);
    char b[32];
    slurp(b, sizeof b, "tmp.count");
    return atoi(b);
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
    if (strstr(g_err, "Sanitizer")) /* the sanitizer build: a report is a failure whatever the status */
        fail_msg("%s: %s", cmd, g_err);
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

/* ---- class 3: one command's outputs never name each other ---- */
static void test_outputs_distinct(void **state)
{
    char before[65];
    (void)state;
    RUN(2, NEED("--residuals X.json names the same file as --out X.json"),
        R " calibrate --data d.csv --robot r.json --out X.json --residuals X.json");
    assert_false(exists("X.json"));
    write_text("keep.json", "{\"precious\": 1}\n");
    hash(before, "keep.json");
    RUN(2, NEED("same file as --out"), R " calibrate --data d.csv --robot r.json --out keep.json --residuals ./keep.json");
    assert_unchanged("keep.json", before);
    RUN(2, NEED("--report (a file beside the page) p.calibration.json", "same file as --out"),
        R " calibrate --data d.csv --robot r.json --out p.calibration.json --report p.html");
    assert_false(exists("p.html"));
    RUN(2, NEED("--residuals keep.json names the same file as --out keep.json"),
        R " diagnose --data d.csv --robot r.json --out keep.json --residuals keep.json");
    RUN(2, NEED("--report keep.json names the same file as --out keep.json"),
        R " diagnose --data d.csv --robot r.json --out keep.json --report keep.json");
    assert_unchanged("keep.json", before);
    /* an output inside --plots: the rule of the shared output helper */
    RUN(1, NEED("same file as plot file"), R " diagnose --data d.csv --robot r.json --plots . --out residuals_order.csv");
    /* rcal report: the CSVs are named from the page, a user's file is never replaced */
    write_text("report_params.csv", "a user's own file\n");
    hash(before, "report_params.csv");
    /* what the page lacks is named with how to get it, not only counted */
    RUN(0, NEED("x_params.csv", "saying \"not in this run\", below)",
                "  not in this run: the comparison against a simulated truth; needs a simulated truth: rcal calibrate "
                "--truth TRUTH.json",
                "the diagnosis; needs a diagnosis: rcal diagnose --data FILE --json > DIAG.json, then rcal report "
                "--diagnosis DIAG.json"),
        R " report --calibration cal.json --out x.html");
    assert_true(exists("x_metrics.csv") && exists("x_params.csv"));
    char hx[65];
    hash(hx, "x_params.csv");
    RUN(0, NEED("y_params.csv"), R " report --calibration cal.json --out y.html");
    assert_unchanged("x_params.csv", hx); /* a second report keeps the first one's data */
    assert_unchanged("report_params.csv", before);
    /* whole or not at all: one CSV cannot be written, the page is not there either */
    RUN(0, NULL, "mkdir z_params.csv");
    RUN(1, NEED("z_params.csv", "not a regular file"), R " report --calibration cal.json --out z.html");
    assert_false(exists("z.html"));
    assert_false(exists("z_metrics.csv"));
    assert_int_equal(temporaries(), 0);
}

/* ---- class 4: links, modes, read-only files, signals ---- */
static int wait_for_temporary(void)
{
    for (int i = 0; i < 500; ++i) {
        if (temporaries() > 0)
            return 0;
        const struct timespec ts = {0, 10000000};
        nanosleep(&ts, NULL);
    }
    return -1;
}

/* rcal ARGS in the directory, stdin a pipe kept open (so it waits), killed
 * with sig once its temporary output exists; returns the wait status. */
static int killed_run(int sig, const char *const *args)
{
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dup2(fds[0], 0);
        close(fds[0]);
        close(fds[1]);
        if (chdir(g_dir) != 0)
            _exit(126);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        execv(RCAL, (char *const *)args);
        _exit(127);
    }
    close(fds[0]);
    if (wait_for_temporary() != 0) {
        kill(pid, SIGKILL);
        fail_msg("%s %s: no temporary output appeared", args[1], args[2]);
    }
    kill(pid, sig);
    int st = 0;
    waitpid(pid, &st, 0);
    close(fds[1]);
    return st;
}

static void test_links_modes_signals(void **state)
{
    struct stat st;
    char before[65];
    (void)state;
    /* through a symbolic link: the target is replaced, the link stays */
    write_text("real.csv", "old\n");
    RUN(0, NULL, "ln -s real.csv link.csv");
    RUN(0, NULL, R " compensate --model m.json --in t.csv --out link.csv 2>/dev/null");
    {
        char p[512];
        path_in(p, sizeof p, "link.csv");
        assert_int_equal(lstat(p, &st), 0);
        assert_true(S_ISLNK(st.st_mode));
    }
    assert_same_file("real.csv", "t_ref.csv");
    /* the mode of the existing file is kept */
    write_text("six.csv", "old\n");
    RUN(0, NULL, "chmod 0600 six.csv && " R " compensate --model m.json --in t.csv --out six.csv 2>/dev/null");
    {
        char p[512];
        path_in(p, sizeof p, "six.csv");
        assert_int_equal(stat(p, &st), 0);
        assert_int_equal(st.st_mode & 07777, 0600);
    }
    assert_same_file("six.csv", "t_ref.csv");
    /* a read-only file is refused (also for root) and stays */
    write_text("ro.csv", "keep\n");
    hash(before, "ro.csv");
    RUN(1, NEED("read-only (mode 0444)", "chmod u+w"),
        "chmod 0444 ro.csv && " R " compensate --model m.json --in t.csv --out ro.csv");
    assert_unchanged("ro.csv", before);
    RUN(1, NEED("read-only"), R " poses --robot r.json --count 4 --out ro.csv");
    assert_unchanged("ro.csv", before);
    /* SIGINT during compensate --out, SIGTERM during poses --out: no
     * temporary is left, no output appears, the signal is what ended it */
    {
        static const char *const comp[] = {"rcal", "compensate", "--model", "m.json", "--out", "sig.csv", NULL};
        const int w = killed_run(SIGINT, comp);
        assert_true(WIFSIGNALED(w) && WTERMSIG(w) == SIGINT);
        assert_int_equal(temporaries(), 0);
        assert_false(exists("sig.csv"));
    }
    {
        static const char *const poses[] = {"rcal", "poses", "--robot", "r.json", "--count", "1000", "--candidates",
                                            "200000", "--out", "big.csv", NULL};
        const int w = killed_run(SIGTERM, poses);
        assert_true(WIFSIGNALED(w) && WTERMSIG(w) == SIGTERM);
        assert_int_equal(temporaries(), 0);
        assert_false(exists("big.csv"));
    }
}

/* ---- class 5: names inside a file are read only when regular and bounded ---- */
static void test_unasked_reads(void **state)
{
    static char cal[1 << 16], page[1 << 18];
    (void)state;
    const size_t n = slurp(cal, sizeof cal, "cal.json");
    const char *at = strstr(cal, "\"file\":\"d.csv\"");
    assert_non_null(at);
    RUN(0, NULL, "mkfifo fifo && truncate -s 300M sparse.bin");
    static const char *const names[][2] = {{"/dev/zero", "a character device, not a regular file"},
                                           {"/dev/urandom", "a character device, not a regular file"},
                                           {"fifo", "a FIFO, not a regular file"},
                                           {"sparse.bin", "larger than the limit of 256 MiB"}};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k) {
        char edited[sizeof cal + 64];
        snprintf(edited, sizeof edited, "%.*s\"file\":\"%s\"%s", (int)(at - cal), cal, names[k][0],
                 at + strlen("\"file\":\"d.csv\""));
        assert_true(strlen(edited) + 8 > n); /* the whole file, one name replaced */
        write_text("cal_x.json", edited);
        /* timeout 60 would end a read that never ends: exit 124 */
        RUN(0, NULL, R " report --calibration cal_x.json --out prov.html");
        slurp(page, sizeof page, "prov.html");
        if (!strstr(page, names[k][1]))
            fail_msg("%s: the page does not say '%s'", names[k][0], names[k][1]);
        assert_non_null(strstr(page, "was not read"));
    }
}

/* d.csv with field `col` (1-based) of line `line` replaced by v, as name */
static void data_with(const char *name, unsigned line, unsigned col, const char *v)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "awk -F, -v v='%s' 'NR==%u{$%u=v}1' OFS=, d.csv > '%s'", v, line, col, name);
    assert_int_equal(sh("%s", cmd), 0);
}

/* ---- class 6: data no sensor produces ---- */
static void test_impossible_data(void **state)
{
    (void)state;
    /* d.csv: x,y,z,q1..q6,L; line 5's L starts at column 81, line 7's q1 at 29 */
    static const char *const lengths[] = {"0.001", "1e-300", "0", "0.5", "nan", "-3"};
    for (size_t k = 0; k < sizeof lengths / sizeof lengths[0]; ++k) {
        data_with("bad_l.csv", 5, 10, lengths[k]);
        RUN(1, NEED("bad_l.csv:5:81: field 'L'"), R " calibrate --data bad_l.csv --robot r.json");
    }
    data_with("bad_l.csv", 5, 10, "0.5");
    RUN(1, NEED("bad_l.csv:5:81", "metres? rcal reads millimetres"), R " diagnose --data bad_l.csv --robot r.json");
    /* a joint beyond the robot's limits (+-165 deg for q1), in every command that has a robot */
    data_with("bad_q.csv", 7, 4, "175");
    static const char *const need_q[] = {"bad_q.csv:7:29: field 'q1': 175 deg is outside joint 1's limits [-165, 165]",
                                         "check --robot", NULL};
    RUN(1, need_q, R " calibrate --data bad_q.csv --robot r.json");
    RUN(1, need_q, R " calibrate --data d.csv --validate bad_q.csv --robot r.json");
    RUN(1, need_q, R " diagnose --data bad_q.csv --robot r.json");
    RUN(1, need_q, R " evaluate --model m.json --data bad_q.csv");
    RUN(1, need_q, R " compare --data bad_q.csv --robot r.json --cases 1");
    /* the file's rounding is not a fault: 165.04 passes, 165.06 does not */
    data_with("edge_q.csv", 7, 4, "165.04");
    RUN(0, NULL, R " calibrate --data edge_q.csv --robot r.json > /dev/null");
    data_with("edge_q.csv", 7, 4, "-165.06");
    RUN(1, NEED("-165.06 deg is outside"), R " calibrate --data edge_q.csv --robot r.json");
    /* one file twice, by any name; validation data that is training data */
    RUN(0, NULL, "ln d.csv d_hard.csv");
    RUN(2, NEED("--data ./d.csv is the same file as --data d.csv"),
        R " calibrate --data d.csv --data ./d.csv --robot r.json");
    RUN(2, NEED("same file as --data d.csv"), R " calibrate --data d.csv --data d_hard.csv --robot r.json");
    RUN(2, NEED("--validate d_hard.csv is the same file as --data d.csv", "never saw"),
        R " calibrate --data d.csv --validate d_hard.csv --robot r.json");
    /* messages that point the right way: a model path that is a directory, targets without a header */
    RUN(0, NULL, "mkdir -p model_dir && printf 'nan,0,0,0,0,0\\n' > no_header.csv");
    RUN(1, NEED("model_dir: is a directory, not a file"), R " compensate --model model_dir --in no_header.csv --out o.csv");
    RUN(1, NEED("no_header.csv:1:1", "this first line holds numbers", "q1,q2,q3,q4,q5,q6"),
        R " compensate --model m.json --in no_header.csv --out o.csv");
}

/* ---- class 7: options are never silently cut ---- */
static void test_options_not_cut(void **state)
{
    (void)state;
#define ACQ R " acquire --backend posix --protocol ascii-poll --reconnect-s 0 --quiet --port no-such-tty " \
            "--poses plan.csv --out acq.csv"
    RUN(2, NEED("--poll-cmd 'ABCDEFGHIJKLMNOP' is longer than the 15 bytes", "not cut"),
        ACQ " --poll-cmd ABCDEFGHIJKLMNOP");
    assert_false(exists("acq.csv"));
    /* 15 bytes, or 14 and an escaped CR: accepted (then the missing port fails) */
    RUN(1, NEED("no-such-tty"), ACQ " --poll-cmd ABCDEFGHIJKLMNO");
    assert_null(strstr(g_err, "not cut"));
    RUN(1, NEED("no-such-tty"), ACQ " --poll-cmd 'ABCDEFGHIJKLMN\\r'");
    RUN(2, NEED("not cut"), ACQ " --poll-cmd 'ABCDEFGHIJKLMNO\\r'");
#undef ACQ
    if (access(SIMDISPLAY_EXE, X_OK) == 0)
        RUN(2, NEED("--poll-cmd is longer than 15 bytes", "not cut"),
            "timeout 10 '" SIMDISPLAY_EXE "' --poll-cmd ABCDEFGHIJKLMNOPQRSTUVWXYZ");
    /* the command line in a report's provenance says when it was cut */
    {
        char buf[64];
        char a0[] = "calibrate", a1[] = "--data",
             a2[] = "a-very-long-file-name-of-measurements-from-the-robot-cell-number-seven.csv";
        const char *const argv[] = {a0, a1, a2};
        rch_shell_join(buf, sizeof buf, 3, argv);
        assert_non_null(strstr(buf, " ... (cut)"));
        assert_int_equal(strlen(buf), sizeof buf - 16 + strlen(" ... (cut)"));
    }
}

/* Costs that are what they say: the long commands are refused at
 * once with the estimate and the option that raises the limit; a small run
 * takes what its estimate says (within 4x here; the measured figures, within
 * 2x on an idle machine, are in docs/methods.md) */
static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void test_costs_stated(void **state)
{
    (void)state;
    RUN(2, NEED("would take about", "days", "above the limit of 60.0 min", "raise --max-minutes"),
        R " calibrate --data d.csv --robot r.json --method ltlm-paper --max-iter 100000 --cases 1000");
    RUN(2, NEED("both parameter sets", "above the limit of 60 min", "raise --max-minutes"),
        R " compare --data d.csv --robot r.json --cases 10000 --samples 0 --params both");
    RUN(2, NEED("above the limit of 1 min"),
        R " compare --data d.csv --robot r.json --cases 100 --samples 0 --max-minutes 1");
    {
        rch_calib_cfg cfg;
        double t0, t, est, bound;
        rch_calib_cfg_init(&cfg);
        cfg.method = RC_METHOD_LTLM_PAPER;
        cfg.max_iter = 300;
        cfg.cases = 2;
        t0 = now_s();
        RUN(0, NULL, R " calibrate --data d.csv --robot r.json --method ltlm-paper --max-iter 300 --cases 2");
        t = now_s() - t0;
        {
            rch_data d;
            rch_diag dg;
            char p[512];
            path_in(p, sizeof p, "d.csv");
            assert_int_equal(rch_data_load(&d, p, 0, &dg), 0);
            est = rch_calib_estimate_s(&cfg, d.n, &bound);
            rch_data_free(&d);
        }
        print_message("calibrate ltlm-paper --max-iter 300 --cases 2: estimate %.2f s, took %.2f s\n", est, t);
#ifdef NDEBUG /* a sanitizer or valgrind build is slower than the reference figures */
        assert_true(est > 0.25 * t && est < 4.0 * t);
#endif
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_descriptors),
        cmocka_unit_test(test_stdout_checked),
        cmocka_unit_test(test_stream_stops),
        cmocka_unit_test(test_outputs_distinct),
        cmocka_unit_test(test_links_modes_signals),
        cmocka_unit_test(test_unasked_reads),
        cmocka_unit_test(test_impossible_data),
        cmocka_unit_test(test_options_not_cut),
        cmocka_unit_test(test_costs_stated),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
