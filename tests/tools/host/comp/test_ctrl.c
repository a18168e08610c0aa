/* SPDX-License-Identifier: MIT */
/* test_ctrl.c - the robot file's controller conventions (rch_ctrl.h) and
 * the URDF reader's refusals (rch_urdf_robot.h):
 *  - the Fanuc LR Mate file: the pendant's J3 is the forearm's angle from the
 *    horizon (model q3 = -J3 - J2, computed here from the FK: the forearm's
 *    direction), to the model and back exact;
 *  - a KUKA-style member (A1, A4, A6 reversed, A2 -90 and A3 +90 at the
 *    model's zero) read, applied, written back and read again the same;
 *  - bad members refused with file:line:col;
 *  - compensate's joint CSV through the map: a controller value the model's
 *    limits accept only once mapped is compensated, and an identity
 *    compensation gives the controller's values back;
 *  - a URDF that is not one chain of six revolute joints refused with why. */
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

#include "rch_robot.h"
#include "rch_urdf_robot.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static void test_fanuc_j3(void **state)
{
    (void)state;
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, RCAL_SOURCE_DIR "/data/lrmate200id.json", &d), 0);
    assert_true(r.ctrl.present && !r.ctrl.identity_joints);
    for (int n = 0; n < 50; ++n) {
        const double j2 = (-60 + 2.5 * n) * DEG, j3 = (40 - 1.7 * n) * DEG;
        const double c[6] = {0.1, j2, j3, 0.2, 0.3, 0.4};
        double q[6], back[6];
        rch_ctrl_to_model(q, &r.ctrl, c);
        /* the forearm (axis 3 -> wrist centre) rises at J3 above the horizon */
        double p3[3], R[9], pw[3];
        rc_model m = r.nominal;
        (void)R;
        /* frames from the DH rows: axis 3's origin and the wrist centre */
        double T[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        for (int i = 0; i < 4; ++i) {
            const double th = q[i] + m.x[RC_P_THETA(i)], a = m.x[RC_P_A(i)], dd = m.x[RC_P_D(i)],
                         al = m.x[RC_P_ALPHA(i)];
            const double A[16] = {cos(th), -sin(th) * cos(al), sin(th) * sin(al), a * cos(th),
                                  sin(th), cos(th) * cos(al), -cos(th) * sin(al), a * sin(th),
                                  0, sin(al), cos(al), dd, 0, 0, 0, 1};
            double U[16];
            for (int x = 0; x < 4; ++x)
                for (int y = 0; y < 4; ++y) {
                    U[4 * x + y] = 0;
                    for (int k = 0; k < 4; ++k)
                        U[4 * x + y] += T[4 * x + k] * A[4 * k + y];
                }
            memcpy(T, U, sizeof T);
            if (i == 2)
                for (int k = 0; k < 3; ++k)
                    p3[k] = T[4 * k + 3] - m.x[RC_P_A(2)] * T[4 * k]; /* on axis 3, before the a3 offset */
        }
        for (int k = 0; k < 3; ++k)
            pw[k] = T[4 * k + 3];
        /* forearm direction (axis 3 to the wrist centre) without the a3 offset: the x3-z3 plane's z3 part */
        const double dx = pw[0] - p3[0], dy = pw[1] - p3[1], dz = pw[2] - p3[2];
        const double h = sqrt(dx * dx + dy * dy);
        /* the line from axis 3 along z3 (d4): its elevation; a3 is perpendicular to it */
        const double a3 = m.x[RC_P_A(2)], d4 = m.x[RC_P_D(3)];
        const double elev = atan2(dz, h) - atan2(a3, d4);
        assert_true(fabs(remainder(elev - j3, 2 * PI)) < 1e-9);
        rch_ctrl_from_model(back, &r.ctrl, q);
        for (int i = 0; i < 6; ++i)
            assert_true(fabs(back[i] - c[i]) < 1e-12);
    }
}

static const char kuka[] =
    "{\"format\": \"rcal-model/1\", \"name\": \"kuka-like\", \"dh\": ["
    "{\"a_mm\": 25, \"d_mm\": 400, \"alpha_deg\": -90, \"theta_deg\": 0},"
    "{\"a_mm\": 455, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": -90},"
    "{\"a_mm\": 35, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0},"
    "{\"a_mm\": 0, \"d_mm\": 420, \"alpha_deg\": 90, \"theta_deg\": 0},"
    "{\"a_mm\": 0, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0},"
    "{\"a_mm\": 0, \"d_mm\": 80, \"alpha_deg\": 0, \"theta_deg\": 0}],"
    "\"controller\": {\"joint_sign\": [-1, 1, 1, -1, 1, -1], \"joint_zero_deg\": [0, -90, 90, 0, 0, 0],"
    " \"flange_rpy_deg\": [0, 90, 0], \"base_xyz_mm\": [0, 0, 100]}}";

