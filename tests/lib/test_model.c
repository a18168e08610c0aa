/* SPDX-License-Identifier: MIT */
/* Kinematics and measurement model: analytic Jacobians against finite
 * differences, FK against the real file's nominal x, y, z. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rc_kin.h"
#include "rc_model.h"
#include "rc_rand.h"
#include "rct_irb120.h"

static rc_model nominal(void)
{
    rc_model m;
    double dh[RC_NJ][4];
    const double enc[3] = {250.0, -460.0, 10.0};
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(&m, (const double(*)[4])dh, enc), RC_OK);
    for (int i = 0; i < RC_NJ; ++i) {
        m.q_min_rad[i] = rct_irb120_lim_deg[i][0] * 3.14159265358979323846 / 180.0;
        m.q_max_rad[i] = rct_irb120_lim_deg[i][1] * 3.14159265358979323846 / 180.0;
    }
    return m;
}

static void random_pose(rc_sample *s, rc_rng *g)
{
    memset(s, 0, sizeof *s);
    for (int j = 0; j < RC_NJ; ++j)
        s->q_rad[j] = (2.0 * rc_rng_u01(g) - 1.0) * 2.5;
    s->t = rc_rng_u01(g);
    s->group = (uint16_t)rc_rng_below(g, 3);
    s->outlet = 0;
}

/* d value / d x_k of sample s: central differences against rc_meas's analytic gradient. */
static void check_sample_jacobian(const rc_model *m, const rc_sample *s)
{
    double l, jac[RC_MAX_PARAMS];
    assert_int_equal(rc_meas(&l, jac, m, s), RC_OK);
    for (unsigned k = 0; k < m->n_params; ++k) {
        const double h = rc_param_unit(m, k) == 0 ? 1e-4 : 1e-7;
        rc_model mp = *m, mm = *m;
        mp.x[k] += h;
        mm.x[k] -= h;
        double lp, lm;
        assert_int_equal(rc_meas(&lp, NULL, &mp, s), RC_OK);
        assert_int_equal(rc_meas(&lm, NULL, &mm, s), RC_OK);
        const double fd = (lp - lm) / (2.0 * h);
        if (fabs(fd - jac[k]) > 1e-5 * (1.0 + fabs(fd))) {
            char name[64];
            print_error("param %s: analytic %.9g, finite difference %.9g\n", rc_param_name(name, 64, m, k), jac[k],
                        fd);
            fail();
        }
    }
}

/* d l / d x_k: central differences against rc_meas's analytic gradient, for
 * the base model and a model with every effect kind. */
static void check_param_jacobian_points(rc_model *m, rc_rng *g, int tracker, int points)
{
    for (int trial = 0; trial < 50; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, g);
        if (tracker) {
            s.sensor = (uint8_t)(RC_SENSOR_TRACKER_X + trial % 3);
            s.target = (uint8_t)(trial % 2);
        } else if (points) { /* a length to cable point trial % points */
            s.target = (uint8_t)(trial % points);
        }
        check_sample_jacobian(m, &s);
    }
}

static void check_param_jacobian_sensor(rc_model *m, rc_rng *g, int tracker)
{
    check_param_jacobian_points(m, g, tracker, 0);
}

static void check_param_jacobian(rc_model *m, rc_rng *g) { check_param_jacobian_sensor(m, g, 0); }

static void test_param_jacobian_base(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 1);
    rc_model m = nominal();
    for (unsigned k = 0; k < RC_N_BASE; ++k) /* away from the special nominal values */
        m.x[k] += 0.01 * rc_rng_normal(&g);
    check_param_jacobian(&m, &g);
}

/* The nominal model with every effect kind, effect parameters ~1e-3. */
static rc_model model_with_effects(rc_rng *g)
{
    rc_model m = nominal();
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 1, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 2, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 3, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TIME_DRIFT, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_GROUP_OFFSET, 0, 3), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_SCALE, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    assert_int_equal(m.n_params, RC_N_BASE + 1 + 1 + 1 + 4 + 3 + 3 + 1 + 3); /* drift: t, t^2, t^3 */
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        m.x[k] = 1e-3 * rc_rng_normal(g);
    return m;
}

