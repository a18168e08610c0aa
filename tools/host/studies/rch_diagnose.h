/* SPDX-License-Identifier: MIT */
/* rch_diagnose.h - where model and measurement disagree, and which missing
 * physical effect explains it (issue 6, `rcal diagnose`).
 *
 * What: the diagnosis workflow on cable-length data.
 *  1. Geometric fit (24 DH + encoder) on all samples, started like
 *     `rcal calibrate` (encoder guess, encoder alone, then everything).
 *  2. k-fold cross-validation. Folds are drawn at random WITHIN each set-up
 *     group (the samples of every group are shuffled and dealt round-robin
 *     over the folds), so every held-out sample has group-mates in training:
 *     (groups: consecutive samples with the same wrist joints q4..q6; a wrist
 *     reading that moves by one display step stays in its group)
 *     that keeps every candidate testable, a per-group offset included. (A
 *     leave-group-out scheme could never validate a group offset.)
 *  3. Noise floor per sample: encoder resolution (step^2/12), an optional
 *     encoder noise, and the joint readings' display step projected through
 *     the joint Jacobian: sum_j (dl/dq_j)^2 step^2/12. The floor is
 *     sqrt(mean of those variances). Steps are detected from the data (the
 *     coarsest grid that every value sits on) unless given.
 *  4. Structure tests of the held-out residuals (F tests with an intercept):
 *     bias, each joint's first and second harmonics, the gravity levers of
 *     joints 2 and 3, cable length, cable direction, acquisition order, and
 *     the groups (one-way ANOVA). Bonferroni over the tests.
 *  5. Candidate effects (rc_model effects), each fitted jointly with the
 *     geometry in every fold: length_offset, length_scale, time_drift,
 *     group_offset, joint_compliance j2/j3, joint_periodic j1..j6,
 *     tool_offset, cable_sag, length_nonlinearity, length_periodic (its
 *     period started from the largest sine in the residuals against the
 *     length). A
 *     candidate that adds no identifiable direction (rank of the scaled
 *     normal matrix does not grow) is flagged, not tested. Significance:
 *     the score test of the candidate's added directions at the current
 *     model (cluster-robust by pose, F(q, poses - q); rch_diagnose_score.c),
 *     Bonferroni over the tested candidates at level alpha; for
 *     length_periodic, whose period is searched on the same residuals, the
 *     held-out gain's paired one-sided z test instead. The held-out gain
 *     (per-pose paired differences of held-out squared errors) is measured
 *     and reported for every candidate.
 *     Among the significant ones the best gain wins, except that a candidate
 *     with fewer parameters whose held-out MSE is within one standard error
 *     of the best is preferred (one-standard-error rule).
 *  4b. Length jumps in acquisition order (rch_jumps: a display re-zeroed,
 *     counts lost): when found, and at least one lies inside a set-up (a
 *     step where the set-up changes is confounded with set-up dependent
 *     effects, and then left to those candidates), their offsets (fitted on all samples, a
 *     nuisance) are removed from the lengths, the geometry is refitted and
 *     cross-validated again, and the candidate search runs on top; the
 *     verdict is then "length_jump".
 *  6. The chosen effect joins the model and the search repeats (at most
 *     max_steps effects). The first chosen effect is the verdict; when none
 *     is significant the verdict is "none" (the residual is noise, its RMS
 *     the noise estimate, whatever its size against the quantization floor),
 *     or "unexplained" when a structure test remains significant (the
 *     strongest named).
 *
 * Depends on: rcal core (rc_model, rc_solve, rc_rand), rch_data (groups).
 * Memory: rch_diagnose_run allocates the per-sample arrays of the result;
 * rch_diagnose_free releases them. Thread safety: reentrant (no globals).
 * Errors: 0 or -1 with the reason in rch_diag.
 */
#ifndef RCH_DIAGNOSE_H
#define RCH_DIAGNOSE_H

#include <stddef.h>
#include <stdio.h>

#include "rc_solve.h"
#include "rch_diag.h"
#include "rch_jumps.h"
#include "rch_resid.h"
struct rch_inputs; /* rch_inputs.h: the inputs as read */

