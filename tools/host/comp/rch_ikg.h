/* SPDX-License-Identifier: MIT */
/* rch_ikg.h - a general inverse kinematics for any six-joint arm of rc_model
 * (prefix rch_ikg_): Newton's method on rc_kin's forward kinematics and
 * geometric Jacobian (lib/rc_kin.h), damped (Levenberg-Marquardt) where the
 * Jacobian is near singular, from the caller's seed and then from a fixed
 * set of starts; every solution classified into a branch.
 *
 * Where it applies: any DH table with any joint-side effect rc_kin carries
 * (an offset wrist as UR's, a KUKA's or Fanuc's spherical one, a user's own
 * table). The closed form of rch_ik.h stays the IK of its class (spherical
 * wrist, axes 2 and 3 parallel); rch_ik_solve falls back to this solver for
 * every other arm.
 *
 * Starts: the caller's seed; then the eight closed-form solutions of the
 * arm's idealised table when it is of a class with one (rch_ikg_seed.c:
 * spherical wrist as rch_ik.h, or UR's offset wrist), each a few Newton
 * steps from the real arm's solution of its branch (a target just past the
 * idealised arm's reach still gets them); then a fixed set of generic starts
 * (any other arm). When none of these gives the asked branch (next to a
 * singularity, where a calibrated arm's solutions lie along an almost free
 * curve or in a close pair across a fold): scans with one joint held (q6:
 * the wrist's self-motion, q1: the shoulder's, q3: across the elbow's fold)
 * from each closed-form start and each solution met, the other five fitted
 * and the solutions located as the roots of the residual's signed component
 * (rch_ikg.c, scan). The fast path is unchanged: the scans cost only where
 * they are needed (milliseconds, next to a singularity).
 *
 * Branch: three bits, each the side of one singularity the configuration
 * is on, so that a branch changes only through that singularity:
 *   4 shoulder: s = ((P - o0) x z1) . z0, P = o5 the origin of DH frame 5
 *     (the wrist centre of a spherical wrist; UR's p05), z0, z1 axes 1, 2
 *     and o0 the base: P in the plane of axis 1 parallel to axis 2;
 *   2 elbow:    e = ((o2 - o1) x (E - o2)) . z1, E = o3 + d4 z3 (on axis 4
 *     where its common normal to axis 5 starts: the wrist centre of a
 *     spherical wrist, UR's elbow point): the arm stretched or folded;
 *   1 wrist:    sin(q5 + theta5) < 0 (theta5 the row's offset; ABB's "axis 5
 *     negative" where theta5 = 0), axes 4 and 6 aligned at sin = 0;
 * the shoulder and elbow bits set when the factor's sign differs from its
 * sign at q = 0 (taken positive where the zero position is itself singular,
 * as a UR's stretched arm). For the closed-form class this is ABB's cfx
 * (rch_ik_confdata; tested). An arm with axes 2 and 3 parallel has one
 * solution per branch (8); a general 6R arm may have up to 16, so several
 * may share a branch: the one nearest the seed is returned.
 *
 * Accuracy: a solution's forward kinematics meets the target within
 * RCH_IKG_TOL_MM and RCH_IKG_TOL_RAD (Newton's last step is quadratic: far
 * below in practice), or, where Newton stalls next to a singularity, within
 * RCH_IKG_ACCEPT_MM and RCH_IKG_ACCEPT_RAD. Joint values: each axis taken in the turn nearest the
 * seed (no seed: in (-180, 180] deg) and moved by whole turns into the
 * model's limits when a turn fits.
 *
 * Host side: no heap, no stdio; reentrant (an rch_ikg is shared read-only). */
#ifndef RCH_IKG_H
#define RCH_IKG_H

#include <stddef.h>

#include "rc_kin.h"
#include "rc_model.h"

#define RCH_IKG_TOL_MM 1e-8
#define RCH_IKG_TOL_RAD 1e-10
/* A Newton run that stops converging (next to a singularity, where the Jacobian's conditioning bounds the
 * last digits) is a solution within these: 1000 times below what a compensated program needs. */
#define RCH_IKG_ACCEPT_MM 1e-6
#define RCH_IKG_ACCEPT_RAD 1e-9
#define RCH_IKG_MAX_SOL 16 /* distinct solutions rch_ikg_all reports */
#define RCH_IKG_ANY_BRANCH (-1)

typedef enum {
    RCH_IKG_OK = 0,
    RCH_IKG_ARG = 1,         /* a bad argument (non-finite target, rotation not orthonormal, branch not 0..7) */
    RCH_IKG_UNREACHABLE = 2, /* no start converged: the pose is out of the arm's reach */
    RCH_IKG_NO_BRANCH = 3,   /* reachable, but not in the branch asked for (a singular or boundary pose) */
    RCH_IKG_LIMITS = 4       /* the branch's solution is outside the joint limits in every turn */
} rch_ikg_status;

