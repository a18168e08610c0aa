/* SPDX-License-Identifier: MIT */
/* rch_ffi.h - a flat C API over the core and host libraries for foreign-
 * function use (Python ctypes, python/rcal/), prefix rch_ffi_.
 *
 * What: load a model file, forward kinematics, cable lengths, calibration
 * (from CSV files or from arrays, every option of `rcal calibrate` that
 * changes the fit) with the same pipeline as `rcal calibrate`, its
 * standard errors and classes, writing the calibrated model; the diagnosis
 * of `rcal diagnose` with its Next command; `rcal evaluate`; compensation
 * of a batch of joint targets with the same model set-up and stream as
 * `rcal compensate` (the tool point, u95 per target); `rcal export` and the
 * HTML report. Each calls the host function the command calls.
 *
 * The interface a foreign caller sees is deliberately plain:
 *  - handles are opaque pointers (rch_ffi_model, rch_ffi_calib,
 *    rch_ffi_diag) created by rch_ffi_model_load, rch_ffi_calibrate*,
 *    rch_ffi_diagnose and released by the matching *_free (NULL is accepted
 *    there). No struct layout crosses the API, so
 *    compile-time limits such as RC_MAX_PARAMS never leak to the caller.
 *  - numbers are double, counts size_t or unsigned, flags int or unsigned
 *    (OR of RCH_FFI_CAL_* / RCH_FFI_DIAG_*), lists of names a string
 *    ("a1,theta6"), figures of a result by name; arrays are
 *    plain row-major double arrays whose shape is given in the comment of
 *    each parameter ("(n x 6)"). Angles at this interface are DEGREES,
 *    lengths MILLIMETRES (as in the CSV files and the command line).
 *  - every function that can fail returns an int status (rch_ffi_status:
 *    0 on success, negative on failure) and, when err is not NULL, writes a
 *    NUL-terminated message of at most err_len bytes into err: the host
 *    library's diagnostic, "file:line:col: message" when the failure is in
 *    an input file. rch_ffi_strerror() names a status.
 *
 * Depends on: rcal_core, rcal_host (rch_robot, rch_calib, rch_diagnose,
 * rch_evaluate, rch_comp, rch_export, rch_report).
 * Memory: handles are heap-allocated by this module and owned by the caller
 * until *_free; every array is the caller's. Thread safety: no global
 * state; a handle may be read from several threads, never freed while in use.
 */
#ifndef RCH_FFI_H
#define RCH_FFI_H

#include <stddef.h>

/* Version of this interface; a caller checks it against what it was written
 * for (python/rcal does). Bumped when a signature or a meaning changes. */
#define RCH_FFI_ABI 3

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
/* The version of rcal this library was built from (rc_version(),
 * "MAJOR.MINOR.PATCH"); never NULL. */
const char *rch_ffi_version(void);
/* Short English name of a status; never NULL. */
const char *rch_ffi_strerror(int status);
/* The BLAS/LAPACK this library computes with (rch_lapack.h): one line into
 * line (len bytes, truncated), *linked_in 1 when LAPACK and BLAS are inside
 * this library (the build's pinned reference archives), version[3] LAPACK's
 * ILAVER. Either pointer may be NULL. RCH_FFI_OK, RCH_FFI_ERR_ARG for
 * line NULL with len > 0. */
int rch_ffi_lapack(char *line, size_t len, int *linked_in, int *version);

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
 * rotation, or NULL; q_deg: (n x 6). nominal: 0 the model, 1 its nominal
 * table, 2 its determined part (rch_comp_determined). */
int rch_ffi_fk(const rch_ffi_model *m, int nominal, double *pos_mm, double *rot, const double *q_deg, size_t n,
               char *err, size_t err_len);
/* Predicted cable length at n poses (rc_meas; samples with t = 0 and group
 * 0, which matters only to time-drift and group-offset effects).
 * len_mm: (n); q_deg: (n x 6). RCH_FFI_ERR_NUMERIC when a flange point
 * coincides with the encoder outlet. */
