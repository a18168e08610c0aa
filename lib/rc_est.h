/* SPDX-License-Identifier: MIT */
/* rc_est.h - the other identification methods of the LTLM paper's comparison
 * (its Table 5): EKF, PF, SCA, QIBAS and SSLM. LM and LTLM are rc_solve's.
 *
 * What: every method identifies the same parameters as rc_solve (the free
 * parameters of an rc_model, from cable lengths) and reports the training RMS
 * after each iteration through the rc_iter_cb callback, so that convergence
 * curves of all seven methods can be drawn on one chart. All are seedable and
 * deterministic: the same seed, start and samples give bit-identical results.
 *
 * Identifiable subset. 27 parameters from cable lengths alone are rank
 * deficient (e.g. d1 trades against e_z, theta1 against a rotation of e about
 * z, theta6 and alpha6 do not move the flange point). Unless keep_all is set,
 * the methods here work on an identifiable SUBSET of the free parameters,
 * chosen at the start point by greedy pivoted Cholesky of the column-scaled
 * (correlation) matrix J^T J on the training samples: a parameter is kept
 * while the part of its Jacobian column not explained by the parameters
 * already kept exceeds sqrt(subset_tol) of the column's norm; the others stay
 * at their start values (rc_est_subset does only this step).
 *
 * Bounds. The population methods (PF, SCA, QIBAS) search a box around the
 * start point x0: x0_j +- bound_j, bound_j by unit class (a, d: bound_len_mm;
 * alpha, theta: bound_ang_rad; encoder: bound_enc_mm; effect parameters:
 * bound_len_mm when in mm, bound_ang_rad when in rad, else bound_other).
 * They work in normalised coordinates u_j = (x_j - x0_j) / bound_j in [-1, 1].
 * The start point is always a member of the initial population, so a
 * population method never ends worse than its start. EKF uses bound_j as the
 * prior standard deviation.
 *
 * The methods and their hyperparameters (defaults when the config field is 0):
 *  - RC_EST_EKF: extended Kalman filter with a residual-based adaptive
 *    measurement noise (the paper's M2 cites an adaptive-residual EKF, its
 *    ref. 10; we use the residual-based rule of Akhlaghi, Zhou & Huang 2017).
 *    State = the parameters, constant model with process noise
 *    Q = ekf_q * P0 per measurement (0: 1e-9), P0 = diag(bound_j^2). Each
 *    cable length is a scalar measurement, Jacobian row h from rc_meas at
 *    the current state, Joseph-form covariance update (symmetrised). After
 *    each update the measurement variance adapts to the post-update residual
 *    eps = innov R / S: R <- ekf_alpha R + (1 - ekf_alpha) (eps^2 + h^T P h)
 *    with P the updated covariance (ekf_alpha 0: 0.3); R starts at
 *    noise_mm^2 when noise_mm is given, else at the start's mean squared
 *    residual, never below (resolution_mm / sqrt(12))^2 (resolution 0:
 *    0.004 mm), and carries over from pass to pass. Sequential updates over the training
 *    samples in their order; max_iter passes (0: 10). Each pass restarts
 *    from P0 at the current state (re-linearised; no sample counted twice
 *    in one covariance); the state after the last pass is returned (the
 *    curve shows every pass); stops early when a pass lowers the cost by
 *    less than tol_cost (0: 1e-10) relative.
 *  - RC_EST_PF: regularised particle filter. pop particles (0: 100) drawn
 *    around the start (normalised sd 1/3, clamped to the box; particle 0 is
 *    the start). Each of max_iter passes (0: 100) over the training samples:
 *    log-likelihood of particle i = -SSE_i / (2 R) with R = the best
 *    particle's mean squared residual (noise plus unmodelled error), tempered
 *    by the largest exponent phi <= 1 that keeps the effective sample size
 *    >= pop/2 (annealing, so the cloud cannot collapse to one particle);
 *    systematic resampling; Gaussian jitter per coordinate with Silverman's
 *    bandwidth h = (4 / ((d + 2) N))^(1/(d+4)) times the weighted sd of the
 *    particles (floor 1e-7), reflected into the box. The estimate is the best
 *    of the weighted means and particles seen.
 *  - RC_EST_SCA: Sine Cosine Algorithm (Mirjalili 2016): pop agents (0: 30),
 *    agent 0 at the start, the others uniform in the box; max_iter iterations
 *    (0: 500); destination P = best so far; per agent and coordinate
 *    X <- X + r1 sin(r2) |r3 P - X| if r4 < 0.5, else X + r1 cos(r2) |r3 P - X|,
 *    r1 = a - t a / T with a = 2, r2 ~ U[0, 2 pi], r3 ~ U[0, 2], r4 ~ U[0, 1];
 *    clamped to the box. Coordinates are normalised and centred on the start,
 *    so that r3 P scales around the start (not around the DH origin).
 *  - RC_EST_QIBAS: beetle antennae search with quadratic interpolation: one
 *    beetle at the start; per iteration a random unit direction b
 *    (normalised coordinates), antennae x +- d b, the parabola through
 *    (x - d b, x, x + d b) gives the step t* = d (f_l - f_r) / (2 (f_l - 2 f + f_r))
 *    when its curvature is positive (clamped to |t*| <= step), otherwise the
 *    BAS step -step * sign(f_r - f_l) b; the best of the four points becomes x.
 *    d decays geometrically from qibas_d0 (0: 0.2) to 1e-6 over max_iter
 *    iterations (0: 2000); step = 2 d. 3 cost evaluations per iteration.
 *  - RC_EST_SSLM: variable step-size LM, our reading of the paper's ref. 19
 *    (Li, Li & Luo 2023; docs/methods.md says what is read and where it
 *    departs): the LM direction with a FIXED damping, the step size along it
 *    variable. In column-scaled variables (D = the column norms at the
 *    start, kept): (A_s + mu I) delta = -g_s, mu = sslm_mu (0: 1e-2); the
 *    step x <- x + eta delta / D with eta first tried at min(1, 2 eta_prev)
 *    (eta_0 = 1) and halved (at most 40 times) until the cost falls; that
 *    eta is kept for the next iteration. No step size lowers the cost:
 *    converged. max_iter (0: 100); stops on a relative cost decrease below
 *    tol_cost (0: 1e-10). Plain LM varies mu and always takes eta = 1.
 *
 * Depends on: rc_model, rc_solve (rc_cost, rc_normal_eq, rc_iter_cb),
 * rc_rand, rc_linalg; libm. Memory: rc_est_work is large (about
 * 2 * RC_EST_MAX_POP * RC_MAX_PARAMS + 2 * RC_MAX_PARAMS^2 doubles); the caller
 * owns it (static or heap on a host). Thread safety: reentrant; one workspace
 * per thread. Errors: RC_ERR_ARG for a bad config (population above
 * RC_EST_MAX_POP, no samples), RC_ERR_RANK when no parameter is free,
 * RC_ERR_NUMERIC when the start point cannot be evaluated.
 */
