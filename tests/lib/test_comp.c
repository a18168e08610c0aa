/* SPDX-License-Identifier: MIT */
/* test_comp.c - compensation of joint targets (rc_comp): accuracy on a
 * simulated truth (given and identified from cable lengths), singular poses,
 * joint limits, non-convergence, bad input, the stream, inverse kinematics,
 * the compiled table (rc_kin) against the solver model, counters that wrap.
 *
 * Built twice: with rc_real = double (comp_core) and with -DRC_REAL_FLOAT
 * (comp_core_float). The compensation's inputs and outputs are rc_real; the
 * checks evaluate the solver model (rc_model, double) at those joints, so a
 * float build is judged by the same double-precision truth. Tolerances that
 * depend on the type are TOL_* below. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_comp.h"
#include "rc_rand.h"
#include "rc_solve.h"
#include "rct_irb120.h"

#define DEG (3.14159265358979323846 / 180.0)

/* What rc_real resolves: positions to ~1e-5 mm in double (the default
 * tolerance), to a few 1e-3 mm in float (RC_COMP_TOL_MM = 2^15 eps). */
#if RC_REAL_IS_FLOAT
#define TOL_POS 1e-2  /* mm, flange position reached */
#define TOL_ROT 5e-5  /* rad */
#define TOL_Q 1e-6    /* rad, joint values compared after float arithmetic */
#else
#define TOL_POS 1e-4
#define TOL_ROT 1e-6
#define TOL_Q 1e-12
#endif

/* rc_real <-> double joint vectors */
static void q_to_real(rc_real out[RC_NJ], const double q[RC_NJ])
{
    for (int i = 0; i < RC_NJ; ++i)
        out[i] = (rc_real)q[i];
}

/* rc_fk of the solver model at rc_real joints */
static void fk_r(double p[3], double R[9], const rc_model *m, const rc_real q[RC_NJ])
{
    double qd[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        qd[i] = (double)q[i];
    rc_fk(p, R, m, qd);
}

static const double enc_mm[3] = {600, -300, 50};

static void make_nominal(rc_model *m)
{
    double dh[RC_NJ][4];
    rct_irb120_dh(dh);
    assert_int_equal(rc_model_init(m, (const double(*)[4])dh, enc_mm), RC_OK);
    for (int i = 0; i < RC_NJ; ++i) {
        m->q_min_rad[i] = rct_irb120_lim_deg[i][0] * DEG;
        m->q_max_rad[i] = rct_irb120_lim_deg[i][1] * DEG;
    }
}

/* truth = nominal + N(0, len) on a, d and N(0, ang) on alpha, theta. */
static void make_truth(rc_model *t, const rc_model *nom, double len_mm, double ang_deg, uint64_t seed)
{
    rc_rng g;
    rc_rng_seed(&g, seed);
    *t = *nom;
    for (int k = 0; k < RC_N_DH; ++k)
        t->x[k] += (k % 4 < 2 ? len_mm : ang_deg * DEG) * rc_rng_normal(&g);
}

/* A random pose inside the limits, kept away from the three singularities
 * as a robot program is: the wrist (q5 = 0), the stretched elbow (q3 = -77
 * deg, the workspace boundary) and the wrist centre over axis 1 (closer than
 * 100 mm). */
static void random_pose_d(double q[RC_NJ], rc_rng *g)
{
    static const double lo[RC_NJ] = {-120, -60, -62, -120, -100, -180};
    static const double hi[RC_NJ] = {120, 80, 50, 120, 100, 180};
    rc_model nom;
    make_nominal(&nom);
    for (;;) {
        double p[3], R[9];
        for (int i = 0; i < RC_NJ; ++i)
            q[i] = (lo[i] + (hi[i] - lo[i]) * rc_rng_u01(g)) * DEG;
        if (fabs(q[4]) < 10 * DEG)
            q[4] = (q[4] < 0 ? -10 : 10) * DEG;
        rc_fk(p, R, &nom, q);
        const double wx = p[0] - 72.0 * R[2], wy = p[1] - 72.0 * R[5];
        if (wx * wx + wy * wy > 100.0 * 100.0)
            return;
    }
}

/* The same pose as rc_real (the value the compensation receives). */
static void random_pose(rc_real q[RC_NJ], rc_rng *g)
{
    double qd[RC_NJ];
    random_pose_d(qd, g);
    q_to_real(q, qd);
}

static double dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static double rot_angle(const double A[9], const double B[9])
{
    double tr = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k)
            tr += A[3 * r + k] * B[3 * r + k];
    double c = 0.5 * (tr - 1.0);
    c = c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c);
    return acos(c);
}