static void test_kuka_member(void **state)
{
    (void)state;
    rch_robot r, r2;
    rch_diag d;
    assert_int_equal(rch_robot_parse(&r, kuka, strlen(kuka), "kuka.json", &d), 0);
    /* KUKA's home A1..A6 = 0, -90, 90, 0, 0, 0 is the model's zero */
    const double home[6] = {0, -90 * DEG, 90 * DEG, 0, 0, 0};
    double q[6];
    rch_ctrl_to_model(q, &r.ctrl, home);
    for (int i = 0; i < 6; ++i)
        assert_true(fabs(q[i]) < 1e-15);
    const double c[6] = {10 * DEG, -80 * DEG, 100 * DEG, 5 * DEG, 6 * DEG, 7 * DEG};
    rch_ctrl_to_model(q, &r.ctrl, c);
    assert_true(fabs(q[0] + 10 * DEG) < 1e-15 && fabs(q[1] - 10 * DEG) < 1e-15 && fabs(q[2] - 10 * DEG) < 1e-15);
    assert_true(fabs(q[3] + 5 * DEG) < 1e-15 && fabs(q[5] + 7 * DEG) < 1e-15);
    /* the flange and base: the controller's flange pose is B T F */
    double p[3], R[9], p0[3], R0[9];
    rch_ctrl_fk(p, R, &r.ctrl, &r.model, q);
    rc_fk(p0, R0, &r.model, q);
    assert_true(fabs(p[2] - p0[2] - 100) < 1e-9);
    /* F = Ry(90): the flange's x is the DH frame's -z... its z the DH frame's x */
    for (int k = 0; k < 3; ++k)
        assert_true(fabs(R[3 * k + 2] - R0[3 * k]) < 1e-12);
    /* written back and read again */
    char path[] = "/tmp/rcal_ctrl_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    rch_robot_info info = {0};
    info.ctrl = &r.ctrl;
    assert_int_equal(rch_robot_write(f, r.name, &r.model, &r.nominal, &info), 0);
    fclose(f);
    assert_int_equal(rch_robot_load(&r2, path, &d), 0);
    unlink(path);
    for (int i = 0; i < 6; ++i) {
        assert_true(r2.ctrl.sign[i] == r.ctrl.sign[i]);
        assert_true(fabs(r2.ctrl.zero_rad[i] - r.ctrl.zero_rad[i]) < 1e-15);
    }
    for (int k = 0; k < 9; ++k)
        assert_true(fabs(r2.ctrl.flange_R[k] - r.ctrl.flange_R[k]) < 1e-15);
    assert_true(r2.ctrl.has_base && fabs(r2.ctrl.base_mm[2] - 100) < 1e-15);
}

static void expect_bad(const char *from, const char *to, const char *needle)
{
    char text[4096], msg[800];
    const char *at = strstr(kuka, from);
    assert_non_null(at);
    snprintf(text, sizeof text, "%.*s%s%s", (int)(at - kuka), kuka, to, at + strlen(from));
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_parse(&r, text, strlen(text), "bad.json", &d), -1);
    rch_diag_str(&d, msg, sizeof msg);
    if (!strstr(msg, needle) || !strstr(msg, "bad.json:1:"))
        fail_msg("\"%s\" lacks \"%s\" or the place", msg, needle);
}

static void test_bad_member(void **state)
{
    (void)state;
    expect_bad("[-1, 1, 1, -1, 1, -1]", "[-1, 1, 2, -1, 1, -1]", "must be 1 or -1");
    expect_bad("[-1, 1, 1, -1, 1, -1]", "[-1, 1, 1]", "array of 6 numbers");
    expect_bad("\"joint_zero_deg\"", "\"joint_zeros\"", "unknown member \"joint_zeros\"");
    expect_bad("[0, -90, 90, 0, 0, 0]", "[0, -900, 90, 0, 0, 0]", "beyond one turn");
    expect_bad("\"flange_rpy_deg\": [0, 90, 0]", "\"flange_rpy_deg\": [0, \"x\", 0]", "finite number");
}

