/* SPDX-License-Identifier: MIT */
/* rch_prior_scale.h - the prior's scale estimated from the data (empirical
 * Bayes, type-II maximum likelihood; prefix rch_prior_scale_).
 *
 * The physical prior's standard deviations (rch_prior.h: 0.5 mm, 0.1 deg,
 * 1 deg) are a statement about robots in general; a given robot may be
 * built looser. What this robot's data determine tells how far its
 * parameters really are from the drawing: for each type t (link lengths,
 * twists, joint zeros) the factor c_t on the stated sd that maximises the
 * marginal likelihood of the data (the evidence, parameters integrated out
 * in the linearised model at the MAP fit). MacKay's fixed point:
 *
 *   c_t^2 = sum_{k in t} (x_k - mu_k)^2 / sd_k^2  /  gamma_t,
 *   gamma_t = sum_{k in t} (1 - Sigma_kk / (c_t sd_k)^2),
 *
 * with Sigma = (J^T J / s^2 + P(c))^-1 and x the MAP under P(c), predicted
 * from the fit under the stated prior by one exact step of the linearised
 * problem (no refit inside the loop). gamma_t counts the parameters of the
 * type the data determine; below 2 the data say too little of the type's
 * spread and the stated sd is kept (said as the fallback). The estimate's
 * relative standard error is 1 / sqrt(2 gamma_t) (the spread of a variance
 * estimated from gamma_t values).
 *
 * Decisions: the factor is kept within [1, RCH_PRIOR_SCALE_MAX]: never
 * narrower than the stated tolerance (a robot whose determined parameters
 * sit near the drawing does not make the undetermined ones better known),
 * never wider than 10 x (a prior of 5 mm, 1 deg twists, 10 deg zeros would
 * no longer be physical). Only the DH types scale; the attachment, effects
 * and sensors keep theirs. The estimate itself (factor_fit) may narrow the
 * joint zeros down to RCH_PRIOR_SCALE_MIN_FIT x: a zero the data barely see
 * (theta6 behind a cable at the flange centre, seen only through a6's few
 * tenths of a millimetre) is then drawn toward the drawing as far as the
 * determined zeros are, instead of wandering a degree on noise and turning
 * a tool point 50 mm off the axis by 0.9 mm; its uncertainty keeps the
 * stated sd (factor). Measured (tests/system/sim/truth_study.py, 32 robots, TCP
 * 50, 0, 150): TCP median 0.31 -> 0.22 mm, the most targets a robot made
 * worse 34 % -> 5 %; narrowing the uncertainty too, or the lengths and
 * twists, lost coverage (robots below 75 %: 1 -> 5 of 32 under wide errors).
 *
 * The u95 figures read an estimated scale as what it is: with the scale
 * from gamma_t values, an undetermined parameter of the type is Student-t
 * about the drawing, with gamma_t degrees of freedom but at most
 * RCH_PRIOR_SCALE_TAIL_DOF (3), so the prior enters the posterior's 95 %
 * figures widened by t_{min(gamma_t, 3), 0.975} / 1.96
 * (rch_prior_scale_predictive: 1.62; 1.42 at gamma 4); the fit itself uses
 * the estimated sd. Decision (measured, tests/system/sim/truth_study.py --errors
 * wide, builds Student-t(3) about the drawing): a sample variance from 5-10
 * values of a heavy-tailed spread falls short of the true one on many
 * robots, and t_gamma alone left 5 of 16 off-centre robots below 75 %
 * coverage of the flange (pooled 0.78); at most 3 degrees of freedom: 1 of
 * 16 (pooled 0.98; 4 degrees: 2 of 16, 0.94). A robot whose spread is
 * within the stated sd keeps the stated Gaussian (factor 1: no widening).
 *
 * Depends on: rc_model, rc_solve (rc_normal_eq), rch_stats (the F
 * distribution), LAPACKE. Memory: heap
 * scratch inside the call, freed before it returns. Errors: -1 with a
 * message on a degenerate problem or out of memory.
 */