static void assert_finite_q(const rc_real q[RC_NJ])
{
    for (int i = 0; i < RC_NJ; ++i)
        assert_true(isfinite(q[i]));
}

static void assert_in_limits(const rc_model *m, const rc_real q[RC_NJ])
{
    for (int i = 0; i < RC_NJ; ++i) {
        assert_true(q[i] >= (rc_real)m->q_min_rad[i]);
        assert_true(q[i] <= (rc_real)m->q_max_rad[i]);
    }
}

/* With the true model as the calibrated one, the true robot lands on the
 * nominal targets to far better than 0.05 mm, where uncompensated it is off
 * by millimetres. Orientation is matched too. */
static void test_truth_model_compensates(void **state)
{
    (void)state;
    rc_model nom, truth;
    rc_rng g;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 11);
    rc_rng_seed(&g, 5);
    double sum_unc = 0.0, max_comp = 0.0, max_rot = 0.0;
    unsigned iters = 0;
    const int n = 300;
    for (int k = 0; k < n; ++k) {
        rc_real q[RC_NJ], qc[RC_NJ];
        double pn[3], Rn[9], pt[3], Rt[9], pu[3];
        rc_comp_result res;
        random_pose(q, &g);
        fk_r(pn, Rn, &nom, q);
        fk_r(pu, NULL, &truth, q);
        sum_unc += dist3(pu, pn);
        assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, NULL), RC_OK);
        assert_int_equal(res.exit, RC_COMP_CONVERGED);
        assert_in_limits(&truth, qc);
        fk_r(pt, Rt, &truth, qc);
        max_comp = fmax(max_comp, dist3(pt, pn));
        max_rot = fmax(max_rot, rot_angle(Rt, Rn));
        assert_true(res.pos_err_mm <= RC_COMP_TOL_MM);
        iters += res.iterations;
    }
    assert_true(sum_unc / n > 1.0);   /* off by millimetres */
    assert_true(max_comp < TOL_POS);  /* well inside 0.05 mm */
    assert_true(max_rot < TOL_ROT);
    assert_true(iters <= 4u * (unsigned)n); /* Newton: a few iterations each */
}

/* End to end: identify the model from simulated cable lengths with rc_solve
 * (encoder outlet known), then compensate with the identified model. */
static void test_identified_model_compensates(void **state)
{
    (void)state;
    static rc_solve_work w;
    static rc_sample s[240];
    static uint8_t fixed[RC_MAX_PARAMS];
    rc_model nom, truth, cal;
    rc_rng g;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 23);
    rc_rng_seed(&g, 7);
    for (size_t i = 0; i < sizeof s / sizeof s[0]; ++i) {
        random_pose_d(s[i].q_rad, &g);
        s[i].t = 0.0;
        s[i].group = 0;
        s[i].outlet = 0;
        assert_int_equal(rc_meas(&s[i].value, NULL, &truth, &s[i]), RC_OK);
    }
    cal = nom;
    memset(fixed, 0, sizeof fixed);
    fixed[RC_P_ENC] = fixed[RC_P_ENC + 1] = fixed[RC_P_ENC + 2] = 1; /* outlet known */
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.fixed = fixed;
    rc_solve_result sr;
    assert_int_equal(rc_solve(&cal, &sr, &w, &cfg, s, sizeof s / sizeof s[0]), RC_OK);
    assert_true(sr.rms_final_mm < 1e-3);

    rc_rng_seed(&g, 99);
    double sum_unc = 0.0, max_comp = 0.0;
    const int n = 200;
    for (int k = 0; k < n; ++k) {
        rc_real q[RC_NJ], qc[RC_NJ];
        double pn[3], pt[3], pu[3];
        random_pose(q, &g);
        fk_r(pn, NULL, &nom, q);
        fk_r(pu, NULL, &truth, q);
        sum_unc += dist3(pu, pn);
        assert_int_equal(rc_comp_joint(qc, NULL, &cal, &nom, q, NULL, NULL), RC_OK);
        fk_r(pt, NULL, &truth, qc); /* where the true robot goes */
        max_comp = fmax(max_comp, dist3(pt, pn));
    }
    assert_true(sum_unc / n > 1.0);
    assert_true(max_comp < 0.05);
}

