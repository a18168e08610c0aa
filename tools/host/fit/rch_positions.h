/* SPDX-License-Identifier: MIT */
/* rch_positions.h - laser-tracker positions as calibration data.
 *
 * A positions file (docs/positions.md: q1..q6 deg, x, y, z mm in the
 * tracker's frame, optional target, pose, sigma_mm) is read by the one CSV
 * reader (rch_data, RCH_DATA_POSITIONS); each row becomes three samples,
 * its x, y and z components (rc_sample.sensor, lib/rc_sensor.h), so the
 * solvers, the posterior and the identifiability see rows as for lengths.
 * The samples of one pose share rc_sample.t = the pose's number (the pose
 * column, else consecutive rows with the same joint readings), so that a
 * held-out split keeps a pose whole (rch_pos_split).
 * The tracker frame (RC_EFF_TRACKER_POSITION, _ROTATION) and the targets
 * (RC_EFF_TRACKER_TARGETS) are effects of the model without a prior; their
 * start is closed form (rch_pos_start: Kabsch fit of the nominal flange
 * points to the measured ones, then the targets, alternated).
 * Errors in 3-D (rch_pos_errors): |p_model - p_measured| over the
 * positions, and ISO 9283 positioning accuracy AP = |mean measured - model|
 * and repeatability RP = mean l + 3 s_l (l the distances of the repeats to
 * their mean) where a pose and target were measured more than once.
 * Host side (prefix rch_pos_). Memory: rch_pos_load allocates, rch_pos_free.
 */
#ifndef RCH_POSITIONS_H
#define RCH_POSITIONS_H

#include <stddef.h>

#include "rc_solve.h"
#include "rch_diag.h"
#include "rch_jw.h"

#define RCH_POS_MAX_FILES 16
typedef struct rch_pos {
    rc_sample *s;       /* (n) three per position row: x, y, z (RC_SENSOR_TRACKER_*); t the pose's number */
    size_t n;
    unsigned *line;     /* (n) source line of each sample */
    unsigned *file;     /* (n) index of its file in the paths given */
    size_t rows;        /* position rows (n / 3) */
    size_t poses;       /* distinct pose numbers */
    unsigned n_targets; /* largest target + 1 */
    int has_sigma;
    double sigma_mm;    /* the median of the sigma_mm column (has_sigma): each row's weight is sigma_mm / its
                           own (rc_sample.weight), so the fit's noise is that of a row at the median */
    size_t dropped;     /* rows identical in every field to an earlier one: warned, dropped */
    char sha256[RCH_POS_MAX_FILES][65]; /* rch_pos_load: each file's digest, of the bytes read (the first
                                           RCH_POS_MAX_FILES files; a calibration reads each file once) */
} rch_pos;

/* Plausibility checks of rch_pos_load (tools/host/fit/rch_pos_read.c). */
#define RCH_POS_REPEAT_MM 1.0      /* one pose and target measured twice: at most this apart (mm) */
#define RCH_POS_SAME_Q_DEG 0.1     /* rows of one pose number: joints at most this apart (deg) */
#define RCH_POS_MIN_SPREAD_MM 50.0 /* scale judged when the nominal points spread this far (RMS, mm) */
#define RCH_POS_SCALE_MIN 0.5      /* measured spread / nominal spread accepted: [MIN, MAX] */
#define RCH_POS_SCALE_MAX 3.0
#define RCH_POS_MIRROR_MIN_MM 3.0  /* mirrored: the rotation leaves more than this (RMS, mm) */
#define RCH_POS_MIRROR_RATIO 0.2   /*   and the reflection less than this part of it */
#define RCH_POS_MIN_ROWS_RIGID 6   /* the controller's positions judged with rows >= this + targets */
#define RCH_POS_ROUNDING_RATIO 1.25 /* rounded joints: the controller's positions when the rigid fit leaves what
                                       the joints' rounding alone leaves, within this factor either way */
#define RCH_POS_ROUNDING_MIN_DEG 0.05 /* joints on a display step of at least this (deg) are judged so */

/* Load positions files paths (k), pose numbers counted on over the files
 * from pose0 (the merged data's first free number); limits: the robot's
 * model, its joint limits checked and its kinematics the nominal the
 * points are judged against (NULL: neither). Before any fit, each file is
 * refused (-1, d: file:line:col, or file: for a finding over the whole
 * file) for: rows with another field count than the header (rch_data);
 * joints or coordinates all within +-7 / +-5 (radians, metres); a pose
 * number reused for other joints (> RCH_POS_SAME_Q_DEG); one pose and
 * target at places more than RCH_POS_REPEAT_MM apart (several targets
 * without a target column, a wrong target); two targets' distance
 * changing from pose to pose by more than that; with limits: a spread of
 * the points outside [RCH_POS_SCALE_MIN, _MAX] times the nominal's (the
 * likely unit named: cm, inches, dm, m, µm); a mirrored frame (the best
 * reflection fits to less than RCH_POS_MIRROR_RATIO of the best rotation's
 * RMS, itself above RCH_POS_MIRROR_MIN_MM; the likely swap named); points
 * the nominal kinematics give after a rigid motion to within 0.75 x the
 * file's decimal step + 1e-6 mm (the controller's computed positions). A
 * row identical in every field to an earlier one is warned on stderr
 * ("file:line: warning: ...") and dropped (dropped), not a repeat. 0 or -1. */
