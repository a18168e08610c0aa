/* SPDX-License-Identifier: MIT */
/* test_diag_effects.c - the length-side effects of issue 14 in the core model
 * (cable_sag, length_nonlinearity): values against formulas written here
 * (the sag against a real catenary's arc length), the analytic Jacobian
 * against central differences, the model file round trip, `--effects`
 * parsing, and that they never move the flange (rc_fk, rc_kin). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_kin.h"
#include "rc_model.h"
#include "rch_calib_effects.h"
#include "rch_robot.h"

#define DEGR (3.14159265358979323846 / 180.0)

static void irb(rc_model *m)
{
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    const double enc[3] = {420.0, -380.0, 60.0};
    double dh[6][4];
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            dh[i][k] = r.nominal.x[4 * i + k];
    assert_int_equal(rc_model_init(m, (const double(*)[4])dh, enc), RC_OK);
}

static void pose(rc_sample *s, unsigned k)
{
    memset(s, 0, sizeof *s);
    for (unsigned j = 0; j < 6; ++j)
        s->q_rad[j] = (25.0 * sin(1.3 * k + j) + 5.0 * j) * DEGR;
}

/* Arc length of a catenary through two points a horizontal distance h and
 * a height v apart, horizontal tension H, weight w per length:
 * S^2 = v^2 + (2 H / w sinh(w h / 2 H))^2. */
static double catenary_arc(double h, double v, double H, double w)
{
    const double a = H / w, s = 2.0 * a * sinh(h / (2.0 * a));
    return sqrt(v * v + s * s);
}

static void test_sag_matches_catenary(void **state)
{
    (void)state;
    rc_model m;
    irb(&m);
    rc_model base = m;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_CABLE_SAG, 0, 0), RC_OK);
    assert_string_equal(rc_effect_name(RC_EFF_CABLE_SAG), "cable_sag");
    /* a 1.5 g/m cable at 4 N: w = 0.0147 N/m, the parameter in mm per m^3 */
    const double w = 1.5e-3 * 9.81, T = 4.0;
    m.x[m.effects[0].first] = 1000.0 * w * w / (24.0 * T * T);
    for (unsigned k = 0; k < 20; ++k) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        double l, l0, p[3];
        pose(&s, k);
        assert_int_equal(rc_meas(&l, NULL, &m, &s), RC_OK);
        assert_int_equal(rc_meas(&l0, NULL, &base, &s), RC_OK);
        rc_fk(p, NULL, &base, s.q_rad);
        const double dx = (p[0] - m.x[RC_P_ENC]) * 1e-3, dy = (p[1] - m.x[RC_P_ENC + 1]) * 1e-3,
                     dz = (p[2] - m.x[RC_P_ENC + 2]) * 1e-3;
        const double h = sqrt(dx * dx + dy * dy), L = sqrt(h * h + dz * dz);
        /* the tension along the chord T has the horizontal component T h / L */
        const double sag_mm = (catenary_arc(h, dz, T * h / L, w) - L) * 1e3;
        assert_true(sag_mm > 0.0);
        assert_true(fabs((l - l0) - sag_mm) < 0.02 * sag_mm + 1e-9);
    }
}

static void test_nonlinearity_value(void **state)
{
    (void)state;
    rc_model m;
    irb(&m);
    rc_model base = m;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_NONLIN, 0, 0), RC_OK);
    assert_int_equal(m.effects[0].count, 2);
    m.x[m.effects[0].first] = 2.0;      /* mm per m^2 */
    m.x[m.effects[0].first + 1] = -3.0; /* mm per m^3 */
    char name[48];
    assert_string_equal(rc_param_name(name, sizeof name, &m, m.effects[0].first + 1u), "length_nonlinearity.n3");
    for (unsigned k = 0; k < 10; ++k) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        double l, l0;
        pose(&s, k);
        assert_int_equal(rc_meas(&l, NULL, &m, &s), RC_OK);
        assert_int_equal(rc_meas(&l0, NULL, &base, &s), RC_OK);
        const double v = l0 / 1000.0 - 0.5; /* the documented centre, 0.5 m */
        assert_true(fabs((l - l0) - (2.0 * v * v - 3.0 * v * v * v)) < 1e-9);
    }
}

