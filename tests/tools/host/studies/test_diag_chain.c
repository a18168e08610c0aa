/* SPDX-License-Identifier: MIT */
/* test_diag_chain.c - the printed chain of `rcal diagnose` ends (issue 47,
 * item 4): run diagnose, run the `Next:` command it prints, then diagnose
 * again with the options and effects that command carries, until the
 * diagnosis prints the same command again. Every printed command must be
 * accepted (exit 0), the chain must end within CHAIN_MAX diagnoses, and
 * the nuisance a diagnosis names must be in its next command.
 *
 *   diag_chain          simulated faults (rcal simulate, then in code: every
 *                       length -5 mm, a 2 mm linear drift over the run, a
 *                       3 mm jump at row 300): the chain names the fault
 *                       (length_offset, time_drift, --jumps) and ends at a
 *                       held-out error within 1.2 x the clean file's
 *   diag_chain --real   the real IRB120 file, with and without
 *                       --dequantize-joints: the end's held-out RMSE (as
 *                       calibrate prints it) <= 0.12 mm and no fitted jump
 *                       over 10 mm; exit 77 when the file is absent
 *   diag_chain --walk ARGS...   any start, walked in the current directory
 *                       and printed (a measurement) */
#include <setjmp.h>
#include <stdarg.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <unistd.h>

#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define CHAIN_MAX 5

/* What one chain did. */
typedef struct chain {
    unsigned diagnoses;         /* diagnose runs until the command repeated */
    int ended;                  /* 1: the last diagnosis printed the command before it */
    char last_next[2048];       /* the command the chain ended on */
    char first_next[2048];      /* the first diagnosis's */
    double heldout_after_mm;    /* the last calibrate's held-out RMSE after calibration */
    double max_jump_mm;         /* the largest jump any calibrate of the chain fitted */
} chain;

/* Run cmd, its stdout+stderr into out (len). The exit status. */
static int run(const char *cmd, char *out, size_t len)
{
    char tmp[] = "/tmp/rcal_diag_chain_XXXXXX", full[4096];
    const int fd = mkstemp(tmp);
    assert_true(fd >= 0);
    close(fd);
    snprintf(full, sizeof full, "%s > %s 2>&1", cmd, tmp);
    const int st = system(full);
    FILE *f = fopen(tmp, "r");
    assert_non_null(f);
    const size_t got = fread(out, 1, len - 1, f);
    out[got] = '\0';
    fclose(f);
    unlink(tmp);
    return st;
}

/* The text after "Next: " on its own line, into next (len). 0 or -1. */
static int next_of(const char *out, char *next, size_t len)
{
    const char *p = NULL, *q = out;
    while ((q = strstr(q, "\nNext: ")) != NULL)
        p = q++;
    if (!p)
        return -1;
    p += 7;
    const size_t n = strcspn(p, "\n");
    if (n >= len)
        return -1;
    memcpy(next, p, n);
    next[n] = '\0';
    return 0;
}

/* The diagnose arguments the calibrate command cmd carries (its inputs,
 * --jumps, --dequantize-joints, --effects; not --out), into args (len). */
static void diagnose_args(char *args, size_t len, const char *cmd)
{
    char buf[2048], *save = NULL;
    size_t pos = 0;
    snprintf(buf, sizeof buf, "%s", cmd);
    args[0] = '\0';
    for (char *t = strtok_r(buf, " ", &save); t; t = strtok_r(NULL, " ", &save)) {
        if (strcmp(t, "rcal") == 0 || strcmp(t, "calibrate") == 0)
            continue;
        if (strcmp(t, "--out") == 0) {
            (void)strtok_r(NULL, " ", &save);
            continue;
        }
        pos += (size_t)snprintf(args + pos, len - pos, "%s%s", pos ? " " : "", t);
    }
}

/* The held-out RMSE after calibration ("held-out RMSE X mm before -> Y mm
 * after") and the largest |jump| ("jump k at line L (t T): +S +- E mm") of
 * calibrate's report. */