static void test_param_jacobian_effects(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 2);
    rc_model m = model_with_effects(&g);
    check_param_jacobian(&m, &g);
}

/* A cable on the points of a tool plate (RC_EFF_CABLE_POINTS): the length of
 * a sample with target k is the distance from the encoder to flange + R6
 * p_k (written here from rc_fk's flange pose), every derivative by
 * differences with the other effects present (the tool offset's columns
 * zero for such a sample), the prepared path equal, and the effect's
 * argument checks. */
static void test_cable_points(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 5);
    static const double pts[3][3] = {{60.0, 0.0, 20.0}, {-30.0, 52.0, 20.0}, {-30.0, -52.0, 21.0}};
    rc_model plain = nominal();
    assert_int_equal(rc_model_add_effect(&plain, RC_EFF_CABLE_POINTS, 0, 4), RC_ERR_ARG); /* 3 per point */
    assert_int_equal(rc_model_add_effect(&plain, RC_EFF_CABLE_POINTS, 0, 3 * RC_MAX_TARGETS + 3), RC_ERR_ARG);
    assert_int_equal(rc_model_add_effect(&plain, RC_EFF_CABLE_POINTS, 0, 9), RC_OK);
    assert_int_equal(rc_model_add_effect(&plain, RC_EFF_CABLE_POINTS, 0, 9), RC_ERR_ARG); /* one plate */
    const unsigned pf = plain.effects[plain.n_effects - 1].first;
    memcpy(&plain.x[pf], pts, sizeof pts);
    for (int trial = 0; trial < 30; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        s.target = (uint8_t)(trial % 3);
        double o[3], R[9], p[3], l, d2 = 0.0;
        rc_fk(o, R, &plain, s.q_rad); /* the flange: the plate moves no flange */
        for (int r = 0; r < 3; ++r) {
            const double *t = pts[s.target];
            p[r] = o[r] + R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2] - plain.x[RC_P_ENC + r];
            d2 += p[r] * p[r];
        }
        assert_int_equal(rc_meas(&l, NULL, &plain, &s), RC_OK);
        assert_true(fabs(l - sqrt(d2)) < 1e-9);
    }
    rc_model m = model_with_effects(&g); /* with a tool offset, which a point's length does not see */
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_CABLE_POINTS, 0, 9), RC_OK);
    const unsigned mf = m.effects[m.n_effects - 1].first, tf = m.effects[m.n_effects - 2].first;
    memcpy(&m.x[mf], pts, sizeof pts);
    rc_meas_prep pr;
    rc_meas_prepare(&pr, &m);
    for (int trial = 0; trial < 30; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        s.target = (uint8_t)(trial % 3);
        double l, lp, jac[RC_MAX_PARAMS], jp[RC_MAX_PARAMS];
        assert_int_equal(rc_meas(&l, jac, &m, &s), RC_OK);
        assert_int_equal(rc_meas_prepared(&lp, jp, &m, &pr, &s, NULL, NULL), RC_OK);
        assert_true(fabs(l - lp) < 1e-9);
        for (unsigned k = 0; k < m.n_params; ++k)
            assert_true(fabs(jac[k] - jp[k]) < 1e-9 * (1.0 + fabs(jac[k])));
        for (unsigned k = 0; k < 3; ++k) /* the tool offset: not this sample's point */
            assert_true(jac[tf + k] == 0.0);
        for (unsigned k = 0; k < 9; ++k) /* only its own point's three columns */
            assert_true((k / 3u == s.target) == (jac[mf + k] != 0.0));
    }
    check_param_jacobian_points(&m, &g, 0, 3); /* every derivative by differences */
}

/* A laser tracker's position (rc_sensor.h): every derivative of each
 * component by differences (a model with every effect, axis tilts and a
 * tracker turned by about 1 rad), lengths blind to the tracker's parameters,
 * the prepared path equal, and the value against one written here:
 * R (o6 + R6 t) + T with R from the axis and angle. */
