/* SPDX-License-Identifier: MIT */
/* rch_stats.h - summary statistics of a series of errors: the one definition
 * of RMSE, mean |e|, SD, mean and max used by the reports.
 *
 * Accumulate values one at a time (rch_stats_add) or take an array
 * (rch_stats_of); read the figures from the accumulator. The sum of squares is
 * accumulated in input order (RMSE = sqrt(sum e^2 / n), bit for bit what a
 * plain loop gives), the mean and SD with Welford's update (SD with n - 1 in
 * the denominator, 0 for fewer than two values). These are the same
 * definitions as the core's rc_metrics (rc_eval), which computes them for the
 * cable-length residuals of a model; rch_stats_metrics converts.
 *
 * Host side (prefix rch_): no heap, no I/O. An all-zero rch_stats is empty.
 */
#ifndef RCH_STATS_H
#define RCH_STATS_H

#include <stddef.h>

#include "rc_solve.h"

typedef struct rch_stats {
    size_t n;
    double sum_sq;  /* sum e^2 */
    double sum_abs; /* sum |e| */
    double mean;    /* running mean (Welford) */
    double m2;      /* running sum of squared deviations (Welford) */
    double max_abs; /* max |e| */
} rch_stats;

void rch_stats_add(rch_stats *s, double e);
/* s reset, then every v[i] (n) added. */
void rch_stats_of(rch_stats *s, const double *v, size_t n);

double rch_stats_rms(const rch_stats *s);      /* sqrt(sum e^2 / n); 0 when empty */
double rch_stats_mean_abs(const rch_stats *s); /* mean |e|; 0 when empty */
double rch_stats_sd(const rch_stats *s);       /* standard deviation, n - 1; 0 below two values */
/* The standard error of a standard deviation sd estimated with dof degrees
 * of freedom (chi-square: sd / sqrt(2 dof)); NAN when dof <= 0. */
double rch_sd_se(double sd, double dof);

/* The same figures in the core's rc_metrics (rmse, mean |e|, SD, mean, max). */
void rch_stats_metrics(rc_metrics *out, const rch_stats *s);

/* RMS of v (n): sqrt(sum v^2 / n), 0 for n = 0. */
double rch_rms(const double *v, size_t n);

/* Median (mean of the two middle values for even n) and maximum of v (n
 * finite values, reordered): an O(n) selection (Hoare's FIND), the very
 * values a sort gives. Both NaN for n = 0. */
void rch_median_max(double *med, double *max, double *v, size_t n);
/* The robust standard deviation of v (n finite values, reordered): 1.4826
 * x the median absolute deviation from the median (the standard deviation
 * for Gaussian values, not inflated by a few far ones). 0 for n = 0. */
double rch_mad_sd(double *v, size_t n);

/* The p quantile (0..1) of v (n finite values, sorted in place), linear
 * between order statistics (numpy's default): NaN for n = 0. */
double rch_quantile(double *v, size_t n, double p);

/* Upper tail P(F > f) of the F(d1, d2) distribution: 1 for f <= 0 or any
 * argument NaN or not positive, 0 for f = +inf; never a misleading value
 * down to 1e-290 (test diag_fdist_gsl: within 1e-9 of GSL, relative). */
double rch_f_sf(double f, double d1, double d2);

/* The f with P(F(d1, d2) > f) = p (0 < p < 1): rch_f_sf inverted by
 * bisection in log f (relative 1e-13). NaN for arguments out of range. */
double rch_f_isf(double p, double d1, double d2);

/* What the 95 % region of a three-dimensional estimate needs when its
 * covariance is itself estimated with nu degrees of freedom (a
 * cluster-robust covariance from G groups: nu = G - 1): Hotelling's T^2
 * quantile 3 nu / (nu - 2) F95(3, nu - 2) over the chi2(3) quantile of a
 * known covariance. 1 for nu = +inf; 1.563 at nu = 14, 1.127 at 47, 1.018
 * at 299; INFINITY for nu < 4 (or NaN). */
double rch_t2_ratio95_3d(double nu);

#endif
