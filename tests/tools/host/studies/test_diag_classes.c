/* SPDX-License-Identifier: MIT */
/* rcal diagnose keeps each sensor kind its own class (rch_dg_sensor_class):
 * with cable lengths and plate touches together, and with tracker positions
 * and plate touches together, the sensors table holds one entry per kind
 * with its own rows and label ("cable", "touch", "tracker (3-D)": the
 * tracker's only), and the structure tests run on each kind's rows apart
 * (names prefixed by the kind, the touch's plate ANOVA, the tracker's
 * coordinate ANOVA, no touch test against a place). The data: the nominal
 * IRB120 with a probe and three plates (and a tracker target), its own
 * predictions at random joints written as files, with a little noise. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rc_rand.h"
#include "rch_diagnose.h"
#include "rch_positions.h"
#include "rch_robot.h"
#include "rch_sensors.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define N_TOUCH 150
#define N_OTHER 120
#define DEG (3.14159265358979323846 / 180.0)

static char dir[64];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/rcal_diag_classes_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int first_of(const rc_model *m, unsigned kind)
{
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == kind)
            return (int)m->effects[i].first;
    return -1;
}

/* The truth: the robot file's nominal with a probe and three plates (and, with targets, a tracker frame). */
static rc_model truth(int tracker)
{
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, ROBOT, &d), 0);
    rc_model m = r.model;
    assert_int_equal(rch_sensor_of_kind(RC_SENSOR_PLANE)->add_effects(&m, 3), 0);
    const int tf = first_of(&m, RC_EFF_TOUCH_TIP), nf = first_of(&m, RC_EFF_PLANE_NORMALS),
              df = first_of(&m, RC_EFF_PLANE_OFFSETS);
    const double tip[3] = {12.0, -25.0, 160.0};
    const double n[3][3] = {{0, 0, 1}, {-1, 0, 0}, {-0.6, -0.48, 0.64}}, dist[3] = {150.0, -500.0, -100.0};
    memcpy(&m.x[tf], tip, sizeof tip);
    for (unsigned k = 0; k < 3; ++k) {
        rc_plane_angles(&m.x[nf + 2 * (int)k], &m.x[nf + 2 * (int)k + 1], n[k]);
        m.x[df + (int)k] = dist[k];
    }
    if (tracker) {
        assert_int_equal(rch_pos_add_effects(&m, 1), 0);
        const double frame[6] = {-1500.0, 300.0, -200.0, 0.1, -0.2, 0.3};
        assert_int_equal(rch_pos_set_frame(&m, frame), 0);
    }
    return m;
}

/* Random joints within +-2 rad (+-1 rad for joints 2 and 3), rounded to 0.001 deg as written. */
static void random_q(double q[RC_NJ], rc_rng *g)
{
    for (int j = 0; j < RC_NJ; ++j)
        q[j] = round((2.0 * rc_rng_u01(g) - 1.0) * (j == 1 || j == 2 ? 1.0 : 2.0) / DEG * 1000.0) / 1000.0 * DEG;
}

static void write_q(FILE *f, const double q[RC_NJ])
{
    for (int j = 0; j < RC_NJ; ++j)
        fprintf(f, "%s%.3f", j ? "," : "", q[j] / DEG);
}

/* path <- touches of m: pose,plane,q1..q6,height_mm (the probe's height above its plate, 0.005 mm noise). */
static void write_touches(const char *path, const rc_model *m, rc_rng *g)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "pose,plane,q1,q2,q3,q4,q5,q6,height_mm\n");
    for (unsigned i = 0; i < N_TOUCH;) {
        rc_sample c;
        memset(&c, 0, sizeof c);
        random_q(c.q_rad, g);
        c.sensor = RC_SENSOR_PLANE;
        c.target = (uint8_t)(i % 3);
        double v;
        assert_int_equal(rc_meas(&v, NULL, m, &c), RC_OK);
        if (v < 20.0 || v > 2000.0)
            continue; /* the probe on the plate's outer side, as it comes */
        fprintf(f, "%u,%u,", i, (unsigned)c.target);
        write_q(f, c.q_rad);
        fprintf(f, ",%.4f\n", v + 0.005 * rc_rng_normal(g));
        ++i;
    }
    fclose(f);
}

