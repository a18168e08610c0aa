/* SPDX-License-Identifier: MIT */
/* rch_cell.h - the arm's links as capsules, the cell's floor and boxes, and
 * the straight cable between them (issue 48, item 4).
 *
 * A capsule is a segment (from, to) in the frame of one DH row (frame 0 the
 * base, frame i after T_1..T_i, rc_model.h) swept by a radius: the arm's
 * links as a robot file describes them ("links", docs/model-format.md). The
 * cell ("cell") is a floor plane (a point and the normal towards the robot)
 * and axis-aligned boxes in the base frame. The cable is the straight
 * segment from an outlet to the attachment point (the flange point, the
 * tool point or a plate point).
 *
 * A pose is unsafe (rch_cell_check) when
 *  - the flange point or the attachment point is below the floor, or a
 *    moving link (frame >= 1) reaches below it (RCH_CELL_BELOW_FLOOR);
 *  - a moving link enters a box (RCH_CELL_LINK_BOX);
 *  - the cable comes within the clearance of a link (RCH_CELL_CABLE_LINK;
 *    the links of frame 6, which carry the cable's hook, are not checked),
 *    of a box (RCH_CELL_CABLE_BOX) or of the floor (RCH_CELL_CABLE_FLOOR:
 *    the attachment point nearer the floor than the clearance, or the
 *    outlet below it; the outlet itself may stand on the floor).
 * Distances: exact for segment-segment (closest points, clamped) and
 * segment-plane; segment-box by golden-section search of the distance along
 * the segment, which is convex (to 1e-9 of the segment's length).
 * Host side (prefix rch_): no heap; caller-owned structs. */
#ifndef RCH_CELL_H
#define RCH_CELL_H

#include <stddef.h>

#include "rc_model.h"

#define RCH_CELL_MAX_LINKS 16u
#define RCH_CELL_MAX_BOXES 16u
#define RCH_CELL_CLEARANCE_MM 20.0 /* rcal poses --clearance-mm default */

typedef struct rch_capsule {
    char name[32];
    unsigned frame;       /* 0 (base) .. 6 (flange) */
    double from_mm[3], to_mm[3]; /* in that frame */
    double radius_mm;
} rch_capsule;

typedef struct rch_box {
    char name[32];
    double min_mm[3], max_mm[3]; /* base frame, min < max */
} rch_box;

typedef struct rch_cell {
    unsigned n_links;
    rch_capsule link[RCH_CELL_MAX_LINKS];
    int has_floor;
    double floor_point_mm[3], floor_normal[3]; /* unit normal, towards the robot */
    unsigned n_boxes;
    rch_box box[RCH_CELL_MAX_BOXES];
} rch_cell;

typedef enum {
    RCH_CELL_SAFE = 0,
    RCH_CELL_BELOW_FLOOR = 1,
    RCH_CELL_LINK_BOX = 2,
    RCH_CELL_CABLE_LINK = 3,
    RCH_CELL_CABLE_BOX = 4,
    RCH_CELL_CABLE_FLOOR = 5
} rch_cell_reason;
#define RCH_CELL_N_REASONS 6

/* "cable near a link" etc.; "safe" for RCH_CELL_SAFE. */
const char *rch_cell_reason_name(rch_cell_reason r);
/* Its JSON key: "below_floor", "link_in_box", "cable_link", "cable_box", "cable_floor" ("safe"). */
const char *rch_cell_reason_key(rch_cell_reason r);

/* The verdict on one pose: the first reason found (in the order of the enum
 * above after SAFE), which link or box (index, -1: none or the floor), and
 * the distance that failed (mm; negative: inside). */
typedef struct rch_cell_verdict {
    rch_cell_reason reason;
    int which;
    double dist_mm;
} rch_cell_verdict;

/* Every frame of the chain: frames (7 x 12), frame i as R (3 x 3 row-major)
 * then t (3), frame 0 the identity; the joint-side effects included
 * (rc_model_theta), axis tilts not (a plan's nominal model has none). */
void rch_cell_frames(double frames[7][12], const rc_model *m, const double q_rad[RC_NJ]);

/* Link k's segment in the base frame at frames. */
void rch_cell_link_base(double a_mm[3], double b_mm[3], const rch_cell *c, unsigned k, const double frames[7][12]);

/* Distance between segments [p0, p1] and [q0, q1] (mm). */
double rch_cell_seg_seg_mm(const double p0[3], const double p1[3], const double q0[3], const double q1[3]);
/* Signed distance of point p from the floor (positive on the robot's side). */
double rch_cell_floor_mm(const rch_cell *c, const double p[3]);
/* Distance between segment [p0, p1] and box b (0 when they meet). */
double rch_cell_seg_box_mm(const double p0[3], const double p1[3], const rch_box *b);

/* The verdict on pose q: the arm's links of c at q, and the cable from
 * outlet_mm (base frame) to attach_flange_mm (the attachment point in the
 * flange frame: {0,0,0} the flange point). A cell with nothing in it is
 * always safe. */
void rch_cell_check(rch_cell_verdict *out, const rch_cell *c, const rc_model *m, const double q_rad[RC_NJ],
                    const double outlet_mm[3], const double attach_flange_mm[3], double clearance_mm);

/* A plan row about to be run (rcal acquire): sample s measured from outlet
 * (0: the model's encoder, k: its RC_EFF_OUTLET k) to its point (the
 * model's RC_EFF_CABLE_POINTS point s->target, else its tool point, else
 * the flange) with clearance 0: would the cable cross a link, a box or the
 * floor, or the arm go below it? 0: no; 1: yes, why (size) says what and
 * where ("the cable 3.2 mm inside link 4 (upper arm)"). */
int rch_cell_row_refused(char *why, size_t size, const rch_cell *c, const rc_model *m, const rc_sample *s,
                         unsigned outlet);

/* 1: the cell has anything to check (links, a floor or boxes). */
int rch_cell_any(const rch_cell *c);

#endif
