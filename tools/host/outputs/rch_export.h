/* SPDX-License-Identifier: MIT */
/* rch_export.h - hand a model on: a URDF of the calibrated robot and the DH
 * table as CSV (docs/export.md).
 *
 * URDF layout (rcal's standard DH, rc_model.h: T_i = Rz(q_i + theta_i)
 * Tz(d_i) Tx(a_i) Rx(alpha_i)). A URDF joint applies its <origin> and then
 * the rotation about its axis, so only what commutes with Rz(q_i) can precede
 * the motion. rcal splits T_i = Rz(q_i) E_i with
 *   E_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
 *       = origin xyz (a_i cos theta_i, a_i sin theta_i, d_i), rpy (alpha_i, 0, theta_i),
 * which URDF's fixed-axis roll-pitch-yaw expresses exactly (no gimbal lock):
 *   joint 1 origin = identity, joint i origin = E_{i-1} (i = 2..6),
 *   the fixed flange joint origin = E_6 (and the tool offset of a model with
 *   RC_EFF_TOOL_OFFSET, so that the flange link is rcal's measured point),
 * all axes (0 0 1), the URDF joint position equal to rcal's joint reading q_i.
 * The joint-zero offsets theta_i are folded into the yaw of the next origin,
 * not written as <calibration>: URDF's <calibration rising/falling> marks
 * reference-switch edges that no kinematics consumer (KDL,
 * robot_state_publisher, MoveIt) applies, so a URDF relying on it would not
 * reproduce the calibrated FK. Each joint's comment gives its offset and the
 * difference calibrated - nominal. Lengths in metres, angles in radians,
 * numbers "%.17g"; every string written into the XML is escaped.
 *
 * DH CSV: header "joint,name,unit,nominal,calibrated,correction,standard_error",
 * then per joint 1..6 the rows a, d (mm), alpha, theta (deg), then the encoder
 * outlet x, y, z (mm; nominal and correction empty: the outlet has no
 * nominal) when the model file gives one, then every effect parameter (the
 * name of rc_param_name, unit mm, deg, rad/m or 1; nominal 0). Correction =
 * calibrated - nominal, angles wrapped into (-180, 180]. standard_error is
 * empty unless the model file carries a "std_error" block (see
 * rch_export_se_parse).
 *
 * Host side (prefix rch_): stdio and the heap. Errors: 0, or -1 with an
 * rch_diag that names the file and what is wrong. */
#ifndef RCH_EXPORT_H
#define RCH_EXPORT_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_diag.h"
#include "rch_robot.h"
#include "rch_urdf.h"

typedef enum { RCH_EXPORT_URDF = 0, RCH_EXPORT_DH_CSV = 1 } rch_export_format;

/* One URDF joint origin: translation (metres) and fixed-axis roll, pitch,
 * yaw (radians): R = Rz(yaw) Ry(pitch) Rx(roll). */
typedef struct {
    double xyz_m[3];
    double rpy_rad[3];
} rch_urdf_origin;

/* The origins of the layout above: origin[0..5] joints 1..6, origin[6] the
 * fixed flange joint (with the tool offset when m has one). (7) */
void rch_urdf_origins(rch_urdf_origin origin[RC_NJ + 1], const rc_model *m);

/* Standard errors of the model's base parameters, when the file has them. */
typedef struct {
    int has;                 /* 1: a std_error block was found */
    int has_dh[RC_NJ][4];    /* per value: given */
    double dh[RC_NJ][4];     /* a_mm, d_mm, alpha_deg, theta_deg */
    int has_enc[3];
    double enc_mm[3];
} rch_export_se;

/* Look for an optional standard-error block in a model file's text:
 * "std_error" (or "standard_error") at the top level or inside
 * "calibration", shaped like the model: {"dh": [{"a_mm": .., "d_mm": ..,
 * "alpha_deg": .., "theta_deg": ..} x 6], "encoder_mm": [x, y, z]}. Missing
 * members (or null) leave that value unknown. 0 (se->has says whether a block
 * was found), or -1 when the block is malformed. */
int rch_export_se_parse(rch_export_se *se, const char *text, size_t len, const char *file, rch_diag *d);

typedef struct {
    rch_export_format format;
    const rch_urdf_names *names;  /* URDF: NULL for the generated names */
    const rch_export_se *se;      /* CSV: NULL for none */
    const char *source;           /* model file named in the URDF's comment; may be NULL */
    int drop_joint_effects;       /* URDF: 1 writes the geometry of a model with joint-side
                                     effects (FK then differs from rcal's); 0 refuses */
} rch_export_cfg;

typedef struct {
    unsigned n_joints;        /* URDF: joints written (6 movable + 1 fixed) */
    unsigned n_rows;          /* CSV: data rows written */
    unsigned n_effects_left;  /* model effects the URDF does not carry (length-side ones,
                                 and joint-side ones with drop_joint_effects) */
    int has_se;               /* CSV: a standard error was written */
    int overlay;              /* URDF with --nominal-urdf: 1 the user's URDF was written with its joint
                                 origins calibrated (rch_urdf_robot.h); 0 its names only (its chain is not
                                 the model's nominal table: overlay_why says how) */
    int flange_moved;         /* overlay: no fixed joint after joint 6 took the flange's change */
    char overlay_why[256];
} rch_export_result;

/* Write robot r in cfg->format to f. URDF: refuses (-1) a model with
 * joint-side effects (joint_periodic, joint_compliance) unless
 * drop_joint_effects; length-side effects do not change the geometry and are
 * listed in a comment. -1 also on a write error. */
int rch_export_write(rch_export_result *res, FILE *f, const rch_export_cfg *cfg, const rch_robot *r, rch_diag *d);

/* The whole export of `rcal export`: load the model file (rch_robot_load, and
 * its standard errors), the nominal URDF when nominal_urdf is not NULL,
 * and write to f. A URDF with a nominal URDF whose chain is the model's
 * nominal table is the overlay (rch_urdf_overlay_write: the user's file,
 * only joint origins changed); else the generated URDF with its names. */
int rch_export_file(rch_export_result *res, FILE *f, rch_export_format format, const char *model_path,
                    const char *nominal_urdf, int drop_joint_effects, rch_diag *d);

#endif