int rch_pos_load(rch_pos *out, const char *const *paths, size_t k, double pose0, const rc_model *limits,
                 rch_diag *d);
/* The same for one file's text (len bytes; name in the diagnostics), the
 * joints not checked against limits, model's kinematics the nominal (NULL:
 * none). What fuzz/fuzz_pos_load.c drives. 0, or -1 with d set. */
/* For a fit (calibrate, diagnose): every target label 0 .. n_targets - 1
 * has rows; a gap is refused at the first row of the label after it (issue
 * 47: target 1 absent was stored at (0, 0, 0), and evaluate then judged a
 * 0.02 mm model 39 mm off). paths: the files p was loaded from. 0, or -1
 * with d set. */
int rch_pos_targets_whole(const rch_pos *p, const char *const *paths, rch_diag *d);
int rch_pos_parse(rch_pos *out, const char *text, size_t len, const char *name, const rc_model *model, rch_diag *d);
void rch_pos_free(rch_pos *p);

/* Samples of s (n) that are lengths (RC_SENSOR_LENGTH) and that are tracker components. */
size_t rch_pos_count_lengths(const rc_sample *s, size_t n);
size_t rch_pos_count_tracker(const rc_sample *s, size_t n);

/* Add the tracker frame and n_targets targets to m when absent (a model
 * with fewer targets gets more, those it had kept). 0, or -1 (capacity). */
int rch_pos_add_effects(rc_model *m, unsigned n_targets);
/* The first parameter of m's effect of kind, or -1; *count its parameters. */
int rch_pos_effect_at(const rc_model *m, unsigned kind, unsigned *count);

/* Closed-form start of the tracker frame and targets of m from the tracker
 * samples of s (n) at m's geometry; keep_frame: m's frame is kept (given as
 * a start) and only the targets are placed. 0, or -1 (fewer than 3 points
 * apart). */
int rch_pos_start(rc_model *m, const rc_sample *s, size_t n, int keep_frame);
/* Set m's tracker frame to frame (6: T mm, rotation vector rad). 0, or -1 (none). */
int rch_pos_set_frame(rc_model *m, const double frame[6]);
/* 1 when m's tracker frame is not all zero (given: a robot file, an option). */
int rch_pos_frame_given(const rc_model *m);

/* What only a sensor absent from s (n) sees is held in fixed (m->n_params):
 * without lengths the outlets, e and the length-side and attachment
 * effects; without tracker samples the tracker's effects. */
void rch_pos_fix_unseen(uint8_t *fixed, const rc_model *m, const rc_sample *s, size_t n);

/* Held-out split keeping a pose whole: idx (n) a permutation (rch_split);
 * rewritten so that the first returned count are the held-out samples
 * (about want), every tracker pose whole on one side. */
size_t rch_pos_split(size_t *idx, const rc_sample *s, size_t n, size_t want);

typedef struct rch_pos_err {
    size_t points;                 /* positions compared (x, y, z triples) */
    double rms_mm, mean_mm, max_mm; /* of |p_model - p_measured| */
    size_t repeated;               /* pose-target pairs measured more than once */
    double ap_max_mm, rp_max_mm;   /* ISO 9283 AP and RP, the largest over them (NAN: none) */
} rch_pos_err;

/* 3-D errors of model m on the tracker samples of s (n). 0, or -1 (a
 * target the model lacks, out of memory). */
int rch_pos_errors(rch_pos_err *e, const rc_model *m, const rc_sample *s, size_t n);
/* e as the JSON object `name` (points, rms, mean, max in mm; repeated,
 * ap_max, rp_max, null without repeats): what calibrate and evaluate write. */
void rch_pos_err_json(rch_jw *w, const char *name, const rch_pos_err *e);

/* A model on tracker data: nothing of the robot refitted. When m has a
 * tracker frame (calibrated from that tracker) and !refit_frame it is
 * kept and only the targets m lacks are fitted; otherwise the frame and
 * every target are fitted (closed-form start, then least squares). */
typedef struct rch_pos_eval {
    rch_pos_err err;
    int frame_fitted;        /* 1: the tracker frame was fitted here */
    unsigned targets_known;  /* targets taken from the model */
    unsigned targets_fitted; /* targets fitted here */
    double frame[6];         /* T (mm) and w (rad) used */
    double rms_component_mm; /* RMS of the x, y, z residual rows */
    rc_model used;           /* the model as evaluated */
} rch_pos_eval;
int rch_pos_evaluate(rch_pos_eval *out, const rc_model *m, const rch_pos *p, int refit_frame, rc_solve_work *w,
                     char *err, size_t errlen);

#endif
