/* SPDX-License-Identifier: MIT */
/* rch_comp_frames.c - the frames a robtarget is read in (see rch_comp.h): a
 * robtarget is the pose of its tool's TCP in its work object, so its flange
 * pose is X = W T F^-1 (W the wobj's uframe x oframe, F the tool's tframe),
 * and the corrected flange pose X' is written back as T' = W^-1 X' F. The
 * tool and work object come from the module (literal tooldata, wobjdata)
 * or --tool; what cannot be read (a moving or robot-held work object, a
 * stationary tool, a rot that is not a unit quaternion) is refused.
 * Depends on: rch_ik (quaternions). Memory: none. Errors: -1 with why set. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "rch_comp_int.h"
#include "rch_ik.h"

static void pose_mul(rch_cpi_pose *o, const rch_cpi_pose *a, const rch_cpi_pose *b)
{
    rch_cpi_pose r;
    for (int i = 0; i < 3; ++i) {
        r.p[i] = a->p[i];
        for (int j = 0; j < 3; ++j) {
            r.p[i] += a->R[3 * i + j] * b->p[j];
            r.R[3 * i + j] = 0;
            for (int k = 0; k < 3; ++k)
                r.R[3 * i + j] += a->R[3 * i + k] * b->R[3 * k + j];
        }
    }
    *o = r;
}

static void pose_inv(rch_cpi_pose *o, const rch_cpi_pose *a)
{
    rch_cpi_pose r;
    for (int i = 0; i < 3; ++i) {
        r.p[i] = 0;
        for (int j = 0; j < 3; ++j) {
            r.R[3 * i + j] = a->R[3 * j + i];
            r.p[i] -= a->R[3 * j + i] * a->p[j];
        }
    }
    *o = r;
}

/* v (7): trans, ABB quaternion (its norm within 1e-3 of 1, normalised). 0 or -1. */
static int pose_from(rch_cpi_pose *o, const double v[7])
{
    const double n = sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(fabs(n - 1.0) <= 1e-3))
        return -1;
    const double q[4] = {v[3] / n, v[4] / n, v[5] / n, v[6] / n};
    memcpy(o->p, v, 3 * sizeof o->p[0]);
    rch_ik_quat_to_rot(o->R, q);
    return 0;
}

static int rot_is_identity(const double v[7])
{
    return v[3] == 1.0 && v[4] == 0.0 && v[5] == 0.0 && v[6] == 0.0;
}

/* The tool and work object the instruction that uses robtarget t names, as
 * the module declares them (or --tool for a tool it does not): 0, or -1
 * with why set. tool: --tool (3) or NULL. */
int rch_cpi_robtarget_frames(rch_cpi_frames *fr, const rch_rapid_target *t, const double *tool, unsigned base,
                             char *why, size_t why_len)
{
    double fv[7] = {0, 0, 0, 1, 0, 0, 0}, wv[7] = {0, 0, 0, 1, 0, 0, 0};
    if (t->use_error[0]) {
        snprintf(why, why_len, "%s", t->use_error);
        return -1;
    }
    pose_from(&fr->W, wv);
    fr->simple = 1;
    if (t->wobj[0] && strcasecmp(t->wobj, "wobj0") != 0) {
        if (!t->wobj_declared) {
            snprintf(why, why_len, "used in work object %s (line %u), which this module does not declare with a "
                     "literal wobjdata: rcal needs its uframe and oframe (declare it in this module)", t->wobj,
                     base + t->use_line);
            return -1;
        }
        if (t->wobj_robhold) {
            snprintf(why, why_len, "used in work object %s (line %u), which the robot holds (robhold TRUE: a "
                     "stationary tool): rcal corrects robtargets of a tool the robot holds", t->wobj,
                     base + t->use_line);
            return -1;
        }
        if (!t->wobj_ufprog) {
            snprintf(why, why_len, "used in work object %s (line %u), whose user frame moves (ufprog FALSE, ufmec "
                     "\"%.40s\"): rcal corrects robtargets in a fixed frame", t->wobj, base + t->use_line,
                     t->wobj_ufmec);
            return -1;
        }
        rch_cpi_pose U, O;
        if (pose_from(&U, t->wobj_uframe) != 0 || pose_from(&O, t->wobj_oframe) != 0) {
            snprintf(why, why_len, "used in work object %s (line %u), whose uframe or oframe rot is not a unit "
                     "quaternion", t->wobj, base + t->use_line);
            return -1;
        }
        pose_mul(&fr->W, &U, &O);
        fr->simple = 0;
    }
    if (t->tool_declared) {
        if (!t->tool_robhold) {
            snprintf(why, why_len, "used with tool %s (line %u), a stationary tool (robhold FALSE): its robtargets "
                     "are not TCP poses", t->tool, base + t->use_line);
            return -1;
        }
        memcpy(fv, t->tool_frame, sizeof fv);
        if (!rot_is_identity(fv))
            fr->simple = 0;
    } else if (t->tool[0] && strcasecmp(t->tool, "tool0") != 0) {
        if (!tool) {
            snprintf(why, why_len, "used with tool %s (line %u), which this module does not declare with a literal "
                     "tooldata: a robtarget is the pose of that tool's TCP; give --tool X,Y,Z (its TCP in the "
                     "flange frame, tool0's orientation) or declare %s in this module", t->tool, base + t->use_line,
                     t->tool);
            return -1;
        }
        /* tool0 is the flange turned 180 deg about z (RCH_IK_TOOL0_RZ_DEG) */
        fv[0] = -tool[0];
        fv[1] = -tool[1];
        fv[2] = tool[2];
    } else if (!t->tool[0] && tool) { /* no instruction of the module uses it: --tool */
        fv[0] = -tool[0];
        fv[1] = -tool[1];
        fv[2] = tool[2];
    }
    if (pose_from(&fr->F, fv) != 0) {
        snprintf(why, why_len, "used with tool %s (line %u), whose tframe rot is not a unit quaternion", t->tool,
                 base + t->use_line);
        return -1;
    }
    fr->tcp[0] = -fv[0];
    fr->tcp[1] = -fv[1];
    fr->tcp[2] = fv[2];
    fr->has_tcp = fv[0] != 0.0 || fv[1] != 0.0 || fv[2] != 0.0 || (tool && !t->tool[0]);
    return 0;
}

/* The flange (tool0) pose of robtarget t read with fr: pos, quat (4). */
void rch_cpi_tool0_pose(double pos[3], double quat[4], const rch_cpi_frames *fr, const rch_rapid_target *t)
{
    rch_cpi_pose T, Fi, X;
    pose_from(&T, t->val); /* its norm is checked by rch_ik_solve */
    pose_mul(&X, &fr->W, &T);
    pose_inv(&Fi, &fr->F);
    pose_mul(&X, &X, &Fi);
    memcpy(pos, X.p, sizeof X.p);
    rch_ik_rot_to_quat(quat, X.R);
}

/* The robtarget read with fr whose flange (tool0) pose is pos, quat (4),
 * in place: T = W^-1 X F. */
void rch_cpi_target_pose(double pos[3], double quat[4], const rch_cpi_frames *fr)
{
    double v[7] = {pos[0], pos[1], pos[2], quat[0], quat[1], quat[2], quat[3]};
    rch_cpi_pose X, Wi, T;
    pose_from(&X, v);
    pose_inv(&Wi, &fr->W);
    pose_mul(&T, &Wi, &X);
    pose_mul(&T, &T, &fr->F);
    memcpy(pos, T.p, sizeof T.p);
    rch_ik_rot_to_quat(quat, T.R);
}
