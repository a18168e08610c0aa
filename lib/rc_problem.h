/* SPDX-License-Identifier: MIT */
/* rc_problem.h - the least-squares problem the solver sees, and the solver.
 *
 * A problem is n_params parameters x and blocks of residual rows: each block
 * a source of rows (a sensor) with its dimension (rows per item) and unit,
 * asked for an item's rows and their Jacobian rows by a callback (as
 * cminpack's lmstr asks for one row at a time, and Ceres' AddResidualBlock);
 * the memory does not grow with the number of items. A Gaussian prior is one
 * more block (Ceres' NormalPrior): the rows (noise / sd_k) (x_k - mean_k),
 * diagonal, so the solver adds them in closed form. The solver knows nothing
 * of what the parameters mean: what a robot is, which parameter is an angle
 * or can never move a row is the problem's (lib/rc_solve.h builds the
 * robot's problem from an rc_model and its samples).
 *
 * The cost is sum over the data rows of r^2 plus the prior's rows; the rows
 * are taken in block order, items in order, so a pass sums the same numbers
 * in the same order every time. Heap-free: the workspace is caller-owned,
 * sized by rc_problem_work_size. Thread safety: reentrant.
 */
#ifndef RC_PROBLEM_H
#define RC_PROBLEM_H

#include <stddef.h>
#include <stdint.h>

#include "rc_config.h"
#include "rc_status.h"

/* Rows one item of a block may have (a tracker position: 3). */
#define RC_MAX_BLOCK_DIM 3

/* The methods: one table, one line per method (name, its variant flags, a
 * description): the enum, the names, the command line's choices and the
 * report's list are expanded from it.
 * X(ID, name, paper, ltlm, deg, description):
 *  paper: the paper's Eq. 10 verbatim (fixed mu, raw units, no acceptance);
 *  ltlm: Algorithm I's chaotic candidates on top of the step; deg: angles in
 *  degrees inside Eq. 10. */
#define RC_METHODS(X)                                                                                             \
    X(LM, "lm", 0, 0, 0, "robust LM: scaled, gain-ratio damping, identifiable and significant subspace")          \
    X(LTLM, "ltlm", 0, 1, 0, "robust LM + Algorithm I's chaotic candidates")                                      \
    X(LM_PAPER, "lm-paper", 1, 0, 0, "the paper's Eq. 10 (fixed mu, angles in rad)")                              \
    X(LTLM_PAPER, "ltlm-paper", 1, 1, 0, "the paper's Algorithm I (Eqs. 13-18, angles in rad)")                   \
    X(LM_PAPER_DEG, "lm-paper-deg", 1, 0, 1, "Eq. 10 with angles in degrees")                                     \
    X(LTLM_PAPER_DEG, "ltlm-paper-deg", 1, 1, 1, "Algorithm I with angles in degrees")

#define RC_METHOD_ENUM_(id, name, paper, ltlm, deg, text) RC_METHOD_##id,
typedef enum rc_method { RC_METHODS(RC_METHOD_ENUM_) RC_METHOD_COUNT_ } rc_method;
#undef RC_METHOD_ENUM_

/* The methods' names as one '|'-separated string literal ("lm|ltlm|..."),
 * for an option table's choices. */
#define RC_METHOD_CHOICE_(id, name, paper, ltlm, deg, text) "|" name
#define RC_METHOD_CHOICES (RC_METHODS(RC_METHOD_CHOICE_) + 1)
/* The same with ", " between the names, for messages. */
#define RC_METHOD_LIST_(id, name, paper, ltlm, deg, text) ", " name
#define RC_METHOD_LIST (RC_METHODS(RC_METHOD_LIST_) + 2)

typedef struct rc_method_desc {
    rc_method method;
    const char *name;        /* "lm", ...: the command line's and the model file's */
    uint8_t paper;           /* the paper's update verbatim */
    uint8_t ltlm;            /* with Algorithm I's candidates */
    uint8_t deg;             /* angles in degrees inside Eq. 10 */
    const char *description; /* one line, for help texts */
} rc_method_desc;

/* The description of method, NULL when it is not one. */
const rc_method_desc *rc_method_describe(unsigned method);
/* Name of a method ("lm", ...); "unknown" otherwise. */
const char *rc_method_name(rc_method method);
/* The method named name: RC_OK, or RC_ERR_ARG for an unknown name (out
 * untouched). */
rc_status rc_method_from_name(rc_method *out, const char *name);

