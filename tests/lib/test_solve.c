/* SPDX-License-Identifier: MIT */
/* rc_solve and rc_est with the core alone (issue 50 item 5): data drawn by
 * this file's own standard-DH chain (not rc_kin) from a robot whose 24 DH
 * values and outlet differ from the nominal IRB120, with 0.01 mm noise; every
 * solver started at the nominal must reach the noise and predict new poses'
 * lengths as the true robot gives them. Beside it the solver's contracts:
 * rc_solve_buf equals rc_solve to the last bit, a workspace too small and a
 * problem with nothing free are refused, rc_cost_tab equals rc_cost, the
 * normal equations' gradient is the cost's derivative, a prior that is
 * certain holds its parameters. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_est.h"
#include "rc_model.h"
#include "rc_rand.h"
#include "rc_solve.h"
#include "rct_irb120.h"

#define PI 3.14159265358979323846
enum { N_TRAIN = 240, N_TEST = 120 };
static const double NOISE_MM = 0.01;
static const double ENC_MM[3] = {250.0, -460.0, 10.0};

/* The true robot: nominal DH (a mm, d mm, alpha rad, theta offset rad) and
 * outlet, each value moved by a fixed draw (lengths +-1 mm, angles +-0.1 deg,
 * the outlet +-3 mm). */
typedef struct truth {
    double dh[6][4];
    double enc[3];
} truth;

static void make_truth(truth *t, rc_rng *g)
{
    rct_irb120_dh(t->dh);
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            t->dh[i][k] += (2.0 * rc_rng_u01(g) - 1.0) * (k < 2 ? 1.0 : 0.1 * PI / 180.0);
    for (int k = 0; k < 3; ++k)
        t->enc[k] = ENC_MM[k] + (2.0 * rc_rng_u01(g) - 1.0) * 3.0;
}

/* This file's forward kinematics: standard DH, T = prod Rz(q + off) Tz(d)
 * Tx(a) Rx(alpha); the flange centre's position (mm). */
static void own_fk(double p[3], const double dh[6][4], const double q[6])
{
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, o[3] = {0, 0, 0};
    for (int i = 0; i < 6; ++i) {
        const double a = dh[i][0], d = dh[i][1], al = dh[i][2], th = q[i] + dh[i][3];
        const double ct = cos(th), st = sin(th), ca = cos(al), sa = sin(al);
        /* the joint's transform: rotation A, translation b */
        const double A[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0, sa, ca};
        const double b[3] = {a * ct, a * st, d};
        double Rn[9], on[3];
        for (int r = 0; r < 3; ++r) {
            on[r] = o[r];
            for (int c = 0; c < 3; ++c) {
                Rn[r * 3 + c] = 0.0;
                for (int k = 0; k < 3; ++k)
                    Rn[r * 3 + c] += R[r * 3 + k] * A[k * 3 + c];
                on[r] += R[r * 3 + c] * b[c];
            }
        }
        memcpy(R, Rn, sizeof R);
        memcpy(o, on, sizeof o);
    }
    memcpy(p, o, sizeof o);
}

static double own_len(const truth *t, const double q[6])
{
    double p[3];
    own_fk(p, t->dh, q);
    return sqrt((p[0] - t->enc[0]) * (p[0] - t->enc[0]) + (p[1] - t->enc[1]) * (p[1] - t->enc[1]) +
                (p[2] - t->enc[2]) * (p[2] - t->enc[2]));
}

/* n poses within 80 % of the IRB120's joint ranges, the true length with noise sd (0: none). */
static void draw(rc_sample *s, size_t n, const truth *t, double sd, rc_rng *g)
{
    for (size_t i = 0; i < n; ++i) {
        memset(&s[i], 0, sizeof s[i]);
        for (int j = 0; j < 6; ++j) {
            const double lo = rct_irb120_lim_deg[j][0], hi = rct_irb120_lim_deg[j][1];
            const double half = 0.8 * 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
            s[i].q_rad[j] = (mid + (2.0 * rc_rng_u01(g) - 1.0) * (j == 5 ? 180.0 : half)) * PI / 180.0;
        }
        s[i].t = (double)i / (double)(n > 1 ? n - 1 : 1);
        s[i].value = own_len(t, s[i].q_rad) + sd * rc_rng_normal(g);
    }
}

static rc_model nominal(void)
{
    rc_model m;
    double dh[RC_NJ][4];
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(&m, (const double(*)[4])dh, ENC_MM), RC_OK);
    for (int i = 0; i < RC_NJ; ++i) {
        m.q_min_rad[i] = rct_irb120_lim_deg[i][0] * PI / 180.0;
        m.q_max_rad[i] = rct_irb120_lim_deg[i][1] * PI / 180.0;
    }
    return m;
}

