/* SPDX-License-Identifier: MIT */
/* test_robust_solve.c - numeric robustness of the identification (issue 7).
 *
 * Degenerate data sets go through rc_solve with every method (LM, LTLM,
 * LM_PAPER, LTLM_PAPER) and through rc_encoder_guess:
 *   fewer samples than identifiable parameters, every sample at one pose,
 *   collinear and coplanar flange points, a constant length column, huge and
 *   tiny values, a single wild outlier, and a length that puts the flange on
 *   the encoder outlet.
 * Each must give a clear status or exit reason, never a NaN or infinity in
 * the model, never a crash, and stop within the iteration limit (ctest's
 * timeout catches a hang).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_solve.h"
#include "robust_common.h"

static rc_solve_work W; /* large: two RC_MAX_PARAMS^2 matrices */

static const rc_method methods[] = {RC_METHOD_LM, RC_METHOD_LTLM, RC_METHOD_LM_PAPER,
                                    RC_METHOD_LTLM_PAPER};

#define MAX_ITER 40u

static int model_finite(const rc_model *m)
{
    for (unsigned k = 0; k < m->n_params; ++k)
        if (!isfinite(m->x[k]))
            return 0;
    return 1;
}

static int is_clear_error(rc_status st)
{
    return st == RC_ERR_RANK || st == RC_ERR_NUMERIC || st == RC_ERR_NOCONV || st == RC_ERR_ARG ||
           st == RC_ERR_SINGULAR || st == RC_ERR_RANGE;
}

/* Start point: the nominal model with the encoder outlet 20 mm off. */
static void start_model(rc_model *m)
{
    rb_nominal(m);
    m->x[RC_P_ENC + 0] += 20.0;
    m->x[RC_P_ENC + 1] -= 10.0;
    m->x[RC_P_ENC + 2] += 5.0;
}

typedef struct outcome {
    rc_status st;
    rc_solve_result res;
} outcome;

/* One solve under the robustness contract; returns what happened. */
static const rc_model *g_start; /* start model override, NULL: start_model() */

static outcome solve_checked(const char *what, rc_method method, unsigned max_iter, const rc_sample *s,
                             size_t n)
{
    outcome o;
    rc_model m;
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    memset(&o, 0, sizeof o);
    cfg.method = method;
    cfg.max_iter = max_iter;
    cfg.seed = 5;
    if (g_start)
        m = *g_start;
    else
        start_model(&m);
    o.st = rc_solve(&m, &o.res, &W, &cfg, s, n);
    const unsigned limit = max_iter ? max_iter
                                    : (method == RC_METHOD_LM || method == RC_METHOD_LTLM) ? 100u : 50u;
    print_message("%-22s %-10s -> %-34s exit %-36s iter %3u rank %2u/%2u rms %.4g -> %.4g mm\n", what,
                  rc_method_name(method), rc_strerror(o.st), rc_exit_str(o.res.exit), o.res.iterations,
                  o.res.rank, o.res.n_free, o.res.rms_start_mm, o.res.rms_final_mm);
    /* never a NaN or infinity in the model, whatever the outcome */
    if (!model_finite(&m))
        fail_msg("%s / %s: the model holds a non-finite parameter after rc_solve", what,
                 rc_method_name(method));
    /* stops within its limit */
    assert_true(o.res.iterations <= limit);
    if (o.st == RC_OK) {
        /* a documented exit reason */
        assert_true(o.res.exit >= RC_EXIT_SMALL_STEP && o.res.exit <= RC_EXIT_NONFINITE);
        if (o.res.exit != RC_EXIT_NONFINITE) {
            assert_true(isfinite(o.res.rms_final_mm));
            /* the model returned must reproduce the reported RMS */
            double c;
            assert_int_equal(rc_cost(&c, &m, s, n), RC_OK);
            assert_true(fabs(sqrt(c / (double)n) - o.res.rms_final_mm) <=
                        1e-6 * (o.res.rms_final_mm + 1e-3));
        }
    } else {
        assert_true(is_clear_error(o.st));
        assert_non_null(rc_strerror(o.st));
    }
    return o;
}

static void all_methods(const char *what, const rc_sample *s, size_t n, outcome out[4])
{
    for (unsigned i = 0; i < 4; ++i) {
        out[i] = solve_checked(what, methods[i], MAX_ITER, s, n);
        (void)solve_checked(what, methods[i], 0, s, n); /* default limits */
    }
}

/* ---- data sets ---------------------------------------------------------- */

enum { NS = 60 };
static rc_sample S[NS];

