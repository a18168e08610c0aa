/* SPDX-License-Identifier: MIT */
/* rc_comp.h - compensation of joint targets with a calibrated model (prefix rc_comp_).
 *
 * What: a robot program's joint targets q were computed with the nominal
 * model, so the program means the flange pose FK_nom(q). The calibrated model
 * says where the flange really goes, FK_cal(q). Compensation finds q' with
 *   FK_cal(q') == FK_nom(q)
 * by damped Gauss-Newton (Levenberg-Marquardt) on the calibrated model with
 * its analytic joint Jacobian (rc_fk_jac), seeded with q. The same engine
 * solves the inverse use: a Cartesian target (position, optionally a
 * rotation) to the joint target on any model (rc_comp_pose), which is also
 * the numeric inverse kinematics of the nominal model.
 *
 * What is corrected: by default the full 6-D flange pose. A 6R arm has six
 * joints, so position and orientation can both be matched and the solution
 * is locally unique. Position is what the cable encoder measures and is
 * always matched first. Orientation is matched as the calibrated model
 * predicts it: the identified parameters (every a, d, alpha, theta that moves
 * the flange point) also tilt the flange, and that tilt is corrected; the
 * parameters a cable length cannot see (alpha6 and theta6: a rotation of the
 * last frame about the flange point, plus any direction the solver left
 * unidentified) stay at their nominal values in the calibrated model, so they
 * produce no correction: what the data cannot see is left as the nominal
 * model has it. When orientation cannot be matched (at or near a wrist
 * singularity, or when a joint is held by its limit) the position is still
 * matched, the orientation best effort, and the result says so
 * (RC_COMP_POSITION_ONLY). RC_COMP_FLAG_POSITION_ONLY asks for the position
 * alone: then the minimum-norm joint correction is taken (DLS picks no motion
 * along the three redundant directions).
 *
 * Method, per iteration: weighted residual e = [p* - p ; w log(R* R^T)] (mm,
 * w in mm/rad), Jw = [Jp ; w Jw], step (Jw^T Jw + lambda^2 I) dq = Jw^T e by
 * Cholesky (always positive definite, so singular poses give bounded steps
 * and no NaN), step length capped at max_step_rad, joints kept inside
 * [max(q_min, seed - max_dev), min(q_max, seed + max_dev)] by an active set
 * (a joint that would leave its box is put on the bound and the others
 * re-solved for the rest), trial accepted only if the weighted error drops
 * (else lambda grows). One rc_fk_jac per iteration. When the 6-D solve ends
 * without meeting the position tolerance, position-only iterations follow from
 * the best point.
 *
 * Two layers, as MuJoCo splits mjModel from mjData:
 *  - rc_comp_kin_*, rc_comp_stream_init_kin: the engine. It works on compiled,
 *    constant kinematic tables (rc_kin, rc_kin.h: flash on a microcontroller)
 *    and keeps every intermediate (two iterates with their 6x6 Jacobians, the
 *    chain's frames, the normal equations) in a caller-owned rc_comp_work,
 *    so a call needs little stack: rc_comp_stream_step's worst case on a
 *    Cortex-M7 at -Os is checked against 2,048 B by scripts/stack_usage.sh
 *    in the test run. All of it is in rc_real (rc_config.h): double by
 *    default, float with -DRC_REAL_FLOAT, with no double arithmetic left on
 *    this path (checked on a Cortex-M4F build by cross_build.sh).
 *  - rc_comp_joint, rc_comp_pose, rc_comp_stream_init (rc_comp_model.c):
 *    the same on the solver's rc_model, which they compile first; this is
 *    what host code calls.
 *
 * Tolerances follow the scalar type: the defaults are 1e-5 mm and 1e-8 rad
 * in double, and never below what the type can resolve (RC_COMP_TOL_MM,
 * RC_COMP_TOL_RAD: 2^15 and 2^6 machine epsilons, about 0.004 mm on a 1 m
 * arm and 8e-6 rad in float).
 *
 * Depends on: rc_kin (FK, Jacobian, 6x6 Cholesky in rc_real), libm; the
 * rc_model wrappers also on rc_model.
 * Memory: no heap; every struct is caller-owned and fixed size; the rc_kin
 * tables given to the _kin functions are referenced, not copied, and must
 * outlive the stream. rc_comp_stream_init compiles its models into the
 * stream itself (the stream may then be copied).
 * Thread safety: reentrant; models may be shared read-only between threads;
 * one rc_comp_stream or rc_comp_work per thread.
 * Errors: rc_status (see each function); contract violations (NULL where not
 * allowed) to RC_ASSERT. Every function always writes a finite q_out.
 */
