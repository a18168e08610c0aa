/* SPDX-License-Identifier: MIT */
/* rch_poses_link.h - a plan as a robot program that speaks rcal-link/1 (docs/controller-link.md), for
 * `rcal poses --format rapid-link|urscript-link`: the program connects to `rcal acquire --controller` at
 * host:port, moves where rcal says and reports its own joints. outlet_label: (n) the rows' outlet column
 * (NULL, or one label throughout: one outlet, reported as -1); point_label: (n) the rows' plate point (the
 * plan's target column; NULL: no plate, reported as -1). 0, or -1 (a write failed). */
#ifndef RCH_POSES_LINK_H
#define RCH_POSES_LINK_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"

/* ABB RAPID: one CONST jointtarget per row (the RAPID reader's), SocketCreate/SocketConnect/SocketSend/
 * SocketReceive, MoveAbsJ ... fine + WaitRob \ZeroSpeed, CJointT (5 decimals), a 1 s ITimer heartbeat, a
 * reconnect in main's ERROR handler. */
int rch_poses_write_rapid_link(FILE *f, const rc_sample *rows, const unsigned char *outlet_label,
                               const unsigned char *point_label, size_t n, const char *host, unsigned port,
                               const char *comment);

/* UR URScript: socket_open / socket_read_line / socket_send_line, movej, is_steady,
 * get_actual_joint_positions (deg via r2d), a heartbeat thread, a reconnect on silence. */
int rch_poses_write_urscript_link(FILE *f, const rc_sample *rows, const unsigned char *outlet_label,
                                  const unsigned char *point_label, size_t n, const char *host, unsigned port,
                                  const char *comment);

#endif