int rch_ffi_cable_length(const rch_ffi_model *m, double *len_mm, const double *q_deg, size_t n, char *err,
                         size_t err_len);

/* ---- calibration (rcal calibrate) ---- */

/* Flags of a calibration (OR them), each an option of `rcal calibrate`. */
enum {
    RCH_FFI_CAL_TOOL_OFFSET = 1,     /* --tool-offset: identify the cable attachment in the flange frame */
    RCH_FFI_CAL_JUMPS = 2,           /* --jumps: fit length jumps in acquisition order (nuisance) */
    RCH_FFI_CAL_DEQUANTIZE = 4,      /* --dequantize-joints: rounded joints recovered from x, y, z */
    RCH_FFI_CAL_NO_PRIOR = 8,        /* --no-prior: plain least squares, no physical prior */
    RCH_FFI_CAL_HOLDOUT_GROUPS = 16, /* --holdout-groups: hold out whole set-up groups */
    RCH_FFI_CAL_NO_JUMP_CHECK = 32,  /* --no-jump-check */
    RCH_FFI_CAL_NO_SCREEN = 64,      /* --no-screen: every row fitted, none left out as irreconcilable */
    RCH_FFI_CAL_NO_DEQUANTIZE = 128, /* --no-dequantize-joints: the joints as read (default: automatic) */
    RCH_FFI_CAL_PRIOR_STATED = 256,  /* --prior-stated: the prior's sd as stated, not scaled from the data */
    RCH_FFI_CAL_NO_LENGTH_OFFSET = 512, /* --no-length-offset: a display's zero never weighed by default */
    RCH_FFI_CAL_NO_DRIFT = 1024,     /* --no-drift: a drift over the run never weighed by default */
    RCH_FFI_CAL_FORCE = 2048         /* --force: write a model the judge refuses (rch_calib_judge.c) */
};

/* Calibrate with the host function `rcal calibrate` runs (rch_calib_run):
 * the result is the CLI's bit for bit, with the CLI's checks before the fit
 * (each data file once, --validate not a --data file, every joint reading
 * within the robot's limits: file:line:col).
 * data_paths: (n_data, 1..16) measurement CSVs (q1..q6 deg, L mm; optional
 * x, y, z, t, group, outlet columns), merged as several --data;
 * robot_path: nominal robot model (required); method: "lm", "ltlm",
 * "lm-paper", "ltlm-paper", "lm-paper-deg", "ltlm-paper-deg" (NULL: "lm");
 * test_fraction in [0, 1); seed: split and LTLM seed; max_iter: 0 for the
 * method's default; fix: parameters held nominal ("a1,theta6") or NULL;
 * effects: --effects list ("cable_sag,joint_periodic:2") or NULL; flags:
 * RCH_FFI_CAL_*; validate_path: --validate file or NULL; truth_path: a
 * simulated truth model or NULL (rch_ffi_calib_truth); cases, case_samples:
 * --cases (0 or 1: one calibration) and --samples; plots_dir: --plots or
 * NULL; residuals_path: --residuals or NULL (not with cases > 1 or jumps). */
int rch_ffi_calibrate(rch_ffi_calib **out, const char *const *data_paths, size_t n_data, const char *robot_path,
                      const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                      const char *fix, const char *effects, unsigned flags, const char *validate_path,
                      const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                      const char *residuals_path, char *err, size_t err_len);
/* The same from arrays: q_deg (n x 6) joint readings in degrees, len_mm (n)
 * cable lengths in mm, in acquisition order; xyz_mm (n x 3) the
 * controller's flange positions or NULL (needed by RCH_FFI_CAL_DEQUANTIZE);
 * group (n) set-up groups (>= 0) or NULL; outlet (n) encoder-place labels
 * (>= 0) or NULL; target (n) the tool plate's point each length was
 * measured on (0..RC_MAX_TARGETS-1, a positions file's target column) or
 * NULL, with cable_points_mm (n_cable_points x 3) those points' nominal
 * coordinates in the flange frame (--cable-point, in label order) and
 * cable_point_sd_mm their tolerance (--cable-point-sd; 0: the default).
 * They are written exactly ("%.17g") to a temporary CSV that goes through
 * the same reader and pipeline as a file, so arrays holding a file's
 * values give that file's result. */
