/* SPDX-License-Identifier: MIT */
/* test_methods.c - the seven identification methods on a simulated robot
 * with known errors: held-out RMSE near the noise level (gradient methods and
 * EKF) or a measured, bounded shortfall (population methods); determinism
 * with a fixed seed; the identifiable subset; argument errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_est.h"
#include "rc_solve.h"
#include "rch_start.h"
#include "rch_est.h"
#include "rch_prior.h"
#include "rch_robot.h"
#include "rch_sim.h"

enum { NTR = 150, NTE = 60 };

typedef struct fixture {
    rch_robot robot;
    rc_model truth;
    rc_model start;
    rc_sample tr[NTR], te[NTE];
    rch_est_ws *ws;
    double noise_mm;
} fixture;

/* Truth = nominal + random DH errors (0.3 mm, 0.05 deg), encoder at a known
 * place; noise 0.01 mm, 0.004 mm resolution, joint angles not rounded (so
 * that the noise level is the only floor). */
static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    rch_diag d;
    rch_sim_config c;
    rc_rng g;
    const double enc[3] = {250.0, -460.0, 10.0};
    assert_non_null(f);
    assert_int_equal(rch_robot_load(&f->robot, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    memset(&c, 0, sizeof c);
    c.q_step_deg = -1.0;
    c.group_size = 15;
    rch_sim_defaults(&c);
    rc_rng_seed(&g, 2024);
    rch_sim_truth(&f->truth, &f->robot.model, enc, &c, &g);
    assert_int_equal(rch_sim_samples(f->tr, NULL, NTR, &f->truth, &c, &g), 0);
    assert_int_equal(rch_sim_samples(f->te, NULL, NTE, &f->truth, &c, &g), 0);
    f->ws = rch_est_ws_new();
    assert_non_null(f->ws);
    assert_int_equal(rch_calib_start(&f->start, &f->ws->solve, &f->robot, f->tr, NTR, &d), 0);
    f->noise_mm = c.noise_mm;
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    rch_est_ws_free(f->ws);
    free(f);
    return 0;
}

/* Run one method with its defaults, check the curve and return the
 * held-out RMSE. */
static double run_method(fixture *f, rch_est_id id, const rch_est_opts *opts, rc_model *out)
{
    rc_model m = f->start;
    rch_est_out o;
    rch_curve curve;
    rc_metrics before, after;
    memset(&curve, 0, sizeof curve);
    assert_int_equal(rch_est_run(&m, &o, &curve, f->ws, id, 7, opts, f->tr, NTR), RC_OK);
    assert_int_equal(rc_eval(&before, &f->start, f->te, NTE), RC_OK);
    assert_int_equal(rc_eval(&after, &m, f->te, NTE), RC_OK);
    print_message("%-6s held-out RMSE %.4f -> %.4f mm (train %.4f), %u iterations, %u passes, "
                  "%u moved, %.1f ms\n",
                  rch_est_name(id), before.rmse_mm, after.rmse_mm, o.rms_final_mm, o.iterations,
                  o.cost_evals, o.n_moved, o.time_ms);
    /* a convergence curve: start + one value per iteration, never rising for
     * the methods that keep their best point */
    assert_int_equal(curve.n, (size_t)o.iterations + 1);
    assert_true(fabs(curve.rms_mm[0] - o.rms_start_mm) < 1e-9);
    assert_true(curve.rms_mm[curve.n - 1] <= curve.rms_mm[0] + 1e-12);
    assert_true(fabs(curve.rms_mm[curve.n - 1] - o.rms_final_mm) < 1e-6 * (1.0 + o.rms_final_mm));
    assert_true(before.rmse_mm > 0.3); /* the start is really off */
    rch_curve_free(&curve);
    if (out)
        *out = m;
    return after.rmse_mm;
}

static void test_gradient_and_filter_methods(void **state)
{
    fixture *f = *state;
    /* at the noise level: noise 0.01 mm (+ resolution); 0.02 allows for the
     * subset's dropped weak directions and the finite sample */
    /* the core's LM/LTLM stop once no eigen-direction's step is significant
     * (rc_solve since b3932fe): on this fixture 0.0199 mm held-out, train
     * 0.0103 against 0.0097 at the least-squares minimum; bound 0.03 */
    assert_true(run_method(f, RCH_EST_LM, NULL, NULL) < 0.03);
    assert_true(run_method(f, RCH_EST_LTLM, NULL, NULL) < 0.03);
    assert_true(run_method(f, RCH_EST_SSLM, NULL, NULL) < 0.02);
    assert_true(run_method(f, RCH_EST_EKF, NULL, NULL) < 0.02);
}

/* Population methods: a measured shortfall. With the default budgets
 * (PF 100 x 100, SCA 30 x 500, QIBAS 2000 x 3 cost evaluations) in a box of
 * +-2 mm / +-0.2 deg / +-5 mm around the start, they do not reach the noise
 * level on 20 parameters. Measured on this fixture (held-out RMSE from 0.42):
 * PF 0.046 (train 0.019), SCA 0.27 (train 0.15), QIBAS 0.13 mm (train 0.027);
 * the test groups have wrist orientations the training groups lack, which
 * is where the directions a random search leaves unconverged show.
 * Asserted with margin: they lower the training RMS they optimise to below
 * half the start (QIBAS: a fifth), and do not make the held-out error worse
 * (QIBAS: below half the start). */
static void check_population(fixture *f, rch_est_id id, double train_frac, double test_frac)
{
    rc_model m;
    rc_metrics before;
    double t0, t1;
    assert_int_equal(rc_eval(&before, &f->start, f->te, NTE), RC_OK);
    assert_int_equal(rc_eval(&before, &f->start, f->tr, NTR), RC_OK);
    t0 = before.rmse_mm;
    assert_int_equal(rc_eval(&before, &f->start, f->te, NTE), RC_OK);
    double test = run_method(f, id, NULL, &m);
    rc_metrics tr;
    assert_int_equal(rc_eval(&tr, &m, f->tr, NTR), RC_OK);
    t1 = tr.rmse_mm;
    assert_true(t1 < train_frac * t0);
    assert_true(test < test_frac * before.rmse_mm);
}

static void test_population_methods(void **state)
{
    fixture *f = *state;
    check_population(f, RCH_EST_PF, 0.5, 1.0);
    check_population(f, RCH_EST_SCA, 0.5, 1.0);
    check_population(f, RCH_EST_QIBAS, 0.2, 0.5);
}

/* Same seed: bit-identical parameters; another seed: a different path for
 * the stochastic methods. Small budgets keep it fast. */
static void test_determinism(void **state)
{
    fixture *f = *state;
    rch_est_opts o;
    memset(&o, 0, sizeof o);
    o.max_iter = 15;
    o.pop = 12;
    for (int id = 0; id < RCH_EST_COUNT; ++id) {
        rc_model a = f->start, b = f->start, c = f->start;
        rch_est_out out;
        assert_int_equal(rch_est_run(&a, &out, NULL, f->ws, (rch_est_id)id, 99, &o, f->tr, NTR), RC_OK);
        assert_int_equal(rch_est_run(&b, &out, NULL, f->ws, (rch_est_id)id, 99, &o, f->tr, NTR), RC_OK);
        assert_memory_equal(a.x, b.x, sizeof a.x);
        assert_int_equal(rch_est_run(&c, &out, NULL, f->ws, (rch_est_id)id, 100, &o, f->tr, NTR), RC_OK);
        if (id == RCH_EST_PF || id == RCH_EST_SCA || id == RCH_EST_QIBAS) {
            if (memcmp(a.x, c.x, sizeof a.x) == 0)
                print_error("%s: seeds 99 and 100 gave the same result\n", rch_est_name((rch_est_id)id));
            assert_true(memcmp(a.x, c.x, sizeof a.x) != 0);
        }
    }
}

/* The identifiable subset drops the exact null directions: alpha6 and theta6
 * (they do not move the flange point), one of d1 / e_z, one of theta1 / e_x /
 * e_y; and it honours a caller's mask. The population methods never move a
 * dropped parameter. */
static void test_subset(void **state)
{
    fixture *f = *state;
    uint8_t out[RC_MAX_PARAMS], in[RC_MAX_PARAMS];
    unsigned kept;
    assert_int_equal(rc_est_subset(out, &kept, &f->ws->est, &f->start, NULL, 0.0, f->tr, NTR),
                     RC_OK);
    print_message("identifiable subset: %u of 27\n", kept);
    assert_true(kept <= 23 && kept >= 18);
    assert_int_equal(out[RC_P_ALPHA(5)], 1);
    assert_int_equal(out[RC_P_THETA(5)], 1);
    assert_true(out[RC_P_D(0)] || out[RC_P_ENC + 2]);
    assert_true(out[RC_P_THETA(0)] || out[RC_P_ENC] || out[RC_P_ENC + 1]);
    memset(in, 0, sizeof in);
    in[RC_P_A(1)] = 1;
    assert_int_equal(rc_est_subset(out, &kept, &f->ws->est, &f->start, in, 0.0, f->tr, NTR), RC_OK);
    assert_int_equal(out[RC_P_A(1)], 1);
    {
        rc_model m = f->start;
        rc_est_config cfg;
        memset(&cfg, 0, sizeof cfg);
        cfg.method = RC_EST_SCA;
        cfg.max_iter = 5;
        cfg.pop = 8;
        cfg.fixed = in;
        assert_int_equal(rc_est_solve(&m, NULL, &f->ws->est, &cfg, f->tr, NTR), RC_OK);
        assert_true(m.x[RC_P_A(1)] == f->start.x[RC_P_A(1)]);
        assert_true(m.x[RC_P_ALPHA(5)] == f->start.x[RC_P_ALPHA(5)]);
        assert_true(m.x[RC_P_THETA(5)] == f->start.x[RC_P_THETA(5)]);
    }
}


/* With the physical prior every method minimises the same MAP objective
 * (rc_est.h): EKF iterated from the prior and SSLM with the prior rows reach
 * the robust LM's MAP estimate; the population methods lower the objective
 * from the start and stay inside the prior's 3 sd box. */
static double map_objective(const rc_model *m, const rch_est_opts *o, const fixture *f)
{
    rc_solve_config pc;
    double ssr;
    memset(&pc, 0, sizeof pc);
    pc.prior_mean = o->prior_mean;
    pc.prior_sd = o->prior_sd;
    pc.prior_noise_mm = o->prior_noise_mm;
    pc.fixed = o->fixed;
    assert_int_equal(rc_cost(&ssr, m, f->tr, NTR), RC_OK);
    return ssr + rc_prior_cost(m, &pc);
}

static void test_prior_every_method(void **state)
{
    fixture *f = *state;
    double mean[RC_MAX_PARAMS] = {0}, sd[RC_MAX_PARAMS] = {0};
    uint8_t fixed[RC_MAX_PARAMS] = {0};
    rch_est_opts o;
    rc_model ref, m;
    rc_sample ws[400];
    rc_rng g;
    double ref_rms, rms, mx;
    rch_prior_fill(mean, sd, &f->start, &f->robot.model, &f->robot.prior);
    rch_prior_gauge(fixed);
    memset(&o, 0, sizeof o);
    o.prior_mean = mean;
    o.prior_sd = sd;
    o.prior_noise_mm = f->noise_mm;
    o.fixed = fixed;
    rc_rng_seed(&g, 99);
    rch_sim_poses(ws, 400, &f->truth, 0.0, &g);
    run_method(f, RCH_EST_LM, &o, &ref);
    const double f_ref = map_objective(&ref, &o, f), f_start = map_objective(&f->start, &o, f);
    rch_sim_flange_diff(&ref_rms, &mx, &ref, &f->truth, ws, 400, 1);
    print_message("MAP objective: start %.6g, LM %.6g mm^2; LM flange vs truth %.4f mm RMS\n", f_start, f_ref,
                  ref_rms);
    const rch_est_id exact[] = {RCH_EST_EKF, RCH_EST_SSLM, RCH_EST_LTLM};
    for (size_t i = 0; i < sizeof exact / sizeof exact[0]; ++i) {
        run_method(f, exact[i], &o, &m);
        const double fo = map_objective(&m, &o, f);
        double dx = 0.0;
        for (unsigned k = 0; k < RC_N_DH; ++k) /* mm and rad: 1e-3 mm is 1e-3 rad here, both far below the prior */
            dx = fmax(dx, fabs(m.x[k] - ref.x[k]));
        rch_sim_flange_diff(&rms, &mx, &m, &f->truth, ws, 400, 1);
        print_message("%-6s objective %.6g (LM %.6g), largest DH difference to LM %.2e, flange vs truth %.4f mm\n",
                      rch_est_name(exact[i]), fo, f_ref, dx, rms);
        assert_true(fo <= f_ref * (1.0 + 1e-3));
        /* SSLM's fixed damping creeps along the directions only the prior
         * holds (curvature (noise / sd)^2, 4e-4 of the data's): after its 100
         * iterations the objective is 4e-4 above the minimum and a prior-held
         * DH value 0.09 mm away (measured), the flange unchanged */
        if (exact[i] != RCH_EST_SSLM)
            assert_true(dx < 2e-3);
        assert_true(rms < 1.5 * ref_rms + 0.002);
    }
    const rch_est_id pop[] = {RCH_EST_PF, RCH_EST_SCA, RCH_EST_QIBAS};
    for (size_t i = 0; i < sizeof pop / sizeof pop[0]; ++i) {
        run_method(f, pop[i], &o, &m);
        const double fo = map_objective(&m, &o, f);
        print_message("%-6s objective %.6g (start %.6g, LM %.6g)\n", rch_est_name(pop[i]), fo, f_start, f_ref);
        assert_true(fo < f_start);
        assert_true(fo >= f_ref * (1.0 - 1e-6)); /* none below the MAP minimum */
        for (unsigned k = 0; k < RC_N_DH; ++k)
            if (!fixed[k] && sd[k] > 0.0)
                assert_true(fabs(m.x[k] - mean[k]) <= 3.0 * sd[k] + 1e-12 + fabs(f->start.x[k] - mean[k]));
    }
}

static void test_errors(void **state)
{
    fixture *f = *state;
    rc_model m = f->start;
    rc_est_config cfg;
    uint8_t all[RC_MAX_PARAMS];
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_EST_PF;
    cfg.pop = RC_EST_MAX_POP + 1;
    assert_int_equal(rc_est_solve(&m, NULL, &f->ws->est, &cfg, f->tr, NTR), RC_ERR_ARG);
    cfg.pop = 0;
    assert_int_equal(rc_est_solve(&m, NULL, &f->ws->est, &cfg, f->tr, 0), RC_ERR_ARG);
    memset(all, 1, sizeof all);
    cfg.fixed = all;
    assert_int_equal(rc_est_solve(&m, NULL, &f->ws->est, &cfg, f->tr, NTR), RC_ERR_RANK);
    cfg.fixed = NULL;
    cfg.method = (rc_est_method)42;
    assert_int_equal(rc_est_solve(&m, NULL, &f->ws->est, &cfg, f->tr, NTR), RC_ERR_ARG);
    assert_memory_equal(m.x, f->start.x, sizeof m.x); /* untouched on errors */
    assert_int_equal(rch_est_parse("ltlm"), RCH_EST_LTLM);
    assert_int_equal(rch_est_parse("M2"), RCH_EST_EKF);
    assert_int_equal(rch_est_parse("QIBAS"), RCH_EST_QIBAS);
    assert_int_equal(rch_est_parse("foo"), -1);
    assert_string_equal(rc_est_method_name(RC_EST_SSLM), "sslm");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gradient_and_filter_methods),
        cmocka_unit_test(test_population_methods),
        cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_subset),
        cmocka_unit_test(test_prior_every_method),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