#define RCH_DIAGNOSE_MAX_CAND 24
#define RCH_DIAGNOSE_MAX_STEPS 4
#define RCH_DIAGNOSE_MAX_TESTS 40
#define RCH_DIAGNOSE_MAX_SENSORS (RC_MAX_OUTLETS + RC_SENSOR_COUNT_) /* up to RC_MAX_OUTLETS cable outlets, the
                                                                   tracker, each other sensor kind */
#define RCH_DIAGNOSE_MAX_FILES 16
#define RCH_DIAGNOSE_MAX_FOLDS 20
#define RCH_DIAGNOSE_MAX_NOTES 8
#define RCH_DIAGNOSE_MAX_PARAMS 16

/* All-zero means defaults. */
typedef struct rch_diagnose_cfg {
    unsigned folds;          /* k of the cross-validation; 0: 5 (2..RCH_DIAGNOSE_MAX_FOLDS) */
    unsigned max_steps;      /* effects added one after the other; 0: 3 */
    unsigned long long seed; /* fold assignment */
    double q_step_deg;       /* joint display step; 0: detected; < 0: none */
    double len_step_mm;      /* length display step; 0: detected; < 0: none */
    double len_noise_mm;     /* encoder noise sigma beyond its step; 0: none */
    double alpha;            /* family-wise level of each decision; 0: 0.01 */
    double gap_factor;       /* held-out RMSE above gap_factor * floor is a gap; 0: 1.25 */
    int groups_given;        /* 1: keep rc_sample.group; 0: group by fixed wrist (q4..q6) */
    int have_encoder;        /* 1: start from the encoder in the nominal model */
    unsigned max_iter;       /* LM iterations of a warm-started fold fit; 0: 100 (fits on all
                                samples: at most 200). Fewer is faster but leaves slow, weakly
                                identified directions (e.g. the common level of group offsets)
                                less converged, which inflates held-out errors a little. */
    int verbose;             /* progress to stderr */
    int no_jumps;            /* 1: do not look for length jumps in acquisition order */
    int dequantize;          /* rch_diagnose_file: recover rounded joints from x, y, z (rch_dequant); the
                                joint step of the floor is then the 0.05 mm rounding of x, y, z */
    int keep_effects;        /* 1: the nominal model's effects stay (the sensors' frames, outlets and targets,
                                effects already known): the search adds to them; 0: geometry alone (they are
                                dropped, as before) */
    int jumps;               /* 1: length jumps found are removed as nuisance (rcal calibrate --jumps) even
                                where they coincide with a set-up change */
    double jump_max_mm;      /* the largest jump a display event explains (a re-zeroed display, counts lost);
                                a jump found above it is named as implausible in the report; 0: 10 mm */
    /* The jumps rcal calibrate fits on the same inputs (rch_diagnose_inputs sets them: calibrate's jump
     * search and its rule decide, so that both agree on whether a file has jumps). jumps_given 1: no
     * search of the diagnosis's own; n_given_jumps change points at acquisition times given_jump_t
     * (ascending) with the lengths' offsets of the n_given_jumps + 1 segments (given_offset_mm[0]: the
     * first, the reference) removed from the lengths. */
    int jumps_given;
    unsigned n_given_jumps;
    double given_jump_t[RCH_JUMPS_MAX];
    double given_jump_mm[RCH_JUMPS_MAX];      /* each jump's size (length change at it) */
    double given_jump_se_mm[RCH_JUMPS_MAX];
    double given_offset_mm[RCH_JUMPS_MAX + 1];
} rch_diagnose_cfg;

/* What one sensor saw and how well the model predicts it held out: a cable
 * outlet (lengths, mm) or the tracker (positions: 3-D errors, mm). */
typedef struct rch_diagnose_sensor {
    char name[40];         /* "cable", "cable outlet 2" (the file's label), "tracker" */
    int tracker;           /* 1: not a cable: the tracker's positions (three coordinates a row) or another sensor */
    char kind[16];         /* "cable", "tracker", or the sensor's name (rch_sensors.h: "touch") */
    unsigned label;        /* the outlet's label in the file (cable) */
    size_t rows;           /* lengths, or position rows (three samples each) */
    double before_mm;      /* held-out RMS, geometry only (3-D for the tracker) */
    double after_mm;       /* held-out RMS with the effects found */
    double floor_mm;       /* the quantization floor of its rows (3-D for the tracker) */
} rch_diagnose_sensor;

