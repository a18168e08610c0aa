/* SPDX-License-Identifier: MIT */
/* rch_calib.h - the calibration pipeline behind `rcal calibrate`: the result
 * of one calibration and its outputs.
 *
 * The inputs are read by rch_inputs_load (rch_inputs.h); every fit starts
 * from the BC model (rch_start.h); then every parameter is identified with
 * the chosen method (rch_calib_run), the held-out samples give the
 * before/after figures, an optional simulated truth gives flange errors over
 * random poses, and rch_ident describes what the data could not identify.
 * The request is an rch_calib_cfg (rch_calib_cfg.h); --method, --effects and
 * --fix are read by rch_calib_effects.h.
 *
 * Where each part lives (tools/host/fit/): rch_calib.c the run (split,
 * cases, residuals, cost), rch_calib_fit.c one fit, rch_calib_figures.c what
 * follows it (truth, uncertainty, validation), rch_calib_print.c the text
 * report, rch_calib_json.c the JSON, rch_calib_model.c the model file.
 *
 * Depends on: the core (rc_model, rc_solve), rch_calib_cfg, rch_robot,
 * rch_ident, rch_uncert, rch_jumps, rch_positions, rch_dequant,
 * rch_evaluate, rch_stats. Memory: the result owns nothing on the heap (the
 * pipeline frees its scratch before returning). Errors: 0, or a negative
 * code with a message in rch_diag (see rch_calib_run). Not thread-safe only
 * in that a result must not be shared while it is written.
 */
#ifndef RCH_CALIB_H
#define RCH_CALIB_H

#include <stddef.h>
#include <stdio.h>

#include "rc_solve.h"
#include "rch_calib_cfg.h"
#include "rch_diag.h"
#include "rch_ident.h"
#include "rch_robot.h"
#include "rch_dequant.h"
#include "rch_evaluate.h"
#include "rch_jumps.h"
#include "rch_jw.h"
#include "rch_positions.h"
#include "rch_prior_scale.h"
#include "rch_stats.h"
#include "rch_uncert.h"

/* Poses (and their seed) of the flange comparison against a simulated truth. */
#define RCH_CALIB_TRUTH_POSES 2000
#define RCH_CALIB_TRUTH_SEED 12345

/* The run's cost on the reference machine (docs/methods.md, "Cost
 * estimates"): seconds for n_rows rows as cfg would run them; *bound_s the
 * most it can take when nothing converges early (the iteration cap). */
double rch_calib_estimate_s(const rch_calib_cfg *cfg, size_t n_rows, double *bound_s);

/* The rows a fit cannot reconcile with the rest (rch_calib_screen.c): beyond
 * RCH_SCREEN_K robust standard deviations of their sensor's residuals (and
 * RCH_SCREEN_FLOOR_MM), left out of the refit; more than
 * RCH_SCREEN_MAX_SHARE of the rows: the file is refused. */
#define RCH_SCREEN_K 8.0
#define RCH_SCREEN_FLOOR_MM 0.05
#define RCH_SCREEN_MAX_SHARE 0.05
#define RCH_SCREEN_MAX_NAMED 64
typedef struct rch_screen_row {
    unsigned line, file;   /* the data file's line; file: the input's index (cable files, then positions) */
    double residual_mm;    /* |model - measured| (a tracker row: its largest coordinate) under the first fit */
    double scale_mm;       /* its sensor's robust scale */
    int tracker;           /* a position row, or another sensor's (else a length) */
    uint8_t sensor;        /* its rc_sensor_kind (the first sample's of the row) */
    unsigned label_fits;   /* 1 + the outlet label whose place explains the length (a wrong label), 0: none */
    int block;             /* one of three or more out rows in a row (a different session) */
} rch_screen_row;
typedef struct rch_calib_screen_result {
    size_t rows, out;      /* rows screened, rows left out */
    double scale_mm[2];    /* the robust scale of the cable's and the tracker's residuals */
    unsigned n_named;      /* (at most RCH_SCREEN_MAX_NAMED) */
    rch_screen_row row[RCH_SCREEN_MAX_NAMED];
} rch_calib_screen_result;

/* What an out row likely is, in words. */
const char *rch_screen_kind(const rch_screen_row *w);

/* The systematic length errors the default run weighs (rch_calib_sys.c):
 * a length offset (a display's zero; each outlet's own) and a linear drift
 * over the run, each by its score against its Occam penalty at the fit
 * without it, fitted (a refit) when it wins and the refit confirms. */
