/* SPDX-License-Identifier: MIT */
/* rch_urscript_comp.h - a URScript program through the compensation
 * (rch_comp_urscript.c; the reader is rch_urscript.h). Internal to the
 * compensation (prefix rch_cpi_), called by rch_comp_run.c.
 *
 * Joint lists (radians, the controller's joints: rch_ctrl) are corrected as
 * joint targets. A pose p[x,y,z,rx,ry,rz] (metres, rotation vector; the TCP
 * of the last set_tcp before it, else --tool, else the flange) goes through
 * the nominal IK on the branch UR's controller takes: the solution nearest
 * the joints the robot stands at, taken as the previous target's in the
 * text (or get_inverse_kin's qnear); its joints are corrected and the
 * nominal pose of the corrected joints is written. A pose with no joint
 * target or qnear before it is refused (where the robot stands is not in
 * the program). Each written pose is checked as the controller will read
 * it: the nominal solution nearest the compensated previous joints must be
 * the corrected joints, else it is refused. All or nothing. */
#ifndef RCH_URSCRIPT_COMP_H
#define RCH_URSCRIPT_COMP_H

#include <stdio.h>

#include "rch_comp_int.h"

#define RCH_COMP_FORMAT_URSCRIPT ((int)RCH_COMP_URSCRIPT) /* rch_cpi_ctx.format of a URScript program (RCH_COMP_URSCRIPT) */

/* The rest of a URScript input: the line already read (raw, got bytes) and
 * everything after it, at most RCH_URS_MAX_BYTES, corrected all or nothing.
 * 0, 1 (some flagged), -1 (d set). */
int rch_cpi_urscript(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d);

/* 1 when a first line (not blank, not a comment) starts a URScript program:
 * def/sec/global/local/thread, or a call of movej, movel, movep, movec,
 * set_tcp or get_inverse_kin, or a pose literal p[. */
int rch_cpi_urscript_detect(const char *text, size_t n);

#endif