static void add_tracker(rc_model *m, rc_rng *g)
{
    assert_int_equal(rc_model_add_effect(m, RC_EFF_AXIS_TILT, 2, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_POSITION, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_ROTATION, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_ROTATION, 0, 0), RC_ERR_ARG); /* one frame */
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_TARGETS, 0, 4), RC_ERR_ARG); /* 3 per target */
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_TARGETS, 0, 3 * RC_MAX_TARGETS + 3), RC_ERR_ARG);
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_TARGETS, 0, 6), RC_OK); /* targets 0, 1 */
    assert_int_equal(rc_model_add_effect(m, RC_EFF_TRACKER_TARGETS, 0, 6), RC_ERR_ARG); /* one set */
    const unsigned n = m->n_params;
    m->x[n - 13] = 1e-3;                       /* tilt */
    m->x[n - 12] = 1200.0 + rc_rng_normal(g); /* T */
    m->x[n - 11] = -800.0;
    m->x[n - 10] = 300.0;
    m->x[n - 9] = 0.3;                         /* w: about 1 rad */
    m->x[n - 8] = -0.5;
    m->x[n - 7] = 0.8;
    for (unsigned k = n - 6; k < n; ++k)
        m->x[k] = 40.0 * rc_rng_normal(g);
}

/* The sensor-side scale effects (issue 31): the tracker's scale about its
 * origin and each outlet's own offset and scale, against finite differences
 * and against their formulas. */
static void test_sensor_scales(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 37);
    rc_model m = nominal();
    add_tracker(&m, &g);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TRACKER_SCALE, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TRACKER_SCALE, 0, 0), RC_ERR_ARG); /* one per tracker */
    m.x[m.n_params - 1] = 40e-6;
    check_param_jacobian_sensor(&m, &g, 1);
    rc_model plain = m; /* the scale about the tracker's origin: value = (1 + s) value_unscaled */
    plain.x[plain.n_params - 1] = 0.0;
    for (int trial = 0; trial < 10; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        s.sensor = (uint8_t)(RC_SENSOR_TRACKER_X + trial % 3);
        double a, b;
        assert_int_equal(rc_meas(&a, NULL, &m, &s), RC_OK);
        assert_int_equal(rc_meas(&b, NULL, &plain, &s), RC_OK);
        assert_true(fabs(a - (1.0 + 40e-6) * b) < 1e-9 * (1.0 + fabs(b)));
    }
    rc_model c = nominal(); /* two outlets: e and outlet 2 (numbered as a file may number them) */
    assert_int_equal(rc_model_add_effect(&c, RC_EFF_OUTLET, 2, 0), RC_OK);
    c.x[c.n_params - 3] = 900.0;
    c.x[c.n_params - 2] = -300.0;
    c.x[c.n_params - 1] = 200.0;
    assert_int_equal(rc_model_add_effect(&c, RC_EFF_OUTLET_OFFSET, 0, 0), RC_OK);
    assert_int_equal(c.effects[c.n_effects - 1].count, 3); /* outlets 0..2 */
    assert_int_equal(rc_model_add_effect(&c, RC_EFF_OUTLET_SCALE, 0, 0), RC_OK);
    const unsigned off = c.effects[c.n_effects - 2].first, sc = c.effects[c.n_effects - 1].first;
    for (unsigned k = 0; k < 3; ++k) {
        c.x[off + k] = 0.1 * (k + 1);
        c.x[sc + k] = 1e-4 * (k + 1);
    }
    rc_model c0 = c;
    memset(&c0.x[off], 0, 6 * sizeof c0.x[0]);
    for (int trial = 0; trial < 20; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        s.outlet = (uint8_t)(trial % 2 ? 2 : 0);
        double l, l0, jac[RC_MAX_PARAMS];
        assert_int_equal(rc_meas(&l, jac, &c, &s), RC_OK);
        assert_int_equal(rc_meas(&l0, NULL, &c0, &s), RC_OK);
        const unsigned o = s.outlet;
        assert_true(fabs(l - ((1.0 + c.x[sc + o]) * l0 + c.x[off + o])) < 1e-9 * l0);
        for (unsigned k = 0; k < 3; ++k) {
            assert_true(fabs(jac[off + k] - (k == o ? 1.0 : 0.0)) < 1e-12);
            assert_true(fabs(jac[sc + k] - (k == o ? l0 : 0.0)) < 1e-9 * l0);
        }
    }
}

