/* SPDX-License-Identifier: MIT */
/* rch_ffi.h - a flat C API over the core and host libraries for foreign-
 * function use (Python ctypes, python/rcal/), prefix rch_ffi_.
 *
 * What: load a model file, forward kinematics, cable lengths, calibration
 * (from a CSV file or from arrays) with the same pipeline as `rcal
 * calibrate`, writing the calibrated model, and compensation of a batch of
 * joint targets with the same stream as `rcal compensate`.
 *
 * The interface a foreign caller sees is deliberately plain:
 *  - handles are opaque pointers (rch_ffi_model, rch_ffi_calib) created by
 *    rch_ffi_*_load / rch_ffi_calibrate_* and released by the matching
 *    *_free (NULL is accepted there). No struct layout crosses the API, so
 *    compile-time limits such as RC_MAX_PARAMS never leak to the caller.
 *  - numbers are double, counts size_t or unsigned, flags int; arrays are
 *    plain row-major double arrays whose shape is given in the comment of
 *    each parameter ("(n x 6)"). Angles at this interface are DEGREES,
 *    lengths MILLIMETRES (as in the CSV files and the command line).
 *  - every function that can fail returns an int status (rch_ffi_status:
 *    0 on success, negative on failure) and, when err is not NULL, writes a
 *    NUL-terminated message of at most err_len bytes into err: the host
 *    library's diagnostic, "file:line:col: message" when the failure is in
 *    an input file. rch_ffi_strerror() names a status.
 *
 * Depends on: rcal_core, rcal_host (rch_robot, rch_calib, rc_comp).
 * Memory: handles are heap-allocated by this module and owned by the caller
 * until *_free; every array is the caller's. Thread safety: no global
 * state; a handle may be read from several threads, never freed while in use.
 */
#ifndef RCH_FFI_H
#define RCH_FFI_H

#include <stddef.h>

/* Version of this interface; a caller checks it against what it was written
 * for (python/rcal does). Bumped when a signature or a meaning changes. */
#define RCH_FFI_ABI 1

typedef enum rch_ffi_status {
    RCH_FFI_OK = 0,
    RCH_FFI_ERR_ARG = -1,     /* called wrong: NULL handle, n = 0, unknown method or parameter name */
    RCH_FFI_ERR_INPUT = -2,   /* an input file is missing, unreadable or malformed (err: file:line:col) */
    RCH_FFI_ERR_RANGE = -3,   /* a value outside its range (a target outside the joint limits) */
    RCH_FFI_ERR_NUMERIC = -4, /* the model produced NaN/inf (cable length at the encoder outlet) */
    RCH_FFI_ERR_SOLVER = -5,  /* the calibration could not run (too few samples, solver error) */
    RCH_FFI_ERR_NOMEM = -6,   /* out of memory */
    RCH_FFI_ERR_IO = -7       /* writing an output failed, or it would overwrite an input */
} rch_ffi_status;

typedef struct rch_ffi_model rch_ffi_model; /* a robot model with its nominal table */
typedef struct rch_ffi_calib rch_ffi_calib; /* the result of one calibration */

/* RCH_FFI_ABI of the library as built. */
int rch_ffi_abi(void);
/* Short English name of a status; never NULL. */
const char *rch_ffi_strerror(int status);

/* ---- models ---- */

/* Load a model file (rcal-model/1 JSON: a nominal robot such as
 * data/irb120.json, or a calibrated model from rcal calibrate --out). */
int rch_ffi_model_load(rch_ffi_model **out, const char *path, char *err, size_t err_len);
void rch_ffi_model_free(rch_ffi_model *m);
/* The model's "name" into buf (len bytes, truncated). */
int rch_ffi_model_name(const rch_ffi_model *m, char *buf, size_t len);
/* 1 when the file had a "nominal" table (a calibrated model), else 0. */
int rch_ffi_model_has_nominal(const rch_ffi_model *m);
/* Joint limits, degrees. q_min_deg, q_max_deg: (6). */
int rch_ffi_model_limits(const rch_ffi_model *m, double *q_min_deg, double *q_max_deg);
/* Number of model parameters (27 plus the effects' parameters). */
unsigned rch_ffi_model_n_params(const rch_ffi_model *m);
/* Parameter k: its name ("a1", "theta3", "ex", ...) into name (len bytes),
 * its value in mm for lengths, degrees for angles, the effect's own unit
 * otherwise (*unit: 0 mm, 1 deg, 2 other). nominal: 1 for the nominal
 * table's value (27 base parameters only; the encoder is the model's). */
int rch_ffi_model_param(const rch_ffi_model *m, unsigned k, int nominal, char *name, size_t len, double *value,
                        int *unit);

/* Forward kinematics at n poses. pos_mm: (n x 3) flange point (the tool
 * point when the model has a tool offset); rot: (n x 9) row-major flange
 * rotation, or NULL; q_deg: (n x 6). nominal: 1 to use the nominal table. */
/* nominal: 0 the model, 1 its nominal table, 2 its determined part (what
 * compensation uses). */
int rch_ffi_fk(const rch_ffi_model *m, int nominal, double *pos_mm, double *rot, const double *q_deg, size_t n,
               char *err, size_t err_len);
/* Predicted cable length at n poses (rc_meas; samples with t = 0 and group
 * 0, which matters only to time-drift and group-offset effects).
 * len_mm: (n); q_deg: (n x 6). RCH_FFI_ERR_NUMERIC when a flange point
 * coincides with the encoder outlet. */
int rch_ffi_cable_length(const rch_ffi_model *m, double *len_mm, const double *q_deg, size_t n, char *err,
                         size_t err_len);

/* ---- calibration (rcal calibrate) ---- */

