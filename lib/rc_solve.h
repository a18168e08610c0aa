/* SPDX-License-Identifier: MIT */
/* rc_solve.h - identification of model parameters from cable lengths.
 *
 * Least squares on r_i = l(q_i; x) - L_i over the training samples, with
 * the normal equations J^T J, J^T r accumulated sample by sample: memory does
 * not grow with the number of samples (the samples themselves stay with the
 * caller).
 *
 * Methods:
 *  - RC_METHOD_LM (default): Levenberg-Marquardt in scaled variables
 *    (each free parameter divided by its Jacobian column norm at the start, so
 *    mm and rad are comparable), step acceptance by gain ratio with Nielsen's
 *    damping update, and the step restricted to the identifiable subspace:
 *    eigen-directions of the scaled J^T J that rc_ident calls not
 *    identifiable (relative singular value below RC_IDENT_NULL_REL) are left
 *    untouched, so the solver never wanders along what the data cannot see;
 *    and a direction is moved only while its step is significant against the
 *    residual noise (snr_min), which ends the slow creep along weakly
 *    identified directions that would only fit noise.
 *  - RC_METHOD_LTLM: the paper's Algorithm I construction on top of the
 *    robust LM: x1 = an accepted robust LM step from x_k, x2 = the robust
 *    LM's next step from x1 (new normal equations at x1, same damping and
 *    eigen-truncation), a = (x_k + x1)/2, b = (x1 + x2)/2, M candidates on
 *    the two segments from ONE scalar logistic-tent sequence; the best of
 *    {x1, candidates} is kept. Both steps lie in the identifiable,
 *    significant subspace, so no candidate moves along a direction the
 *    robust LM excludes.
 *  - RC_METHOD_LM_PAPER: the paper's Eq. 10 verbatim: x <- x - (J^T J + mu I)^-1
 *    J^T r with fixed mu (default 5), raw units (mm, rad), no step acceptance.
 *  - RC_METHOD_LTLM_PAPER: Algorithm I literally (Eqs. 13-18): x1 and x2 are
 *    two consecutive Eq. 10 steps (new Jacobian at x1), a and b the
 *    midpoints, xl(m) = x1 - (x1 - a) N_m, xr(m) = x1 + (x2 - b) N_m for
 *    m = 1..M with one scalar sequence N_m of Eq. 11, and x_{k+1} = the best
 *    of {xl(m), xr(m), x1} (x_k itself is not a candidate: the cost may rise).
 *    Left open by the paper, chosen here: M = n_candidates (10), K = max_iter
 *    (50), N_0 = chaos_n0 (drawn from seed in (0.05, 0.95) when 0), and the
 *    sequence continues across iterations (iteration k uses N_{(k-1)M+1} ..
 *    N_{kM}); ties keep the earlier point in the order x1, xl(1), xr(1),
 *    xl(2), ...
 *  - RC_METHOD_LM_PAPER_DEG, RC_METHOD_LTLM_PAPER_DEG: the same with the
 *    angles measured in degrees inside Eq. 10 (J columns of angles divided
 *    by 180/pi, steps multiplied back), the likely reading of mu = 5 since
 *    the paper reports angles in degrees (Table 7).
 *
 * Memory: rc_solve_work is large (two RC_MAX_PARAMS^2 matrices); callers own
 * it (static or heap on the host), or pass a buffer of rc_solve_work_size()
 * bytes to rc_solve_buf. Thread safety: reentrant.
 */
#ifndef RC_SOLVE_H
#define RC_SOLVE_H

#include <stddef.h>
#include <stdint.h>

#include "rc_model.h"
#include "rc_problem.h"

typedef struct rc_ltlm_event {
    unsigned iter;          /* 1-based iteration k+1 */
    rc_ltlm_point kind;
    unsigned m;             /* candidate index 1..M (XL, XR), else 0 */
    double n_m;             /* N_m (XL, XR), else 0 */
    const rc_model *x;      /* the point (valid during the call only) */
    double cost_mm2;        /* sum of squared residuals; -1: not evaluated or not finite */
} rc_ltlm_event;

