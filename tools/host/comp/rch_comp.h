/* SPDX-License-Identifier: MIT */
/* rch_comp.h - compensate a robot program's joint targets (prefix rch_comp_).
 *
 * What: streams a program's target list through the compensation
 * (rc_comp_stream_step, lib/rc_comp.h): q' with FK_cal(q') = FK_nom(q) for
 * every target, everything else copied unchanged. Input forms, detected from
 * the first line that is not blank or a comment (or forced):
 *  - CSV without a header: six numbers per line, q1..q6 in degrees; output:
 *    the six corrected angles ("%.6f").
 *  - CSV with a header (first field not a number): the columns q1..q6 (or
 *    j1..j6), any case, are corrected; every other column is copied, so a
 *    whole target list (names, speeds, ...) goes through. The header is copied.
 *  - ABB RAPID (a line starting with MODULE or %%%, or holding
 *    "jointtarget" or "robtarget"): the module is read whole (rch_rapid.h
 *    finds every target literal: declarations, inline arguments,
 *    assignments, several per line, over several lines). A joint target's
 *    six robot axes are corrected ("%.4f"); a robtarget goes through the
 *    nominal IK with its confdata (rch_ik.h), its joints are corrected, and
 *    the nominal pose of the corrected joints is written (trans "%.4f", rot
 *    "%.7f", confdata recomputed). Every other byte is copied. All or
 *    nothing: a target that cannot be corrected (out of reach, singular, a
 *    confdata with no solution, not a literal number, a wrong shape, a
 *    joint limit) is named with line, column and reason, and nothing is
 *    written.
 *  - Fanuc LS (a first line /PROG): read whole, every position of /POS
 *    corrected (rch_comp_fanuc.c, docs/comp-fanuc.md); the user and tool
 *    frames from fanuc_frames_path. All or nothing as RAPID.
 *  - KUKA KRL (.src or .dat; a first line &ACCESS, &REL, &PARAM, &COMMENT,
 *    DEF, DEFDAT, GLOBAL DEF or DECL): read whole (rch_krl.h), axis targets
 *    corrected in the controller's joints, Cartesian ones through the
 *    nominal IK on their Status/Turn branch in their $TOOL/$BASE; all or
 *    nothing as RAPID (rch_comp_krl.c, docs/comp-krl.md).
 * Blank lines and lines starting with '#' are copied. A malformed line or a
 * target outside the joint limits is an error with file:line:col. A target
 * that does not converge is written as the stream's fallback (the closest
 * point found within the bounds; the target plus the last good correction
 * when it follows the previous target on a path) and counted; its warning names the
 * cause (a joint limit, the largest allowed correction, the iteration limit)
 * and the position error of what was written.
 *
 * Files (rch_comp_run): the output is written to a temporary file beside it
 * and renamed into place only when the whole input went through (rch_out,
 * rch_file.h); an output that names the input, the model or the nominal
 * model is refused before anything is written, so a typo never destroys a
 * program or a model (issue 12). "-" is standard input / output (streamed,
 * flushed per line).
 *
 * Host side: stdio and the heap. Errors: -1 with rch_diag set.
 */
#ifndef RCH_COMP_H
#define RCH_COMP_H

#include <stdio.h>

#include "rc_comp.h"
#include "rch_diag.h"
#include "rch_robot.h"
#include "rch_ctrl.h"
#include "rch_uncert.h"

typedef enum rch_comp_format {
    RCH_COMP_AUTO = 0, /* detect from the first line */
    RCH_COMP_CSV = 1,
    RCH_COMP_RAPID = 2,
    RCH_COMP_URSCRIPT = 3, /* a Universal Robots program (.script; rch_urscript_comp.h) */
    RCH_COMP_KRL = 4,      /* KUKA KRL .src/.dat (rch_krl.h): a first line &ACCESS, &REL, &PARAM, &COMMENT, DEF
                              (not ending in a colon: URScript's def), DEFDAT, GLOBAL DEF or DECL */
    RCH_COMP_FANUC = 5     /* a Fanuc LS program (first line /PROG): rch_comp_fanuc.c, docs/comp-fanuc.md */
} rch_comp_format;

