/* SPDX-License-Identifier: MIT */
/* rc_problem (issue 50 item 1): the solver on a problem that is not a robot.
 * A straight line y = a + b t seen by two sensors of different dimension
 * (a scalar block: y at t_i; a 2-D block: (a + b s_j, a - b s_j) at s_j) and
 * a prior block on b: the MAP answer is the linear one, solved here in closed
 * form from the same numbers (2 x 2 normal equations by Cramer's rule).
 * Beside it: a parameter no row sees, marked inert, keeps its value to the
 * last bit; a fixed parameter stays; the robot's problem splits cable lengths
 * and tracker positions into blocks of dimension 1 and 3 whose cost is
 * rc_cost's; the method table is the one list of names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rc_problem.h"
#include "rc_rand.h"
#include "rc_solve.h"
#include "rct_irb120.h"

enum { N1 = 7, N2 = 5, NP = 3 };

typedef struct line_data {
    double t[N1], y[N1];        /* the scalar sensor */
    double s[N2], u[N2], v[N2]; /* the 2-D sensor: u = a + b s, v = a - b s */
    double x[NP];               /* the point of the pass (prepare) */
    unsigned passes;
} line_data;

static rc_status line_prepare(void *ctx, const double *x)
{
    line_data *d = ctx;
    memcpy(d->x, x, sizeof d->x);
    ++d->passes;
    return RC_OK;
}

static rc_status rows_scalar(double *r, double *jac, void *ctx, size_t i)
{
    const line_data *d = ctx;
    r[0] = d->x[0] + d->x[1] * d->t[i] - d->y[i];
    if (jac != NULL) {
        jac[0] = 1.0;
        jac[1] = d->t[i];
        jac[2] = 0.0;
    }
    return RC_OK;
}

static rc_status rows_pair(double *r, double *jac, void *ctx, size_t j)
{
    const line_data *d = ctx;
    r[0] = d->x[0] + d->x[1] * d->s[j] - d->u[j];
    r[1] = d->x[0] - d->x[1] * d->s[j] - d->v[j];
    if (jac != NULL) {
        const double J[2 * NP] = {1.0, d->s[j], 0.0, 1.0, -d->s[j], 0.0};
        memcpy(jac, J, sizeof J);
    }
    return RC_OK;
}

static void make_data(line_data *d, double a, double b, double noise, uint64_t seed)
{
    rc_rng g;
    rc_rng_seed(&g, seed);
    memset(d, 0, sizeof *d);
    for (unsigned i = 0; i < N1; ++i) {
        d->t[i] = 0.5 * i - 1.0;
        d->y[i] = a + b * d->t[i] + noise * rc_rng_normal(&g);
    }
    for (unsigned j = 0; j < N2; ++j) {
        d->s[j] = 0.3 * j + 0.2;
        d->u[j] = a + b * d->s[j] + noise * rc_rng_normal(&g);
        d->v[j] = a - b * d->s[j] + noise * rc_rng_normal(&g);
    }
}

/* The closed-form MAP of (a, b): minimise the rows' squares plus
 * w (b - mean_b)^2, w = (noise_p / sd_b)^2. */
static void closed_form(double *a, double *b, const line_data *d, double w, double mean_b)
{
    double S11 = 0, S12 = 0, S22 = 0, r1 = 0, r2 = 0;
    for (unsigned i = 0; i < N1; ++i) {
        S11 += 1;
        S12 += d->t[i];
        S22 += d->t[i] * d->t[i];
        r1 += d->y[i];
        r2 += d->t[i] * d->y[i];
    }
    for (unsigned j = 0; j < N2; ++j) {
        S11 += 2;
        S12 += d->s[j] - d->s[j];
        S22 += 2 * d->s[j] * d->s[j];
        r1 += d->u[j] + d->v[j];
        r2 += d->s[j] * (d->u[j] - d->v[j]);
    }
    S22 += w;
    r2 += w * mean_b;
    const double det = S11 * S22 - S12 * S12;
    *a = (r1 * S22 - S12 * r2) / det;
    *b = (S11 * r2 - S12 * r1) / det;
}

static void line_problem(rc_problem *p, rc_block bl[2], line_data *d)
{
    memset(p, 0, sizeof *p);
    bl[0] = (rc_block){rows_scalar, d, 0, N1, 1, "mm"};
    bl[1] = (rc_block){rows_pair, d, 0, N2, 2, "mm"};
    p->n_params = NP;
    p->n_blocks = 2;
    p->blocks = bl;
    p->prepare = line_prepare;
    p->prepare_ctx = d;
}