#define RCH_SYS_TIE 1.0 /* a score within this of its Occam penalty is a tie: not fitted, said so */
typedef struct rch_calib_sys {
    int tested;                /* the score test ran (lengths, the default run, not --no-length-offset and
                                  --no-drift both) */
    int offset_testable, drift_testable; /* 0: the model's own columns hold it (e.g. --effects group_offset) */
    unsigned n_offsets;        /* offset columns: one per outlet */
    double offset_score, offset_occam, offset_size_mm; /* chi-square gain, penalty, the largest offset (mm) */
    double drift_score, drift_occam, drift_size_mm;    /* the same for the drift (mm over the run) */
    int offset_fitted, drift_fitted; /* in the final model by this decision */
    int refit_kept_out;        /* a refit with one was made and did not confirm its score (not kept): 1 the
                                  offset, 2 the drift */
    double refit_gain, refit_occam; /* that refit's profile-likelihood gain and its penalty */
} rch_calib_sys;

/* How far the fit's residual lies from what its sensor can produce
 * (rch_calib_judge.c): a fit whose noise is far beyond it explains nothing
 * and is not written unless forced. */
#define RCH_JUDGE_FACTOR 10.0
/* The default repeatability of a draw-wire encoder reading with the
 * robot's own (mm): a 0.01 mm display on an arm of 0.01-0.03 mm
 * repeatability (ABB IRB120: 0.01 mm). */
#define RCH_JUDGE_SENSOR_SD_MM 0.02
typedef struct rch_calib_judge {
    int done;
    double floor_mm;           /* what the length sensor can produce: sqrt(sd^2 + step^2/12 + joints^2) */
    double sensor_sd_mm;       /* the encoder's (and the robot's) repeatability: stated or the default */
    int sensor_sd_stated;
    double display_step_mm;    /* the lengths' display step (from the data's digits, or stated) */
    double joint_step_deg;     /* the joints' display step (from the data's digits, or stated; 0: finer) */
    double joint_part_mm;      /* that step's effect on a length through the joints (rms over the rows) */
    double pos_floor_mm;       /* the tracker's: its stated sigma (or the default) and the joints' step */
    double noise_mm, ratio;    /* the fit's noise and noise / floor (the worse sensor's) */
    int beyond;                /* ratio > RCH_JUDGE_FACTOR */
    int worse_than_nominal;    /* the model predicts its own training rows worse than the nominal one */
    /* causes tried when beyond (rch_calib_judge.c): a relabelling of the joint columns or the plate's
     * points whose nominal fit explains the data far better than the file as read */
    int cause_found;
    char cause[1024];           /* what it is and the fix, or "" */
    char tried[240];           /* the causes tried, in words */
} rch_calib_judge;

/* The calibration's plan (rch_calib_plan.c, DESIGN.md "The calibration as
 * a plan"): the stages, each booked in one timing record by the plan's
 * runner (cf. Ceres' Solver::Summary). A stage's time is its own: a stage
 * that runs others (a refit inside the screen) is booked without theirs. */
typedef enum rch_calib_stage_id {
    RCH_STAGE_READ,        /* every input read once (rch_inputs_load) */
    RCH_STAGE_SETUP,       /* the cost checked, the effects the fit carries added */
    RCH_STAGE_SPLIT,       /* the training / held-out split (or the cases) */
    RCH_STAGE_START,       /* the BC start model, the prior and the parameters held */
    RCH_STAGE_MAP,         /* the MAP fit with its noise loop (with --jumps: each pass a jump fit) */
    RCH_STAGE_JUMP_CHECK,  /* the default run's length-jump check */
    RCH_STAGE_ATTACHMENT,  /* the cable attachment decided by the evidence */
    RCH_STAGE_PRIOR_SCALE, /* the prior's scale from the data, the refit under it */
    RCH_STAGE_JUMPS,       /* the length jumps fitted as nuisance (--jumps, or found by the check) */
    RCH_STAGE_METRICS,     /* the before/after figures */
    RCH_STAGE_UNCERTAINTY, /* truth, identifiability, uncertainty, validation (rch_calib_finish) */
    RCH_STAGE_SYSTEMATIC,  /* a length offset and a drift weighed (refits booked to their own stages) */
    RCH_STAGE_SCREEN,      /* the irreconcilable rows left out (refits booked to their own stages) */
    RCH_STAGE_JUDGE,       /* the fit against its sensor */
    RCH_STAGE_OUTPUTS,     /* the residual CSV, the jumps' lines */
    RCH_STAGE_N
} rch_calib_stage_id;
typedef struct rch_calib_timing {
    double wall_ms[RCH_STAGE_N]; /* each stage's own wall time (CLOCK_MONOTONIC), summed over its runs */
    double cpu_ms[RCH_STAGE_N];  /* its process CPU time (CLOCK_PROCESS_CPUTIME_ID) */
    unsigned runs[RCH_STAGE_N];  /* how often it ran (refits and cases run the fit's stages again) */
    double total_wall_ms, total_cpu_ms; /* the sums */
} rch_calib_timing;
/* "read", "setup", ... (the stage's name in --timing and the JSON), or "?". */
const char *rch_calib_stage_name(unsigned id);