static void test_tracker_jacobian(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 31);
    rc_model m = nominal(); /* joint-side, point and length effects beside the tracker */
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 1, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 3, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_SCALE, 0, 0), RC_OK);
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        m.x[k] = 1e-3 * rc_rng_normal(&g);
    add_tracker(&m, &g);
    char name[64];
    assert_string_equal(rc_param_name(name, sizeof name, &m, m.n_params - 1), "tracker_targets.1.z");
    check_param_jacobian_sensor(&m, &g, 1);
    check_param_jacobian_sensor(&m, &g, 0); /* lengths: zero derivative for the tracker's */
    rc_meas_prep p;
    rc_meas_prepare(&p, &m);
    rc_model plain = nominal(); /* no tool offset: rc_fk gives the flange */
    add_tracker(&plain, &g);
    const double *w = &plain.x[plain.n_params - 9], *T = &plain.x[plain.n_params - 12];
    const double th = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double a[3] = {w[0] / th, w[1] / th, w[2] / th}, c = cos(th), sn = sin(th);
    const double R[9] = {c + a[0] * a[0] * (1 - c),        a[0] * a[1] * (1 - c) - a[2] * sn,
                         a[0] * a[2] * (1 - c) + a[1] * sn, a[1] * a[0] * (1 - c) + a[2] * sn,
                         c + a[1] * a[1] * (1 - c),        a[1] * a[2] * (1 - c) - a[0] * sn,
                         a[2] * a[0] * (1 - c) - a[1] * sn, a[2] * a[1] * (1 - c) + a[0] * sn,
                         c + a[2] * a[2] * (1 - c)};
    for (int trial = 0; trial < 20; ++trial) {
        rc_sample s;
        random_pose(&s, &g);
        s.sensor = (uint8_t)(RC_SENSOR_TRACKER_X + trial % 3);
        s.target = (uint8_t)(trial % 2);
        double v0, v1, j0[RC_MAX_PARAMS], j1[RC_MAX_PARAMS];
        assert_int_equal(rc_meas(&v0, j0, &m, &s), RC_OK);
        assert_int_equal(rc_meas_prepared(&v1, j1, &m, &p, &s, NULL, NULL), RC_OK);
        assert_true(fabs(v0 - v1) < 1e-9 * (1.0 + fabs(v0)));
        assert_int_equal(rc_meas_prepared(&v1, NULL, &m, &p, &s, NULL, NULL), RC_OK);
        assert_true(fabs(v0 - v1) < 1e-9 * (1.0 + fabs(v0)));
        for (unsigned k = 0; k < m.n_params; ++k)
            assert_true(fabs(j1[k] - j0[k]) < 1e-9 * (1.0 + fabs(j0[k])));
        double o6[3], R6[9], pt[3], want = 0.0;
        rc_fk(o6, R6, &plain, s.q_rad);
        const double *t = &plain.x[plain.n_params - (s.target == 1 ? 3 : 6)];
        for (int r = 0; r < 3; ++r)
            pt[r] = o6[r] + R6[3 * r] * t[0] + R6[3 * r + 1] * t[1] + R6[3 * r + 2] * t[2];
        const int cc = s.sensor - RC_SENSOR_TRACKER_X;
        want = R[3 * cc] * pt[0] + R[3 * cc + 1] * pt[1] + R[3 * cc + 2] * pt[2] + T[cc];
        assert_int_equal(rc_meas(&v0, NULL, &plain, &s), RC_OK);
        assert_true(fabs(v0 - want) < 1e-9 * (1.0 + fabs(want)));
    }
    rc_sample s;
    random_pose(&s, &g);
    s.sensor = RC_SENSOR_TRACKER_Y;
    s.target = 2; /* a target the model lacks */
    double v;
    assert_int_equal(rc_meas(&v, NULL, &m, &s), RC_ERR_ARG);
}

