/* SPDX-License-Identifier: MIT */
/* test_seen.c - one vocabulary of what the data see (rch_seen.h, issue 32):
 * `rcal calibrate` on a tracker-only, a centred one-outlet cable and an
 * off-centre cable run, data from the independent kinematics
 * (tests/common/rct_indep.h: a perturbed IRB120, Gaussian noise the code is
 * never told), prints only the new words (never the old contradictory
 * pairs), the headline at the point the data see, no cable-pose advice for
 * a tracker; and the class table itself.
 * Depends on: the rcal binary, rch_seen. Memory: files in the build tree. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rct_indep.h"
#include "rct_irb120.h"
#include "rch_seen.h"

#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define DIR RCAL_BINARY_DIR "/tests/tools/host/model"
#define DEG (3.14159265358979323846 / 180.0)

/* A true robot: nominal plus 0.3 mm / 0.05 deg errors (seeded). */
static void true_robot(double dh[6][4], rct_rng *g)
{
    rct_irb120_dh(dh);
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            if (!(i == 0 && (k == 1 || k == 3))) /* the gauge (d1, theta1) at nominal */
                dh[i][k] += rct_gauss(g) * (k < 2 ? 0.3 : 0.05 * DEG);
}

static void draw_q(double q[6], rct_rng *g)
{
    for (int j = 0; j < 6; ++j) {
        const double lo = rct_irb120_lim_deg[j][0] * 0.8, hi = rct_irb120_lim_deg[j][1] * 0.8;
        q[j] = (lo + (hi - lo) * rct_u01(g)) * DEG;
    }
}

/* point of the flange frame t (3) at q: p + R t */
static void point(double out[3], double dh[6][4], const double q[6], const double t[3])
{
    double p[3], R[9];
    rct_pose(p, R, dh, q);
    for (int i = 0; i < 3; ++i)
        out[i] = p[i] + R[i * 3] * t[0] + R[i * 3 + 1] * t[1] + R[i * 3 + 2] * t[2];
}

static void write_cable(const char *path, const double att[3], unsigned seed)
{
    rct_rng g = {seed};
    double dh[6][4], e[3] = {250.0, -460.0, 10.0};
    true_robot(dh, &g);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "q1,q2,q3,q4,q5,q6,L\n");
    for (int i = 0; i < 300; ++i) {
        double q[6], p[3];
        draw_q(q, &g);
        point(p, dh, q, att);
        for (int j = 0; j < 6; ++j)
            fprintf(f, "%.6f,", q[j] / DEG);
        fprintf(f, "%.5f\n", rct_dist(p, e) + 0.01 * rct_gauss(&g));
    }
    fclose(f);
}

static void write_tracker(const char *path, unsigned seed)
{
    rct_rng g = {seed};
    double dh[6][4];
    const double tg[3][3] = {{60, 0, 30}, {-30, 52, 30}, {-30, -52, 30}};
    true_robot(dh, &g);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "pose,target,q1,q2,q3,q4,q5,q6,x,y,z\n");
    for (int i = 0; i < 40; ++i) {
        double q[6];
        draw_q(q, &g);
        for (int k = 0; k < 3; ++k) {
            double p[3];
            point(p, dh, q, tg[k]);
            fprintf(f, "%d,%d", i, k);
            for (int j = 0; j < 6; ++j)
                fprintf(f, ",%.6f", q[j] / DEG);
            /* the tracker 1.5 m away, turned 90 deg about z */
            fprintf(f, ",%.5f,%.5f,%.5f\n", 1500.0 - p[1] + 0.02 * rct_gauss(&g), p[0] + 300.0 + 0.02 * rct_gauss(&g),
                    p[2] - 200.0 + 0.02 * rct_gauss(&g));
        }
    }
    fclose(f);
}

/* The calibrate text of args into a heap string. */
static char *run(const char *args)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "%s calibrate --robot %s %s 2>&1", RCAL, ROBOT, args);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t cap = 1 << 16, n = 0;
    char *s = malloc(cap);
    size_t k;
    while ((k = fread(s + n, 1, cap - n - 1, p)) > 0) {
        n += k;
        if (n + 1 >= cap)
            s = realloc(s, cap *= 2);
    }
    s[n] = '\0';
    pclose(p);
    return s;
}

/* Only the new words: no "identifiable"-style class column, no "data vs
 * prior" pairs. */
static void only_new_words(const char *s)
{
    static const char *old[] = {"  identifiable ", "not identifiable  ", "  weak  ", "data vs prior", "  fixed  ",
                                "NOT identifiable", "weakly identifiable", "(se "};
    for (size_t k = 0; k < sizeof old / sizeof old[0]; ++k) {
        if (strstr(s, old[k]))
            fprintf(stderr, "old word \"%s\" printed\n", old[k]);
        assert_null(strstr(s, old[k]));
    }
    assert_non_null(strstr(s, "what the data see"));
    assert_non_null(strstr(s, "determined by the data"));
}

static void test_tracker(void **st)
{
    (void)st;
    write_tracker(DIR "/seen_tracker.csv", 5);
    char *s = run("--positions " DIR "/seen_tracker.csv");
    only_new_words(s);
    assert_non_null(strstr(s, "at the tracker's targets: +-"));
    assert_non_null(strstr(s, "the flange centre behind them"));
    assert_non_null(strstr(s, "prior only"));
    assert_null(strstr(s, "--outlet")); /* no cable-pose advice */
    assert_null(strstr(s, "outlets:"));
    const char *h = strstr(s, "at the tracker's targets: +-");
    assert_true(atof(h + strlen("at the tracker's targets: +-")) < 0.2);
    free(s);
}

