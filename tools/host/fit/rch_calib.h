/* SPDX-License-Identifier: MIT */
/* rch_calib.h - the calibration pipeline behind `rcal calibrate` and the
 * nominal-FK check behind `rcal fkcheck`.
 *
 * Before calibration (BC): the one definition of the start model. Nominal
 * geometry; the encoder outlet from the robot file when it has one, else from
 * rc_encoder_guess; then the encoder alone is refined by LM with everything
 * else held (rch_calib_bc). `rcal calibrate`, `rcal compare`, `rcal bench`
 * and `rcal diagnose` all start from it. Then every parameter is identified
 * with the chosen method (rch_calib_run), the held-out samples give the
 * before/after figures, an optional simulated truth gives flange errors over
 * random poses, and rch_ident describes what the data could not identify.
 *
 * Depends on: the core (rc_model, rc_solve), rch_data, rch_robot, rch_sim,
 * rch_ident, rch_jw. Memory: the result owns nothing on the heap (the pipeline
 * frees its scratch before returning). Errors: 0, or a negative code with a
 * message in rch_diag (see rch_calib_run). Not thread-safe only in that a
 * result must not be shared while it is written.
 */
#ifndef RCH_CALIB_H
#define RCH_CALIB_H

#include <stddef.h>
#include <stdio.h>

#include "rc_solve.h"
#include "rch_diag.h"
#include "rch_ident.h"
#include "rch_robot.h"
#include "rch_dequant.h"
#include "rch_evaluate.h"
#include "rch_jumps.h"
#include "rch_positions.h"
#include "rch_stats.h"
#include "rch_uncert.h"

/* Poses (and their seed) of the flange comparison against a simulated truth. */
#define RCH_CALIB_TRUTH_POSES 2000
#define RCH_CALIB_TRUTH_SEED 12345
/* Iteration cap of the encoder-only fit of the BC model. */
#define RCH_CALIB_BC_MAX_ITER 200

/* BC model from the samples (n): start = nominal as given (the caller chooses
 * which effects it carries; they stay at their values), encoder from nominal
 * when has_encoder, else from rc_encoder_guess; then the encoder alone fitted
 * (LM, at most RCH_CALIB_BC_MAX_ITER iterations). w: solver scratch. Returns 0
 * or -1 with d set. */
int rch_calib_bc(rc_model *start, rc_solve_work *w, const rc_model *nominal, int has_encoder, const rc_sample *s,
                 size_t n, rch_diag *d);

/* rch_calib_bc with the robot file's model and encoder. */
int rch_calib_start(rc_model *start, rc_solve_work *w, const rch_robot *robot, const rc_sample *train, size_t n,
                    rch_diag *d);

/* Parse a method name (lm, ltlm, lm-paper, ltlm-paper). Returns 0 or -1. */
int rch_method_parse(rc_method *out, const char *name);

/* Add the effects of list to m: comma-separated, "length_offset",
 * "length_scale", "time_drift", "tool_offset", "cable_sag",
 * "length_nonlinearity", "length_periodic:P" (P the period's start value
 * in mm, 1..1000), "joint_compliance:J" (J = 2
 * or 3), "joint_periodic:J" (J = 1..6). 0, or -1 with d naming the entry. */
int rch_calib_effects(rc_model *m, const char *list, rch_diag *d);

/* A copy of m without its nuisance effects (group offsets, time drift):
 * they describe one acquisition, not the robot, and predict nothing at a new
 * pose. */
void rch_model_strip_nuisance(rc_model *out, const rc_model *m);

/* Mark the comma-separated parameter names of list (e.g. "a1,theta6") in
 * fixed (m->n_params). 0, or -1 with d naming the unknown parameter. */
int rch_calib_fix(uint8_t *fixed, const rc_model *m, const char *list, rch_diag *d);

