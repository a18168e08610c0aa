/* SPDX-License-Identifier: MIT */
/* rch_krl.h - KUKA KRL programs (.src and .dat) read for compensation
 * (prefix rch_krl_), and KUKA's conventions: A, B, C, Status and Turn.
 *
 * The reader (rch_krl.c) goes through the text line by line (KRL has one
 * statement per line; ';' starts a comment, "..." is a string) and finds
 * every aggregate `{...}` that holds a target:
 *   - declarations `[GLOBAL] DECL [GLOBAL] E6POS|POS|E6AXIS|AXIS NAME={...}`
 *     (DECL may be left out), several on a line;
 *   - assignments `NAME={...}` (the type: the name's declaration in the
 *     file, else the components: A1..A6 an axis target, X..C with S and T a
 *     Cartesian one; X..C without S and T could be a FRAME: refused);
 *   - motion arguments `PTP|LIN|SPTP|SLIN {...}`, `CIRC|SCIRC {aux},{end}`
 *     followed by C_DIS, C_PTP, C_VEL, C_ORI, C_SPL, CA n or a WITH list
 *     that does not set $TOOL or $BASE.
 * FRAME declarations are frames, not targets, and stay as they are.
 * The frames a Cartesian target is read in: $TOOL and $BASE in effect at its
 * line, set by `$TOOL={...}`, `$TOOL=TOOL_DATA[n]`, `$TOOL=$NULLFRAME`,
 * `BAS(#TOOL,n)`, `BAS(#INITMOV,..)` (both $NULLFRAME), `FDAT_ACT=FPn`
 * (likewise $BASE); a point XPn declared in a .dat: the TOOL_NO / BASE_NO of
 * its FDAT FPn in the same file (KUKA's inline forms), else $NULLFRAME.
 * TOOL_DATA[n] and BASE_DATA[n] are taken from the program itself (lines
 * `TOOL_DATA[n]={X ..,A ..}` as $config.dat writes them, anywhere in it);
 * one named but not defined there leaves the frame unknown, and a Cartesian
 * target read in an unknown frame is refused.
 * Refused (the target's error, never passed through): a component that is
 * not a literal decimal number, a missing or repeated one (a partial
 * aggregate takes the rest from the robot's position), an E6POS whose E1..E6
 * are not 0 (a track would move the base), relative motions (PTP_REL,
 * LIN_REL, ...), a motion whose target is an expression (`XP1:{X 10}`), a
 * FRAME as a motion target, an FDAT with IPO_FRAME #TCP (external TCP),
 * WITH $TOOL/$BASE, any other aggregate with target components.
 *
 * Conventions (rch_krl_kin.c): a pose {X,Y,Z,A,B,C} is Trans(X,Y,Z)
 * Rz(A) Ry(B) Rx(C), mm and degrees; it is the TCP ($TOOL) in $BASE, so the
 * flange is $BASE X $TOOL^-1. Status: bit 0 the wrist centre behind axis 1
 * (x < 0 in the A1 coordinate system: the overhead area), bit 1 the wrist
 * centre in front of the line through axes A2 and A3 (A3 >= phi), bit 2
 * A5 < 0; Turn bit i: axis i+1 < 0 deg (docs/comp-krl.md cites them).
 *
 * Host side: the targets on the heap; no stdio. Errors: -1 with d set. */
#ifndef RCH_KRL_H
#define RCH_KRL_H

#include <stddef.h>

#include "rc_model.h"
#include "rch_ctrl.h"
#include "rch_diag.h"
#include "rch_ikg.h"

#define RCH_KRL_MAX_BYTES (16u << 20)
/* component slots: 0..5 X Y Z A B C (or A1..A6), 6 S, 7 T, 8..13 E1..E6 */
#define RCH_KRL_NSLOT 14
#define RCH_KRL_S 6
#define RCH_KRL_T 7
#define RCH_KRL_E1 8

typedef enum rch_krl_type {
    RCH_KRL_AXIS = 1,
    RCH_KRL_E6AXIS = 2,
    RCH_KRL_POS = 3,
    RCH_KRL_E6POS = 4
} rch_krl_type;

typedef enum rch_krl_context {
    RCH_KRL_DECLARATION = 1,
    RCH_KRL_ASSIGNMENT = 2,
    RCH_KRL_MOTION = 3,  /* a motion's target */
    RCH_KRL_CIRC_AUX = 4 /* CIRC's auxiliary point */
} rch_krl_context;

/* A frame {X,Y,Z,A,B,C}: mm and degrees. */
typedef struct rch_krl_frame {
    double v[6];
} rch_krl_frame;

typedef struct rch_krl_target {
    rch_krl_type type;
    rch_krl_context context;
    unsigned line, col;              /* 1-based, of the '{' */
    size_t off, end;                 /* the aggregate: text[off..end) */
    unsigned mask;                   /* slots given (bit k: slot k) */
    double val[RCH_KRL_NSLOT];
    size_t num_off[RCH_KRL_NSLOT];   /* each number's bytes, its sign included */
    size_t num_len[RCH_KRL_NSLOT];
    unsigned num_col[RCH_KRL_NSLOT];
    char name[48];                   /* declared or assigned name; "" for a motion's */
    char instr[8];                   /* the motion (PTP, LIN, ...); "" */
    rch_krl_frame tool, base;        /* Cartesian: the frames it is read in */
    char frames[96];                 /* where they come from ("$TOOL at line 4", "FDAT FP1", ...) */
    char error[320];                 /* not empty: refused (why) */
} rch_krl_target;

typedef struct rch_krl_targets {
    rch_krl_target *t; /* (n) in the order of the text */
    size_t n, cap;
} rch_krl_targets;

/* Every target of text[0..len) (named name in messages) into *out (zero it
 * first; rch_krl_free after). 0, or -1 with d set (out of memory, too
 * large). A target that cannot be read carries its error. */
int rch_krl_scan(rch_krl_targets *out, const char *text, size_t len, const char *name, rch_diag *d);
void rch_krl_free(rch_krl_targets *ts);

const char *rch_krl_type_name(rch_krl_type t);
const char *rch_krl_context_name(rch_krl_context c);

/* rch_krl_kin.c: KUKA's conventions on the model m with the controller map
 * ctl (rch_ctrl.h: the flange frame and the joint signs and zeros). */

/* Frame <-> pose: p (3, mm), R (3 x 3 row-major) of {X,Y,Z,A,B,C}. */
void rch_krl_frame_to_pose(double p[3], double R[9], const rch_krl_frame *f);
void rch_krl_pose_to_frame(rch_krl_frame *f, const double p[3], const double R[9]);

/* Status of controller joints a_deg (6) on m: bits as above. */
int rch_krl_status(const rc_model *m, const rch_ctrl *ctl, const double a_deg[RC_NJ]);
/* Turn of a_deg (6): bit i when axis i+1 < 0. */
int rch_krl_turn(const double a_deg[RC_NJ]);

/* The controller joints a_deg (6) that put the flange at p, R (the
 * controller's flange frame in the robot's root) with Status s and Turn t,
 * inside m's joint limits; ik: rch_ikg_init(ik, m, NULL). 0, or -1 with why
 * set. */
int rch_krl_ik(double a_deg[RC_NJ], const rch_ikg *ik, const rc_model *m, const rch_ctrl *ctl, const double p[3],
               const double R[9], int s, int t, char *why, size_t why_len);
/* The controller's flange pose at controller joints a_deg: p (3), R (9). */
void rch_krl_fk(double p[3], double R[9], const rc_model *m, const rch_ctrl *ctl, const double a_deg[RC_NJ]);

#endif
