/* SPDX-License-Identifier: MIT */
/* The identifiability table by sensor (rch_ident.h): with data that hold no
 * cable length (plate touches alone, tracker positions alone) the encoder
 * outlet e is no part of the problem (no ex, ey, ez in a direction or a
 * known set, n_params without them) and no explanation speaks of the cable
 * (its lengths, the encoder); the explanations speak of the data's sensor
 * (the tracker's alpha6 "tracker positions cannot see it", the touch
 * probe's tip as the cable attachment: "d6 touch_tip.z"); with cable
 * lengths the table keeps e and its words. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_ident.h"
#include "rch_positions.h"
#include "rch_robot.h"
#include "rch_sensors.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define NS 240

static rc_model nominal(void)
{
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, ROBOT, &d), 0);
    return r.model;
}

/* Does the space-separated list text name ex, ey or ez? */
static int names_e(const char *text)
{
    for (const char *p = text; *p;) {
        p += strspn(p, " +-0123456789.");
        const size_t len = strcspn(p, " ");
        if (len == 2 && p[0] == 'e' && (p[1] == 'x' || p[1] == 'y' || p[1] == 'z'))
            return 1;
        p += len;
    }
    return 0;
}

/* Is name the first (largest) component of combo ("+0.97 alpha6 -0.22 theta6")? */
static int leads(const char *combo, const char *name)
{
    const size_t len = strlen(name);
    return strlen(combo) >= 6 + len && strncmp(combo + 6, name, len) == 0 &&
           (combo[6 + len] == ' ' || combo[6 + len] == '\0');
}

/* No e and no cable words anywhere in id. */
static void assert_no_cable(const rch_ident *id)
{
    for (unsigned k = 0; k < id->n_dirs; ++k) {
        assert_false(names_e(id->dirs[k].combo));
        assert_null(strstr(id->dirs[k].why, "encoder"));
        assert_null(strstr(id->dirs[k].why, "cable"));
        assert_null(strstr(id->dirs[k].why, "lengths"));
    }
    for (unsigned k = 0; k < id->n_combos; ++k) {
        assert_false(names_e(id->combos[k].params));
        assert_null(strstr(id->combos[k].why, "encoder"));
        assert_null(strstr(id->combos[k].why, "cable"));
    }
}

/* Random joints within +-2 rad (+-1 rad for joints 2 and 3). */
static void random_q(double q[RC_NJ], rc_rng *g)
{
    for (int j = 0; j < RC_NJ; ++j)
        q[j] = (2.0 * rc_rng_u01(g) - 1.0) * (j == 1 || j == 2 ? 1.0 : 2.0);
}

/* Touches on 3 plates (the model's own prediction as value): e out, no cable words. */
static void test_touch_only(void **state)
{
    (void)state;
    rc_model m = nominal();
    const unsigned np0 = m.n_params;
    const rch_sensor_desc *sd = rch_sensor_of_kind(RC_SENSOR_PLANE);
    assert_non_null(sd);
    assert_int_equal(sd->add_effects(&m, 3), 0);
    int tf = -1, nf = -1, df = -1;
    for (unsigned i = 0; i < m.n_effects; ++i) {
        if (m.effects[i].kind == RC_EFF_TOUCH_TIP)
            tf = (int)m.effects[i].first;
        if (m.effects[i].kind == RC_EFF_PLANE_NORMALS)
            nf = (int)m.effects[i].first;
        if (m.effects[i].kind == RC_EFF_PLANE_OFFSETS)
            df = (int)m.effects[i].first;
    }
    assert_true(tf >= 0 && nf >= 0 && df >= 0);
    const double tip[3] = {12.0, -25.0, 160.0};
    const double n[3][3] = {{0, 0, 1}, {-1, 0, 0}, {-0.6, -0.48, 0.64}}, d[3] = {150.0, -500.0, -100.0};
    memcpy(&m.x[tf], tip, sizeof tip);
    for (unsigned k = 0; k < 3; ++k) {
        rc_plane_angles(&m.x[nf + 2 * (int)k], &m.x[nf + 2 * (int)k + 1], n[k]);
        m.x[df + (int)k] = d[k];
    }
    rc_rng g;
    rc_rng_seed(&g, 11);
    rc_sample *s = calloc(NS, sizeof *s);
    assert_non_null(s);
    for (size_t i = 0; i < NS; ++i) {
        random_q(s[i].q_rad, &g);
        s[i].sensor = RC_SENSOR_PLANE;
        s[i].target = (uint8_t)(i % 3);
        assert_int_equal(rc_meas(&s[i].value, NULL, &m, &s[i]), RC_OK);
    }
    rch_ident *id = calloc(1, sizeof *id);
    assert_non_null(id);
    assert_int_equal(rch_ident_compute(id, &m, s, NS), 0);
    assert_int_equal(id->n_params, m.n_params - 3); /* every parameter but e */
    assert_true(id->n_params > np0 - 3);            /* the tip and the plates are in */
    assert_true(id->n_dirs > 0);
    assert_no_cable(id);
    int tip_set = 0; /* the probe tip's sets in the sensor's words, as the cable attachment's */
    for (unsigned k = 0; k < id->n_combos; ++k)
        if (strcmp(id->combos[k].params, "d6 touch_tip.z") == 0) {
            tip_set = 1;
            assert_non_null(strstr(id->combos[k].why, "the touch tip's z"));
        }
    assert_true(tip_set);
    free(id);
    free(s);
}