#ifndef RC_COMP_H
#define RC_COMP_H

#include <stdint.h>

#include "rc_kin.h"
#include "rc_model.h"

/* Flags of rc_comp_config.flags. */
enum {
    RC_COMP_FLAG_POSITION_ONLY = 1u /* match the flange position only */
};

/* Default tolerances: 1e-5 mm and 1e-8 rad, or what rc_real resolves if
 * that is coarser (float). */
#define RC_COMP_TOL_MM (RC_REAL_EPS * RC_REAL_C(32768.0) > RC_REAL_C(1e-5) ? RC_REAL_EPS * RC_REAL_C(32768.0) : RC_REAL_C(1e-5))
#define RC_COMP_TOL_RAD (RC_REAL_EPS * RC_REAL_C(64.0) > RC_REAL_C(1e-8) ? RC_REAL_EPS * RC_REAL_C(64.0) : RC_REAL_C(1e-8))

/* The stream seeds a target with the last good correction only when no
 * joint moved more than this since that target (a path); a jump (the next
 * target of a program) starts from the target itself, so that one
 * near-singular target cannot steer the next one's solution. */
#define RC_COMP_WARM_RAD RC_REAL_C(0.05)

/* All-zero means defaults. */
typedef struct rc_comp_config {
    unsigned max_iter;    /* trial steps per call (both phases), 0: 12 */
    rc_real tol_mm;       /* position tolerance, 0: RC_COMP_TOL_MM (1e-5 mm in double) */
    rc_real tol_rad;      /* orientation tolerance, 0: RC_COMP_TOL_RAD (1e-8 rad in double) */
    rc_real w_rot_mm;     /* weight of orientation error, mm per rad, 0: 100 */
    rc_real lambda_mm;    /* smallest damping lambda (mm/rad), 0: 0.01 */
    rc_real max_step_rad; /* largest joint change per iteration, 0: 0.2 rad */
    rc_real max_dev_rad;  /* largest |q_out - seed| per joint. 0: 0.1 rad for
                             rc_comp_joint and the stream (a calibration
                             correction larger than ~6 deg means a wrong model),
                             unbounded for rc_comp_pose (inverse kinematics) */
    unsigned flags;       /* RC_COMP_FLAG_* */
} rc_comp_config;

/* How a call ended. */
typedef enum rc_comp_exit {
    RC_COMP_CONVERGED = 0,     /* position and (unless position-only) orientation within tolerance */
    RC_COMP_POSITION_ONLY = 1, /* position within tolerance; orientation could not be matched
                                  (singular pose, workspace boundary, joint limit or
                                  max_dev): best effort */
    RC_COMP_MAX_ITER = 2,      /* position tolerance not met within max_iter, no bound in the way */
    RC_COMP_NO_DESCENT = 3,    /* damping reached its limit without progress (singularity) */
    RC_COMP_BAD_INPUT = 4,     /* target or seed not finite, or outside the joint limits */
    RC_COMP_NONFINITE = 5,     /* the model produced NaN/inf */
    RC_COMP_JOINT_LIMIT = 6,   /* position not met: the step needed a joint beyond its limit
                                  (limit_mask names it) */
    RC_COMP_MAX_DEV = 7        /* position not met: the step needed a correction beyond
                                  max_dev_rad (bound_mask names the joint) */
} rc_comp_exit;

typedef struct rc_comp_result {
    rc_comp_exit exit;
    unsigned iterations;      /* trial steps taken (each one rc_kin_fk_jac) */
    rc_real pos_err_mm;       /* |p* - p(q_out)| on the solving model, for the q_out written
                                 (the stream's fallback output included) */
    rc_real rot_err_rad;      /* angle of R* R(q_out)^T (0 when no rotation target) */
    rc_real corr_max_rad;     /* max_i |q_out_i - q_i| (rc_comp_joint: the correction) */
    unsigned bound_mask;      /* bit i: joint i ended on a bound (limit or max_dev) */
    unsigned limit_mask;      /* bit i: joint i ended on its joint limit */
    int held_last;            /* the stream's RC_ERR_NOCONV: 1 = q_out is the target plus the last good
                                 correction (on a path), 0 = the solver's closest point (a jump) */
} rc_comp_result;