/* Wrist singularity (q5 = 0 and nearly 0), arm stretched, wrist centre on
 * axis 1: no NaN, joints within their box, position matched or flagged. */
static void test_singular_poses(void **state)
{
    (void)state;
    rc_model nom, truth;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 31);
    /* q3 where a3 and d4 line up with a2: elbow stretched */
    const rc_real q3_str = (rc_real)(-90 * DEG + atan2(70.0, 302.0));
    const rc_real poses[][RC_NJ] = {
        {0.3, 0.2, -0.4, 0.5, 0.0, -0.2},
        {0.3, 0.2, -0.4, 0.5, 1e-7, -0.2},
        {0.3, 0.2, -0.4, 0.0, 0.0, 0.0},
        {0.0, 0.1, q3_str, 0.2, 0.5, 0.1},
        {0.0, 0.0, q3_str, 0.0, 0.0, 0.0},
        {0.1, -0.3, 1.0, 0.0, 0.6, 0.0}, /* wrist centre near axis 1 */
    };
    for (size_t k = 0; k < sizeof poses / sizeof poses[0]; ++k) {
        for (unsigned flags = 0; flags < 2; ++flags) {
            rc_real qc[RC_NJ];
            double pn[3], pt[3];
            rc_comp_result res;
            rc_comp_config cfg;
            memset(&cfg, 0, sizeof cfg);
            cfg.flags = flags;
            rc_status st = rc_comp_joint(qc, &res, &truth, &nom, poses[k], NULL, &cfg);
            assert_finite_q(qc);
            assert_in_limits(&truth, qc);
            for (int i = 0; i < RC_NJ; ++i)
                assert_true(fabs((double)qc[i] - (double)poses[k][i]) <= 0.1 + TOL_Q);
            assert_true(isfinite(res.pos_err_mm) && isfinite(res.rot_err_rad));
            fk_r(pn, NULL, &nom, poses[k]);
            fk_r(pt, NULL, &truth, qc);
            if (st == RC_OK) {
                assert_true(dist3(pt, pn) < TOL_POS);
                assert_true(res.exit == RC_COMP_CONVERGED || res.exit == RC_COMP_POSITION_ONLY);
            } else {
                assert_int_equal(st, RC_ERR_NOCONV);
                assert_true(res.exit == RC_COMP_MAX_ITER || res.exit == RC_COMP_NO_DESCENT ||
                            res.exit == RC_COMP_JOINT_LIMIT || res.exit == RC_COMP_MAX_DEV);
            }
            /* the position is matched at every one of these poses */
            assert_true(dist3(pt, pn) < 0.05);
        }
    }
}

/* A target on the joint-2 limit whose correction points outside: joint 2
 * stays on its limit, the bound is reported; with position only the other
 * joints take over and the position is matched. */
static void test_joint_limit(void **state)
{
    (void)state;
    rc_model nom, truth;
    make_nominal(&nom);
    truth = nom;
    truth.x[RC_P_THETA(1)] -= 0.01; /* joint 2 reads 0.01 rad more than it is */
    const rc_real q[RC_NJ] = {RC_REAL_C(0.2), (rc_real)(110 * DEG), RC_REAL_C(-0.5), RC_REAL_C(0.3),
                              RC_REAL_C(0.8), RC_REAL_C(0.1)};
    rc_real qc[RC_NJ];
    double pn[3], pt[3];
    rc_comp_result res;
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);

    rc_status st = rc_comp_joint(qc, &res, &truth, &nom, q, NULL, &cfg);
    assert_finite_q(qc);
    assert_in_limits(&truth, qc);
    assert_true(res.bound_mask & 2u);
    assert_true(res.limit_mask & 2u);
    assert_true(qc[1] == (rc_real)truth.q_max_rad[1]);
    assert_true(st == RC_OK ? res.exit == RC_COMP_POSITION_ONLY : st == RC_ERR_NOCONV);

    cfg.flags = RC_COMP_FLAG_POSITION_ONLY;
    assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, &cfg), RC_OK);
    assert_int_equal(res.exit, RC_COMP_CONVERGED);
    assert_in_limits(&truth, qc);
    fk_r(pn, NULL, &nom, q);
    fk_r(pt, NULL, &truth, qc);
    assert_true(dist3(pt, pn) < TOL_POS);
}

