/* SPDX-License-Identifier: MIT */
/* rch_ik.h - the nominal inverse kinematics of a 6R arm with a spherical
 * wrist, and ABB's robtarget conventions (prefix rch_ik_).
 *
 * The class: standard DH rows (rc_model.h) with alpha2 = 0 (axes 2 and 3
 * parallel), sin(alpha1) != 0, a4 = a5 = d5 = a6 = 0 (axes 4, 5, 6 meet at
 * the wrist centre), alpha4 and alpha5 +-90 deg; a1, d2, d3, alpha3,
 * alpha6 and every joint zero are free. The IRB120's and the KR6's robot
 * files are of it. The model must have no effect that moves the flange
 * (joint-side, geometry or point side): the IK is of the pure DH table.
 *
 * The eight solutions are closed form: axis 1 from the wrist centre's
 * distance to the arm plane (two), axis 3 from its distance to axis 2 (two:
 * the elbow), axis 2 from its direction, axes 4, 5, 6 from the wrist's
 * rotation (two: the flip). ABB's confdata [cf1, cf4, cf6, cfx] picks one:
 * cfx (0..7) = 4 (wrist centre behind axis 1) + 2 (wrist centre behind the
 * lower arm) + 1 (axis 5 negative), each "behind" relative to the zero
 * position's side (RAPID reference manual, confdata); then cf1, cf4, cf6,
 * the quadrants floor(q / 90 deg) of axes 1, 4 and 6, pick the turn of
 * each (q + k 360 deg). A quadrant is met within RCH_IK_QUADRANT_TOL_DEG
 * (a target taught on a quadrant's border).
 *
 * Frames: a robtarget is the pose of the TCP in the base frame (wobj0 with
 * the base at the world origin). ABB's tool0 is the DH flange frame turned
 * 180 deg about its z axis (RCH_IK_TOOL0_RZ_DEG): the IRB120's zero position
 * then reads [[374,0,630],[0.707107,0,0.707107,0]] as its controller shows
 * it. The TCP (tool_mm, may be NULL: the flange) is a point in the DH flange
 * frame, as rcal compensate --tool takes it; its orientation is tool0's.
 * Quaternions are ABB's [q1, q2, q3, q4] = [w, x, y, z]. */
#ifndef RCH_IK_H
#define RCH_IK_H

#include <stddef.h>

#include "rc_model.h"

#define RCH_IK_TOOL0_RZ_DEG 180.0
#define RCH_IK_QUADRANT_TOL_DEG 1.0

/* 0 when m is of the class above, else -1 with the reason in why. */
int rch_ik_supported(const rc_model *m, char *why, size_t why_len);

/* The pose of the TCP (tool_mm (3) in the flange frame, or NULL) at q_rad (6):
 * pos_mm (3), quat (4, w first, w >= 0), cf (4, may be NULL) the confdata of q. */
void rch_ik_fk(double pos_mm[3], double quat[4], int cf[4], const rc_model *m, const double q_rad[RC_NJ],
               const double *tool_mm);

/* ABB's confdata of q_rad (6) on m: cf1, cf4, cf6, cfx. */
void rch_ik_confdata(int cf[4], const rc_model *m, const double q_rad[RC_NJ]);

/* Every closed-form solution of the pose: q_rad (8 x 6), each axis in
 * (-180, 180] deg; returns how many (0..8). */
int rch_ik_all(double q_rad[8][RC_NJ], const rc_model *m, const double pos_mm[3], const double quat[4],
               const double *tool_mm);

/* The solution with confdata cf (4) inside m's joint limits: q_rad (6).
 * quat is normalised first (its norm must be within 1e-3 of 1). 0, or -1
 * with the reason in why (out of reach, singular, no solution with this
 * confdata, a joint limit). */
int rch_ik_solve(double q_rad[RC_NJ], const rc_model *m, const double pos_mm[3], const double quat[4],
                 const int cf[4], const double *tool_mm, char *why, size_t why_len);

/* Rotation (3 x 3 row-major) <-> ABB quaternion (w first; w >= 0 out). */
void rch_ik_quat_to_rot(double rot[9], const double quat[4]);
void rch_ik_rot_to_quat(double quat[4], const double rot[9]);

#endif