/* What a target whose u95 at the compensated point (the flange or the
 * --tool TCP) exceeds max_unc_mm does: left uncompensated with a warning
 * (SKIP, the default), compensated with a warning naming its line and u95
 * (WARN), or the whole run refused (REFUSE: -1 naming the line and u95,
 * the --out file not written). */
typedef enum rch_comp_u95_policy {
    RCH_COMP_U95_SKIP = 0,
    RCH_COMP_U95_WARN = 1,
    RCH_COMP_U95_REFUSE = 2
} rch_comp_u95_policy;

/* What rch_comp_run does; zero-initialise, then set the paths. */
typedef struct rch_comp_job {
    const char *model_path;   /* calibrated model (rcal-model/1); required */
    const char *nominal_path; /* nominal model the targets were made with; NULL: the model file's "nominal" */
    const char *in_path;      /* targets; NULL or "-": standard input */
    const char *out_path;     /* result; NULL or "-": standard output */
    rch_comp_format format;
    int position_only;        /* match the flange position only (forced) */
    int full_pose;            /* position and orientation (forced); neither: rch_comp_orient_decide */
    double max_dev_deg;       /* largest correction per joint; 0: the default 0.1 rad */
    double max_unc_mm;        /* a target where the model's 95 % position uncertainty exceeds this is left
                                 uncompensated, with a warning; 0: 1 mm */
    int accept_robtargets;    /* accepted for old command lines: robtargets are corrected now */
    rch_comp_u95_policy u95_policy; /* what a target beyond max_unc_mm does (default: left uncompensated) */
    const double *tool_mm;    /* (3) the TCP in the flange frame (mm) that compensation places; NULL: the
                                 flange centre. Never the cable attachment point the calibration measured */
    const char *uncertainty_path; /* per target its predicted 95 % position uncertainty (u95_mm, of the point
                                     compensated) as CSV, or NULL */
    int assume_degrees;       /* joint targets are degrees even where they all look like radians; 0: such a
                                 program (rch_data_q_look_rad: every joint within +-pi, two of them moving by
                                 0.2 or more) is refused, nothing written (issue 47) */
    const char *fanuc_frames_path; /* a Fanuc program's user and tool frames (rch_fanuc.h), or NULL */
} rch_comp_job;

/* The model whose point compensation moves: m without its cable attachment
 * (every RC_EFF_TOOL_OFFSET effect removed) and, when tool_mm (3) is not
 * NULL, with that TCP as its tool offset. The calibration measured the
 * attachment; the program means the flange (or its TCP). */
void rch_comp_point_model(rc_model *out, const rc_model *m, const double *tool_mm);

/* m rebuilt with some of its effects left out: the nuisance ones
 * (rc_effect_desc.nuisance) with drop_nuisance, the measured point's offset
 * (RC_EFF_TOOL_OFFSET) with drop_point; with tool_mm (3, may be NULL) a tool
 * offset of that value first. The one place a model loses effects. */
void rch_model_rebuild(rc_model *out, const rc_model *m, int drop_nuisance, int drop_point, const double *tool_mm);

/* What the compensation may act on (issue 10): the determined model is
 * compiled into the stream; these say where it can be trusted. */
typedef struct rch_comp_gate {
    const rc_model *fit;       /* the full fit (for the size of what the held parameters would have moved) */
    const rch_model_unc *unc;  /* covariance of the determined DH parameters; NULL: no gate */
    double max_unc_mm;         /* see rch_comp_job */
    int accept_robtargets;     /* unused (robtargets are corrected) */
    FILE *u95_out;             /* one line "line,u95_mm" per target, or NULL */
    const rc_model *nominal;   /* the nominal model the program was made with (pure DH): the robtargets'
                                  inverse kinematics; NULL: a robtarget is refused */
    const double *tool_mm;     /* (3) the TCP the robtargets are poses of, in the flange frame; NULL: tool0 */
    /* A robtarget used with another TCP (a tooldata the module declares) is
     * compensated at that point: these models without a point (the stream's
     * cal, fit and nominal before rch_comp_point_model) and the stream's
     * config; NULL: such a robtarget is refused */
    const rc_model *det_any, *fit_any;
    const rc_comp_config *cfg;
    rch_comp_u95_policy u95_policy; /* see rch_comp_job */
    int assume_degrees;        /* see rch_comp_job (0: joint targets that look like radians are refused) */
    const rch_ctrl *ctrl;      /* the controller's joint conventions (the nominal file's, else the model
                                  file's "controller"): a joint CSV's values are the controller's, mapped to
                                  the model's and back; NULL: the identity */
    const char *fanuc_frames_path; /* see rch_comp_job */
} rch_comp_gate;