/* A correction that only joint 1 can make, at joint 1's limit: the call
 * fails and names the joint limit (not the iteration limit), and the error
 * it reports is the error of the q_out it returned. Issue 12. */
static void test_joint_limit_named(void **state)
{
    (void)state;
    rc_model nom, truth;
    make_nominal(&nom);
    truth = nom;
    truth.x[RC_P_THETA(0)] -= 0.05; /* joint 1 turns 0.05 rad less than it reads */
    const rc_real q[RC_NJ] = {(rc_real)(165 * DEG), RC_REAL_C(0.3), RC_REAL_C(-0.2), RC_REAL_C(0.2),
                              RC_REAL_C(0.7), RC_REAL_C(0.1)};
    rc_real qc[RC_NJ];
    double pn[3], pt[3];
    rc_comp_result res;
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.flags = RC_COMP_FLAG_POSITION_ONLY;
    cfg.max_iter = 40;
    assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, &cfg), RC_ERR_NOCONV);
    rc_real qj[RC_NJ];
    memcpy(qj, qc, sizeof qj);
    const double err_joint = (double)res.pos_err_mm;
    assert_int_equal(res.exit, RC_COMP_JOINT_LIMIT);
    assert_true(res.limit_mask & 1u);
    assert_non_null(strstr(rc_comp_exit_str(res.exit), "joint limit"));
    fk_r(pn, NULL, &nom, q);
    fk_r(pt, NULL, &truth, qc);
    assert_true(fabs(dist3(pt, pn) - (double)res.pos_err_mm) < TOL_POS);
    assert_true(res.pos_err_mm > RC_REAL_C(1.0)); /* it really is off */

    /* no good correction yet (a jump): the stream writes the solver's
     * closest point, what a cold rc_comp_joint gives, and reports its error,
     * below that of the target itself (about 0.05 rad x the reach) */
    rc_comp_stream s;
    assert_int_equal(rc_comp_stream_init(&s, &truth, &nom, &cfg), RC_OK);
    assert_int_equal(rc_comp_stream_step(&s, qc, &res, q), RC_ERR_NOCONV);
    assert_memory_equal(qc, qj, sizeof qj);
    assert_int_equal(res.held_last, 0);
    fk_r(pt, NULL, &truth, qc);
    assert_true(fabs(dist3(pt, pn) - (double)res.pos_err_mm) < TOL_POS);
    assert_true(fabs((double)res.pos_err_mm - err_joint) < TOL_POS);
    fk_r(pt, NULL, &truth, q);
    assert_true((double)res.pos_err_mm < dist3(pt, pn));
    assert_int_equal(res.exit, RC_COMP_JOINT_LIMIT);
}

/* Not converging: one iteration only, and a target the model cannot reach
 * within max_dev. The call returns RC_ERR_NOCONV, the best point (closer than
 * the start), finite and within the box. */
static void test_nonconvergence(void **state)
{
    (void)state;
    rc_model nom, truth;
    make_nominal(&nom);
    make_truth(&truth, &nom, 2.0, 0.5, 41);
    const rc_real q[RC_NJ] = {RC_REAL_C(0.4), RC_REAL_C(0.3), RC_REAL_C(-0.3), RC_REAL_C(0.6), RC_REAL_C(0.9),
                              RC_REAL_C(-0.4)};
    rc_real qc[RC_NJ];
    double pn[3], pu[3], pt[3];
    rc_comp_result res;
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_iter = 1;
    cfg.max_step_rad = RC_REAL_C(0.002); /* one short step cannot get there, in float either */
    fk_r(pn, NULL, &nom, q);
    fk_r(pu, NULL, &truth, q);
    assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, &cfg), RC_ERR_NOCONV);
    assert_int_equal(res.exit, RC_COMP_MAX_ITER);
    assert_finite_q(qc);
    fk_r(pt, NULL, &truth, qc);
    assert_true(dist3(pt, pn) < dist3(pu, pn));
    assert_true(fabs(dist3(pt, pn) - (double)res.pos_err_mm) < (RC_REAL_IS_FLOAT ? 1e-3 : 1e-9));

    /* 100 mm of link error cannot be undone within 0.01 rad */
    rc_model bad = truth;
    bad.x[RC_P_A(1)] += 100.0;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = 0.01;
    cfg.max_iter = 30;
    assert_int_equal(rc_comp_joint(qc, &res, &bad, &nom, q, NULL, &cfg), RC_ERR_NOCONV);
    assert_int_equal(res.exit, RC_COMP_MAX_DEV); /* named as the bound it is */
    assert_finite_q(qc);
    for (int i = 0; i < RC_NJ; ++i)
        assert_true(fabs((double)qc[i] - (double)q[i]) <= 0.01 + TOL_Q);
    assert_true(res.bound_mask != 0u);
    fk_r(pu, NULL, &bad, q);
    fk_r(pt, NULL, &bad, qc);
    assert_true(dist3(pt, pn) < dist3(pu, pn));
}