enum { RCH_CALIB_SEEN_FLANGE = 0, RCH_CALIB_SEEN_ATTACHMENT = 1, RCH_CALIB_SEEN_TARGETS = 2 };

typedef struct rch_calib_result {
    rch_calib_cfg cfg;        /* as given (paths point at the caller's strings) */
    rch_robot robot;          /* the robot file; robot.model has the tool offset when asked */
    size_t n_data, n_train, n_test;
    rc_model before;          /* BC model */
    rc_model model;           /* identified model */
    rc_solve_result solve;
    double time_ms;           /* the identification alone (the last fit's MAP to prior-scale stages) */
    /* Where the run's time went, stage by stage (the plan's runner books it;
     * writing is the caller's), and how much work it did. */
    rch_calib_timing timing;
    rch_fit_counts counts;
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
    /* The headline: the predicted 95 % accuracy at the point the data see
     * (rch_calib_figures.c): the tracker's targets, the cable attachment, or
     * the flange centre when the cable is hooked there; the flange centre's
     * own figure said apart when the point is off it. */
    int seen_at;              /* RCH_CALIB_SEEN_FLANGE, _ATTACHMENT or _TARGETS */
    double seen_median_mm, seen_max_mm; /* over the data's poses (every target) */
    int flange_apart;         /* the point is off the flange centre: its figure below is said apart */
    double flange_median_mm, flange_max_mm; /* the flange centre over the data's poses */
    int flange_prior_only;    /* the flange centre's figure is the prior's (> 2 x the seen point's) */
    rc_model determined;      /* the model compensation uses (the whole estimate) */
    int prior_on;             /* maximum a posteriori with the physical prior (robust methods, no --no-prior) */
    double prior_mean[RC_MAX_PARAMS]; /* (RC_MAX_PARAMS) the prior: nominal DH, start attachment */
    double prior_sd[RC_MAX_PARAMS];   /* (RC_MAX_PARAMS) its sd (mm, rad); 0: none (outlet, nuisance); the DH
                                         types scaled by prior_scale when it was estimated */
    double prior_sd_fit[RC_MAX_PARAMS]; /* (RC_MAX_PARAMS) the sd the final fit used when prior_scaled (the
                                           joint zeros may be narrower than prior_sd's: rch_prior_scale.h) */
    int prior_scaled;                 /* the prior's scale was estimated from the data (rch_prior_scale) */
    rch_prior_scale prior_scale;      /* the factors, their uncertainty, the fallbacks */
    double noise_mm;          /* residual sd the prior was weighed against (estimated: SSR / (n - p_eff)) */
    double p_eff;             /* effective number of parameters the data determined (trace of the hat matrix) */
    unsigned noise_passes;    /* fits it took for the noise estimate to settle */
    unsigned n_outside_prior; /* DH parameters more than 3 prior sd from nominal (flagged) */
    unsigned n_outlets;       /* encoder places in the data (column outlet; 1 without it) */
    uint8_t outlet_label[RC_MAX_OUTLETS]; /* (n_outlets) the file's label of outlet k (k = 0: e) */
    unsigned jumps_found;     /* the default run's jump check: jumps the fit does not model (0: none) */
    double jump_check_max_mm; /* the largest of them */
    double jump_check_scale_mm; /* the robust sd of the residual with the steps (a step counts above 8 x it) */
    unsigned jump_check_steps; /* every change point the check's search found (jumps_found of them far above) */
    int jumps_auto;           /* they were then fitted as nuisance (the run's decision; cfg.jumps as asked) */
    int attach_auto;          /* the cable attachment vector was the default's to decide (not --tool-offset) */
    int attach_centred;       /* decided: the cable is at the flange centre (no attachment vector) */
    int attach_bound;         /* attach_dchi2 is a lower bound (one centred fit proved the attachment needed) */
    double attach_dchi2;      /* how much the attachment vector improved the MAP objective (noise units) */
    double attach_occam;      /* its Occam penalty 2 sum ln(prior sd / posterior sd) */
    unsigned n_groups;        /* set-up groups of the data (file column, else from the wrist) */
    int groups_from_file;
    rch_provenance prov;      /* data file, samples, sha256, date, tool */
    double (*read_q)[RC_NJ];  /* with cfg.keep_poses: each data file's poses as read (rch_inputs.read_q; heap:
                                 rch_calib_result_free), else NULL */
    size_t read_n[RCH_PROV_MAX_FILES]; /* (prov.n_files) poses of each in read_q */
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
    size_t n_lengths;         /* cable lengths among the samples read */
    unsigned other_sensor;    /* the rc_sensor_kind of a sensor of the table (rch_sensors.h) among them, 0: none */
    char sensor_note[400];    /* that sensor's caveat on the data (rch_sensor_desc.caveat), "" */
    /* with cfg.positions_paths: */
    size_t n_pos_rows;        /* position rows read (three samples each) */
    size_t n_pos_poses;
    unsigned n_targets;
    int pos_has_sigma;
    double pos_sigma_mm;      /* the files' median sigma_mm (rows are weighed equally) */
    int have_pos;             /* the 3-D figures below are set */
    rch_pos_err pos_before, pos_after; /* held-out positions (the training ones when none is held out) */
    rch_pos_err pos_train_after;
    rch_calib_screen_result screen; /* the rows left out as irreconcilable (screen.out 0: none) */
    uint8_t fixed[RC_MAX_PARAMS];   /* the parameters the final fit held (gauge, --fix, unseen) */
    rch_calib_sys sys;              /* the systematic length errors weighed */
    rch_calib_judge judge;          /* the fit against what its sensor can produce */
} rch_calib_result;

