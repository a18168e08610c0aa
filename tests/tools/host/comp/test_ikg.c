/* SPDX-License-Identifier: MIT */
/* test_ikg.c - the general inverse kinematics (rch_ikg.h) against its own
 * forward kinematics: every branch of random poses of a UR5e (offset wrist)
 * and an IRB120 (spherical wrist, where the branch must be ABB's cfx and the
 * solution the closed form's), poses next to the wrist, elbow and shoulder
 * singularities, a seed's solution, and targets out of reach refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rch_ik.h"
#include "rch_ikg.h"
#include "rch_robot.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static rch_robot ur, abb;

/* random poses per tool of test_ur_every_branch: under AddressSanitizer a quarter (the sanitizer pass watches
 * the code paths, the Release ctest keeps the breadth; a branch proved absent runs the scans, 10 x slower
 * instrumented) */
#if defined(__SANITIZE_ADDRESS__)
#define N_EVERY 50
#else
#define N_EVERY 200
#endif

static int setup(void **state)
{
    (void)state;
    rch_diag d;
    assert_int_equal(rch_robot_load(&ur, RCAL_SOURCE_DIR "/data/ur5e.json", &d), 0);
    assert_int_equal(rch_robot_load(&abb, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    return 0;
}

static unsigned long long lcg = 12345;
static double urand(double lo, double hi)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(lcg >> 11) / 9007199254740992.0;
}

static double wrapd(double a)
{
    a = fmod(a, 2 * PI);
    return a > PI ? a - 2 * PI : a <= -PI ? a + 2 * PI : a;
}

/* position and orientation distance of the FK of q from (p, R) */
static void fk_err(double *e_mm, double *e_rad, const rch_ikg *ik, const double q[6], const double p[3],
                   const double R[9])
{
    double p2[3], R2[9];
    rch_ikg_fk(p2, R2, ik, q);
    *e_mm = sqrt((p2[0] - p[0]) * (p2[0] - p[0]) + (p2[1] - p[1]) * (p2[1] - p[1]) + (p2[2] - p[2]) * (p2[2] - p[2]));
    double m = 0;
    for (int k = 0; k < 9; ++k)
        m = fmax(m, fabs(R2[k] - R[k]));
    *e_rad = m;
}

static void random_q(double q[6], const rc_model *m)
{
    for (int i = 0; i < 6; ++i) {
        const double lo = fmax(m->q_min_rad[i], -PI), hi = fmin(m->q_max_rad[i], PI);
        q[i] = urand(lo, hi);
    }
}

/* UR5e: 8 solutions, one per branch, each meeting the pose; the solve of each
 * branch returns that branch, and the branch of the pose's own joints
 * returns them. */
static void test_ur_every_branch(void **state)
{
    (void)state;
    const double tool[3] = {10, -20, 150};
    for (int with_tool = 0; with_tool < 2; ++with_tool) {
        rch_ikg ik;
        assert_int_equal(rch_ikg_init(&ik, &ur.nominal, with_tool ? tool : NULL), RCH_IKG_OK);
        int full = 0;
        for (int n = 0; n < N_EVERY; ++n) {
            double q[6], p[3], R[9];
            random_q(q, &ur.nominal);
            rch_ikg_fk(p, R, &ik, q);
            double all[RCH_IKG_MAX_SOL][6];
            int br[RCH_IKG_MAX_SOL];
            const int ns = rch_ikg_all(all, br, &ik, p, R);
            assert_true(ns >= 1);
            int seen = 0;
            for (int k = 0; k < ns; ++k) {
                double em, er;
                fk_err(&em, &er, &ik, all[k], p, R);
                assert_true(em < 1e-6 && er < 1e-9);
                assert_int_equal(br[k], rch_ikg_branch(&ik, all[k]));
                assert_false(seen & (1 << br[k])); /* one solution per branch */
                seen |= 1 << br[k];
            }
            full += ns == 8;
            for (int b = 0; b < 8; ++b) {
                double qs[6];
                rch_ikg_info inf;
                const rch_ikg_status st = rch_ikg_solve(qs, &inf, &ik, p, R, b, NULL);
                if (!(seen & (1 << b))) {
                    assert_int_not_equal(st, RCH_IKG_OK);
                    continue;
                }
                assert_int_equal(st, RCH_IKG_OK);
                assert_int_equal(rch_ikg_branch(&ik, qs), b);
                assert_int_equal(inf.branch, b);
                double em, er;
                fk_err(&em, &er, &ik, qs, p, R);
                assert_true(em < 1e-6 && er < 1e-9);
            }
            double qs[6];
            assert_int_equal(rch_ikg_solve(qs, NULL, &ik, p, R, rch_ikg_branch(&ik, q), NULL), RCH_IKG_OK);
            for (int i = 0; i < 6; ++i)
                assert_true(fabs(wrapd(qs[i] - q[i])) < 1e-7);
        }
        /* most random poses of a UR-type arm have 8 (the rest 4 or 2) */
        assert_true(full >= N_EVERY * 6 / 10);
    }
}

/* A seed near a solution: one Newton run, that solution in the seed's turn. */
static void test_seed(void **state)
{
    (void)state;
    rch_ikg ik;
    assert_int_equal(rch_ikg_init(&ik, &ur.nominal, NULL), RCH_IKG_OK);
    for (int n = 0; n < 100; ++n) {
        double q[6], p[3], R[9], seed[6], qs[6];
        random_q(q, &ur.nominal);
        if (n % 2 && q[5] < 0)
            q[5] += 2 * PI; /* a turn other than (-pi, pi] (inside +-360 deg) */
        rch_ikg_fk(p, R, &ik, q);
        for (int i = 0; i < 6; ++i)
            seed[i] = q[i] + urand(-0.05, 0.05);
        /* a pose next to a singularity has another solution near q: not this test's */
        double all[RCH_IKG_MAX_SOL][6];
        const int ns = rch_ikg_all(all, NULL, &ik, p, R);
        double other = HUGE_VAL;
        for (int k = 0; k < ns; ++k) {
            double m = 0;
            for (int i = 0; i < 6; ++i)
                m = fmax(m, fabs(wrapd(all[k][i] - q[i])));
            if (m > 1e-6)
                other = fmin(other, m);
        }
        if (other < 0.5) {
            --n;
            continue;
        }
        rch_ikg_info inf;
        assert_int_equal(rch_ikg_solve(qs, &inf, &ik, p, R, RCH_IKG_ANY_BRANCH, seed), RCH_IKG_OK);
        assert_int_equal(inf.starts, 1);
        for (int i = 0; i < 6; ++i)
            assert_true(fabs(qs[i] - q[i]) < 1e-7);
    }
}

/* IRB120: the general branch is ABB's cfx, and each branch's solution is the
 * closed form's of that cfx. */
static void test_abb_is_closed_form(void **state)
{
    (void)state;
    rch_ikg ik;
    assert_int_equal(rch_ikg_init(&ik, &abb.nominal, NULL), RCH_IKG_OK);
    for (int n = 0; n < 200; ++n) {
        double q[6], p[3], R[9], quat[4];
        random_q(q, &abb.nominal);
        int cf[4];
        rch_ik_confdata(cf, &abb.nominal, q);
        assert_int_equal(rch_ikg_branch(&ik, q), cf[3]);
        rch_ik_fk(p, quat, NULL, &abb.nominal, q, NULL);
        rch_ikg_fk(p, R, &ik, q);
        double all[8][6];
        const int na = rch_ik_all(all, &abb.nominal, p, quat, NULL);
        for (int k = 0; k < na; ++k) {
            int c[4];
            rch_ik_confdata(c, &abb.nominal, all[k]);
            double qs[6];
            /* the closed form's own joint limits aside: compare in (-pi, pi] */
            rch_ikg ikw = ik;
            for (int i = 0; i < 6; ++i) {
                ikw.q_min_rad[i] = -4 * PI;
                ikw.q_max_rad[i] = 4 * PI;
            }
            assert_int_equal(rch_ikg_solve(qs, NULL, &ikw, p, R, c[3], NULL), RCH_IKG_OK);
            for (int i = 0; i < 6; ++i)
                assert_true(fabs(wrapd(qs[i] - all[k][i])) < 1e-6);
        }
    }
}

/* The shoulder factor's zero along q2 (bisection on the branch bit). */
static int shoulder_singular(double q[6], const rch_ikg *ik)
{
    double lo = -PI, hi = PI;
    q[1] = lo;
    const int b0 = rch_ikg_branch(ik, q) & 4;
    double prev = lo;
    int found = 0;
    for (int s = 1; s <= 720 && !found; ++s) {
        q[1] = -PI + s * PI / 360;
        if ((rch_ikg_branch(ik, q) & 4) != b0) {
            lo = prev;
            hi = q[1];
            found = 1;
        }
        prev = q[1];
    }
    if (!found)
        return 0;
    for (int it = 0; it < 80; ++it) {
        q[1] = 0.5 * (lo + hi);
        if ((rch_ikg_branch(ik, q) & 4) == b0)
            lo = q[1];
        else
            hi = q[1];
    }
    q[1] = 0.5 * (lo + hi);
    return 1;
}

/* Poses at and next to each singularity: a solution meeting the pose. */
static void test_singular(void **state)
{
    (void)state;
    const rch_robot *rob[2] = {&ur, &abb};
    for (int r = 0; r < 2; ++r) {
        rch_ikg ik;
        assert_int_equal(rch_ikg_init(&ik, &rob[r]->nominal, NULL), RCH_IKG_OK);
        const rc_model *m = &rob[r]->nominal;
        int n_sh = 0;
        for (int n = 0; n < 60; ++n) {
            for (int kind = 0; kind < 3; ++kind) {
                double q[6];
                random_q(q, m);
                const double eps = (n % 3 == 0) ? 0.0 : (n % 3 == 1 ? 1e-7 : 1e-4);
                if (kind == 0)
                    q[4] = eps - m->x[RC_P_THETA(4)]; /* wrist: axes 4 and 6 aligned */
                else if (kind == 1) {
                    /* elbow: stretched or folded. UR: theta3 = 0; ABB: a3 x3 + d4 z3 along
                     * x2, tan theta3 = -d4 / a3 */
                    q[2] = (r == 0 ? 0.0 : atan2(-m->x[RC_P_D(3)], m->x[RC_P_A(2)])) - m->x[RC_P_THETA(2)] + eps;
                } else {
                    if (!shoulder_singular(q, &ik))
                        continue;
                    q[1] += eps;
                    ++n_sh;
                }
                double p[3], R[9], qs[6];
                rch_ikg_fk(p, R, &ik, q);
                rch_ikg ikw = ik;
                for (int i = 0; i < 6; ++i) {
                    ikw.q_min_rad[i] = -4 * PI;
                    ikw.q_max_rad[i] = 4 * PI;
                }
                rch_ikg_info inf;
                const rch_ikg_status st = rch_ikg_solve(qs, &inf, &ikw, p, R, RCH_IKG_ANY_BRANCH, NULL);
                if (st != RCH_IKG_OK)
                    fail_msg("robot %d kind %d eps %g: %s (err %g mm)", r, kind, eps, rch_ikg_strerror(st), inf.err_mm);
                double em, er;
                fk_err(&em, &er, &ik, qs, p, R);
                assert_true(em < 1e-6 && er < 1e-9);
                /* and from a seed next to the singular joints */
                double seed[6];
                for (int i = 0; i < 6; ++i)
                    seed[i] = q[i] + 0.01;
                assert_int_equal(rch_ikg_solve(qs, NULL, &ikw, p, R, RCH_IKG_ANY_BRANCH, seed), RCH_IKG_OK);
                fk_err(&em, &er, &ik, qs, p, R);
                assert_true(em < 1e-6 && er < 1e-9);
            }
        }
        assert_true(n_sh > 10);
    }
}

/* Out of reach: beyond the sum of the links (at once) and inside it but
 * beyond the arm's real reach (no start converges); bad arguments. */
static void test_unreachable(void **state)
{
    (void)state;
    rch_ikg ik;
    assert_int_equal(rch_ikg_init(&ik, &ur.nominal, NULL), RCH_IKG_OK);
    const double R[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
    double q[6] = {9, 9, 9, 9, 9, 9};
    rch_ikg_info inf;
    const double far[3] = {5000, 0, 0}, near_far[3] = {1050, 0, 600};
    assert_int_equal(rch_ikg_solve(q, &inf, &ik, far, R, RCH_IKG_ANY_BRANCH, NULL), RCH_IKG_UNREACHABLE);
    assert_int_equal(inf.starts, 0);
    assert_true(sqrt(near_far[0] * near_far[0] + near_far[2] * near_far[2]) < ik.reach_mm);
    assert_int_equal(rch_ikg_solve(q, &inf, &ik, near_far, R, 3, NULL), RCH_IKG_UNREACHABLE);
    assert_true(inf.starts > 1 && inf.err_mm > 1.0);
    assert_true(q[0] == 9 && q[5] == 9); /* left unchanged */
    assert_string_equal(rch_ikg_strerror(RCH_IKG_UNREACHABLE), "out of reach: no joint solution reaches this pose");
    const double bad[9] = {1, 0, 0, 0, 1, 0, 0, 0, 2};
    const double p[3] = {400, 100, 300};
    assert_int_equal(rch_ikg_solve(q, NULL, &ik, p, bad, RCH_IKG_ANY_BRANCH, NULL), RCH_IKG_ARG);
    assert_int_equal(rch_ikg_solve(q, NULL, &ik, p, R, 8, NULL), RCH_IKG_ARG);
    const double nan_p[3] = {NAN, 0, 0};
    assert_int_equal(rch_ikg_solve(q, NULL, &ik, nan_p, R, RCH_IKG_ANY_BRANCH, NULL), RCH_IKG_ARG);
}

/* Joint limits: a solution outside them in every turn is refused as such. */
static void test_limits(void **state)
{
    (void)state;
    rch_ikg ik;
    assert_int_equal(rch_ikg_init(&ik, &abb.nominal, NULL), RCH_IKG_OK);
    double q[6] = {0.3, 0.2, -0.1, 0.4, 0.7, 0.2}, p[3], R[9], qs[6];
    rch_ikg_fk(p, R, &ik, q);
    ik.q_max_rad[0] = 0.2; /* axis 1 at 0.3 rad now beyond its limit */
    assert_int_equal(rch_ikg_solve(qs, NULL, &ik, p, R, rch_ikg_branch(&ik, q), NULL), RCH_IKG_LIMITS);
}

/* rch_ik_solve (the robtargets' IK) on a UR5e: outside the closed form's
 * class it takes the general IK with the confdata rch_ik_fk gives (cfx the
 * general branch, cf1, cf4, cf6 the quadrants): the joints come back. */
static void test_rch_ik_solve_offset_wrist(void **state)
{
    (void)state;
    char why[512];
    assert_int_not_equal(rch_ik_supported(&ur.nominal, why, sizeof why), 0);
    const double tool[3] = {0, 0, 120};
    int n_ok = 0;
    for (int n = 0; n < 200; ++n) {
        double q[6], p[3], quat[4], qs[6];
        int cf[4];
        random_q(q, &ur.nominal);
        rch_ik_fk(p, quat, cf, &ur.nominal, q, tool);
        if (fabs(sin(q[4])) < 0.05) /* next to the wrist singularity the quadrants may tie: not this test's */
            continue;
        if (rch_ik_solve(qs, &ur.nominal, p, quat, cf, tool, why, sizeof why) != 0)
            fail_msg("pose %d: %s", n, why);
        for (int i = 0; i < 6; ++i)
            assert_true(fabs(qs[i] - q[i]) < 1e-7);
        ++n_ok;
    }
    assert_true(n_ok > 150);
}

/* A calibrated (perturbed) UR5e next to the idealised arm's boundaries (issue 51): poses whose wrist centre
 * lies inside the idealised arm's shoulder cylinder (|D| = d2 + d3 + d4 from axis 1: no closed-form
 * solution, so no start) are reachable by the real arm; a branch-only solve of such a pose returns the
 * pose's own branch, meeting it. Before, the closed form gave no start there (18 of these 40 solved, and
 * 0.7 % of all branch solves of a perturbed UR ended in NO_BRANCH or UNREACHABLE); 39 with the starts on
 * both sides, all 40 with the scans (tests/tools/host/comp/test_ikg_branch.c the sweep). */
static void test_perturbed_boundary(void **state)
{
    (void)state;
    rc_model m = ur.nominal;
    static const double dmm[6][2] = {{0.31, -0.42}, {-0.27, 0.18}, {0.44, 0.36}, {-0.12, 0.47}, {0.29, -0.33},
                                     {-0.41, -0.22}};
    static const double ddeg[6][2] = {{0.03, -0.04}, {-0.05, 0.02}, {0.04, 0.05}, {-0.02, -0.03}, {0.05, 0.01},
                                      {-0.04, 0.03}};
    for (int i = 0; i < 6; ++i) {
        m.x[RC_P_A(i)] += dmm[i][0];
        m.x[RC_P_D(i)] += dmm[i][1];
        m.x[RC_P_ALPHA(i)] += ddeg[i][0] * PI / 180;
        m.x[RC_P_THETA(i)] += ddeg[i][1] * PI / 180;
    }
    rch_ikg ik;
    assert_int_equal(rch_ikg_init(&ik, &m, NULL), RCH_IKG_OK);
    const double D = ur.nominal.x[RC_P_D(1)] + ur.nominal.x[RC_P_D(2)] + ur.nominal.x[RC_P_D(3)];
    const double d6 = ur.nominal.x[RC_P_D(5)];
    int n_inside = 0, n_ok = 0;
    for (int n = 0; n < 2000 && n_inside < 40; ++n) {
        double q[6], p[3], R[9], qs[6];
        random_q(q, &m);
        /* q2 where the wrist centre comes nearest axis 1 (its cylinder of radius |D| on the idealised arm) */
        double best = HUGE_VAL, q2 = q[1];
        for (int k = 0; k < 2000; ++k) {
            q[1] = -PI + 2 * PI * k / 2000.0;
            rch_ikg_fk(p, R, &ik, q);
            const double rr = hypot(p[0] - d6 * R[2], p[1] - d6 * R[5]);
            if (rr < best) {
                best = rr;
                q2 = q[1];
            }
        }
        for (double h = PI / 2000; h > 1e-9; h /= 2) /* refined */
            for (int sgn = -1; sgn <= 1; sgn += 2) {
                q[1] = q2 + sgn * h;
                rch_ikg_fk(p, R, &ik, q);
                const double rr = hypot(p[0] - d6 * R[2], p[1] - d6 * R[5]);
                if (rr < best) {
                    best = rr;
                    q2 = q[1];
                }
            }
        q[1] = q2 + urand(-2e-3, 2e-3);
        rch_ikg_fk(p, R, &ik, q);
        const double o5[2] = {p[0] - d6 * R[2], p[1] - d6 * R[5]};
        if (!(hypot(o5[0], o5[1]) < fabs(D)))
            continue; /* the idealised arm has solutions: not this test's */
        ++n_inside;
        const int b = rch_ikg_branch(&ik, q);
        rch_ikg_info inf;
        const rch_ikg_status st = rch_ikg_solve(qs, &inf, &ik, p, R, b, NULL);
        if (st != RCH_IKG_OK) {
            print_message("pose %d branch %d: %s\n", n, b, rch_ikg_strerror(st));
            continue;
        }
        double em, er;
        fk_err(&em, &er, &ik, qs, p, R);
        assert_true(em < 1e-6 && er < 1e-9);
        assert_int_equal(rch_ikg_branch(&ik, qs), b);
        ++n_ok;
    }
    print_message("perturbed UR5e, wrist centre inside the idealised shoulder cylinder: %d of %d solved\n", n_ok,
                  n_inside);
    assert_int_equal(n_inside, 40);
    assert_int_equal(n_ok, 40); /* 18 before the starts were put on both sides of the boundary, 39 before the
                                 * scans (rch_ikg.c) */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ur_every_branch), cmocka_unit_test(test_seed),
        cmocka_unit_test(test_abb_is_closed_form), cmocka_unit_test(test_singular),
        cmocka_unit_test(test_unreachable), cmocka_unit_test(test_limits),
        cmocka_unit_test(test_rch_ik_solve_offset_wrist), cmocka_unit_test(test_perturbed_boundary),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