/* Options of a calibration, as `rcal calibrate` takes them. robot_path:
 * nominal robot model (required); method: "lm", "ltlm", "lm-paper" or
 * "ltlm-paper" (NULL: "lm"); test_fraction in [0, 1); seed: split and LTLM
 * seed; max_iter: 0 for the method's default; fix: parameters held nominal
 * ("a1,theta6") or NULL; tool_offset: 1 to identify the cable attachment;
 * truth_path: a simulated truth model or NULL (rch_ffi_calib_truth). */

/* Calibrate from a measurements CSV (q1..q6 in degrees, L in mm) with the
 * host function `rcal calibrate` runs (rch_calib_run): the result is the
 * CLI's bit for bit. */
int rch_ffi_calibrate_file(rch_ffi_calib **out, const char *data_path, const char *robot_path, const char *method,
                           double test_fraction, unsigned long seed, unsigned max_iter, const char *fix,
                           int tool_offset, const char *truth_path, char *err, size_t err_len);
/* Calibrate from arrays: q_deg (n x 6) joint readings in degrees, len_mm (n)
 * cable lengths in mm, in acquisition order. They are written exactly
 * ("%.17g") to a temporary CSV that goes through the same reader and
 * pipeline as a file, so arrays holding a file's values give that file's
 * result. */
int rch_ffi_calibrate_arrays(rch_ffi_calib **out, const double *q_deg, const double *len_mm, size_t n,
                             const char *robot_path, const char *method, double test_fraction, unsigned long seed,
                             unsigned max_iter, const char *fix, int tool_offset, const char *truth_path, char *err,
                             size_t err_len);
void rch_ffi_calib_free(rch_ffi_calib *c);

/* Which error metrics rch_ffi_calib_metrics returns. */
enum {
    RCH_FFI_BEFORE = 0,       /* held-out samples (training ones if none held out), BC model */
    RCH_FFI_AFTER = 1,        /* the same samples, identified model (zero when it diverged) */
    RCH_FFI_TRAIN_BEFORE = 2, /* training samples, BC model */
    RCH_FFI_TRAIN_AFTER = 3   /* training samples, identified model */
};
/* out: (6) n, rmse_mm, mean_abs_mm, sd_mm, mean_mm, max_mm. */
int rch_ffi_calib_metrics(const rch_ffi_calib *c, int which, double *out);
/* Counts and solver outcome. Each pointer may be NULL. exit: the solver's
 * exit reason (text) into exit_buf (exit_len bytes). */
int rch_ffi_calib_info(const rch_ffi_calib *c, size_t *n_train, size_t *n_test, int *converged, unsigned *iterations,
                       unsigned *cost_evals, char *exit_buf, size_t exit_len);
/* Parameters of the identified model as `rcal calibrate --json` lists them:
 * value and delta against nominal in mm or degrees (unit as in
 * rch_ffi_model_param). The encoder's delta is against the BC model. */
unsigned rch_ffi_calib_n_params(const rch_ffi_calib *c);
int rch_ffi_calib_param(const rch_ffi_calib *c, unsigned k, char *name, size_t len, double *value, double *delta,
                        int *unit);
/* A new model handle holding the identified model and the robot's nominal
 * table (the model `rcal calibrate --out` writes, at full precision). */
int rch_ffi_calib_model(rch_ffi_model **out, const rch_ffi_calib *c, char *err, size_t err_len);
/* Write the calibrated model file (what `rcal calibrate --out path` writes),
 * whole or not at all, never over one of the calibration's inputs.
 * RCH_FFI_ERR_NUMERIC when the model is not finite, RCH_FFI_ERR_IO on a
 * write error or when path names an input. */
int rch_ffi_calib_write(const rch_ffi_calib *c, const char *path, char *err, size_t err_len);
/* Flange positions against the simulated truth (truth_path given), mm, over
 * the CLI's random poses with base heading and height aligned. out: (4)
 * before_rms, before_max, after_rms, after_max. RCH_FFI_ERR_ARG when the
 * calibration had no truth. */
int rch_ffi_calib_truth(const rch_ffi_calib *c, double *out);
/* The report as `rcal calibrate --json` prints it (one JSON object, the same
 * writer), NUL-terminated into buf (len bytes). *needed (may be NULL): the
 * bytes it takes with the NUL. RCH_FFI_ERR_ARG when buf is NULL or too
 * small (call again with *needed bytes). */
int rch_ffi_calib_json(const rch_ffi_calib *c, char *buf, size_t len, size_t *needed);

/* ---- compensation (rcal compensate) ---- */

/* Compensate n joint targets, in order, with one rc_comp_stream (as `rcal
 * compensate` does line by line): q' with FK_cal(q') = FK_nom(q).
 * cal: calibrated model; nominal: the model the targets were made with, or
 * NULL for cal's "nominal" table. out_deg: (n x 6) corrected targets;
 * status: (n) or NULL, per target 0 converged, 1 position matched with the
 * orientation best effort, 2 not converged (written as the target plus the
 * last good correction), 3 left uncompensated (the model's 95 % position
 * uncertainty there is above 1 mm); q_deg: (n x 6) targets. The model is
 * the determined part of cal (rch_comp_determined), as in `rcal compensate`.
 * position_only: 0 as the model file says (position only unless it says
 * the orientation was determined), 1 position only, 2 position and
 * orientation; max_dev_deg: largest correction per joint, 0 for the
 * default (0.1 rad). A target outside cal's joint limits stops the batch
 * with RCH_FFI_ERR_RANGE ("target i: q j = ... is outside ..."). */
int rch_ffi_compensate(const rch_ffi_model *cal, const rch_ffi_model *nominal, double *out_deg, int *status,
                       const double *q_deg, size_t n, int position_only, double max_dev_deg, char *err,
                       size_t err_len);

#endif /* RCH_FFI_H */
