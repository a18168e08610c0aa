/* SPDX-License-Identifier: MIT */
/* test_hostile_cli.c - issue 12 ("No typo destroys a file, and no broken
 * display becomes a measurement"): every example of the issue, run through
 * the built binaries (build/tools/rcal, build/firmware_host/rcal-rt) as a
 * hostile user would type it, class by class. Each case asserts the exit
 * status, that every file the command was given is byte for byte what it
 * was (SHA-256 before and after), that no output appeared where none may,
 * and the message (the option named, or file:line:col). The in-process tests
 * (tests/tools/host/studies/test_acquire.c, tests/system/robust/test_robust_parsers.c,
 * tests/tools/host/files/test_file.c, ...) assert the mechanisms; this one asserts what
 * a user of the binaries gets. A class-by-class table (class, case, what it
 * gets now) is printed at the end; a case that still misbehaves in a file
 * this test's author could not change is shown as OPEN and asserts only
 * what already holds (nothing written, non-zero exit). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "rch_json.h"
#include "rch_robot.h"
#include "rch_sha256.h"

#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define RCAL_RT RCAL_BINARY_DIR "/firmware_host/rcal-rt"
#define R "timeout 120 '" RCAL "'"
#define RT "timeout 120 '" RCAL_RT "'"
#define DEMO RCAL_SOURCE_DIR "/data/sim_irb120.csv"
#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define ACQ R " acquire --backend posix --protocol ascii --reconnect-s 0 --quiet --port no-such-tty"

static char g_dir[64];
static char g_out[1 << 16], g_err[1 << 14];
static double g_secs, g_worst_secs;
static double g_cpu_secs; /* the last command's CPU time (user + system of its processes): what a bound on its
                             work is asserted on, the wall time depending on the machine's load */
static char g_worst_cmd[256];

/* ---- the table ---- */
typedef struct {
    const char *cls;
    char what[96];
    char got[160];
    int open;
} row;
static row g_rows[160];
static size_t g_nrows;

static void note(const char *cls, int open, const char *what, const char *fmt, ...)
{
    va_list ap;
    row *r;
    if (g_nrows == sizeof g_rows / sizeof g_rows[0])
        return;
    r = &g_rows[g_nrows++];
    r->cls = cls;
    r->open = open;
    snprintf(r->what, sizeof r->what, "%s", what);
    va_start(ap, fmt);
    vsnprintf(r->got, sizeof r->got, fmt, ap);
    va_end(ap);
}

/* first line of stderr, shortened, for the table */
static const char *first_err(void)
{
    static char b[120];
    size_t n = strcspn(g_err, "\n");
    const char *s = g_err;
    if (strncmp(s, "rcal ", 5) == 0 || strncmp(s, "rcal-rt", 7) == 0)
        s += strcspn(s, ":") + (s[strcspn(s, ":")] ? 2 : 0), n = strcspn(s, "\n");
    snprintf(b, sizeof b, "%.*s%s", (int)(n > 100 ? 100 : n), s, n > 100 ? "..." : "");
    return b;
}

/* ---- files in the temporary directory ---- */
static void path_in(char *p, size_t n, const char *name)
{
    snprintf(p, n, "%s/%s", g_dir, name);
}

