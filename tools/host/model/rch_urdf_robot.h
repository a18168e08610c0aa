/* SPDX-License-Identifier: MIT */
/* rch_urdf_robot.h - a URDF as the nominal model, and a calibrated model
 * written over the user's URDF (prefix rch_urdf_).
 *
 * In: the six revolute (or continuous) joints of one serial chain
 * (rch_urdf_chain; fixed joints between them folded) become a standard DH
 * table (rc_model.h) from their axis lines at q = 0: z of DH frame i-1 is
 * joint i's axis (its URDF direction, so the URDF's joint value is the
 * model's q_i), x along the common normal to the next axis (between
 * parallel axes the perpendicular from the frame's origin), frame 0 on axis
 * 1 at the foot of the root origin with x the root's x made perpendicular,
 * frame 6 on axis 6 at the foot of the flange origin (alpha6 = a6 = 0). What
 * DH leaves out goes to the robot's controller member (rch_ctrl.h): the base
 * B (DH frame 0 in the URDF root link) and the flange F (the flange link in
 * DH frame 6), so that B T_dh(q) F is the URDF's flange pose exactly (tested
 * at 200 poses to 1e-9 m). The flange link: the child of joint 6, followed
 * down fixed joints while a link has exactly one fixed child. Joint limits
 * from <limit> (a continuous joint: +-180 deg). No encoder position.
 *
 * Out (overlay): the user's URDF text with only joint origins rewritten so
 * that its forward kinematics is the calibrated model's: each link keeps its
 * nominal place relative to the DH frame of its joint's axis (N_i), each
 * movable joint's <origin> becomes the calibrated chain's, and the first
 * fixed joint after joint 6 (towards the flange link) takes the flange's
 * change; every other byte (links, meshes, limits, names, comments) is
 * copied. */
#ifndef RCH_URDF_ROBOT_H
#define RCH_URDF_ROBOT_H

#include <stdio.h>

#include "rch_robot.h"
#include "rch_urdf.h"

/* A URDF's text as a robot: model == nominal (no effects), ctrl with B and
 * F, name the robot's. 0, or -1 with the reason in d (not one chain of six
 * revolute joints, an axis of zero length, ...). */
int rch_urdf_robot_parse(rch_robot *out, const char *text, size_t len, const char *file, rch_diag *d);

/* Write the overlay of text (the nominal URDF, file names it) for the
 * calibrated model cal, whose nominal DH table must be the URDF's (each
 * value within 1e-6 mm or rad, angles modulo a turn): else -2 with the
 * difference in d (nothing written). *flange_moved: 1 when the flange's change had no fixed
 * joint after joint 6 to go to (the URDF's last link is then joint 6's
 * child placed as the model's DH frame 6 would carry it). 0, or -1 (d set). */
int rch_urdf_overlay_write(FILE *f, int *flange_moved, const char *text, size_t len, const char *file,
                           const rc_model *nominal, const rc_model *cal, rch_diag *d);

#endif
