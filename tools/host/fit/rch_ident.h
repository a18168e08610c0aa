/* SPDX-License-Identifier: MIT */
/* rch_ident.h - identifiability of the model parameters from the data
 * (cable lengths, tracker positions, a table sensor's rows: rch_sensors.h).
 *
 * The problem analysed is the parameters the data's sensors see: what only
 * an absent sensor sees (rch_pos_fix_unseen: without lengths the encoder e,
 * the outlets and the attachment; without a sensor's rows its effects) is
 * held by the fit and is no part of the table (n_params counts the rest).
 * The explanations speak of the data the samples hold ("tracker positions
 * cannot see it"; a table sensor by its descriptor's words) and a known set
 * is used only when all its parameters are in the problem.
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
/* a direction gets a known reason only when this share of its squared
 * length lies on the reason's parameters (a mix of null directions gets
 * none rather than a wrong one) */
#define RCH_IDENT_WHY_SHARE 0.8

typedef struct rch_ident_dir {
    double sv_rel;       /* singular value relative to the largest */
    int weak;            /* 0: not identifiable (null), 1: weakly identifiable */
    char combo[256];     /* e.g. "+0.71 d1 -0.71 ez" */
    char why[256];       /* plain-words explanation, "" when no known pattern */
} rch_ident_dir;

#define RCH_IDENT_MAX_COMBOS 12

/* A known set of parameters whose (scaled) Jacobian columns are dependent:
 * some combination of them alone is not (or weakly) identifiable. Where
 * several null directions share one singular value the SVD's directions mix
 * these; the sets say what the null space holds. */
typedef struct rch_ident_combo {
    char params[96];     /* "d1 ez" */
    int weak;            /* 0: not identifiable, 1: weakly */
    double sv_rel;       /* smallest singular value of their columns, relative to the Jacobian's largest */
    char why[256];       /* plain words */
} rch_ident_combo;

typedef struct rch_ident {
    unsigned n_params;            /* parameters analysed (those of the problem) */
    double sv_rel[RC_MAX_PARAMS]; /* (n_params) descending */
    unsigned rank;                /* sv_rel >= RC_IDENT_NULL_REL */
    unsigned n_weak;              /* RC_IDENT_NULL_REL <= sv_rel < RC_IDENT_WEAK_REL */
    double cond;                  /* s_max / s_min over the identifiable ones */
    double observability;         /* O1 = (prod s_i)^(1/r) / sqrt(n), identifiable part */
    unsigned n_dirs;
    rch_ident_dir dirs[RCH_IDENT_MAX_DIRS];
    unsigned n_combos;
    rch_ident_combo combos[RCH_IDENT_MAX_COMBOS]; /* the known dependent sets found, smallest first; a set
                                                     holding one already found is not listed */
    rc_ident core;                /* rc_ident's classes per direction and per parameter, log det */
} rch_ident;

/* Analyse model m at its current parameters over samples (n). Returns 0, or
 * -1 when the Jacobian cannot be formed or LAPACK fails. */
int rch_ident_compute(rch_ident *out, const rc_model *m, const rc_sample *s, size_t n);

#endif