/* What u95_mm says of one target, by how its compensation ended (status: 0
 * converged, 1 position matched with the orientation best effort, 2 not
 * converged, 3 left uncompensated for its uncertainty): the posterior's 95 %
 * radius u95_mm at the target where its position was matched; for 2, u95_mm
 * plus miss_mm, the distance by which the written joints miss the intended
 * point on the calibrated model (what the robot then misses by, to 95 %);
 * for 3 NaN (the robot goes to the program's own joints: the calibrated
 * model's radius there says nothing of that error). The one rule of the
 * command's --uncertainty-out and of the Python package. */
double rch_comp_u95_written(double u95_mm, int status, double miss_mm);

/* Whether compensation corrects the orientation when neither
 * --position-only nor --full-pose forces it (issue 47): when doing so is
 * expected to leave the tool's orientation closer to the program's than not
 * doing it. The tool's axis is the flange z axis (a spindle's or a wheel's
 * on the flange). Over RCH_COMP_ORIENT_POSES poses q uniform in the joint
 * limits (fixed seed): delta, the tilt of that axis that position-only
 * compensation leaves on the calibrated (determined) model, the angle
 * between its z axis at the position-only solution q' and the nominal one at
 * q (the calibrated-vs-nominal rotation at the target, turned by the
 * correction's own joint moves); and tr C_r, the predicted variance of the
 * tilt after correcting (rch_model_unc_rot_trace at q', the rotation
 * perpendicular to the axis; determined part: parameters the data left to
 * the prior sit at the drawing's value either way, and a roll about the
 * axis does not move it). Corrected when the RMS of delta exceeds the RMS
 * of the predicted error (uncorr_deg > unc_deg). A model without a
 * covariance (rcal-model/1) is not decided (known 0): position only, as
 * before. */
#define RCH_COMP_ORIENT_POSES 256
/* Correcting the orientation must be expected to leave the tool's axis this
 * factor closer than not correcting (RMS); within it the two are a tie, and
 * the joints move least (position only). */
#define RCH_COMP_ORIENT_TIE 1.1
typedef struct rch_comp_orient {
    int known;         /* the model carries a covariance: the figures are numbers */
    int tie;           /* correcting was expected closer, but within RCH_COMP_ORIENT_TIE: position only */
    int correct;       /* the decision: match the orientation too */
    double uncorr_deg; /* RMS over the poses of the calibrated-vs-nominal flange rotation angle */
    double unc_deg;    /* RMS over the poses of the predicted orientation error after correcting */
} rch_comp_orient;
/* det: the determined model, nominal: the model the targets were made with
 * (both at the point compensated: rch_comp_point_model); cfg: the run's
 * (its bound; NULL: defaults). unc NULL or without a covariance: known 0,
 * correct 0. */
void rch_comp_orient_decide(rch_comp_orient *o, const rch_model_unc *unc, const rc_model *det,
                            const rc_model *nominal, const rc_comp_config *cfg);
/* The mode a run uses: 1 position only. forced_position / forced_pose: the
 * options; calibrated: the model file has a nominal table or an uncertainty
 * (a bare model is compensated in full pose, as before). */
int rch_comp_position_only(const rch_comp_orient *o, int forced_position, int forced_pose, int calibrated,
                           int orientation_determined);