#define RCH_CALIB_MAX_FILES 16
typedef struct rch_calib_cfg {
    const char *data_path;  /* measurements CSV (required; the first of data_paths when several) */
    const char *const *data_paths; /* (n_data_paths) several files merged, NULL: data_path alone */
    size_t n_data_paths;
    const char *validate_path; /* data the fit never sees: evaluated with no refit, or NULL */
    const char *plots_dir;  /* predicted-uncertainty plot and its CSV, or NULL */
    const char *robot_path; /* nominal robot model (required) */
    const char *truth_path; /* simulated truth model, or NULL */
    const char *fix;        /* parameters held at nominal ("a1,theta6"), or NULL */
    rc_method method;
    double test_fraction;   /* share held out, [0, 1) */
    unsigned long seed;     /* split and LTLM seed */
    unsigned max_iter;      /* 0: the method's default */
    int tool_offset;        /* 1: also identify the cable attachment in the flange frame */
    const char *effects;    /* effects fitted with the geometry (rch_calib_effects), or NULL */
    int jumps;              /* 1: fit length jumps at change points in acquisition order (nuisance, rch_jumps) */
    int dequantize;         /* 1: recover rounded joint angles from the file's x, y, z (rch_dequant) */
    int holdout_groups;     /* 1: hold out whole set-up groups instead of random rows */
    unsigned long cases;    /* > 1: repeat on `cases` random subsets (the paper's protocol) */
    size_t case_samples;    /* rows per case (0: every row) */
    const char *residuals_path; /* per-sample residual CSV (rch_resid.h) of a single run, or NULL */
    int no_jump_check;      /* 1: the default run does not look for length jumps (rch_calib_save_model
                               refuses a model fitted across jumps it found) */
    int no_prior;           /* 1: least squares without the physical prior (rch_prior.h), no cable
                               attachment vector unless asked, no gauge: the earlier behaviour */
    const char *const *positions_paths; /* (n_positions_paths) laser-tracker positions files
                                           (rch_positions.h), merged after the data; data_path may
                                           then be NULL */
    size_t n_positions_paths;
    int have_tracker_start; /* tracker_start is the tracker frame's start (else closed form) */
    double tracker_start[6]; /* T (mm) and the rotation vector (rad) of the base in the tracker's frame */
    double max_minutes;     /* refuse a run estimated longer (rch_calib_estimate_s); 0: 60 */
} rch_calib_cfg;

/* The run's cost on the reference machine (docs/methods.md, "Cost
 * estimates"): seconds for n_rows rows as cfg would run them; *bound_s the
 * most it can take when nothing converges early (the iteration cap). */
double rch_calib_estimate_s(const rch_calib_cfg *cfg, size_t n_rows, double *bound_s);

/* The defaults of `rcal calibrate`: everything zero or NULL but method LM,
 * test fraction 0.1, seed 1, one case. */
void rch_calib_cfg_init(rch_calib_cfg *cfg);

typedef struct rch_calib_result {
    rch_calib_cfg cfg;        /* as given (paths point at the caller's strings) */
    rch_robot robot;          /* the robot file; robot.model has the tool offset when asked */
    size_t n_data, n_train, n_test;
    rc_model before;          /* BC model */
    rc_model model;           /* identified model */
    rc_solve_result solve;
    double time_ms;           /* the identification alone */
    int finite;               /* every parameter of model is finite */
    int after_ok;             /* model is finite and gives finite lengths */
    rc_metrics before_m;      /* on the held-out samples (the training ones when none is held out) */
    rc_metrics after_m;
    rc_metrics train_before;
    rc_metrics train_after;   /* zero when !after_ok */
    int have_truth;
    double truth_before_rms_mm, truth_before_max_mm; /* flange vs truth, base heading/height aligned */
    double truth_after_rms_mm, truth_after_max_mm;
    int have_ident;
    rch_ident ident;          /* at the solution, over the training samples */
    int have_unc;             /* uncertainty computed (model finite, enough samples) */
    rch_model_unc unc;        /* covariance, standard errors, classes, predicted uncertainty */
    rc_model determined;      /* the model compensation uses (the whole estimate) */
    int prior_on;             /* maximum a posteriori with the physical prior (robust methods, no --no-prior) */
    double prior_mean[RC_MAX_PARAMS]; /* (RC_MAX_PARAMS) the prior: nominal DH, start attachment */
    double prior_sd[RC_MAX_PARAMS];   /* (RC_MAX_PARAMS) its sd (mm, rad); 0: none (outlet, nuisance) */
    double noise_mm;          /* residual sd the prior was weighed against (estimated: SSR / (n - p_eff)) */
    double p_eff;             /* effective number of parameters the data determined (trace of the hat matrix) */
    unsigned noise_passes;    /* fits it took for the noise estimate to settle */
    unsigned n_outside_prior; /* DH parameters more than 3 prior sd from nominal (flagged) */
    unsigned n_outlets;       /* encoder places in the data (column outlet; 1 without it) */
    uint8_t outlet_label[RC_MAX_OUTLETS]; /* (n_outlets) the file's label of outlet k (k = 0: e) */
    unsigned jumps_found;     /* the default run's jump check: jumps the fit does not model (0: none) */
    double jump_check_max_mm; /* the largest of them */
    unsigned jump_check_steps; /* every change point the check's search found (jumps_found of them far above) */
    int jumps_auto;           /* they were then fitted as nuisance (cfg.jumps set by the run) */
    int have_jump_at, keep_jump_at; /* the change points of this training set are known (searched once) */
    int attach_m0;                  /* fitting the no-attachment model: refit at the attachment model's points */
    unsigned n_jump_at;
    double jump_rms_before_mm; /* training RMS of the geometry alone (the search's) */
    size_t jump_at[RCH_JUMPS_MAX];    /* (n_jump_at) first training sample (in t order) after each jump */
    int attach_auto;          /* the cable attachment vector was the default's to decide (not --tool-offset) */
    int attach_centred;       /* decided: the cable is at the flange centre (no attachment vector) */
    double attach_dchi2;      /* how much the attachment vector improved the MAP objective (noise units) */
    double attach_occam;      /* its Occam penalty 2 sum ln(prior sd / posterior sd) */
    unsigned n_groups;        /* set-up groups of the data (file column, else from the wrist) */
    int groups_from_file;
    rch_provenance prov;      /* data file, samples, sha256, date, tool */
    int have_dequant;
    rch_dequant_result dequant;   /* with cfg.dequantize */
    unsigned dequant_refused_lines[16]; /* first refused rows (file lines) */
    int have_jumps;
    rch_jumps jumps;              /* with cfg.jumps: on the training samples */
    unsigned jump_lines[RCH_JUMPS_MAX]; /* file line of the first sample after each jump (one file) */
    size_t n_ambiguous;           /* held-out samples between a jump and the training rows around it */
    rc_metrics after_unambiguous; /* held-out without them */
    unsigned long cases_done;     /* with cfg.cases > 1 */
    rch_stats case_before, case_after; /* held-out RMSE over the cases */
    rch_stats case_unamb;              /* with --jumps: held-out RMSE without the ambiguous samples */
    size_t case_ambiguous;             /* ambiguous held-out samples over the cases */
    int have_validate;
    rch_evaluate_result validate; /* on cfg.validate_path */
    char plot_paths[2400];    /* files written into plots_dir, "\n"-separated */
    /* with cfg.positions_paths: */
    size_t n_pos_rows;        /* position rows read (three samples each) */
    size_t n_pos_poses;
    unsigned n_targets;
    int pos_has_sigma;
    double pos_sigma_mm;      /* the files' median sigma_mm (rows are weighed equally) */
    int have_pos;             /* the 3-D figures below are set */
    rch_pos_err pos_before, pos_after; /* held-out positions (the training ones when none is held out) */
    rch_pos_err pos_train_after;
} rch_calib_result;