typedef void (*rc_ltlm_cb)(void *ctx, const rc_ltlm_event *ev);

/* Callback after each iteration: training RMS (mm) and the current model. */
typedef void (*rc_iter_cb)(void *ctx, unsigned iter, double train_rms_mm, const rc_model *m);

/* The robust LM's initial damping for a MAP fit started near its optimum
 * (a refit from an earlier fit of nearly the same problem): Gauss-Newton
 * steps from the first iteration, the damping raised only where a step is
 * refused. The default 1e-3 holds the directions only the prior determines
 * (eigenvalues near 1e-8 of the largest) all but still, so a warm refit
 * crawled along them for 10 iterations. Not for least squares without a
 * prior: there the damping is what keeps ill-determined directions still. */
#define RC_SOLVE_MU0_WARM 1e-9

/* All-zero means defaults. */
typedef struct rc_solve_config {
    rc_method method;
    unsigned max_iter;       /* 0: 100 (paper variants: 50) */
    double mu0;              /* robust: initial damping relative to the largest
                                scaled eigenvalue, 0: 1e-3; paper: absolute mu, 0: 5;
                                RC_SOLVE_MU0_WARM (robust only) for a start near the optimum */
    double tol_step;         /* 0: 1e-9 (relative, scaled) */
    double tol_cost;         /* 0: 1e-4 (relative decrease of the cost in one iteration) */
    double rcond;            /* 0: rc_ident's rule (null below a relative singular value of
                                RC_IDENT_NULL_REL, an eigenvalue 1e-12 of the largest);
                                > 0: own eigenvalue cut-off relative to the largest */
    double snr_min;          /* 0: 1: an eigen-direction is stepped along only when its
                                Gauss-Newton step is at least snr_min standard errors
                                (sigma from the current residual); negative: off */
    unsigned n_candidates;   /* LTLM M (candidates per segment), 0: 10 */
    double chaos_r;          /* LTLM map parameter r, 0: 0.5 */
    double chaos_n0;         /* LTLM N_0 in (0, 1); 0: drawn from seed */
    uint64_t seed;           /* LTLM chaotic seed (for N_0) */
    const uint8_t *fixed;    /* (n_params) nonzero: parameter held fixed; NULL: none */
    /* A Gaussian prior on the parameters (maximum a posteriori estimation;
     * robust LM and LTLM only, the paper variants ignore it). The cost
     * becomes sum r_i^2 + sum_k (noise / sd_k)^2 (x_k - mean_k)^2: the
     * residuals' variance noise^2 against each parameter's prior variance
     * sd_k^2, so the prior rows weigh as much as the data say they should.
     * With a prior every direction is determined (by the data or by the
     * prior), so no direction is truncated as null and the significance
     * rule (snr_min) is off. prior_mean NULL or prior_noise_mm <= 0: no
     * prior. */
    const double *prior_mean; /* (n_params) the prior's mean (nominal geometry) */
    const double *prior_sd;   /* (n_params) its standard deviation (mm, rad, or the effect's unit);
                                 <= 0 or not finite: no prior on that parameter */
    double prior_noise_mm;    /* standard deviation of one residual (mm) the prior is weighed against */
    rc_iter_cb on_iter;
    rc_ltlm_cb on_ltlm;      /* LTLM variants: every point of every iteration; may be NULL */
    void *cb_ctx;            /* passed to on_iter and on_ltlm */
} rc_solve_config;

/* Workspace of rc_solve: the solver's (rc_lsq_work), the model the data
 * rows are evaluated on (the caller's effects, the point's x), then the two
 * matrices last so that a workspace sized by the parameter count
 * (rc_solve_work_size, rc_solve_buf) is this struct's prefix followed by the
 * matrices at their real size. rc_solve keeps its normal-equation row blocks
 * (4 x n_params) and the samples' joint sines and cosines (rc_qtrig_fill) in
 * the unused tails of A and V (beyond n_params^2 entries) when they fit
 * there (the tables up to 1,396 samples for 27 parameters); A and V hold
 * nf x nf matrices (leading dimension nf). */