static void test_bad_input(void **state)
{
    (void)state;
    rc_model nom, truth;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 3);
    rc_real qc[RC_NJ];
    rc_comp_result res;
    rc_real q[RC_NJ] = {RC_REAL_C(0.1), RC_REAL_C(0.2), (rc_real)NAN, RC_REAL_C(0.1), RC_REAL_C(0.5), RC_REAL_C(0.0)};
    assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, NULL), RC_ERR_RANGE);
    assert_int_equal(res.exit, RC_COMP_BAD_INPUT);
    for (int i = 0; i < RC_NJ; ++i)
        assert_true(qc[i] == RC_REAL_C(0.0));
    q[2] = RC_REAL_C(3.0); /* outside joint 3's limits */
    assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, NULL), RC_ERR_RANGE);
    assert_memory_equal(qc, q, sizeof q);
    q[2] = RC_REAL_C(0.0);
    q[0] = (rc_real)INFINITY;
    assert_int_equal(rc_comp_joint(qc, &res, &truth, &nom, q, NULL, NULL), RC_ERR_RANGE);

    /* a calibrated model with NaN in it: RC_ERR_NUMERIC, q unchanged */
    rc_model broken = truth;
    broken.x[RC_P_A(2)] = NAN;
    q[0] = RC_REAL_C(0.1);
    assert_int_equal(rc_comp_joint(qc, &res, &broken, &nom, q, NULL, NULL), RC_ERR_NUMERIC);
    assert_int_equal(res.exit, RC_COMP_NONFINITE);
    assert_memory_equal(qc, q, sizeof q);

    /* inverse use: non-finite target */
    const rc_real p_nan[3] = {(rc_real)NAN, 0, 500};
    assert_int_equal(rc_comp_pose(qc, &res, &truth, p_nan, NULL, q, NULL), RC_ERR_RANGE);
    assert_finite_q(qc);

    /* a stream on the broken model: every step RC_ERR_NUMERIC, q unchanged */
    rc_comp_stream s;
    assert_int_equal(rc_comp_stream_init(&s, &broken, &nom, NULL), RC_ERR_RANGE);
    assert_int_equal(rc_comp_stream_step(&s, qc, &res, q), RC_ERR_NUMERIC);
    assert_memory_equal(qc, q, sizeof q);
    assert_int_equal(s.n_fail, 1);
}

/* A smooth stream converges in about one iteration per target; a forced
 * failure gives q + the last good correction and the flag. */
