/* SPDX-License-Identifier: MIT */
/* rch_ctrl.h - how a controller's numbers map to the model's (prefix
 * rch_ctrl_): a robot file's optional "controller" member
 *   "controller": {
 *     "joint_sign":     [s1, .., s6],        each +1 or -1 (default +1)
 *     "joint_zero_deg": [z1, .., z6],        the controller's value at model q = 0 (default 0)
 *     "q3_coupling":    k,                   model q3 += k q2 (default 0; Fanuc: -1)
 *     "flange_rpy_deg": [r, p, y],           the controller's flange frame in the last DH frame:
 *     "flange_xyz_mm":  [x, y, z]            F = Trans(xyz) Rz(y) Ry(p) Rx(r) (default identity)
 *     "base_rpy_deg", "base_xyz_mm"          DH frame 0 in the controller's (a URDF root link's)
 *                                            base frame, B likewise (default identity)
 *   }
 * so that the controller's flange pose is B T_dh(q) F, T_dh the model's
 * forward kinematics (rch_ctrl_fk), and
 * with c the controller's joint values (radians)
 *   q_i = s_i (c_i - z_i)          i = 1, 2, 4, 5, 6
 *   q_3 = s_3 (c_3 - z_3) + k q_2
 * (KUKA: A1, A4, A6 turn opposite to the model's right-handed axes, A2 and A3
 * read -90 and +90 at the model's zero; Fanuc: the pendant's J3 is the
 * forearm's angle from the horizon, so the model's q3, measured from the
 * upper arm, is -J3 - J2: sign -1, k = -1). Absent: the identity (the ABB
 * files: the controller's joints are the model's). docs/model-format.md.
 *
 * Host side: no heap, no stdio. */
#ifndef RCH_CTRL_H
#define RCH_CTRL_H

#include "rc_model.h"
#include "rch_diag.h"
#include "rch_jw.h"

struct rch_json; /* rch_json.h (private): the parsed member rch_ctrl_read takes */

typedef struct rch_ctrl {
    int present;            /* 1: the file has a "controller" member */
    int identity_joints;    /* 1: the joint map is the identity (signs +1, zeros 0, k 0) */
    double sign[RC_NJ];
    double zero_rad[RC_NJ];
    double q3_coupling;
    int has_flange;         /* 1: flange_R / flange_mm are not the identity */
    double flange_R[9];     /* row-major, in the last DH frame */
    double flange_mm[3];
    double flange_rpy_deg[3]; /* as read (written back by rch_ctrl_write) */
    int has_base;           /* 1: base_R / base_mm are not the identity */
    double base_R[9];       /* DH frame 0 in the controller's base frame */
    double base_mm[3];
    double base_rpy_deg[3];
} rch_ctrl;

/* The controller's flange pose at model joints q_rad: B T_dh(q) F. pos_mm
 * (3), rot (3 x 3, may be NULL). */
void rch_ctrl_fk(double pos_mm[3], double rot[9], const rch_ctrl *c, const rc_model *m, const double q_rad[RC_NJ]);

/* Rotation (row-major) of URDF's fixed-axis roll, pitch, yaw (rad), and back. */
void rch_ctrl_rpy_to_rot(double R[9], const double rpy_rad[3]);
void rch_ctrl_rot_to_rpy(double rpy_rad[3], const double R[9]);

/* The identity map. */
void rch_ctrl_identity(rch_ctrl *c);

/* Read the "controller" member (NULL: the identity). 0, or -1 with d set
 * (file:line:col of the offending value). */
int rch_ctrl_read(rch_ctrl *c, const struct rch_json *member, const char *file, rch_diag *d);

/* Write c as the "controller" member (nothing when !c->present). */
void rch_ctrl_write(rch_jw *w, const rch_ctrl *c);

/* Controller joints (rad) -> model joints (rad), and back. q and c may alias. */
void rch_ctrl_to_model(double q_rad[RC_NJ], const rch_ctrl *c, const double ctrl_rad[RC_NJ]);
void rch_ctrl_from_model(double ctrl_rad[RC_NJ], const rch_ctrl *c, const double q_rad[RC_NJ]);

#endif
