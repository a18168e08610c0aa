/* SPDX-License-Identifier: MIT */
/* ik_bench.c - the general inverse kinematics' time per target (not a test):
 *   ik_bench ROBOT.json [N]
 * N (default 20000) random reachable poses of the robot (FK of random joints
 * inside its limits), solved three ways: seeded (the target's joints moved
 * by up to 0.05 rad: a program's previous target, URScript's qnear), by the
 * target's branch with no seed (a KRL Status, a Fanuc CONFIG, ABB's cfx),
 * and by the target's branch with the seed. Prints the median, 90th
 * percentile and worst microseconds per target of each, the median of the
 * targets of each branch, and how many solves failed (none should; by
 * status); then the same on the table perturbed as a
 * calibration perturbs it (every a, d by up to 0.5 mm, every alpha, theta
 * by up to 0.05 deg: the closed form's starts are then a few Newton steps
 * off). One core, wall clock (CLOCK_MONOTONIC). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rch_ikg.h"
#include "rch_robot.h"

static unsigned long long lcg = 777;
static double urand(double lo, double hi)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(lcg >> 11) / 9007199254740992.0;
}

static double now_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e6 + (double)t.tv_nsec * 1e-3;
}

static int cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: ik_bench ROBOT.json [N]\n");
        return 2;
    }
    const int n = argc > 2 ? atoi(argv[2]) : 20000;
    rch_robot r;
    rch_diag d;
    if (rch_robot_load(&r, argv[1], &d) != 0) {
        fprintf(stderr, "%s\n", d.msg);
        return 1;
    }
    static rch_ikg ik;
    double *t = malloc(sizeof(double) * (size_t)n), *tb = malloc(sizeof(double) * (size_t)n);
    int *br = malloc(sizeof(int) * (size_t)n);
    if (!t || !tb || !br)
        return 1;
    static const char *const mode[3] = {"seeded (seed within 0.05 rad)", "branch, no seed", "branch and seed"};
    for (int pert = 0; pert < 2; ++pert) {
    rc_model m0 = r.nominal;
    if (pert)
        for (int i = 0; i < 6; ++i) {
            m0.x[RC_P_A(i)] += urand(-0.5, 0.5);
            m0.x[RC_P_D(i)] += urand(-0.5, 0.5);
            m0.x[RC_P_ALPHA(i)] += urand(-0.05, 0.05) * 3.14159265358979 / 180;
            m0.x[RC_P_THETA(i)] += urand(-0.05, 0.05) * 3.14159265358979 / 180;
        }
    if (rch_ikg_init(&ik, &m0, NULL) != RCH_IKG_OK || n < 1)
        return 1;
    printf("ik_bench: %s%s, %d random poses, rch_ikg_solve\n", r.name, pert ? ", DH perturbed" : "", n);
    for (int m = 0; m < 3; ++m) {
        int fails = 0, by_status[5] = {0, 0, 0, 0, 0};
        unsigned long starts = 0;
        lcg = 777;
        for (int k = 0; k < n; ++k) {
            double q[6], seed[6], p[3], R[9], qs[6];
            for (int i = 0; i < 6; ++i) {
                q[i] = urand(fmax(r.nominal.q_min_rad[i], -3.14159), fmin(r.nominal.q_max_rad[i], 3.14159));
                seed[i] = q[i] + urand(-0.05, 0.05);
            }
            rch_ikg_fk(p, R, &ik, q);
            const int b = rch_ikg_branch(&ik, q);
            rch_ikg_info inf;
            const double t0 = now_us();
            const rch_ikg_status st = rch_ikg_solve(qs, &inf, &ik, p, R, m == 0 ? RCH_IKG_ANY_BRANCH : b,
                                                    m == 1 ? NULL : seed);
            t[k] = now_us() - t0;
            br[k] = b;
            fails += st != RCH_IKG_OK;
            ++by_status[st <= RCH_IKG_LIMITS ? st : 1];
            starts += inf.starts;
        }
        /* the median of each branch's targets */
        double med_b[8];
        int n_b[8];
        for (int b = 0; b < 8; ++b) {
            n_b[b] = 0;
            for (int k = 0; k < n; ++k)
                if (br[k] == b)
                    tb[n_b[b]++] = t[k];
            qsort(tb, (size_t)n_b[b], sizeof *tb, cmp);
            med_b[b] = n_b[b] ? tb[n_b[b] / 2] : 0.0;
        }
        qsort(t, (size_t)n, sizeof *t, cmp);
        printf("  %-30s median %7.2f us  p90 %7.2f us  max %8.1f us  starts/target %.2f  failed %d", mode[m],
               t[n / 2], t[(n * 9) / 10], t[n - 1], (double)starts / n, fails);
        if (fails)
            printf(" (unreachable %d, no branch %d, limits %d)", by_status[RCH_IKG_UNREACHABLE],
                   by_status[RCH_IKG_NO_BRANCH], by_status[RCH_IKG_LIMITS]);
        printf("\n    median by the target's branch (us):");
        for (int b = 0; b < 8; ++b)
            printf(" %d: %.2f", b, med_b[b]);
        printf("\n");
    }
    }
    free(t);
    free(tb);
    free(br);
    return 0;
}