/* path <- cable lengths of m from its encoder: q1..q6,L. */
static void write_cable(const char *path, const rc_model *m, rc_rng *g)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "q1,q2,q3,q4,q5,q6,L\n");
    for (unsigned i = 0; i < N_OTHER; ++i) {
        rc_sample c;
        memset(&c, 0, sizeof c);
        random_q(c.q_rad, g);
        c.sensor = RC_SENSOR_LENGTH;
        double v;
        assert_int_equal(rc_meas(&v, NULL, m, &c), RC_OK);
        write_q(f, c.q_rad);
        fprintf(f, ",%.3f\n", v + 0.005 * rc_rng_normal(g));
    }
    fclose(f);
}

/* path <- tracker positions of m's target 0: q1..q6,x,y,z,target,pose. */
static void write_positions(const char *path, const rc_model *m, rc_rng *g)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "q1,q2,q3,q4,q5,q6,x,y,z,target,pose\n");
    for (unsigned i = 0; i < N_OTHER / 3; ++i) {
        rc_sample c;
        memset(&c, 0, sizeof c);
        random_q(c.q_rad, g);
        write_q(f, c.q_rad);
        for (unsigned k = 0; k < 3; ++k) {
            double v;
            c.sensor = (uint8_t)(RC_SENSOR_TRACKER_X + k);
            assert_int_equal(rc_meas(&v, NULL, m, &c), RC_OK);
            fprintf(f, ",%.4f", v + 0.005 * rc_rng_normal(g));
        }
        fprintf(f, ",0,%u\n", i);
    }
    fclose(f);
}

static rch_diagnose_cfg config(void)
{
    rch_diagnose_cfg cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.folds = 3;
    cfg.max_steps = 1;
    cfg.max_iter = 40;
    cfg.seed = 7;
    return cfg;
}

/* The sensor of r named name, NULL when none. */
static const rch_diagnose_sensor *sensor(const rch_diagnose_result *r, const char *kind)
{
    const rch_diagnose_sensor *z = NULL;
    for (unsigned k = 0; k < r->n_sensors; ++k)
        if (strcmp(r->sensors[k].kind, kind) == 0) {
            assert_null(z); /* one class per kind */
            z = &r->sensors[k];
        }
    return z;
}

/* Tests of r->before whose name starts with prefix. */
static unsigned tests_of(const rch_diagnose_result *r, const char *prefix)
{
    unsigned c = 0;
    for (unsigned k = 0; k < r->n_tests; ++k)
        c += strncmp(r->before[k].name, prefix, strlen(prefix)) == 0;
    return c;
}

static int has_test(const rch_diagnose_result *r, const char *name)
{
    for (unsigned k = 0; k < r->n_tests; ++k)
        if (strcmp(r->before[k].name, name) == 0)
            return 1;
    return 0;
}

/* The touch's class in r: its rows, no test against a place, its plate ANOVA. */
static void assert_touch_class(const rch_diagnose_result *r)
{
    const rch_diagnose_sensor *t = sensor(r, "touch");
    assert_non_null(t);
    assert_string_equal(t->name, "touch");
    assert_int_equal(t->rows, N_TOUCH);
    assert_true(t->tracker); /* not the cable: no outlet */
    assert_true(tests_of(r, "touch: ") >= 10);
    assert_true(has_test(r, "touch: plane (ANOVA)"));
    assert_false(has_test(r, "touch: distance from the tracker"));
    assert_false(has_test(r, "touch: cable length"));
}