/* Tracker positions of one target at the flange centre: e out, alpha6 a
 * direction of its own explained in the tracker's words. */
static void test_tracker_only(void **state)
{
    (void)state;
    rc_model m = nominal();
    assert_int_equal(rch_pos_add_effects(&m, 1), 0);
    rc_rng g;
    rc_rng_seed(&g, 5);
    rc_sample *s = calloc(NS, sizeof *s);
    assert_non_null(s);
    for (size_t i = 0; i < NS; i += 3) {
        double q[RC_NJ];
        random_q(q, &g);
        for (unsigned c = 0; c < 3; ++c) {
            memcpy(s[i + c].q_rad, q, sizeof q);
            s[i + c].sensor = (uint8_t)(RC_SENSOR_TRACKER_X + c);
            s[i + c].target = 0;
            assert_int_equal(rc_meas(&s[i + c].value, NULL, &m, &s[i + c]), RC_OK);
        }
    }
    rch_ident *id = calloc(1, sizeof *id);
    assert_non_null(id);
    assert_int_equal(rch_ident_compute(id, &m, s, NS), 0);
    assert_int_equal(id->n_params, m.n_params - 3);
    assert_no_cable(id);
    int alpha6 = 0;
    for (unsigned k = 0; k < id->n_dirs; ++k)
        if (leads(id->dirs[k].combo, "alpha6")) {
            alpha6 = 1;
            assert_non_null(strstr(id->dirs[k].why, "tracker positions cannot see it"));
        }
    assert_true(alpha6);
    free(id);
    free(s);
}

/* Cable lengths (one outlet): e stays in, alpha6 in the cable's words. */
static void test_cable_keeps_e(void **state)
{
    (void)state;
    rc_model m = nominal();
    const double e[3] = {400.0, -300.0, -200.0};
    memcpy(&m.x[RC_P_ENC], e, sizeof e);
    rc_rng g;
    rc_rng_seed(&g, 3);
    rc_sample *s = calloc(NS, sizeof *s);
    assert_non_null(s);
    for (size_t i = 0; i < NS; ++i) {
        random_q(s[i].q_rad, &g);
        s[i].sensor = RC_SENSOR_LENGTH;
        assert_int_equal(rc_meas(&s[i].value, NULL, &m, &s[i]), RC_OK);
    }
    rch_ident *id = calloc(1, sizeof *id);
    assert_non_null(id);
    assert_int_equal(rch_ident_compute(id, &m, s, NS), 0);
    assert_int_equal(id->n_params, m.n_params);
    int alpha6 = 0, e_seen = 0;
    for (unsigned k = 0; k < id->n_dirs; ++k) {
        e_seen |= names_e(id->dirs[k].combo);
        if (leads(id->dirs[k].combo, "alpha6")) {
            alpha6 = 1;
            assert_non_null(strstr(id->dirs[k].why, "cable lengths cannot see it"));
        }
    }
    for (unsigned k = 0; k < id->n_combos; ++k)
        e_seen |= names_e(id->combos[k].params);
    assert_true(alpha6);
    assert_true(e_seen); /* d1 ez, theta1 ex ey: the cable's own gauges */
    free(id);
    free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_touch_only),
        cmocka_unit_test(test_tracker_only),
        cmocka_unit_test(test_cable_keeps_e),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