/* The whole calibration: the inputs (rch_inputs_load), the cost (refused
 * above cfg->max_minutes), the effects the fit carries, one fit or the
 * cases. Returns 0 (the solver ran; r->after_ok says whether the result is
 * usable), -1 on a failure of the work (unreadable file, too few samples,
 * solver error: d set), -2 on a bad request (unknown --fix or --effects
 * name, --residuals with --cases or --jumps, a run estimated too long: d
 * set). */
int rch_calib_run(rch_calib_result *r, const rch_calib_cfg *cfg, rch_diag *d);

/* Why r's model is not one to use (r->judge: the noise against the
 * sensor's floor, the model against the nominal one, the cause found or
 * the causes tried), one sentence into buf (len); and the floor's parts. */
void rch_calib_judge_text(char *buf, size_t len, const rch_calib_result *r);
void rch_calib_judge_floor_text(char *buf, size_t len, const rch_calib_result *r);

/* The text report (the paper's Table 7 form, identifiability, solver line). */
void rch_calib_print(FILE *f, const rch_calib_result *r);
/* The plan's timing record: one line per stage that ran (wall, CPU, runs)
 * after prefix, then the total (--timing, on stderr); as a JSON member
 * "timing" {wall_ms, cpu_ms, stages: [{stage, runs, wall_ms, cpu_ms}]}. */
void rch_calib_timing_print(FILE *f, const rch_calib_timing *t, const char *prefix);
void rch_calib_timing_json(rch_jw *w, const rch_calib_timing *t);
/* The rows the fit left out (r->screen), one line each: "FILE:LINE: left
 * out: ... likely ...", each line after prefix. */
void rch_calib_print_screened(FILE *f, const rch_calib_result *r, const char *prefix);
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
/* The same, the text written also handed back (*text: heap, the caller frees; *len bytes) for a reader in this
 * process (--report), which then never opens the file written. 0, or -1 with d set (*text NULL). */
int rch_calib_save_model_text(const rch_calib_result *r, const char *path, char **text, size_t *len, rch_diag *d);
/* What the result holds on the heap (read_q, with cfg.keep_poses); the result itself is the caller's. */
void rch_calib_result_free(rch_calib_result *r);

#endif
