/* SPDX-License-Identifier: MIT */
/* rch_compare.h - the LTLM paper's comparison of seven identification
 * methods (its Table 6, Fig. 6d, Figs. 7-8) on measured data: the protocol
 * behind `rcal compare`.
 *
 * Protocol, per case c = 0..cases-1: draw `samples` rows at random (seed
 * seed * 1000003 + c), hold out round(test_fraction * samples) of them
 * (at least one), build the start (BC) model from the training part only
 * (rch_calib_start: nominal DH + encoder fitted alone), run every selected
 * method from that same start on the same training samples (rch_est_run;
 * the parameter set of cfg.params, below),
 * evaluate on the held-out samples. Nothing is tuned on held-out samples:
 * every hyperparameter is a fixed default documented in rc_est.h / rc_solve.h.
 *
 * Results: per row (BC and the seven methods) the mean and spread over cases
 * of the held-out RMSE, mean |e|, max |e|, the identification time, the
 * training RMS, iterations and cost evaluations; the held-out RMSE of every
 * case; the LTLM parameters in the paper's Table 7 form; for plots (when
 * asked), the convergence curve of every method and the per-sample held-out
 * errors of case 1.
 *
 * Depends on: rch_calib, rch_est, rch_eval, rch_stats, rch_robot (host), rc_solve
 * (core); rch_plot for rch_compare_plots, rch_jw for rch_compare_json.
 * Memory: rch_compare_run allocates inside the result; rch_compare_free
 * releases it (also after a failed run). Thread safety: one result per
 * thread. Errors: 0, or -1 with d set (bad configuration, too few rows,
 * out of memory, the BC model cannot be built); a method that fails in a
 * case is counted in its row (failed), not an error of the run.
 */
#ifndef RCH_COMPARE_H
#define RCH_COMPARE_H

#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"
#include "rch_est.h"
#include "rch_stats.h"
#include "rch_plot.h"
#include "rch_robot.h"
#include "rch_resid.h"

/* The parameter set the methods work on (rcal compare --params).
 *  PAPER  (the set-up the paper describes, and this project's before issue
 *         11): LM and LTLM move every free parameter (rc_solve's own
 *         truncation of unidentifiable directions); EKF, PF, SCA, QIBAS and
 *         SSLM move rc_est's identifiable subset (rc_est_subset at the start,
 *         19-20 of 27 on the real data); PF, SCA and QIBAS search the box
 *         +-2 mm / +-0.2 deg / encoder +-5 mm around the start.
 *  COMMON every method moves the same parameters: the identifiable subset of
 *         rc_est_subset, computed once per case at the start model on the
 *         training samples (the other parameters stay at their start values
 *         for all seven); PF, SCA and QIBAS search one box for all three,
 *         RCH_COMPARE_COMMON_BOX_MM / _DEG (encoder: the same mm;
 *         chosen a priori, ten and twenty-five times the paper-mode box, the
 *         size of a gross assembly error; not tuned on held-out errors, see
 *         DESIGN.md); the EKF's prior sd is the same box. */
typedef enum rch_compare_params { RCH_PARAMS_PAPER = 0, RCH_PARAMS_COMMON = 1 } rch_compare_params;
#define RCH_COMPARE_COMMON_BOX_MM 20.0
#define RCH_COMPARE_COMMON_BOX_DEG 5.0
/* "paper", "common". */
const char *rch_compare_params_name(rch_compare_params p);

/* Rows of the result: 0 = BC (the start model), id + 1 = method id. */
enum { RCH_COMPARE_ROWS = RCH_EST_ALL + 1 };

/* The paper's Table 6 (Liu et al. 2024) as published: RMSE, "SD" (its Eq. 20,
 * our mean|e|) and MAX in mm of BC (row 0) and M1..M7 (rows 1..7). */
extern const double rch_compare_table6[8][3];

#define RCH_COMPARE_MAX_CASES 10000ul
/* the default limit of one comparison's estimated time (rch_compare_estimate_s) */
#define RCH_COMPARE_MAX_MINUTES 60.0