typedef struct fixture {
    truth t;
    rc_sample train[N_TRAIN];
    rc_sample test[N_TEST]; /* noise-free: the true robot's lengths */
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    rc_rng g;
    if (!f)
        return -1;
    rc_rng_seed(&g, 50);
    make_truth(&f->t, &g);
    draw(f->train, N_TRAIN, &f->t, NOISE_MM, &g);
    draw(f->test, N_TEST, &f->t, 0.0, &g);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    free(*state);
    return 0;
}

/* The two kinematics agree on the nominal robot: the generator is a fair
 * judge (a disagreement here is a convention, not a solver fault). */
static void test_own_fk_matches(void **state)
{
    (void)state;
    truth t;
    rc_model m = nominal();
    rc_rng g;
    rct_irb120_dh(t.dh);
    memcpy(t.enc, ENC_MM, sizeof t.enc);
    rc_rng_seed(&g, 3);
    for (int k = 0; k < 50; ++k) {
        rc_sample s;
        double l;
        draw(&s, 1, &t, 0.0, &g);
        assert_int_equal(rc_meas(&l, NULL, &m, &s), RC_OK);
        assert_true(fabs(l - s.value) < 1e-9);
    }
}

/* Held-out RMS of a model against the true lengths (mm). */
static double test_rms(const rc_model *m, const fixture *f)
{
    rc_metrics e;
    assert_int_equal(rc_eval(&e, m, f->test, N_TEST), RC_OK);
    return e.rmse_mm;
}

static void check_fit(const rc_model *m, double rms_train, const fixture *f, const char *who)
{
    const double held = test_rms(m, f);
    /* the training residual at the noise (less the fitted parameters' share), the prediction of new
     * poses well inside it: the identifiable part of the robot is recovered */
    if (!(rms_train > 0.8 * NOISE_MM && rms_train < 1.15 * NOISE_MM && held < 0.6 * NOISE_MM))
        fail_msg("%s: training RMS %.5f mm, held-out %.5f mm (noise %.3f mm)", who, rms_train, held, NOISE_MM);
}

static void test_lm_and_ltlm_recover(void **state)
{
    const fixture *f = *state;
    static rc_solve_work w;
    const rc_model start = nominal();
    const double before = test_rms(&start, f);
    assert_true(before > 50.0 * NOISE_MM); /* the true robot is far from nominal */
    const rc_method methods[] = {RC_METHOD_LM, RC_METHOD_LTLM};
    for (size_t k = 0; k < sizeof methods / sizeof methods[0]; ++k) {
        rc_model m = start;
        rc_solve_config cfg;
        rc_solve_result res;
        memset(&cfg, 0, sizeof cfg);
        cfg.method = methods[k];
        cfg.seed = 7;
        assert_int_equal(rc_solve(&m, &res, &w, &cfg, f->train, N_TRAIN), RC_OK);
        assert_true(res.exit != RC_EXIT_NONFINITE && res.exit != RC_EXIT_NO_DESCENT);
        assert_true(res.rank > 0 && res.rank < res.n_free); /* DH has dependent directions */
        check_fit(&m, res.rms_final_mm, f, rc_method_name(methods[k]));
    }
}

static void test_buf_equals_solve(void **state)
{
    const fixture *f = *state;
    static rc_solve_work w;
    rc_model a = nominal(), b = nominal();
    rc_solve_config cfg;
    rc_solve_result ra, rb;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_METHOD_LM;
    assert_int_equal(rc_solve(&a, &ra, &w, &cfg, f->train, N_TRAIN), RC_OK);
    const size_t need = rc_solve_work_size(b.n_params, N_TRAIN);
    assert_true(need > rc_solve_work_size(b.n_params, 0));
    double *buf = malloc(need);
    assert_non_null(buf);
    assert_int_equal(rc_solve_buf(&b, &rb, buf, need, &cfg, f->train, N_TRAIN), RC_OK);
    assert_memory_equal(a.x, b.x, sizeof a.x);
    assert_int_equal(ra.iterations, rb.iterations);
    /* too small a workspace: refused, the model untouched */
    rc_model c = nominal();
    assert_int_equal(rc_solve_buf(&c, &rb, buf, rc_solve_work_size(c.n_params, 0) - 1, &cfg, f->train, N_TRAIN),
                     RC_ERR_CAPACITY);
    rc_model d = nominal();
    assert_memory_equal(c.x, d.x, sizeof c.x);
    free(buf);
}

static void test_nothing_free(void **state)
{
    const fixture *f = *state;
    static rc_solve_work w;
    rc_model m = nominal();
    uint8_t fixed[RC_MAX_PARAMS];
    rc_solve_config cfg;
    memset(fixed, 1, sizeof fixed);
    memset(&cfg, 0, sizeof cfg);
    cfg.fixed = fixed;
    assert_int_equal(rc_solve(&m, NULL, &w, &cfg, f->train, N_TRAIN), RC_ERR_RANK);
}

