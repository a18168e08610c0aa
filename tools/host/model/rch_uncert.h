/* SPDX-License-Identifier: MIT */
/* rch_uncert.h - uncertainty of a calibration: parameter covariance and
 * standard errors, what the data determined, the flange-position uncertainty
 * the covariance predicts, and the "determined part" of a model that
 * compensation may act on.
 *
 * Covariance. At the solution x (free parameters F, nf of them), with the
 * Jacobian J (n x nf) of the residuals r = l(q; x) - L, columns scaled to
 * unit norm (S = diag of the column norms), A = Js^T Js = V diag(ev) V^T:
 *  - directions rc_ident classes as null are NOT IDENTIFIABLE: the data carry no
 *    information on them; the pseudo-inverse A+ leaves them out and the
 *    parameters that lie in them get no standard error;
 *  - classical:     Cov = s^2 S^-1 A+ S^-1,  s^2 = r^T r / (n - rank);
 *  - cluster-robust (samples that share a set-up group are not independent):
 *    Cov = c S^-1 A+ (sum_g u_g u_g^T) A+ S^-1, u_g = Js_g^T r_g summed over
 *    the samples of group g, c = G/(G-1) (n-1)/(n-rank) (the usual small-sample
 *    factor); used when the samples carry at least 5 groups of >= 2 samples.
 * Per parameter: standard error sqrt(Cov_kk) and a class: rc_ident's class,
 * made weak also when the standard error exceeds a typical DH error.
 *
 * Host side (prefix rch_): heap and LAPACKE. */
#ifndef RCH_UNCERT_H
#define RCH_UNCERT_H

#include <stddef.h>
#include <stdint.h>

#include "rc_model.h"

typedef enum {
    RCH_PARAM_FIXED = 0,          /* held fixed by the user or the solver set-up */
    RCH_PARAM_IDENTIFIABLE = 1,
    RCH_PARAM_WEAK = 2,           /* determined only with a large standard error */
    RCH_PARAM_NOT_IDENTIFIABLE = 3
} rch_param_class;

typedef enum { RCH_COV_CLASSICAL = 0, RCH_COV_CLUSTER = 1 } rch_cov_kind;

/* Directions and parameters are classed by the one definition, lib/rc_ident.h
 * (not identifiable below a relative singular value of 1e-6, weak below
 * 1e-3, a parameter tied to a direction by a squared share of 0.01). Also
 * weak here: a standard error above a typical DH error (0.1 mm, 0.1 deg):
 * the data do not determine the parameter to the size of what it corrects. */
#define RCH_UNCERT_WEAK_MM 0.1
#define RCH_UNCERT_WEAK_RAD 1.7453292519943295e-3

typedef struct rch_uncert {
    unsigned n_params;                /* of the model */
    unsigned nf;                      /* free parameters */
    unsigned rank;                    /* directions rc_ident does not class as null */
    unsigned n_weak;                  /* of them weak */
    rch_cov_kind kind;
    unsigned n_groups;                /* clusters used (cluster-robust) */
    size_t n_samples;
    double sigma_mm;                  /* residual standard deviation s */
    double se[RC_MAX_PARAMS];         /* (n_params) standard error (mm or rad); 0 when fixed, NaN when not identifiable */
    uint8_t cls[RC_MAX_PARAMS];       /* (n_params) rch_param_class */
    double null_share[RC_MAX_PARAMS]; /* (n_params) share in not-identifiable directions, 0..1 */
    double weak_share[RC_MAX_PARAMS]; /* (n_params) share in weak directions, 0..1 */
    uint8_t comp_nominal[RC_MAX_PARAMS]; /* (n_params) 1: compensation keeps it nominal (tied to a weak or
                                            not-identifiable direction that moves the robot, or weak) */
    double *cov;                      /* (n_params x n_params) heap, row-major; rows/cols of fixed params 0 */
    int has_prior;                    /* the posterior of a MAP fit (rch_uncert_compute_map) */
    double prior_sd[RC_MAX_PARAMS];   /* (n_params) the prior's sd, 0: none */
    uint8_t prior_cls[RC_MAX_PARAMS]; /* (n_params) rch_prior_class: what the data did to the prior */
    double p_eff;                     /* effective parameters the data determined (trace of the hat matrix) */
} rch_uncert;

/* Compute the covariance at m over the training samples (n). fixed
 * (n_params, may be NULL) marks parameters held fixed. want_cluster: 1 uses
 * the cluster-robust form when the groups allow it (else classical, and kind
 * says which was used). 0, or -1 (message in err[errlen]). */
int rch_uncert_compute(rch_uncert *u, const rc_model *m, const uint8_t *fixed, const rc_sample *s, size_t n,
                       int want_cluster, char *err, size_t errlen);