/* The whole calibration. Returns 0 (the solver ran; r->after_ok says whether
 * the result is usable), -1 on a failure of the work (unreadable file, too few
 * samples, solver error: d set), -2 on a bad request (unknown --fix name: d
 * set). */
int rch_calib_run(rch_calib_result *r, const rch_calib_cfg *cfg, rch_diag *d);

/* The text report (the paper's Table 7 form, identifiability, solver line). */
void rch_calib_print(FILE *f, const rch_calib_result *r);
/* The report as one JSON object (rch_jw), "rcal-calibrate/1", starting with
 * rch_jw_header's members (argv: the command line from the command's name;
 * argc 0 gives "rcal"). docs/json-formats.md. 0, or -1 on a write error. */
int rch_calib_json(FILE *f, const rch_calib_result *r, int argc, char **argv);
/* The calibrated model file (rcal-model/1) with a "calibration" member.
 * -1 when the model is not finite or on a write error. */
int rch_calib_write_model(FILE *f, const rch_calib_result *r);
/* rch_calib_write_model into path, whole or not at all (rch_save), never over
 * one of the inputs (--data, --robot, --truth). 0, or -1 with d set. */
int rch_calib_save_model(const rch_calib_result *r, const char *path, rch_diag *d);

/* rcal fkcheck: the nominal FK at each row's joint angles against the row's
 * x, y, z columns. A row further than tol_mm is explained by the display
 * rounding when a joint change of at most RCH_FK_ROUNDING_DEG (max over the
 * joints of the minimum-norm change) reproduces the difference, else a fault. */
#define RCH_FK_ROUNDING_DEG 0.1
typedef struct rch_fk_fault {
    unsigned line;        /* line in the data file */
    double dist_mm;       /* |FK - xyz| */
    double dq_deg;        /* joint change that would explain it */
    double fk_mm[3], file_mm[3];
} rch_fk_fault;
typedef struct rch_fkcheck_result {
    size_t rows, faults, rounding;
    double rms_mm, max_mm, max_consistent_mm;
    rch_fk_fault *fault;      /* (faults) on the heap: rch_fkcheck_free */
    char robot_name[128];
} rch_fkcheck_result;

/* 0, or -1 with d set (unreadable files, no x, y, z columns, no memory). */
int rch_fkcheck_run(rch_fkcheck_result *r, const char *data_path, const char *robot_path, double tol_mm,
                    rch_diag *d);
void rch_fkcheck_free(rch_fkcheck_result *r);

#endif