/* A touch on a plate (RC_SENSOR_PLANE, lib/rc_sensor_plane.c): every
 * derivative by central differences (the chain's, the tip's, the plates'),
 * the value against n . (o6 + R6 t) - d written here with the pole and its
 * basis written out, and the angles' round trip over the sphere. */
static void test_plane_jacobian(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 41);
    rc_model m = nominal();
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 2, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_AXIS_TILT, 1, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOUCH_TIP, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_PLANE_NORMALS, 0, 4), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_PLANE_OFFSETS, 0, 2), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_PLANE_NORMALS, 0, 3), RC_ERR_ARG); /* one set; pairs */
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        m.x[k] = 1e-3 * rc_rng_normal(&g);
    const unsigned tip = m.n_params - 9, nrm = m.n_params - 6, off = m.n_params - 2;
    m.x[tip] = 20.0, m.x[tip + 1] = -15.0, m.x[tip + 2] = 150.0;
    m.x[nrm] = 0.7, m.x[nrm + 1] = -2.0, m.x[nrm + 2] = 2.2, m.x[nrm + 3] = 1.1;
    m.x[off] = 300.0, m.x[off + 1] = -120.0;
    char name[64];
    assert_string_equal(rc_param_name(name, sizeof name, &m, nrm + 3), "plane_normals.p1.phi");
    assert_string_equal(rc_param_name(name, sizeof name, &m, off + 1), "plane_offsets.p1");
    assert_string_equal(rc_sensor_unit(RC_SENSOR_PLANE), "mm");
    assert_string_equal(rc_sensor_name(RC_SENSOR_PLANE), "plane");
    const double P[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)}, E1[3] = {-2 / sqrt(5.0), 1 / sqrt(5.0), 0};
    const double E2[3] = {P[1] * E1[2] - P[2] * E1[1], P[2] * E1[0] - P[0] * E1[2], P[0] * E1[1] - P[1] * E1[0]};
    rc_model flat = m; /* no joint-side effect, no tilt: rc_fk is the chain the test writes against */
    flat.x[RC_N_BASE] = flat.x[RC_N_BASE + 1] = flat.x[RC_N_BASE + 2] = flat.x[RC_N_BASE + 3] = 0.0;
    flat.x[RC_N_BASE + 4] = 0.0;
    for (int trial = 0; trial < 40; ++trial) {
        rc_sample s;
        random_pose(&s, &g);
        s.sensor = RC_SENSOR_PLANE;
        s.target = (uint8_t)(trial % 2);
        s.value = trial % 3 == 0 ? 50.0 : 0.0; /* a gauge block: the value is what the prediction is held to */
        double v;
        check_sample_jacobian(&m, &s);
        double o6[3], R6[9], n[3];
        const double th = flat.x[nrm + 2 * s.target], ph = flat.x[nrm + 2 * s.target + 1];
        rc_fk(o6, R6, &flat, s.q_rad);
        for (int r = 0; r < 3; ++r)
            n[r] = cos(th) * P[r] + sin(th) * (cos(ph) * E1[r] + sin(ph) * E2[r]);
        double want = -flat.x[off + s.target];
        for (int r = 0; r < 3; ++r)
            want += n[r] * (o6[r] + R6[3 * r] * flat.x[tip] + R6[3 * r + 1] * flat.x[tip + 1] +
                            R6[3 * r + 2] * flat.x[tip + 2]);
        assert_int_equal(rc_meas(&v, NULL, &flat, &s), RC_OK);
        assert_true(fabs(v - want) < 1e-9 * (1.0 + fabs(want)));
    }
    for (int trial = 0; trial < 200; ++trial) { /* angles of a normal give it back */
        double n[3] = {rc_rng_normal(&g), rc_rng_normal(&g), rc_rng_normal(&g)}, th, ph, back[3];
        const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int r = 0; r < 3; ++r)
            n[r] /= len;
        rc_plane_angles(&th, &ph, n);
        rc_plane_normal(back, NULL, NULL, th, ph);
        for (int r = 0; r < 3; ++r)
            assert_true(fabs(back[r] - n[r]) < 1e-12);
    }
    rc_sample s;
    random_pose(&s, &g);
    s.sensor = RC_SENSOR_PLANE;
    s.target = 2; /* a plate the model lacks */
    double v;
    assert_int_equal(rc_meas(&v, NULL, &m, &s), RC_ERR_ARG);
}

