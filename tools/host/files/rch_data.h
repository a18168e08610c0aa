/* SPDX-License-Identifier: MIT */
/* rch_data.h - reading and writing measurement files (CSV).
 *
 * Format: comma-separated, first line a header; columns are found by name
 * (case-insensitive): q1..q6 joint angles in degrees, L cable length in mm.
 * Optional: x, y, z (the controller's nominal flange position, mm), t
 * (acquisition time or order, any unit; scaled to [0, 1]), group (set-up
 * group, integer >= 0). Every other column is ignored. Blank lines and lines
 * starting with '#' are skipped.
 * A bad field is refused with file, line and column: missing fields, text
 * that is not a number, NaN, infinity, and values no sensor produces
 * (|q| > 720 deg, L < 1 mm or L > 20000 mm; with a robot model, a joint
 * beyond its limits by more than RCH_DATA_LIMIT_TOL_DEG), hexadecimal floats.
 * A row with more or fewer fields than the header (a decimal comma, a lost
 * field: the columns after it shifted) is refused with its line and the
 * counts; empty fields after the header's last (a trailing comma) are not
 * counted. Nothing is silently used.
 * Memory: the loader allocates; rch_data_free releases.
 */
#ifndef RCH_DATA_H
#define RCH_DATA_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_diag.h"

enum {
    RCH_DATA_NO_LEN = 1u,      /* pose plan: L is not required (len_mm = 0) */
    RCH_DATA_POSE = 2u,        /* a 'pose' column (index 0..1e9) is required: pose[] */
    RCH_DATA_ALLOW_EMPTY = 4u, /* a header without rows is not an error */
    RCH_DATA_POSITIONS = 8u,   /* a tracker's positions file: x, y, z (mm, tracker frame) required, L not;
                                  optional target (0..RC_MAX_TARGETS-1, rc_sample.target), pose (pose[]),
                                  sigma_mm (sigma_mm[]); docs/positions.md. Rows stay rows: rch_pos_load
                                  (tools/host/fit/rch_positions.h) makes the three samples of each */
    RCH_DATA_SENSOR = 32u,     /* another sensor's file (rch_data_parse_sensor): its label column (required,
                                  0..RC_MAX_TARGETS-1, rc_sample.target) and value column (optional: value 0
                                  without it; |value| <= 1e4) named by the caller; pose, sigma_mm optional; L, x, y, z, outlet not read */
    RCH_DATA_TARGETS = 16u     /* joint targets (rcal-rt --in): the header is optional. The first line is a
                                  header when one of its fields names a column (q1, L, pose, ... any case),
                                  never because a field fails to parse; otherwise it is the first row of a
                                  file of exactly six fields q1..q6 (degrees), each read as in any row (so
                                  0x10, 1e, inf, nan are refused there with file:line:col). Use with
                                  RCH_DATA_NO_LEN */
};

typedef struct rch_data {
    rc_sample *s;       /* (n) samples, q in rad */
    size_t n;
    double (*xyz)[3];   /* (n x 3) x, y, z columns, or NULL when absent */
    unsigned *line;     /* (n) source line of each sample */
    unsigned long *pose; /* (n) pose column (RCH_DATA_POSE), else NULL */
    int has_t;          /* a t column was present */
    int has_group;      /* a group column was present */
    int has_outlet;     /* an outlet column was present (rc_sample.outlet holds the file's label) */
    int has_target;     /* a target column was present (a tracker's target, a cable's point on a tool plate) */
    double *sigma_mm;   /* (n) RCH_DATA_POSITIONS: the sigma_mm column, or NULL when absent */
} rch_data;

/* Number the outlets of samples s (n) 0, 1, ... in the order their labels
 * (rc_sample.outlet as read) first appear, so that the first outlet is the
 * model's e; label (RC_MAX_OUTLETS) receives each number's label. Returns
 * the number of outlets, or -1 with d set (more than RC_MAX_OUTLETS). */
int rch_data_outlets(uint8_t label[RC_MAX_OUTLETS], rc_sample *s, size_t n, rch_diag *d);
/* The other way: the labels of samples s (n) as read replaced by the outlet
 * numbers a calibration gave them, label (n_labels) being the label of
 * number k (what rch_data_outlets returned then), so that new data read with
 * the same labels meet the same outlets. A label not among them is refused
 * with its line (lines (n), may be NULL) in file name. 0, or -1 with d set. */
int rch_data_outlets_as(const uint8_t *label, unsigned n_labels, rc_sample *s, size_t n, const unsigned *lines,
                        const char *name, rch_diag *d);

#define RCH_DATA_MAX_BYTES ((size_t)1 << 30) /* largest file loaded (1 GiB) */
/* most rows loaded: 1 GiB of short rows is 60 million, about 35 GB for a
 * calibration; 2 million take about 1.1 GB and 45 s */
#define RCH_DATA_MAX_ROWS ((size_t)2000000)

/* Shortest cable length a draw-wire encoder reads (mm): below it a value is
 * a unit or display error (0.001, 1e-300), never a measurement. */
#define RCH_DATA_MIN_LEN_MM 1.0
/* Joint readings beyond the robot's limits by more than this (degrees: the
 * rounding of a file written with 0.1 deg) are refused. */
#define RCH_DATA_LIMIT_TOL_DEG 0.05

/* rch_data_check_scale: at least this many rows, and the robot's spread at
 * least this (mm), else no verdict. */
#define RCH_DATA_SCALE_MIN_ROWS 8
#define RCH_DATA_SCALE_MIN_SPREAD_MM 5.0