static void test_stream(void **state)
{
    (void)state;
    rc_model nom, truth;
    rc_comp_stream s;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 17);
    assert_int_equal(rc_comp_stream_init(&s, &truth, &nom, NULL), RC_OK);
    unsigned iters = 0;
    rc_real last_dq[RC_NJ] = {0};
    const int n = 1000;
    for (int k = 0; k < n; ++k) {
        const double t = (double)k / 1000.0; /* one second at 1 kHz */
        rc_real q[RC_NJ], qc[RC_NJ];
        double pn[3], pt[3];
        rc_comp_result res;
        for (int i = 0; i < RC_NJ; ++i)
            q[i] = (rc_real)(0.5 * sin(2.0 * 3.14159265 * 0.5 * t + i) * (i == 4 ? 0.5 : 1.0) + (i == 4 ? 0.8 : 0.0));
        assert_int_equal(rc_comp_stream_step(&s, qc, &res, q), RC_OK);
        iters += res.iterations;
        fk_r(pn, NULL, &nom, q);
        fk_r(pt, NULL, &truth, qc);
        assert_true(dist3(pt, pn) < TOL_POS);
        for (int i = 0; i < RC_NJ; ++i)
            last_dq[i] = qc[i] - q[i];
    }
    assert_true(s.n_ok == (unsigned long)n && s.n_fail == 0);
    assert_true(iters <= 2u * (unsigned)n);

    /* force a failure on the path (the next cycle): one iteration,
     * impossible tolerance: the target plus the last good correction */
    s.cfg.max_iter = 1;
    s.cfg.tol_mm = RC_REAL_C(1e-30);
    rc_real q[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        q[i] = (rc_real)(0.5 * sin(2.0 * 3.14159265 * 0.5 * 1.0 + i) * (i == 4 ? 0.5 : 1.0) + (i == 4 ? 0.8 : 0.0));
    rc_real qc[RC_NJ];
    double pn[3], pt[3];
    rc_comp_result res;
    assert_int_equal(rc_comp_stream_step(&s, qc, &res, q), RC_ERR_NOCONV);
    for (int i = 0; i < RC_NJ; ++i)
        assert_true(qc[i] == q[i] + last_dq[i]);
    assert_int_equal(res.held_last, 1);
    assert_int_equal(s.fail_run, 1);
    assert_int_equal(s.n_fail, 1);
    /* the error reported is the error of what was output (issue 12) */
    fk_r(pn, NULL, &nom, q);
    fk_r(pt, NULL, &truth, qc);
    assert_true(fabs(dist3(pt, pn) - (double)res.pos_err_mm) < (RC_REAL_IS_FLOAT ? 1e-3 : 1e-9));
    /* a failure after a jump: the closest point found from the target itself
     * (what rc_comp_joint gives), never further off than the target */
    const rc_real qf[RC_NJ] = {RC_REAL_C(0.3), RC_REAL_C(0.1), RC_REAL_C(-0.2), RC_REAL_C(0.4), RC_REAL_C(0.9),
                               RC_REAL_C(0.2)};
    rc_real qj[RC_NJ];
    rc_comp_result rj;
    assert_int_equal(rc_comp_joint(qj, &rj, &truth, &nom, qf, NULL, &s.cfg), RC_ERR_NOCONV);
    assert_int_equal(rc_comp_stream_step(&s, qc, &res, qf), RC_ERR_NOCONV);
    assert_int_equal(res.held_last, 0);
    assert_memory_equal(qc, qj, sizeof qj);
    assert_int_equal(s.fail_run, 2);
    fk_r(pn, NULL, &nom, qf);
    fk_r(pt, NULL, &truth, qc);
    assert_true(fabs(dist3(pt, pn) - (double)res.pos_err_mm) < (RC_REAL_IS_FLOAT ? 1e-3 : 1e-9));
    fk_r(pt, NULL, &truth, qf);
    assert_true((double)res.pos_err_mm <= dist3(pt, pn));
}

/* A jump (the next target of a program, more than RC_COMP_WARM_RAD on a
 * joint) starts from the target itself: the stream then gives exactly what
 * a cold rc_comp_joint gives, whatever the previous target's correction;
 * on a path (small moves) the previous correction seeds the next. */
static void test_stream_jump_is_cold(void **state)
{
    (void)state;
    rc_model nom, truth;
    static rc_comp_stream s;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 23);
    assert_int_equal(rc_comp_stream_init(&s, &truth, &nom, NULL), RC_OK);
    uint32_t g = 99u;
    unsigned same = 0, n = 0, warm_iters = 0, cold_iters = 0;
    for (int k = 0; k < 60; ++k) {
        rc_real q[RC_NJ], qs[RC_NJ], qj[RC_NJ];
        for (int i = 0; i < RC_NJ; ++i) {
            g = g * 1664525u + 1013904223u;
            double u = (double)(g >> 8) / 16777216.0;
            q[i] = (rc_real)(nom.q_min_rad[i] * 0.6 + (nom.q_max_rad[i] - nom.q_min_rad[i]) * 0.6 * u);
        }
        if (fabs((double)q[4]) < 0.2)
            q[4] = RC_REAL_C(0.5);
        rc_comp_result rs, rj;
        rc_status a = rc_comp_stream_step(&s, qs, &rs, q);
        rc_status b = rc_comp_joint(qj, &rj, &truth, &nom, q, NULL, NULL);
        assert_int_equal(a, b);
        if (a != RC_OK)
            continue;
        ++n;
        same += memcmp(qs, qj, sizeof qs) == 0;
        /* a small move from here: seeded by this correction, fewer steps than cold */
        rc_real q2[RC_NJ], o1[RC_NJ], o2[RC_NJ];
        for (int i = 0; i < RC_NJ; ++i)
            q2[i] = q[i] + RC_REAL_C(0.001);
        rc_comp_result r1, r2;
        if (rc_comp_stream_step(&s, o1, &r1, q2) == RC_OK && rc_comp_joint(o2, &r2, &truth, &nom, q2, NULL, NULL) == RC_OK) {
            warm_iters += r1.iterations;
            cold_iters += r2.iterations;
        }
    }
    print_message("far targets: stream == cold solve at %u of %u; small moves: %u steps seeded, %u cold\n", same, n,
                  warm_iters, cold_iters);
    assert_true(n >= 50);
    assert_int_equal(same, n);
    assert_true(warm_iters < cold_iters);
}

