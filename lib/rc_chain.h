/* SPDX-License-Identifier: MIT */
/* rc_chain.h - the one definition of a link of the kinematic chain, for every
 * chain of the core: the solver model's (rc_model.c, double) and the compiled
 * firmware table's (rc_kin.c, rc_real, float on a Cortex-M4F). Each includes
 * this header after defining
 *   RC_CHAIN_T     the number type,
 *   RC_CHAIN_LINK  the name of the function to generate,
 * so the arithmetic is written once and a double build of both gives the
 * same numbers bit for bit (tests/core/test_model.c, tests/comp/test_comp.c).
 *
 * The link: frame i+1 = frame i . Rz(theta) . Tz(d) . Tx(a) . Rx(alpha) . Ry(beta)
 * (standard DH, then Hayati's axis tilt beta, RC_EFF_AXIS_TILT), written on the
 * columns x, y, z of R (3 x 3, row-major) and the origin o:
 *   x' = x ct + y st,  v = y ct - x st,  y' = v ca + z sa,  z' = z ca - v sa,
 *   o' = o + a x' + d z,
 * then the tilt turns x', z' about y':  x'' = x' + cm1 x' - sb z',
 * z'' = z' + sb x' + cm1 z'  (cm1 = cos beta - 1, written so that a zero tilt is
 * the identity to the bit). rot = 0 computes o' only (a point needs no last
 * rotation). N may not alias P. */
#if !defined(RC_CHAIN_T) || !defined(RC_CHAIN_LINK)
#error "define RC_CHAIN_T and RC_CHAIN_LINK before including rc_chain.h"
#endif

static void RC_CHAIN_LINK(RC_CHAIN_T N[9], RC_CHAIN_T on[3], const RC_CHAIN_T P[9], const RC_CHAIN_T o[3],
                          RC_CHAIN_T a, RC_CHAIN_T d, RC_CHAIN_T ct, RC_CHAIN_T st, RC_CHAIN_T ca, RC_CHAIN_T sa,
                          RC_CHAIN_T cm1, RC_CHAIN_T sb, int rot)
{
    for (unsigned r = 0; r < 3; ++r) {
        const RC_CHAIN_T xr = P[3 * r], yr = P[3 * r + 1], zr = P[3 * r + 2];
        const RC_CHAIN_T nx = xr * ct + yr * st, v = yr * ct - xr * st;
        on[r] = o[r] + a * nx + d * zr;
        if (rot) {
            N[3 * r] = nx;
            N[3 * r + 1] = v * ca + zr * sa;
            N[3 * r + 2] = zr * ca - v * sa;
        }
    }
    if (rot && (cm1 != (RC_CHAIN_T)0 || sb != (RC_CHAIN_T)0))
        for (unsigned r = 0; r < 3; ++r) {
            const RC_CHAIN_T x = N[3 * r], z = N[3 * r + 2];
            N[3 * r] = x + cm1 * x - sb * z;
            N[3 * r + 2] = z + sb * x + cm1 * z;
        }
}

#undef RC_CHAIN_T
#undef RC_CHAIN_LINK