typedef struct rch_compare_config {
    unsigned long cases;      /* 1..RCH_COMPARE_MAX_CASES */
    size_t samples;           /* rows drawn per case, <= rows in the data; 0: every row */
    double test_fraction;     /* share held out, in (0, 1) */
    unsigned long long seed;  /* case c uses seed * 1000003 + c */
    int run[RCH_EST_ALL];     /* 1: run method id; at least one (the paper variants: --literal) */
    int curves;               /* 1: keep case 1's convergence curves and per-sample errors (plots) */
    rch_compare_params params; /* the methods' parameter set (above) */
    const char *models_dir;   /* non-NULL: case 1's model of every row written here (rch_compare_model_file
                                 names), rcal-model/2 through rch_robot_write, never over one of inputs */
    const char *const *inputs; /* (n_inputs) the command's input files (NULL entries skipped) */
    size_t n_inputs;
    /* Nuisance, with every method (rcal compare --jumps). 1: length jumps
     * at change points in acquisition order are fitted on each case's
     * training rows: an rc_solve method (LM, LTLM and the paper variants)
     * runs the jump search itself with its own configuration
     * (rch_jumps_config.solve); the rc_est methods (EKF .. SSLM), which
     * cannot run the search, get the change points the robust LM's search
     * found in that case and fit the segment offsets themselves with the
     * geometry (start 0, the first segment the reference). Held-out rows are
     * placed in their segment by acquisition time; the geometry alone is
     * what the models (--models, --residuals) keep. */
    int jumps;
    /* 1: the robust LM and LTLM are maximum a posteriori with the robot's
     * physical prior (rch_prior_fill, gauge theta1 and d1 held: rch_prior_gauge),
     * noise re-estimated per case from the robust LM's fit, SSR / (n - p),
     * until it settles (2 %, at most 4 fits). The five rc_est methods take
     * it too (rc_est.h: the MAP objective, no subset, the box 3 prior sd,
     * EKF iterated from the prior); the paper-literal variants ignore it. */
    int prior;
    double max_minutes;       /* refuse a run estimated longer; 0: RCH_COMPARE_MAX_MINUTES */
} rch_compare_config;

/* Seconds one rch_compare_run of cfg on n rows takes on the reference
 * machine: cases x rows drawn x the sum over the selected methods of their
 * measured cost per drawn row (docs/methods.md, "Cost estimates"), x 1.2
 * with jumps. --params both runs it twice. */
double rch_compare_estimate_s(const rch_compare_config *cfg, size_t n);

/* File name of row r's model in models_dir: "BC.json", "M1-LM.json", ...,
 * "M7-LTLM.json", then "M1-LM-paper.json" .. "M7-LTLM-paper-deg.json" (the
 * order rcal grind --models reads them in). */
void rch_compare_model_file(char *buf, size_t len, int row);
/* The model files of M1..M7 (not BC) that exist in dir, in row order:
 * paths[k] the file, names[k] its row label ("M1 LM"). Returns how many. */
#define RCH_COMPARE_PATH_MAX 1200
size_t rch_compare_model_list(char (*paths)[RCH_COMPARE_PATH_MAX], char (*names)[32], const char *dir);

/* Defaults: 10 cases of 300 rows, 0.1 held out, seed 1, every method, no curves. */
void rch_compare_defaults(rch_compare_config *cfg);

/* "LM,EKF,m7" (rch_est_parse names, comma separated) into run[]. An empty
 * list, an empty name or an unknown name is refused: -1 with d set. */
int rch_compare_methods(int run[RCH_EST_ALL], const char *list, rch_diag *d);

/* One row (BC or a method) in one case. */
typedef struct rch_compare_cell {
    int ok;                   /* ran and succeeded (0: not run, or failed) */
    rc_metrics held_out;      /* on the case's held-out samples */
    double train_rmse_mm;     /* training RMS at the end (NaN when it could not be evaluated) */
    double time_ms;           /* the identification alone (methods only) */
    unsigned iterations, cost_evals; /* methods only */
    unsigned n_moved;         /* parameters the method moved (LM/LTLM: the rank it found among them) */
    double dlen_max_mm;       /* largest |a_i, d_i - nominal| of the model (the paper's Table 7 size) */
    double dang_max_deg;      /* largest |alpha_i, theta_i - nominal| (theta1, whose nominal is the gauge, included) */
    unsigned n_jumps;         /* --jumps: the change points the model was fitted with */
} rch_compare_cell;

/* Statistics of one row over the cases where it succeeded. */
typedef struct rch_compare_row {
    int used;            /* the row was run */
    unsigned failed;     /* cases where the method failed (not counted in the stats) */
    rch_stats rmse_mm, mean_abs_mm, max_mm; /* held-out, over the cases */
    rch_stats train_rmse_mm;                /* training RMS at the end */
    rch_stats time_ms, iterations, cost_evals; /* methods only (BC: empty) */
    rch_stats n_moved;                         /* parameters moved (LM/LTLM: rank) */
    rch_stats dlen_max_mm, dang_max_deg;       /* the cells' largest parameter changes (BC: 0) */
    rch_stats n_jumps;                         /* --jumps */
} rch_compare_row;