static void test_control_good_data(void **state)
{
    rc_model t;
    outcome o[4];
    (void)state;
    rb_truth(&t);
    rb_random(S, NS, &t, 1);
    all_methods("control", S, NS, o);
    assert_int_equal(o[0].st, RC_OK);
    assert_true(o[0].res.rms_final_mm < 1e-3); /* noise-free: LM recovers the lengths */
    assert_true(o[0].res.rank < o[0].res.n_free); /* 27 parameters hold null directions */
}

static void test_fewer_samples_than_params(void **state)
{
    rc_model t;
    outcome o[4];
    (void)state;
    rb_truth(&t);
    for (size_t n = 1; n <= 20; n += 3) {
        char what[32];
        snprintf(what, sizeof what, "n=%zu < params", n);
        rb_random(S, n, &t, 2 + n);
        all_methods(what, S, n, o);
        /* the robust methods say how little the data identify */
        for (int i = 0; i < 2; ++i)
            if (o[i].st == RC_OK)
                assert_true(o[i].res.rank <= n);
    }
}

static void test_one_pose(void **state)
{
    rc_model t;
    outcome o[4];
    (void)state;
    rb_truth(&t);
    rb_random(S, 1, &t, 3);
    for (size_t i = 1; i < NS; ++i)
        S[i] = S[0];
    all_methods("all at one pose", S, NS, o);
    for (int i = 0; i < 2; ++i)
        if (o[i].st == RC_OK)
            assert_true(o[i].res.rank <= 1);
}

/* Flange points on a straight line (x from 300 to 450 mm at z = 500). */
static size_t collinear(rc_sample *s, size_t n, const rc_model *t)
{
    rc_model nom;
    rb_nominal(&nom);
    for (size_t i = 0; i < n; ++i) {
        memset(&s[i], 0, sizeof s[i]);
        assert_int_equal(rb_ik_xz(s[i].q_rad, &nom, 300.0 + 150.0 * (double)i / (double)(n - 1), 500.0), 0);
        double p[3];
        rc_fk(p, NULL, &nom, s[i].q_rad);
        assert_true(fabs(p[1]) < 1e-6 && fabs(p[2] - 500.0) < 1e-6);
        (void)rc_meas(&s[i].value, NULL, t, &s[i]);
    }
    return n;
}

static void test_collinear(void **state)
{
    rc_model t;
    outcome o[4];
    (void)state;
    rb_truth(&t);
    collinear(S, 40, &t);
    all_methods("collinear flange", S, 40, o);
}

static void test_constant_length(void **state)
{
    rc_model t;
    outcome o[4];
    (void)state;
    rb_truth(&t);
    rb_random(S, NS, &t, 4);
    for (size_t i = 0; i < NS; ++i)
        S[i].value = 500.0;
    all_methods("constant L column", S, NS, o);
}

static void test_huge_and_tiny(void **state)
{
    rc_model t;
    outcome o[4];
    static const double L[] = {1e-300, 1e-9, 1e6, 1e12, 1e150};
    (void)state;
    rb_truth(&t);
    for (size_t k = 0; k < sizeof L / sizeof L[0]; ++k) {
        char what[32];
        rb_random(S, NS, &t, 5);
        for (size_t i = 0; i < NS; ++i)
            S[i].value = L[k] * (1.0 + 1e-3 * (double)i);
        snprintf(what, sizeof what, "L ~ %g", L[k]);
        all_methods(what, S, NS, o);
    }
    /* huge and tiny joint angles (the data reader allows +-720 deg) */
    rb_random(S, NS, &t, 6);
    for (size_t i = 0; i < NS; ++i)
        for (int j = 0; j < RC_NJ; ++j)
            S[i].q_rad[j] = (i % 2 ? 720.0 : 1e-300) * RB_DEG * (j % 2 ? -1.0 : 1.0);
    all_methods("q = +-720 deg / 1e-300", S, NS, o);
}

static void test_one_wild_outlier(void **state)
{
    rc_model t;
    outcome o[4];
    static const double jump[] = {1e3, 1e9, -499.9};
    (void)state;
    rb_truth(&t);
    for (size_t k = 0; k < sizeof jump / sizeof jump[0]; ++k) {
        char what[32];
        rb_random(S, NS, &t, 7);
        S[NS / 2].value += jump[k];
        snprintf(what, sizeof what, "outlier %+g mm", jump[k]);
        all_methods(what, S, NS, o);
    }
}

/* The start model's encoder outlet sits exactly on the flange point of one
 * sample: the length derivative is undefined there (rc_meas: RC_ERR_NUMERIC). */
static void test_flange_on_outlet(void **state)
{
    rc_model t;
    static rc_model m;
    outcome o[4];
    double p[3];
    (void)state;
    rb_truth(&t);
    rb_random(S, NS, &t, 8);
    start_model(&m);
    rc_fk(p, NULL, &m, S[3].q_rad);
    memcpy(&m.x[RC_P_ENC], p, sizeof p);
    g_start = &m;
    all_methods("flange on outlet", S, NS, o);
    g_start = NULL;
}

