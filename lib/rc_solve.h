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
 *    eigen-directions of the scaled J^T J below rcond * largest are left
 *    untouched, so the solver never wanders along what the data cannot see;
 *    and a direction is moved only while its step is significant against the
 *    residual noise (snr_min), which ends the slow creep along weakly
 *    identified directions that would only fit noise.
 *  - RC_METHOD_LTLM: the robust LM step, then M logistic-tent chaotic
 *    candidates in an interval around the LM candidate (paper Algorithm I);
 *    the best of LM candidate and chaotic candidates is kept if it lowers the
 *    cost.
 *  - RC_METHOD_LM_PAPER: the paper's Eq. 10 verbatim: x <- x - (J^T J + mu I)^-1
 *    J^T r with fixed mu (default 5), raw units, no step acceptance.
 *  - RC_METHOD_LTLM_PAPER: Algorithm I on top of the paper's LM step.
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

typedef enum rc_method {
    RC_METHOD_LM = 0,
    RC_METHOD_LTLM = 1,
    RC_METHOD_LM_PAPER = 2,
    RC_METHOD_LTLM_PAPER = 3
} rc_method;

/* Why the solver stopped. */
typedef enum rc_exit {
    RC_EXIT_NONE = 0,
    RC_EXIT_SMALL_STEP = 1,    /* scaled step below tol_step */
    RC_EXIT_SMALL_COST = 2,    /* relative cost decrease below tol_cost */
    RC_EXIT_SMALL_GRAD = 3,    /* no identifiable direction left whose step is significant */
    RC_EXIT_MAX_ITER = 4,      /* iteration limit reached */
    RC_EXIT_NO_DESCENT = 5,    /* damping grew to its limit without a better point */
    RC_EXIT_NONFINITE = 6      /* a cost or step became NaN/inf (paper variants) */
} rc_exit;

/* Callback after each iteration: training RMS (mm) and the current model. */
typedef void (*rc_iter_cb)(void *ctx, unsigned iter, double train_rms_mm, const rc_model *m);

/* All-zero means defaults. */
typedef struct rc_solve_config {
    rc_method method;
    unsigned max_iter;       /* 0: 100 (paper variants: 50) */
    double mu0;              /* robust: initial damping relative to the largest
                                scaled eigenvalue, 0: 1e-3; paper: absolute mu, 0: 5 */
    double tol_step;         /* 0: 1e-9 (relative, scaled) */
    double tol_cost;         /* 0: 1e-4 (relative decrease of the cost in one iteration) */
    double rcond;            /* 0: 1e-9: eigenvalue cut-off relative to the largest */
    double snr_min;          /* 0: 1: an eigen-direction is stepped along only when its
                                Gauss-Newton step is at least snr_min standard errors
                                (sigma from the current residual); negative: off */
    unsigned n_candidates;   /* LTLM M, 0: 10 */
    double chaos_r;          /* LTLM map parameter r, 0: 0.5 */
    double ltlm_span;        /* LTLM interval half-width as a multiple of |step|, 0: 1 */
    uint64_t seed;           /* LTLM chaotic seed */
    const uint8_t *fixed;    /* (n_params) nonzero: parameter held fixed; NULL: none */
    rc_iter_cb on_iter;
    void *cb_ctx;
} rc_solve_config;

typedef struct rc_solve_result {
    rc_exit exit;
    unsigned iterations;
    unsigned cost_evals;      /* passes over the training samples */
    double rms_start_mm;      /* training RMS at the start */
    double rms_final_mm;      /* training RMS at the end */
    unsigned n_free;          /* parameters the solver was allowed to move */
    unsigned rank;            /* identifiable directions among them (last iteration) */
    double cond;              /* sqrt(largest / smallest kept eigenvalue), scaled */
    unsigned ltlm_wins;       /* LTLM: iterations where a chaotic candidate won */
} rc_solve_result;

/* Workspace of rc_solve. The two matrices come last so that a workspace
 * sized by the parameter count (rc_solve_work_size, rc_solve_buf) is this
 * struct's prefix followed by the matrices at their real size. rc_solve
 * keeps the samples' joint sines and cosines (rc_qtrig_fill) in the unused
 * tails of A and V (beyond n_params^2 entries) when they fit there (up to
 * 1,414 samples for 27 parameters); A and V hold nf x nf matrices (leading
 * dimension nf) as before. */
typedef struct rc_solve_work {
    double ev[RC_MAX_PARAMS];                 /* (nf) eigenvalues */
    double g[RC_MAX_PARAMS];                  /* (nf) gradient J^T r */
    double c[RC_MAX_PARAMS];                  /* (nf) V^T g */
    double D[RC_MAX_PARAMS];                  /* (nf) column scaling */
    double dx[RC_MAX_PARAMS];                 /* (nf) step */
    double jrow[RC_MAX_PARAMS];               /* (n_params) one Jacobian row */
    double chaos[RC_MAX_PARAMS];              /* (nf) chaotic variables */
    uint16_t idx[RC_MAX_PARAMS];              /* (nf) free parameter indices */
    rc_model trial;
    rc_model best;
    rc_model cand;                            /* LTLM chaotic candidate */
    double A[RC_MAX_PARAMS * RC_MAX_PARAMS];  /* (nf x nf) normal matrix */
    double V[RC_MAX_PARAMS * RC_MAX_PARAMS];  /* (nf x nf) eigenvectors */
} rc_solve_work;

const char *rc_method_name(rc_method method);
const char *rc_exit_str(rc_exit e);

/* Sum of squared residuals over samples (n). RC_ERR_NUMERIC on a degenerate
 * sample or a non-finite result. */
rc_status rc_cost(double *cost_mm2, const rc_model *m, const rc_sample *samples, size_t n);

/* Accumulate the normal equations over the samples for the free parameters
 * idx (nf): A (nf x nf, full) = J^T J, g (nf) = J^T r, cost = sum r^2.
 * jrow: (m->n_params) scratch. */
rc_status rc_normal_eq(double *A, double *g, double *cost_mm2, double *jrow, const rc_model *m,
                       const uint16_t *idx, unsigned nf, const rc_sample *samples, size_t n);

/* Identify the parameters of m (in: start, out: solution) from samples (n).
 * res may be NULL. RC_ERR_RANK when no parameter is free. */
rc_status rc_solve(rc_model *m, rc_solve_result *res, rc_solve_work *w, const rc_solve_config *cfg,
                   const rc_sample *samples, size_t n);

/* Workspace sized by the parameter count (as cminpack's lwa): the bytes
 * rc_solve_buf needs for a model of n_params parameters, and with
 * n_samples > 0 also for the tables of those samples' joint sines and
 * cosines (12 doubles a sample), which spare every pass 12 sines per sample.
 * 0 when n_params is outside 27..RC_MAX_PARAMS. For 27 parameters: 23 KB
 * without tables, sizeof(rc_solve_work) is 159 KB. */
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
