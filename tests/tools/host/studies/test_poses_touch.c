/* SPDX-License-Identifier: MIT */
/* test_poses_touch.c - a touch run's plan (rch_poses_touch_plan, issue 50):
 * every row inside the joint limits less the margin, the probe's nominal
 * point (this test's own FK product: rc_fk's flange and rotation times the
 * probe) on its plate's plane (the gauge block's top at +height) within the
 * rounding's tolerance and inside the usable disc, the probe's axis within
 * the cone, the flange on the plate's outer side; every plate touched at
 * least min_per_plate times at height 0 with a 2-D spread (recomputed here),
 * the gauge's share met; the plan's predicted accuracy better than random
 * touches'; the same seed the same plan; bad plates refused naming the
 * plate (a normal without direction, a size inside the edge, a gauge on a
 * plate not given, too few touches for the quotas, a plate out of reach). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rc_model.h"
#include "rch_poses_touch.h"
#include "rct_irb120.h"

#define PI 3.14159265358979323846
#define D2R (PI / 180.0)

static void irb120(rc_model *m)
{
    double dh[6][4];
    const double enc[3] = {250, -460, 10};
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(m, (const double(*)[4])dh, enc), RC_OK);
    for (int j = 0; j < RC_NJ; ++j) {
        m->q_min_rad[j] = rct_irb120_lim_deg[j][0] * D2R;
        m->q_max_rad[j] = rct_irb120_lim_deg[j][1] * D2R;
    }
}

static void plate(rch_touch_plate *p, double x, double y, double z, double nx, double ny, double nz, double size)
{
    p->point_mm[0] = x;
    p->point_mm[1] = y;
    p->point_mm[2] = z;
    p->normal[0] = nx;
    p->normal[1] = ny;
    p->normal[2] = nz;
    p->size_mm = size;
}

static void config(rch_poses_touch_config *c)
{
    memset(c, 0, sizeof *c);
    c->count = 30;
    c->candidates = 800;
    c->passes = 2;
    c->seed = 7;
    c->margin_deg = 5.0;
    c->cone_deg = 30.0;
    c->edge_mm = 10.0;
    c->wrist_deg = 10.0;
    c->min_per_plate = 3;
    c->n_plates = 3;
    plate(&c->plates[0], 375, 0, 60, 0, 0, 1, 140);
    plate(&c->plates[1], 465, 0, 375, -1, 0, 0, 140);
    plate(&c->plates[2], 390, 0, 210, -0.64, 0, 0.77, 140);
    c->tool_mm[0] = 10;
    c->tool_mm[1] = -5;
    c->tool_mm[2] = 150;
    c->gauge_mm = 50;
    c->gauge_plate = 0;
    c->has_gauge_at = 1;
    c->gauge_at_mm[0] = 375;
    c->gauge_at_mm[1] = 30;
    c->gauge_at_mm[2] = 60;
    c->gauge_size_mm = 40;
    c->gauge_share = 0.2;
    c->n_eval = 200;
}

static void test_rows_valid(void **state)
{
    (void)state;
    rc_model m;
    rch_poses_touch_config c;
    rch_poses_touch_result r, r2;
    rch_diag d;
    irb120(&m);
    config(&c);
    assert_int_equal(rch_poses_touch_plan(&r, &m, &c, NULL, &d), 0);
    assert_int_equal(r.n, c.count);
    size_t per[RCH_TOUCH_MAX_PLATES] = {0}, gauge = 0;
    double su[RCH_TOUCH_MAX_PLATES] = {0}, sv[RCH_TOUCH_MAX_PLATES] = {0}, suu[RCH_TOUCH_MAX_PLATES] = {0},
           svv[RCH_TOUCH_MAX_PLATES] = {0}, suv[RCH_TOUCH_MAX_PLATES] = {0};
    for (size_t i = 0; i < r.n; ++i) {
        const rc_sample *s = &r.rows[i];
        assert_true(s->target < c.n_plates);
        for (int j = 0; j < RC_NJ; ++j) {
            assert_true(s->q_rad[j] >= m.q_min_rad[j] + c.margin_deg * D2R - 1e-12);
            assert_true(s->q_rad[j] <= m.q_max_rad[j] - c.margin_deg * D2R + 1e-12);
        }
        double o[3], R[9], p[3], n[3];
        rc_fk(o, R, &m, s->q_rad);
        for (int k = 0; k < 3; ++k)
            p[k] = o[k] + R[3 * k] * c.tool_mm[0] + R[3 * k + 1] * c.tool_mm[1] + R[3 * k + 2] * c.tool_mm[2];
        const rch_touch_plate *pl = &c.plates[s->target];
        const double ln = sqrt(pl->normal[0] * pl->normal[0] + pl->normal[1] * pl->normal[1] + pl->normal[2] * pl->normal[2]);
        for (int k = 0; k < 3; ++k)
            n[k] = pl->normal[k] / ln;
        const int top = s->value != 0.0;
        const double *centre = top ? c.gauge_at_mm : pl->point_mm;
        double dv[3], h = 0.0, rr = 0.0;
        for (int k = 0; k < 3; ++k) {
            dv[k] = p[k] - centre[k];
            h += n[k] * dv[k];
            rr += dv[k] * dv[k];
        }
        /* on the face (0.0001 deg rounding: a few um), inside the usable disc */
        assert_true(fabs(h - (top ? c.gauge_mm : 0.0)) < 0.01);
        assert_true(sqrt(rr - h * h) <= 0.5 * (top ? c.gauge_size_mm : pl->size_mm) - c.edge_mm + 0.01);
        /* the probe's axis (the flange z) within the cone about -n; the flange outside */
        const double cz = -(R[2] * n[0] + R[5] * n[1] + R[8] * n[2]);
        assert_true(cz >= cos(c.cone_deg * D2R) - 1e-9);
        assert_true(n[0] * (o[0] - pl->point_mm[0]) + n[1] * (o[1] - pl->point_mm[1]) + n[2] * (o[2] - pl->point_mm[2]) >
                    0.0);
        assert_true(fabs(sin(s->q_rad[4] + m.x[RC_P_THETA(4)])) >= sin(c.wrist_deg * D2R) - 1e-9);
        if (top) {
            assert_int_equal(s->target, c.gauge_plate);
            ++gauge;
            continue;
        }
        const unsigned k = s->target; /* spread in the face: coordinates on two in-plane axes */
        double u[3] = {n[1], -n[0], 0.0};
        if (fabs(n[2]) > 0.9) {
            u[0] = 1.0;
            u[1] = 0.0;
        }
        double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        for (int q = 0; q < 3; ++q)
            u[q] /= lu;
        const double v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
        const double a = p[0] * u[0] + p[1] * u[1] + p[2] * u[2], b = p[0] * v[0] + p[1] * v[1] + p[2] * v[2];
        su[k] += a;
        sv[k] += b;
        suu[k] += a * a;
        svv[k] += b * b;
        suv[k] += a * b;
        ++per[k];
    }
    for (unsigned k = 0; k < c.n_plates; ++k) {
        assert_true(per[k] >= c.min_per_plate);
        const double nk = (double)per[k], cu = suu[k] / nk - su[k] * su[k] / nk / nk,
                     cv = svv[k] / nk - sv[k] * sv[k] / nk / nk, cuv = suv[k] / nk - su[k] * sv[k] / nk / nk;
        const double tr = 0.5 * (cu + cv), small = tr - sqrt(fmax(tr * tr - (cu * cv - cuv * cuv), 0.0));
        assert_true(sqrt(fmax(small, 0.0)) >= 1.0);
        assert_int_equal(per[k], r.per_plate[k]);
    }
    assert_true(gauge >= (size_t)ceil(c.gauge_share * (double)c.count));
    assert_int_equal(gauge, r.gauge_rows);
    assert_true(r.plan.median_mm < r.random.median_mm);
    /* the same seed, the same plan */
    assert_int_equal(rch_poses_touch_plan(&r2, &m, &c, NULL, &d), 0);
    assert_int_equal(r2.n, r.n);
    assert_memory_equal(r2.rows, r.rows, r.n * sizeof *r.rows);
    rch_poses_touch_free(&r2);
    rch_poses_touch_free(&r);
}

static void refused(const rch_poses_touch_config *c, const char *what)
{
    rc_model m;
    rch_poses_touch_result r;
    rch_diag d;
    irb120(&m);
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_poses_touch_plan(&r, &m, c, NULL, &d), -1);
    if (!strstr(d.msg, what))
        fail_msg("expected '%s' in: %s", what, d.msg);
    assert_null(r.rows);
}

static void test_bad_plates(void **state)
{
    (void)state;
    rch_poses_touch_config c;
    config(&c);
    c.plates[1].normal[0] = 0.0; /* no direction */
    refused(&c, "--plate 2 (plate 1): its normal");
    config(&c);
    c.plates[2].size_mm = 15.0; /* inside the 10 mm edge */
    refused(&c, "--plate 3 (plate 2): size 15 mm");
    config(&c);
    c.gauge_plate = 5;
    refused(&c, "on plate 5");
    config(&c);
    c.count = 9; /* 3 x 3 + 3 on the gauge */
    refused(&c, "need at least 12");
    config(&c);
    c.plates[1].point_mm[0] = 5000.0; /* out of reach */
    refused(&c, "--plate 2 (plate 1 at 5000,0,375)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_valid),
        cmocka_unit_test(test_bad_plates),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