/* The same with the clusters given apart from the samples' group field
 * (cl: n labels, NULL: s[i].group), for a model whose effects use the group
 * field for something else (segments of length jumps). */
int rch_uncert_compute_cl(rch_uncert *u, const rc_model *m, const uint8_t *fixed, const rc_sample *s,
                          const uint16_t *cl, size_t n, int want_cluster, char *err, size_t errlen);
/* The posterior of a maximum a posteriori fit: prior_sd (n_params; 0 or
 * NULL: no prior on that parameter) and noise_mm, the residual sd the
 * prior was weighed against (rch_calib's estimate). Every free parameter
 * gets a standard error (the prior's where the data are silent) and a
 * prior class (determined, partly, prior only); nothing is held for
 * compensation. prior_sd NULL or noise_mm <= 0: rch_uncert_compute_cl. */
int rch_uncert_compute_map(rch_uncert *u, const rc_model *m, const uint8_t *fixed, const rc_sample *s,
                           const uint16_t *cl, size_t n, int want_cluster, const double *prior_sd, double noise_mm,
                           char *err, size_t errlen);
void rch_uncert_free(rch_uncert *u);

/* The determined part of a calibration, for compensation: the fit with
 * every DH parameter the data did not determine back at its nominal value:
 * those tied to a weak or not-identifiable direction that moves the robot
 * (d1 with the encoder height, the base heading, a weak wrist combination),
 * and those whose standard error makes them weak (theta6 with a6 near 0).
 * A not-identifiable direction that moves nothing the robot does (d2 - d3 of
 * the parallel joints 2 and 3) does not hold its parameters: their
 * determined combination (d2 + d3) is kept. The encoder outlet and effects
 * are kept (they do not move the robot). */
void rch_uncert_determined(rc_model *out, const rc_model *fit, const rc_model *nominal, const rch_uncert *u);

/* 95 % uncertainty of the flange position predicted at q: the longest
 * semi-axis of the 95 % confidence ellipsoid of p(q; x),
 * sqrt(chi2_3(0.95) * lambda_max(Jp Cov Jp^T)), Jp = dp/dx by central
 * differences. Returns the figure in mm. */
double rch_uncert_pos95_mm(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ]);

/* Summary over poses: the median and the largest pos95 over the samples'
 * poses (inside the data) and over n_random poses uniform in the joint
 * limits (whole workspace, seed). */
/* The same for the flange orientation: longest semi-axis of the 95 %
 * ellipsoid of the small-rotation vector, in degrees. */
double rch_uncert_rot95_deg(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ]);
/* The same over the parameters compensation uses (not comp_nominal). */
double rch_uncert_rot95_det_deg(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ]);

typedef struct rch_uncert_map {
    double data_median_mm, data_max_mm;
    double rot_data_median_deg, rot_data_max_deg; /* orientation, over the data's poses */
    double rot_det_median_deg, rot_det_max_deg;   /* orientation of the determined model (held parameters
                                                     nominal, their uncertainty not counted) */
    double work_median_mm, work_max_mm;
    size_t n_data, n_work;
} rch_uncert_map;
int rch_uncert_map_compute(rch_uncert_map *out, const rch_uncert *u, const rc_model *m, const rc_sample *s, size_t n,
                           size_t n_random, uint64_t seed);

/* 95 % position semi-axis (mm) of a point t_mm (3, in the flange frame)
 * of m at the poses of s (n; with target >= 0 only the rows of that
 * tracker target): the flange of m without its tool offset, plus R t. With
 * t_first >= 0 t is m->x[t_first .. t_first + 2] (a tracker target, the
 * cable attachment) and its covariance counts with the rest. Values into v
 * (n); returns how many. */
size_t rch_uncert_point95(double *v, const rch_uncert *u, const rc_model *m, const rc_sample *s, size_t n,
                          const double t_mm[3], int t_first, int target);

/* Sensitivity of the point of m at q (the flange, or the tool point when m
 * carries a tool offset) to every parameter: Jp (3 x m->n_params), the DH,
 * tool offset and axis tilt columns in closed form (rc_kin), the joint-side
 * effects' by central differences of rc_fk, the encoder's, outlets' and
 * length-side effects' zero. The one definition the uncertainty figures use
 * (rch_poses plans with it). */
void rch_uncert_point_sens(double Jp[3][RC_MAX_PARAMS], const rc_model *m, const double q_rad[RC_NJ]);
/* The 95 % quantile of |e| for e ~ N(0, C), C (3 x 3, row-major,
 * symmetric): the radius rch_model_unc_radius95_mm gives (mm when C is in
 * mm^2). NaN when C is not finite. */
double rch_uncert_radius95(const double C[9]);

/* The words of a class ("identifiable", "weak", "not identifiable",
 * "fixed"). Inline so that the model-file reader needs no LAPACKE. */