static void test_cable_centred(void **st)
{
    (void)st;
    const double att[3] = {0, 0, 0};
    write_cable(DIR "/seen_centred.csv", att, 7);
    char *s = run("--data " DIR "/seen_centred.csv");
    only_new_words(s);
    assert_non_null(strstr(s, "at the flange centre: +-"));
    assert_null(strstr(s, "the flange centre behind"));
    assert_non_null(strstr(s, "not seen by the data (one cable attachment point"));
    free(s);
}

static void test_cable_off_centre(void **st)
{
    (void)st;
    const double att[3] = {40.0, 25.0, 20.0};
    write_cable(DIR "/seen_off.csv", att, 9);
    char *s = run("--data " DIR "/seen_off.csv");
    only_new_words(s);
    if (strstr(s, "estimated in the flange frame")) { /* the attachment found off the centre */
        assert_non_null(strstr(s, "at the cable attachment point: +-"));
        assert_non_null(strstr(s, "the flange centre behind it"));
    }
    free(s);
}

/* rcal compensate --u95-policy: refuse writes nothing and exits 1, warn
 * compensates and names each line with its u95 (the flange of a tracker
 * model: prior only, about 1.2 mm). */
static void test_comp_policy(void **st)
{
    (void)st;
    write_tracker(DIR "/seen_tracker.csv", 5);
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s calibrate --robot %s --positions %s --out %s >/dev/null 2>&1", RCAL, ROBOT,
             DIR "/seen_tracker.csv", DIR "/seen_tracker_model.json");
    assert_int_equal(system(cmd), 0);
    FILE *f = fopen(DIR "/seen_prog.csv", "w");
    assert_non_null(f);
    fputs("q1,q2,q3,q4,q5,q6\n10,20,30,40,50,60\n-20,10,5,30,-40,10\n", f);
    fclose(f);
    remove(DIR "/seen_out.csv");
    snprintf(cmd, sizeof cmd,
             "%s compensate --model %s --in %s --out %s --max-uncertainty-mm 0.5 --u95-policy refuse 2>/dev/null",
             RCAL, DIR "/seen_tracker_model.json", DIR "/seen_prog.csv", DIR "/seen_out.csv");
    assert_int_not_equal(system(cmd), 0);
    assert_null(fopen(DIR "/seen_out.csv", "r"));
    snprintf(cmd, sizeof cmd,
             "%s compensate --model %s --in %s --out %s --max-uncertainty-mm 0.5 --u95-policy warn 2>%s", RCAL,
             DIR "/seen_tracker_model.json", DIR "/seen_prog.csv", DIR "/seen_out.csv", DIR "/seen_warn.txt");
    assert_int_equal(system(cmd), 0);
    f = fopen(DIR "/seen_warn.txt", "r");
    assert_non_null(f);
    char buf[4096];
    const size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    assert_non_null(strstr(buf, "seen_prog.csv:2: warning: compensated, but"));
    assert_non_null(strstr(buf, "seen_prog.csv:3: warning: compensated, but"));
    f = fopen(DIR "/seen_out.csv", "r");
    assert_non_null(f);
    fclose(f);
    /* below the threshold nothing is said */
    snprintf(cmd, sizeof cmd,
             "%s compensate --model %s --in %s --out %s --max-uncertainty-mm 100 --u95-policy refuse 2>/dev/null",
             RCAL, DIR "/seen_tracker_model.json", DIR "/seen_prog.csv", DIR "/seen_out.csv");
    assert_int_equal(system(cmd), 0);
}

/* The table: one class from both facts, the ratio deciding with a prior. */
static void test_table(void **st)
{
    (void)st;
    assert_int_equal(rch_seen_of(RCH_PARAM_NOT_IDENTIFIABLE, RCH_PRIOR_CLASS_DETERMINED, 1), RCH_SEEN_DATA);
    assert_int_equal(rch_seen_of(RCH_PARAM_IDENTIFIABLE, RCH_PRIOR_CLASS_PRIOR_ONLY, 1), RCH_SEEN_PRIOR);
    assert_int_equal(rch_seen_of(RCH_PARAM_NOT_IDENTIFIABLE, RCH_PRIOR_CLASS_NONE, 0), RCH_SEEN_UNSEEN);
    assert_int_equal(rch_seen_of(RCH_PARAM_WEAK, RCH_PRIOR_CLASS_NONE, 0), RCH_SEEN_PARTLY);
    assert_int_equal(rch_seen_of(RCH_PARAM_FIXED, RCH_PRIOR_CLASS_DETERMINED, 1), RCH_SEEN_HELD);
    assert_int_equal(rch_seen_of(RCH_PARAM_IDENTIFIABLE, rch_prior_classify(0.4, 1.0), 1), RCH_SEEN_DATA);
    assert_int_equal(rch_seen_of(RCH_PARAM_IDENTIFIABLE, rch_prior_classify(0.6, 1.0), 1), RCH_SEEN_PARTLY);
    assert_int_equal(rch_seen_of(RCH_PARAM_IDENTIFIABLE, rch_prior_classify(1.05, 1.0), 1), RCH_SEEN_PRIOR);
    for (int k = 0; k < RCH_SEEN_COUNT; ++k) {
        assert_int_equal(rch_seen_table[k].c, k);
        assert_int_equal(rch_seen_parse(rch_seen_table[k].key), k);
        assert_int_equal(rch_seen_parse(rch_seen_table[k].words), k);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table),
        cmocka_unit_test(test_tracker),
        cmocka_unit_test(test_cable_centred),
        cmocka_unit_test(test_cable_off_centre),
        cmocka_unit_test(test_comp_policy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
