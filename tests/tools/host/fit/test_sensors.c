/* SPDX-License-Identifier: MIT */
/* Sensors read from data files (rch_sensors.h), through the touch sensor:
 * a file is the sensor's by its label column; rows become samples of its
 * kind with the label, the optional height and sigma's weight; wrong rows
 * refused at file:line:column; a plate with too few touches refused by
 * name; the closed-form start recovers a known probe and plates from
 * touches the model itself predicts (the accuracy study with an independent
 * generator is tests/system/sim/touch_study.py). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_data.h"
#include "rch_robot.h"
#include "rch_sensors.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"

static const char *const HDR = "pose,plane,q1,q2,q3,q4,q5,q6,height_mm,sigma_mm\n";

static void test_file_by_header(void **state)
{
    (void)state;
    const char *cable = "q1,q2,q3,q4,q5,q6,L\n0,0,0,0,30,0,800\n";
    const char *touch = "# a comment first\nPose, \"Plane\",q1,q2,q3,q4,q5,q6\n";
    assert_null(rch_sensor_for_file(cable, strlen(cable)));
    const rch_sensor_desc *sd = rch_sensor_for_file(touch, strlen(touch));
    assert_non_null(sd);
    assert_int_equal(sd->kind, RC_SENSOR_PLANE);
    assert_ptr_equal(rch_sensor_of_kind(RC_SENSOR_PLANE), sd);
    assert_null(rch_sensor_of_kind(RC_SENSOR_LENGTH));
    assert_null(rch_sensor_of_kind(RC_SENSOR_TRACKER_X));
}

static void test_rows(void **state)
{
    (void)state;
    char text[512];
    snprintf(text, sizeof text, "%s0,0,10,20,-30,40,50,60,0,0.01\n1,2,11,21,-31,41,51,61,50.000,0.02\n"
                                "2,1,12,22,-32,42,52,62,0,0.04\n", HDR);
    const rch_sensor_desc *sd = rch_sensor_for_file(text, strlen(text));
    rch_data d;
    rch_diag dg;
    assert_int_equal(rch_sensor_parse(&d, sd, text, strlen(text), "t.csv", NULL, &dg), 0);
    assert_int_equal(d.n, 3);
    assert_int_equal(d.s[1].sensor, RC_SENSOR_PLANE);
    assert_int_equal(d.s[1].target, 2);
    assert_true(d.s[1].value == 50.0 && d.s[0].value == 0.0);
    assert_true(fabs(d.s[2].q_rad[3] - 42.0 * 3.14159265358979323846 / 180.0) < 1e-15);
    assert_true(fabs(d.s[1].weight - 1.0) < 1e-15 && fabs(d.s[0].weight - 2.0) < 1e-15 &&
                fabs(d.s[2].weight - 0.5) < 1e-15); /* the median sigma (0.02) over each row's */
    assert_int_equal(d.line[2], 4);
    rch_data_free(&d);
    unsigned ns = 0;
    rc_sample s[3];
    memset(s, 0, sizeof s);
    s[1].sensor = RC_SENSOR_PLANE;
    ns = (unsigned)rch_sensors_count(s, 3);
    assert_int_equal(ns, 1);
}

/* A wrong row: refused at its line and column, with the column's name. */
static void refused(const char *rows, unsigned line, const char *col_text, const char *needle)
{
    char text[512];
    snprintf(text, sizeof text, "%s%s", HDR, rows);
    const rch_sensor_desc *sd = rch_sensor_for_file(text, strlen(text));
    rch_data d;
    rch_diag dg;
    memset(&dg, 0, sizeof dg);
    assert_int_equal(rch_sensor_parse(&d, sd, text, strlen(text), "t.csv", NULL, &dg), -1);
    const char *p = text;
    for (unsigned l = 1; l < line; ++l)
        p = strchr(p, '\n') + 1;
    const unsigned col = (unsigned)(strstr(p, col_text) - p) + 1;
    if (dg.line != line || dg.col != col || !strstr(dg.msg, needle))
        fail_msg("%u:%u: %s (expected %u:%u, '%s')", dg.line, dg.col, dg.msg, line, col, needle);
}

