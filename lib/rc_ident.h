/* SPDX-License-Identifier: MIT */
/* rc_ident.h - what the data can identify: the one definition (prefix rc_ident_).
 *
 * Given n model parameters and the data, the question "which parameters, and
 * which combinations of them, do the cable lengths determine?" is answered
 * from the singular values of the column-scaled identification Jacobian
 * J D^-1 (D = diag of the column norms, so that mm and rad compare), or
 * equivalently from the eigenvalues of the scaled normal matrix
 * D^-1 J^T J D^-1 (singular value = sqrt(eigenvalue)). Everything that
 * classifies identifiability in the project goes through this module and its
 * thresholds; nothing else compares a singular value or an eigenvalue with a
 * constant of its own.
 *
 * Thresholds (relative singular value s_k / s_max of the scaled Jacobian):
 *   s_k / s_max <  RC_IDENT_NULL_REL (1e-6)          not identifiable (null)
 *   RC_IDENT_NULL_REL <= s_k / s_max < RC_IDENT_WEAK_REL (1e-3)   weak
 *   s_k / s_max >= RC_IDENT_WEAK_REL                 identifiable
 * In eigenvalues of the scaled normal matrix the same bounds are the squares:
 * lambda_k / lambda_max below 1e-12 is null, below 1e-6 weak. The rank is the
 * number of directions that are not null (weak ones count towards the rank).
 * A column whose norm is at most RC_IDENT_ZERO_COL (1e-12) times the largest
 * column norm (diagonal of J^T J at most 1e-24 times the largest: alpha6 and
 * rounding-level columns) is treated as exactly zero, so it is never
 * identifiable and never spoils the scaling.
 *
 * A parameter's class is the worst class of the directions it takes part in:
 * with V the unit directions (eigenvectors), parameter i is not identifiable
 * when its share sum_{k null} V[i][k]^2 is at least RC_IDENT_SHARE (0.01, a
 * component of 0.1), weak when the share over the null and weak directions is
 * at least RC_IDENT_SHARE, identifiable otherwise.
 *
 * Figures for pose planning: log_det = sum over the rank of log(s_k^2) (the
 * D-optimality criterion of the scaled information matrix, restricted to what
 * is identifiable) and the observability index O1 = (prod_{k<rank} s_k)^(1/rank)
 * / sqrt(n_rows) (Borm and Menq), the figure `rcal calibrate` reports.
 *
 * Storage: matrices full, row-major, leading dimension n. V (n x n) holds
 * direction k in column k, V[i * n + k]. No heap, no stdio, no globals; the
 * caller owns every buffer. Thread-safe for distinct buffers. Errors are
 * rc_status codes; contract violations go to RC_ASSERT.
 */
#ifndef RC_IDENT_H
#define RC_IDENT_H

#include <stddef.h>
#include <stdint.h>

#include "rc_config.h"
#include "rc_status.h"

#define RC_IDENT_NULL_REL 1e-6 /* relative singular value below which a direction is null */
#define RC_IDENT_WEAK_REL 1e-3 /* relative singular value below which a direction is weak */
#define RC_IDENT_ZERO_COL 1e-12 /* relative column norm at or below which a column is zero */
#define RC_IDENT_SHARE 0.01     /* squared component that ties a parameter to a direction */

/* Class of a direction or a parameter, in the words of the identifiability
 * report. Ordered: a larger value is worse. */
typedef enum rc_ident_class {
    RC_IDENT_IDENTIFIABLE = 0,
    RC_IDENT_WEAK = 1,
    RC_IDENT_NONE = 2 /* not identifiable */
} rc_ident_class;