/* Every input `rcal calibrate` takes, with the same meaning (issue 31):
 * cable-length files (one or several outlets: the `outlet` column), laser
 * tracker positions files (several targets: the `target` column), both
 * mixed; the robot; the effects already known. The paths must outlive the
 * result (it keeps them for the next step and the model file). */
typedef struct rch_diagnose_in {
    const char *const *data_paths;      /* (n_data) cable-length CSV files, merged in order */
    size_t n_data;
    const char *const *positions_paths; /* (n_positions) tracker positions CSV files (docs/positions.md) */
    size_t n_positions;
    const char *robot_path;             /* the nominal robot (required) */
    int robot_given;                    /* 1: the user named it (the next step names it too) */
    const char *effects;                /* effects already known, as `rcal calibrate --effects` names them, or
                                           NULL: the search adds to them and never offers them again */
    const char *const *cable_points;    /* (n_cable_points) "X,Y,Z": the tool plate's points the cable is
                                           hooked on (rcal calibrate --cable-point), or NULL */
    size_t n_cable_points;
} rch_diagnose_in;

/* One structure test of residuals against an explanatory variable. */
typedef struct rch_diagnose_test {
    char name[40];        /* "q2 harmonics", "groups (ANOVA)", ... */
    unsigned dof1, dof2;  /* F(dof1, dof2) */
    double f_stat;
    double p_value;
    double r2;            /* share of residual variance it explains */
    int significant;      /* p < alpha / n_tests */
} rch_diagnose_test;

/* One candidate effect in one step. */
typedef struct rch_diagnose_cand {
    char name[40];         /* "joint_periodic j3" */
    rc_effect_kind kind;
    unsigned joint;        /* 1-based joint, 0 when not a joint effect */
    unsigned n_params;     /* parameters it adds */
    unsigned n_ident;      /* of which identifiable from cable lengths (rank gain) */
    int tested;            /* cross-validated */
    int implausible;       /* fitted joint error beyond 1 deg: not eligible */
    double rmse_cv_mm;     /* held-out RMSE with the candidate */
    double gain_mm2;       /* mean reduction of held-out squared error */
    double gain_se_mm2;    /* its standard error */
    double z;              /* gain / se */
    double p_value;        /* one-sided, of the held-out gain */
    int scored;            /* the score test could be formed */
    double score_f;        /* its F statistic (cluster-robust by pose) */
    unsigned score_dof;    /* its numerator dof (the directions tested) */
    double score_p;        /* its p-value */
    double p_decision;     /* the p the decision reads: score_p, or p_value for length_periodic (a searched period) */
    int significant;       /* p_decision < alpha / tested candidates */
    char note[160];
} rch_diagnose_cand;

typedef struct rch_diagnose_step {
    double rmse_base_mm;   /* held-out RMSE of the model entering the step */
    unsigned n_cand;
    rch_diagnose_cand cand[RCH_DIAGNOSE_MAX_CAND];
    int chosen;            /* index into cand, -1 when none */
    char why[240];
} rch_diagnose_step;

/* A fitted effect parameter in display units, with its fold-jackknife
 * standard error. */
typedef struct rch_diagnose_param {
    char name[48];
    double value;
    double se;
    char unit[12];
} rch_diagnose_param;

