/* SPDX-License-Identifier: MIT */
/* rch_poses_int.h - what the pose planner's files share (rch_poses.c,
 * rch_poses_length.c, rch_poses_position.c, rch_poses_outlets.c); internal
 * to the planner, not part of the host library's API (rch_poses.h is).
 * Depends on: rch_poses.h. Memory and errors: as rch_poses.h (heap, -1 with
 * d set). */
#ifndef RCH_POSES_INT_H
#define RCH_POSES_INT_H

#include <stddef.h>
#include <stdio.h>

#include "rch_poses.h"

#define PI_ 3.14159265358979323846

/* The estimate printed (over 10 s) and checked against the limit before the
 * work starts: 0, or -1 with d set (above --max-minutes). length: the length
 * criterion's cost model (rch_poses_estimate). */
int rch_poses_plan_cost(const rch_poses_config *c, FILE *progress, size_t n, size_t n_cand, unsigned nf, int length,
                        rch_diag *d);
/* The checks both criteria share (count, candidates, length range, margin
 * inside every joint's limits); *n_cand the candidates to draw. 0 or -1. */
int rch_poses_check_config(const rc_model *m, const rch_poses_config *c, size_t *n_cand, rch_diag *d);
/* C = M^-1 (M symmetric positive definite, nf x nf; LAPACK's Cholesky). 0 or -1. */
int rch_poses_spd_inverse(double *C, const double *M, unsigned nf);
/* The point a plan is judged at (the flange, a tool or a probe) and its free parameters: the workspace's
 * information and the predicted accuracy of both criteria and of the touch plan. */
typedef struct rch_poses_point {
    const rc_model *m;  /* the joint limits of the workspace poses */
    const rc_model *mp; /* the point's model (rch_uncert_point_sens) */
    unsigned nf;        /* free parameters */
    const int *col;     /* (nf) the column of rch_uncert_point_sens of each, -1: it does not move the point */
    const double *sc;   /* (nf) their scale (prior sd) */
} rch_poses_point;
/* Q = mean over n workspace poses (uniform in the joint limits, seed) of Jps^T Jps, Jps the point's
 * sensitivity to the scaled free parameters; Q (nf x nf). */
void rch_poses_workspace_q(double *Q, const rch_poses_point *pt, size_t n, unsigned long long seed);
/* The predicted accuracy of a design of information M (nf x nf): the 95 % radius at n_eval workspace poses
 * (their own seed). 0 or -1 (M not positive definite, out of memory). */
int rch_poses_point_accuracy(rch_poses_accuracy *acc, const rch_poses_point *pt, const double *M, size_t n_eval,
                             unsigned long long seed);
/* The prior's information in scaled coordinates: M (nf x nf) = the identity. */
void rch_poses_prior_info(double *M, unsigned nf);
/* The I-optimal criterion's state: C = M^-1, B = C Q C (T scratch; all nf x nf). 0 or -1 (M not positive
 * definite). */
int rch_poses_refresh(double *C, double *B, double *T, const double *M, const double *Q, unsigned nf);
/* A += w x x^T, A (r x r) row-major, x (r). */
void rch_poses_add_outer(double *A, const double *x, double w, unsigned r);
/* A progress line "rcal poses: WHAT k+1/n" at every tenth of n (n >= 10; f NULL: none). */
void rch_poses_progress(FILE *f, const char *what, size_t k, size_t n);

/* The two criteria (rch_poses_plan picks one; res zeroed by the caller). */
int rch_poses_plan_length(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                          rch_diag *d);
int rch_poses_plan_position(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                            rch_diag *d);

#endif
