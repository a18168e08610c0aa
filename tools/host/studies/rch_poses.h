/* SPDX-License-Identifier: MIT */
/* rch_poses.h - planning an identifiable pose set (`rcal poses`).
 *
 * Method (D-optimal design, greedy start + Fedorov exchange):
 *  1. draw `candidates` random poses uniformly inside the joint limits (less
 *     margin_deg, at 0.01 deg steps) whose nominal cable length lies in
 *     [len_min_mm, len_max_mm], the range the encoder reaches;
 *  2. one row per candidate of the identification Jacobian d l / d x (rc_meas,
 *     nominal model with the encoder position), each column scaled by its
 *     RMS over the candidates so that mm and rad compare;
 *  3. keep what the candidates can identify (lib/rc_ident, the project's one
 *     definition): the eigen-directions of the column-scaled information
 *     matrix that are not null (rank r; alpha6, the base heading/height vs
 *     the encoder, d2 vs d3 ... drop out); each candidate's scaled row is
 *     expressed in those r directions;
 *  4. maximise log det(X_S^T X_S) over N poses (X: the rows of step 3): greedy additions (each adds the
 *     candidate with the largest x^T A^-1 x), then exchange passes that swap a
 *     chosen pose for a candidate while the determinant grows.
 * The plan is reported with the observability index O1 of rch_ident beside
 * that of N random poses from the same candidates. Collisions of the cable
 * with the arm are not modelled: review the plan before running it.
 *
 * Cost: grows as N^2 (one core: 100 poses 0.2 s, 300 poses 2 s, 1000 poses
 * 25 s), memory
 * candidates x n_params doubles; hence the limits below, named in the error.
 * Host side (prefix rch_): heap; progress lines on a caller-given stream.
 */
#ifndef RCH_POSES_H
#define RCH_POSES_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_diag.h"

#define RCH_POSES_MAX_COUNT 1000u        /* poses per plan */
#define RCH_POSES_MAX_CANDIDATES 200000u /* candidate poses */

typedef struct rch_poses_config {
    size_t count;              /* N, 1..RCH_POSES_MAX_COUNT */
    size_t candidates;         /* 0: max(2000, 40 N); else N..RCH_POSES_MAX_CANDIDATES */
    unsigned long passes;      /* exchange passes (4 in rcal poses) */
    unsigned long long seed;
    double len_min_mm, len_max_mm; /* cable length range, min < max */
    double margin_deg;             /* kept from every joint limit, >= 0 */
} rch_poses_config;

typedef struct rch_poses_result {
    rc_sample *poses;          /* (n) the plan, q at 0.01 deg steps; rch_poses_free */
    size_t n;
    size_t n_candidates;
    unsigned n_ident;          /* identifiable directions (rc_ident rank of the candidates) */
    unsigned n_params;
    double o1_plan, o1_random; /* observability O1 (rch_ident) of the plan and of N random candidates */
    unsigned rank_plan, rank_random;
} rch_poses_result;

/* Plan poses for model m (with its encoder position set). progress: a
 * stream for progress lines when the plan takes more than a few seconds
 * (NULL: silent). 0, or -1 with d set (limits, empty joint range, length
 * range the candidates cannot reach, out of memory). */
int rch_poses_plan(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                   rch_diag *d);
void rch_poses_free(rch_poses_result *res);

#endif
