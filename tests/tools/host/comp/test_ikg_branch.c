/* SPDX-License-Identifier: MIT */
/* test_ikg_branch.c - issue 51's "every reachable configuration branch
 * right": every target made by the forward kinematics from joints of a
 * branch is solved in that branch (rch_ikg.h), on the nominal and perturbed
 * (calibrated-like) UR5e, UR10e and IRB120, on random configurations and on
 * configurations 1e-3 .. 1 deg from each singularity (the wrist's q5 = 0 / pi,
 * the elbow stretched or folded, the wrist point in the plane through axis 1
 * parallel to axis 2: on axis 1 for a spherical wrist) and
 * two at once; at the singularity itself (the joints' factor 0 within
 * rounding) the definition of rch_ikg.h: a solution of the asked branch, or
 * of the one across that boundary and within RCH_IKG_NEAR_BOUNDARY of it.
 *
 *   test_ikg_branch            the ctest (fixed seed, counts printed)
 *   test_ikg_branch --study N  N configurations per set (the study)
 *   test_ikg_branch --seed S   other configurations and perturbed arms
 *   IKG_VERBOSE=1              every failure listed */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_ikg.h"
#include "rch_ikg_int.h"
#include "rch_robot.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* Under AddressSanitizer (the sanitizer pass watches the code paths; the Release ctest keeps the breadth:
 * a solve that must prove a branch absent runs the scans, 10 x slower instrumented) a quarter per set. */
#if defined(__SANITIZE_ADDRESS__)
static int n_per_set = 75; /* per set; --study N */
#else
static int n_per_set = 300; /* per set; --study N */
#endif
static int verbose;

static unsigned long long lcg = 20261205, lcg_arm = 51;
static double urand_of(unsigned long long *state, double lo, double hi)
{
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(*state >> 11) / 9007199254740992.0;
}
static double urand(double lo, double hi) { return urand_of(&lcg, lo, hi); }

/* The arms: nominal, and perturbed as a calibration perturbs them (every a, d
 * by up to amp_mm, alpha, theta by up to amp_deg), drawn from their own
 * sequence: the same arms in the ctest and the study. */
static void perturb(rc_model *m, double amp_mm, double amp_deg)
{
    for (int i = 0; i < 6; ++i) {
        m->x[RC_P_A(i)] += urand_of(&lcg_arm, -amp_mm, amp_mm);
        m->x[RC_P_D(i)] += urand_of(&lcg_arm, -amp_mm, amp_mm);
        m->x[RC_P_ALPHA(i)] += urand_of(&lcg_arm, -amp_deg, amp_deg) * DEG;
        m->x[RC_P_THETA(i)] += urand_of(&lcg_arm, -amp_deg, amp_deg) * DEG;
    }
}

/* The joint that crosses each bit's boundary: wrist q5, elbow q3, shoulder q2. */
static const int bit_joint[3] = {4, 2, 1};

/* q[j] moved to the zero of branch bit `bit` along joint j nearest a random
 * point (scan, then bisection to the last bit); 0 when the bit never changes. */
static int to_boundary(double q[6], const rch_ikg *ik, int bit)
{
    const int j = bit_joint[bit];
    const int mask = 1 << bit;
    double z[16];
    int nz = 0;
    double prev = -PI;
    q[j] = prev;
    int bprev = rch_ikg_branch(ik, q) & mask;
    for (int s = 1; s <= 720 && nz < 16; ++s) {
        const double x = -PI + s * PI / 360;
        q[j] = x;
        const int b = rch_ikg_branch(ik, q) & mask;
        if (b != bprev) {
            double lo = prev, hi = x;
            for (int it = 0; it < 100 && hi - lo > 0; ++it) {
                const double mid = 0.5 * (lo + hi);
                if (mid <= lo || mid >= hi)
                    break;
                q[j] = mid;
                if ((rch_ikg_branch(ik, q) & mask) == bprev)
                    lo = mid;
                else
                    hi = mid;
            }
            z[nz++] = hi; /* the first value of the other side */
        }
        bprev = b;
        prev = x;
    }
    if (nz == 0)
        return 0;
    q[j] = z[(int)urand(0, nz - 1e-9)];
    return 1;
}

typedef struct {
    int n, ok, wrong, no_branch, unreachable, limits, inexact;
} counts;

/* Solve the pose of q for its branch (no seed, and with a seed 0.05 rad
 * off); count. At the boundary (exact = 1) a solution whose bits differ only
 * where it lies on the boundary is right (rch_ikg.h). */