static void test_periodic_value(void **state)
{
    (void)state;
    rc_model m;
    irb(&m);
    rc_model base = m;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_PERIODIC, 0, 0), RC_OK);
    const unsigned f = m.effects[0].first;
    m.x[f] = 0.08;
    m.x[f + 1] = -0.03;
    m.x[f + 2] = 140.0; /* a drum of 140 mm circumference */
    char name[48];
    assert_string_equal(rc_param_name(name, sizeof name, &m, f + 2u), "length_periodic.period");
    for (unsigned k = 0; k < 10; ++k) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        double l, l0;
        pose(&s, k);
        assert_int_equal(rc_meas(&l, NULL, &m, &s), RC_OK);
        assert_int_equal(rc_meas(&l0, NULL, &base, &s), RC_OK);
        const double turn = l0 / 140.0 * 2.0 * 3.14159265358979323846;
        assert_true(fabs((l - l0) - (0.08 * sin(turn) - 0.03 * cos(turn))) < 1e-9);
    }
    m.x[f + 2] = 0.0; /* no period: no effect, never a division by zero */
    rc_sample s;
    memset(&s, 0, sizeof s);
    double l, l0, jac[RC_MAX_PARAMS];
    pose(&s, 1);
    assert_int_equal(rc_meas(&l, jac, &m, &s), RC_OK);
    assert_int_equal(rc_meas(&l0, NULL, &base, &s), RC_OK);
    assert_true(l == l0 && jac[f] == 0.0 && jac[f + 2] == 0.0);
}

/* Every column of the analytic Jacobian against a central difference, with
 * sag, nonlinearity, periodic, scale and a tool offset together (the chain
 * rule through the chord). */
static void test_jacobian(void **state)
{
    (void)state;
    rc_model m;
    irb(&m);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_SCALE, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_CABLE_SAG, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_NONLIN, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_PERIODIC, 0, 0), RC_OK);
    const double vals[] = {12.0, -7.0, 30.0, 2e-3, 40.0, 25.0, -60.0, 0.3, -0.2, 137.0};
    for (unsigned k = 0; k < 10; ++k)
        m.x[RC_N_BASE + k] = vals[k];
    for (unsigned k = 0; k < 8; ++k) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        double l, jac[RC_MAX_PARAMS];
        pose(&s, k);
        assert_int_equal(rc_meas(&l, jac, &m, &s), RC_OK);
        for (unsigned p = 0; p < m.n_params; ++p) {
            rc_model a = m, b = m;
            const int ang = p < RC_N_DH && (p % 4) >= 2;
            const double h = ang ? 1e-6 : 1e-4;
            double la, lb;
            a.x[p] += h;
            b.x[p] -= h;
            assert_int_equal(rc_meas(&la, NULL, &a, &s), RC_OK);
            assert_int_equal(rc_meas(&lb, NULL, &b, &s), RC_OK);
            const double fd = (la - lb) / (2.0 * h);
            if (fabs(fd - jac[p]) > 1e-5 * (1.0 + fabs(fd)))
                fail_msg("pose %u param %u: analytic %.9g, difference %.9g", k, p, jac[p], fd);
        }
    }
}

/* Length-side effects never move the flange: rc_fk and the compiled
 * kinematics are those of the geometry. */
static void test_not_in_kinematics(void **state)
{
    (void)state;
    rc_model m, g;
    irb(&m);
    g = m;
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_CABLE_SAG, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_NONLIN, 0, 0), RC_OK);
    m.x[RC_N_BASE] = 50.0;
    m.x[RC_N_BASE + 1] = 5.0;
    m.x[RC_N_BASE + 2] = -5.0;
    rc_kin kin;
    assert_int_equal(rc_kin_compile(&kin, &m), RC_OK);
    assert_int_equal(kin.n_jeff, 0);
    assert_int_equal(kin.has_tool, 0);
    rc_sample s;
    memset(&s, 0, sizeof s);
    double p[3], p0[3];
    pose(&s, 3);
    rc_fk(p, NULL, &m, s.q_rad);
    rc_fk(p0, NULL, &g, s.q_rad);
    for (int r = 0; r < 3; ++r)
        assert_true(p[r] == p0[r]);
}

