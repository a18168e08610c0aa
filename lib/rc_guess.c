/* SPDX-License-Identifier: MIT */
/* rc_guess.c - the start value of the encoder outlet (rc_encoder_guess,
 * declared in rc_solve.h): the sphere through the nominal measured points
 * whose radii are the lengths, in closed form (linear least squares in the
 * centre and |e|^2, centred for conditioning), refused when the poses do
 * not spread in three directions or the lengths fit no sphere. No heap, no
 * stdio. */
#include "rc_solve.h"

#include <math.h>
#include <stddef.h>

#include "rc_linalg.h"

rc_status rc_encoder_guess(double enc_mm[3], const rc_model *m, const rc_sample *samples, size_t n)
{
    double A[16] = {0}, b[4] = {0}, c[3] = {0, 0, 0};
    rc_meas_prep mp;
    RC_ASSERT(enc_mm != NULL && m != NULL);
    if (n < 4)
        return RC_ERR_RANK;
    rc_meas_prepare(&mp, m);
    /* centre the points for conditioning: unknowns e' = e - c, k = |e'|^2 */
    for (size_t i = 0; i < n; ++i) {
        double p[3];
        rc_point_prepared(p, m, &mp, &samples[i], NULL, NULL);
        for (int r = 0; r < 3; ++r)
            c[r] += p[r] / (double)n;
    }
    double trace = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double p[3];
        rc_point_prepared(p, m, &mp, &samples[i], NULL, NULL);
        for (int r = 0; r < 3; ++r)
            p[r] -= c[r];
        /* -2 p.e' + k = L^2 - |p|^2 */
        const double row[4] = {-2.0 * p[0], -2.0 * p[1], -2.0 * p[2], 1.0};
        const double rhs = samples[i].value * samples[i].value - (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (unsigned a = 0; a < 4; ++a) {
            b[a] += row[a] * rhs;
            for (unsigned k = 0; k < 4; ++k)
                A[4 * a + k] += row[a] * row[k];
        }
    }
    for (unsigned a = 0; a < 3; ++a)
        trace += A[5 * a];
    /* A pose set without spread in some direction (in any orientation, so
     * the smallest eigenvalue of the centred scatter) cannot place e. */
    double sc[9], vec[9], ev[3];
    for (unsigned a = 0; a < 3; ++a)
        for (unsigned k = 0; k < 3; ++k)
            sc[3 * a + k] = A[4 * a + k];
    if (!(trace > 0.0) || rcu_eig_sym(ev, vec, sc, 3, 0) != RC_OK || !(ev[2] > 1e-8 * trace))
        return RC_ERR_RANK;
    if (rcu_chol_solve(A, b, 4) != RC_OK)
        return RC_ERR_RANK;
    if (!(isfinite(b[0]) && isfinite(b[1]) && isfinite(b[2]) && isfinite(b[3])))
        return RC_ERR_NUMERIC;
    /* Lengths that fit no sphere (a wild reading, a wrong column, a
     * constant column) are refused: the RMS of |p_i - e| - L_i around the
     * guessed outlet must stay below 15 % of the RMS length (+1 mm). The
     * points are nominal, so a robot whose geometry is tens of mm off
     * leaves a residual of that size (42 mm, 6.7 % of the RMS length, for
     * a truth model 30-40 mm from nominal over the whole workspace); the
     * guess only starts the fit. */
    double e[3], res2 = 0.0, len2 = 0.0;
    for (int r = 0; r < 3; ++r)
        e[r] = b[r] + c[r];
    for (size_t i = 0; i < n; ++i) {
        double p[3];
        rc_point_prepared(p, m, &mp, &samples[i], NULL, NULL);
        const double dx = p[0] - e[0], dy = p[1] - e[1], dz = p[2] - e[2];
        const double d = sqrt(dx * dx + dy * dy + dz * dz) - samples[i].value;
        res2 += d * d;
        len2 += samples[i].value * samples[i].value;
    }
    if (!(sqrt(res2) <= 0.15 * sqrt(len2) + sqrt((double)n)))
        return RC_ERR_RANGE;
    for (int r = 0; r < 3; ++r)
        enc_mm[r] = e[r];
    return RC_OK;
}