/* Result of one analysis. Direction k is column k of the caller's V. */
typedef struct rc_ident {
    unsigned n;                          /* parameters analysed */
    unsigned rank;                       /* directions with s_k/s_max >= RC_IDENT_NULL_REL */
    unsigned n_weak;                     /* of those, below RC_IDENT_WEAK_REL */
    unsigned n_null;                     /* n - rank */
    double sv_rel[RC_MAX_PARAMS];        /* (n) s_k / s_max, descending; 0 when s_max is 0 */
    uint8_t dir_class[RC_MAX_PARAMS];    /* (n) rc_ident_class of direction k */
    uint8_t param_class[RC_MAX_PARAMS];  /* (n) rc_ident_class of parameter i */
    double cond;                         /* s_max / s_{rank-1}; 0 when rank is 0 */
    double log_det;                      /* sum_{k<rank} log(s_k^2), scaled information */
    double observability;                /* O1 = (prod_{k<rank} s_k)^(1/rank) / sqrt(n_rows) */
} rc_ident;

/* Words of a class: "identifiable", "weak", "not identifiable". Never NULL. */
const char *rc_ident_class_str(rc_ident_class c);

/* Doubles of scratch rc_ident_normal needs for n parameters: n*n + n. */
size_t rc_ident_work_size(unsigned n);

/* Column scales, the one rule: D (n) = sqrt(col_sq) from the squared column
 * norms col_sq[i * stride] (stride 1 for a vector, n + 1 for the diagonal of
 * J^T J stored (n x n)), 0 for a zero column (col_sq at or
 * below RC_IDENT_ZERO_COL^2 times the largest, or not positive). A caller
 * divides column i by D_i when D_i > 0 and sets it to zero otherwise. */
void rc_ident_scale(double *D, const double *col_sq, unsigned n, size_t stride);

/* Classify from a decomposition already made: sv (n) the singular values of
 * the column-scaled Jacobian in descending order (absolute, not relative;
 * zero beyond the number of rows), V (n x n) the matching unit directions in
 * columns, n_rows the number of Jacobian rows (samples) behind them.
 * RC_ERR_ARG for n outside 1..RC_MAX_PARAMS; RC_ERR_NUMERIC for a non-finite
 * or negative singular value. */
rc_status rc_ident_classify(rc_ident *out, const double *sv, const double *V, unsigned n, size_t n_rows);

/* The same from an eigen-decomposition of the column-scaled normal matrix
 * (what a solver already has): ev (n) descending, V (n x n) eigenvectors in
 * columns; s_k = sqrt(ev_k), a negative rounding-level ev_k counts as 0.
 * RC_ERR_NUMERIC for a non-finite eigenvalue. */
rc_status rc_ident_classify_eig(rc_ident *out, const double *ev, const double *V, unsigned n, size_t n_rows);

/* The null test of the rule on one eigenvalue ev of the column-scaled
 * normal matrix beside its largest ev_max: 1 when sqrt(ev) / sqrt(ev_max) <
 * RC_IDENT_NULL_REL (the relative singular value; in eigenvalues the bound
 * is RC_IDENT_NULL_REL^2 = 1e-12 of the largest), or when ev_max is not
 * positive. A negative rounding-level ev counts as 0. rc_ident_classify_eig
 * decides with this test, and so does every solver that truncates to the
 * identifiable subspace (rc_solve's LM), so the two can never disagree. */
int rc_ident_eig_is_null(double ev, double ev_max);

/* Analyse a normal matrix: AtA (n x n) = J^T J of n parameters over n_rows
 * rows, unscaled. Scales it by its diagonal (zero columns as documented
 * above), decomposes it (rcu_eig_sym), and classifies. Outputs: out, V (n x n)
 * the directions in scaled coordinates, column k for sv_rel[k]. work: at least
 * rc_ident_work_size(n) doubles. RC_ERR_NOCONV when the eigen-solver fails,
 * RC_ERR_NUMERIC for a non-finite matrix. */
rc_status rc_ident_normal(rc_ident *out, double *V, double *work, const double *AtA, unsigned n, size_t n_rows);

#endif /* RC_IDENT_H */
