/* SPDX-License-Identifier: MIT */
/* rch_prior.h - the physical prior of a calibration (prefix rch_prior_).
 *
 * What is known before the data: a robot is built to its drawing within
 * manufacturing tolerances, and mounted and zeroed within a few tenths of a
 * degree. These enter as a Gaussian prior per parameter type, centred on
 * the nominal model, so that the estimate is maximum a posteriori (rc_solve's
 * prior rows) and what the lengths do not determine stays where the drawing
 * puts it, with the prior's uncertainty, instead of wandering to whatever
 * fits the noise (a wrist 70-100 mm off nominal).
 *
 * Defaults (standard deviations; the robot file's "prior" member overrides
 * each, docs/model-format.md):
 *   length_mm      0.5   link lengths a_i, d_i: machined and assembled parts of an
 *                         industrial arm are within a few tenths of a mm of the
 *                         drawing (published identified DH errors of IRB120,
 *                         KR6 and UR arms: 0.05-0.8 mm)
 *   twist_deg      0.1   twists alpha_i: bore alignment, a few hundredths to a tenth
 *                         of a degree
 *   offset_deg     1.0   joint zero offsets theta_i: set by the resolver's
 *                         calibration marks; real robots are often 1-2 deg off
 *                         after a motor change, 0.1 deg after a careful zeroing
 *   attachment_mm  100   the cable attachment point in the flange frame (the
 *                         measured point): a fixture of the user's, known only
 *                         roughly; centred on the start value (0 or the robot file's)
 *   points_mm      0.05  each coordinate of a cable point of a tool plate
 *                         (cable_points), about the nominal coordinates the
 *                         user states: the plate is machined and pinned to
 *                         the flange, so its points are known to its tolerance
 * Every other physical effect (length scale, sag, joint compliance, ...):
 * its plausible range from the effect table (rc_effect_desc.limit) as 3 sd
 * about its start value. The encoder outlets, the nuisance effects
 * (length jumps, group offsets, drift) and a tracker's frame and targets
 * (RC_SIDE_SENSOR) have no prior: the data place them.
 *
 * Gauge. Lengths from one outlet cannot see a rigid motion of the robot
 * about the outlet; in the robot's frame that is the base heading theta1 and
 * height d1 traded against the outlet position. They are held at nominal
 * (rch_prior_gauge) and reported as such: they do not change what the robot
 * does relative to itself (pairwise distances), and a cell sets its robot's
 * base frame anyway. A laser tracker does not lift the gauge: its positions
 * are in its own frame, whose six parameters absorb the same rigid motion
 * (a turn about and a shift along joint 1's axis), so theta1 and d1 stay held.
 *
 * Depends on: rc_model. Memory: none. Thread safety: reentrant.
 */
#ifndef RCH_PRIOR_H
#define RCH_PRIOR_H

#include <stdint.h>

#include "rc_model.h"

typedef struct rch_prior_cfg {
    double length_mm;     /* sd of a_i, d_i */
    double twist_deg;     /* sd of alpha_i */
    double offset_deg;    /* sd of theta_i */
    double attachment_mm; /* sd of each component of the cable attachment (tool_offset effect) */
    double points_mm;     /* sd of each coordinate of a cable point (cable_points effect) */
    int from_file;        /* 1: the robot file had a "prior" member */
} rch_prior_cfg;

#define RCH_PRIOR_LENGTH_MM 0.5
#define RCH_PRIOR_TWIST_DEG 0.1
#define RCH_PRIOR_OFFSET_DEG 1.0
#define RCH_PRIOR_ATTACHMENT_MM 100.0
#define RCH_PRIOR_POINTS_MM 0.05

void rch_prior_defaults(rch_prior_cfg *p);

/* The prior of model m's parameters: mean (n_params) = nominal's DH and
 * m's own start value for the attachment; sd (n_params) by type, 0 (no
 * prior) for the outlet and every other effect. */
void rch_prior_fill(double *mean, double *sd, const rc_model *m, const rc_model *nominal, const rch_prior_cfg *p);

/* Mark the gauge parameters (theta1, d1) in fixed (n_params). */
void rch_prior_gauge(uint8_t *fixed);

/* What the places of the encoder fix of the robot's placement among them
 * (the rigid motion lengths cannot see otherwise): 1 one place (a point: the
 * rotation of the whole robot about it is not observable), 2 the places lie
 * on a line (the rotation about that line is not), 3 they span a plane (the
 * robot is fixed in the outlets' frame). Places within RCH_OUTLET_LINE_SHARE
 * of their longest span from the line through the two farthest apart count
 * as on it. pos_mm: (n x 3); off_line_mm (may be NULL): the largest distance
 * from that line. */
#define RCH_OUTLET_LINE_SHARE 0.05
int rch_prior_outlet_span(double *off_line_mm, const double (*pos_mm)[3], unsigned n);
/* One sentence saying what rch_prior_outlet_span's answer means. */
const char *rch_prior_outlet_span_text(int span);

/* How much the data narrowed a parameter's prior: posterior sd / prior sd.
 * Below RCH_PRIOR_DETERMINED the data determined it, above
 * RCH_PRIOR_ONLY only the prior did ("partly" between). */
#define RCH_PRIOR_DETERMINED 0.5
#define RCH_PRIOR_ONLY 0.9
typedef enum { RCH_PRIOR_CLASS_NONE = 0, RCH_PRIOR_CLASS_DETERMINED = 1, RCH_PRIOR_CLASS_PARTLY = 2,
               RCH_PRIOR_CLASS_PRIOR_ONLY = 3 } rch_prior_class;
rch_prior_class rch_prior_classify(double post_sd, double prior_sd);
const char *rch_prior_class_name(rch_prior_class c);

#endif