static void test_cost_tab_and_gradient(void **state)
{
    const fixture *f = *state;
    rc_model m = nominal();
    static double sq[N_TRAIN * 6], cq[N_TRAIN * 6];
    double c0, c1, A[RC_MAX_PARAMS * RC_MAX_PARAMS], gr[RC_MAX_PARAMS], cost, jrow[RC_MAX_PARAMS];
    uint16_t idx[RC_MAX_PARAMS];
    rc_qtrig_fill(sq, cq, f->train, N_TRAIN);
    assert_int_equal(rc_cost(&c0, &m, f->train, N_TRAIN), RC_OK);
    assert_int_equal(rc_cost_tab(&c1, &m, f->train, sq, cq, N_TRAIN), RC_OK);
    assert_memory_equal(&c0, &c1, sizeof c0);
    for (unsigned k = 0; k < m.n_params; ++k)
        idx[k] = (uint16_t)k;
    assert_int_equal(rc_normal_eq(A, gr, &cost, jrow, &m, idx, m.n_params, f->train, N_TRAIN), RC_OK);
    assert_true(fabs(cost - c0) <= 1e-9 * c0);
    for (unsigned k = 0; k < m.n_params; ++k) { /* d cost / d x_k = 2 (J^T r)_k */
        const double h = k % 4 < 2 || k >= 24 ? 1e-4 : 1e-7;
        rc_model p = m, q = m;
        double cp, cm;
        p.x[k] += h;
        q.x[k] -= h;
        assert_int_equal(rc_cost(&cp, &p, f->train, N_TRAIN), RC_OK);
        assert_int_equal(rc_cost(&cm, &q, f->train, N_TRAIN), RC_OK);
        const double fd = (cp - cm) / (2.0 * h);
        if (fabs(fd - 2.0 * gr[k]) > 1e-5 * (fabs(fd) + 1.0))
            fail_msg("parameter %u: d cost/dx %.9g by differences, 2 J^T r %.9g", k, fd, 2.0 * gr[k]);
        assert_true(A[k * m.n_params + k] >= 0.0); /* J^T J's diagonal */
    }
}

static void test_certain_prior_holds(void **state)
{
    const fixture *f = *state;
    static rc_solve_work w;
    rc_model m = nominal();
    const rc_model m0 = nominal();
    double sd[RC_MAX_PARAMS];
    rc_solve_config cfg;
    for (unsigned k = 0; k < m.n_params; ++k)
        sd[k] = k == 1 ? 1e-9 : 1.0; /* d1 certain, every other value free to move */
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_METHOD_LM;
    cfg.prior_mean = m0.x;
    cfg.prior_sd = sd;
    cfg.prior_noise_mm = NOISE_MM;
    assert_true(rc_prior_cost(&m, &cfg) == 0.0);
    assert_int_equal(rc_solve(&m, NULL, &w, &cfg, f->train, N_TRAIN), RC_OK);
    assert_true(fabs(m.x[1] - m0.x[1]) < 1e-6);     /* held at the prior's mean */
    assert_true(fabs(m.x[0] - m0.x[0]) > 1e-3);     /* a1 moved: the data wanted it */
    assert_true(rc_prior_cost(&m, &cfg) < 1.0);     /* the prior's share of the cost stays small */
}

/* rc_est's methods from the same start: SSLM (a gradient method) reaches the
 * noise as rc_solve does; the EKF reduces the error tenfold in its passes; a
 * population method (SCA; the paper's own tables put them far behind LM)
 * at least halves it and never ends worse than it started. */
static void test_est_methods(void **state)
{
    const fixture *f = *state;
    static rc_est_work w;
    const rc_model start = nominal();
    const double before = test_rms(&start, f);
    const rc_est_method methods[] = {RC_EST_SSLM, RC_EST_EKF, RC_EST_SCA};
    for (size_t k = 0; k < sizeof methods / sizeof methods[0]; ++k) {
        rc_model m = start;
        rc_est_config cfg;
        rc_est_result res;
        memset(&cfg, 0, sizeof cfg);
        cfg.method = methods[k];
        cfg.seed = 11;
        cfg.noise_mm = NOISE_MM;
        assert_int_equal(rc_est_solve(&m, &res, &w, &cfg, f->train, N_TRAIN), RC_OK);
        const double held = test_rms(&m, f);
        if (methods[k] == RC_EST_SSLM)
            check_fit(&m, res.rms_final_mm, f, "sslm");
        else if (!(held < before / (methods[k] == RC_EST_EKF ? 10.0 : 2.0) && res.rms_final_mm < res.rms_start_mm))
            fail_msg("method %d: held-out %.4f mm from %.4f mm", (int)methods[k], held, before);
        assert_true(res.n_moved > 0 && res.n_moved <= res.n_free);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_own_fk_matches),
        cmocka_unit_test(test_lm_and_ltlm_recover),
        cmocka_unit_test(test_buf_equals_solve),
        cmocka_unit_test(test_nothing_free),
        cmocka_unit_test(test_cost_tab_and_gradient),
        cmocka_unit_test(test_certain_prior_holds),
        cmocka_unit_test(test_est_methods),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