/* Points of one LTLM iteration, reported to the problem's on_ltlm. */
typedef enum rc_ltlm_point {
    RC_LTLM_X1 = 0,     /* x_{k+1,1}: one LM step from x_k */
    RC_LTLM_X2 = 1,     /* x_{k+1,2}: the next LM step from x1 (cost not evaluated: -1) */
    RC_LTLM_A = 2,      /* a = (x_k + x1)/2 (cost not evaluated: -1) */
    RC_LTLM_B = 3,      /* b = (x1 + x2)/2 (cost not evaluated: -1) */
    RC_LTLM_XL = 4,     /* xl(m) = x1 - (x1 - a) N_m */
    RC_LTLM_XR = 5,     /* xr(m) = x1 + (x2 - b) N_m */
    RC_LTLM_CHOSEN = 6  /* the best of {x1, xl, xr}: x_{k+1} */
} rc_ltlm_point;

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

const char *rc_exit_str(rc_exit e);

typedef struct rc_solve_result {
    rc_exit exit;
    unsigned iterations;
    unsigned cost_evals;      /* passes over the data rows */
    double rms_start_mm;      /* RMS of the data rows at the start (the blocks' unit; mm for a robot) */
    double rms_final_mm;      /* RMS of the data rows at the end */
    unsigned n_free;          /* parameters the solver was allowed to move */
    unsigned rank;            /* identifiable directions among them (last iteration) */
    double cond;              /* sqrt(largest / smallest kept eigenvalue), scaled */
    unsigned ltlm_wins;       /* LTLM: iterations where a chaotic candidate beat x1 */
} rc_solve_result;

/* The solver's settings; all-zero means defaults (rc_solve.h's
 * rc_solve_config documents each). */
typedef struct rc_solve_opts {
    rc_method method;
    unsigned max_iter;       /* 0: 100 (paper variants: 50) */
    double mu0;              /* robust: initial damping relative to the largest scaled eigenvalue, 0: 1e-3;
                                paper: absolute mu, 0: 5 */
    double tol_step;         /* 0: 1e-9 */
    double tol_cost;         /* 0: 1e-4 */
    double rcond;            /* 0: rc_ident's rule */
    double snr_min;          /* 0: 1; negative: off */
    unsigned n_candidates;   /* LTLM M, 0: 10 */
    double chaos_r;          /* 0: 0.5 */
    double chaos_n0;         /* 0: drawn from seed */
    uint64_t seed;
} rc_solve_opts;

/* An item's rows: r (dim) its weighted residuals (prediction - measured
 * value, in the block's unit) and, when jac is not NULL, jac (dim x
 * n_params, row-major) their derivatives with respect to every parameter,
 * at the point the problem's prepare was last given. item runs from the
 * block's first to first + n - 1. */
typedef rc_status (*rc_rows_fn)(double *r, double *jac, void *ctx, size_t item);

/* A block of residual rows: one sensor's measurements. */
typedef struct rc_block {
    rc_rows_fn rows;
    void *ctx;         /* passed to rows */
    size_t first;      /* the first item passed to rows */
    size_t n;          /* items */
    unsigned dim;      /* rows per item, 1..RC_MAX_BLOCK_DIM */
    const char *unit;  /* the unit of its rows ("mm") */
} rc_block;

/* The prior block: rows (noise / sd_k) (x_k - mean_k) for the parameters
 * with a finite sd_k > 0. noise is the standard deviation of one data row
 * the prior is weighed against, so the prior rows weigh as much as the data
 * say they should. mean NULL, sd NULL or noise <= 0: no prior. */
typedef struct rc_prior_block {
    const double *mean; /* (n_params) */
    const double *sd;   /* (n_params) in the parameters' units; <= 0 or not finite: none on that one */
    double noise;       /* in the data rows' unit */
} rc_prior_block;

/* A point the LTLM variants visit (the problem's on_ltlm). */
typedef struct rc_lsq_event {
    unsigned iter;          /* 1-based iteration k+1 */
    rc_ltlm_point kind;
    unsigned m;             /* candidate index 1..M (XL, XR), else 0 */
    double n_m;             /* N_m (XL, XR), else 0 */
    const double *x;        /* the point (n_params; valid during the call only) */
    double cost;            /* cost (data + prior); -1: not evaluated or not finite */
} rc_lsq_event;

