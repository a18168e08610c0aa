/* SPDX-License-Identifier: MIT */
/* rch_evaluate.h - a calibrated model on data the fit never saw.
 *
 * No refit of the robot: the model predicts every cable length of the new
 * file. The encoder outlet may be refitted alone (a new set-up places the
 * encoder anew; it does not move the robot), and the result says so. With
 * repeated poses (rows with the same joint angles) the file also gives the
 * ISO 9283 distance characteristics, read for a cable encoder: the
 * "commanded distance" of a pose is the cable length the model predicts, the
 * attained distances are the repeated readings:
 *   AD = |mean(L_j) - l_model|   (distance accuracy, per repeated pose)
 *   RD = 3 sqrt(sum (L_j - mean L)^2 / (m - 1))   (distance repeatability)
 * reported as the mean and the largest over the repeated poses.
 *
 * Host side (prefix rch_). */
#ifndef RCH_EVALUATE_H
#define RCH_EVALUATE_H

#include <stddef.h>

#include "rc_solve.h"

typedef struct rch_evaluate_config {
    int refit_encoder;     /* 1: refit the encoder outlet alone first */
    double same_pose_deg;  /* rows within this of each other in every joint are one pose; 0: 1e-6 */
} rch_evaluate_config;

typedef struct rch_evaluate_result {
    rc_metrics m;              /* residuals e = l_model - L over all rows */
    int encoder_refitted;
    double encoder_mm[3];      /* outlet used */
    double encoder_shift_mm;   /* |refitted - model's| */
    size_t n_poses;            /* distinct poses */
    size_t n_repeated;         /* poses read at least twice */
    double ad_mean_mm, ad_max_mm; /* ISO 9283 distance accuracy over repeated poses */
    double rd_mean_mm, rd_max_mm; /* ISO 9283 distance repeatability over repeated poses */
} rch_evaluate_result;

/* Evaluate model m on samples s (n). w is needed only with refit_encoder.
 * 0, or -1 with err set. */
int rch_evaluate(rch_evaluate_result *out, const rc_model *m, const rc_sample *s, size_t n,
                 const rch_evaluate_config *cfg, rc_solve_work *w, char *err, size_t errlen);

#endif
