/* SPDX-License-Identifier: MIT */
/* rch_ident.h - identifiability of the model parameters from cable lengths.
 *
 * The identification Jacobian J (n samples x n_params, each column scaled to
 * unit norm so that mm and rad compare) is decomposed by SVD (LAPACKE
 * dgesvd: small singular values to high accuracy). The thresholds, the rank
 * and the figures come from rc_ident (lib/rc_ident.h), the one definition:
 * relative singular value below RC_IDENT_NULL_REL (1e-6) not identifiable,
 * below RC_IDENT_WEAK_REL (1e-3) weakly identifiable. Each such direction is
 * described with the parameters it mixes and, for the known cases, why (for
 * example "moving the robot base up is the same as moving the encoder down").
 */
#ifndef RCH_IDENT_H
#define RCH_IDENT_H

#include <stddef.h>
#include <stdint.h>

#include "rc_ident.h"
#include "rc_model.h"

#define RCH_IDENT_MAX_DIRS 24

typedef struct rch_ident_dir {
    double sv_rel;       /* singular value relative to the largest */
    int weak;            /* 0: not identifiable (null), 1: weakly identifiable */
    char combo[256];     /* e.g. "+0.71 d1 -0.71 ez" */
    char why[256];       /* plain-words explanation, "" when no known pattern */
} rch_ident_dir;

typedef struct rch_ident {
    unsigned n_params;
    double sv_rel[RC_MAX_PARAMS]; /* (n_params) descending */
    unsigned rank;                /* sv_rel >= RC_IDENT_NULL_REL */
    unsigned n_weak;              /* RC_IDENT_NULL_REL <= sv_rel < RC_IDENT_WEAK_REL */
    double cond;                  /* s_max / s_min over the identifiable ones */
    double observability;         /* O1 = (prod s_i)^(1/r) / sqrt(n), identifiable part */
    unsigned n_dirs;
    rch_ident_dir dirs[RCH_IDENT_MAX_DIRS];
    rc_ident core;                /* rc_ident's classes per direction and per parameter, log det */
} rch_ident;

/* Analyse model m at its current parameters over samples (n). Returns 0, or
 * -1 when the Jacobian cannot be formed or LAPACK fails. */
int rch_ident_compute(rch_ident *out, const rc_model *m, const rc_sample *s, size_t n);

#endif