/* Written as a model file and read back: same kinds and values; and
 * `calibrate --effects` knows both names. */
static void test_model_file_and_effects_list(void **state)
{
    (void)state;
    rc_model m;
    rch_diag d0;
    irb(&m);
    assert_int_equal(rch_calib_effects(&m, "cable_sag,length_nonlinearity", &d0), 0);
    assert_int_equal(m.n_effects, 2);
    assert_int_equal(m.effects[0].kind, RC_EFF_CABLE_SAG);
    assert_int_equal(m.effects[1].kind, RC_EFF_LENGTH_NONLIN);
    m.x[RC_N_BASE] = 3.25;
    m.x[RC_N_BASE + 1] = -1.5;
    m.x[RC_N_BASE + 2] = 0.75;
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "t", &m, NULL, NULL), 0);
    fclose(f);
    assert_non_null(strstr(buf, "\"cable_sag\""));
    assert_non_null(strstr(buf, "\"length_nonlinearity\""));
    static rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_parse(&r, buf, len, "t.json", &d), 0);
    free(buf);
    assert_int_equal(r.model.n_effects, 2);
    assert_int_equal(r.model.effects[0].kind, RC_EFF_CABLE_SAG);
    assert_int_equal(r.model.effects[1].kind, RC_EFF_LENGTH_NONLIN);
    assert_true(fabs(r.model.x[RC_N_BASE] - 3.25) < 1e-12);
    assert_true(fabs(r.model.x[RC_N_BASE + 2] - 0.75) < 1e-12);
    /* an implausible sag (more than 1000 mm per m^3) is refused */
    const char *bad = "{\"format\":\"rcal-model/1\",\"name\":\"x\",\"dh\":["
                      "{\"a_mm\":0,\"d_mm\":290,\"alpha_deg\":-90,\"theta_deg\":0},"
                      "{\"a_mm\":270,\"d_mm\":0,\"alpha_deg\":0,\"theta_deg\":-90},"
                      "{\"a_mm\":70,\"d_mm\":0,\"alpha_deg\":-90,\"theta_deg\":0},"
                      "{\"a_mm\":0,\"d_mm\":302,\"alpha_deg\":90,\"theta_deg\":0},"
                      "{\"a_mm\":0,\"d_mm\":0,\"alpha_deg\":-90,\"theta_deg\":0},"
                      "{\"a_mm\":0,\"d_mm\":72,\"alpha_deg\":0,\"theta_deg\":0}],"
                      "\"encoder_mm\":[400,-300,50],\"effects\":[{\"kind\":\"cable_sag\",\"params\":[5000]}]}";
    assert_int_not_equal(rch_robot_parse(&r, bad, strlen(bad), "bad.json", &d), 0);
    rc_model m2;
    irb(&m2);
    assert_int_not_equal(rch_calib_effects(&m2, "cable_sagg", &d), 0);
    /* length_periodic needs its period's start value; a file with a zero period is refused */
    assert_int_not_equal(rch_calib_effects(&m2, "length_periodic", &d), 0);
    assert_int_equal(rch_calib_effects(&m2, "length_periodic:137", &d), 0);
    assert_true(m2.x[m2.effects[m2.n_effects - 1].first + 2] == 137.0);
    char bad2[2048];
    const char *cut = strstr(bad, "\"effects\"");
    assert_non_null(cut);
    snprintf(bad2, sizeof bad2, "%.*s\"effects\":[{\"kind\":\"length_periodic\",\"params\":[0.1,0,0]}]}",
             (int)(cut - bad), bad);
    assert_int_not_equal(rch_robot_parse(&r, bad2, strlen(bad2), "bad2.json", &d), 0);
    snprintf(bad2, sizeof bad2, "%.*s\"effects\":[{\"kind\":\"length_periodic\",\"params\":[0.1,0,140]}]}",
             (int)(cut - bad), bad);
    assert_int_equal(rch_robot_parse(&r, bad2, strlen(bad2), "good.json", &d), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sag_matches_catenary), cmocka_unit_test(test_nonlinearity_value),
        cmocka_unit_test(test_periodic_value),
        cmocka_unit_test(test_jacobian),             cmocka_unit_test(test_not_in_kinematics),
        cmocka_unit_test(test_model_file_and_effects_list),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
