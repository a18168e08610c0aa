/* SPDX-License-Identifier: MIT */
/* test_sslm.c - SSLM's variable step-size rule (rc_est.h, RC_EST_SSLM) on a
 * tiny problem: two free parameters of a simulated robot, started far
 * enough off that the full LM step does not always lower the cost. The test
 * recomputes every iteration apart from the library: the fixed-damping LM
 * direction in the start's column scaling (its own 2 x 2 solve), the step
 * size first tried at min(1, 2 eta_prev) and halved until the cost falls,
 * and compares the point the library reports after each iteration. Plain LM
 * (damping varied, full steps) or any other step-size rule fails it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_est.h"
#include "rc_rand.h"
#include "rc_solve.h"
#include "rch_robot.h"
#include "rch_sim.h"

enum { NS = 60, MAXIT = 25 };

typedef struct trace {
    unsigned n;
    double x[MAXIT][2]; /* the two free parameters after each iteration */
    uint16_t idx[2];
} trace;

static void on_iter(void *ctx, unsigned iter, double rms_mm, const rc_model *m)
{
    trace *t = ctx;
    (void)iter;
    (void)rms_mm;
    if (t->n < MAXIT) {
        t->x[t->n][0] = m->x[t->idx[0]];
        t->x[t->n][1] = m->x[t->idx[1]];
        t->n++;
    }
}

static double cost_at(const rc_model *base, const uint16_t idx[2], const double x[2], const rc_sample *s)
{
    rc_model m = *base;
    double c;
    m.x[idx[0]] = x[0];
    m.x[idx[1]] = x[1];
    if (rc_cost(&c, &m, s, NS) != RC_OK)
        return HUGE_VAL;
    return c;
}

/* One run from truth + (dth_deg on theta2, da_mm on a3) with damping mu,
 * recomputed iteration by iteration. *carry: iterations where the step size
 * carried over mattered: eta_prev < 0.5 and a longer step than
 * 2 eta_prev (1, 1/2, ...) would also have lowered the cost, so a rule that
 * restarts at 1 each iteration takes another point. Returns 1 when the
 * run converged to the truth's two values. */
