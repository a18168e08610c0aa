/* SPDX-License-Identifier: MIT */
/* rc_linalg.h - small dense linear algebra for the core (prefix rcu_).
 *
 * Symmetric matrices are stored full, row-major, with leading dimension n.
 * No heap: callers pass every buffer. Sizes are bounded by RC_MAX_PARAMS.
 */
#ifndef RC_LINALG_H
#define RC_LINALG_H

#include "rc_status.h"

/* In-place Cholesky factorisation A = L L^T (lower triangle of A receives L)
 * and solution of A x = b into b. A: (n x n). b: (n). RC_ERR_NUMERIC when A is
 * not positive definite. */
rc_status rcu_chol_solve(double *A, double *b, unsigned n);

/* Eigen-decomposition of a symmetric matrix: Householder reduction to
 * tridiagonal form, then implicit QL iterations (the EISPACK tred2/tql2
 * algorithm). A: (n x n), destroyed. V: (n x n), column k the eigenvector of
 * eval[k]. eval: (n), sorted descending. RC_ERR_NOCONV when one eigenvalue
 * needs more than max_iter QL iterations (0 means 60). */
rc_status rcu_eig_sym(double *eval, double *V, double *A, unsigned n, unsigned max_iter);

/* The same by cyclic Jacobi rotations (slower, small eigenvalues to high
 * relative accuracy); kept as the reference the tests compare against.
 * max_sweeps 0 means 60. */
rc_status rcu_eig_sym_jacobi(double *eval, double *V, double *A, unsigned n, unsigned max_sweeps);

/* Largest eigenvalue of a symmetric 3 x 3 matrix A (row-major, the upper
 * triangle is read) in closed form (O. K. Smith, CACM 4(4), 1961: the
 * eigenvalues of B = (A - q I) / p are 2 cos(phi + 2 pi k / 3) with
 * cos(3 phi) = det(B) / 2): no iteration. Accurate to about 1e-12 of the
 * largest magnitude, and to about 1e-8 when the two largest eigenvalues
 * coincide (acos near -1 halves the digits): enough for a 95 % ellipsoid's
 * longest semi-axis, not for eigenvectors. NaN for a matrix that is not
 * finite. */
double rcu_sym3_eig_max(const double A[9]);

#endif /* RC_LINALG_H */