static double work[8192];

static void test_two_blocks_and_prior(void **state)
{
    (void)state;
    line_data d;
    rc_block bl[2];
    rc_problem p;
    make_data(&d, 3.0, -1.5, 0.05, 11);
    line_problem(&p, bl, &d);
    static const uint8_t inert[NP] = {0, 0, 1};
    const double mean[NP] = {0.0, -1.0, 0.0}, sd[NP] = {0.0, 0.2, 0.0};
    p.inert = inert;
    p.prior = (rc_prior_block){mean, sd, 0.05};
    assert_int_equal(rc_problem_rows(&p), N1 + 2 * N2);
    assert_true(rc_problem_work_size(NP) <= sizeof work);
    assert_int_equal(rc_problem_work_size(0), 0);

    double x[NP] = {0.0, 0.0, 0.123456789};
    rc_solve_result res;
    assert_int_equal(rc_problem_solve(x, &res, work, sizeof work, NULL, &p), RC_OK);
    double a, b;
    const double w = (0.05 / 0.2) * (0.05 / 0.2);
    closed_form(&a, &b, &d, w, -1.0);
    print_message("MAP line: a %.12f b %.12f, closed form a %.12f b %.12f (%u passes, exit %s)\n", x[0], x[1], a, b,
                  d.passes, rc_exit_str(res.exit));
    assert_true(fabs(x[0] - a) < 1e-9);
    assert_true(fabs(x[1] - b) < 1e-9);
    assert_true(x[2] == 0.123456789); /* inert: no row sees it, it left the free set */
    assert_int_equal(res.n_free, NP);
    /* the prior pulled b towards its mean: the answer without it differs */
    double a0, b0;
    closed_form(&a0, &b0, &d, 0.0, 0.0);
    assert_true(fabs(b0 - b) > 1e-4);

    /* the cost at the answer: the rows' squares, the prior's apart */
    double c;
    assert_int_equal(rc_problem_cost(&c, &p, x), RC_OK);
    double e = 0.0;
    for (unsigned i = 0; i < N1; ++i)
        e += (a + b * d.t[i] - d.y[i]) * (a + b * d.t[i] - d.y[i]);
    for (unsigned j = 0; j < N2; ++j)
        e += (a + b * d.s[j] - d.u[j]) * (a + b * d.s[j] - d.u[j]) +
             (a - b * d.s[j] - d.v[j]) * (a - b * d.s[j] - d.v[j]);
    assert_true(fabs(c - e) < 1e-9 * e);
    assert_true(fabs(rc_problem_prior_cost(&p, x) - w * (x[1] + 1.0) * (x[1] + 1.0)) < 1e-15);
    assert_true(fabs(res.rms_final_mm - sqrt(c / (N1 + 2 * N2))) < 1e-9);
}

static void test_exact_fixed_and_methods(void **state)
{
    (void)state;
    line_data d;
    rc_block bl[2];
    rc_problem p;
    make_data(&d, -2.0, 0.75, 0.0, 5);
    line_problem(&p, bl, &d);
    static const uint8_t inert[NP] = {0, 0, 1};
    p.inert = inert;
    /* exact data, no prior: LM and LTLM reach the line itself */
    for (int mt = RC_METHOD_LM; mt <= RC_METHOD_LTLM; ++mt) {
        double x[NP] = {1.0, 1.0, 0.0};
        rc_solve_opts o;
        memset(&o, 0, sizeof o);
        o.method = (rc_method)mt;
        o.seed = 3;
        o.tol_cost = 1e-15;
        assert_int_equal(rc_problem_solve(x, NULL, work, sizeof work, &o, &p), RC_OK);
        assert_true(fabs(x[0] + 2.0) < 1e-9 && fabs(x[1] - 0.75) < 1e-9);
    }
    /* b fixed at 0.5: a is the mean of what remains, (sum y - 0.5 sum t + sum u + sum v) / (N1 + 2 N2) */
    uint8_t fixed[NP] = {0, 1, 0};
    p.fixed = fixed;
    double x[NP] = {0.0, 0.5, 0.0}, sum = 0.0;
    rc_solve_opts tight;
    memset(&tight, 0, sizeof tight);
    tight.tol_cost = 1e-15; /* the robust LM's first step is damped: run it to the end, */
    tight.snr_min = -1.0;   /* past steps smaller than the residual's noise */
    for (unsigned i = 0; i < N1; ++i)
        sum += d.y[i] - 0.5 * d.t[i];
    for (unsigned j = 0; j < N2; ++j)
        sum += d.u[j] - 0.5 * d.s[j] + d.v[j] + 0.5 * d.s[j];
    assert_int_equal(rc_problem_solve(x, NULL, work, sizeof work, &tight, &p), RC_OK);
    assert_true(x[1] == 0.5);
    print_message("b fixed: a %.12f, closed form %.12f\n", x[0], sum / (N1 + 2 * N2));
    assert_true(fabs(x[0] - sum / (N1 + 2 * N2)) < 1e-9);
    /* nothing free: refused; a workspace too small: refused */
    uint8_t all[NP] = {1, 1, 1};
    p.fixed = all;
    assert_int_equal(rc_problem_solve(x, NULL, work, sizeof work, NULL, &p), RC_ERR_RANK);
    p.fixed = NULL;
    assert_int_equal(rc_problem_solve(x, NULL, work, rc_problem_work_size(NP) - 8, NULL, &p), RC_ERR_CAPACITY);
}

