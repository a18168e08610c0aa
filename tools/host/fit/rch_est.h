/* SPDX-License-Identifier: MIT */
/* rch_est.h - the seven identification methods of the LTLM paper's
 * comparison (its Table 5) behind one call, with timing and convergence
 * curves, for rcal compare and tests.
 *
 * M1 LM and M7 LTLM are rc_solve's robust methods (all free parameters, the
 * solver's own eigen-truncation of unidentifiable directions); M2 EKF, M3 PF,
 * M4 SCA, M5 QIBAS and M6 SSLM are rc_est's (identifiable subset, bounds
 * around the start; see rc_est.h for every hyperparameter). With
 * rch_est_opts.fixed and same_set all seven move the same parameters
 * (rcal compare --params common). Every method
 * starts from the model it is given (rch_calib_start's BC model in compare).
 *
 * Depends on: rc_solve, rc_est (core), libc. Memory: rch_est_ws holds both
 * solver workspaces (about 1 MB) on the heap; curves grow on the heap.
 * Thread safety: one workspace per thread. Errors: rc_status from the
 * solvers; RC_ERR_CAPACITY when an allocation fails.
 */
#ifndef RCH_EST_H
#define RCH_EST_H

#include <stddef.h>
#include <stdint.h>

#include "rc_est.h"
#include "rc_solve.h"

/* The methods of `rcal compare`: one line each, the enum, the names, the
 * paper's row and the method that runs expanded from it.
 * X(ID, name (the paper's), paper row 1..7, rc_solve's method or -1,
 *   rc_est's method or -1). The first seven are the paper's M1..M7; then the
 * paper's own M1 and M7 (rc_solve's paper variants: Eq. 10 with mu = 5 and
 * no acceptance; Algorithm I on it), angles in rad or in deg inside Eq. 10
 * (rcal compare --literal). */
#define RCH_EST_METHODS(X)                                                                                        \
    X(LM, "LM", 1, RC_METHOD_LM, -1)                                                                              \
    X(EKF, "EKF", 2, -1, RC_EST_EKF)                                                                              \
    X(PF, "PF", 3, -1, RC_EST_PF)                                                                                 \
    X(SCA, "SCA", 4, -1, RC_EST_SCA)                                                                              \
    X(QIBAS, "QIBAS", 5, -1, RC_EST_QIBAS)                                                                        \
    X(SSLM, "SSLM", 6, -1, RC_EST_SSLM)                                                                           \
    X(LTLM, "LTLM", 7, RC_METHOD_LTLM, -1)                                                                        \
    X(LM_PAPER, "LM-paper", 1, RC_METHOD_LM_PAPER, -1)                                                            \
    X(LM_PAPER_DEG, "LM-paper-deg", 1, RC_METHOD_LM_PAPER_DEG, -1)                                                \
    X(LTLM_PAPER, "LTLM-paper", 7, RC_METHOD_LTLM_PAPER, -1)                                                      \
    X(LTLM_PAPER_DEG, "LTLM-paper-deg", 7, RC_METHOD_LTLM_PAPER_DEG, -1)

#define RCH_EST_ENUM_(id, name, row, solve, est) RCH_EST_##id,
typedef enum rch_est_id { RCH_EST_METHODS(RCH_EST_ENUM_) RCH_EST_ALL } rch_est_id;
#undef RCH_EST_ENUM_
/* The paper's seven (M1..M7): the ids before the paper variants. */
#define RCH_EST_COUNT RCH_EST_LM_PAPER

/* "LM", "EKF", "PF", "SCA", "QIBAS", "SSLM", "LTLM" (the paper's names),
 * "LM-paper", "LM-paper-deg", "LTLM-paper", "LTLM-paper-deg". */
const char *rch_est_name(rch_est_id id);
/* Case-insensitive name (or "m1".."m7" for the seven) to id; -1 when unknown. */
int rch_est_parse(const char *name);
/* The paper's method number of id: 1..7 (the paper variants: 1 for LM, 7 for LTLM). */
int rch_est_paper_row(rch_est_id id);
/* 1: id is one of rc_solve's methods (LM, LTLM and the paper variants). */
int rch_est_is_solve(rch_est_id id);

