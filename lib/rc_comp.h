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
 * Depends on: rc_model (FK, Jacobian), rc_linalg (6x6 Cholesky), libm.
 * Memory: no heap; every struct is caller-owned and fixed size; the models
 * are referenced, not copied, and must outlive the stream.
 * Thread safety: reentrant; models may be shared read-only between threads;
 * one rc_comp_stream per thread.
 * Errors: rc_status (see each function); contract violations (NULL where not
 * allowed) to RC_ASSERT. Every function always writes a finite q_out.
 */
#ifndef RC_COMP_H
#define RC_COMP_H

#include "rc_model.h"

/* Flags of rc_comp_config.flags. */
enum {
    RC_COMP_FLAG_POSITION_ONLY = 1u /* match the flange position only */
};

/* All-zero means defaults. */
typedef struct rc_comp_config {
    unsigned max_iter;    /* trial steps per call (both phases), 0: 12 */
    double tol_mm;        /* position tolerance, 0: 1e-5 mm */
    double tol_rad;       /* orientation tolerance, 0: 1e-8 rad */
    double w_rot_mm;      /* weight of orientation error, mm per rad, 0: 100 */
    double lambda_mm;     /* smallest damping lambda (mm/rad), 0: 0.01 */
    double max_step_rad;  /* largest joint change per iteration, 0: 0.2 rad */
    double max_dev_rad;   /* largest |q_out - seed| per joint. 0: 0.1 rad for
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
    RC_COMP_MAX_ITER = 2,      /* position tolerance not met within max_iter */
    RC_COMP_NO_DESCENT = 3,    /* damping reached its limit without progress (bound or singularity) */
    RC_COMP_BAD_INPUT = 4,     /* target or seed not finite, or outside the joint limits */
    RC_COMP_NONFINITE = 5      /* the model produced NaN/inf */
} rc_comp_exit;

typedef struct rc_comp_result {
    rc_comp_exit exit;
    unsigned iterations;      /* trial steps taken (each one rc_fk_jac) */
    double pos_err_mm;        /* |p* - p(q_out)| on the solving model */
    double rot_err_rad;       /* angle of R* R(q_out)^T (0 when no rotation target) */
    double corr_max_rad;      /* max_i |q_out_i - q_i| (rc_comp_joint: the correction) */
    unsigned bound_mask;      /* bit i: joint i ended on a bound (limit or max_dev) */
} rc_comp_result;

/* Short English text of an exit reason; never NULL. */
const char *rc_comp_exit_str(rc_comp_exit e);

/* Joint target on model m that reaches the flange pose (pos_mm, rot).
 * pos_mm: (3) target flange point; rot: (3 x 3) row-major target flange
 * orientation, or NULL for position only; seed_rad: (6) start, must lie
 * within m's joint limits; q_out_rad: (6). res may be NULL; cfg may be NULL.
 * Returns RC_OK (CONVERGED or POSITION_ONLY), RC_ERR_NOCONV (q_out = the best
 * point found: lowest weighted error), RC_ERR_RANGE (bad input; q_out = seed
 * clamped into the limits, or zeros if the seed is not finite),
 * RC_ERR_NUMERIC (model not finite; q_out = seed). */
rc_status rc_comp_pose(double q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *m,
                       const double pos_mm[3], const double rot[9], const double seed_rad[RC_NJ],
                       const rc_comp_config *cfg);

/* Compensate one joint target: q_out with FK_cal(q_out) == FK_nom(q).
 * q_rad: (6) target of the robot program (nominal model); seed_rad: (6)
 * start, or NULL for q itself; q_out_rad: (6). The bound is q +- max_dev
 * (default 0.1 rad) intersected with cal's joint limits.
 * Returns as rc_comp_pose; on RC_ERR_RANGE (q not finite or outside cal's
 * joint limits) q_out = q unchanged (zeros if not finite). */
rc_status rc_comp_joint(double q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *cal,
                        const rc_model *nom, const double q_rad[RC_NJ], const double seed_rad[RC_NJ],
                        const rc_comp_config *cfg);

/* A stream of targets, one call per control cycle. Keeps the last good
 * correction dq = q_out - q: each call is seeded with q + dq (successive
 * targets are close, so this usually converges in one or two iterations), and
 * a call that does not converge outputs q + the last good dq (clamped into the
 * joint limits; q itself before any success) and returns RC_ERR_NOCONV, so the
 * controller keeps a continuous, nearly right command and sees the flag. */
typedef struct rc_comp_stream {
    const rc_model *cal;      /* calibrated model (referenced) */
    const rc_model *nom;      /* nominal model the targets were computed with */
    rc_comp_config cfg;
    double dq_rad[RC_NJ];     /* (6) last good correction */
    int have_dq;              /* dq_rad is valid */
    unsigned long n_ok;       /* calls that converged (RC_OK) */
    unsigned long n_fail;     /* calls that did not (RC_ERR_NOCONV / RANGE / NUMERIC) */
    unsigned fail_run;        /* consecutive failures up to now */
} rc_comp_stream;

/* cfg may be NULL (defaults). Returns RC_OK. */
rc_status rc_comp_stream_init(rc_comp_stream *s, const rc_model *cal, const rc_model *nom,
                              const rc_comp_config *cfg);
/* q_rad: (6) this cycle's nominal target; q_out_rad: (6) corrected target.
 * res may be NULL. Returns RC_OK, RC_ERR_NOCONV (q + last good dq), or
 * RC_ERR_RANGE / RC_ERR_NUMERIC (q unchanged, zeros if not finite). */
rc_status rc_comp_stream_step(rc_comp_stream *s, double q_out_rad[RC_NJ], rc_comp_result *res,
                              const double q_rad[RC_NJ]);

#endif /* RC_COMP_H */