int rch_ffi_calibrate_arrays(rch_ffi_calib **out, const double *q_deg, const double *len_mm, const double *xyz_mm,
                             const int *group, const int *outlet, const int *target, size_t n,
                             const double *cable_points_mm, size_t n_cable_points, double cable_point_sd_mm,
                             const char *robot_path,
                             const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                             const char *fix, const char *effects, unsigned flags, const char *validate_path,
                             const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                             const char *residuals_path, char *err, size_t err_len);
/* The same with laser-tracker positions files (--positions, rch_positions.h:
 * the same plausibility checks and screening as `rcal calibrate`):
 * positions_paths (n_positions, 0..16), data_paths (n_data, 0..16), at
 * least one file in all; each file once among both lists; cable_points_mm
 * (n_cable_points x 3, or NULL and 0) and cable_point_sd_mm as for
 * rch_ffi_calibrate_arrays, for data files with a target column. */
int rch_ffi_calibrate_inputs(rch_ffi_calib **out, const char *const *data_paths, size_t n_data,
                             const char *const *positions_paths, size_t n_positions, const double *cable_points_mm,
                             size_t n_cable_points, double cable_point_sd_mm, const char *robot_path,
                             const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                             const char *fix, const char *effects, unsigned flags, const char *validate_path,
                             const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                             const char *residuals_path, char *err, size_t err_len);
void rch_ffi_calib_free(rch_ffi_calib *c);

/* Which error metrics rch_ffi_calib_metrics returns. */
enum {
    RCH_FFI_BEFORE = 0,       /* held-out samples (training ones if none held out), BC model */
    RCH_FFI_AFTER = 1,        /* the same samples, identified model (zero when it diverged) */
    RCH_FFI_TRAIN_BEFORE = 2, /* training samples, BC model */
    RCH_FFI_TRAIN_AFTER = 3,  /* training samples, identified model */
    RCH_FFI_AFTER_UNAMBIGUOUS = 4, /* with jumps: held-out samples not between a jump and its training rows */
    RCH_FFI_VALIDATE = 5      /* the --validate file, no refit */
};
/* out: (6) n, rmse_mm, mean_abs_mm, sd_mm, mean_mm, max_mm.
 * RCH_FFI_ERR_ARG when the run has no such set (no jumps, no validation). */
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
/* Parameter k's uncertainty as `rcal calibrate --json` lists it under
 * "uncertainty": std_error and prior_sd in the parameter's unit (mm, deg,
 * own; NaN: none; prior_sd 0: no prior on it); cls: "identifiable",
 * "weak", "not identifiable" or "fixed" (cls_len bytes); prior_cls: what
 * the data did to the prior, "determined", "partly", "prior only" or ""
 * without a prior on it; *held: 1 when compensation keeps it nominal.
 * Each pointer may be NULL. RCH_FFI_ERR_ARG when the run has no uncertainty
 * (a model that is not finite, too few samples) or k is out of range. */
int rch_ffi_calib_param_unc(const rch_ffi_calib *c, unsigned k, double *std_error, double *prior_sd, char *cls,
                            size_t cls_len, char *prior_cls, size_t prior_cls_len, int *held);