typedef struct rc_solve_work {
    rc_lsq_work lsq;
    rc_model at;                              /* the model a pass evaluates */
    double A[RC_MAX_PARAMS * RC_MAX_PARAMS];  /* (nf x nf) normal matrix */
    double V[RC_MAX_PARAMS * RC_MAX_PARAMS];  /* (nf x nf) eigenvectors */
} rc_solve_work;

/* The robot's problem (rc_problem.h): the model supplies the data blocks.
 * Consecutive samples of one sensor form a block (cable lengths: dimension
 * 1; a tracker position's three samples x, y, z: one item of dimension 3),
 * in the samples' order, so the rows are the samples' in their order; a
 * sample's rows are its weighted residual (prediction - rc_sample.value) and
 * its weighted Jacobian row (rc_meas_prepared). The prior block is the
 * configuration's prior; alpha6 is marked inert (it turns the flange about
 * its own x after the last translation), the angles for the paper's -deg
 * variants. RC_MODEL_MAX_BLOCKS runs at most; more (sensors interleaved)
 * become one block of dimension 1, the same rows in the same order. */
#define RC_MODEL_MAX_BLOCKS 8
typedef struct rc_model_rows rc_model_rows;
typedef struct rc_model_block {
    const rc_model_rows *owner;
    size_t s0;                 /* its first sample */
} rc_model_block;
struct rc_model_rows {
    const rc_model *eval;      /* the model the rows are taken on */
    rc_model *scratch;         /* NULL: the point is always eval->x; else a pass copies it here */
    rc_meas_prep prep;
    const rc_sample *samples;
    const double *sin_q, *cos_q; /* (n x 6) each, rc_qtrig_fill; NULL: per sample */
    rc_model_block blk[RC_MODEL_MAX_BLOCKS];
    rc_block blocks[RC_MODEL_MAX_BLOCKS];
    uint8_t inert[RC_MAX_PARAMS];
    uint8_t unit[RC_MAX_PARAMS];
};

/* Fill p (and its storage r) with the problem of m on samples (n): m's
 * effects, the point x of each pass copied into scratch (NULL: every pass is
 * at m->x), the readings' sines sin_q, cos_q (or NULL), fixed parameters
 * and the prior from cfg (NULL: none). max_dim 1: every sample a row of its
 * own (a caller's Jacobian row holds n_params entries). */
void rc_model_problem(rc_problem *p, rc_model_rows *r, const rc_model *m, rc_model *scratch, const rc_sample *samples,
                      size_t n, const double *sin_q, const double *cos_q, const struct rc_solve_config *cfg,
                      unsigned max_dim);


/* The prior's part of the cost at m (mm^2, as rc_solve weighs it): 0
 * without a prior (cfg NULL, no prior_mean, prior_noise_mm <= 0). Only
 * parameters not held fixed count. */
double rc_prior_cost(const rc_model *m, const rc_solve_config *cfg);
/* The prior rows added to the normal equations of the free parameters idx
 * (nf): A (nf x nf) += W, g (nf) += W (x - mean), *cost += (x - mean)^T W
 * (x - mean), W = diag((noise / sd_k)^2). Nothing without a prior. The one
 * definition every solver with a prior uses (rc_solve, rc_est's SSLM). */
void rc_prior_normal_eq(double *A, double *g, double *cost, const rc_model *m, const uint16_t *idx, unsigned nf,
                        const rc_solve_config *cfg);

/* Sum of squared residuals over samples (n). RC_ERR_NUMERIC on a degenerate
 * sample or a non-finite result. */
rc_status rc_cost(double *cost_mm2, const rc_model *m, const rc_sample *samples, size_t n);
/* rc_cost with the readings' sines and cosines sin_q, cos_q ((n x 6) each,
 * rc_qtrig_fill of samples; both NULL: per sample): the same sum to the last
 * bit, without the readings' trigonometry on every call. */
