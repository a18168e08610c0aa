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

/* The hook of rc_meas for a tracker sample s: the flange pose o6 (3), R6
 * (3 x 3). value: the component; pt (3): the target in the base frame; g
 * (3): d value / d pt. jac (m->n_params) or NULL: every entry zeroed, then
 * the tracker frame's and the target's filled (the chain's are the
 * caller's). RC_ERR_ARG: a target the model lacks, or not a tracker sample. */
rc_status rc_sensor_tracker(double *value, double pt[3], double g[3], double *jac, const rc_model *m,
                            const rc_sample *s, const double o6[3], const double R6[9]);

#endif /* RC_SENSOR_H */
