/* SPDX-License-Identifier: MIT */
/* Data and model files: bad input is refused with file, line and column. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rch_data.h"
#include "rch_json.h"
#include "rch_robot.h"

static const char *HDR = "x,y,z,q1,q2,q3,q4,q5,q6,L\n";

static int parse(rch_data *d, rch_diag *dg, const char *body)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s%s", HDR, body);
    return rch_data_parse(d, buf, strlen(buf), "t.csv", 0, dg);
}

static void test_good(void **state)
{
    (void)state;
    rch_data d;
    rch_diag dg;
    assert_int_equal(parse(&d, &dg, "1,2,3,10,20,30,40,50,60,509.19\r\n\n# comment\n1,2,3,0,0,0,0,0,0,300\n"), 0);
    assert_int_equal(d.n, 2);
    assert_true(fabs(d.s[0].q_rad[0] - 10.0 * 3.14159265358979 / 180.0) < 1e-9);
    assert_true(fabs(d.s[0].value - 509.19) < 1e-12);
    assert_int_equal(d.line[1], 5);
    assert_non_null(d.xyz);
    assert_true(d.s[0].t == 0.0 && d.s[1].t == 1.0);
    rch_data_free(&d);
}

static void expect_error(const char *body, unsigned line, unsigned col, const char *needle)
{
    rch_data d;
    rch_diag dg;
    memset(&dg, 0, sizeof dg);
    assert_int_equal(parse(&d, &dg, body), -1);
    assert_null(d.s);
    assert_int_equal(dg.line, line);
    assert_int_equal(dg.col, col);
    if (strstr(dg.msg, needle) == NULL) {
        print_error("message '%s' lacks '%s'\n", dg.msg, needle);
        fail();
    }
    assert_string_equal(dg.file, "t.csv");
}

static void test_errors(void **state)
{
    (void)state;
    expect_error("1,2,3,10,20,abc,40,50,60,509\n", 2, 13, "'q3': 'abc' is not a number");
    expect_error("1,2,3,10,20,30,40,50,60,nan\n", 2, 25, "not finite");
    expect_error("1,2,3,10,20,30,40,50,60,inf\n", 2, 25, "not finite");
    expect_error("1,2,3,10,20,30,40,50,60\n", 2, 24, "missing field 'L'");
    expect_error("1,2,3,10,20,30,40,50,60,-5\n", 2, 25, "not a cable length");
    expect_error("1,2,3,1000,20,30,40,50,60,500\n", 2, 7, "outside -720..720");
    expect_error("1,2,3,10,20,30,40,50,60,\n", 2, 25, "is not a number");
    expect_error("1,2,3,10,20,30,40,50,60,500\n1,2,3,10,20,30,40,50,60,5e9999\n", 3, 25, "not a number");
}

static void test_header(void **state)
{
    (void)state;
    rch_data d;
    rch_diag dg;
    const char *t = "q1,q2,q3,q4,q5,q6\n1,2,3,4,5,6\n";
    assert_int_equal(rch_data_parse(&d, t, strlen(t), "p.csv", 0, &dg), -1);
    assert_non_null(strstr(dg.msg, "no 'L' column"));
    assert_int_equal(rch_data_parse(&d, t, strlen(t), "p.csv", RCH_DATA_NO_LEN, &dg), 0);
    assert_int_equal(d.n, 1);
    rch_data_free(&d);
    const char *dup = "q1,q2,q3,q4,q5,q6,L,q1\n";
    assert_int_equal(rch_data_parse(&d, dup, strlen(dup), "p.csv", 0, &dg), -1);
    assert_int_equal(dg.col, 21);
    assert_int_equal(rch_data_parse(&d, "", 0, "e.csv", 0, &dg), -1);
    assert_non_null(strstr(dg.msg, "empty"));
}

static void test_robot_json(void **state)
{
    (void)state;
    rch_robot r;
    rch_diag dg;
    assert_int_equal(rch_robot_load(&r, RCAL_SOURCE_DIR "/data/irb120.json", &dg), 0);
    assert_true(fabs(r.model.x[RC_P_D(0)] - 290.0) < 1e-12);
    assert_true(fabs(r.model.x[RC_P_THETA(1)] + 3.14159265358979 / 2) < 1e-12);
    assert_int_equal(r.has_encoder, 0);
    const char *bad = "{\"dh\": [\n {\"a_mm\": 0, \"d_mm\": \"x\", \"alpha_deg\": 0, \"theta_deg\": 0}]}";
    assert_int_equal(rch_robot_parse(&r, bad, strlen(bad), "m.json", &dg), -1);
    assert_int_equal(dg.line, 1);
    const char *bad2 = "{\"dh\": [1,2,3,4,5,6],\n  \"dh\": 3}";
    assert_int_equal(rch_robot_parse(&r, bad2, strlen(bad2), "m.json", &dg), -1);
    assert_int_equal(dg.line, 2);
    assert_int_equal(dg.col, 3);
    assert_non_null(strstr(dg.msg, "duplicate key"));
    const char *trunc = "{\"dh\": [";
    assert_int_equal(rch_robot_parse(&r, trunc, strlen(trunc), "m.json", &dg), -1);
}

static void info_k(rch_jw *w, const void *ctx)
{
    rch_jw_str(w, "data", (const char *)ctx);
    rch_jw_int(w, "k", 1);
}

/* write -> read round trip of a calibrated model with effects; a name and a
 * data path with quotes, backslashes and control characters stay valid JSON */
static void test_model_round_trip(void **state)
{
    (void)state;
    rch_robot r, back;
    rch_diag dg;
    assert_int_equal(rch_robot_load(&r, RCAL_SOURCE_DIR "/data/irb120.json", &dg), 0);
    rc_model m = r.model;
    m.x[RC_P_A(2)] += 0.123;
    m.x[RC_P_ENC] = 240.5;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 2, 0), RC_OK);
    m.x[m.n_params - 1] = 1e-4;
    char buf[32768];
    FILE *f = fmemopen(buf, sizeof buf, "w");
    assert_non_null(f);
    const char *path = "C:\\data\\\"q\".csv\t\x01";
    const rch_robot_info info = {info_k, path, NULL, NULL, NULL, NULL, 0, NULL};
    assert_int_equal(rch_robot_write(f, "cal \"x\" \\y", &m, &r.nominal, &info), 0);
    fclose(f);
    assert_int_equal(rch_robot_parse(&back, buf, strlen(buf), "rt.json", &dg), 0);
    assert_int_equal(back.model.n_params, m.n_params);
    for (unsigned k = 0; k < m.n_params; ++k)
        assert_true(fabs(back.model.x[k] - m.x[k]) < 1e-9 * (1.0 + fabs(m.x[k])));
    assert_true(back.has_nominal && back.has_encoder);
    assert_string_equal(back.name, "cal \"x\" \\y");
    /* the calibration member is JSON the project's own reader accepts, with the path intact */
    rch_json *root = rch_json_parse(buf, strlen(buf), "rt.json", &dg);
    assert_non_null(root);
    const rch_json *cal = rch_json_get(root, "calibration");
    assert_non_null(cal);
    const rch_json *data = rch_json_get(cal, "data");
    assert_non_null(data);
    assert_int_equal(data->type, RCH_JSTR);
    assert_string_equal(data->str, path);
    rch_json_free(root);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good),       cmocka_unit_test(test_errors),          cmocka_unit_test(test_header),
        cmocka_unit_test(test_robot_json), cmocka_unit_test(test_model_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