/* A figure of the run by name into *value (counts and flags as numbers):
 * "n_data", "time_ms", "prior" (1: MAP with the physical prior),
 * "noise_mm", "effective_params", "outlets", "groups", "attachment_centred",
 * "jumps_found_by_default", "jump_check_max_mm", "jumps_fitted",
 * "n_ambiguous", "dequant_corrected", "dequant_refused", "dequant_rms_deg",
 * "dequant_max_deg", "position95_data_median_mm", "position95_data_max_mm",
 * "position95_workspace_median_mm", "position95_workspace_max_mm",
 * "orientation95_data_median_deg", "orientation95_data_max_deg",
 * "orientation_determined", "sigma_mm", "rank", "validate_encoder_refitted",
 * "validate_poses", "validate_repeated_poses", "validate_ad_mean_mm",
 * "validate_ad_max_mm", "validate_rd_mean_mm", "validate_rd_max_mm",
 * "cases_done", "cases_before_rmse_mean_mm", "cases_after_rmse_mean_mm".
 * RCH_FFI_ERR_ARG for an unknown name or a figure this run does not have
 * (the position95 figures without uncertainty, validate_* without
 * --validate, cases_* with one case). */
int rch_ffi_calib_get(const rch_ffi_calib *c, const char *name, double *value);
/* The length jumps fitted (with RCH_FFI_CAL_JUMPS, or found by the default
 * check and fitted): their number into *n; the first cap of them: line
 * (cap) the data-file line of the first sample after each jump (0 when the
 * data were several files), size_mm and se_mm (cap) its size and standard
 * error. Arrays may be NULL. 0 jumps when none were fitted. */
int rch_ffi_calib_jumps(const rch_ffi_calib *c, unsigned *n, unsigned *line, double *size_mm, double *se_mm,
                        unsigned cap);
/* The encoder places of the data (the outlet column): their number into *n
 * and the file's label of each (cap entries; place 0 is the model's e). */
int rch_ffi_calib_outlets(const rch_ffi_calib *c, unsigned *n, int *label, unsigned cap);
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

/* ---- diagnosis (rcal diagnose) ---- */

typedef struct rch_ffi_diag rch_ffi_diag; /* the result of one diagnosis */

enum {
    RCH_FFI_DIAG_NO_JUMPS = 1,   /* --no-jumps */
    RCH_FFI_DIAG_DEQUANTIZE = 2, /* --dequantize-joints */
    RCH_FFI_DIAG_JUMPS = 4       /* --jumps: the jumps found are known (removed, not the verdict) */
};
/* Which missing effect explains the residuals, with the host function
 * `rcal diagnose` runs (rch_diagnose_file). seed, folds (0: 5), steps (0:
 * 3), q_step_deg, len_step_mm (0: detected, < 0: none), len_noise_mm,
 * alpha (0: 0.01), max_iter (0: 100) as the CLI's options. */
int rch_ffi_diagnose(rch_ffi_diag **out, const char *data_path, const char *robot_path, unsigned long seed,
                     unsigned folds, unsigned steps, unsigned flags, double q_step_deg, double len_step_mm,
                     double len_noise_mm, double alpha, unsigned max_iter, char *err, size_t err_len);
/* The same with every input `rcal diagnose` takes (rch_diagnose_inputs):
 * data_paths and positions_paths each "\n"-separated (NULL or "": none; at
 * most 16 each), effects the known effects as --effects names them (NULL:
 * none). The handle keeps copies of the paths. */
int rch_ffi_diagnose_inputs(rch_ffi_diag **out, const char *data_paths, const char *positions_paths,
                            const char *robot_path, const char *effects, unsigned long seed, unsigned folds,
                            unsigned steps, unsigned flags, double q_step_deg, double len_step_mm,
                            double len_noise_mm, double alpha, unsigned max_iter, char *err, size_t err_len);
void rch_ffi_diag_free(rch_ffi_diag *g);
/* The verdict: effect ("length_jump", "cable_sag", ..., "none",
 * "unexplained") into effect (len), its 1-based joint (0: none) into
 * *joint, and what remains after the chosen effects ("none" or
 * "unexplained") with its reason into remaining and why. Buffers may be NULL. */
int rch_ffi_diag_verdict(const rch_ffi_diag *g, char *effect, size_t len, unsigned *joint, char *remaining,
                         size_t remaining_len, char *why, size_t why_len);
/* The k-th effect chosen (k < *n_chosen of rch_ffi_diag_get "n_chosen"):
 * its name ("joint_periodic j3") into name, the held-out RMSE with it, its
 * gain (mm^2) and p value. RCH_FFI_ERR_ARG past the last. */