static void check(counts *c, const rch_ikg *ik, const double q[6], const char *what, int exact)
{
    double p[3], R[9];
    rch_ikg_fk(p, R, ik, q);
    const int b = rch_ikg_branch(ik, q);
    for (int seeded = 0; seeded < 2; ++seeded) {
        double seed[6], qs[6];
        for (int i = 0; i < 6; ++i)
            seed[i] = q[i] + urand(-0.05, 0.05);
        rch_ikg_info inf;
        const rch_ikg_status st = rch_ikg_solve(qs, &inf, ik, p, R, b, seeded ? seed : NULL);
        ++c->n;
        const char *bad = NULL;
        if (st == RCH_IKG_NO_BRANCH) {
            ++c->no_branch;
            bad = "NO_BRANCH";
        } else if (st == RCH_IKG_UNREACHABLE) {
            ++c->unreachable;
            bad = "UNREACHABLE";
        } else if (st == RCH_IKG_LIMITS) {
            ++c->limits;
            bad = "LIMITS";
        } else if (st != RCH_IKG_OK) {
            ++c->wrong;
            bad = "other status";
        } else {
            double p2[3], R2[9];
            rch_ikg_fk(p2, R2, ik, qs);
            double em = 0.0, er = 0.0;
            for (int k = 0; k < 3; ++k)
                em = fmax(em, fabs(p2[k] - p[k]));
            for (int k = 0; k < 9; ++k)
                er = fmax(er, fabs(R2[k] - R[k]));
            const int bs = rch_ikg_branch(ik, qs);
            if (em > RCH_IKG_ACCEPT_MM || er > 3 * RCH_IKG_ACCEPT_RAD) {
                ++c->inexact;
                bad = "inexact";
            } else if (bs != b && (rch_ikg_on_boundary(ik, qs, RCH_IKG_BOUNDARY) & (bs ^ b)) != (bs ^ b) &&
                       !(exact && (rch_ikg_on_boundary(ik, qs, RCH_IKG_NEAR_BOUNDARY) & (bs ^ b)) == (bs ^ b) &&
                         (rch_ikg_on_boundary(ik, q, RCH_IKG_BOUNDARY) & (bs ^ b)) == (bs ^ b))) {
                /* (a solution on the boundary of the bits that differ is on both sides: right, rch_ikg.h) */
                ++c->wrong;
                bad = "wrong branch";
            } else
                ++c->ok;
        }
        if (bad && verbose) {
            printf("  FAIL %s %s%s: branch %d q", what, bad, seeded ? " (seeded)" : "", b);
            for (int i = 0; i < 6; ++i)
                printf(" %.9g", q[i]);
            printf("  starts %u err %.3g mm\n", inf.starts, inf.err_mm);
            if (verbose > 1) {
                double all[RCH_IKG_MAX_SOL][6], cs[8][6];
                int br[RCH_IKG_MAX_SOL];
                const int na = rch_ikg_all(all, br, ik, p, R), nc = rch_ikg_seeds(cs, ik, p, R);
                for (int k = 0; k < na + nc; ++k) {
                    const double *x = k < na ? all[k] : cs[k - na];
                    printf("    %s %d branch %d:", k < na ? "solution" : "start", k < na ? k : k - na,
                           k < na ? br[k] : rch_ikg_branch(ik, x));
                    for (int i = 0; i < 6; ++i)
                        printf(" %10.6f", x[i]);
                    printf("\n");
                }
            }
        }
    }
}

static void random_q(double q[6], const rch_ikg *ik)
{
    for (int i = 0; i < 6; ++i)
        q[i] = urand(fmax(ik->q_min_rad[i], -PI), fmin(ik->q_max_rad[i], PI));
}

/* One arm: random configurations; each bit's boundary approached by 1e-3 ..
 * 1 deg (log-uniform, either side); two bits at once; the boundary itself.
 * Counts the failures: fails[0] every set but two singularities at once,
 * fails[1] that set, fails[2] its solves, fails[3] all solves. */