static void calib_figures(const char *out, double *after_mm, double *max_jump_mm)
{
    const char *p = strstr(out, "held-out RMSE ");
    double before;
    *after_mm = NAN;
    if (p)
        while (p) {
            if (sscanf(p, "held-out RMSE %lf mm before -> %lf mm after", &before, after_mm) == 2)
                break;
            p = strstr(p + 1, "held-out RMSE ");
        }
    for (p = strstr(out, "\n  jump "); p; p = strstr(p + 1, "\n  jump ")) {
        const char *c = strstr(p, "): ");
        double s;
        if (c && sscanf(c + 3, "%lf", &s) == 1 && fabs(s) > *max_jump_mm)
            *max_jump_mm = fabs(s);
    }
}

/* Walk the chain from `rcal diagnose first_args` (run in dir). */
static void walk(chain *ch, const char *dir, const char *first_args)
{
    static char out[1 << 18];
    char args[2048], cmd[4096], next[2048], prev[2048] = "";
    memset(ch, 0, sizeof *ch);
    snprintf(args, sizeof args, "%s", first_args);
    for (unsigned it = 0; it < CHAIN_MAX; ++it) {
        snprintf(cmd, sizeof cmd, "cd '%s' && %s diagnose %s", dir, RCAL, args);
        const int st = run(cmd, out, sizeof out);
        ch->diagnoses++;
        if (st != 0)
            fail_msg("refused or failed (status %d): rcal diagnose %s\n%s", st, args, out);
        if (next_of(out, next, sizeof next) != 0)
            fail_msg("no Next: after rcal diagnose %s", args);
        print_message("  diagnose %s\n    Next: %s\n", args, next);
        if (it == 0)
            snprintf(ch->first_next, sizeof ch->first_next, "%s", next);
        if (strcmp(next, prev) == 0) {
            ch->ended = 1;
            snprintf(ch->last_next, sizeof ch->last_next, "%s", next);
            return;
        }
        snprintf(prev, sizeof prev, "%s", next);
        const char *o = strstr(next, "--out model.json");
        assert_non_null(o);
        snprintf(cmd, sizeof cmd, "cd '%s' && %s %.*s--out chain_model.json", dir, RCAL, (int)(o - next) - 5,
                 next + 5);
        const int sc = run(cmd, out, sizeof out);
        if (sc != 0)
            fail_msg("the printed command was refused or failed (status %d): %s\n%s", sc, next, out);
        calib_figures(out, &ch->heldout_after_mm, &ch->max_jump_mm);
        print_message("    calibrate: held-out after %.4f mm, largest jump %.3f mm\n", ch->heldout_after_mm,
                      ch->max_jump_mm);
        diagnose_args(args, sizeof args, next);
    }
}

/* A fault written into a copy of the simulated file: 0 offset, 1 drift,
 * 2 jump (the last column is L, mm). */
static void fault_copy(const char *src, const char *dst, int kind)
{
    FILE *in = fopen(src, "r"), *out = fopen(dst, "w");
    assert_non_null(in);
    assert_non_null(out);
    char line[1024];
    size_t row = 0, rows = 0;
    while (fgets(line, sizeof line, in))
        rows++;
    rows -= 1; /* the header */
    rewind(in);
    while (fgets(line, sizeof line, in)) {
        char *comma = strrchr(line, ',');
        if (row == 0 || !comma) {
            fputs(line, out);
            row++;
            continue;
        }
        const double L = strtod(comma + 1, NULL);
        const double add = kind == 0 ? -5.0 : kind == 1 ? 2.0 * (double)(row - 1) / (double)(rows - 1)
                                                        : (row >= 300 ? 3.0 : 0.0);
        *comma = '\0';
        fprintf(out, "%s,%.4f\n", line, L + add);
        row++;
    }
    fclose(in);
    fclose(out);
}