/* Training RMS per iteration; rms_mm[0] is the start. */
typedef struct rch_curve {
    double *rms_mm; /* (n) */
    size_t n, cap;
    int failed;     /* an allocation failed: the curve is truncated */
} rch_curve;
void rch_curve_free(rch_curve *c);

typedef struct rch_est_ws {
    rc_solve_work solve;
    rc_est_work est;
} rch_est_ws;
rch_est_ws *rch_est_ws_new(void);
void rch_est_ws_free(rch_est_ws *ws);

/* Options beyond the per-method defaults (all-zero: defaults). */
typedef struct rch_est_opts {
    unsigned max_iter;     /* 0: the method's default */
    unsigned pop;          /* PF/SCA population; 0: default */
    double bound_len_mm;   /* see rc_est_config; 0: default */
    double bound_ang_rad;
    double bound_enc_mm;
    double bound_other;    /* effect parameters outside mm and rad; 0: default */
    /* The parameter set (rcal compare --params). fixed (n_params, may be
     * NULL): held at the start value by every method. same_set 1: the
     * rc_est methods move exactly the parameters not fixed (no subset of
     * their own), so that all seven methods work on one set. */
    const uint8_t *fixed;
    int same_set;
    /* A Gaussian prior (rc_solve_config's prior_mean, prior_sd,
     * prior_noise_mm; the arrays cover the model's parameters): maximum a
     * posteriori for LM, LTLM and the five rc_est methods (rc_est.h). NULL:
     * least squares. The paper variants ignore it. */
    const double *prior_mean, *prior_sd;
    double prior_noise_mm;
} rch_est_opts;

/* The rc_solve configuration rch_est_run uses for an rc_solve method id
 * (rch_est_is_solve), without callbacks: for the jump search (rch_jumps). */
void rch_est_solve_config(rc_solve_config *cfg, rch_est_id id, uint64_t seed, const rch_est_opts *opts);

typedef struct rch_est_out {
    double time_ms;        /* wall time of the identification alone (CLOCK_MONOTONIC) */
    unsigned iterations;
    unsigned cost_evals;   /* passes over the training samples */
    double rms_start_mm;   /* training RMS */
    double rms_final_mm;
    unsigned n_moved;      /* parameters the method moved (LM/LTLM: rank found) */
} rch_est_out;

/* Identify m (in: start, out: result) with method id from train (n).
 * curve may be NULL. opts may be NULL. */
rc_status rch_est_run(rc_model *m, rch_est_out *out, rch_curve *curve, rch_est_ws *ws,
                      rch_est_id id, uint64_t seed, const rch_est_opts *opts,
                      const rc_sample *train, size_t n);

#endif

/* ---- the chaos study (paper Figs. 2-3, Eq. 12) ---------------------------- */

/* Uniformity of the logistic-tent map rc_lt_map at r: iterate `points` times
 * from n0 (n0 itself not counted), count the iterates in `bins` equal bins
 * of [0, 1), and return the standard deviation of the bin counts,
 * sqrt(sum_k (c_k - points/bins)^2 / bins) (the paper's Eq. 12 as we read it:
 * the population sd; 0 = perfectly uniform). counts: (bins) receives the
 * histogram, or NULL. */
double rch_chaos_sd(unsigned *counts, double r, double n0, unsigned points, unsigned bins);

/* The same averaged over n_starts initial values drawn uniformly in
 * (0.01, 0.99) from seed (fixed seed: reproducible); se (may be NULL)
 * receives the standard error of that mean. */
double rch_chaos_sd_avg(double *se, double r, unsigned points, unsigned bins, unsigned n_starts,
                        uint64_t seed);

/* The expected sd of the bin counts of `points` independent uniform draws:
 * sqrt(points / bins * (1 - 1 / bins)), the yardstick for "uniform". */
double rch_chaos_sd_iid(unsigned points, unsigned bins);
