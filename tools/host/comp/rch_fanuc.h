/* SPDX-License-Identifier: MIT */
/* rch_fanuc.h - the Fanuc LS reader (ASCII TP programs): every position of
 * a program, where its numbers are, and how the program uses it (prefix
 * rch_fanuc_). docs/comp-fanuc.md.
 *
 * Sections, in this order: /PROG name [attributes], then /ATTR and /APPL
 * (copied, not read), /MN (the instructions), /POS (the positions), /END.
 * Another section, a section out of order or missing (/PROG, /MN, /END) is
 * refused.
 *
 * /MN: one statement per numbered line ("  12:  L P[2] 500mm/sec CNT100 ;"),
 * continued on lines that start with ':' (a circular move's second point).
 * Comment statements (! ..., // ...) are skipped. A motion statement (J, L,
 * C, A) names its positions P[n] (or P[n:comment]); C names two. Refused,
 * with file:line:col, because the file does not hold what the robot then
 * does: a motion to a position register PR[...], an indirect index P[R[i]],
 * a motion option that moves the target at run time (Offset, Tool_Offset,
 * INC, VOFFSET, VTOOL_OFFSET, or any PR[] or VR[] among the options), a
 * motion option rcal does not know, UFRAME[i]= / UTOOL[i]= (a frame changed
 * at run time), UFRAME_NUM= / UTOOL_NUM= not set to a literal number, a
 * position P[n] named anywhere but in a motion's target, a motion to a P[n]
 * the /POS section does not hold, and a motion whose position's UF or UT
 * differs from the UFRAME_NUM / UTOOL_NUM set on an earlier line (the
 * controller stops there: frame mismatch).
 *
 * /POS: P[n]{ GP1: UF : u, UT : t, then either
 *   CONFIG : 'F U T, t1, t4, t6', X = x mm, Y = y mm, Z = z mm,
 *   W = w deg, P = p deg, R = r deg
 * or J1 = a deg, ..., J6 = f deg }; (the name P[n:"comment"] allowed; blanks,
 * tabs and line ends anywhere between tokens). Refused: a second group
 * (GP2), extended axes (E1..), a UF or UT that is not a number (F), a
 * duplicate P[n], a number that is not a finite decimal, a field out of
 * order, a config letter other than N/F, U/D, T/B.
 *
 * Lines end at LF, CRLF or a lone CR; a UTF-8 byte-order mark is skipped
 * (offsets stay offsets into the text). Nothing here computes; the caller
 * rewrites the numbers' bytes (num_off/num_len) and copies every other byte.
 *
 * The frames file (rch_fanuc_frames_parse): the controller's user and tool
 * frames, which an LS file does not carry. CSV, '#' comments and blank
 * lines skipped, one frame a line:
 *   uframe,n,x_mm,y_mm,z_mm,w_deg,p_deg,r_deg   (n 1..RCH_FANUC_MAX_FRAMES)
 *   utool,n,x_mm,y_mm,z_mm,w_deg,p_deg,r_deg
 * as the pendant shows them (a user frame in the world frame, a tool frame
 * in the faceplate frame; W, P, R as the positions'). UF 0 is the world,
 * UT 0 the faceplate.
 *
 * Host side: heap, no file I/O. Errors: -1 with rch_diag set (file:line:col). */
#ifndef RCH_FANUC_H
#define RCH_FANUC_H

#include <stddef.h>

#include "rch_diag.h"

#define RCH_FANUC_MAX_BYTES (16u << 20) /* a larger program is refused */
#define RCH_FANUC_NUMS 9                /* numbers a position carries that may change */
#define RCH_FANUC_MAX_FRAMES 61         /* frame numbers 1..61 (more than any controller has) */

typedef struct rch_fanuc_pos {
    unsigned idx;                   /* n of P[n] */
    unsigned line, col;             /* of its 'P' in /POS */
    int joint;                      /* 1: J1..J6 (deg); 0: X, Y, Z (mm), W, P, R (deg) */
    int uf, ut;                     /* its frame numbers */
    char cfg[3];                    /* 'N'/'F', 'U'/'D', 'T'/'B' (Cartesian) */
    unsigned n;                     /* numbers below: 6 (joint) or 9 (Cartesian: the turns of J1, J4, J6) */
    double val[RCH_FANUC_NUMS];     /* J1..J6 | x, y, z, w, p, r, t1, t4, t6 */
    size_t num_off[RCH_FANUC_NUMS]; /* each number's bytes, its sign included */
    size_t num_len[RCH_FANUC_NUMS];
    unsigned num_line[RCH_FANUC_NUMS], num_col[RCH_FANUC_NUMS];
    unsigned n_uses;                /* motion statements that move to it */
    unsigned use_line, use_col;     /* the first one's P[n] */
} rch_fanuc_pos;

typedef struct rch_fanuc_prog {
    char name[40];                  /* /PROG's */
    rch_fanuc_pos *p;               /* in the order of /POS */
    size_t n;
    unsigned n_motion;              /* motion statements */
} rch_fanuc_prog;

/* Read the program text[0..len) (named name in messages). 0, or -1 with d
 * set (prog holds nothing to free then). */
int rch_fanuc_scan(rch_fanuc_prog *prog, const char *text, size_t len, const char *name, rch_diag *d);
void rch_fanuc_free(rch_fanuc_prog *prog);

/* One frame: x, y, z (mm), w, p, r (deg). */
typedef struct rch_fanuc_frames {
    int has_uf[RCH_FANUC_MAX_FRAMES + 1], has_ut[RCH_FANUC_MAX_FRAMES + 1];
    double uf[RCH_FANUC_MAX_FRAMES + 1][6], ut[RCH_FANUC_MAX_FRAMES + 1][6];
} rch_fanuc_frames;

/* The frames file's text (named name): 0, or -1 with d set. Frame 0 of
 * both kinds is the identity, never read from the file. */
int rch_fanuc_frames_parse(rch_fanuc_frames *f, const char *text, size_t len, const char *name, rch_diag *d);

/* Fanuc's W, P, R (deg, fixed angles about x, y, z) -> R = Rz(r) Ry(p) Rx(w)
 * (row-major), and back (p in [-90, 90]). */
void rch_fanuc_wpr_to_rot(double R[9], const double wpr_deg[3]);
void rch_fanuc_rot_to_wpr(double wpr_deg[3], const double R[9]);

#endif