typedef struct rch_diagnose_result {
    size_t n;
    size_t n_poses;            /* distinct poses (the folds keep each whole: all its outlets and targets) */
    unsigned n_sensors;
    rch_diagnose_sensor sensors[RCH_DIAGNOSE_MAX_SENSORS];
    size_t n_cable, n_tracker; /* samples of each kind (a position row is three) */
    unsigned n_known;          /* effects in the model before the search (given, e.g. --effects) */
    rch_diagnose_in in;        /* the inputs (rch_diagnose_inputs; zero after rch_diagnose_run alone) */
    uint8_t outlet_label[RC_MAX_OUTLETS]; /* the files' label of outlet k (k = 0: the robot's encoder) */
    unsigned *line;            /* (n) each sample's line in its file (rch_diagnose_inputs), or NULL */
    unsigned *file;            /* (n) its file: data files first, then positions files, or NULL */
    struct rch_inputs *raw;    /* the inputs as read, once (rch_diagnose_inputs: rch_inputs_load, joints as read,
                                  poses kept), for every later stage (the jumps' calibration, the next step's
                                  model, --report's calibration and page): no file is read again; or NULL */
    size_t n_read;             /* samples read, before --dequantize-joints refused any (rch_inputs.n_read) */
    unsigned n_groups;
    unsigned n_flicker;        /* samples whose wrist reading moved by one display step within a group */
    unsigned folds;
    double q_step_deg, len_step_mm, len_noise_mm; /* used for the floor */
    double noise_floor_mm;     /* sqrt(mean per-sample floor variance) */
    double floor_joints_mm;    /* joint-step part alone */
    double floor_len_mm;       /* length step + noise part alone */
    double train_rmse_geo_mm;  /* geometric fit on all samples */
    double rmse_before_mm;     /* held-out, geometry only */
    double rmse_after_mm;      /* held-out, with the chosen effects */
    double noise_est_mm;       /* the held-out RMS when no structure remains: the noise, estimated */
    rch_jumps jumps;           /* length jumps in acquisition order (n_jumps 0: none found) */
    unsigned jump_line[RCH_JUMPS_MAX]; /* (jumps.n_jumps) the data file's line of the first sample after each
                                          jump, as rcal calibrate names it (0: not from a file) */
    double rmse_jumps_mm;      /* held-out, geometry on the lengths with the jumps removed */
    unsigned jumps_at_setup_change; /* of the jumps found, at a set-up change (confounded) */
    unsigned jumps_confounded; /* steps found only at set-up changes: not taken as jumps */
    int jumps_by_calibrate;    /* 1: the jumps are rcal calibrate's (its search and rule on the same inputs) */
    double jump_max_mm;        /* the bound of a display event used (cfg.jump_max_mm) */
    unsigned jumps_implausible; /* of the jumps, larger than jump_max_mm: not a display event (said so) */
    char known_effects[512];   /* the effects given as known (rch_diagnose_in.effects), as given */
    int jumps_asked;           /* cfg.jumps: the jumps are known (--jumps), not the verdict */
    size_t dequant_corrected, dequant_refused; /* with cfg.dequantize */
    unsigned geo_rank, geo_free;

    unsigned n_tests;
    rch_diagnose_test before[RCH_DIAGNOSE_MAX_TESTS]; /* on held-out residuals, geometry */
    rch_diagnose_test after[RCH_DIAGNOSE_MAX_TESTS];  /* with the chosen effects */

    unsigned n_steps;
    rch_diagnose_step steps[RCH_DIAGNOSE_MAX_STEPS];
    unsigned n_chosen;             /* effects added */
    char effect[32];               /* verdict: effect name, "none", "unexplained" */
    unsigned joint;                /* 1-based joint of the verdict, 0 when none */
    char remaining[16];            /* after the chosen effects: "none" or "unexplained" */
    char remaining_why[240];

    unsigned n_params;
    rch_diagnose_param params[RCH_DIAGNOSE_MAX_PARAMS];
    double effect_rms_mm;          /* rms of the chosen effects' contribution to l */

    unsigned n_notes;              /* what cable lengths cannot identify */
    char notes[RCH_DIAGNOSE_MAX_NOTES][512];

    rc_model geo;                  /* geometric fit on all samples */
    rc_model final;                /* with the chosen effects, all samples */
    rc_sample *s;                  /* (n) the samples as used (with groups) */
    double *res_before_mm;         /* (n) held-out residuals l_model - L, geometry */
    double *res_after_mm;          /* (n) held-out residuals, final model */
    double *floor_mm;              /* (n) per-sample floor sigma */
    double time_ms;
} rch_diagnose_result;

/* Run the workflow on samples (n) with the nominal robot model (its
 * effects are ignored). Returns 0, or -1 with d set (too few samples, a fit
 * failed, out of memory). Free the result with rch_diagnose_free, also after
 * a failure. */