const char *rch_ikg_strerror(rch_ikg_status s);

/* A prepared solver: the model compiled (rc_kin, its own tool offset replaced
 * by the TCP given to rch_ikg_init), the reach bound and the branch
 * references. */
typedef struct rch_ikg {
    rc_kin kin;
    double reach_mm;       /* no point of the TCP is farther from the base origin */
    double ref_sign[2];    /* shoulder, elbow factor signs at q = 0 (+1 where 0) */
    double d4_mm;          /* d of row 4 (the elbow point E) */
    double q_min_rad[RC_NJ], q_max_rad[RC_NJ];
    int cls;               /* the closed form its starts come from: RCH_IKG_CLS_* (rch_ikg_seed.c) */
    double ideal[RC_NJ][4]; /* the idealised table (a, d, alpha, theta) of the starts */
    rc_model ideal_model;  /* the same as a model (the spherical class's rch_ik_all) */
} rch_ikg;

enum { RCH_IKG_CLS_NONE = 0, RCH_IKG_CLS_SPHERICAL = 1, RCH_IKG_CLS_OFFSET = 2 };

/* Prepare ik for model m and the TCP tool_mm (3) in the flange frame (NULL:
 * the flange). RCH_IKG_ARG when m does not compile (rc_kin_compile). */
rch_ikg_status rch_ikg_init(rch_ikg *ik, const rc_model *m, const double *tool_mm);

/* The TCP pose at q_rad (6): pos_mm (3), rot (3 x 3 row-major, may be NULL). */
void rch_ikg_fk(double pos_mm[3], double rot[9], const rch_ikg *ik, const double q_rad[RC_NJ]);

/* The branch (0..7, bits above) of the configuration q_rad (6). */
int rch_ikg_branch(const rch_ikg *ik, const double q_rad[RC_NJ]);

/* The bits (4, 2, 1 as the branch's) of the singularities q_rad (6) lies on:
 * its factor within tol of 0 (shoulder: the distance of P from its plane
 * over the reach; elbow: the sine of the angle at o2 between o1 and E;
 * wrist: sin(q5 + theta5)). Within RCH_IKG_BOUNDARY a configuration is on
 * both sides of that boundary: it answers a solve of either label
 * (rch_ikg_solve). */
#define RCH_IKG_BOUNDARY 1e-7
int rch_ikg_on_boundary(const rch_ikg *ik, const double q_rad[RC_NJ], double tol);

/* At a singularity the labels of its two sides meet: a pose made by joints
 * on (or within rounding of) a boundary may have its solution on the other
 * side, a hair away. When no solution of the asked branch is found,
 * rch_ikg_solve returns one of a branch differing only in bits whose boundary
 * it lies within RCH_IKG_NEAR_BOUNDARY of (the same measures; 1e-3: sin q5
 * within 0.06 deg of 0), with info->branch saying which. */
#define RCH_IKG_NEAR_BOUNDARY 1e-3

/* What one solve did (may be NULL). */
typedef struct {
    unsigned starts;      /* Newton runs */
    unsigned iterations;  /* Newton steps over all runs */
    double err_mm;        /* the returned solution's position error (the best reached when refused) */
    double err_rad;       /* its orientation error */
    int branch;           /* the returned solution's branch (-1 when none) */
} rch_ikg_info;

/* The joints q_rad (6) that put the TCP at pos_mm (3) with orientation rot
 * (3 x 3 row-major, orthonormal within 1e-6): of branch `branch` (0..7) or
 * any (RCH_IKG_ANY_BRANCH), the one nearest seed_rad (6, may be NULL: the
 * first found). With a seed, Newton starts there first: a seed close to a
 * solution (a program's previous target, URScript's qnear) costs one run.
 * RCH_IKG_OK, or the reason with q_rad unchanged. info->branch is the
 * returned solution's branch: the asked one, or at a singularity the label
 * across it (RCH_IKG_BOUNDARY, RCH_IKG_NEAR_BOUNDARY above). */
rch_ikg_status rch_ikg_solve(double q_rad[RC_NJ], rch_ikg_info *info, const rch_ikg *ik, const double pos_mm[3],
                             const double rot[9], int branch, const double *seed_rad);

/* Every distinct solution the starts find (joints in (-pi, pi], inside the
 * limits or not): q_rad (RCH_IKG_MAX_SOL x 6), branch (RCH_IKG_MAX_SOL, may
 * be NULL). Returns how many (0: unreachable). */
int rch_ikg_all(double q_rad[RCH_IKG_MAX_SOL][RC_NJ], int branch[RCH_IKG_MAX_SOL], const rch_ikg *ik,
                const double pos_mm[3], const double rot[9]);

#endif
