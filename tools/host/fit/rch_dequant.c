/* SPDX-License-Identifier: MIT */
/* rch_dequant.c - joint angles from the reported flange position (see
 * rch_dequant.h). */
#include "rch_dequant.h"

#include <math.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)

/* Least-norm solution of J_free dx = r over the free joints (J: 3 x 6
 * position rows); 0, or -1 when they do not span the position. */
static int least_norm(double dx[RC_NJ], const double J[36], const double r[3], const uint8_t *clamped)
{
    double A[9];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            A[a * 3 + b] = 0.0;
            for (int j = 0; j < RC_NJ; ++j)
                if (!clamped[j])
                    A[a * 3 + b] += J[a * 6 + j] * J[b * 6 + j];
        }
    double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                 A[2] * (A[3] * A[7] - A[4] * A[6]);
    if (!(fabs(det) > 1e-12))
        return -1;
    double inv[9] = {(A[4] * A[8] - A[5] * A[7]) / det, (A[2] * A[7] - A[1] * A[8]) / det,
                     (A[1] * A[5] - A[2] * A[4]) / det, (A[5] * A[6] - A[3] * A[8]) / det,
                     (A[0] * A[8] - A[2] * A[6]) / det, (A[2] * A[3] - A[0] * A[5]) / det,
                     (A[3] * A[7] - A[4] * A[6]) / det, (A[1] * A[6] - A[0] * A[7]) / det,
                     (A[0] * A[4] - A[1] * A[3]) / det};
    double y[3];
    for (int a = 0; a < 3; ++a)
        y[a] = inv[a * 3] * r[0] + inv[a * 3 + 1] * r[1] + inv[a * 3 + 2] * r[2];
    for (int j = 0; j < RC_NJ; ++j)
        dx[j] = clamped[j] ? 0.0 : J[j] * y[0] + J[6 + j] * y[1] + J[12 + j] * y[2];
    return 0;
}

/* One row: the smallest dq inside the box |dq_j| <= max_dq with nominal
 * FK(q + dq) = target (Gauss-Newton; joints that would leave the box are
 * clamped at its edge and the rest solved again, an active-set step); 0 when
 * the position is reached to 1e-6 mm inside the box. */
static int solve_row(double dq[RC_NJ], const rc_model *m, const double q[RC_NJ], const double target[3],
                     double max_dq)
{
    uint8_t clamped[RC_NJ] = {0};
    double qq[RC_NJ], p[3], J[36];
    memset(dq, 0, RC_NJ * sizeof *dq);
    for (int it = 0; it < 20; ++it) {
        for (int j = 0; j < RC_NJ; ++j)
            qq[j] = q[j] + dq[j];
        rc_fk_jac(p, NULL, J, m, qq);
        double r[3] = {target[0] - p[0], target[1] - p[1], target[2] - p[2]};
        if (sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) < 1e-6)
            return 0;
        double dx[RC_NJ];
        if (least_norm(dx, J, r, clamped) != 0)
            return -1;
        int hit = 0;
        for (int j = 0; j < RC_NJ; ++j) {
            double v = dq[j] + dx[j];
            if (!clamped[j] && fabs(v) > max_dq) {
                dq[j] = v > 0 ? max_dq : -max_dq;
                clamped[j] = 1;
                hit = 1;
            } else if (!clamped[j]) {
                dq[j] = v;
            }
        }
        (void)hit;
    }
    for (int j = 0; j < RC_NJ; ++j)
        qq[j] = q[j] + dq[j];
    rc_fk(p, NULL, m, qq);
    double e = sqrt((target[0] - p[0]) * (target[0] - p[0]) + (target[1] - p[1]) * (target[1] - p[1]) +
                    (target[2] - p[2]) * (target[2] - p[2]));
    return e < 1e-6 ? 0 : 1;
}

int rch_dequant(rch_dequant_result *res, uint8_t *refused, rc_sample *s, size_t n, const double (*xyz)[3],
                const rc_model *nominal, double max_dq_rad)
{
    memset(res, 0, sizeof *res);
    if (!s || !xyz || !nominal)
        return -1;
    double bound = max_dq_rad > 0 ? max_dq_rad : 0.06 * DEG;
    double sum2 = 0.0, fb = 0.0, fa = 0.0;
    size_t nq = 0;
    res->n_rows = n;
    for (size_t i = 0; i < n; ++i) {
        double dq[RC_NJ], p[3];
        int bad = solve_row(dq, nominal, s[i].q_rad, xyz[i], bound) != 0;
        if (refused)
            refused[i] = (uint8_t)bad;
        if (bad) {
            res->n_refused++;
            continue;
        }
        rc_fk(p, NULL, nominal, s[i].q_rad);
        fb += (p[0] - xyz[i][0]) * (p[0] - xyz[i][0]) + (p[1] - xyz[i][1]) * (p[1] - xyz[i][1]) +
              (p[2] - xyz[i][2]) * (p[2] - xyz[i][2]);
        for (int j = 0; j < RC_NJ; ++j) {
            s[i].q_rad[j] += dq[j];
            sum2 += dq[j] * dq[j];
            res->dq_max_deg = fmax(res->dq_max_deg, fabs(dq[j]) / DEG);
        }
        nq += RC_NJ;
        rc_fk(p, NULL, nominal, s[i].q_rad);
        fa += (p[0] - xyz[i][0]) * (p[0] - xyz[i][0]) + (p[1] - xyz[i][1]) * (p[1] - xyz[i][1]) +
              (p[2] - xyz[i][2]) * (p[2] - xyz[i][2]);
        res->n_corrected++;
    }
    if (nq) {
        res->dq_rms_deg = sqrt(sum2 / (double)nq) / DEG;
        res->fk_rms_before_mm = sqrt(fb / (double)res->n_corrected);
        res->fk_rms_after_mm = sqrt(fa / (double)res->n_corrected);
    }
    return 0;
}

double rch_dequant_detect_step(const double *values, size_t n)
{
    static const double steps[] = {1.0,  0.5,   0.2,   0.1,    0.05,  0.02, 0.01,
                                   0.005, 0.004, 0.002, 0.001, 0.0005, 0.0001};
    if (n == 0)
        return 0.0;
    for (size_t k = 0; k < sizeof steps / sizeof steps[0]; ++k) {
        int ok = 1;
        for (size_t i = 0; i < n && ok; ++i) {
            const double u = values[i] / steps[k];
            ok = fabs(u - floor(u + 0.5)) < 1e-6;
        }
        if (ok)
            return steps[k];
    }
    return 0.0;
}