/* Short English text of an exit reason; never NULL. */
const char *rc_comp_exit_str(rc_comp_exit e);

/* One evaluated iterate (part of rc_comp_work). */
typedef struct rc_comp_point {
    rc_real q[RC_NJ]; /* (6) joints, rad */
    rc_real p[3];     /* (3) flange point, mm */
    rc_real R[9];     /* (3 x 3) flange rotation */
    rc_real J[36];    /* (6 x 6) geometric Jacobian */
    rc_real e[6];     /* (6) residual: p* - p (mm), log(R* R^T) (rad) */
    rc_real pos_err;  /* |e[0..2]| mm */
    rc_real rot_err;  /* rotation angle, rad */
    rc_real cost;     /* weighted squared error of the current phase */
} rc_comp_point;

/* Scratch of one compensation call: caller-owned, no meaning between calls. */
typedef struct rc_comp_work {
    rc_comp_point pt[2];  /* current and trial iterate */
    rc_kin_data kd;       /* frames of the chain */
    rc_real A[36];        /* (6 x 6) damped normal matrix */
    rc_real b[RC_NJ];     /* (6) right-hand side, then the step */
    rc_real pd[3];        /* (3) target point of the last call, mm */
    rc_real Rd[9];        /* (3 x 3) target rotation of the last call */
} rc_comp_work;

/* ---- engine on compiled tables ---- */

/* Joint target on model k that reaches the flange pose (pos_mm, rot).
 * pos_mm: (3) target flange point; rot: (3 x 3) row-major target flange
 * orientation, or NULL for position only; seed_rad: (6) start, must lie
 * within k's joint limits; q_out_rad: (6). res may be NULL; cfg may be NULL.
 * Returns RC_OK (CONVERGED or POSITION_ONLY), RC_ERR_NOCONV (q_out = the best
 * point found: lowest weighted error), RC_ERR_RANGE (bad input; q_out = seed
 * clamped into the limits, or zeros if the seed is not finite),
 * RC_ERR_NUMERIC (model not finite; q_out = seed). */
rc_status rc_comp_kin_pose(rc_real q_out_rad[RC_NJ], rc_comp_result *res, rc_comp_work *w, const rc_kin *k,
                           const rc_real pos_mm[3], const rc_real rot[9], const rc_real seed_rad[RC_NJ],
                           const rc_comp_config *cfg);

/* Compensate one joint target: q_out with FK_cal(q_out) == FK_nom(q).
 * q_rad: (6) target of the robot program (nominal model); seed_rad: (6)
 * start, or NULL for q itself; q_out_rad: (6). The bound is q +- max_dev
 * (default 0.1 rad) intersected with cal's joint limits.
 * Returns as rc_comp_kin_pose; on RC_ERR_RANGE (q not finite or outside
 * cal's joint limits) q_out = q unchanged (zeros if not finite); on
 * RC_ERR_NUMERIC q_out = q. */
rc_status rc_comp_kin_joint(rc_real q_out_rad[RC_NJ], rc_comp_result *res, rc_comp_work *w, const rc_kin *cal,
                            const rc_kin *nom, const rc_real q_rad[RC_NJ], const rc_real seed_rad[RC_NJ],
                            const rc_comp_config *cfg);

/* ---- the same on the solver model (rc_comp_model.c): compile, then solve ---- */

/* These two compile their models and keep the tables and the scratch on the
 * stack (about 6 KB in double): host use. Where stack is scarce, compile
 * once and call rc_comp_kin_* with a caller-owned rc_comp_work.
 *
 * As rc_comp_kin_pose on rc_kin_compile(m). A model that does not compile
 * (not finite) gives RC_ERR_NUMERIC with q_out = seed (RC_ERR_RANGE first
 * when the seed is bad). */
rc_status rc_comp_pose(rc_real q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *m, const rc_real pos_mm[3],
                       const rc_real rot[9], const rc_real seed_rad[RC_NJ], const rc_comp_config *cfg);

/* As rc_comp_kin_joint on the compiled cal and nom; a model that does not
 * compile gives RC_ERR_NUMERIC with q_out = q (RC_ERR_RANGE first when q is
 * bad). */
rc_status rc_comp_joint(rc_real q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *cal, const rc_model *nom,
                        const rc_real q_rad[RC_NJ], const rc_real seed_rad[RC_NJ], const rc_comp_config *cfg);