int rch_diagnose_run(rch_diagnose_result *out, const rc_sample *samples, size_t n,
                     const rc_model *nominal, const rch_diagnose_cfg *cfg, rch_diag *d);

/* rch_diagnose_run on the files of in (rch_diagnose_in): the cable files
 * merged (acquisition order over all of them; set-up groups never across two
 * files), each outlet an RC_EFF_OUTLET of the model, the positions appended
 * with the tracker frame and targets (rch_positions.h), the effects already
 * known added; cfg->groups_given, cfg->have_encoder and cfg->keep_effects are
 * set from them. With cfg->dequantize the cable rows' joints are recovered
 * first (rch_dequant). Same returns; free the result also after a failure. */
int rch_diagnose_inputs(rch_diagnose_result *out, const rch_diagnose_in *in, const rch_diagnose_cfg *cfg,
                        rch_diag *d);

/* rch_diagnose_inputs on one data file and a robot file. */
int rch_diagnose_file(rch_diagnose_result *out, const char *data_path, const char *robot_path,
                      const rch_diagnose_cfg *cfg, rch_diag *d);

void rch_diagnose_free(rch_diagnose_result *r);

/* The calibrated model with the effects the diagnosis chose, fitted as
 * `rcal calibrate --effects LIST` fits it (the one pipeline: maximum a
 * posteriori with the physical prior, the attachment decided by the data,
 * length jumps fitted as nuisance when the verdict is length_jump or the
 * default jump check finds them, every sample used), as a model file at path
 * with its posterior (rch_save: whole or not at all, never over one of
 * inputs). data_path: the diagnosed data; robot_path: the nominal robot.
 * 0, or -1 with d set. */
/* The command that acts on the verdict: `rcal calibrate --data DATA` with
 * --robot ROBOT (robot_path NULL: the default robot, not named), --jumps,
 * --dequantize-joints and --effects as the diagnosis found, into buf (len).
 * 0, or -1 when it does not fit. */
int rch_diagnose_next(char *buf, size_t len, const rch_diagnose_result *r, const char *data_path,
                      const char *robot_path);

/* The nuisance the diagnosis named (length_jump, time_drift, group_offset:
 * what describes this acquisition, not the robot), comma-separated into buf
 * (len): the next step fits each with the geometry (--jumps, --effects
 * time_drift; group offsets as the jumps at the set-up changes, --jumps)
 * and a model never uses them at a new pose. 0, or -1 when it does not fit. */
int rch_diagnose_nuisance(char *buf, size_t len, const rch_diagnose_result *r);

int rch_diagnose_save_model(const rch_diagnose_result *r, const char *data_path, const char *robot_path, const char *path,
                            const char *const *inputs, size_t n_inputs, rch_diag *d);

/* Human report and one JSON object. 0 or -1 on a write error. */
int rch_diagnose_print(FILE *f, const rch_diagnose_result *r);
int rch_diagnose_json(FILE *f, const rch_diagnose_result *r, int argc, char **argv);

/* Residual plots (SVG, each with its data as CSV beside it) into dir:
 * residuals before/after against acquisition order, per-group mean residuals
 * before/after, the candidate gains, and the residuals against the variable
 * of the strongest structure test. Never over one of inputs (n_inputs, NULL
 * entries skipped; rch_plot_save). paths receives the written files,
 * "\n"-separated. 0 or -1 (d set). */
int rch_diagnose_plots(const rch_diagnose_result *r, const char *dir, const char *const *inputs, size_t n_inputs,
                       char *paths, size_t paths_len, rch_diag *d);


/* The table of `rcal diagnose --residuals`: every sample as the diagnosis
 * used it (line (r->n): their data lines), predicted by the final model (the
 * geometry with the chosen effects, fitted on all samples: set train), and
 * the cross-validated held-out residuals of the geometry alone
 * (residual_after_geometry_cv_mm) and with the chosen effects
 * (residual_after_<effect>+..._cv_mm, when one was chosen). 0, or -1. */
int rch_diagnose_resid(rch_resid_table *t, const rch_diagnose_result *r, const unsigned *line);

#endif
