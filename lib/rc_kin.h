/* SPDX-License-Identifier: MIT */
/* rc_kin.h - the compiled kinematic model of the compensation path (prefix rc_kin_).
 *
 * What: forward kinematics and the 6x6 geometric joint Jacobian of a
 * six-joint DH arm, in the build-time scalar type rc_real (rc_config.h), from
 * a constant table, rc_kin, that holds only what they need: per joint a, d,
 * cos and sin of alpha, the theta offset and the joint limits; the tool
 * offset; and the joint-side effects (periodic joint errors, joint
 * compliance with its frozen reference geometry) in model order. It is the
 * mjModel of MuJoCo's mjModel/mjData split: built once (rc_kin_compile from
 * the solver's rc_model, or generated as a `static const` table for flash by
 * `rcal-rt --emit-c`) and never written afterwards. Everything an evaluation
 * computes on the way (the frames of the chain, dtheta/dq, the chain of the
 * gravity lever) goes to a caller-owned rc_kin_data, so a call needs only a
 * few dozen bytes of stack.
 *
 * Same model, same numbers: with rc_real = double, rc_kin_fk and
 * rc_kin_fk_jac compute what rc_fk and rc_fk_jac of the rc_model it was
 * compiled from compute, operation for operation (bit-identical; tested).
 * Length-side effects (length offset and scale, drift, group offsets) do not
 * move the flange and are not part of rc_kin.
 *
 * Depends on: libm (sin, cos in rc_real). rc_kin_compile (rc_kin_compile.c)
 * also on rc_model; a firmware that links generated tables does not need it.
 * Memory: no heap; rc_kin and rc_kin_data are caller-owned, fixed size.
 * Thread safety: reentrant; an rc_kin may be shared read-only; one
 * rc_kin_data per thread.
 * Errors: rc_kin_compile returns rc_status; evaluations cannot fail (a model
 * or joint vector that is not finite gives non-finite results, which the
 * caller checks); contract violations to RC_ASSERT.
 */
#ifndef RC_KIN_H
#define RC_KIN_H

#include <math.h>
#include <stdint.h>

#include "rc_config.h"
#include "rc_status.h"

/* Joint-side effects an rc_kin can hold (the model's limit by default), and
 * how many of them may be joint compliance (each carries a 4-joint reference
 * geometry). A model with more compiles to RC_ERR_CAPACITY. */
#ifndef RC_KIN_MAX_JOINT_EFFECTS
#define RC_KIN_MAX_JOINT_EFFECTS RC_MAX_EFFECTS
#endif
#ifndef RC_KIN_MAX_COMPLIANCE
#define RC_KIN_MAX_COMPLIANCE 2
#endif
#if RC_KIN_MAX_JOINT_EFFECTS < 1 || RC_KIN_MAX_JOINT_EFFECTS > 255 || RC_KIN_MAX_COMPLIANCE < 1 || \
    RC_KIN_MAX_COMPLIANCE > RC_KIN_MAX_JOINT_EFFECTS
#error "RC_KIN_MAX_JOINT_EFFECTS must be within 1..255 and RC_KIN_MAX_COMPLIANCE within 1..RC_KIN_MAX_JOINT_EFFECTS"
#endif

/* One DH row, T = Rz(q + theta_off) Tz(d) Tx(a) Rx(alpha), alpha stored as
 * its cosine and sine. */
typedef struct rc_kin_link {
    rc_real a_mm;
    rc_real d_mm;
    rc_real cos_alpha;
    rc_real sin_alpha;
    rc_real theta_off_rad;
    rc_real tilt_cm1_rad; /* Hayati's beta of the row (RC_EFF_AXIS_TILT): cos(beta) - 1 ... */
    rc_real tilt_sin;     /* ... and sin(beta); both 0 (a table without them): no tilt */
} rc_kin_link;

/* Kinds of rc_kin_jeffect.kind (the values of rc_effect_kind). */
enum { RC_KIN_JE_COMPLIANCE = 2, RC_KIN_JE_PERIODIC = 3 };

/* A joint-side effect: theta_joint += f(q).
 *  periodic:   c = (s1, c1, s2, c2) rad, f = s1 sin q + c1 cos q + s2 sin 2q + c2 cos 2q
 *  compliance: c[0] = k (rad per m), f = k * gravity lever of the joint (m)
 *              from the reference geometry ref[ref]. */
typedef struct rc_kin_jeffect {
    uint8_t kind;  /* RC_KIN_JE_* */
    uint8_t joint; /* 0..5 */
    uint8_t ref;   /* compliance: index into rc_kin.ref */
    rc_real c[4];
} rc_kin_jeffect;

/* Frozen DH rows of joints 1..4 for a compliance effect's gravity lever. */
typedef struct rc_kin_ref {
    rc_kin_link link[4];
} rc_kin_ref;

typedef struct rc_kin {
    rc_kin_link link[RC_NJ];                      /* (6) DH rows */
    rc_real q_min_rad[RC_NJ];                     /* (6) joint limits */
    rc_real q_max_rad[RC_NJ];
    rc_real tool_mm[3];                           /* tool point in the flange frame (has_tool) */
    uint8_t has_tool;                             /* 1: the FK point is flange + R6 tool_mm */
    uint8_t n_jeff;                               /* joint-side effects used */
    uint8_t n_ref;                                /* reference geometries used */
    rc_kin_jeffect jeff[RC_KIN_MAX_JOINT_EFFECTS]; /* (n_jeff) in model order */
    rc_kin_ref ref[RC_KIN_MAX_COMPLIANCE];         /* (n_ref) */
} rc_kin;