/* The robot's problem: 2 lengths, 2 tracker positions (3 samples each), 1
 * length -> blocks of dimension 1, 3, 1 with 2, 2, 1 items; its cost is
 * rc_cost's, its normal equations rc_normal_eq's. */
static void test_robot_blocks(void **state)
{
    (void)state;
    double dh[6][4];
    const double enc[3] = {300.0, -400.0, 0.0};
    rc_model m;
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(&m, (const double(*)[4])dh, enc), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TRACKER_TARGETS, 0, 3), RC_OK);
    m.x[m.n_params - 3] = 10.0;
    rc_sample s[9];
    memset(s, 0, sizeof s);
    rc_rng g;
    rc_rng_seed(&g, 7);
    for (unsigned k = 0; k < 9; ++k) {
        const unsigned pose = k < 2 ? k : k < 8 ? 2 + (k - 2) / 3 : 4;
        rc_rng_seed(&g, 100 + pose);
        for (unsigned j = 0; j < RC_NJ; ++j)
            s[k].q_rad[j] = 0.5 * (rc_rng_u01(&g) - 0.5);
        s[k].sensor = k >= 2 && k < 8 ? (uint8_t)(RC_SENSOR_TRACKER_X + (k - 2) % 3) : RC_SENSOR_LENGTH;
        s[k].value = 500.0 + k;
    }
    rc_problem p;
    rc_model_rows r;
    rc_model_problem(&p, &r, &m, NULL, s, 9, NULL, NULL, NULL, RC_MAX_BLOCK_DIM);
    assert_int_equal(p.n_blocks, 3);
    assert_int_equal(p.blocks[0].dim, 1);
    assert_int_equal(p.blocks[0].n, 2);
    assert_int_equal(p.blocks[1].dim, 3);
    assert_int_equal(p.blocks[1].n, 2);
    assert_int_equal(p.blocks[2].dim, 1);
    assert_int_equal(p.blocks[2].n, 1);
    assert_string_equal(p.blocks[1].unit, "mm");
    assert_int_equal(rc_problem_rows(&p), 9);
    assert_true(p.inert[RC_P_ALPHA(RC_NJ - 1)] && !p.inert[RC_P_ALPHA(0)]);
    double c1, c2;
    assert_int_equal(rc_problem_cost(&c1, &p, m.x), RC_OK);
    assert_int_equal(rc_cost(&c2, &m, s, 9), RC_OK);
    assert_true(c1 == c2);
    /* the normal equations over the blocks (rows of dimension 3 among them) are rc_normal_eq's */
    static double A1[RC_MAX_PARAMS * RC_MAX_PARAMS], A2[RC_MAX_PARAMS * RC_MAX_PARAMS], jrow[3 * RC_MAX_PARAMS],
        jblk[4 * RC_MAX_PARAMS];
    double g1[RC_MAX_PARAMS], g2[RC_MAX_PARAMS];
    uint16_t idx[RC_MAX_PARAMS];
    for (unsigned k = 0; k < m.n_params; ++k)
        idx[k] = (uint16_t)k;
    assert_int_equal(rc_problem_normal_eq(A1, g1, &c1, jrow, jblk, &p, m.x, idx, m.n_params), RC_OK);
    assert_int_equal(rc_normal_eq(A2, g2, &c2, jrow, &m, idx, m.n_params, s, 9), RC_OK);
    assert_true(c1 == c2);
    assert_memory_equal(A1, A2, (size_t)m.n_params * m.n_params * sizeof A1[0]);
    assert_memory_equal(g1, g2, m.n_params * sizeof g1[0]);
}

