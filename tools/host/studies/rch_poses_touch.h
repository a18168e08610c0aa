/* SPDX-License-Identifier: MIT */
/* rch_poses_touch.h - planning a touch run (`rcal poses --plate ...`): the
 * poses at which a probe on the tool touches flat plates (docs/touches.md).
 *
 * The user gives each plate's approximate placement in the base frame (a
 * point on its face, the outward normal toward the probe, the usable face's
 * size: a disc of that diameter about the point, less edge_mm), the probe's
 * point in the flange frame and optionally a gauge block of height gauge_mm
 * standing on one plate (its top a disc of gauge_size_mm about gauge_at_mm
 * lifted by the height). Candidates: a point drawn uniformly on a face (a
 * plate's disc outside the block's footprint, or the block's top, a
 * gauge_share of the draws), a probe axis (the flange z) within cone_deg of
 * the face's inward normal (uniform on the cap), turned at random about it;
 * the joints by the general inverse kinematics (rch_ikg_all on the nominal
 * robot with the probe as the TCP), one solution drawn among those that keep
 * every joint margin_deg inside its limits, keep the wrist wrist_deg from its
 * singularity (|sin(q5 + theta5)|), keep the flange origin on the outward
 * side of every plate whose disc it lies over (the probe and the flange not
 * inside a plate) and, with a cell in the robot file, keep the arm's links
 * above the floor and out of the boxes (rch_cell_check with the probe's point
 * as a cable of zero length, clearance 0). The joints are rounded to
 * 0.0001 deg (what the CSV holds).
 *
 * Selection: the position criterion of rch_poses.h on the touch sensor's rows:
 * the model `rcal calibrate` fits (the nominal DH, Hayati's tilt of each
 * nominally parallel axis, touch_tip, plane_normals, plane_offsets; theta1
 * and d1 held), each row's gradient from the core (rc_meas on an
 * RC_SENSOR_PLANE sample: the sensor table's hook), M = P + sum g g^T /
 * noise^2 with the physical prior and a planner's prior on the sensor's own
 * effects (RCH_TOUCH_SD_*: they have none in the fit), I-optimal on the
 * probe point's 3-D error over the workspace (the probe compensated as the
 * tool), greedy then exchange passes, with quotas: every plate at least
 * min_per_plate touches at height 0 (its three parameters), the block's top
 * at least max(3, gauge_share N) when a gauge is given. A plate whose planned
 * points do not spread 1 mm RMS in two directions is an error (as the fit
 * refuses it). Reported: the predicted 95 % radius at the probe beside N
 * random candidates; the rows ordered for travel in one tour (rch_poses_order).
 * Host side (prefix rch_poses_touch_): heap; errors -1 with d set. */
#ifndef RCH_POSES_TOUCH_H
#define RCH_POSES_TOUCH_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_cell.h"
#include "rch_diag.h"
#include "rch_poses.h"
#include "rch_prior.h"

#define RCH_TOUCH_MAX_PLATES RC_MAX_TARGETS
#define RCH_TOUCH_NOISE_MM 0.01     /* the trigger's noise the prediction is for */
#define RCH_TOUCH_SD_TIP_MM 20.0    /* the planner's prior on the probe's drawing */
#define RCH_TOUCH_SD_NORMAL_RAD 0.05 /* ... on a plate's normal (about 3 deg) */
#define RCH_TOUCH_SD_OFFSET_MM 20.0 /* ... on a plate's offset */

typedef struct rch_touch_plate {
    double point_mm[3]; /* a point on the face (the usable disc's centre), base frame */
    double normal[3];   /* the outward normal toward the probe (any length > 0) */
    double size_mm;     /* the usable face's diameter */
} rch_touch_plate;

typedef struct rch_poses_touch_config {
    size_t count;          /* N touches, 1..RCH_POSES_MAX_COUNT */
    size_t candidates;     /* 0: max(2000, 40 N) */
    unsigned long passes;  /* exchange passes */
    unsigned long long seed;
    double margin_deg;     /* kept from every joint limit */
    double cone_deg;       /* the probe's axis within this of the inward normal, 0 < cone <= 80 */
    double edge_mm;        /* kept from a face's edge */
    double wrist_deg;      /* |q5 + theta5| kept this far from 0 and 180 deg */
    unsigned n_plates;
    rch_touch_plate plates[RCH_TOUCH_MAX_PLATES];
    double tool_mm[3];     /* the probe's point, flange frame */
    double gauge_mm;       /* a gauge block's height (0: none) */
    unsigned gauge_plate;  /* the plate it stands on */
    int has_gauge_at;      /* 0: the block stands at the plate's point */
    double gauge_at_mm[3]; /* where it stands (on the plate's face) */
    double gauge_size_mm;  /* its top's usable diameter */
    double gauge_share;    /* the share of candidates (and least share of the plan) on its top */
    unsigned min_per_plate; /* touches at height 0 per plate, >= 3 */
    double noise_mm;       /* 0: RCH_TOUCH_NOISE_MM */
    const rch_prior_cfg *prior; /* NULL: rch_prior_defaults */
    const rch_cell *cell;  /* NULL or empty: not checked */
    size_t n_work, n_eval; /* 0: 300, 1000 */
    int keep_order;        /* 1: the selection's order */
} rch_poses_touch_config;

typedef struct rch_poses_touch_result {
    rc_sample *rows;       /* (n) q_rad (0.0001 deg steps), target = plate, value = height_mm; rch_poses_touch_free */
    size_t n;
    size_t n_candidates, n_tried; /* candidates found; face points tried (the rest: no valid IK solution) */
    size_t no_ik, rejected_limits, rejected_plate, rejected_cell; /* why tried points were not candidates */
    unsigned n_params, nf;
    size_t per_plate[RCH_TOUCH_MAX_PLATES]; /* rows at height 0 per plate */
    size_t gauge_rows;
    double spread_mm[RCH_TOUCH_MAX_PLATES]; /* the smaller RMS spread of each plate's planned points */
    rch_poses_accuracy plan, random;
    size_t random_per_plate_min; /* the fewest touches of a plate among the random rows */
    rch_poses_travel travel;
} rch_poses_touch_result;

/* Checks a configuration (what is wrong and which plate). 0, or -1 with d set. */
int rch_poses_touch_check(const rc_model *m, const rch_poses_touch_config *c, rch_diag *d);

/* Plan a touch run on model m (nominal). progress: NULL or a stream. 0, or -1 with d set. */
int rch_poses_touch_plan(rch_poses_touch_result *res, const rc_model *m, const rch_poses_touch_config *c,
                         FILE *progress, rch_diag *d);
void rch_poses_touch_free(rch_poses_touch_result *res);

/* The plan as a touch file's skeleton: pose,plane,q1..q6 (deg, %.4f) and
 * height_mm with a gauge; q_rad of rows as given (the caller maps them to the
 * controller's joints). 0, or -1 (a write failed). */
int rch_poses_touch_write_csv(FILE *f, const rc_sample *rows, size_t n, int with_height);

#endif
