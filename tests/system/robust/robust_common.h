/* SPDX-License-Identifier: MIT */
/* robust_common.h - shared helpers of the robustness tests: the IRB120
 * nominal model, a perturbed "true" robot, and pose generators (random,
 * one pose, collinear and coplanar flange points). Test code only. */
#ifndef ROBUST_COMMON_H
#define ROBUST_COMMON_H

#include <math.h>
#include <string.h>

#include "rc_model.h"
#include "rc_rand.h"
#include "rct_irb120.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define RB_DEG (M_PI / 180.0)

/* ABB IRB120, data/irb120.json (a, d, alpha, theta offset). */
static inline void rb_nominal(rc_model *m)
{
    double dh[RC_NJ][4];
    rct_irb120_dh(dh);
    const double enc[3] = {250.0, -460.0, 10.0};
    (void)rc_model_init(m, (const double(*)[4])dh, enc);
}

/* The "real" robot: nominal plus small geometric errors. */
static inline void rb_truth(rc_model *t)
{
    rc_rng g;
    rb_nominal(t);
    rc_rng_seed(&g, 77);
    for (unsigned k = 0; k < RC_N_DH; ++k) {
        const int is_len = (k % 4) < 2;
        t->x[k] += (is_len ? 0.5 : 0.002) * (2.0 * rc_rng_u01(&g) - 1.0);
    }
}

/* Random poses inside +-60 % of the joint range, lengths from model t. */
static inline void rb_random(rc_sample *s, size_t n, const rc_model *t, unsigned long long seed)
{
    rc_rng g;
    rc_rng_seed(&g, seed);
    static const double span_deg[RC_NJ] = {100, 60, 50, 100, 70, 150};
    for (size_t i = 0; i < n; ++i) {
        memset(&s[i], 0, sizeof s[i]);
        for (int j = 0; j < RC_NJ; ++j)
            s[i].q_rad[j] = span_deg[j] * RB_DEG * (2.0 * rc_rng_u01(&g) - 1.0);
        s[i].q_rad[1] = 0.3 * s[i].q_rad[1] + 10 * RB_DEG;
        s[i].t = n > 1 ? (double)i / (double)(n - 1) : 0.0;
        (void)rc_meas(&s[i].value, NULL, t, &s[i]);
    }
}

/* Place the flange point of model m at target (x, z) in the plane y = 0
 * with q1 = q4 = q5 = q6 = 0 by Newton on q2, q3 (test helper). */
static inline int rb_ik_xz(double q[RC_NJ], const rc_model *m, double x, double z)
{
    memset(q, 0, RC_NJ * sizeof q[0]);
    q[1] = 10 * RB_DEG;
    q[2] = 10 * RB_DEG;
    for (int it = 0; it < 100; ++it) {
        double p[3], jac[36];
        rc_fk_jac(p, NULL, jac, m, q);
        const double ex = x - p[0], ez = z - p[2];
        if (fabs(ex) + fabs(ez) < 1e-9)
            return 0;
        /* 2x2 block rows x, z; columns q2, q3 */
        const double a = jac[0 * 6 + 1], b = jac[0 * 6 + 2], c = jac[2 * 6 + 1], d = jac[2 * 6 + 2];
        const double det = a * d - b * c;
        if (fabs(det) < 1e-12)
            return -1;
        q[1] += (d * ex - b * ez) / det;
        q[2] += (-c * ex + a * ez) / det;
    }
    return -1;
}

#endif
