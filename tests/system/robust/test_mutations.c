/* SPDX-License-Identifier: MIT */
/* test_mutations.c - issue 33's mutation table as a test: data from a
 * simulated robot (the independent generator, tests/common/rct_indep.h: its
 * own DH kinematics and random numbers; a true IRB120 with DH errors), a
 * tracker file (30 poses x 3 targets, a frame turned 68 deg and 1.7 m away,
 * noise 0.005 mm) and a cable file (300 rows from 3 outlets, noise
 * 0.01 mm), each mutated as a user's mistake would, then calibrated through
 * rch_calib_run (what `rcal calibrate` runs). Each mutation must be refused,
 * or named (file:line, rch_calib_result.screen) with the model from the rest
 * within 1.5x the clean data's flange error against the truth (2000 random
 * poses, rigidly aligned). Prints the table (mutation, outcome, error).
 * Memory: static buffers; the temporary files are removed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "rch_calib.h"
#include "rch_calib_cfg.h"
#include "rct_indep.h"
#include "rct_irb120.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define NPOSE 30
#define NTG 3
#define NCAB 300
#define DEG (3.14159265358979323846 / 180.0)

static double g_dh[6][4];                        /* the true robot */
static const double g_out[3][3] = {{250, -460, 10}, {-350, -420, 20}, {420, 300, -30}}; /* true outlets */
static char g_truth[64];

typedef struct {
    double q_deg[6];
    double p[3]; /* tracker: measured, mm */
    double len_mm;
    unsigned target, outlet;
} row;

static row g_pos[NPOSE * NTG * 2], g_cab[NCAB];

static void random_q(double q_deg[6], rct_rng *g)
{
    static const double span[6] = {100, 40, 45, 100, 70, 150};
    for (int j = 0; j < 6; ++j)
        q_deg[j] = floor((span[j] * (2.0 * rct_u01(g) - 1.0) + (j == 1 ? 10.0 : 0.0)) * 1e4 + 0.5) / 1e4;
}

/* Tracker rows of n poses (3 targets each) from seed. */
static size_t gen_positions(row *r, unsigned n, uint64_t seed)
{
    rct_rng g = {seed};
    static const double tg[NTG][3] = {{0, 0, 45}, {40, 0, 80}, {-30, 50, 60}};
    const double th = 68.0 * DEG, T[3] = {1700.0, -300.0, 120.0};
    const double Rt[9] = {cos(th), -sin(th), 0, sin(th), cos(th), 0, 0, 0, 1};
    size_t k = 0;
    for (unsigned i = 0; i < n; ++i) {
        double q_deg[6], q[6], o[3], R6[9];
        random_q(q_deg, &g);
        for (int j = 0; j < 6; ++j)
            q[j] = q_deg[j] * DEG;
        rct_pose(o, R6, g_dh, q);
        for (unsigned t = 0; t < NTG; ++t, ++k) {
            double a[3];
            for (int c = 0; c < 3; ++c)
                a[c] = o[c] + R6[3 * c] * tg[t][0] + R6[3 * c + 1] * tg[t][1] + R6[3 * c + 2] * tg[t][2];
            memcpy(r[k].q_deg, q_deg, sizeof q_deg);
            for (int c = 0; c < 3; ++c)
                r[k].p[c] = Rt[3 * c] * a[0] + Rt[3 * c + 1] * a[1] + Rt[3 * c + 2] * a[2] + T[c] + 0.005 * rct_gauss(&g);
            r[k].target = t;
        }
    }
    return k;
}

static void gen_cable(void)
{
    rct_rng g = {4242};
    for (unsigned i = 0; i < NCAB; ++i) {
        double q[6], p[3];
        random_q(g_cab[i].q_deg, &g);
        for (int j = 0; j < 6; ++j)
            q[j] = g_cab[i].q_deg[j] * DEG;
        rct_flange(p, g_dh, q);
        g_cab[i].outlet = i * 3 / NCAB;
        g_cab[i].len_mm = rct_dist(p, g_out[g_cab[i].outlet]) + 0.01 * rct_gauss(&g);
    }
}

/* The truth as a model file (rcal-model/1) for rch_calib_cfg.truth_path. */
static void write_truth(void)
{
    strcpy(g_truth, "/tmp/rcal_mut_truthXXXXXX");
    const int fd = mkstemp(g_truth);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(rct_write_truth(g_truth, "mutation truth", g_dh), 0);
}

/* How a file is written wrong. */
typedef struct {
    double scale;      /* positions multiplied by (0: 1) */
    int swap_xy;       /* x and y columns swapped */
    int no_target;     /* no target column */
    int pose_col;      /* a pose column (pose = row / 3) */
    int comma_row;     /* a decimal comma in this row's x (1-based; 0: none) */
    int controller;    /* the nominal robot's own flange x, y, z, base frame */
    double len_scale;  /* cable lengths multiplied by (0: 1) */
    double xyz_scale;  /* cable file: x, y, z columns (the controller's flange) multiplied by (0: none) */
} wcfg;