typedef struct rc_problem {
    unsigned n_params;          /* 1..RC_MAX_PARAMS */
    unsigned n_blocks;
    const rc_block *blocks;     /* (n_blocks) the data */
    /* Called once per pass with the point every row of the pass is taken
     * at, before the first rows call (what rows share: a model's sines);
     * NULL: none. */
    rc_status (*prepare)(void *ctx, const double *x);
    void *prepare_ctx;
    rc_prior_block prior;       /* all zero: none */
    const uint8_t *fixed;       /* (n_params) nonzero: held fixed; NULL: none */
    /* (n_params) nonzero: a parameter the problem knows can never move a
     * row while its column is zero (a robot's alpha6 at the flange centre):
     * it leaves the free set when its starting column is zero; NULL: none */
    const uint8_t *inert;
    /* (n_params) unit class of each parameter: 1 an angle in rad (the paper's
     * -deg variants count it in degrees), else 0; NULL: no angles */
    const uint8_t *unit;
    void (*on_iter)(void *ctx, unsigned iter, double rms, const double *x);
    void (*on_ltlm)(void *ctx, const rc_lsq_event *ev);
    void *cb_ctx;               /* passed to on_iter and on_ltlm */
} rc_problem;

/* Data rows of p (sum of n x dim over its blocks). */
size_t rc_problem_rows(const rc_problem *p);

/* The data's cost at x (sum of squared rows, without the prior). */
rc_status rc_problem_cost(double *cost, const rc_problem *p, const double *x);
/* The prior's cost at x over the parameters not held fixed. */
double rc_problem_prior_cost(const rc_problem *p, const double *x);
/* The prior rows added to the normal equations of the free parameters idx
 * (nf): A (nf x nf) += W, g += W (x - mean), *cost += (x - mean)^T W
 * (x - mean), W = diag((noise / sd_k)^2). */
void rc_problem_prior_normal_eq(double *A, double *g, double *cost, const rc_problem *p, const double *x,
                                const uint16_t *idx, unsigned nf);
/* The data's normal equations at x for the free parameters idx (nf): A
 * (nf x nf, full) = J^T J, g = J^T r, cost = sum r^2. jrow:
 * (RC_MAX_BLOCK_DIM x n_params) scratch; jblk: (4 x nf) scratch or NULL
 * (then row by row; the same sums to the last bit). */
rc_status rc_problem_normal_eq(double *A, double *g, double *cost, double *jrow, double *jblk, const rc_problem *p,
                               const double *x, const uint16_t *idx, unsigned nf);

/* The solver's small workspace; the two matrices and the row blocks follow
 * it in rc_problem_solve's buffer. */
typedef struct rc_lsq_work {
    double ev[RC_MAX_PARAMS];                 /* (nf) eigenvalues */
    double g[RC_MAX_PARAMS];                  /* (nf) gradient J^T r */
    double c[RC_MAX_PARAMS];                  /* (nf) V^T g */
    double D[RC_MAX_PARAMS];                  /* (nf) column scaling */
    double dx[RC_MAX_PARAMS];                 /* (nf) step */
    double jrow[RC_MAX_BLOCK_DIM * RC_MAX_PARAMS]; /* one item's Jacobian rows */
    double lt_a[RC_MAX_PARAMS];               /* (nf) LTLM a on the free parameters */
    double lt_b[RC_MAX_PARAMS];               /* (nf) LTLM b */
    double lt_x2[RC_MAX_PARAMS];              /* (nf) LTLM x2 */
    uint16_t idx[RC_MAX_PARAMS];              /* (nf) free parameter indices */
    double trial[RC_MAX_PARAMS];              /* (n_params) points */
    double best[RC_MAX_PARAMS];
    double cand[RC_MAX_PARAMS];
} rc_lsq_work;

/* Bytes of rc_problem_solve's workspace for n_params parameters: the small
 * workspace, two n_params^2 matrices and 4 x n_params row blocks; 0 outside
 * 1..RC_MAX_PARAMS. */
size_t rc_problem_work_size(unsigned n_params);

/* Minimise the problem's cost from x (in: start, out: solution; n_params)
 * with the method of opts (NULL: defaults) in work (work_bytes, aligned for
 * double, at least rc_problem_work_size). res may be NULL. RC_ERR_RANK when
 * no parameter is free, RC_ERR_CAPACITY when work is too small. */
rc_status rc_problem_solve(double *x, rc_solve_result *res, void *work, size_t work_bytes, const rc_solve_opts *opts,
                           const rc_problem *p);

/* rc_problem_solve on the small workspace w and the matrices A, V (n_params^2
 * entries each), jblk (4 x n_params, or NULL): for a caller that keeps them
 * in a larger workspace (rc_solve). */
rc_status rc_problem_solve_in(double *x, rc_solve_result *res, rc_lsq_work *w, double *A, double *V, double *jblk,
                              const rc_solve_opts *opts, const rc_problem *p);

#endif /* RC_PROBLEM_H */
