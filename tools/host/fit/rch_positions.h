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

typedef struct rch_pos {
    rc_sample *s;       /* (n) three per position row: x, y, z (RC_SENSOR_TRACKER_*); t the pose's number */
    size_t n;
    unsigned *line;     /* (n) source line of each sample */
    unsigned *file;     /* (n) index of its file in the paths given */
    size_t rows;        /* position rows (n / 3) */
    size_t poses;       /* distinct pose numbers */
    unsigned n_targets; /* largest target + 1 */
    int has_sigma;
    double sigma_mm;    /* the median of the sigma_mm column (has_sigma); not a row weight */
} rch_pos;

/* Load positions files paths (k), pose numbers counted on over the files
 * from pose0 (the merged data's first free number); limits: joint limits
 * checked (NULL: none). 0, or -1 with d set (file:line:col). */
int rch_pos_load(rch_pos *out, const char *const *paths, size_t k, double pose0, const rc_model *limits,
                 rch_diag *d);
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