static char sim_dir[] = "/tmp/rcal_diag_chain_sim_XXXXXX";

static int sim_setup(void **state)
{
    (void)state;
    char cmd[1024], out[4096];
    if (!mkdtemp(sim_dir))
        return -1;
    snprintf(cmd, sizeof cmd, "cd '%s' && %s simulate --out sim.csv --samples 600 --seed 7 --group-size 20", sim_dir,
             RCAL);
    if (run(cmd, out, sizeof out) != 0)
        return -1;
    return 0;
}

static int sim_teardown(void **state)
{
    (void)state;
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", sim_dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* The clean file's chain: `none`, and the held-out error the faults' chains
 * must reach. */
static double clean_heldout_mm;

static void test_clean(void **state)
{
    (void)state;
    chain ch;
    walk(&ch, sim_dir, "--data sim.csv");
    assert_true(ch.ended);
    assert_true(ch.diagnoses <= 2);
    assert_true(isfinite(ch.heldout_after_mm));
    clean_heldout_mm = ch.heldout_after_mm;
}

static void fault_chain(int kind, const char *file, const char *named)
{
    char src[512], dst[512], args[600];
    chain ch;
    snprintf(src, sizeof src, "%s/sim.csv", sim_dir);
    snprintf(dst, sizeof dst, "%s/%s", sim_dir, file);
    fault_copy(src, dst, kind);
    snprintf(args, sizeof args, "--data %s", file);
    walk(&ch, sim_dir, args);
    assert_true(ch.ended);
    assert_true(ch.diagnoses <= 3);
    if (!strstr(ch.first_next, named))
        fail_msg("%s: the first next step does not carry %s: %s", file, named, ch.first_next);
    if (!strstr(ch.last_next, named))
        fail_msg("%s: the chain ended without %s: %s", file, named, ch.last_next);
    assert_true(clean_heldout_mm > 0.0);
    if (!(ch.heldout_after_mm <= 1.2 * clean_heldout_mm))
        fail_msg("%s: the chain's end holds out %.4f mm, the clean file's %.4f", file, ch.heldout_after_mm,
                 clean_heldout_mm);
    assert_true(ch.max_jump_mm <= 10.0);
}

static void test_offset(void **state)
{
    (void)state;
    fault_chain(0, "off5.csv", "length_offset");
}

static void test_drift(void **state)
{
    (void)state;
    fault_chain(1, "drift2.csv", "time_drift");
    /* --out fits what Next names: the model file carries the drift it was fitted with */
    static char out[1 << 20];
    char cmd[1024], path[512];
    snprintf(cmd, sizeof cmd, "cd '%s' && rm -f out_drift.json && %s diagnose --data drift2.csv --out out_drift.json",
             sim_dir, RCAL);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    snprintf(path, sizeof path, "%s/out_drift.json", sim_dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    const size_t got = fread(out, 1, sizeof out - 1, f);
    out[got] = '\0';
    fclose(f);
    if (!strstr(out, "\"time_drift\""))
        fail_msg("diagnose --out: the model has no time_drift");
}

static void test_jump(void **state)
{
    (void)state;
    fault_chain(2, "jump3.csv", "--jumps");
}

/* A 30 mm jump is more than a display event: named as implausible beside
 * it and counted in the JSON (--jump-max-mm, default 10 mm); under a bound
 * of 50 mm it is not. */
static void test_jump_bound(void **state)
{
    (void)state;
    static char out[1 << 20];
    char src[512], dst[512], cmd[1024];
    snprintf(src, sizeof src, "%s/jump3.csv", sim_dir);
    snprintf(dst, sizeof dst, "%s/jump30.csv", sim_dir);
    FILE *in = fopen(src, "r"), *o = fopen(dst, "w");
    assert_true(in && o);
    char line[1024];
    size_t row = 0;
    while (fgets(line, sizeof line, in)) { /* jump3's 3 mm step made 30 mm */
        char *comma = strrchr(line, ',');
        if (row++ >= 300 && comma) {
            const double L = strtod(comma + 1, NULL) + 27.0;
            *comma = '\0';
            fprintf(o, "%s,%.4f\n", line, L);
        } else {
            fputs(line, o);
        }
    }
    fclose(in);
    fclose(o);
    snprintf(cmd, sizeof cmd, "cd '%s' && %s diagnose --data jump30.csv", sim_dir, RCAL);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    if (!strstr(out, "IMPLAUSIBLE as a display event") || !strstr(out, "larger than 10 mm"))
        fail_msg("a 30 mm jump not named implausible:\n%s", out);
    snprintf(cmd, sizeof cmd, "cd '%s' && %s diagnose --data jump30.csv --json --jump-max-mm 50", sim_dir, RCAL);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "\"jumps_implausible\":0"));
    assert_non_null(strstr(out, "\"jump_max_mm\":50"));
}

