/* SPDX-License-Identifier: MIT */
/* rch_fkcheck.h - the nominal-FK check behind `rcal fkcheck`: the nominal FK
 * at each row's joint angles against the row's x, y, z columns.
 *
 * A row further than tol_mm is explained by the display rounding when a
 * joint change of at most RCH_FK_ROUNDING_DEG (max over the joints of the
 * minimum-norm change) reproduces the difference, else a fault.
 *
 * Depends on: the core (rc_fk, rc_fk_jac), rch_data, rch_robot, rch_stats.
 * Memory: the result's fault list on the heap (rch_fkcheck_free). Errors: 0,
 * or -1 with d set.
 */
#ifndef RCH_FKCHECK_H
#define RCH_FKCHECK_H

#include <stddef.h>

#include "rch_diag.h"

#define RCH_FK_ROUNDING_DEG 0.1
typedef struct rch_fk_fault {
    unsigned line;        /* line in the data file */
    double dist_mm;       /* |FK - xyz| */
    double dq_deg;        /* joint change that would explain it */
    double fk_mm[3], file_mm[3];
} rch_fk_fault;
typedef struct rch_fkcheck_result {
    size_t rows, faults, rounding;
    double rms_mm, max_mm, max_consistent_mm;
    rch_fk_fault *fault;      /* (faults) on the heap: rch_fkcheck_free */
    char robot_name[128];
} rch_fkcheck_result;

/* 0, or -1 with d set (unreadable files, no x, y, z columns, no memory). */
int rch_fkcheck_run(rch_fkcheck_result *r, const char *data_path, const char *robot_path, double tol_mm,
                    rch_diag *d);
void rch_fkcheck_free(rch_fkcheck_result *r);

#endif