/* ---- a stream of targets, one call per control cycle ----
 * Keeps the last good correction dq = q_out - q: each call is seeded with
 * q + dq (successive targets are close, so this usually converges in one or
 * two iterations), and a call that does not converge returns RC_ERR_NOCONV
 * with, on a path (no joint moved more than RC_COMP_WARM_RAD since the last
 * good target), q + the last good dq (clamped into the joint limits), so the
 * controller keeps a continuous, nearly right command and sees the flag, and
 * after a jump the solver's closest point inside the bounds (never worse
 * than q: the last dq belongs to another pose); res then describes that
 * output (res->held_last says which; its position error is the error of
 * what was output).
 *
 * Counters: n_ok and n_fail are 32-bit and wrap modulo 2^32, i.e. after
 * 4,294,967,296 calls (49.7 days at 1 kHz, 4.97 days at 10 kHz): read them as
 * differences of two readings taken less than a wrap apart, with unsigned
 * 32-bit subtraction (rc_comp_count_since), which is right across the wrap.
 * fail_run saturates at UINT32_MAX instead: a run of failures must never look
 * like a recovery.
 *
 * RC_COMP_STREAM_OWN_MODELS (default 1) gives the stream room for two
 * compiled models, used by rc_comp_stream_init; a firmware that only uses
 * rc_comp_stream_init_kin on tables in flash sets it to 0 and saves
 * 2 x sizeof(rc_kin) of RAM per stream (rc_comp_stream_init is then not
 * defined). Library and callers must agree on it. */
#ifndef RC_COMP_STREAM_OWN_MODELS
#define RC_COMP_STREAM_OWN_MODELS 1
#endif
typedef struct rc_comp_stream {
    const rc_kin *cal;      /* calibrated model (referenced; NULL: own[0]) */
    const rc_kin *nom;      /* nominal model the targets were computed with (NULL: own[1]) */
    rc_comp_config cfg;
    rc_real dq_rad[RC_NJ];  /* (6) last good correction */
    rc_real q_prev_rad[RC_NJ]; /* (6) the target dq_rad was found for */
    int have_dq;            /* dq_rad and q_prev_rad are valid */
    rc_status model_status; /* rc_comp_stream_init: how the models compiled (RC_OK) */
    uint32_t n_ok;          /* calls that converged (RC_OK), modulo 2^32 */
    uint32_t n_fail;        /* calls that did not (RC_ERR_NOCONV / RANGE / NUMERIC), modulo 2^32 */
    uint32_t fail_run;      /* consecutive failures up to now, saturating */
    rc_comp_work work;      /* scratch of the step */
#if RC_COMP_STREAM_OWN_MODELS
    rc_kin own[2];          /* models compiled by rc_comp_stream_init (unused with _init_kin) */
#endif
} rc_comp_stream;

/* Calls counted since an earlier reading `then` of the same counter, across
 * a wrap of the 32-bit counter (correct while fewer than 2^32 calls apart). */
static inline uint32_t rc_comp_count_since(uint32_t now, uint32_t then) { return (uint32_t)(now - then); }

/* Stream over compiled tables (referenced, e.g. `static const rc_kin` in
 * flash). cfg may be NULL (defaults). Returns RC_OK. */
rc_status rc_comp_stream_init_kin(rc_comp_stream *s, const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg);

#if RC_COMP_STREAM_OWN_MODELS
/* Stream over solver models, compiled into the stream (rc_comp_model.c).
 * cfg may be NULL. Returns RC_OK, or rc_kin_compile's error (then every step
 * returns RC_ERR_NUMERIC with q_out = q). */
rc_status rc_comp_stream_init(rc_comp_stream *s, const rc_model *cal, const rc_model *nom, const rc_comp_config *cfg);
#endif

/* q_rad: (6) this cycle's nominal target; q_out_rad: (6) corrected target.
 * res may be NULL. Returns RC_OK, RC_ERR_NOCONV (q + last good dq on a
 * path, else the closest point found), or
 * RC_ERR_RANGE / RC_ERR_NUMERIC (q unchanged, zeros if not finite). */
rc_status rc_comp_stream_step(rc_comp_stream *s, rc_real q_out_rad[RC_NJ], rc_comp_result *res,
                              const rc_real q_rad[RC_NJ]);

#endif /* RC_COMP_H */