static void write_bytes(const char *name, const char *bytes, size_t n)
{
    char p[512];
    FILE *f;
    path_in(p, sizeof p, name);
    f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(bytes, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

static void write_text(const char *name, const char *text)
{
    write_bytes(name, text, strlen(text));
}

static int exists(const char *name)
{
    char p[512];
    struct stat st;
    path_in(p, sizeof p, name);
    return stat(p, &st) == 0;
}

/* SHA-256 of a file in the directory, "absent" when it does not exist */
static void hash(char hex[65], const char *name)
{
    char p[512];
    path_in(p, sizeof p, name);
    if (rch_sha256_file(hex, p) != 0)
        strcpy(hex, "absent");
}

/* ---- running a command in the directory ---- */
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

/* Runs "cd DIR && ( CMD )" with stdout/stderr to files (read into g_out
 * and g_err; the binaries run under `timeout 120`); returns the exit status (128 + signal for a
 * signal) and leaves the wall time in g_secs. */
static int sh(const char *fmt, ...)
{
    char cmd[4096], full[4400];
    va_list ap;
    struct timespec t0, t1;
    int st;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    snprintf(full, sizeof full, "cd '%s' && ( %s ) > cmd.out 2> cmd.err", g_dir, cmd);
    struct rusage r0, r1;
    getrusage(RUSAGE_CHILDREN, &r0);
    clock_gettime(CLOCK_MONOTONIC, &t0);
    st = system(full);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    getrusage(RUSAGE_CHILDREN, &r1);
    g_secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    g_cpu_secs = (double)(r1.ru_utime.tv_sec - r0.ru_utime.tv_sec) + (double)(r1.ru_stime.tv_sec - r0.ru_stime.tv_sec) +
                 1e-6 * (double)(r1.ru_utime.tv_usec - r0.ru_utime.tv_usec + r1.ru_stime.tv_usec - r0.ru_stime.tv_usec);
    if (g_secs > g_worst_secs) {
        g_worst_secs = g_secs;
        snprintf(g_worst_cmd, sizeof g_worst_cmd, "%.200s", cmd);
    }
    slurp(g_out, sizeof g_out, "cmd.out");
    slurp(g_err, sizeof g_err, "cmd.err");
    assert_true(st != -1);
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

/* A refused command: exit status rc, each needle in stderr, each named file
 * unchanged (hashes taken before the run), the outputs in `absent` not
 * created. One table row. */
typedef struct {
    const char *keep[4];
    const char *absent[3];
} files;

static void refused(const char *cls, const char *what, int rc, const char *const *needles, const files *fl,
                    const char *fmt, ...)
{
    char cmd[4096], before[4][65], after[65];
    va_list ap;
    int got;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    for (int k = 0; k < 4 && fl && fl->keep[k]; ++k) {
        hash(before[k], fl->keep[k]);
        assert_string_not_equal(before[k], "absent");
    }
    got = sh("%s", cmd);
    if (got != rc)
        fail_msg("%s: exit %d, expected %d\n  stderr: %s", cmd, got, rc, g_err);
    for (size_t k = 0; needles && needles[k]; ++k)
        if (!strstr(g_err, needles[k]))
            fail_msg("%s: stderr does not contain '%s': %s", cmd, needles[k], g_err);
    for (int k = 0; k < 4 && fl && fl->keep[k]; ++k) {
        hash(after, fl->keep[k]);
        if (strcmp(before[k], after) != 0)
            fail_msg("%s: %s changed", cmd, fl->keep[k]);
    }
    for (int k = 0; k < 3 && fl && fl->absent[k]; ++k)
        if (exists(fl->absent[k]))
            fail_msg("%s: %s was created", cmd, fl->absent[k]);
    if (g_cpu_secs >= 30.0) /* the work is bounded: CPU time, not the wall's (under load, sanitizers) */
        fail_msg("%s: %.1f s of CPU (%.1f s wall): the work is not bounded", cmd, g_cpu_secs, g_secs);
    note(cls, 0, what, "exit %d, %s%s (%.2f s)", got, fl && fl->keep[0] ? "inputs unchanged; " : "", first_err(),
         g_secs);
}

#define NEED(...) ((const char *const[]){__VA_ARGS__, NULL})
#define KEEP(...) (&(files){{__VA_ARGS__}, {NULL}})

/* ---- fixtures ---- */
static int setup(void **state)
{
    char cmd[1024];
    (void)state;
    strcpy(g_dir, "/tmp/rcal_hostile_XXXXXX");
    if (!mkdtemp(g_dir))
        return -1;
    if (access(RCAL, X_OK) != 0 || access(RCAL_RT, X_OK) != 0) {
        print_message("rcal or rcal-rt not built\n");
        return -1;
    }
    snprintf(cmd, sizeof cmd,
             "cd '%s' && cp '%s' d.csv && cp '%s' r.json && %s calibrate --data d.csv --robot r.json --out model.json "
             "--json > cal.json 2>/dev/null && %s poses --robot r.json --count 4 --seed 5 --out plan.csv >/dev/null",
             g_dir, DEMO, ROBOT, R, R);
    if (system(cmd) != 0)
        return -1;
    write_text("prog.mod", "MODULE M\n  CONST jointtarget j1:=[[10,20,-30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                           "ENDMODULE\n");
    write_text("a.csv", "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms\n");
    return 0;
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

/* ---- class 1: an output that is also an input ---- */
static void test_output_is_input(void **state)
{
    static const char *const C = "1 output = input";
    (void)state;
    {
        char a[512], b[512];
        path_in(a, sizeof a, "d.csv");
        path_in(b, sizeof b, "d_hardlink.csv");
        assert_int_equal(link(a, b), 0);
        path_in(a, sizeof a, "prog.mod");
        path_in(b, sizeof b, "prog_link.mod");
        assert_int_equal(link(a, b), 0);
    }
    refused(C, "acquire --out a.csv --announce a.csv", 1, NEED("--announce"), KEEP("a.csv", "plan.csv"),
            ACQ " --poses plan.csv --out a.csv --announce a.csv");
    refused(C, "acquire --announce = --poses", 1, NEED("--poses"), &(files){{"plan.csv"}, {"new.csv"}},
            ACQ " --poses plan.csv --out new.csv --announce ./plan.csv");
    refused(C, "acquire --out = --poses", 1, NEED("--poses"), KEEP("plan.csv"),
            ACQ " --poses plan.csv --out plan.csv");
    refused(C, "compensate --in prog.mod --out prog.mod", 1, NEED("--out", "same file as the input"),
            KEEP("prog.mod", "model.json"), R " compensate --model model.json --in prog.mod --out prog.mod");
    refused(C, "compensate --out = --model", 1, NEED("--out", "same file as the input"), KEEP("prog.mod", "model.json"),
            R " compensate --model model.json --in prog.mod --out ./model.json");
    refused(C, "compensate --out = hard link of --in", 1, NEED("same file as the input"), KEEP("prog.mod"),
            R " compensate --model model.json --in prog.mod --out prog_link.mod");
    refused(C, "calibrate --data d.csv --out d.csv", 2, NEED("--out"), KEEP("d.csv", "r.json"),
            R " calibrate --data d.csv --robot r.json --out d.csv");
    refused(C, "calibrate --out = hard link of --data", 2, NEED("--out"), KEEP("d.csv", "r.json"),
            R " calibrate --data d.csv --robot r.json --out d_hardlink.csv");
    refused(C, "calibrate --out = --robot", 2, NEED("--out"), KEEP("d.csv", "r.json"),
            R " calibrate --data d.csv --robot r.json --out ./r.json");
    refused(C, "simulate --out = --truth-out", 1, NEED("--truth-out"), &(files){{"r.json"}, {"s.csv"}},
            R " simulate --robot r.json --samples 5 --out s.csv --truth-out ./s.csv");
    refused(C, "simulate --truth-out = --robot", 1, NEED("--truth-out"), &(files){{"r.json"}, {"s.csv"}},
            R " simulate --robot r.json --samples 5 --out s.csv --truth-out r.json");
    write_text("s_keep.csv", "precious\n");
    refused(C, "simulate --out kept, --truth-out = --robot", 1, NEED("--truth-out"), KEEP("r.json", "s_keep.csv"),
            R " simulate --robot r.json --samples 5 --out s_keep.csv --truth-out r.json");
    refused(C, "poses --out = --robot", 1, NEED("--out"), KEEP("r.json"), R " poses --robot r.json --count 5 --out r.json");
    refused(C, "export --out = --model", 1, NEED("--out"), KEEP("model.json"),
            R " export --model model.json --format urdf --out ./model.json");
    refused(C, "report --out = --calibration", 1, NEED("--out"), KEEP("cal.json", "model.json"),
            R " report --calibration cal.json --model model.json --out cal.json");
    /* a failed fit neither creates nor empties --out */
    {
        char text[4096];
        FILE *f = fopen(DEMO, "r");
        size_t n = 0;
        assert_non_null(f);
        for (int i = 0; i < 21 && fgets(text + n, (int)(sizeof text - n), f); ++i)
            n += strlen(text + n);
        fclose(f);
        write_text("short.csv", text);
        write_text("keep.json", "{\"precious\": true}\n");
        refused(C, "calibrate: failed fit, existing --out", 1, NEED("at least 27"), KEEP("keep.json", "short.csv"),
                R " calibrate --data short.csv --out keep.json");
        refused(C, "calibrate: failed fit, new --out", 1, NEED("at least 27"), &(files){{"short.csv"}, {"never.json"}},
                R " calibrate --data short.csv --out never.json");
    }
}

/* ---- class 2: two acquisitions on one output (lock) ---- */
static void test_two_acquisitions(void **state)
{
    static const char *const C = "2 one output, two acquisitions";
    char cmd[4096], pty[128] = "", pidword[64];
    int fd[2], st = 0;
    pid_t sim, first;
    FILE *simout;
    (void)state;
    if (access(SIMDISPLAY_EXE, X_OK) != 0) {
        print_message("SKIP: %s not built\n", SIMDISPLAY_EXE);
        skip();
    }
    /* the display: a simulated robot following the plan rcal acquire announces */
    assert_int_equal(sh(R " simulate --robot r.json --out sim.csv --truth-out truth.json --samples 5 --seed 5"), 0);
    assert_int_equal(pipe(fd), 0);
    snprintf(cmd, sizeof cmd, "cd '%s' && exec '%s' --truth truth.json --poses plan.csv --follow announce "
             "--protocol ascii --rate-hz 50 --max-seconds 60 2>sim.log", g_dir, SIMDISPLAY_EXE);
    sim = fork();
    assert_true(sim >= 0);
    if (sim == 0) {
        dup2(fd[1], 1);
        close(fd[0]);
        close(fd[1]);
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    simout = fdopen(fd[0], "r");
    assert_non_null(simout);
    assert_non_null(fgets(pty, sizeof pty, simout));
    pty[strcspn(pty, "\n")] = '\0';
    assert_true(strncmp(pty, "/dev/", 5) == 0);
    /* the first acquisition: 4 poses, 1.5 s settling each */
    snprintf(cmd, sizeof cmd, "cd '%s' && exec '%s' acquire --backend posix --protocol ascii --port %s --poses plan.csv "
             "--out acq.csv --announce announce --settle-ms 1500 --read-timeout-ms 300 --quiet >first.out 2>first.err",
             g_dir, RCAL, pty);
    first = fork();
    assert_true(first >= 0);
    if (first == 0) {
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    for (int i = 0; i < 100 && !exists("acq.csv"); ++i)
        nanosleep(&(struct timespec){0, 50000000L}, NULL);
    nanosleep(&(struct timespec){0, 300000000L}, NULL);
    assert_true(exists("acq.csv"));
    snprintf(pidword, sizeof pidword, "pid %ld", (long)first);
    snprintf(cmd, sizeof cmd, "%s acquire --backend posix --protocol ascii --port %s --poses plan.csv --out ./acq.csv "
             "--announce announce2 --quiet", R, pty);
    {
        const int rc = sh("%s", cmd);
        if (rc != 1 || !strstr(g_err, pidword) || !strstr(g_err, "another acquisition"))
            fail_msg("second acquisition: exit %d: %s", rc, g_err);
        note(C, 0, "acquire twice on acq.csv", "second: exit 1, %s", first_err());
    }
    assert_int_equal(waitpid(first, &st, 0), first);
    kill(sim, SIGTERM);
    waitpid(sim, NULL, 0);
    fclose(simout);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    /* the first one recorded every pose once, in order */
    {
        char text[4096];
        int n = 0;
        slurp(text, sizeof text, "acq.csv");
        for (const char *p = strchr(text, '\n'); p && p[1]; p = strchr(p + 1, '\n')) {
            int pose = -1;
            assert_int_equal(sscanf(p + 1, "%d,", &pose), 1);
            assert_int_equal(pose, n);
            ++n;
        }
        assert_int_equal(n, 4);
        note(C, 0, "the first acquisition", "exit 0, 4 poses recorded once each");
    }
}

/* ---- class 3: unbounded work on bad input ---- */
static void test_unbounded_work(void **state)
{
    static const char *const C = "3 unbounded work";
    char big[8192];
    (void)state;
    /* an acquisition file whose line never ends: the resume scan stops */
    {
        static char endless[200100];
        const char hdr[] = "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms\n";
        memcpy(endless, hdr, sizeof hdr - 1);
        memset(endless + sizeof hdr - 1, '7', 200000);
        write_bytes("endless.csv", endless, sizeof hdr - 1 + 200000);
    }
    refused(C, "acquire --out (line without end)", 1, NEED("endless.csv:2:", "longer than 4096 bytes"),
            KEEP("endless.csv", "plan.csv"), ACQ " --poses plan.csv --out endless.csv");
    if (access("/dev/full", W_OK) == 0)
        refused(C, "acquire --out /dev/full", 1, NEED("not a regular file"), KEEP("plan.csv"),
                ACQ " --poses plan.csv --out /dev/full");
    if (access("/dev/zero", R_OK) == 0) {
        refused(C, "calibrate --data /dev/zero", 1, NEED("/dev/zero:1:1", "a NUL byte in the first line"), NULL,
                R " calibrate --data /dev/zero");
        refused(C, "compensate --in /dev/zero", 1, NEED("/dev/zero:1:", "longer than 65536 bytes"),
                &(files){{"model.json"}, {"z.out"}}, R " compensate --model model.json --in /dev/zero --out z.out");
        refused(C, "rcal-rt --in /dev/zero", 1, NEED("/dev/zero:1:1", "a NUL byte"), NULL,
                RT " --in /dev/zero --seconds 0.01");
        refused(C, "acquire --poses /dev/zero", 1, NEED("/dev/zero"), &(files){{"a.csv"}, {"z.csv"}},
                ACQ " --poses /dev/zero --out z.csv");
    }
    memset(big, '1', sizeof big - 2);
    big[sizeof big - 2] = '\n';
    big[sizeof big - 1] = '\0';
    write_text("long.csv", "10,20,-30,40,50,60\n");
    {
        char lp[512];
        FILE *f;
        path_in(lp, sizeof lp, "long.csv");
        f = fopen(lp, "a");
        assert_non_null(f);
        for (int i = 0; i < 10; ++i)
            fputs(big, f);
        fclose(f);
    }
    refused(C, "rcal-rt --in (8 KiB line)", 1, NEED("long.csv:2:", "the six joint angles q1..q6"), KEEP("long.csv"),
            RT " --in long.csv --seconds 0.01");
    {
        /* 1 GiB of short rows would be 60 million rows (35 GB for a fit): the row limit */
        char tp[512];
        FILE *f;
        path_in(tp, sizeof tp, "tiny.csv");
        f = fopen(tp, "w");
        assert_non_null(f);
        fputs("q1,q2,q3,q4,q5,q6,L\n", f);
        for (long i = 0; i <= 2000000; ++i)
            fputs("0,0,0,0,30,0,500\n", f);
        assert_int_equal(fclose(f), 0);
        refused(C, "calibrate, 2000001 short rows", 1, NEED("tiny.csv:2000002:1:", "more than 2000000 data rows"),
                &(files){{"tiny.csv"}, {"tiny.json"}}, R " calibrate --data tiny.csv --out tiny.json");
        remove(tp);
    }
    {
        /* a 17 MiB JSON array of numbers (a 64 MiB one took 2.4 GB): the JSON reader's limit */
        char jp[512];
        FILE *f;
        path_in(jp, sizeof jp, "wide.json");
        f = fopen(jp, "w");
        assert_non_null(f);
        fputs("{\"before\": [0", f);
        for (long i = 0; i < 17L * 1024 * 1024 / 2; ++i)
            fputs(",0", f);
        fputs("]}\n", f);
        assert_int_equal(fclose(f), 0);
        refused(C, "report --calibration (17 MiB of numbers)", 1, NEED("wide.json", "limit"),
                &(files){{"wide.json"}, {"wide.html"}}, R " report --calibration wide.json --out wide.html");
        remove(jp);
    }
    refused(C, "poses --count 100000", 2, NEED("--count", "1000"), &(files){{"r.json"}, {"p.csv"}},
            R " poses --robot r.json --count 100000 --out p.csv");
    refused(C, "chaos --points 1e8 --starts 1e5", 2, NEED("--points"), NULL, R " chaos --points 1e8 --starts 1e5");
    refused(C, "chaos --points 10000000 --starts 100000", 2, NEED("limit of 1e+09"), NULL,
            R " chaos --points 10000000 --starts 100000");
    refused(C, "compare --cases 10000 --samples 0", 2, NEED("--cases", "limit of"), KEEP("d.csv"),
            R " compare --data d.csv --cases 10000 --samples 0");
    refused(C, "bench --runs 10000", 2, NEED("--runs", "limit of"), KEEP("d.csv"), R " bench --data d.csv --runs 10000");
    refused(C, "rcal-rt --bench --targets 1e7 --repeat 1000", 2, NEED("--targets times --repeat", "limit"), NULL,
            RT " --bench --targets 10000000 --repeat 1000");
    refused(C, "rcal-rt --rate-hz 100000 --seconds 3600", 2, NEED("cycles", "limit"), NULL,
            RT " --rate-hz 100000 --seconds 3600");
}

/* ---- class 4: numbers that wrap or mean something else ---- */
static void test_numbers(void **state)
{
    static const char *const C = "4 numbers";
    static const struct {
        const char *what, *args, *opt;
    } cases[] = {
        {"calibrate --max-iter 4294967297", R " calibrate --data d.csv --max-iter 4294967297 --out n.json", "--max-iter"},
        {"calibrate --max-iter -1", R " calibrate --data d.csv --max-iter -1 --out n.json", "--max-iter"},
        {"acquire --read-timeout-ms 4294967296", ACQ " --poses plan.csv --out n.json --read-timeout-ms 4294967296",
         "--read-timeout-ms"},
        {"acquire --read-timeout-ms 0", ACQ " --poses plan.csv --out n.json --read-timeout-ms 0", "--read-timeout-ms"},
        {"simulate --seed ' -1'", R " simulate --seed ' -1' --samples 5 --out n.json", "--seed"},
        {"calibrate --seed ' -1'", R " calibrate --data d.csv --seed ' -1' --out n.json", "--seed"},
        {"poses --seed 18446744073709551616", R " poses --count 5 --seed 18446744073709551616 --out n.json", "--seed"},
        {"compensate --max-dev-deg 0", R " compensate --model model.json --in prog.mod --max-dev-deg 0 --out n.json",
         "--max-dev-deg"},
        {"grind --max-dev-deg 0", R " grind --model model.json --truth model.json --max-dev-deg 0", "--max-dev-deg"},
        {"bench --runs 0", R " bench --runs 0", "--runs"},
        {"compare --methods ''", R " compare --data d.csv --methods ''", "--methods"},
        {"compare --methods ','", R " compare --data d.csv --methods ,", "--methods"},
        {"simulate --noise-mm 1e300", R " simulate --noise-mm 1e300 --samples 5 --out n.json", "--noise-mm"},
        {"simulate --noise-mm nan", R " simulate --noise-mm nan --samples 5 --out n.json", "--noise-mm"},
        {"poses --margin-deg 500", R " poses --count 5 --margin-deg 500 --out n.json", "--margin-deg"},
        {"calibrate --test-fraction 0x1p-2", R " calibrate --data d.csv --test-fraction 0x1p-2 --out n.json",
         "--test-fraction"},
        {"simulate --samples 5x", R " simulate --samples 5x --out n.json", "--samples"},
        {"rcal-rt --rate-hz ' 1000'", RT " --rate-hz ' 1000' --seconds 0.01", "--rate-hz"},
        {"rcal-rt --targets 4294967297", RT " --bench --targets 4294967297", "--targets"},
        {"rcal-rt --repeat 0", RT " --bench --repeat 0", "--repeat"},
        {"rcal-rt --seconds -1", RT " --seconds -1", "--seconds"},
        {"rcal-rt --rate-hz (no value)", RT " --rate-hz", "--rate-hz"},
        {"rcal-rt --frobnicate", RT " --frobnicate", "--frobnicate"},
    };
    (void)state;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k)
        refused(C, cases[k].what, 2, NEED(cases[k].opt), &(files){{"d.csv", "model.json", "plan.csv"}, {"n.json"}},
                "%s", cases[k].args);
}

/* strict JSON: python3's reader with NaN/Infinity refused, else (no python3)
 * the project's own reader; 0 when it parses */
static int json_ok(const char *name)
{
    char p[512], cmd[1400];
    rch_diag d;
    rch_json *j;
    path_in(p, sizeof p, name);
    j = rch_json_load(p, &d);
    if (!j)
        return -1;
    rch_json_free(j);
    if (system("command -v python3 >/dev/null 2>&1") != 0)
        return 0;
    snprintf(cmd, sizeof cmd,
             "python3 -c 'import json,sys\ndef bad(c): raise ValueError(c)\njson.load(open(sys.argv[1],"
             " encoding=\"utf-8\"), parse_constant=bad)' '%s' 2>/dev/null",
             p);
    return system(cmd) == 0 ? 0 : -1;
}

/* ---- class 5: output that is not what it claims ---- */
static void test_outputs_truthful(void **state)
{
    static const char *const C = "5 output is what it claims";
    static const char weird[] = "we\"ird\\pa\tth\x01.csv";
    char p[512], q[512];
    (void)state;
    /* a data path with ", \, a tab and a control byte: --json and --out parse, the path comes back */
    path_in(p, sizeof p, "d.csv");
    path_in(q, sizeof q, weird);
    {
        char cmd[1400];
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", p, q);
        assert_int_equal(system(cmd), 0);
    }
    {
        rch_diag d;
        rch_json *j;
        char out[512];
        assert_int_equal(sh(R " calibrate --data 'we\"ird\\pa\tth\001.csv' --json --out 'mo\"d\\el.json' > cj.json"), 0);
        slurp(g_out, sizeof g_out, "cj.json");
        assert_int_equal(json_ok("cj.json"), 0);
        assert_int_equal(json_ok("mo\"d\\el.json"), 0);
        path_in(out, sizeof out, "cj.json");
        j = rch_json_load(out, &d);
        assert_non_null(j);
        assert_non_null(rch_json_get(j, "data"));
        assert_string_equal(rch_json_get(j, "data")->str, weird);
        rch_json_free(j);
        path_in(out, sizeof out, "mo\"d\\el.json");
        {
            rch_robot back;
            assert_int_equal(rch_robot_load(&back, out, &d), 0);
        }
        note(C, 0, "calibrate --json/--out, path with \" \\ TAB ^A", "exit 0; both files strict JSON, path round-trips");
        assert_int_equal(sh(R " evaluate --model model.json --data 'we\"ird\\pa\tth\001.csv' --json > ej.json"), 0);
        assert_int_equal(json_ok("ej.json"), 0);
        note(C, 0, "evaluate --json, same path", "exit 0; strict JSON");
        assert_int_equal(sh(R " compare --data 'we\"ird\\pa\tth\001.csv' --samples 40 --cases 1 --methods LM --json "
                              "> cmp.json"),
                         0);
        assert_int_equal(json_ok("cmp.json"), 0);
        note(C, 0, "compare --json, same path", "exit 0; strict JSON");
    }
    /* chaos --json: never nan, whatever the map */
    {
        static const char *const args[] = {"--step 0.3 --starts 5", "--r 4 --starts 3 --points 1000", "--r 0 --starts 2",
                                           "--starts 1 --points 1", "--r 3.99 --starts 2 --bins 1"};
        for (size_t k = 0; k < sizeof args / sizeof args[0]; ++k) {
            const int rc = sh(R " chaos %s --json > ch.json", args[k]);
            if (rc != 0 && rc != 2)
                fail_msg("chaos %s: exit %d", args[k], rc);
            slurp(g_out, sizeof g_out, "ch.json");
            if (rc == 0) {
                assert_int_equal(json_ok("ch.json"), 0);
                assert_null(strstr(g_out, "nan"));
                assert_null(strstr(g_out, "inf"));
            }
            note(C, 0, "chaos --json", "%s: exit %d%s", args[k], rc, rc == 0 ? ", strict JSON, no nan/inf" : "");
        }
    }
    /* a model name and a path with comment ends: the generated header compiles */
    {
        static const char evil[] = "evil */ int injected = 1; /* \\\n#error boom ?\?/";
        char cmd[2048], mp[512];
        FILE *f;
        rch_robot rb;
        rch_diag d;
        path_in(mp, sizeof mp, "model.json");
        assert_int_equal(rch_robot_load(&rb, mp, &d), 0);
        path_in(mp, sizeof mp, "x*");
        assert_int_equal(mkdir(mp, 0755), 0);
        path_in(mp, sizeof mp, "x*/il.json");
        f = fopen(mp, "w");
        assert_non_null(f);
        assert_int_equal(rch_robot_write(f, evil, &rb.model, &rb.nominal, NULL), 0);
        assert_int_equal(fclose(f), 0);
        assert_int_equal(sh(RT " --emit-c './x*/il.json' > fw_model_data.h"), 0);
        path_in(mp, sizeof mp, "use.c");
        f = fopen(mp, "w");
        assert_non_null(f);
        fputs("#include <stdio.h>\n#include \"fw_model_data.h\"\nint main(void)\n{\n"
              "    (void)fw_kin_cal;\n    (void)fw_kin_nom;\n    puts(fw_model_name);\n    return 0;\n}\n",
              f);
        fclose(f);
        /* rc_version.c itself (the ABI guard symbol), not the core library, so
         * that a sanitizer build's instrumented library is not needed here */
        snprintf(cmd, sizeof cmd, "'%s' -std=c99 -Wall -Wextra -Werror -pedantic -I. -I'%s/lib' -I'%s/include' use.c "
                 "'%s/lib/rc_version.c' -o use -lm && ./use", RCAL_CC, RCAL_SOURCE_DIR, RCAL_BINARY_DIR, RCAL_SOURCE_DIR);
        if (sh("%s", cmd) != 0)
            fail_msg("the header rcal-rt --emit-c wrote does not compile: %s%s", g_out, g_err);
        if (strncmp(g_out, evil, strlen(evil)) != 0 || strcmp(g_out + strlen(evil), "\n") != 0)
            fail_msg("the name in the header is not the model's: %s", g_out);
        note(C, 0, "rcal-rt --emit-c, */ \\ newline ?\?/ in name, */ in path", "exit 0; header compiles -Werror, name intact");
    }
    /* poses: inside the joint limits less the margin; acquire refuses a plan outside them */
    {
        rch_robot rb;
        rch_diag d;
        char text[1 << 14];
        int n = 0;
        const double mg = 20.0 * 3.14159265358979323846 / 180.0;
        assert_int_equal(rch_robot_load(&rb, ROBOT, &d), 0);
        assert_int_equal(sh(R " poses --robot r.json --count 30 --margin-deg 20 --seed 3 --out p20.csv"), 0);
        slurp(text, sizeof text, "p20.csv");
        for (const char *l = strchr(text, '\n'); l && l[1]; l = strchr(l + 1, '\n')) {
            double qd[6];
            int pose = -1;
            const char *s = l + 1;
            if (sscanf(s, "%d,%lf,%lf,%lf,%lf,%lf,%lf", &pose, &qd[0], &qd[1], &qd[2], &qd[3], &qd[4], &qd[5]) != 7 ||
                pose != n)
                fail_msg("poses line: %.80s", s);
            for (int i = 0; i < 6; ++i) {
                const double qr = qd[i] * 3.14159265358979323846 / 180.0;
                assert_true(qr >= rb.model.q_min_rad[i] + mg - 1e-6 && qr <= rb.model.q_max_rad[i] - mg + 1e-6);
            }
            ++n;
        }
        assert_int_equal(n, 30);
        note(C, 0, "poses --margin-deg 20", "exit 0; all 30 poses 20 deg inside the limits");
        write_text("outside.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,0,30,0\n170,0,0,0,30,0\n");
        refused(C, "acquire, plan pose outside the limits", 1, NEED("outside the joint limits"),
                &(files){{"outside.csv"}, {"o.csv"}}, ACQ " --poses outside.csv --out o.csv");
        refused(C, "poses --margin-deg 90", 1, NEED("leaves no room"), &(files){{"r.json"}, {"p90.csv"}},
                R " poses --robot r.json --count 5 --margin-deg 90 --out p90.csv");
    }
}

/* ---- class 6: messages that point the right way ---- */

/* calibrate's report without its first line (the file name) and the solver
 * line (a time) */
static void report_body(char *dst, size_t cap)
{
    size_t n = 0;
    const char *p = strchr(g_out, '\n');
    dst[0] = '\0';
    while (p && p[1]) {
        const char *e = strchr(p + 1, '\n');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        if (strncmp(p + 1, "solver:", 7) != 0 && n + len < cap) {
            memcpy(dst + n, p, len);
            n += len;
            dst[n] = '\0';
        }
        p = e;
    }
}

static void test_messages(void **state)
{
    static const char *const C = "6 messages";
    static char plain[1 << 16], other[1 << 16];
    static char src[1 << 16];
    char hdrline[256];
    size_t n;
    (void)state;
    n = slurp(src, sizeof src, "d.csv");
    assert_true(n > 1000 && n < sizeof src - 64);
    snprintf(hdrline, sizeof hdrline, "%.*s", (int)strcspn(src, "\n"), src);
    assert_int_equal(sh(R " calibrate --data d.csv"), 0);
    report_body(plain, sizeof plain);
    /* accepted: byte-order mark, CR-only endings, quoted header: the same report */
    {
        static char buf[1 << 16];
        memcpy(buf, "\xEF\xBB\xBF", 3);
        memcpy(buf + 3, src, n);
        write_bytes("bom.csv", buf, n + 3);
        memcpy(buf, src, n);
        for (size_t i = 0; i < n; ++i)
            if (buf[i] == '\n')
                buf[i] = '\r';
        write_bytes("cr.csv", buf, n);
        {
            size_t m = 0;
            const char *h = src;
            while (*h != '\n') {
                const size_t w = strcspn(h, ",\n");
                m += (size_t)snprintf(buf + m, sizeof buf - m, "\"%.*s\"%s", (int)w, h, h[w] == ',' ? "," : "");
                h += w + (h[w] == ',');
            }
            memcpy(buf + m, h, n - (size_t)(h - src));
            write_bytes("quoted.csv", buf, m + n - (size_t)(h - src));
        }
        static const char *const ok[] = {"bom.csv", "cr.csv", "quoted.csv"};
        for (int k = 0; k < 3; ++k) {
            if (sh(R " calibrate --data %s", ok[k]) != 0)
                fail_msg("%s: %s", ok[k], g_err);
            report_body(other, sizeof other);
            if (strcmp(plain, other) != 0)
                fail_msg("%s: the report differs from the plain file's", ok[k]);
            note(C, 0, ok[k], "accepted: exit 0, the same figures as the plain file");
        }
        /* named: tab, semicolon, NUL-filled last line, hex float */
        memcpy(buf, src, n);
        for (size_t i = 0; i < n; ++i)
            if (buf[i] == ',')
                buf[i] = '\t';
        write_bytes("tab.csv", buf, n);
        for (size_t i = 0; i < n; ++i)
            if (buf[i] == '\t')
                buf[i] = ';';
        write_bytes("semi.csv", buf, n);
        memcpy(buf, src, n);
        memset(buf + n, 0, 40);
        write_bytes("nul.csv", buf, n + 40);
        {
            /* the L of the 5th sample (line 6) as a hex float */
            const char *l6 = src;
            for (int i = 0; i < 5; ++i)
                l6 = strchr(l6, '\n') + 1;
            const char *lc = strchr(l6, '\n');
            while (lc[-1] != ',')
                --lc;
            const size_t head = (size_t)(lc - src);
            memcpy(buf, src, head);
            memcpy(buf + head, "0x1.8p+9", 8);
            const char *rest = strchr(lc, '\n');
            memcpy(buf + head + 8, rest, n - (size_t)(rest - src));
            write_bytes("hex.csv", buf, head + 8 + n - (size_t)(rest - src));
            char where[64];
            snprintf(where, sizeof where, "hex.csv:6:%d:", (int)(lc - l6) + 1);
            refused(C, "hex float as L", 1, NEED(where, "hexadecimal"), &(files){{"hex.csv"}, {"h.json"}},
                    R " calibrate --data hex.csv --out h.json");
        }
    }
    refused(C, "tab-separated", 1, NEED("tab.csv:1:1:", "separated by tabs"), &(files){{"tab.csv"}, {"t.json"}},
            R " calibrate --data tab.csv --out t.json");
    refused(C, "semicolon-separated", 1, NEED("semi.csv:1:1:", "separated by semicolons"),
            &(files){{"semi.csv"}, {"t.json"}}, R " calibrate --data semi.csv --out t.json");
    refused(C, "NUL-filled last line", 1, NEED("nul.csv:602:1:", "power cut", "nul.csv.dropped"),
            &(files){{"nul.csv"}, {"t.json"}}, R " calibrate --data nul.csv --out t.json");
    (void)hdrline;
    /* models: an absurd link length or effect parameter must be blamed on the model */
    {
        static const struct {
            const char *file, *from, *to;
        } bad_link[] = {
            {"link_huge.json", "\"a_mm\": 270", "\"a_mm\": 270000"},
            {"link_neg.json", "\"d_mm\": 302", "\"d_mm\": -30200"},
        };
        for (int k = 0; k < 2; ++k) {
            char what[96];
            assert_int_equal(sh("sed 's/%s/%s/' r.json > %s && ! cmp -s r.json %s", bad_link[k].from, bad_link[k].to,
                                bad_link[k].file, bad_link[k].file),
                             0);
            const int rc = sh(R " calibrate --data d.csv --robot %s --out lm.json", bad_link[k].file);
            snprintf(what, sizeof what, "model with %s", bad_link[k].to);
            assert_int_not_equal(rc, 0);
            assert_false(exists("lm.json"));
            const int blames_model = strstr(g_err, bad_link[k].file) != NULL;
            note(C, !blames_model, what, "exit %d, nothing written; %s%s", rc,
                 blames_model ? "" : "OPEN (rch_calib.c, lead): blames the poses: ", first_err());
        }
    }
    {
        static const struct {
            const char *file, *effects;
        } bad_eff[] = {
            {"eff_offset.json", "[{\"kind\": \"length_offset\", \"params\": [1e300]}]"},
            {"eff_compl.json", "[{\"kind\": \"joint_compliance\", \"joint\": 2, \"params\": [1e9]}]"},
            {"eff_period.json", "[{\"kind\": \"joint_periodic\", \"joint\": 1, \"params\": [1e6, 1e6, 0, 0]}]"},
            {"eff_drift.json", "[{\"kind\": \"time_drift\", \"params\": [1e12, 0]}]"},
            {"eff_scale.json", "[{\"kind\": \"length_scale\", \"params\": [-5]}]"},
            {"eff_tool.json", "[{\"kind\": \"tool_offset\", \"params\": [1e7, 0, 0]}]"},
        };
        for (size_t k = 0; k < sizeof bad_eff / sizeof bad_eff[0]; ++k) {
            char what[96];
            assert_int_equal(sh("sed 's/^  \"joint_limits_deg\"/  \"effects\": %s,\\n  \"joint_limits_deg\"/' r.json > %s "
                                "&& grep -q effects %s",
                                bad_eff[k].effects, bad_eff[k].file, bad_eff[k].file),
                             0);
            const int rc = sh(R " calibrate --data d.csv --robot %s --out le.json", bad_eff[k].file);
            snprintf(what, sizeof what, "model effect %.60s", bad_eff[k].effects + 11);
            const int good = rc != 0 && strstr(g_err, bad_eff[k].file) != NULL;
            if (rc != 0)
                assert_false(exists("le.json"));
            {
                char lp[512];
                path_in(lp, sizeof lp, "le.json");
                remove(lp);
            }
            note(C, !good, what, "exit %d; %s%s", rc,
                 good ? "" : rc == 0 ? "OPEN (rch_robot.c, lead): accepted: " : "OPEN (rch_robot.c, lead): not blamed on the model: ",
                 rc == 0 ? "a fit was run and written" : first_err());
        }
    }
}

/* ---- the table ---- */
static void test_table(void **state)
{
    size_t open = 0, ncls = 0;
    const char *last = "";
    (void)state;
    print_message("issue 12, run through the binaries: class | case | what it gets now\n");
    for (size_t i = 0; i < g_nrows; ++i) {
        const row *r = &g_rows[i];
        if (strcmp(r->cls, last) != 0) {
            size_t k = 0;
            for (size_t j = i; j < g_nrows && strcmp(g_rows[j].cls, r->cls) == 0; ++j)
                ++k;
            print_message("-- class %s: %zu cases\n", r->cls, k);
            last = r->cls;
            ++ncls;
        }
        print_message("   %-44s | %s\n", r->what, r->got);
        open += (size_t)r->open;
    }
    print_message("%zu cases in %zu classes, %zu OPEN; longest run %.2f s: %s\n", g_nrows, ncls, open, g_worst_secs,
                  g_worst_cmd);
    assert_true(g_nrows >= 60);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_output_is_input), cmocka_unit_test(test_two_acquisitions),
        cmocka_unit_test(test_unbounded_work),  cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_outputs_truthful), cmocka_unit_test(test_messages),
        cmocka_unit_test(test_table),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
