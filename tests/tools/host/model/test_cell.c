/* SPDX-License-Identifier: MIT */
/* test_cell.c - rch_cell (issue 48, item 4): the distances against brute
 * force (dense sampling of both segments / the segment), the chain's frames
 * against rc_fk, the verdicts, the robot file's "links" and "cell" (unknown
 * keys refused at file:line:col), the shipped robots' links. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rc_rand.h"
#include "rch_cell.h"
#include "rch_robot.h"

static double dist3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static void lerp(double *o, const double *a, const double *b, double t)
{
    for (int i = 0; i < 3; ++i)
        o[i] = a[i] + t * (b[i] - a[i]);
}

static void rnd3(double *v, rc_rng *g, double s)
{
    for (int i = 0; i < 3; ++i)
        v[i] = s * (2.0 * rc_rng_u01(g) - 1.0);
}

/* segment-segment: never above the sampled minimum, and within the
 * sampling's resolution of it (parallel, crossing, degenerate cases
 * included) */
static void test_seg_seg_brute(void **st)
{
    (void)st;
    rc_rng g;
    rc_rng_seed(&g, 7);
    const int N = 400;
    for (int trial = 0; trial < 300; ++trial) {
        double p0[3], p1[3], q0[3], q1[3];
        rnd3(p0, &g, 100);
        rnd3(p1, &g, 100);
        rnd3(q0, &g, 100);
        rnd3(q1, &g, 100);
        if (trial % 10 == 1) /* parallel */
            for (int i = 0; i < 3; ++i)
                q1[i] = q0[i] + 0.7 * (p1[i] - p0[i]);
        if (trial % 10 == 2) /* a point */
            memcpy(q1, q0, sizeof q0);
        const double d = rch_cell_seg_seg_mm(p0, p1, q0, q1);
        double best = 1e300, lp = dist3(p0, p1), lq = dist3(q0, q1);
        for (int i = 0; i <= N; ++i)
            for (int j = 0; j <= N; ++j) {
                double a[3], b[3];
                lerp(a, p0, p1, (double)i / N);
                lerp(b, q0, q1, (double)j / N);
                const double x = dist3(a, b);
                best = x < best ? x : best;
            }
        assert_true(d <= best + 1e-9);
        assert_true(d >= best - (lp + lq) / N - 1e-9);
        assert_true(fabs(rch_cell_seg_seg_mm(q0, q1, p0, p1) - d) < 1e-9); /* symmetric */
    }
}

static void test_seg_box_brute(void **st)
{
    (void)st;
    rc_rng g;
    rc_rng_seed(&g, 11);
    const int N = 20000;
    for (int trial = 0; trial < 300; ++trial) {
        rch_box b;
        double c[3], h[3], p0[3], p1[3];
        rnd3(c, &g, 50);
        for (int i = 0; i < 3; ++i) {
            h[i] = 5 + 40 * rc_rng_u01(&g);
            b.min_mm[i] = c[i] - h[i];
            b.max_mm[i] = c[i] + h[i];
        }
        rnd3(p0, &g, 150);
        rnd3(p1, &g, 150);
        const double d = rch_cell_seg_box_mm(p0, p1, &b);
        double best = 1e300;
        for (int i = 0; i <= N; ++i) {
            double a[3], dd = 0;
            lerp(a, p0, p1, (double)i / N);
            for (int k = 0; k < 3; ++k) {
                const double x = a[k] < b.min_mm[k] ? b.min_mm[k] - a[k] : a[k] > b.max_mm[k] ? a[k] - b.max_mm[k] : 0;
                dd += x * x;
            }
            best = sqrt(dd) < best ? sqrt(dd) : best;
        }
        assert_true(d <= best + 1e-6);
        assert_true(d >= best - dist3(p0, p1) / N - 1e-6);
    }
}

static rch_robot *load(const char *rel)
{
    char p[1024];
    rch_diag dg;
    rch_robot *r = calloc(1, sizeof *r);
    snprintf(p, sizeof p, "%s/%s", RCAL_SOURCE_DIR, rel);
    assert_non_null(r);
    if (rch_robot_load(r, p, &dg) != 0)
        fail_msg("%s", dg.msg);
    return r;
}

/* the chain's last frame is rc_fk's flange; every link's segment ends where
 * the robot file says in its frame */
static void test_frames_vs_fk(void **st)
{
    (void)st;
    rch_robot *r = load("data/irb120.json");
    rc_rng g;
    rc_rng_seed(&g, 3);
    for (int t = 0; t < 100; ++t) {
        double q[RC_NJ], fr[7][12], pos[3], rot[9];
        for (int j = 0; j < RC_NJ; ++j)
            q[j] = r->model.q_min_rad[j] + (r->model.q_max_rad[j] - r->model.q_min_rad[j]) * rc_rng_u01(&g);
        rch_cell_frames(fr, &r->model, q);
        rc_fk(pos, rot, &r->model, q);
        for (int i = 0; i < 3; ++i)
            assert_true(fabs(fr[6][9 + i] - pos[i]) < 1e-9);
        for (int i = 0; i < 9; ++i)
            assert_true(fabs(fr[6][i] - rot[i]) < 1e-12);
    }
    free(r);
}

/* the shipped robots: links present, a floor, every link's far end at the
 * home pose above the floor, and the home pose safe from the README's outlet */
