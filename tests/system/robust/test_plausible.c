/* SPDX-License-Identifier: MIT */
/* test_plausible.c - issue 33 item 2: wrong positions files never become a
 * model in silence. Each bad file is made from data of the independent
 * generator (tests/common/rct_indep.h: its own DH kinematics and random
 * numbers; a true IRB120 with DH errors, a tracker turned and 1.7 m away,
 * three targets, noise 0.02 mm), written as a user's mistake would write
 * it, and read by rch_pos_load with the robot's model: each is refused with
 * its message and location, or warned; the clean file passes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "rch_positions.h"
#include "rch_robot.h"
#include "rct_indep.h"
#include "rct_irb120.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define NPOSE 40
#define NTG 3
#define DEG (3.14159265358979323846 / 180.0)

typedef struct {
    double q_deg[6];
    double p[3]; /* measured, mm */
    unsigned target, pose;
} row;

typedef struct {
    int nominal;    /* the nominal arm, no targets, no noise, the base frame: the controller's x, y, z */
    int aligned;    /* tracker frame = the robot's base frame shifted (no turn) */
    double far_mm;  /* extra distance of the tracker along x */
    unsigned ntg;   /* targets per pose */
    uint64_t seed;
} gen_cfg;

static rc_model g_robot;

/* Rows (ntg per pose, NPOSE poses): joints rounded to 4 decimals, then the
 * generator's kinematics at the joints as written. Returns the count. */
static size_t generate(row *r, const gen_cfg *c)
{
    double dh[6][4];
    rct_rng g = {c->seed};
    rct_irb120_dh(dh);
    if (!c->nominal)
        for (int i = 0; i < 6; ++i) {
            dh[i][0] += 0.4 * (2.0 * rct_u01(&g) - 1.0);
            dh[i][1] += 0.4 * (2.0 * rct_u01(&g) - 1.0);
            dh[i][2] += 0.03 * DEG * (2.0 * rct_u01(&g) - 1.0);
            dh[i][3] += 0.03 * DEG * (2.0 * rct_u01(&g) - 1.0);
        }
    static const double tg[NTG][3] = {{0, 0, 45}, {40, 0, 80}, {-30, 50, 60}};
    const double th = c->aligned || c->nominal ? 0.0 : 68.0 * DEG;
    const double Rt[9] = {cos(th), -sin(th), 0, sin(th), cos(th), 0, 0, 0, 1};
    const double T[3] = {c->nominal ? 0.0 : 1700.0 + c->far_mm, c->nominal ? 0.0 : -300.0, c->nominal ? 0.0 : 120.0};
    static const double span[6] = {100, 40, 45, 100, 70, 150};
    size_t n = 0;
    for (unsigned k = 0; k < NPOSE; ++k) {
        double q[6];
        for (int j = 0; j < 6; ++j) {
            double v = span[j] * (2.0 * rct_u01(&g) - 1.0) + (j == 1 ? 10.0 : 0.0);
            v = floor(v * 1e4 + 0.5) / 1e4;
            r[n].q_deg[j] = v;
            q[j] = v * DEG;
        }
        for (unsigned t = 0; t < c->ntg; ++t, ++n) {
            double o[3], R6[9], a[3];
            if (t > 0)
                memcpy(r[n].q_deg, r[n - 1].q_deg, sizeof r[n].q_deg);
            rct_pose(o, R6, dh, q);
            for (int i = 0; i < 3; ++i)
                a[i] = o[i] + (c->nominal ? 0.0 : R6[3 * i] * tg[t][0] + R6[3 * i + 1] * tg[t][1] + R6[3 * i + 2] * tg[t][2]);
            for (int i = 0; i < 3; ++i)
                r[n].p[i] = Rt[3 * i] * a[0] + Rt[3 * i + 1] * a[1] + Rt[3 * i + 2] * a[2] + T[i] +
                            (c->nominal ? 0.0 : 0.02 * rct_gauss(&g));
            r[n].target = t;
            r[n].pose = k;
        }
    }
    return n;
}

typedef struct {
    double scale;     /* positions multiplied by */
    int swap_xy;      /* x and y columns swapped */
    int no_target;    /* the target column left out */
    int pose_col;     /* a pose column */
    const char *fmt;  /* of x, y, z ("%.4f") */
} write_cfg;

static char g_path[64];

