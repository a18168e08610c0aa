/* SPDX-License-Identifier: MIT */
/* rc_sensor_plane.c - a point touched on a plane as a measured quantity.
 *
 * What: a touch probe (or a hard tool tip) on the tool meets a flat plate;
 * a plane sample (rc_sample.sensor = RC_SENSOR_PLANE, target = k the plate
 * or plate placement) says the probe's point p = o6 + R6 t lies on plane k,
 * so it predicts n_k . p - d_k (mm) against a measured 0 (or a probe's
 * reading in rc_sample.value). t: RC_EFF_TOUCH_TIP (mm, flange frame); n_k:
 * rc_plane_normal of RC_EFF_PLANE_NORMALS' theta_k, phi_k; d_k:
 * RC_EFF_PLANE_OFFSETS (mm). A plane sees only distances along its normal:
 * three plates apart in direction see the robot as a point does, and the
 * plates absorb the base's rigid motion (no prior: side RC_SIDE_SENSOR).
 * Gradient g = n_k; d value / d t = n_k^T R6, / d theta_k = dn/dtheta . p,
 * / d phi_k = dn/dphi . p, / d d_k = -1.
 * Depends on: libm only. No heap, no stdio.
 */
#include "rc_sensor.h"

#include <math.h>
#include <string.h>

static const double pole[3] = {0.2672612419124244, 0.5345224838248488, 0.8017837257372732}; /* (1,2,3)/sqrt 14 */
static const double e1[3] = {-0.8944271909999159, 0.4472135954999579, 0.0};                /* (-2,1,0)/sqrt 5 */
static const double e2[3] = {-0.3585685828003181, -0.7171371656006362, 0.5976143046671968}; /* pole x e1 */

void rc_plane_normal(double n[3], double dn_dtheta[3], double dn_dphi[3], double theta, double phi)
{
    const double ct = cos(theta), st = sin(theta), cp = cos(phi), sp = sin(phi);
    for (int r = 0; r < 3; ++r) {
        const double u = cp * e1[r] + sp * e2[r]; /* the normal's direction across the pole */
        n[r] = ct * pole[r] + st * u;
        if (dn_dtheta)
            dn_dtheta[r] = -st * pole[r] + ct * u;
        if (dn_dphi)
            dn_dphi[r] = st * (-sp * e1[r] + cp * e2[r]);
    }
}

void rc_plane_angles(double *theta, double *phi, const double n[3])
{
    const double c = n[0] * pole[0] + n[1] * pole[1] + n[2] * pole[2];
    const double a = n[0] * e1[0] + n[1] * e1[1] + n[2] * e1[2];
    const double b = n[0] * e2[0] + n[1] * e2[1] + n[2] * e2[2];
    *theta = atan2(sqrt(a * a + b * b), c);
    *phi = atan2(b, a);
}

rc_status rc_sensor_plane(double *value, double pt[3], double g[3], double *jac, const rc_model *m,
                          const rc_sample *s, const double o6[3], const double R6[9])
{
    int tf = -1, nf = -1, df = -1; /* first parameters of the tip, plate k's normal angles and offset */
    RC_ASSERT(value != NULL && pt != NULL && g != NULL && m != NULL && s != NULL && o6 != NULL && R6 != NULL);
    if (s->sensor != RC_SENSOR_PLANE)
        return RC_ERR_ARG;
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        if (e->kind == RC_EFF_TOUCH_TIP && tf < 0)
            tf = e->first;
        else if (e->kind == RC_EFF_PLANE_NORMALS && nf < 0 && 2u * s->target + 2u <= e->count)
            nf = e->first + 2 * s->target;
        else if (e->kind == RC_EFF_PLANE_OFFSETS && df < 0 && s->target + 1u <= e->count)
            df = e->first + s->target;
    }
    if (nf < 0 || df < 0)
        return RC_ERR_ARG; /* a plate the model does not have */
    const double zero[3] = {0.0, 0.0, 0.0};
    const double *t = tf >= 0 ? &m->x[tf] : zero;
    for (int r = 0; r < 3; ++r)
        pt[r] = o6[r] + R6[3 * r] * t[0] + R6[3 * r + 1] * t[1] + R6[3 * r + 2] * t[2];
    double dth[3], dph[3];
    rc_plane_normal(g, dth, dph, m->x[nf], m->x[nf + 1]);
    *value = g[0] * pt[0] + g[1] * pt[1] + g[2] * pt[2] - m->x[df];
    if (jac == NULL)
        return RC_OK;
    memset(jac, 0, m->n_params * sizeof *jac);
    if (tf >= 0)
        for (int j = 0; j < 3; ++j)
            jac[tf + j] = g[0] * R6[j] + g[1] * R6[3 + j] + g[2] * R6[6 + j];
    jac[nf] = dth[0] * pt[0] + dth[1] * pt[1] + dth[2] * pt[2];
    jac[nf + 1] = dph[0] * pt[0] + dph[1] * pt[1] + dph[2] * pt[2];
    jac[df] = -1.0;
    return RC_OK;
}