static void tmpfile_name(char *path, size_t len)
{
    snprintf(path, len, "/tmp/rcal_mutXXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
}

static void write_pos(const char *path, const row *r, size_t n, const wcfg *w)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    double dh[6][4];
    rct_irb120_dh(dh);
    fprintf(f, "%sq1,q2,q3,q4,q5,q6%s,x,y,z\n", w->pose_col ? "pose," : "", w->no_target ? "" : ",target");
    for (size_t i = 0; i < n; ++i) {
        const double s = w->scale > 0 ? w->scale : 1.0;
        double p[3] = {r[i].p[0], r[i].p[1], r[i].p[2]};
        if (w->controller) {
            double q[6];
            for (int j = 0; j < 6; ++j)
                q[j] = r[i].q_deg[j] * DEG;
            rct_flange(p, dh, q);
        }
        if (w->pose_col)
            fprintf(f, "%zu,", (i % (NPOSE * NTG)) / NTG);
        fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f", r[i].q_deg[0], r[i].q_deg[1], r[i].q_deg[2], r[i].q_deg[3],
                r[i].q_deg[4], r[i].q_deg[5]);
        if (!w->no_target)
            fprintf(f, ",%u", r[i].target);
        const double x = p[w->swap_xy ? 1 : 0] * s, y = p[w->swap_xy ? 0 : 1] * s;
        if ((size_t)w->comma_row == i + 1) {
            char buf[40];
            snprintf(buf, sizeof buf, "%.4f", x);
            *strchr(buf, '.') = ',';
            fprintf(f, ",%s,%.4f,%.4f\n", buf, y, p[2] * s);
        } else
            fprintf(f, ",%.4f,%.4f,%.4f\n", x, y, p[2] * s);
    }
    assert_int_equal(fclose(f), 0);
}

static void write_cab(const char *path, const row *r, size_t n, const wcfg *w)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    double dh[6][4];
    rct_irb120_dh(dh);
    fprintf(f, "%sq1,q2,q3,q4,q5,q6,L,outlet\n", w->xyz_scale > 0 ? "x,y,z," : "");
    for (size_t i = 0; i < n; ++i) {
        if (w->xyz_scale > 0) {
            double q[6], p[3];
            for (int j = 0; j < 6; ++j)
                q[j] = r[i].q_deg[j] * DEG;
            rct_flange(p, dh, q);
            fprintf(f, "%.4f,%.4f,%.4f,", p[0] * w->xyz_scale, p[1] * w->xyz_scale, p[2] * w->xyz_scale);
        }
        fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u\n", r[i].q_deg[0], r[i].q_deg[1], r[i].q_deg[2],
                r[i].q_deg[3], r[i].q_deg[4], r[i].q_deg[5], r[i].len_mm * (w->len_scale > 0 ? w->len_scale : 1.0),
                r[i].outlet);
    }
    assert_int_equal(fclose(f), 0);
}

typedef struct {
    int refused;
    char msg[300];
    unsigned screened, first_line;
    double err_mm; /* flange RMS against the truth */
    size_t n_rows;
} outcome;

static rch_calib_result g_r;

static outcome calibrate(const char *path, int tracker)
{
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    const char *paths[1] = {path};
    cfg.robot_path = ROBOT;
    cfg.truth_path = g_truth;
    cfg.test_fraction = 0.0;
    if (tracker) {
        cfg.positions_paths = paths;
        cfg.n_positions_paths = 1;
    } else {
        cfg.data_path = path;
        cfg.data_paths = paths;
        cfg.n_data_paths = 1;
    }
    rch_diag d;
    memset(&d, 0, sizeof d);
    outcome o;
    memset(&o, 0, sizeof o);
    if (rch_calib_run(&g_r, &cfg, &d) != 0) {
        o.refused = 1;
        rch_diag_str(&d, o.msg, sizeof o.msg);
        return o;
    }
    o.screened = (unsigned)g_r.screen.out;
    o.first_line = g_r.screen.n_named ? g_r.screen.row[0].line : 0u;
    o.err_mm = g_r.truth_after_rms_mm;
    o.n_rows = g_r.n_data;
    return o;
}

static double g_clean[2];

static void report(const char *what, const outcome *o, double clean_mm)
{
    char res[200];
    if (o->refused)
        snprintf(res, sizeof res, "refused: %.150s", o->msg);
    else if (o->screened)
        snprintf(res, sizeof res, "%u row%s left out, first line %u", o->screened, o->screened == 1 ? "" : "s",
                 o->first_line);
    else
        snprintf(res, sizeof res, "fitted, %zu rows", o->n_rows);
    if (o->refused)
        printf("| %s | %s | - |\n", what, res);
    else
        printf("| %s | %s | %.4f mm (clean %.4f) |\n", what, res, o->err_mm, clean_mm);
}