#ifndef RCH_PRIOR_SCALE_H
#define RCH_PRIOR_SCALE_H

#include <stddef.h>
#include <stdint.h>

#include "rc_model.h"

#define RCH_PRIOR_SCALE_MAX 10.0
#define RCH_PRIOR_SCALE_MIN_GAMMA 2.0
#define RCH_PRIOR_SCALE_MIN_FIT 0.2 /* the joint zeros' estimate: at most 5 x narrower than stated */
#define RCH_PRIOR_SCALE_TAIL_DOF 3.0 /* the predictive's degrees of freedom at most: heavy-tailed builds */

typedef enum { RCH_PS_LENGTH = 0, RCH_PS_TWIST = 1, RCH_PS_OFFSET = 2, RCH_PS_TYPES = 3 } rch_ps_type;

typedef struct rch_prior_scale {
    double factor[RCH_PS_TYPES];    /* the factor the uncertainty applies on the stated sd (within [1,
                                       RCH_PRIOR_SCALE_MAX]) */
    double factor_fit[RCH_PS_TYPES]; /* the factor the estimate applies: factor, except the joint zeros' down to
                                        RCH_PRIOR_SCALE_MIN_FIT */
    double factor_ml[RCH_PS_TYPES]; /* the type-II ML factor before the bounds */
    double rel_se[RCH_PS_TYPES];    /* relative standard error of the factor, 1 / sqrt(2 gamma) */
    double gamma[RCH_PS_TYPES];     /* parameters of the type the data determine */
    unsigned n[RCH_PS_TYPES];       /* free parameters of the type with a prior */
    int fallback[RCH_PS_TYPES];     /* 1: gamma below RCH_PRIOR_SCALE_MIN_GAMMA: the stated sd kept */
    unsigned iterations;
    int converged;
} rch_prior_scale;

/* The type of DH parameter k (a, d: length; alpha: twist; theta: zero), or
 * -1 for every other parameter. */
int rch_prior_scale_type(unsigned k);

/* Estimate the factors on the stated prior (mean, sd: n_params, sd 0 = no
 * prior) at m, the MAP fit under the prior (mean, sd_fit: n_params, NULL =
 * sd; another scale of the same prior, as when the attachment is decided at
 * an estimated scale) with the noise noise_mm weighing the data, over the
 * samples s (n); fixed (n_params, may be NULL) marks held parameters. 0, or
 * -1 (message in err). */
int rch_prior_scale_estimate(rch_prior_scale *out, const rc_model *m, const double *mean, const double *sd,
                             const double *sd_fit, const uint8_t *fixed, const rc_sample *s, size_t n,
                             double noise_mm, char *err, size_t errlen);

/* sd_out (n_params) = sd scaled by the factors (DH types only): the
 * uncertainty's (factor). */
void rch_prior_scale_apply(double *sd_out, const double *sd, unsigned n_params, const rch_prior_scale *ps);

/* The same with the estimate's factors (factor_fit). */
void rch_prior_scale_apply_fit(double *sd_out, const double *sd, unsigned n_params, const rch_prior_scale *ps);

/* The predictive width of a type whose scale was estimated (factor above
 * 1, no fallback): a parameter the data do not see is then Student-t with
 * min(gamma, RCH_PRIOR_SCALE_TAIL_DOF) degrees of freedom about the prior
 * mean, not Gaussian (the scale itself comes from gamma values of a
 * heavy-tailed spread); its 95 % interval is t_{nu, 0.975} / 1.96 times the
 * Gaussian one. 1 for a type kept at its stated sd. */
double rch_prior_scale_predictive(const rch_prior_scale *ps, int type);

/* sd_out (n_params) = sd times the predictive width of each DH type: the
 * prior as the posterior's 95 % figures (u95) read it; sd_out may be sd. */
void rch_prior_scale_apply_predictive(double *sd_out, const double *sd, unsigned n_params,
                                      const rch_prior_scale *ps);

#endif