static void test_effect_capacity(void **state)
{
    (void)state;
    rc_model m = nominal();
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 0, 0), RC_ERR_ARG);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_GROUP_OFFSET, 0, RC_MAX_PARAMS), RC_ERR_CAPACITY);
    assert_int_equal(m.n_params, RC_N_BASE);
}

/* d p / d q and the angular rows against finite differences, with a periodic
 * joint error so the chain rule through effects is exercised. */
static void test_joint_jacobian(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 3);
    rc_model m = nominal();
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 2, 0), RC_OK);
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        m.x[k] = 2e-3;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    m.x[m.n_params - 3] = 12.0;
    m.x[m.n_params - 2] = -7.0;
    m.x[m.n_params - 1] = 30.0;
    for (int trial = 0; trial < 50; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        double p[3], R[9], J[36];
        rc_fk_jac(p, R, J, &m, s.q_rad);
        for (unsigned j = 0; j < RC_NJ; ++j) {
            const double h = 1e-7;
            double qp[RC_NJ], qm[RC_NJ], pp[3], pm[3], Rp[9], Rm[9];
            memcpy(qp, s.q_rad, sizeof qp);
            memcpy(qm, s.q_rad, sizeof qm);
            qp[j] += h;
            qm[j] -= h;
            rc_fk(pp, Rp, &m, qp);
            rc_fk(pm, Rm, &m, qm);
            for (int r = 0; r < 3; ++r)
                assert_true(fabs((pp[r] - pm[r]) / (2 * h) - J[6 * r + j]) < 1e-5);
            /* angular velocity: skew part of dR R^T */
            double W[9];
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                    double sum = 0.0;
                    for (int k = 0; k < 3; ++k)
                        sum += (Rp[3 * a + k] - Rm[3 * a + k]) / (2 * h) * R[3 * b + k];
                    W[3 * a + b] = sum;
                }
            assert_true(fabs(W[7] - J[6 * 3 + j]) < 1e-6);
            assert_true(fabs(W[2] - J[6 * 4 + j]) < 1e-6);
            assert_true(fabs(W[3] - J[6 * 5 + j]) < 1e-6);
        }
    }
}

/* rc_kin_fk_dh_jac: the closed-form sensitivity of the flange point and
 * orientation to the 24 DH parameters against central differences of rc_fk
 * (point and small-rotation vector of R+ R-^T), with a tool offset and a
 * joint-side effect in the model (the formulas must hold through both). */