static void test_cable_and_touch(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 21);
    const rc_model m = truth(0);
    char cab[96], tch[96];
    snprintf(cab, sizeof cab, "%s/cab.csv", dir);
    snprintf(tch, sizeof tch, "%s/touch.csv", dir);
    write_cable(cab, &m, &g);
    write_touches(tch, &m, &g);
    const char *data[2] = {cab, tch};
    rch_diagnose_in in;
    memset(&in, 0, sizeof in);
    in.data_paths = data;
    in.n_data = 2;
    in.robot_path = ROBOT;
    const rch_diagnose_cfg cfg = config();
    rch_diagnose_result r;
    rch_diag d;
    memset(&d, 0, sizeof d);
    const int rc = rch_diagnose_inputs(&r, &in, &cfg, &d);
    if (rc != 0)
        print_message("%s\n", d.msg);
    assert_int_equal(rc, 0);
    assert_int_equal(r.n_sensors, 2);
    const rch_diagnose_sensor *c = sensor(&r, "cable");
    assert_non_null(c);
    assert_string_equal(c->name, "cable"); /* one outlet: no "cable outlet 0" beside another sensor */
    assert_int_equal(c->rows, N_OTHER);
    assert_false(c->tracker);
    assert_touch_class(&r);
    assert_true(tests_of(&r, "cable: ") >= 12);
    assert_true(has_test(&r, "cable: cable length"));
    assert_int_equal(tests_of(&r, "cable: ") + tests_of(&r, "touch: "), r.n_tests);
    rch_diagnose_free(&r);
    unlink(cab);
    unlink(tch);
}

static void test_tracker_and_touch(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 22);
    const rc_model m = truth(1);
    char pos[96], tch[96];
    snprintf(pos, sizeof pos, "%s/pos.csv", dir);
    snprintf(tch, sizeof tch, "%s/touch.csv", dir);
    write_positions(pos, &m, &g);
    write_touches(tch, &m, &g);
    const char *data[1] = {tch}, *positions[1] = {pos};
    rch_diagnose_in in;
    memset(&in, 0, sizeof in);
    in.data_paths = data;
    in.n_data = 1;
    in.positions_paths = positions;
    in.n_positions = 1;
    in.robot_path = ROBOT;
    const rch_diagnose_cfg cfg = config();
    rch_diagnose_result r;
    rch_diag d;
    memset(&d, 0, sizeof d);
    const int rc = rch_diagnose_inputs(&r, &in, &cfg, &d);
    if (rc != 0)
        print_message("%s\n", d.msg);
    assert_int_equal(rc, 0);
    assert_int_equal(r.n_sensors, 2);
    const rch_diagnose_sensor *t = sensor(&r, "tracker");
    assert_non_null(t);
    assert_string_equal(t->name, "tracker");
    assert_int_equal(t->rows, N_OTHER / 3); /* position rows */
    assert_touch_class(&r);
    assert_true(has_test(&r, "tracker: coordinate x, y, z (ANOVA)"));
    assert_true(has_test(&r, "tracker: distance from the tracker"));
    assert_int_equal(tests_of(&r, "tracker: ") + tests_of(&r, "touch: "), r.n_tests);
    /* the report: the 3-D label on the tracker's line only */
    char txt[128];
    snprintf(txt, sizeof txt, "%s/out.txt", dir);
    FILE *f = fopen(txt, "w+");
    assert_non_null(f);
    rch_diagnose_print(f, &r);
    rewind(f);
    char line[512];
    int tracker3d = 0, touch3d = 0;
    while (fgets(line, sizeof line, f)) {
        tracker3d |= strncmp(line, "  tracker (3-D) ", 16) == 0;
        touch3d |= strncmp(line, "  touch (3-D)", 13) == 0;
    }
    fclose(f);
    unlink(txt);
    assert_true(tracker3d);
    assert_false(touch3d);
    rch_diagnose_free(&r);
    unlink(pos);
    unlink(tch);
}

static int teardown(void **state)
{
    (void)state;
    rmdir(dir);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cable_and_touch),
        cmocka_unit_test(test_tracker_and_touch),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