int rch_ffi_diag_chosen(const rch_ffi_diag *g, unsigned k, char *name, size_t len, double *rmse_cv_mm,
                        double *gain_mm2, double *p_value);
/* The k-th fitted effect parameter: name, value, its standard error and
 * unit (text). RCH_FFI_ERR_ARG past the last ("n_params"). */
int rch_ffi_diag_param(const rch_ffi_diag *g, unsigned k, char *name, size_t len, double *value, double *se,
                       char *unit, size_t unit_len);
/* A figure by name: "n", "n_groups", "folds", "n_chosen", "n_params",
 * "noise_floor_mm", "floor_joints_mm", "floor_len_mm", "train_rmse_geo_mm",
 * "rmse_before_mm", "rmse_after_mm", "noise_est_mm", "n_jumps",
 * "rmse_jumps_mm", "dequant_corrected", "dequant_refused", "effect_rms_mm",
 * "q_step_deg", "len_step_mm", "time_ms". */
int rch_ffi_diag_get(const rch_ffi_diag *g, const char *name, double *value);
/* The command that acts on the verdict ("rcal calibrate --data ... --jumps
 * --effects ... --out model.json"), what `rcal diagnose` prints after
 * "Next: " (rch_diagnose_next); name_robot: 1 when the robot was the
 * caller's (then --robot names it, as the CLI does after --robot), 0 for
 * the default robot. */
int rch_ffi_diag_next(const rch_ffi_diag *g, int name_robot, char *buf, size_t len);
/* The nuisance the diagnosis named and the next step fits ("length_jump,
 * time_drift,group_offset", rch_diagnose_nuisance), into buf (len). */
int rch_ffi_diag_nuisance(const rch_ffi_diag *g, char *buf, size_t len);
/* Per sample (the file's rows as used): the cross-validated held-out
 * residuals of the geometry (before) and with the chosen effects (after),
 * and the noise floor sigma, mm. Each (n) array may be NULL. */
int rch_ffi_diag_residuals(const rch_ffi_diag *g, double *before_mm, double *after_mm, double *floor_mm);
/* The report as `rcal diagnose --json` prints it; as rch_ffi_calib_json. */
int rch_ffi_diag_json(const rch_ffi_diag *g, char *buf, size_t len, size_t *needed);
/* The calibrated model with the effects found, what `rcal diagnose --out
 * path` writes (never over the data or the robot file). */
int rch_ffi_diag_write(const rch_ffi_diag *g, const char *path, char *err, size_t err_len);

/* ---- evaluation (rcal evaluate) ---- */

/* A model on data the fit never saw (rch_evaluate, no refit of the robot;
 * refit_encoder: the outlet alone first; same_pose_deg: rows this close are
 * one pose, 0: 1e-6). The joint readings are checked against m's limits.
 * out: (17) n, rmse_mm, mean_abs_mm, sd_mm, mean_mm, max_mm,
 * encoder_refitted, encoder x, y, z (mm), encoder_shift_mm, poses,
 * repeated_poses, ad_mean_mm, ad_max_mm, rd_mean_mm, rd_max_mm (ISO 9283). */
int rch_ffi_evaluate(double *out, const rch_ffi_model *m, const char *data_path, int refit_encoder,
                     double same_pose_deg, char *err, size_t err_len);

/* ---- compensation (rcal compensate) ---- */