static size_t g_npos;

/* Rows r (n) written as w says to a temporary file, calibrated, reported, removed. */
static outcome run_file(const char *what, const row *r, size_t n, const wcfg *w, int tracker, double clean_mm)
{
    char path[64];
    tmpfile_name(path, sizeof path);
    if (tracker)
        write_pos(path, r, n, w);
    else
        write_cab(path, r, n, w);
    const outcome o = calibrate(path, tracker);
    report(what, &o, clean_mm);
    unlink(path);
    return o;
}

static void expect_refused(const char *what, const row *r, size_t n, const wcfg *w, int tracker, const char *needle)
{
    const outcome o = run_file(what, r, n, w, tracker, g_clean[tracker]);
    assert_true(o.refused);
    if (!strstr(o.msg, needle))
        fail_msg("%s: refused, but the message lacks '%s': %s", what, needle, o.msg);
}

/* Named (the lines screened include want_line; 0: any) or dropped with the
 * model within 1.5x clean_mm; or, when may_refuse, refused by a
 * plausibility check that names want_line (file:LINE:). w: how the file is
 * written. */
static void expect_named_as(const char *what, const row *r, size_t n, int tracker, unsigned want_line,
                            size_t want_rows, const wcfg *w, double clean_mm, int may_refuse)
{
    const outcome o = run_file(what, r, n, w, tracker, clean_mm);
    if (o.refused) {
        char at[32];
        snprintf(at, sizeof at, ":%u:", want_line);
        if (!may_refuse || !want_line || !strstr(o.msg, at))
            fail_msg("%s: refused without naming line %u: %s", what, want_line, o.msg);
        return;
    }
    if (want_line) {
        int hit = 0;
        for (unsigned k = 0; k < g_r.screen.n_named; ++k)
            hit |= g_r.screen.row[k].line == want_line;
        if (!hit)
            fail_msg("%s: line %u not named (%u rows left out)", what, want_line, o.screened);
    }
    if (want_rows)
        assert_int_equal(o.n_rows, want_rows);
    if (!(o.err_mm <= 1.5 * clean_mm))
        fail_msg("%s: %.4f mm against the truth, clean %.4f", what, o.err_mm, clean_mm);
}

static void expect_named(const char *what, const row *r, size_t n, int tracker, unsigned want_line, size_t want_rows)
{
    const wcfg w = {0};
    expect_named_as(what, r, n, tracker, want_line, want_rows, &w, g_clean[tracker], 1);
}

/* expect_named of a single-target file (no target column): never refused;
 * its clean error is measured first. */
static void expect_named_w(const char *what, const row *r, size_t n, int tracker, unsigned want_line)
{
    static double clean_one;
    const wcfg w = {.no_target = 1};
    if (clean_one == 0.0) {
        static row c[NPOSE];
        char path[64];
        for (unsigned i = 0; i < NPOSE; ++i)
            c[i] = g_pos[NTG * i];
        tmpfile_name(path, sizeof path);
        write_pos(path, c, NPOSE, &w);
        const outcome o = calibrate(path, 1);
        unlink(path);
        assert_false(o.refused);
        clean_one = o.err_mm;
        report("clean tracker file, one target per pose (30 poses)", &o, clean_one);
    }
    expect_named_as(what, r, n, tracker, want_line, 0, &w, clean_one, 0);
}

static int setup(void **state)
{
    (void)state;
    rct_rng g = {2033};
    rct_irb120_dh(g_dh);
    for (int i = 0; i < 6; ++i) {
        g_dh[i][0] += 0.4 * (2.0 * rct_u01(&g) - 1.0);
        g_dh[i][1] += 0.4 * (2.0 * rct_u01(&g) - 1.0);
        g_dh[i][2] += 0.03 * DEG * (2.0 * rct_u01(&g) - 1.0);
        g_dh[i][3] += 0.03 * DEG * (2.0 * rct_u01(&g) - 1.0);
    }
    write_truth();
    g_npos = gen_positions(g_pos, NPOSE, 33);
    gen_cable();
    printf("| mutation | outcome | flange error against the truth (RMS) |\n|---|---|---|\n");
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    unlink(g_truth);
    return 0;
}