static void write_file(const row *r, size_t n, const write_cfg *w, const char *extra)
{
    strcpy(g_path, "/tmp/rcal_plausXXXXXX");
    const int fd = mkstemp(g_path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fprintf(f, "%sq1,q2,q3,q4,q5,q6%s,x,y,z\n", w->pose_col ? "pose," : "", w->no_target ? "" : ",target");
    for (size_t i = 0; i < n; ++i) {
        const double x = r[i].p[w->swap_xy ? 1 : 0] * w->scale, y = r[i].p[w->swap_xy ? 0 : 1] * w->scale,
                     z = r[i].p[2] * w->scale;
        char fx[40], fy[40], fz[40];
        snprintf(fx, sizeof fx, w->fmt ? w->fmt : "%.4f", x);
        snprintf(fy, sizeof fy, w->fmt ? w->fmt : "%.4f", y);
        snprintf(fz, sizeof fz, w->fmt ? w->fmt : "%.4f", z);
        if (w->pose_col)
            fprintf(f, "%u,", r[i].pose);
        fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f", r[i].q_deg[0], r[i].q_deg[1], r[i].q_deg[2], r[i].q_deg[3],
                r[i].q_deg[4], r[i].q_deg[5]);
        if (!w->no_target)
            fprintf(f, ",%u", r[i].target);
        fprintf(f, ",%s,%s,%s\n", fx, fy, fz);
    }
    if (extra)
        fputs(extra, f);
    fclose(f);
}

/* Load g_path with the robot; *d filled. */
static int load(rch_pos *p, rch_diag *d)
{
    const char *paths[1] = {g_path};
    memset(d, 0, sizeof *d);
    return rch_pos_load(p, paths, 1, 0.0, &g_robot, d);
}

static void expect_refused(unsigned line, const char *n1, const char *n2)
{
    rch_pos p;
    rch_diag d;
    char msg[1024];
    assert_int_equal(load(&p, &d), -1);
    printf("    refused: %s\n", rch_diag_str(&d, msg, sizeof msg));
    assert_string_equal(d.file, g_path);
    assert_int_equal(d.line, line);
    assert_non_null(strstr(d.msg, n1));
    if (n2)
        assert_non_null(strstr(d.msg, n2));
    assert_null(p.s);
    remove(g_path);
}

static row g_rows[NPOSE * NTG + 64];

static size_t gen_default(void)
{
    const gen_cfg c = {0, 0, 0.0, NTG, 33};
    return generate(g_rows, &c);
}

static void test_clean_passes(void **state)
{
    (void)state;
    const size_t n = gen_default();
    const write_cfg w = {1.0, 0, 0, 0, NULL};
    write_file(g_rows, n, &w, NULL);
    rch_pos p;
    rch_diag d;
    char msg[1024];
    if (load(&p, &d) != 0)
        fail_msg("%s", rch_diag_str(&d, msg, sizeof msg));
    assert_int_equal(p.rows, n);
    assert_int_equal(p.poses, NPOSE);
    assert_int_equal(p.n_targets, NTG);
    assert_int_equal(p.dropped, 0);
    rch_pos_free(&p);
    remove(g_path);
    const write_cfg wp = {1.0, 0, 0, 1, "%.2f"}; /* a pose column, two decimals */
    write_file(g_rows, n, &wp, NULL);
    assert_int_equal(load(&p, &d), 0);
    assert_int_equal(p.poses, NPOSE);
    rch_pos_free(&p);
    remove(g_path);
}

/* a. a decimal comma: one field more than the header; a lost field: one less */
static void test_field_count(void **state)
{
    (void)state;
    const size_t n = gen_default();
    const write_cfg w = {1.0, 0, 0, 0, NULL};
    char extra[256];
    snprintf(extra, sizeof extra, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,0,1234,5678,%.4f,%.4f\n", g_rows[0].q_deg[0],
             g_rows[0].q_deg[1], g_rows[0].q_deg[2], g_rows[0].q_deg[3], g_rows[0].q_deg[4], g_rows[0].q_deg[5],
             g_rows[0].p[1], g_rows[0].p[2]);
    write_file(g_rows, n, &w, extra);
    expect_refused((unsigned)n + 2, "the row has 11 fields, the header 10", "decimal comma");
    snprintf(extra, sizeof extra, "1,2,3,4,5,6,0,1000.5,200.25\n");
    write_file(g_rows, n, &w, extra);
    expect_refused((unsigned)n + 2, "missing field 'z'", "the row has 9 fields, the header 10");
}

/* b. units: cm, inches, metres from a tracker 6 m away (beyond the old +-5 check) */
static void test_units(void **state)
{
    (void)state;
    size_t n = gen_default();
    write_cfg w = {0.1, 0, 0, 0, NULL};
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "centimetres", "multiply by 10)");
    w.scale = 1.0 / 25.4;
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "inches", "multiply by 25.4");
    const gen_cfg far = {0, 0, 4500.0, NTG, 34};
    n = generate(g_rows, &far);
    w.scale = 0.001;
    w.fmt = "%.7f";
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "metres", "multiply by 1000");
}

/* c. a mirrored frame: x and y swapped (tracker aligned: the swap named; turned: mirrored) */
static void test_mirrored(void **state)
{
    (void)state;
    const gen_cfg al = {0, 1, 0.0, NTG, 35};
    size_t n = generate(g_rows, &al);
    const write_cfg w = {1.0, 1, 0, 0, NULL};
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "mirrored", "it looks like x and y swapped");
    n = gen_default();
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "mirrored (left-handed)", "swap two of the x, y, z columns back");
    for (size_t i = 0; i < n; ++i)
        g_rows[i].p[2] = -g_rows[i].p[2]; /* swapped and z negated: right-handed again */
    write_file(g_rows, n, &w, NULL);
    rch_pos p;
    rch_diag d;
    assert_int_equal(load(&p, &d), 0);
    rch_pos_free(&p);
    remove(g_path);
}