rc_status rc_cost_tab(double *cost_mm2, const rc_model *m, const rc_sample *samples, const double *sin_q,
                      const double *cos_q, size_t n);

/* Accumulate the normal equations over the samples for the free parameters
 * idx (nf): A (nf x nf, full) = J^T J, g (nf) = J^T r, cost = sum r^2.
 * jrow: (m->n_params) scratch. */
rc_status rc_normal_eq(double *A, double *g, double *cost_mm2, double *jrow, const rc_model *m,
                       const uint16_t *idx, unsigned nf, const rc_sample *samples, size_t n);

/* Mark cfg as a start near the optimum: RC_SOLVE_MU0_WARM as its initial
 * damping when it is a robust LM or LTLM fit with a prior and no mu0 of its
 * own; otherwise cfg is left as it is (the one place that rule is made). */
void rc_solve_config_warm(rc_solve_config *cfg);

/* Identify the parameters of m (in: start, out: solution) from samples (n).
 * res may be NULL. RC_ERR_RANK when no parameter is free. */
rc_status rc_solve(rc_model *m, rc_solve_result *res, rc_solve_work *w, const rc_solve_config *cfg,
                   const rc_sample *samples, size_t n);

/* Workspace sized by the parameter count (as cminpack's lwa): the bytes
 * rc_solve_buf needs for a model of n_params parameters (the prefix of
 * rc_solve_work up to A, the two n_params^2 matrices and 4 x n_params for the
 * normal-equation row blocks), and with n_samples > 0 also for the tables of
 * those samples' joint sines and cosines (12 doubles a sample), which spare
 * every pass 12 sines per sample. 0 when n_params is outside
 * 27..RC_MAX_PARAMS. For 27 parameters: 25,512 bytes without tables;
 * sizeof(rc_solve_work) is 160,440 bytes (RC_MAX_PARAMS 96). */
size_t rc_solve_work_size(unsigned n_params, size_t n_samples);

/* rc_solve in caller-provided storage work (work_bytes, aligned for
 * double, e.g. from malloc or a double array): at least
 * rc_solve_work_size(m->n_params, 0) bytes, else RC_ERR_CAPACITY; with
 * rc_solve_work_size(m->n_params, n) bytes or more the sample tables are
 * kept too. The result is the same as rc_solve's to the last bit. */
rc_status rc_solve_buf(rc_model *m, rc_solve_result *res, void *work, size_t work_bytes,
                       const rc_solve_config *cfg, const rc_sample *samples, size_t n);

/* Residual statistics of a model on samples (residual e = l_model - L). */
typedef struct rc_metrics {
    size_t n;
    double rmse_mm;     /* sqrt(mean e^2) */
    double mean_abs_mm; /* mean |e|  (the paper's Eq. 20 calls this "SD") */
    double sd_mm;       /* true standard deviation of e (n - 1 in the denominator) */
    double mean_mm;     /* mean e (bias) */
    double max_mm;      /* max |e| */
} rc_metrics;

rc_status rc_eval(rc_metrics *out, const rc_model *m, const rc_sample *samples, size_t n);



/* Initial guess of the encoder outlet e from the model's flange points and
 * the measured lengths, by the linearisation |p|^2 - 2 p.e + |e|^2 = L^2
 * (linear least squares in e and |e|^2, 4 x 4 normal equations).
 * enc_mm: (3) output. RC_ERR_RANK when the points are (nearly) coplanar in
 * any orientation; RC_ERR_RANGE when the lengths fit no sphere around the
 * guessed e (RMS of |p_i - e| - L_i above 15 % of the RMS length + 1 mm: a
 * wild reading, a wrong or constant column). */
rc_status rc_encoder_guess(double enc_mm[3], const rc_model *m, const rc_sample *samples, size_t n);
#endif /* RC_SOLVE_H */