/* The 32-bit counters wrap (documented), rc_comp_count_since counts across
 * the wrap, and the run of failures saturates instead of wrapping to 0. */
static void test_counters_wrap(void **state)
{
    (void)state;
    rc_model nom, truth;
    rc_comp_stream s;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 17);
    assert_int_equal(rc_comp_stream_init(&s, &truth, &nom, NULL), RC_OK);
    const rc_real q[RC_NJ] = {RC_REAL_C(0.3), RC_REAL_C(0.1), RC_REAL_C(-0.2), RC_REAL_C(0.4), RC_REAL_C(0.9),
                              RC_REAL_C(0.2)};
    const rc_real bad[RC_NJ] = {RC_REAL_C(0.3), RC_REAL_C(0.1), RC_REAL_C(3.0), RC_REAL_C(0.4), RC_REAL_C(0.9),
                                RC_REAL_C(0.2)};
    rc_real qc[RC_NJ];
    s.n_ok = UINT32_MAX - 1u; /* 49.7 days at 1 kHz */
    const uint32_t then = s.n_ok;
    for (int k = 0; k < 3; ++k)
        assert_int_equal(rc_comp_stream_step(&s, qc, NULL, q), RC_OK);
    assert_int_equal(s.n_ok, 1u); /* wrapped */
    assert_int_equal(rc_comp_count_since(s.n_ok, then), 3u);
    s.fail_run = UINT32_MAX - 1u;
    s.n_fail = UINT32_MAX;
    for (int k = 0; k < 3; ++k)
        assert_int_equal(rc_comp_stream_step(&s, qc, NULL, bad), RC_ERR_RANGE);
    assert_true(s.fail_run == UINT32_MAX); /* saturated, never back to 0 */
    assert_int_equal(s.n_fail, 2u);
}

/* The compiled table computes what the solver model computes: bit for bit
 * in double, to float rounding in float; with a tool offset, periodic joint
 * errors and joint compliance (chain rule through dtheta/dq). */
