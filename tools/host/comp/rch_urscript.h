/* SPDX-License-Identifier: MIT */
/* rch_urscript.h - the URScript reader (prefix rch_urs_): every joint list
 * and pose literal of a Universal Robots program (.script) that rcal
 * compensate corrects, with the bytes of each number, so that a caller can
 * rewrite the numbers and copy every other byte.
 *
 * Tokens: comments ('#' to the end of the line), strings ("..." and '...',
 * on one line), names, numbers, brackets (round and square, matched by kind).
 * A literal is a square bracket whose elements are all literal numbers: a
 * pose p[x, y, z, rx, ry, rz] (metres, a rotation vector in radians) or a
 * list [q1, ..., q6] (radians). Each is classified by where it stands:
 *
 *   movej/movel/movep(X, ...)        X a target (pose or joint list)
 *   movec(X, Y, ...)                 both the via and the end point
 *   get_inverse_kin(X, qnear=Q, ..)  X a pose target, Q the branch seed (read, kept)
 *   set_tcp(X)                       X the TCP pose used by the pose targets after it
 *   [global|local] name = X          a variable assigned a pose or a joint list
 *
 * (positional or named: pose=, q=, pose_via=, pose_to=, x=, qnear=; a=,
 * v=, t=, r= and every other argument are not read and stay as written).
 * Refused, with the literal's line and column (error set, the caller names it
 * and writes nothing): a pose literal anywhere else (an argument of
 * pose_trans, pose_add, a user function, an expression: it is not a target
 * and rcal cannot tell what it is), a list of six numbers anywhere else
 * except in the arguments of a function known to take other vectors
 * (force_mode, set_payload, ...), a target whose elements are not literal
 * numbers (p[x, 0.2, ...], d2r(10)) or not six of them, and
 * get_inverse_kin's tcp argument (the fifth: another TCP than set_tcp's).
 *
 * Lines end at LF, CRLF or a lone CR, each counted for line:col.
 *
 * Host side: heap, no file I/O. Errors (a string or a bracket not closed,
 * brackets of different kinds, a NUL byte, too large an input): -1 with
 * rch_diag set. */
#ifndef RCH_URSCRIPT_H
#define RCH_URSCRIPT_H

#include <stddef.h>

#include "rch_diag.h"

#define RCH_URS_MAX_BYTES (16u << 20) /* a larger program is refused */
#define RCH_URS_NUMS 6

typedef enum rch_urs_kind {
    RCH_URS_JOINTS = 1, /* [q1..q6] radians */
    RCH_URS_POSE = 2    /* p[x, y, z, rx, ry, rz] metres, rotation vector */
} rch_urs_kind;

typedef enum rch_urs_role {
    RCH_URS_NONE = 0,   /* a refused literal in no target's place (an expression, another function) */
    RCH_URS_MOVE = 1,   /* an argument of movej/movel/movep/movec (instr names which) */
    RCH_URS_ASSIGN = 2, /* assigned to a variable (name) */
    RCH_URS_IK = 3,     /* get_inverse_kin's pose (qnear: the index of its seed, or -1) */
    RCH_URS_TCP = 4,    /* set_tcp's pose: not corrected */
    RCH_URS_QNEAR = 5   /* get_inverse_kin's qnear: not corrected */
} rch_urs_role;

typedef struct rch_urs_target {
    rch_urs_kind kind;
    rch_urs_role role;
    unsigned line, col;              /* 1-based, of the literal ('p' of a pose, '[' of a list) */
    size_t off, end;                 /* the literal: text[off..end) */
    unsigned n;                      /* numbers read: 6, or 0 with an error */
    size_t num_off[RCH_URS_NUMS];    /* each number's bytes, its sign included */
    size_t num_len[RCH_URS_NUMS];
    unsigned num_line[RCH_URS_NUMS], num_col[RCH_URS_NUMS];
    double val[RCH_URS_NUMS];
    char instr[24];                  /* movej, movel, movep, movec, get_inverse_kin, set_tcp; "" assigned */
    char name[48];                   /* the variable assigned ("" otherwise) */
    int arg;                         /* the argument's position (0-based) */
    long qnear;                      /* RCH_URS_IK: index of its qnear target in the list, or -1 */
    char error[200];                 /* not "" when the literal cannot be corrected: why */
} rch_urs_target;

typedef struct rch_urs_targets {
    rch_urs_target *t;
    size_t n, cap;
} rch_urs_targets;

/* Read text[0..len) (named file in messages; its first line is line
 * first_line of the file, 0 or 1: the first). ts: zeroed by the caller;
 * every literal found (in text order), refused ones with error set.
 * 0, or -1 with d set (the text cannot be read at all). */
int rch_urs_scan(rch_urs_targets *ts, const char *text, size_t len, const char *file, unsigned first_line,
                 rch_diag *d);
void rch_urs_free(rch_urs_targets *ts);

/* "joint list" / "pose"; "movej argument", "assignment", ... */
const char *rch_urs_kind_name(rch_urs_kind k);
const char *rch_urs_role_name(rch_urs_role r);

#endif