/* compensate's joint CSV: the controller's values in and out */
static void test_comp_csv(void **state)
{
    (void)state;
    char dir[] = "/tmp/rcal_ctrl_comp_XXXXXX", cmd[2048], path[256];
    assert_non_null(mkdtemp(dir));
    /* J2 = 0, J3 = 150 (pendant): model q3 = -150 deg, inside [-215, 135]; the raw 150 is outside */
    snprintf(path, sizeof path, "%s/in.csv", dir);
    FILE *f = fopen(path, "w");
    fprintf(f, "q1,q2,q3,q4,q5,q6\n10,0,150,0,30,0\n0,20,-30,10,-40,5\n");
    fclose(f);
    snprintf(cmd, sizeof cmd, "%s compensate --model %s/data/lrmate200id.json --in %s/in.csv --out %s/out.csv "
             "2> %s/err.txt", RCAL_BINARY_DIR "/tools/rcal", RCAL_SOURCE_DIR, dir, dir, dir);
    const int st = system(cmd);
    snprintf(path, sizeof path, "%s/err.txt", dir);
    char err[4096] = "";
    f = fopen(path, "r");
    if (f) {
        err[fread(err, 1, sizeof err - 1, f)] = '\0';
        fclose(f);
    }
    if (st != 0)
        fail_msg("rcal compensate: %s", err);
    snprintf(path, sizeof path, "%s/out.csv", dir);
    f = fopen(path, "r");
    assert_non_null(f);
    char line[256];
    assert_non_null(fgets(line, sizeof line, f));
    double v[6];
    assert_non_null(fgets(line, sizeof line, f));
    assert_int_equal(sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]), 6);
    const double want[6] = {10, 0, 150, 0, 30, 0};
    for (int i = 0; i < 6; ++i) /* the model is its own nominal: no correction, the controller's numbers back */
        assert_true(fabs(v[i] - want[i]) < 1e-6);
    fclose(f);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

static void expect_urdf_refused(const char *urdf, const char *needle)
{
    rch_robot r;
    rch_diag d;
    char msg[800];
    assert_int_equal(rch_urdf_robot_parse(&r, urdf, strlen(urdf), "x.urdf", &d), -1);
    rch_diag_str(&d, msg, sizeof msg);
    if (!strstr(msg, needle))
        fail_msg("\"%s\" lacks \"%s\"", msg, needle);
}

#define J(n, p, c, t) "<joint name=\"" n "\" type=\"" t "\"><parent link=\"" p "\"/><child link=\"" c "\"/>" \
                      "<origin xyz=\"0 0 0.1\"/><axis xyz=\"0 1 0\"/></joint>"

static void test_urdf_refused(void **state)
{
    (void)state;
    expect_urdf_refused("<robot name=\"r\">" J("j1", "b", "l1", "revolute") J("j2", "l1", "l2", "revolute")
                        J("j3", "l2", "l3", "prismatic") J("j4", "l3", "l4", "revolute") J("j5", "l4", "l5", "revolute")
                        J("j6", "l5", "l6", "revolute") "</robot>", "prismatic");
    expect_urdf_refused("<robot name=\"r\">" J("j1", "b", "l1", "revolute") J("j2", "l1", "l2", "revolute")
                        J("j3", "l2", "l3", "revolute") J("j4", "l3", "l4", "revolute") J("j5", "l4", "l5", "revolute")
                        "</robot>", "5 revolute");
    expect_urdf_refused("<robot name=\"r\">" J("j1", "b", "l1", "revolute") J("j2", "l1", "l2", "revolute")
                        J("j3", "l2", "l3", "revolute") J("j4", "l3", "l4", "revolute") J("j5", "l4", "l5", "revolute")
                        J("j6", "l4", "l6", "revolute") "</robot>", "serial chain");
    expect_urdf_refused("<robot name=\"r\"><joint name=\"j1\" type=\"revolute\"></robot>", "not well-formed XML");
    expect_urdf_refused("<robot name=\"r\"><joint name=\"j1\" type=\"revolute\"><origin xyz=\"1 2\"/></joint></robot>",
                        "not three numbers");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fanuc_j3),  cmocka_unit_test(test_kuka_member),  cmocka_unit_test(test_bad_member),
        cmocka_unit_test(test_comp_csv), cmocka_unit_test(test_urdf_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