/* ---- rc_encoder_guess --------------------------------------------------- */

static void guess_checked(const char *what, const rc_sample *s, size_t n, int must_fail)
{
    rc_model nom;
    double e[3] = {1.0, 2.0, 3.0};
    rb_nominal(&nom);
    rc_status st = rc_encoder_guess(e, &nom, s, n);
    print_message("encoder guess %-22s -> %-34s e = %.4g %.4g %.4g\n", what, rc_strerror(st), e[0], e[1], e[2]);
    if (st == RC_OK) {
        assert_true(isfinite(e[0]) && isfinite(e[1]) && isfinite(e[2]));
        /* never an absurd outlet (a wild length once gave 2.9e13 mm) */
        assert_true(fabs(e[0]) < 1e5 && fabs(e[1]) < 1e5 && fabs(e[2]) < 1e5);
        if (must_fail)
            fail_msg("rc_encoder_guess(%s) returned a position where the poses cannot place the outlet", what);
    } else {
        assert_true(is_clear_error(st));
    }
}

static void test_encoder_guess_degenerate(void **state)
{
    rc_model t;
    (void)state;
    rb_truth(&t);
    rb_random(S, NS, &t, 9);
    guess_checked("control", S, NS, 0);
    for (size_t n = 0; n < 4; ++n)
        guess_checked("n < 4", S, n, 1);
    rb_random(S, 1, &t, 10);
    for (size_t i = 1; i < NS; ++i)
        S[i] = S[0];
    guess_checked("one pose", S, NS, 1);
    collinear(S, 40, &t);
    guess_checked("collinear (axis)", S, 40, 1);
    /* coplanar: only q1 moves, flange points on a horizontal circle */
    rb_random(S, NS, &t, 11);
    for (size_t i = 0; i < NS; ++i) {
        for (int j = 1; j < RC_NJ; ++j)
            S[i].q_rad[j] = S[0].q_rad[j];
        (void)rc_meas(&S[i].value, NULL, &t, &S[i]);
    }
    guess_checked("coplanar (q1 only)", S, NS, 1);
    /* the same degeneracies, not aligned with the base axes: the arm turned
     * by q1 = 45 deg, flange points on an oblique line, then in the
     * vertical plane x = y */
    {
        rc_model nom;
        rb_nominal(&nom);
        for (size_t i = 0; i < 40; ++i) {
            memset(&S[i], 0, sizeof S[i]);
            assert_int_equal(rb_ik_xz(S[i].q_rad, &nom, 300.0 + 3.0 * (double)i, 400.0 + 4.0 * (double)i), 0);
            S[i].q_rad[0] = 45.0 * RB_DEG;
            (void)rc_meas(&S[i].value, NULL, &t, &S[i]);
        }
        guess_checked("collinear (oblique)", S, 40, 1);
        rc_rng g;
        rc_rng_seed(&g, 15);
        for (size_t i = 0; i < 40; ++i) {
            memset(&S[i], 0, sizeof S[i]);
            assert_int_equal(rb_ik_xz(S[i].q_rad, &nom, 300.0 + 150.0 * rc_rng_u01(&g),
                                      300.0 + 300.0 * rc_rng_u01(&g)), 0);
            S[i].q_rad[0] = 45.0 * RB_DEG;
            (void)rc_meas(&S[i].value, NULL, &t, &S[i]);
        }
        /* was RC_OK with an outlet 1.9 m off until the guard used the
         * smallest scatter eigenvalue (found by this suite) */
        guess_checked("coplanar (oblique)", S, 40, 1);
    }
    rb_random(S, NS, &t, 12);
    for (size_t i = 0; i < NS; ++i)
        S[i].value = 500.0;
    guess_checked("constant L", S, NS, 0);
    rb_random(S, NS, &t, 13);
    for (size_t i = 0; i < NS; ++i)
        S[i].value = 1e150;
    guess_checked("L = 1e150", S, NS, 0);
    rb_random(S, NS, &t, 14);
    S[5].value = 1e9;
    guess_checked("one outlier 1e9", S, NS, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_control_good_data),
        cmocka_unit_test(test_fewer_samples_than_params),
        cmocka_unit_test(test_one_pose),
        cmocka_unit_test(test_collinear),
        cmocka_unit_test(test_constant_length),
        cmocka_unit_test(test_huge_and_tiny),
        cmocka_unit_test(test_one_wild_outlier),
        cmocka_unit_test(test_flange_on_outlet),
        cmocka_unit_test(test_encoder_guess_degenerate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