/* Scratch of one evaluation (MuJoCo's mjData): caller-owned, contents
 * undefined between calls except where an evaluation's documentation says. */
typedef struct rc_kin_data {
    rc_real o[RC_NJ + 1][3];  /* frame origins: o[0] base, o[k] after joint k (mm) */
    rc_real R[RC_NJ + 1][9];  /* frame rotations, row-major */
    rc_real theta_rad[RC_NJ]; /* effective joint angles */
    rc_real D[36];            /* (6 x 6) dtheta/dq */
    rc_real lo[5][3];         /* chain of the gravity lever (4 joints) */
    rc_real lR[5][9];
} rc_kin_data;

/* libm in rc_real: the float build calls sinf, cosf, ... (no double). */
#if RC_REAL_IS_FLOAT
#define rc_rsin sinf
#define rc_rcos cosf
#define rc_rsqrt sqrtf
#define rc_ratan2 atan2f
#define rc_rfabs fabsf
#define rc_rfmax fmaxf
#define rc_rfmin fminf
#define RC_REAL_HUGE HUGE_VALF
#else
#define rc_rsin sin
#define rc_rcos cos
#define rc_rsqrt sqrt
#define rc_ratan2 atan2
#define rc_rfabs fabs
#define rc_rfmax fmax
#define rc_rfmin fmin
#define RC_REAL_HUGE HUGE_VAL
#endif

struct rc_model;

/* Compile the kinematics of m into out (converting to rc_real).
 * RC_ERR_RANGE when a DH value, joint limit or effect parameter is not
 * finite or a limit pair is reversed; RC_ERR_CAPACITY when m has more
 * joint-side effects than RC_KIN_MAX_JOINT_EFFECTS or more compliance
 * effects than RC_KIN_MAX_COMPLIANCE. out is fully written either way (all
 * zero on error). Defined in rc_kin_compile.c. */
rc_status rc_kin_compile(rc_kin *out, const struct rc_model *m);

/* Forward kinematics. pos_mm: (3) flange point (tool point with a tool
 * offset); rot: (3 x 3) flange orientation, or NULL; q_rad: (6). */
void rc_kin_fk(rc_real pos_mm[3], rc_real rot[9], rc_kin_data *d, const rc_kin *k, const rc_real q_rad[RC_NJ]);

/* Forward kinematics and the geometric joint Jacobian. jac: (6 x 6)
 * row-major, rows 0..2 d(pos_mm)/d(q_rad), rows 3..5 angular velocity per
 * joint rate; joint-side effects enter by the chain rule. rot may be NULL. */
void rc_kin_fk_jac(rc_real pos_mm[3], rc_real rot[9], rc_real jac[36], rc_kin_data *d, const rc_kin *k,
                   const rc_real q_rad[RC_NJ]);

/* Forward kinematics and its sensitivity to the 24 DH parameters (order
 * a, d, alpha, theta per joint, as rc_model's RC_P_A .. RC_P_THETA), from
 * the chain in closed form: with z_i the axis of joint i at origin o_i,
 * x_{i+1} the x axis of frame i+1 at o_{i+1} and p the FK point,
 *   d p / d theta_i = z_i x (p - o_i)           d w / d theta_i = z_i
 *   d p / d d_i     = z_i                       d w / d d_i     = 0
 *   d p / d a_i     = x_{i+1}                   d w / d a_i     = 0
 *   d p / d alpha_i = x_{i+1} x (p - o_{i+1})   d w / d alpha_i = x_{i+1}
 * where w is the small-rotation vector of the flange in the base frame.
 * A theta offset enters the joint angle with slope 1 whatever the
 * joint-side effects add, so they change the chain, not these formulas.
 * (The encoder and the length-side effects do not move the flange; the
 * tool offset and joint-side effect parameters are not DH columns.)
 * pos_mm (3), rot (3 x 3, or NULL) as rc_kin_fk; jp, jr: (3 x RC_N_DH)
 * row-major, either may be NULL. One chain evaluation: what 48 central
 * differences of rc_kin_fk give, up to their truncation and rounding. */
void rc_kin_fk_dh_jac(rc_real pos_mm[3], rc_real rot[9], rc_real *jp, rc_real *jr, rc_kin_data *d, const rc_kin *k,
                      const rc_real q_rad[RC_NJ]);

/* Solve (A) x = b for a symmetric positive definite 6x6 A by Cholesky, in
 * rc_real. A: (6 x 6) row-major, overwritten by its factor; b: (6), replaced
 * by x. RC_ERR_NUMERIC when A is not positive definite (or not finite). The
 * solver's n x n double version is rcu_chol_solve (rc_linalg.h); this one is
 * the compensation's, kept in rc_real so that a single-precision build never
 * calls double code. */
rc_status rc_kin_chol6(rc_real A[36], rc_real b[RC_NJ]);

#endif /* RC_KIN_H */