static void test_clean(void **state)
{
    (void)state;
    char path[64];
    const wcfg w = {0};
    for (int tracker = 1; tracker >= 0; --tracker) {
        tmpfile_name(path, sizeof path);
        if (tracker)
            write_pos(path, g_pos, g_npos, &w);
        else
            write_cab(path, g_cab, NCAB, &w);
        const outcome o = calibrate(path, tracker);
        unlink(path);
        assert_false(o.refused);
        assert_int_equal(o.screened, 0);
        g_clean[tracker] = o.err_mm;
        report(tracker ? "clean tracker file (30 poses x 3 targets)" : "clean cable file (300 rows, 3 outlets)", &o,
               o.err_mm);
        assert_true(o.err_mm < 0.1);
    }
}

static void test_outliers(void **state)
{
    (void)state;
    static row r[NPOSE * NTG];
    memcpy(r, g_pos, g_npos * sizeof r[0]);
    r[40].p[0] += 1000.0;
    expect_named("one tracker row 1 m off", r, g_npos, 1, 42, 0);
    memcpy(r, g_pos, g_npos * sizeof r[0]);
    r[40].p[1] += 5.0;
    expect_named("one tracker row 5 mm off", r, g_npos, 1, 42, 0);
    /* one target per pose: no other target to compare with, the screen finds it */
    static row one[NPOSE];
    for (unsigned i = 0; i < NPOSE; ++i)
        one[i] = g_pos[NTG * i];
    one[13].p[0] += 1000.0;
    expect_named_w("one tracker row 1 m off (one target per pose)", one, NPOSE, 1, 15);
    one[13].p[0] -= 1000.0 - 5.0;
    expect_named_w("one tracker row 5 mm off (one target per pose)", one, NPOSE, 1, 15);
    static row c[NCAB];
    memcpy(c, g_cab, sizeof c);
    c[123].len_mm += 50.0;
    expect_named("one cable length 50 mm off", c, NCAB, 0, 125, 0);
    memcpy(c, g_cab, sizeof c);
    c[20].outlet = 1;
    c[150].outlet = 2;
    c[260].outlet = 0;
    expect_named("3 of 300 cable rows with the wrong outlet label", c, NCAB, 0, 22, 0);
}

static void test_files(void **state)
{
    (void)state;
    const wcfg cm = {.scale = 0.1}, inch = {.scale = 1.0 / 25.4}, swap = {.swap_xy = 1}, notg = {.no_target = 1},
               comma = {.comma_row = 17}, ctrl = {.controller = 1, .no_target = 1}, lcm = {.len_scale = 0.1},
               linch = {.len_scale = 1.0 / 25.4}, pose = {.pose_col = 1}, xcm = {.xyz_scale = 0.1},
               xmm = {.xyz_scale = 1.0};
    expect_refused("positions in cm", g_pos, g_npos, &cm, 1, "centimetres");
    expect_refused("positions in inches", g_pos, g_npos, &inch, 1, "inch");
    expect_refused("x and y swapped (a mirrored frame)", g_pos, g_npos, &swap, 1, "mirror");
    expect_refused("3 targets per pose, no target column", g_pos, g_npos, &notg, 1, "target");
    expect_refused("a decimal comma (one field more than the header)", g_pos, g_npos, &comma, 1, ":18");
    static row ctl[NPOSE];
    for (unsigned i = 0; i < NPOSE; ++i)
        ctl[i] = g_pos[NTG * i];
    expect_refused("the controller's own x, y, z as tracker data", ctl, NPOSE, &ctrl, 1, "controller");
    expect_refused("cable lengths in cm", g_cab, NCAB, &lcm, 0, "look like cm");
    expect_refused("cable lengths in inches", g_cab, NCAB, &linch, 0, "look like inches");
    expect_refused("a cable file's x, y, z columns in cm", g_cab, NCAB, &xcm, 0, "x, y, z columns look like cm");
    char path[64];
    tmpfile_name(path, sizeof path);
    write_cab(path, g_cab, NCAB, &xmm); /* the same columns in mm pass */
    const outcome o = calibrate(path, 0);
    unlink(path);
    assert_false(o.refused);
    /* a second session appended, its pose numbers starting at 0 again */
    static row two[NPOSE * NTG * 2];
    memcpy(two, g_pos, g_npos * sizeof two[0]);
    gen_positions(two + g_npos, NPOSE, 34);
    expect_refused("pose ids reused by a second session", two, 2 * g_npos, &pose, 1, "pose");
}

static void test_duplicates(void **state)
{
    (void)state;
    static row r[NPOSE * NTG + NTG];
    memcpy(r, g_pos, g_npos * sizeof r[0]);
    memcpy(&r[g_npos], &g_pos[30], NTG * sizeof r[0]); /* one pose's rows pasted again */
    expect_named("exact duplicate rows (one pose pasted twice)", r, g_npos + NTG, 1, 0, 3 * g_npos);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_clean), cmocka_unit_test(test_outliers),
                                       cmocka_unit_test(test_files), cmocka_unit_test(test_duplicates)};
    return cmocka_run_group_tests(tests, setup, teardown);
}