static void test_dh_sensitivity(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 11);
    rc_model m = nominal();
    for (unsigned k = 0; k < RC_N_DH; ++k)
        m.x[k] += (rc_param_unit(&m, k) == 1 ? 0.01 : 2.0) * (2.0 * rc_rng_u01(&g) - 1.0);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 1, 0), RC_OK);
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        m.x[k] = 3e-3;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    m.x[m.n_params - 3] = 10.0;
    m.x[m.n_params - 2] = -20.0;
    m.x[m.n_params - 1] = 40.0;
    rc_kin kin;
    rc_kin_data kd;
    assert_int_equal(rc_kin_compile(&kin, &m), RC_OK);
    for (int trial = 0; trial < 30; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        double p[3], R[9], p0[3], jp[3 * RC_N_DH], jr[3 * RC_N_DH];
        rc_kin_fk_dh_jac(p, R, jp, jr, &kd, &kin, s.q_rad);
        rc_fk(p0, NULL, &m, s.q_rad);
        for (int r = 0; r < 3; ++r)
            assert_true(p[r] == p0[r]); /* the same chain as rc_kin_fk, bit for bit */
        for (unsigned k = 0; k < RC_N_DH; ++k) {
            const double h = rc_param_unit(&m, k) == 1 ? 1e-7 : 1e-5;
            rc_model mp = m, mm = m;
            mp.x[k] += h;
            mm.x[k] -= h;
            double pp[3], pm[3], Rp[9], Rm[9], D[9], w[3];
            rc_fk(pp, Rp, &mp, s.q_rad);
            rc_fk(pm, Rm, &mm, s.q_rad);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    D[3 * i + j] =
                        Rp[3 * i] * Rm[3 * j] + Rp[3 * i + 1] * Rm[3 * j + 1] + Rp[3 * i + 2] * Rm[3 * j + 2];
            w[0] = 0.5 * (D[7] - D[5]) / (2.0 * h);
            w[1] = 0.5 * (D[2] - D[6]) / (2.0 * h);
            w[2] = 0.5 * (D[3] - D[1]) / (2.0 * h);
            for (int r = 0; r < 3; ++r) {
                const double fd = (pp[r] - pm[r]) / (2.0 * h);
                if (fabs(fd - jp[r * RC_N_DH + (int)k]) > 1e-5 * (1.0 + fabs(fd)) ||
                    fabs(w[r] - jr[r * RC_N_DH + (int)k]) > 1e-6) {
                    char name[64];
                    print_error("param %s row %d: dp %.9g vs %.9g, dw %.9g vs %.9g\n", rc_param_name(name, 64, &m, k),
                                r, jp[r * RC_N_DH + (int)k], fd, jr[r * RC_N_DH + (int)k], w[r]);
                    fail();
                }
            }
        }
    }
}

static void test_fk_zero_pose(void **state)
{
    (void)state;
    rc_model m = nominal();
    double q[RC_NJ] = {0}, p[3];
    rc_fk(p, NULL, &m, q);
    /* IRB120 at zero: flange at x = 302 + 72, z = 290 + 270 + 70 */
    assert_true(fabs(p[0] - 374.0) < 1e-9);
    assert_true(fabs(p[1]) < 1e-9);
    assert_true(fabs(p[2] - 630.0) < 1e-9);
}

static void test_wrap_angles(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 9);
    rc_model m = nominal(), w;
    m.x[RC_P_THETA(5)] = 2802.79 * 3.14159265358979323846 / 180.0;
    m.x[RC_P_ALPHA(2)] = -7.0;
    m.x[RC_P_THETA(0)] = 3.14159265358979323846;
    w = m;
    rc_model_wrap_angles(&w);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        assert_true(w.x[RC_P_ALPHA(i)] > -3.1415926536 && w.x[RC_P_ALPHA(i)] <= 3.1415926536);
        assert_true(w.x[RC_P_THETA(i)] > -3.1415926536 && w.x[RC_P_THETA(i)] <= 3.1415926536);
    }
    for (int trial = 0; trial < 20; ++trial) { /* same lengths */
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, &g);
        double l1, l2;
        assert_int_equal(rc_meas(&l1, NULL, &m, &s), RC_OK);
        assert_int_equal(rc_meas(&l2, NULL, &w, &s), RC_OK);
        assert_true(fabs(l1 - l2) < 1e-9);
    }
}

static void test_lt_map(void **state)
{
    (void)state;
    double n = 0.37;
    for (int i = 0; i < 10000; ++i) {
        n = rc_lt_map(n, 0.5);
        assert_true(n >= 0.0 && n < 1.0);
    }
    /* Eq. 11 by hand: N = 0.2 < 0.5: 0.5*0.2*0.8 + 3.5*0.1 = 0.43 */
    assert_true(fabs(rc_lt_map(0.2, 0.5) - 0.43) < 1e-12);
    /* N = 0.8: 0.5*0.8*0.2 + 3.5*0.1 = 0.43 */
    assert_true(fabs(rc_lt_map(0.8, 0.5) - 0.43) < 1e-12);
}

/* The solver's passes (rc_meas_prepared: angle addition from the model's
 * and the readings' sines) against the single measurement rc_meas: the same
 * length and Jacobian to rounding, for the base model and one with every
 * effect; with the readings' tables or without them, bit for bit the same;
 * rc_point_prepared is rc_fk's point. */