static int check_rule(double dth_deg, double da_mm, double mu, unsigned *shortened_out, unsigned *carry)
{
    static rch_robot robot;
    static rc_est_work w;
    static rc_sample s[NS];
    rch_diag d;
    rch_sim_config c;
    rc_rng g;
    rc_model truth, start;
    const double enc[3] = {250.0, -460.0, 10.0};
    uint8_t fixed[RC_MAX_PARAMS];
    trace t;
    rc_est_config cfg;
    rc_est_result res;
    assert_int_equal(rch_robot_load(&robot, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    memset(&c, 0, sizeof c);
    c.q_step_deg = -1.0;
    rch_sim_defaults(&c);
    rc_rng_seed(&g, 77);
    rch_sim_truth(&truth, &robot.model, enc, &c, &g);
    assert_int_equal(rch_sim_samples(s, NULL, NS, &truth, &c, &g), 0);

    /* free: theta2 and a3; started 70 deg and 150 mm off (a curved problem) */
    memset(&t, 0, sizeof t);
    t.idx[0] = RC_P_THETA(1);
    t.idx[1] = RC_P_A(2);
    for (unsigned k = 0; k < truth.n_params; ++k)
        fixed[k] = 1;
    fixed[t.idx[0]] = fixed[t.idx[1]] = 0;
    start = truth;
    start.x[t.idx[0]] += dth_deg * 3.14159265358979 / 180.0;
    start.x[t.idx[1]] += da_mm;

    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_EST_SSLM;
    cfg.keep_all = 1;
    cfg.fixed = fixed;
    cfg.max_iter = MAXIT;
    cfg.sslm_mu = mu;
    cfg.on_iter = on_iter;
    cfg.cb_ctx = &t;
    rc_model m = start;
    assert_int_equal(rc_est_solve(&m, &res, &w, &cfg, s, NS), RC_OK);
    assert_true(t.n >= 3);

    /* the rule, recomputed */
    double x[2] = {start.x[t.idx[0]], start.x[t.idx[1]]}, D[2] = {0, 0}, eta = 1.0;
    unsigned shortened = 0;
    for (unsigned k = 0; k < t.n; ++k) {
        double A[4], gv[2], cost, jrow[RC_MAX_PARAMS];
        rc_model cur = start;
        cur.x[t.idx[0]] = x[0];
        cur.x[t.idx[1]] = x[1];
        assert_int_equal(rc_normal_eq(A, gv, &cost, jrow, &cur, t.idx, 2, s, NS), RC_OK);
        if (k == 0) {
            D[0] = sqrt(A[0]);
            D[1] = sqrt(A[3]);
        }
        /* (A_s + mu I) delta = -g_s, A_s = D^-1 A D^-1, g_s = D^-1 g: Cramer */
        const double a00 = A[0] / (D[0] * D[0]) + cfg.sslm_mu, a11 = A[3] / (D[1] * D[1]) + cfg.sslm_mu;
        const double a01 = A[1] / (D[0] * D[1]);
        const double b0 = -gv[0] / D[0], b1 = -gv[1] / D[1];
        const double det = a00 * a11 - a01 * a01;
        const double delta[2] = {(b0 * a11 - a01 * b1) / det, (a00 * b1 - a01 * b0) / det};
        double a = fmin(1.0, 2.0 * eta), xn[2] = {0, 0};
        int ok = 0;
        for (int h = 0; h <= 40 && !ok; ++h) {
            xn[0] = x[0] + a * delta[0] / D[0];
            xn[1] = x[1] + a * delta[1] / D[1];
            if (cost_at(&start, t.idx, xn, s) < cost)
                ok = 1;
            else
                a *= 0.5;
        }
        assert_true(ok);
        if (a < 1.0)
            ++shortened;
        if (eta < 0.5) { /* would a restart at 1 have taken a longer step? */
            double a1 = 1.0, xr[2];
            for (int h = 0; h <= 40 && a1 > 2.0 * eta * 1.000001; ++h, a1 *= 0.5) {
                xr[0] = x[0] + a1 * delta[0] / D[0];
                xr[1] = x[1] + a1 * delta[1] / D[1];
                if (cost_at(&start, t.idx, xr, s) < cost) {
                    ++*carry;
                    break;
                }
            }
        }
        /* the library's point after iteration k + 1 */
        assert_true(fabs(t.x[k][0] - xn[0]) <= 1e-9 * (1.0 + fabs(xn[0])));
        assert_true(fabs(t.x[k][1] - xn[1]) <= 1e-9 * (1.0 + fabs(xn[1])));
        x[0] = t.x[k][0];
        x[1] = t.x[k][1];
        eta = a;
    }
    *shortened_out = shortened;
    return fabs(m.x[t.idx[0]] - truth.x[t.idx[0]]) < 1e-3 && fabs(m.x[t.idx[1]] - truth.x[t.idx[1]]) < 0.1;
}

static void test_step_sizes(void **state)
{
    unsigned shortened = 0, carry = 0;
    (void)state;
    /* started 70 deg / 150 mm off (a curved problem): some steps shortened, converged */
    assert_true(check_rule(70.0, 150.0, 1e-3, &shortened, &carry));
    assert_true(shortened >= 1);
}

/* The step size carried over: runs where eta_prev < 0.5 occurs and a
 * restart at eta = 1 would have been accepted at a longer step, so that
 * carrying eta over (first try min(1, 2 eta_prev)) decides the point; a
 * rule that does not carry it over fails the recomputation. */
static void test_step_size_carried(void **state)
{
    static const double runs[][3] = {{70.0, 150.0, 1e-3}, {120.0, 300.0, 1e-3}, {150.0, -200.0, 1e-4},
                                     {100.0, 250.0, 1e-5}, {160.0, 400.0, 1e-5}};
    unsigned carry = 0;
    (void)state;
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; ++k) {
        unsigned sh = 0, c = 0;
        (void)check_rule(runs[k][0], runs[k][1], runs[k][2], &sh, &c);
        print_message("start off by %g deg / %g mm, mu %g: %u steps shortened, %u where the carried step size "
                      "mattered\n", runs[k][0], runs[k][1], runs[k][2], sh, c);
        carry += c;
    }
    assert_true(carry >= 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_step_sizes),
        cmocka_unit_test(test_step_size_carried),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