typedef struct rch_compare_result {
    size_t rows_in_data;
    unsigned long cases;
    size_t n_draw, n_train, n_test;
    rch_compare_params params;
    int jumps;              /* cfg.jumps */
    rch_stats n_common;     /* COMMON: size of the common set over the cases */
    unsigned n_params;      /* parameters of the model */
    rch_compare_row row[RCH_COMPARE_ROWS];
    rch_compare_cell *cell; /* (cases x RCH_COMPARE_ROWS) every row in every case, row-major by case */
    /* LTLM parameters over the cases where it succeeded (the paper's Table 7):
     * dh[j][0..3] = a (mm), d (mm), alpha (deg), theta (deg) of joint j; enc_mm[k] = e_x, e_y, e_z. */
    unsigned n_ltlm;
    rch_stats ltlm_dh[RC_NJ][4];
    rch_stats ltlm_enc_mm[3];
    /* with cfg.curves: case 1 only */
    rch_curve curve[RCH_EST_ALL];    /* training RMS per iteration of each method run */
    rch_stats noise_mm;              /* --prior: the noise the prior was weighed against, over the cases */
    double *err_case1_mm;            /* (RCH_COMPARE_ROWS x n_test) model - measured length; NaN where absent */
    /* always, for --residuals (rch_resid.h): case 1's data rows and models */
    size_t *idx_case1;               /* (n_draw) indices into s: the n_test held out first, then training */
    rc_model *model_case1;           /* (RCH_COMPARE_ROWS) the model of each row in case 1 */
    int ok_case1[RCH_COMPARE_ROWS];  /* 1: that row ran and succeeded in case 1 */
} rch_compare_result;

/* Run the protocol on s (n) with the nominal robot. progress (may be NULL)
 * gets one line per case and one per failed method. Returns 0 or -1 with d
 * set; res must be released with rch_compare_free either way. */
int rch_compare_run(rch_compare_result *res, const rch_compare_config *cfg, const rch_robot *robot,
                    const rc_sample *s, size_t n, FILE *progress, rch_diag *d);
void rch_compare_free(rch_compare_result *res);

/* "BC", "LM", ..., "LTLM", "LM-paper", ..., "LTLM-paper-deg". */
const char *rch_compare_row_name(int row);
/* Mean identification time of LM (NaN when LM was not run or has no time). */
double rch_compare_lm_time_ms(const rch_compare_result *res);
/* 1 when some method failed in some case (the command then exits 1). */
int rch_compare_any_failed(const rch_compare_result *res);

/* The report (the paper's Table 6 and Table 7 forms) as text. data_name is
 * printed in the header line. */
void rch_compare_report(FILE *f, const rch_compare_result *res, const rch_compare_config *cfg,
                        const char *data_name);
/* The same as one JSON object (rch_jw: strings escaped, null where a
 * figure is absent). 0, or -1 on a write error. */
int rch_compare_json(FILE *f, const rch_compare_result *res, const rch_compare_config *cfg, const char *data_name,
                     int argc, char **argv);

/* Write convergence.svg, convergence_zoom.svg (need cfg.curves), rmse_bars.svg,
 * time_bars.svg and per_sample.svg into pd->dir (created with its parents
 * when missing; never over one of pd->inputs). Stops at the first failure:
 * 0, or -1 with d set. */
int rch_compare_plots(const rch_compare_result *res, const rch_compare_config *cfg, const rch_plot_dir *pd,
                      rch_diag *d);
/* convergence_curves.csv (rch_compare_plots writes it too): the data of
 * convergence.svg, one row per method and iteration, "method,iteration,
 * train_rmse_mm", iteration 0 = the start. An iteration is one step of the
 * method: LM, LTLM, SSLM one (accepted or rejected) step, EKF one pass over
 * the training samples, PF one filter pass, SCA one generation, QIBAS one
 * beetle move (3 cost evaluations). 0, or -1 with d set. */
int rch_compare_curves_csv(const rch_compare_result *res, const rch_compare_config *cfg, const rch_plot_dir *pd,
                           rch_diag *d);

/* The table of `rcal compare --residuals`: case 1's drawn rows of s (line:
 * their data lines), set test (held out) or train, predicted by case 1's
 * start (BC) model, one residual_after_<method>_mm column per method run
 * (empty where it failed). 0, or -1 out of memory. */
int rch_compare_resid(rch_resid_table *t, const rch_compare_result *res, const rc_sample *s, const unsigned *line);

#endif