/* d. three targets a pose, no target column; with it, a pose's targets swapped */
static void test_targets(void **state)
{
    (void)state;
    const size_t n = gen_default();
    write_cfg w = {1.0, 0, 1, 0, NULL};
    write_file(g_rows, n, &w, NULL);
    expect_refused(3, "lines 2 and 3 are the same pose", "add a target column");
    w.no_target = 0;
    g_rows[7 * NTG + 1].target = 2; /* pose 7: targets 1 and 2 exchanged */
    g_rows[7 * NTG + 2].target = 1;
    write_file(g_rows, n, &w, NULL);
    expect_refused(7 * NTG + 2 + 2, "targets 0 and 1 are", "names the wrong target");
    g_rows[7 * NTG + 2].target = 2; /* two rows of target 2 at pose 7 */
    write_file(g_rows, n, &w, NULL);
    expect_refused(7 * NTG + 2 + 2, "target 2 of the same pose measured", "a wrong target number");
}

/* e. a second session appended with the pose numbers counted again from 0 */
static void test_pose_reused(void **state)
{
    (void)state;
    const gen_cfg c1 = {0, 0, 0.0, 1, 36}, c2 = {0, 0, 0.0, 1, 37};
    size_t n = generate(g_rows, &c1);
    n += generate(g_rows + n, &c2);
    const write_cfg w = {1.0, 0, 0, 1, NULL};
    write_file(g_rows, n, &w, NULL);
    expect_refused(NPOSE + 2, "pose 0: line 42 has other joints than line 2", "reused");
}

/* f. a row pasted twice: warned with both lines, dropped, not a repeat */
static void test_duplicate(void **state)
{
    (void)state;
    size_t n = gen_default();
    g_rows[n] = g_rows[8]; /* a true repeat of pose 2, target 2: fresh noise */
    g_rows[n].p[0] += 0.013;
    g_rows[n + 1] = g_rows[5]; /* pose 1, target 2: the same text again */
    n += 2;
    const write_cfg w = {1.0, 0, 0, 1, NULL};
    write_file(g_rows, n, &w, NULL);
    char errp[] = "/tmp/rcal_plaus_errXXXXXX";
    const int efd = mkstemp(errp), saved = dup(2);
    assert_true(efd >= 0 && saved >= 0);
    fflush(stderr);
    dup2(efd, 2);
    rch_pos p;
    rch_diag d;
    const int rc = load(&p, &d);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    assert_int_equal(rc, 0);
    assert_int_equal(p.dropped, 1);
    assert_int_equal(p.rows, n - 1);
    char buf[1024] = {0}, want[256];
    lseek(efd, 0, SEEK_SET);
    assert_true(read(efd, buf, sizeof buf - 1) > 0);
    close(efd);
    remove(errp);
    printf("    warned: %s", buf);
    snprintf(want, sizeof want, "%s:%zu: warning: the same row as line 7, every field identical", g_path, n + 1);
    assert_non_null(strstr(buf, want));
    rc_model m = g_robot; /* ISO 9283: one pose and target repeated (the fresh one), not two */
    assert_int_equal(rch_pos_add_effects(&m, NTG), 0);
    assert_int_equal(rch_pos_start(&m, p.s, p.n, 0), 0);
    rch_pos_err e;
    assert_int_equal(rch_pos_errors(&e, &m, p.s, p.n), 0);
    assert_int_equal(e.repeated, 1);
    rch_pos_free(&p);
    remove(g_path);
}

/* g. the controller's x, y, z (the nominal arm's flange, base frame) as tracker data */
static void test_controller(void **state)
{
    (void)state;
    const gen_cfg c = {1, 1, 0.0, 1, 38};
    const size_t n = generate(g_rows, &c);
    write_cfg w = {1.0, 0, 0, 0, NULL};
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "these are the controller's computed positions, not measurements", NULL);
    w.fmt = "%.2f";
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "controller's computed positions", "rounding 0.01 mm");
    w.fmt = "%.10f";
    write_file(g_rows, n, &w, NULL);
    expect_refused(0, "controller's computed positions", NULL);
}

int main(void)
{
    rch_robot r;
    rch_diag d;
    if (rch_robot_load(&r, ROBOT, &d) != 0)
        return 1;
    g_robot = r.model;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clean_passes), cmocka_unit_test(test_field_count), cmocka_unit_test(test_units),
        cmocka_unit_test(test_mirrored),     cmocka_unit_test(test_targets),     cmocka_unit_test(test_pose_reused),
        cmocka_unit_test(test_duplicate),    cmocka_unit_test(test_controller),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