static inline const char *rch_param_class_name(rch_param_class c)
{
    switch (c) {
    case RCH_PARAM_FIXED: return "fixed";
    case RCH_PARAM_IDENTIFIABLE: return "identifiable";
    case RCH_PARAM_WEAK: return "weak";
    case RCH_PARAM_NOT_IDENTIFIABLE: return "not identifiable";
    }
    return "?";
}

/* What a model file (rcal-model/2) carries of a calibration's uncertainty:
 * enough for compensation to act only on what the data determined and to
 * know where the model can be trusted. Fixed size (no heap): the covariance
 * of the 24 DH parameters only (the encoder and nuisance effects do not move
 * the robot). */
/* The determined model's orientation counts as determined when its 95 %
 * uncertainty over the data's poses (median; the parameters compensation
 * holds nominal not counted) is below this (deg). */
#define RCH_ORIENT_DETERMINED_DEG 0.05
typedef struct rch_model_unc {
    int present;                        /* the file had an "uncertainty" member */
    unsigned n;                         /* parameters described */
    rch_cov_kind kind;
    unsigned n_groups, rank;
    double sigma_mm;
    uint8_t cls[RC_MAX_PARAMS];         /* (n) rch_param_class */
    uint8_t comp_nominal[RC_MAX_PARAMS]; /* (n) 1: held nominal for compensation */
    double se[RC_MAX_PARAMS];           /* (n) SI units; NaN when none */
    double cov_dh[RC_N_DH * RC_N_DH];   /* (24 x 24) SI units (mm, rad) */
    int orientation_determined;
    rch_uncert_map map;                 /* figures over the data and the workspace */
    int has_prior;                      /* the posterior of a MAP fit: every se a number, nothing held */
    uint8_t prior_cls[RC_MAX_PARAMS];   /* (n) rch_prior_class */
    double prior_sd[RC_MAX_PARAMS];     /* (n) SI units; 0: no prior */
} rch_model_unc;

/* Fill from a computed rch_uncert (map and orientation_determined are set by
 * the caller). */
void rch_model_unc_from(rch_model_unc *out, const rch_uncert *u);
/* 95 % position uncertainty at q of the determined model (identifiable DH
 * parameters only: the others are held nominal and carry no information). */
double rch_model_unc_pos95_mm(const rch_model_unc *u, const rc_model *m, const double q_rad[RC_NJ]);
/* The radius (mm) that holds the error of the point of m at q (the flange,
 * or the TCP when m carries a tool offset) with 95 % probability under the
 * posterior covariance of the DH parameters: the 95 % quantile of |e|,
 * e ~ N(0, Jp Cov Jp^T), every parameter that has a standard error counted
 * (prior-only directions included). What `rcal compensate
 * --uncertainty-out` writes per target as u95_mm. */
double rch_model_unc_radius95_mm(const rch_model_unc *u, const rc_model *m, const double q_rad[RC_NJ]);
/* 95 % error bound (mm) of a tool point tool_mm (3, in the flange frame)
 * of the robot compensated with the determined model det
 * (rch_model_unc_determined of fit), at q: |what resetting the held
 * parameters moves the point| + the longest semi-axis of the 95 % ellipsoid
 * of every parameter with a standard error (held ones included: the fit's
 * covariance is the data's word on how far the truth may lie from the value
 * compensation keeps). Not-identifiable parameters (the base height and
 * heading, set by other means) are not counted. Wide 100 mm off the flange
 * axis when theta6 is weak (cable lengths barely see the roll about it). */
double rch_model_unc_tool95_mm(const rch_model_unc *u, const rc_model *det, const rc_model *fit,
                               const double q_rad[RC_NJ], const double tool_mm[3]);
/* Trace (rad^2) of the covariance of the flange's small-rotation vector at
 * q (with axis, 3, unit, base frame, not NULL: of its part perpendicular to
 * axis, what tilts that axis) predicted by u over the DH parameters
 * compensation moves (not held
 * nominal, not fixed, with a finite standard error) and, with
 * determined_only, not those the data left to the prior alone
 * (RCH_PRIOR_CLASS_PRIOR_ONLY: their estimate sits at the drawing's value,
 * so a correction does not move them and they weigh the same on both sides
 * of rch_comp_orient_decide). m: the determined model (a tool offset does
 * not change the rotation). NaN when u has no covariance. */
double rch_model_unc_rot_trace(const rch_model_unc *u, const rc_model *m, const double q_rad[RC_NJ],
                               int determined_only, const double *axis);
/* The determined model: fit with its weak and not-identifiable DH
 * parameters at their nominal values. */
void rch_model_unc_determined(rc_model *out, const rc_model *fit, const rc_model *nominal, const rch_model_unc *u);

#endif