static void test_method_table(void **state)
{
    (void)state;
    static const char *const choices = RC_METHOD_CHOICES;
    assert_string_equal(choices, "lm|ltlm|lm-paper|ltlm-paper|lm-paper-deg|ltlm-paper-deg");
    assert_string_equal(RC_METHOD_LIST, "lm, ltlm, lm-paper, ltlm-paper, lm-paper-deg, ltlm-paper-deg");
    for (unsigned k = 0; k < RC_METHOD_COUNT_; ++k) {
        const rc_method_desc *d = rc_method_describe(k);
        rc_method back;
        assert_non_null(d);
        assert_int_equal(d->method, k);
        assert_int_equal(rc_method_from_name(&back, d->name), RC_OK);
        assert_int_equal(back, k);
        assert_int_equal(d->paper, strstr(d->name, "paper") != NULL);
        assert_int_equal(d->ltlm, strncmp(d->name, "ltlm", 4) == 0);
        assert_int_equal(d->deg, strstr(d->name, "-deg") != NULL);
    }
    assert_null(rc_method_describe(RC_METHOD_COUNT_));
    assert_string_equal(rc_method_name((rc_method)RC_METHOD_COUNT_), "unknown");
}

/* The effects' one list: every kind described under its own number, every
 * name its kind's; a length with every length-side effect has the same value
 * with and without its Jacobian (one function per effect does both). */
static void test_effect_list(void **state)
{
    (void)state;
    assert_int_equal(RC_EFF_LAST, RC_EFF_COUNT_ - 1);
    assert_null(rc_effect_describe(RC_EFF_NONE));
    assert_null(rc_effect_describe(RC_EFF_COUNT_));
    for (unsigned k = 1; k <= RC_EFF_LAST; ++k) {
        const rc_effect_desc *d = rc_effect_describe(k);
        assert_non_null(d);
        assert_int_equal(d->kind, k);
        assert_int_equal(rc_effect_by_name(d->name), (int)k);
        assert_string_equal(rc_effect_name((rc_effect_kind)k), d->name);
    }
    double dh[6][4];
    const double enc[3] = {300.0, -400.0, 0.0};
    rc_model m;
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(&m, (const double(*)[4])dh, enc), RC_OK);
    static const rc_effect_kind len_side[] = {RC_EFF_LENGTH_OFFSET, RC_EFF_LENGTH_SCALE, RC_EFF_CABLE_SAG,
                                              RC_EFF_LENGTH_NONLIN, RC_EFF_LENGTH_PERIODIC, RC_EFF_TOOL_OFFSET};
    for (unsigned k = 0; k < sizeof len_side / sizeof len_side[0]; ++k)
        assert_int_equal(rc_model_add_effect(&m, len_side[k], 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TIME_DRIFT, 0, 2), RC_OK);
    for (unsigned k = RC_N_BASE; k < m.n_params; ++k)
        m.x[k] = 1e-3 * (double)(k - RC_N_BASE + 1);
    m.x[RC_N_BASE + 1 + 1 + 1 + 2 + 2] = 250.0; /* the drum's period */
    rc_sample s;
    memset(&s, 0, sizeof s);
    s.q_rad[1] = 0.3;
    s.q_rad[2] = -0.2;
    s.t = 0.4;
    double l1, l2, jac[RC_MAX_PARAMS];
    assert_int_equal(rc_meas(&l1, NULL, &m, &s), RC_OK);
    assert_int_equal(rc_meas(&l2, jac, &m, &s), RC_OK);
    assert_true(l1 == l2);
    assert_true(jac[RC_N_BASE] == 1.0); /* length_offset */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_blocks_and_prior),
        cmocka_unit_test(test_exact_fixed_and_methods),
        cmocka_unit_test(test_robot_blocks),
        cmocka_unit_test(test_method_table),
        cmocka_unit_test(test_effect_list),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