/* Load a file (at most RCH_DATA_MAX_BYTES); on failure returns non-zero with d filled in. */
int rch_data_load(rch_data *out, const char *path, unsigned flags, rch_diag *d);
/* The same, also refusing joint readings outside the limits of limits
 * (q_min_rad..q_max_rad, with RCH_DATA_LIMIT_TOL_DEG) with file:line:column;
 * limits NULL: no such check. */
int rch_data_load_limited(rch_data *out, const char *path, unsigned flags, const rc_model *limits, rch_diag *d);
/* Units estimated from the data (issue 33): the spread of the cable lengths
 * (median absolute deviation, the rows of the first row's outlet) against
 * the spread of the distance from m's nominal flange to its encoder outlet
 * at the same joints, and the spread of the x, y, z columns about their
 * centre against m's flange's: a ratio more than 3x from 1 and within 2x of
 * another unit's (cm 0.1, inches 1/25.4, metres 0.001, 0.1 mm 10, ...) is
 * refused naming the unit and the fix ("the cable lengths look like cm: ...
 * (multiply by 10)"). Fewer than RCH_DATA_SCALE_MIN_ROWS rows, or poses
 * spreading less than RCH_DATA_SCALE_MIN_SPREAD_MM: no verdict. Called by
 * rch_data_load_limited for cable files (not plans, not positions).
 * 0, or -1 with d set. */
int rch_data_check_scale(const rch_data *data, const char *name, const rc_model *m, rch_diag *d);
/* The same from memory (name is used in the diagnostics). */
int rch_data_parse(rch_data *out, const char *text, size_t len, const char *name, unsigned flags,
                   rch_diag *d);
/* The same with joint limits (as rch_data_load_limited; limits may be NULL). */
int rch_data_parse_limited(rch_data *out, const char *text, size_t len, const char *name, unsigned flags,
                           const rc_model *limits, rch_diag *d);
/* A sensor's file (RCH_DATA_SENSOR, tools/host/fit/rch_sensors.h): label the
 * name of its label column ("plane"), value of its measured value's (NULL:
 * the sensor has none, value 0); joints within limits' (NULL: unchecked).
 * rc_sample.sensor is left 0: the caller sets its kind. 0, or -1 with d set. */
int rch_data_parse_sensor(rch_data *out, const char *text, size_t len, const char *name, const char *label,
                          const char *value, const rc_model *limits, rch_diag *d);
/* 1 when the header line of text (len; the first line neither blank nor a
 * '#' comment) has a column named column (any case, quotes removed). */
int rch_data_header_has(const char *text, size_t len, const char *column);
void rch_data_free(rch_data *data);

/* Units: joint angles that all stay within +-7 (degrees, as read) look
 * like radians, cable lengths all below 20 mm look like metres: refused
 * with a message naming the likely unit (file name in d). 0 or -1. */
int rch_data_check_units(const rch_data *data, const char *name, rch_diag *d);

/* Joint targets that look like radians where degrees are read (issue 47:
 * rcal compensate, rcal-rt --in). max_abs_deg (RC_NJ): the largest |q| of
 * each joint over the n targets, as read. The rule: every value of every
 * joint within +-RCH_DATA_RAD_BOUND (pi, and its 4-decimal rounding
 * 3.1416) and at least RCH_DATA_RAD_JOINTS joints reaching
 * RCH_DATA_RAD_MOVE somewhere (a radians program moves its joints by tenths
 * of a radian). A program in degrees is refused by it only when every one
 * of its targets stays within 3.14 deg of the all-zero pose in all six
 * joints (q5 near 0: the wrist singularity) while two joints move more than
 * 0.2 deg; all-zero targets (a home position) are never refused. Returns 1
 * with why (why_len) set to the reason, else 0. */
#define RCH_DATA_RAD_BOUND 3.1421
#define RCH_DATA_RAD_MOVE 0.2
#define RCH_DATA_RAD_JOINTS 2
int rch_data_q_look_rad(char *why, size_t why_len, const double max_abs_deg[RC_NJ], size_t n);

/* Copy of the samples selected by idx (k). Returns NULL on allocation failure. */
rc_sample *rch_data_pick(const rc_sample *s, const size_t *idx, size_t k);

/* Write samples as CSV: x,y,z (nominal FK at q when nominal is not NULL),
 * q1..q6 (deg, %.4f), L (mm, %.4f). Returns 0 or -1 (errno set). */
int rch_data_write(FILE *f, const rc_sample *s, size_t n, const rc_model *nominal);

/* Write a pose plan: "pose,q1,..,q6" then one line per sample, q in degrees
 * (%.4f). Read back with rch_data_load(..., RCH_DATA_NO_LEN). 0 or -1. */
int rch_data_write_plan(FILE *f, const rc_sample *s, size_t n);
/* The same with a last column outlet (rc_sample.outlet): a plan for several
 * places of the encoder (`rcal acquire --outlet N` records its rows). */
int rch_data_write_plan_outlets(FILE *f, const rc_sample *s, size_t n);
/* The same with the columns asked for: outlet, and target (rc_sample.target:
 * the cable point of a tool plate each row is measured on). */
int rch_data_write_plan_cols(FILE *f, const rc_sample *s, size_t n, int with_outlet, int with_target);

/* Random train/test split: a permutation of 0..n-1 from seed; the first
 * n_test indices go to test. idx: (n) output. */
void rch_split(size_t *idx, size_t n, unsigned long long seed);

#endif