static void check_prepared(const rc_model *m, rc_rng *g)
{
    rc_meas_prep p;
    rc_meas_prepare(&p, m);
    for (int trial = 0; trial < 200; ++trial) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        random_pose(&s, g);
        double sq[RC_NJ], cq[RC_NJ], l0, l1, l2, j0[RC_MAX_PARAMS], j1[RC_MAX_PARAMS], j2[RC_MAX_PARAMS];
        rc_qtrig_fill(sq, cq, &s, 1);
        for (unsigned i = 0; i < RC_NJ; ++i) {
            assert_true(sq[i] == sin(s.q_rad[i]));
            assert_true(cq[i] == cos(s.q_rad[i]));
        }
        assert_int_equal(rc_meas(&l0, j0, m, &s), RC_OK);
        assert_int_equal(rc_meas_prepared(&l1, j1, m, &p, &s, sq, cq), RC_OK);
        assert_int_equal(rc_meas_prepared(&l2, j2, m, &p, &s, NULL, NULL), RC_OK);
        assert_true(l1 == l2);
        assert_memory_equal(j1, j2, m->n_params * sizeof j1[0]);
        assert_true(fabs(l1 - l0) < 1e-9 * (1.0 + l0));
        for (unsigned k = 0; k < m->n_params; ++k)
            assert_true(fabs(j1[k] - j0[k]) < 1e-9 * (1.0 + fabs(j0[k])));
        double pf[3], pp[3];
        rc_fk(pf, NULL, m, s.q_rad);
        rc_point_prepared(pp, m, &p, &s, NULL, NULL);
        for (int r = 0; r < 3; ++r)
            assert_true(fabs(pf[r] - pp[r]) < 1e-9 * (1.0 + fabs(pf[r])));
    }
}

static void test_prepared_base(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 21);
    rc_model m = nominal();
    for (unsigned k = 0; k < RC_N_BASE; ++k)
        m.x[k] += 0.01 * rc_rng_normal(&g);
    m.x[RC_P_THETA(1)] += 40.0; /* an offset of many turns: angle addition does not care */
    check_prepared(&m, &g);
}

static void test_prepared_effects(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 22);
    rc_model m = model_with_effects(&g);
    rc_meas_prep p;
    rc_meas_prepare(&p, &m);
    assert_true(p.has_joint_effect && p.joint_effect[1] && p.joint_effect[2] && p.joint_effect[3]);
    assert_true(!p.joint_effect[0] && !p.joint_effect[4] && !p.joint_effect[5]);
    assert_int_equal(p.tool, m.n_params - 3);
    check_prepared(&m, &g);
}

/* An angle of a diverged solve (beyond 1e6 rad) is not reduced: reducing it
 * by the double nearest 2 pi would move it. */
static void test_wrap_leaves_huge_angles(void **state)
{
    (void)state;
    rc_model m = nominal();
    m.x[RC_P_THETA(2)] = 1.25e147;
    m.x[RC_P_ALPHA(3)] = -3.0e7;
    m.x[RC_P_THETA(4)] = 7.0;
    rc_model_wrap_angles(&m);
    assert_true(m.x[RC_P_THETA(2)] == 1.25e147);
    assert_true(m.x[RC_P_ALPHA(3)] == -3.0e7);
    assert_true(fabs(m.x[RC_P_THETA(4)] - (7.0 - 2.0 * 3.14159265358979323846)) < 1e-15);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_param_jacobian_base), cmocka_unit_test(test_param_jacobian_effects),
        cmocka_unit_test(test_cable_points),
        cmocka_unit_test(test_effect_capacity),     cmocka_unit_test(test_joint_jacobian),
        cmocka_unit_test(test_fk_zero_pose),        cmocka_unit_test(test_lt_map),              cmocka_unit_test(test_wrap_angles),
        cmocka_unit_test(test_prepared_base),       cmocka_unit_test(test_prepared_effects),
        cmocka_unit_test(test_wrap_leaves_huge_angles), cmocka_unit_test(test_dh_sensitivity), cmocka_unit_test(test_tracker_jacobian), cmocka_unit_test(test_sensor_scales),
        cmocka_unit_test(test_plane_jacobian),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