static void test_bad_rows(void **state)
{
    (void)state;
    refused("0,0,10,20,-30,40,50,60,0,0.01\n1,16,11,21,-31,41,51,61,0,0.01\n", 3, "16", "field 'plane'");
    refused("0,1.5,10,20,-30,40,50,60,0,0.01\n", 2, "1.5", "plane number");
    refused("0,0,10,20,-30,40,50,60,20000,0.01\n", 2, "20000", "field 'height_mm'");
    refused("0,0,10,20,-30,40,50,60,0,0\n", 2, "0\n", "sigma_mm");
    refused("0,0,10,20,x,40,50,60,0,0.01\n", 2, "x", "field 'q3'");
}

static rc_model nominal_touch(unsigned planes)
{
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, ROBOT, &d), 0);
    rc_model m = r.model;
    const rch_sensor_desc *sd = rch_sensor_of_kind(RC_SENSOR_PLANE);
    assert_int_equal(sd->add_effects(&m, planes), 0);
    return m;
}

static int first_of(const rc_model *m, unsigned kind)
{
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == kind)
            return m->effects[i].first;
    return -1;
}

/* Touches the true model predicts (heights: each row's own), from poses
 * with the flange above the plates: the start recovers tip and plates. */
static void test_start_recovers(void **state)
{
    (void)state;
    rc_model truth = nominal_touch(3);
    const int tf = first_of(&truth, RC_EFF_TOUCH_TIP), nf = first_of(&truth, RC_EFF_PLANE_NORMALS),
              df = first_of(&truth, RC_EFF_PLANE_OFFSETS);
    const double tip[3] = {12.0, -25.0, 160.0};
    const double n[3][3] = {{0, 0, 1}, {-1, 0, 0}, {-0.6, -0.48, 0.64}}, d[3] = {150.0, -500.0, -100.0};
    memcpy(&truth.x[tf], tip, sizeof tip);
    for (unsigned k = 0; k < 3; ++k) {
        rc_plane_angles(&truth.x[nf + 2 * k], &truth.x[nf + 2 * k + 1], n[k]);
        truth.x[df + k] = d[k];
    }
    rc_rng g;
    rc_rng_seed(&g, 7);
    rc_sample s[240];
    size_t ns = 0;
    while (ns < 240) {
        rc_sample c;
        memset(&c, 0, sizeof c);
        for (int j = 0; j < RC_NJ; ++j)
            c.q_rad[j] = (2.0 * rc_rng_u01(&g) - 1.0) * (j == 1 || j == 2 ? 1.0 : 2.0);
        c.sensor = RC_SENSOR_PLANE;
        c.target = (uint8_t)(ns % 3);
        double o[3], R[9], v;
        rc_fk(o, R, &truth, c.q_rad);
        if (n[c.target][0] * o[0] + n[c.target][1] * o[1] + n[c.target][2] * o[2] - d[c.target] < 50.0)
            continue; /* the flange on the plate's outer side, as a probe comes */
        assert_int_equal(rc_meas(&v, NULL, &truth, &c), RC_OK);
        c.value = v; /* the probe's height above the plate where it was */
        s[ns++] = c;
    }
    rc_model m = nominal_touch(3);
    rch_diag dg;
    const rch_sensor_desc *sd = rch_sensor_of_kind(RC_SENSOR_PLANE);
    assert_int_equal(sd->start(&m, s, ns, &dg), 0);
    for (unsigned j = 0; j < 3; ++j)
        assert_true(fabs(m.x[tf + j] - tip[j]) < 1e-6);
    for (unsigned k = 0; k < 3; ++k) {
        double nk[3];
        rc_plane_normal(nk, NULL, NULL, m.x[nf + 2 * k], m.x[nf + 2 * k + 1]);
        for (unsigned r = 0; r < 3; ++r)
            assert_true(fabs(nk[r] - n[k][r]) < 1e-9);
        assert_true(fabs(m.x[df + k] - d[k]) < 1e-6);
    }
    for (size_t i = 0; i < ns; ++i) /* plate 1 with two touches left: refused by name */
        if (s[i].target == 1 && i > 4) /* touches 1 and 4 kept */
            s[i].target = 0;
    m = nominal_touch(3);
    memset(&dg, 0, sizeof dg);
    assert_int_equal(sd->start(&m, s, ns, &dg), -1);
    assert_non_null(strstr(dg.msg, "plane 1"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_file_by_header),
        cmocka_unit_test(test_rows),
        cmocka_unit_test(test_bad_rows),
        cmocka_unit_test(test_start_recovers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