static void sweep(int fails[4], const char *name, const rc_model *m)
{
    rch_ikg ik;
    assert_int_equal(rch_ikg_init(&ik, m, NULL), RCH_IKG_OK);
    rch_ikg ikw = ik; /* the joint limits widened for the solve (the branch is tested, not the limits) */
    for (int i = 0; i < 6; ++i) {
        ikw.q_min_rad[i] = -4 * PI;
        ikw.q_max_rad[i] = 4 * PI;
    }
    static const char *const set_name[] = {"random", "near wrist", "near elbow", "near shoulder", "near two",
                                           "at a boundary"};
    for (int set = 0; set < 6; ++set) {
        counts c = {0, 0, 0, 0, 0, 0, 0};
        int made = 0;
        for (int n = 0; made < n_per_set && n < 4 * n_per_set; ++n) {
            double q[6];
            random_q(q, &ik);
            int exact = 0;
            if (set >= 1 && set <= 3) {
                if (!to_boundary(q, &ik, set - 1))
                    continue;
                q[bit_joint[set - 1]] += (urand(0, 1) < 0.5 ? -1 : 1) * pow(10.0, urand(-3, 0)) * DEG;
            } else if (set == 4) {
                int bits[2] = {(int)urand(0, 3), 0};
                bits[1] = (bits[0] + 1 + (int)urand(0, 2)) % 3;
                int ok = 1;
                for (int k = 0; k < 2 && ok; ++k)
                    ok = to_boundary(q, &ik, bits[k]);
                if (!ok)
                    continue;
                for (int k = 0; k < 2; ++k)
                    q[bit_joint[bits[k]]] += (urand(0, 1) < 0.5 ? -1 : 1) * pow(10.0, urand(-3, 0)) * DEG;
            } else if (set == 5) {
                if (!to_boundary(q, &ik, (int)urand(0, 3)))
                    continue;
                exact = 1;
            }
            int inside = 1;
            for (int i = 0; i < 6; ++i)
                inside &= q[i] >= ik.q_min_rad[i] && q[i] <= ik.q_max_rad[i];
            if (!inside)
                continue;
            ++made;
            check(&c, &ikw, q, set_name[set], exact);
        }
        const int f = c.n - c.ok;
        printf("%-26s %-14s solves %5d  right %5d  wrong %d  NO_BRANCH %d  UNREACHABLE %d  LIMITS %d  inexact %d\n",
               name, set_name[set], c.n, c.ok, c.wrong, c.no_branch, c.unreachable, c.limits, c.inexact);
        fails[set == 4] += f;
        if (set == 4)
            fails[2] += c.n;
        fails[3] += c.n;
    }
}

static rch_robot ur5e, irb120;

static int setup(void **state)
{
    (void)state;
    rch_diag d;
    assert_int_equal(rch_robot_load(&ur5e, RCAL_SOURCE_DIR "/data/ur5e.json", &d), 0);
    assert_int_equal(rch_robot_load(&irb120, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    return 0;
}

/* The arms of the sweep: each nominal, then two perturbed draws. The ctest
 * (its fixed seed): every solve right. The study (--study N, other poses):
 * at most 1 in 10000 wrong or refused (docs/comp.md: what is left open). */
static int study;

static void sweep_arm(const char *name, const rc_model *nominal)
{
    int fails[4] = {0, 0, 0, 0};
    char label[64];
    sweep(fails, name, nominal);
    for (int k = 0; k < 2; ++k) {
        rc_model m = *nominal;
        perturb(&m, 0.5, 0.05);
        snprintf(label, sizeof label, "%s perturbed %d", name, k + 1);
        sweep(fails, label, &m);
    }
    printf("%s: %d failed of %d solves (random, next to one singularity, on a boundary); %d of %d next to two "
           "at once\n",
           name, fails[0], fails[3] - fails[2], fails[1], fails[2]);
    if (study)
        assert_true(10000 * (fails[0] + fails[1]) <= fails[3]);
    else {
        assert_int_equal(fails[0], 0);
        assert_int_equal(fails[1], 0);
    }
}

static void test_ur5e(void **state)
{
    (void)state;
    sweep_arm("UR5e", &ur5e.nominal);
}

/* UR10e: UR's published table (d1 180.7, a2 -612.7, a3 -571.55, d4 174.15,
 * d5 119.85, d6 116.55 mm) on the UR5e's file. */
static void test_ur10e(void **state)
{
    (void)state;
    rc_model m = ur5e.nominal;
    m.x[RC_P_D(0)] = 180.7;
    m.x[RC_P_A(1)] = -612.7;
    m.x[RC_P_A(2)] = -571.55;
    m.x[RC_P_D(3)] = 174.15;
    m.x[RC_P_D(4)] = 119.85;
    m.x[RC_P_D(5)] = 116.55;
    sweep_arm("UR10e", &m);
}

/* IRB120 (the joint limits widened in sweep: the branch is tested, not the
 * limits). */
static void test_irb120(void **state)
{
    (void)state;
    sweep_arm("IRB120", &irb120.nominal);
}

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--study") == 0 && i + 1 < argc) {
            n_per_set = atoi(argv[++i]);
            study = 1;
        }
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) /* other poses and other perturbed arms */
            lcg_arm = lcg = strtoull(argv[++i], NULL, 10);
    verbose = getenv("IKG_VERBOSE") ? atoi(getenv("IKG_VERBOSE")) : 0;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ur5e),
        cmocka_unit_test(test_ur10e),
        cmocka_unit_test(test_irb120),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