static void test_shipped(void **st)
{
    (void)st;
    const char *files[] = {"data/irb120.json", "data/irb1600.json"};
    for (int f = 0; f < 2; ++f) {
        rch_robot *r = load(files[f]);
        const double q0[RC_NJ] = {0, 0, 0, 0, 0.5, 0}, out[3] = {250, -460, 10}, fl[3] = {0, 0, 0};
        rch_cell_verdict v;
        assert_true(r->cell.n_links >= 6);
        assert_true(r->cell.has_floor);
        rch_cell_check(&v, &r->cell, &r->model, q0, out, fl, 20.0);
        assert_int_equal(v.reason, RCH_CELL_SAFE);
        /* the flange pointing into the floor: below it */
        const double qdown[RC_NJ] = {0, 1.5, 0.6, 0, 1.0, 0};
        rch_cell_check(&v, &r->cell, &r->model, qdown, out, fl, 20.0);
        assert_int_equal(v.reason, RCH_CELL_BELOW_FLOOR);
        free(r);
    }
}

/* the cable through the upper arm: refused, and named */
static void test_cable_through_link(void **st)
{
    (void)st;
    rch_robot *r = load("data/irb120.json");
    const double q[RC_NJ] = {0, 0, 0, 0, 0.5, 0}, fl[3] = {0, 0, 0};
    double fr[7][12], a[3], b[3], mid[3], flange[3], out[3];
    rch_cell_frames(fr, &r->model, q);
    unsigned k = 0;
    while (strcmp(r->cell.link[k].name, "upper arm") != 0)
        ++k;
    rch_cell_link_base(a, b, &r->cell, k, (const double(*)[12])fr);
    lerp(mid, a, b, 0.5);
    memcpy(flange, &fr[6][9], sizeof flange);
    for (int i = 0; i < 3; ++i) /* an outlet beyond the upper arm seen from the flange */
        out[i] = flange[i] + 2.0 * (mid[i] - flange[i]);
    rch_cell_verdict v;
    rch_cell_check(&v, &r->cell, &r->model, q, out, fl, 20.0);
    assert_int_equal(v.reason, RCH_CELL_CABLE_LINK);
    assert_true(v.dist_mm < 0.0);
    char why[200];
    rc_sample s;
    memset(&s, 0, sizeof s);
    memcpy(s.q_rad, q, sizeof q);
    memcpy(&r->model.x[RC_P_ENC], out, sizeof out);
    assert_int_equal(rch_cell_row_refused(why, sizeof why, &r->cell, &r->model, &s, 0), 1);
    assert_non_null(strstr(why, "cable near a link"));
    free(r);
}

static void test_boxes_and_keys(void **st)
{
    (void)st;
    rch_robot *r = calloc(1, sizeof *r);
    rch_diag dg;
    const char *txt =
        "{\"dh\": [{\"a_mm\":0,\"d_mm\":290,\"alpha_deg\":-90,\"theta_deg\":0},"
        "{\"a_mm\":270,\"d_mm\":0,\"alpha_deg\":0,\"theta_deg\":-90},{\"a_mm\":70,\"d_mm\":0,\"alpha_deg\":-90,"
        "\"theta_deg\":0},{\"a_mm\":0,\"d_mm\":302,\"alpha_deg\":90,\"theta_deg\":0},{\"a_mm\":0,\"d_mm\":0,"
        "\"alpha_deg\":-90,\"theta_deg\":0},{\"a_mm\":0,\"d_mm\":72,\"alpha_deg\":0,\"theta_deg\":0}],\n"
        " \"cell\": {\"floor\": {}, \"boxes\": [{\"name\": \"table\", \"min_mm\": [300,-200,0], "
        "\"max_mm\": [600,200,100]}]}}";
    assert_int_equal(rch_robot_parse(r, txt, strlen(txt), "t.json", &dg), 0);
    assert_int_equal(r->cell.n_boxes, 1);
    assert_string_equal(r->cell.box[0].name, "table");
    assert_true(r->cell.has_floor && r->cell.floor_normal[2] == 1.0);
    /* a cable from an outlet on the far side of the table, over it at 50 mm: near the box */
    const double q[RC_NJ] = {0, 0, 0, 0, 0.5, 0}, fl[3] = {0, 0, 0};
    double fr[7][12], out[3];
    rch_cell_frames(fr, &r->model, q);
    out[0] = 900;
    out[1] = 0;
    out[2] = 150;
    rch_cell_verdict v;
    rch_cell_check(&v, &r->cell, &r->model, q, out, fl, 20.0);
    const double d = rch_cell_seg_box_mm(out, &fr[6][9], &r->cell.box[0]);
    assert_int_equal(v.reason, d < 20.0 ? RCH_CELL_CABLE_BOX : RCH_CELL_SAFE);
    /* a misspelled key: refused at its line:col */
    char bad[2048]; /* the dh line, then links with "radius" for "radius_mm" on line 2 */
    const int dh_len = (int)(strchr(txt, '\n') - txt + 1);
    snprintf(bad, sizeof bad, "%.*s \"links\": [{\"frame\": 2, \"from_mm\": [0,0,0], \"to_mm\": [1,0,0], "
             "\"radius\": 5}]}", dh_len, txt);
    assert_int_equal(rch_robot_parse(r, bad, strlen(bad), "t.json", &dg), -1);
    assert_non_null(strstr(dg.msg, "radius"));
    assert_int_equal(dg.line, 2);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seg_seg_brute),      cmocka_unit_test(test_seg_box_brute),
        cmocka_unit_test(test_frames_vs_fk),       cmocka_unit_test(test_shipped),
        cmocka_unit_test(test_cable_through_link), cmocka_unit_test(test_boxes_and_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