#ifndef RC_EST_H
#define RC_EST_H

#include <stddef.h>
#include <stdint.h>

#include "rc_model.h"
#include "rc_solve.h"

/* Largest population (PF particles, SCA agents). */
#ifndef RC_EST_MAX_POP
#define RC_EST_MAX_POP 256
#endif
#if RC_EST_MAX_POP < 4 || RC_EST_MAX_POP > 4096
#error "RC_EST_MAX_POP must be within 4..4096"
#endif

/* The estimators: one line each (X(ID, name)), the enum and the names
 * expanded from it. */
#define RC_EST_METHODS(X) X(EKF, "ekf") X(PF, "pf") X(SCA, "sca") X(QIBAS, "qibas") X(SSLM, "sslm")
#define RC_EST_ENUM_(id, name) RC_EST_##id,
typedef enum rc_est_method { RC_EST_METHODS(RC_EST_ENUM_) RC_EST_COUNT_ } rc_est_method;
#undef RC_EST_ENUM_

/* All-zero means the defaults listed above. */
typedef struct rc_est_config {
    rc_est_method method;
    unsigned max_iter;      /* passes / iterations; 0: per-method default */
    unsigned pop;           /* PF particles, SCA agents; 0: 100 / 30 */
    double bound_len_mm;    /* box half-width for a, d; 0: 2 mm */
    double bound_ang_rad;   /* box half-width for alpha, theta; 0: 0.2 deg */
    double bound_enc_mm;    /* box half-width for the encoder e; 0: 5 mm */
    double bound_other;     /* other effect parameters; 0: 1e-3 */
    double noise_mm;        /* EKF measurement sd; 0: resolution_mm / sqrt(12) */
    double resolution_mm;   /* encoder resolution; 0: 0.004 mm */
    double ekf_q;           /* EKF process noise per update, relative to P0; 0: 1e-9 */
    double ekf_alpha;       /* EKF forgetting factor of the adaptive R, (0, 1]; 0: 0.3; 1: R fixed */
    double qibas_d0;        /* QIBAS initial antenna length (normalised); 0: 0.2 */
    double sslm_mu;         /* SSLM fixed damping, scaled variables; 0: 1e-2 */
    double tol_cost;        /* relative cost decrease to stop (EKF, SSLM); 0: 1e-10 */
    double subset_tol;      /* identifiable-subset threshold; 0: RC_IDENT_NULL_REL^2 (1e-12, rc_ident) */
    int keep_all;           /* nonzero: no subset selection, every free parameter moves */
    uint64_t seed;
    const uint8_t *fixed;   /* (n_params) nonzero: held fixed; NULL: none */
    /* A Gaussian prior, as rc_solve_config's (prior_mean NULL or
     * prior_noise_mm <= 0: none). With it every method minimises the MAP
     * objective SSR + sum ((noise / sd_k) (x_k - mean_k))^2: no subset
     * (every free parameter moves), the population box is 3 prior sd wide
     * per side where a parameter has a prior, SSLM adds the prior rows
     * (rc_prior_normal_eq), and EKF becomes the iterated EKF from the prior
     * (run_iekf: R = noise^2 fixed, no process noise; its fixed point is the
     * MAP estimate). The figures (rms_*, the curves) stay the data's
     * residuals. */
    const double *prior_mean; /* (n_params) */
    const double *prior_sd;   /* (n_params) mm, rad or the effect's unit; <= 0: no prior on it */
    double prior_noise_mm;
    rc_iter_cb on_iter;     /* after each iteration: best training RMS so far */
    void *cb_ctx;
} rc_est_config;