typedef struct rch_comp_result {
    rch_comp_format format;       /* the form read (detected or forced) */
    unsigned long n;              /* targets compensated */
    unsigned long n_fail;         /* not converged: written as the stream's fallback */
    unsigned long n_pos_only;     /* position matched, orientation best effort */
    unsigned long n_joint_limit;  /* of n_fail: a joint limit was the cause */
    unsigned long iters;          /* iterations, all targets */
    double max_corr_deg;          /* largest correction written */
    double max_fail_err_mm;       /* largest position error of a flagged target, as written */
    double t_ns;                  /* time spent in the compensation */
    int no_nominal;               /* the model file has no "nominal" table and none was given */
    int version1;                 /* the model file carries no uncertainty (rcal-model/1): the held
                                     parameters come from the nominal model's identifiability */
    int position_only_used;       /* the mode compensation ran in */
    int orientation_determined;   /* as the model file says */
    int mode_forced;              /* --position-only or --full-pose chose the mode */
    rch_comp_orient orient;       /* the figures the mode was chosen by (when not forced) */
    int u95_unknown;              /* the model carries no uncertainty: every u95 is NaN ("n/a") */
    unsigned n_held;              /* DH parameters held nominal */
    char held[256];               /* their names */
    double max_held_mm;           /* largest flange move the held parameters' fitted values would have made */
    unsigned long n_uncertain;    /* targets left uncompensated: uncertainty above max_unc_mm */
    double max_pos95_mm;          /* largest 95 % position uncertainty at a compensated target; NaN when the
                                     model carries none */
    unsigned long n_robtargets;   /* of n: RAPID robtargets, Fanuc Cartesian positions corrected (through the
                                     nominal IK) */
} rch_comp_result;

/* Compensate lines of `in` (named in_name in messages) to `out` with the
 * stream s. warn (may be NULL): one warning line per flagged target.
 * Returns 0 (every target converged), 1 (some flagged; the output is
 * complete), -1 (an input error: d set; the output is incomplete). */
int rch_comp_lines(FILE *out, rch_comp_result *res, FILE *in, const char *in_name, rc_comp_stream *s,
                   const rc_model *cal, rch_comp_format format, FILE *warn, rch_diag *d);
/* The same with a gate (may be NULL): targets where the determined model's
 * 95 % position uncertainty exceeds gate->max_unc_mm are written unchanged
 * with a warning and counted (return 1). */
int rch_comp_lines_gated(FILE *out, rch_comp_result *res, FILE *in, const char *in_name, rc_comp_stream *s,
                         const rc_model *cal, const rch_comp_gate *gate, rch_comp_format format, FILE *warn,
                         rch_diag *d);

/* The model compensation uses, from a model file: its determined part
 * (rcal-model/2), or for a version-1 calibrated model the fit with every DH
 * parameter the nominal model's identifiability (400 random poses in the
 * joint limits) ties to an undetermined combination that moves the robot
 * held nominal (unc->present is then 1 with a zero covariance, *version1 1).
 * held/held_len: the held parameters' names. Returns how many are held. */
unsigned rch_comp_determined(rc_model *det, rch_model_unc *unc, int *version1, char *held, size_t held_len,
                             const rch_robot *robot, const rc_model *nominal);

/* --nominal that names the calibrated model itself (issue 47): the same
 * file (rch_path_same) or the same numbers (every DH parameter and effect
 * parameter equal; the encoder's place, which moves no joint, is not
 * compared): compensation would correct nothing. 0, or -1 with d set naming
 * both options. */
int rch_comp_same_model(rch_diag *d, const rch_comp_job *job, const rch_robot *model, const rch_robot *nominal);

/* The whole command: load the models, open the input, refuse an output
 * that is one of the inputs, compensate, commit the output. res: counts
 * (set even on failure). Returns as rch_comp_lines, -1 also for a model or
 * file error (d set; no output file created or changed). */
int rch_comp_run(rch_comp_result *res, const rch_comp_job *job, FILE *warn, rch_diag *d);

/* rcal-rt's --in file: q1..q6 in degrees per row (rch_data,
 * RCH_DATA_TARGETS: the header optional and recognised by its names; every
 * field refused with file:line:col unless a finite decimal number; a joint
 * beyond m's limits refused); a file that looks like radians (every joint
 * within +-pi and two of them moving: rch_data_q_look_rad) refused.
 * q_rad: [n][6] rad, malloc'd (the caller frees). 0, or -1 with d set. */
int rch_comp_read_targets(double (**q_rad)[RC_NJ], size_t *n, const char *path, const rc_kin *m, rch_diag *d);

#endif