/* Compensate n joint targets, in order, with one rc_comp_stream, as `rcal
 * compensate` does line by line (the same model set-up as rch_comp_run):
 * q' with FK_cal(q') = FK_nom(q) for the point tool_mm (3, mm in the flange
 * frame; NULL: the flange centre; never the cable attachment).
 * cal: calibrated model; nominal: the model the targets were made with, or
 * NULL for cal's "nominal" table. out_deg: (n x 6) corrected targets;
 * status: (n) or NULL, per target 0 converged, 1 position matched with the
 * orientation best effort, 2 not converged (written as the stream's
 * fallback: the closest point found, or on a path the target plus the last
 * good correction), 3 left uncompensated (the model's 95 % position
 * uncertainty there is above the limit); u95_mm: (n) or NULL, per target
 * the predicted 95 % position uncertainty of the compensated point (what
 * --uncertainty-out writes; NaN when the model carries no uncertainty);
 * q_deg: (n x 6) targets. The model is the determined part of cal
 * (rch_comp_determined). position_only: 0 as rcal compensate chooses
 * (rch_comp_orient_decide; rch_ffi_compensate_mode says), 1 position only
 * (--position-only), 2 position and orientation (--full-pose);
 * max_dev_deg: largest correction per joint, 0 for the default (0.1 rad);
 * max_unc_mm: --max-uncertainty-mm (0: none for a posterior model, 1 mm for
 * one without; a model without an uncertainty meets no limit > 0: its u95
 * is NaN and the policy acts); u95_policy: what a target beyond it does (--u95-policy):
 * 0 skip (left uncompensated, status 3), 1 warn (compensated anyway; the
 * caller sees u95_mm), 2 refuse (RCH_FFI_ERR_RANGE, "target i: ..."). A
 * target outside cal's joint limits stops the batch with RCH_FFI_ERR_RANGE
 * ("target i: q j = ... is outside ..."); a non-finite one with
 * RCH_FFI_ERR_ARG. */
int rch_ffi_compensate(const rch_ffi_model *cal, const rch_ffi_model *nominal, double *out_deg, int *status,
                       double *u95_mm, const double *q_deg, size_t n, int position_only, double max_dev_deg,
                       double max_unc_mm, int u95_policy, const double *tool_mm, char *err, size_t err_len);

/* How rch_ffi_compensate with these arguments (position_only, max_dev_deg,
 * tool_mm: as there) treats the orientation, as
 * `rcal compensate --summary` says it: out[0] 1 position only, 0 position
 * and orientation; out[1] what chose it: 0 the option (position_only 1 or
 * 2), 1 the model's uncertainty (rch_comp_orient_decide), 2 the model file
 * (no covariance to weigh by); out[2] the calibrated-vs-nominal tilt of the
 * tool's axis (the flange z axis), RMS over the joint limits, deg; out[3] the
 * correction's predicted error of that tilt, RMS, deg (NaN: not known). */
int rch_ffi_compensate_mode(const rch_ffi_model *cal, const rch_ffi_model *nominal, int position_only,
                            double max_dev_deg, const double *tool_mm, double out[4], char *err, size_t err_len);

/* ---- export and report (rcal export, rcal report) ---- */

/* The model file model_path as URDF (format 0) or DH CSV (format 1) into
 * out_path, as `rcal export` writes it (whole or not at all, never over an
 * input). nominal_urdf: names from a nominal URDF, or NULL;
 * drop_joint_effects: --drop-joint-effects. *written (may be NULL): URDF
 * joints or CSV rows; *effects_left: effects the URDF does not carry. */
int rch_ffi_export(const char *model_path, const char *out_path, int format, const char *nominal_urdf,
                   int drop_joint_effects, unsigned *written, unsigned *effects_left, char *err, size_t err_len);
/* The HTML report of a calibration (and a diagnosis, g may be NULL) into
 * html_path, as `rcal calibrate --report` makes it: the calibration's JSON
 * (and the diagnosis's) written beside the page as <page>.calibration.json
 * (<page>.diagnosis.json), then rch_report_write with model_path (a model
 * file, or NULL) and the page's plot-data CSVs; tolerance_mm > 0: the
 * verdict passes or fails against it (`rcal report --tolerance-mm`), 0: none.
 * paths (len, may be NULL): every file written, "\n"-separated. Never over
 * an input. */
int rch_ffi_report(const rch_ffi_calib *c, const rch_ffi_diag *g, const char *html_path, const char *model_path,
                   double tolerance_mm, char *paths, size_t paths_len, char *err, size_t err_len);

#endif /* RCH_FFI_H */