typedef struct rc_est_result {
    unsigned iterations;
    unsigned cost_evals;    /* passes over the training samples (costs, Jacobians) */
    double rms_start_mm;    /* training RMS at the start */
    double rms_final_mm;    /* training RMS of the returned model */
    unsigned n_free;        /* parameters not fixed by the caller */
    unsigned n_moved;       /* parameters the method moved (identifiable subset) */
} rc_est_result;

typedef struct rc_est_work {
    double P[RC_MAX_PARAMS * RC_MAX_PARAMS];  /* (nf x nf) EKF covariance / SSLM matrix */
    double T[RC_MAX_PARAMS * RC_MAX_PARAMS];  /* (nf x nf) scratch */
    double pop[RC_EST_MAX_POP * RC_MAX_PARAMS];  /* (N x nf) population, normalised */
    double pop2[RC_EST_MAX_POP * RC_MAX_PARAMS]; /* (N x nf) PF resampling buffer */
    double fit[RC_EST_MAX_POP];               /* (N) cost of each member, mm^2 */
    double fit2[RC_EST_MAX_POP];              /* (N) scratch */
    double wgt[RC_EST_MAX_POP];               /* (N) PF weights */
    double x0[RC_MAX_PARAMS];                 /* (nf) start values of the moved parameters */
    double bound[RC_MAX_PARAMS];              /* (nf) box half-widths */
    double u[RC_MAX_PARAMS];                  /* (nf) current point, normalised */
    double ubest[RC_MAX_PARAMS];              /* (nf) best point, normalised */
    double v[RC_MAX_PARAMS];                  /* (nf) scratch */
    double g[RC_MAX_PARAMS];                  /* (nf) gradient */
    double D[RC_MAX_PARAMS];                  /* (nf) column scaling */
    double dx[RC_MAX_PARAMS];                 /* (nf) step */
    double jrow[RC_MAX_PARAMS];               /* (n_params) one Jacobian row */
    uint16_t idx[RC_MAX_PARAMS];              /* (nf) indices of the moved parameters */
    uint8_t mask[RC_MAX_PARAMS];              /* (n_params) subset mask scratch */
    rc_model trial;
    rc_model best;
} rc_est_work;

/* Short name: "ekf", "pf", "sca", "qibas", "sslm" ("unknown" otherwise). */
const char *rc_est_method_name(rc_est_method method);

/* The identifiable subset at model m on samples (n): fixed_out (m->n_params)
 * receives 1 for every parameter to hold (fixed_in's and the unidentifiable
 * ones), 0 for the kept ones; *n_kept their number. fixed_in may be NULL;
 * tol 0 means rc_ident's null bound RC_IDENT_NULL_REL^2 (1e-12). Uses w->P,
 * w->T, w->jrow, w->idx. */
rc_status rc_est_subset(uint8_t *fixed_out, unsigned *n_kept, rc_est_work *w, const rc_model *m,
                        const uint8_t *fixed_in, double tol, const rc_sample *samples, size_t n);

/* Identify the parameters of m (in: start, out: solution) from samples (n)
 * with the method of cfg. res may be NULL. */
rc_status rc_est_solve(rc_model *m, rc_est_result *res, rc_est_work *w, const rc_est_config *cfg,
                       const rc_sample *samples, size_t n);

#endif /* RC_EST_H */