/* The real file: both chains end in accepted commands at <= 0.12 mm held
 * out, no fitted jump over 10 mm. */
static void real_chain(const char *extra)
{
    char args[1024];
    chain ch;
    snprintf(args, sizeof args, "--data %s%s", RCAL_SHARED_DATA, extra);
    walk(&ch, "/tmp", args);
    assert_true(ch.ended);
    if (!(ch.heldout_after_mm <= 0.12))
        fail_msg("real file%s: the chain's end holds out %.4f mm (> 0.12)", extra, ch.heldout_after_mm);
    if (!(ch.max_jump_mm <= 10.0))
        fail_msg("real file%s: a fitted jump of %.3f mm (> 10)", extra, ch.max_jump_mm);
    assert_non_null(strstr(ch.last_next, "--jumps")); /* calibrate and diagnose agree: the file has jumps */
}

static void test_real_plain(void **state)
{
    (void)state;
    real_chain("");
}

static void test_real_dequantized(void **state)
{
    (void)state;
    real_chain(" --dequantize-joints");
}

/* diag_chain --walk ARGS...: the chain from `rcal diagnose ARGS` in the
 * current directory, printed (a measurement: any start by hand). */
static char walk_args[2048];

static void test_walk(void **state)
{
    (void)state;
    char cwd[1024];
    chain ch;
    assert_non_null(getcwd(cwd, sizeof cwd));
    walk(&ch, cwd, walk_args);
    print_message("%s after %u diagnose run(s); held-out after %.4f mm, largest jump %.3f mm\n",
                  ch.ended ? "ended" : "NOT ENDED", ch.diagnoses, ch.heldout_after_mm, ch.max_jump_mm);
    assert_true(ch.ended);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--walk") == 0) {
        size_t pos = 0;
        for (int k = 2; k < argc && pos < sizeof walk_args; ++k)
            pos += (size_t)snprintf(walk_args + pos, sizeof walk_args - pos, "%s%s", pos ? " " : "", argv[k]);
        const struct CMUnitTest one[] = {cmocka_unit_test(test_walk)};
        return cmocka_run_group_tests(one, NULL, NULL);
    }
    if (argc > 1 && strcmp(argv[1], "--real") == 0) {
        if (access(RCAL_SHARED_DATA, R_OK) != 0) {
            printf("SKIP: %s is absent; the real file's chains not walked\n", RCAL_SHARED_DATA);
            return 77;
        }
        const struct CMUnitTest real[] = {
            cmocka_unit_test(test_real_plain),
            cmocka_unit_test(test_real_dequantized),
        };
        return cmocka_run_group_tests(real, NULL, NULL);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clean),
        cmocka_unit_test(test_offset),
        cmocka_unit_test(test_drift),
        cmocka_unit_test(test_jump),
        cmocka_unit_test(test_jump_bound),
    };
    return cmocka_run_group_tests(tests, sim_setup, sim_teardown);
}
