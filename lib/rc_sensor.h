/* SPDX-License-Identifier: MIT */
/* rc_sensor.h - measured quantities other than a cable length: a laser
 * tracker's position of a target on the tool.
 *
 * What: a tracker sample (rc_sample.sensor = RC_SENSOR_TRACKER_X/Y/Z) is one
 * component c of the target's position in the tracker's frame,
 *   p_tracker = R(w) (o6 + R6 t_k) + T,
 * o6, R6 the flange pose (the model's chain, joint-side effects and axis
 * tilts included), t_k target k (parameters 3k..3k+2 of RC_EFF_TRACKER_TARGETS,
 * mm in the flange frame), T (RC_EFF_TRACKER_POSITION, mm) and w
 * (RC_EFF_TRACKER_ROTATION, rotation vector, rad) the base in the tracker's
 * frame; a model without them has the tracker frame equal to the base.
 * Length-side effects, outlets and the cable attachment do not act on it.
 * Its Jacobian row: d p_c / d x_geom = g . d(point)/d x_geom with
 * g = R^T e_c (rc_model.c does the chain part, as for lengths),
 * d p_c / d T = e_c, d p_c / d w = -e_c^T [R p]x J_l(w), d p_c / d t_k =
 * e_c^T R R6, J_l the left Jacobian of SO(3).
 * Depends on: libm only. No heap, no stdio.
 */
#ifndef RC_SENSOR_H
#define RC_SENSOR_H

#include "rc_model.h"

/* R (3 x 3, row-major) = exp([w]x) (Rodrigues), w (3) rad. */
void rc_rotvec_matrix(double R[9], const double w[3]);

/* The left Jacobian of SO(3) at w: exp([w + d]x) = exp([J d]x) exp([w]x) to
 * first order; J (3 x 3, row-major). */
void rc_rotvec_jl(double J[9], const double w[3]);

/* Rotation vector w (3, |w| <= pi) of the rotation R (3 x 3). */
void rc_rotvec_from_matrix(double w[3], const double R[9]);

/* A sensor's hook (RC_SENSORS): for sample s of its kind, at the flange
 * pose o6 (3), R6 (3 x 3): value, its prediction in the sensor's unit;
 * pt (3), the point on the tool it sees, in the base frame; g (3),
 * d value / d pt, the gradient the chain's part of the Jacobian row is
 * taken along (rc_model.c, the same for every sensor). jac (m->n_params)
 * or NULL: every entry zeroed, then the sensor's own parameters' filled.
 * RC_ERR_ARG: a sample of another kind or one the model cannot predict (a
 * target, a plane it lacks). */
typedef rc_status (*rc_sensor_hook_fn)(double *value, double pt[3], double g[3], double *jac, const rc_model *m,
                                       const rc_sample *s, const double o6[3], const double R6[9]);

/* Every hook RC_SENSORS names, declared from the list. */
#define RC_SENSOR_HOOK_DECL_(id, name, unit, hook)                                                                 \
    rc_status hook(double *value, double pt[3], double g[3], double *jac, const rc_model *m, const rc_sample *s, \
                   const double o6[3], const double R6[9]);
RC_SENSORS(RC_SENSOR_HOOK_DECL_)
#undef RC_SENSOR_HOOK_DECL_

/* The hook of sensor kind sensor (rc_sample.sensor); rc_sensor_none for a
 * cable length (the chain's own) and for a number that is no kind. */
rc_sensor_hook_fn rc_sensor_hook(unsigned sensor);

/* rc_sensor_tracker: a tracker sample's component (see the top);
 * rc_sensor_none: RC_ERR_ARG always (a length is not a hook's). */

#endif /* RC_SENSOR_H */