static void test_kin_matches_model(void **state)
{
    (void)state;
    rc_model m;
    rc_kin k;
    rc_kin_data d;
    rc_rng g;
    make_nominal(&m);
    make_truth(&m, &m, 0.5, 0.1, 29);
    assert_int_equal(rc_kin_compile(&k, &m), RC_OK);
    assert_int_equal(k.n_jeff, 0);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_PERIODIC, 2, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_LENGTH_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 1, 0), RC_OK);
    const double eff[] = {5.0, -3.0, 40.0, 1e-3, -2e-3, 5e-4, 1e-4, 7.0, 2e-3};
    for (unsigned i = 0; i < sizeof eff / sizeof eff[0]; ++i)
        m.x[RC_N_BASE + i] = eff[i];
    assert_int_equal(rc_kin_compile(&k, &m), RC_OK);
    assert_int_equal(k.n_jeff, 2);
    assert_int_equal(k.n_ref, 1);
    assert_true(k.has_tool);
    rc_rng_seed(&g, 3);
    for (int n = 0; n < 50; ++n) {
        double qd[RC_NJ], p[3], R[9], J[36];
        rc_real q[RC_NJ], pk[3], Rk[9], Jk[36];
        random_pose_d(qd, &g);
        q_to_real(q, qd);
        fk_r(p, R, &m, q);
        for (int i = 0; i < RC_NJ; ++i)
            qd[i] = (double)q[i];
        rc_fk_jac(p, R, J, &m, qd);
        rc_kin_fk_jac(pk, Rk, Jk, &d, &k, q);
#if RC_REAL_IS_FLOAT
        for (int i = 0; i < 3; ++i)
            assert_true(fabs((double)pk[i] - p[i]) < 2e-3);
        for (int i = 0; i < 9; ++i)
            assert_true(fabs((double)Rk[i] - R[i]) < 2e-6);
        for (int i = 0; i < 36; ++i) /* the lever's derivative uses another step in float */
            assert_true(fabs((double)Jk[i] - J[i]) < 2e-3 * (1.0 + fabs(J[i])));
#else
        assert_memory_equal(pk, p, sizeof p);
        assert_memory_equal(Rk, R, sizeof R);
        assert_memory_equal(Jk, J, sizeof J);
#endif
        rc_real pf[3];
        rc_kin_fk(pf, NULL, &d, &k, q);
        assert_memory_equal(pf, pk, sizeof pf);
    }
    /* three compliance effects do not fit RC_KIN_MAX_COMPLIANCE = 2 */
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 2, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&m, RC_EFF_JOINT_COMPLIANCE, 1, 0), RC_OK);
    assert_int_equal(rc_kin_compile(&k, &m), RC_ERR_CAPACITY);
    m.x[RC_P_D(3)] = NAN;
    assert_int_equal(rc_kin_compile(&k, &m), RC_ERR_RANGE);
}

/* Inverse use: pose -> joints on the nominal model from a distant seed
 * (full pose and position only), and the corrected target on the truth. */
static void test_pose_ik(void **state)
{
    (void)state;
    rc_model nom, truth;
    rc_rng g;
    make_nominal(&nom);
    make_truth(&truth, &nom, 0.5, 0.1, 19);
    rc_rng_seed(&g, 77);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_iter = 100;
    for (int k = 0; k < 50; ++k) {
        rc_real q[RC_NJ], seed[RC_NJ], qi[RC_NJ], pr[3], Rr[9];
        double p[3], R[9], p2[3], R2[9];
        rc_comp_result res;
        random_pose(q, &g);
        for (int i = 0; i < RC_NJ; ++i)
            seed[i] = (rc_real)((double)q[i] + 0.2 * (rc_rng_u01(&g) - 0.5));
        fk_r(p, R, &nom, q);
        for (int i = 0; i < 9; ++i) {
            if (i < 3)
                pr[i] = (rc_real)p[i];
            Rr[i] = (rc_real)R[i];
        }
        assert_int_equal(rc_comp_pose(qi, &res, &nom, pr, Rr, seed, &cfg), RC_OK);
        assert_int_equal(res.exit, RC_COMP_CONVERGED);
        fk_r(p2, R2, &nom, qi);
        assert_true(dist3(p, p2) < TOL_POS);
        assert_true(rot_angle(R, R2) < TOL_ROT);
        /* corrected target: the truth reaches the same pose */
        assert_int_equal(rc_comp_pose(qi, &res, &truth, pr, Rr, q, &cfg), RC_OK);
        fk_r(p2, R2, &truth, qi);
        assert_true(dist3(p, p2) < TOL_POS);
        assert_true(rot_angle(R, R2) < TOL_ROT);
        /* position only */
        assert_int_equal(rc_comp_pose(qi, &res, &truth, pr, NULL, seed, &cfg), RC_OK);
        fk_r(p2, NULL, &truth, qi);
        assert_true(dist3(p, p2) < TOL_POS);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_truth_model_compensates),
        cmocka_unit_test(test_identified_model_compensates),
        cmocka_unit_test(test_singular_poses),
        cmocka_unit_test(test_joint_limit),
        cmocka_unit_test(test_joint_limit_named),
        cmocka_unit_test(test_counters_wrap),
        cmocka_unit_test(test_kin_matches_model),
        cmocka_unit_test(test_nonconvergence),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_stream),
        cmocka_unit_test(test_stream_jump_is_cold),
        cmocka_unit_test(test_pose_ik),
    };
    print_message("rc_real = %s, sizeof(rc_kin) %zu B, sizeof(rc_comp_stream) %zu B\n", RC_REAL_NAME, sizeof(rc_kin),
                  sizeof(rc_comp_stream));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
