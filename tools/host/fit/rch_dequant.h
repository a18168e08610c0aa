/* SPDX-License-Identifier: MIT */
/* rch_dequant.h - recover joint angles rounded for the file from the
 * controller's reported flange position.
 *
 * Files such as the RobotCali set record q rounded to 0.1 deg but x, y, z
 * computed by the controller from the unrounded angles (its nominal forward
 * kinematics). The rounding alone costs about 0.27 mm of cable length at the
 * IRB120's reach. For each row the smallest joint change dq (least norm,
 * Gauss-Newton on the nominal FK, 3 equations in 6 unknowns) that makes the
 * nominal FK reproduce x, y, z is applied, when it stays inside the rounding
 * interval (every |dq_j| <= max_dq_rad, the half step plus what the 0.05 mm
 * rounding of x, y, z explains). A row needing more is inconsistent (a typo
 * in x, y, z, or a row whose angles were not those of the position): it is
 * refused, not corrected. The lengths are never used.
 *
 * Host side (prefix rch_). */
#ifndef RCH_DEQUANT_H
#define RCH_DEQUANT_H

#include <stddef.h>
#include <stdint.h>

#include "rc_model.h"

typedef struct rch_dequant_result {
    size_t n_rows;
    size_t n_corrected;
    size_t n_refused;
    double dq_rms_deg;     /* RMS of the applied corrections */
    double dq_max_deg;     /* largest applied |dq_j| */
    double fk_rms_before_mm, fk_rms_after_mm; /* |FK(q) - xyz| over the corrected rows */
    int automatic;         /* 1: decided from the file (rch_inputs: no --dequantize-joints given) */
    double q_step_deg;     /* the joints' display step found (rch_dequant_detect_step; 0: none) */
    char why[200];         /* what the automatic decision saw (applied or not); empty when forced */
} rch_dequant_result;

/* s (n): joint angles corrected in place; xyz (n x 3); nominal: the
 * controller's model; max_dq_rad: 0 means 0.06 deg (half of a 0.1 deg step
 * plus 20 %). refused (n, output, may be NULL): 1 for inconsistent rows
 * (their angles are left as they were). Returns 0, -1 on bad arguments. */
int rch_dequant(rch_dequant_result *res, uint8_t *refused, rc_sample *s, size_t n, const double (*xyz)[3],
                const rc_model *nominal, double max_dq_rad);

/* Coarsest display step of a fixed list (1, 0.5, 0.2, 0.1, ... 1e-4) that
 * every value sits on (within 1e-6 of a step); 0 when none fits. values: (n). */
double rch_dequant_detect_step(const double *values, size_t n);

#endif
