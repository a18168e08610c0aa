/* SPDX-License-Identifier: MIT */
/* rch_diagnose_score.c - the score (Lagrange multiplier) test of one
 * candidate effect at the current model's solution, robust to the samples of
 * one pose sharing their errors (cluster-robust by pose).
 *
 * The held-out gain of a candidate pays for the variance of its fitted
 * parameters, so an effect that is real but small against the noise shows a
 * negative gain while the training fit plainly wants it (issue 31: gear
 * errors on joint 3 moved the flange 3x more than geometry alone left, with
 * a held-out z near 0). The score test asks the training data directly
 * whether the candidate's directions, with the current parameters' own
 * directions projected out, correlate with the residuals:
 *   Z = (I - Jb Jb^+) Jc U       (n x q) the candidate's identifiable
 *                                 directions, U the top q eigenvectors of
 *                                 Zc^T Zc (q: the rank the candidate adds)
 *   s = sum_g Z_g^T r_g        the score, r the current model's residuals
 *   u_g = Z_g^T (I - H_gg)^-1 r1_g   per pose, r1 the residuals with the
 *                               candidate fitted (its own signal removed),
 *                               H_gg the pose's leverage in the tested
 *                               directions (CR3: as if the pose were left out)
 *   T = s^T (c sum_g u_g u_g^T)^-1 s,  c = (G-1)/G (n-1)/(n-K)
 *                               (K: the current model's fitted directions)
 *   F = T (G - q) / (q (G - 1))  ~  F(q, G - q)  under "no such effect"
 * r: the training residuals of the current model, J: their Jacobian at it
 * with the candidate's parameters at zero (where it predicts as the current
 * model), G: the poses. The covariance from per-pose scores makes the test
 * valid when the rows of a pose share a joint-rounding error or a tracker's
 * per-station error, and when noise differs between sensors. Read from r1
 * (the Wald form of the same test) it keeps its power under the
 * alternative: from r it would grow with the effect itself and bound T by G
 * (36 tracker poses: p >= 1e-4 however large the effect).
 * Depends on: the core (rc_meas), LAPACKE (dgelsd, dsyev, dposv), rch_stats.
 * Memory: allocates its scratch and frees it. */
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose_int.h"
#include "rch_stats.h"

/* Free parameters of m0 in column order: the base's free ones first (nbf),
 * then every candidate parameter. */
static unsigned free_columns(unsigned *col, unsigned *nbf, const rc_model *m0, unsigned nb, const ctx *c)
{
    unsigned k = 0;
    for (unsigned j = 0; j < nb; ++j)
        if (!(c->have_fixed && c->fixed0[j]))
            col[k++] = j;
    *nbf = k;
    for (unsigned j = nb; j < m0->n_params; ++j)
        col[k++] = j;
    return k;
}

#define MAX_POSE_ROWS 48 /* rows of one pose corrected for leverage (16 tracker targets) */

/* Solve A x = b in place (m x m row-major, partial pivoting). 0, or -1 when singular. */
static int solve_small(double *A, double *b, size_t m)
{
    for (size_t k = 0; k < m; ++k) {
        size_t piv = k;
        for (size_t i = k + 1; i < m; ++i)
            if (fabs(A[i * m + k]) > fabs(A[piv * m + k]))
                piv = i;
        if (!(fabs(A[piv * m + k]) > 1e-12))
            return -1;
        if (piv != k) {
            for (size_t j = 0; j < m; ++j) {
                const double t = A[k * m + j];
                A[k * m + j] = A[piv * m + j];
                A[piv * m + j] = t;
            }
            const double t = b[k];
            b[k] = b[piv];
            b[piv] = t;
        }
        for (size_t i = k + 1; i < m; ++i) {
            const double f = A[i * m + k] / A[k * m + k];
            for (size_t j = k; j < m; ++j)
                A[i * m + j] -= f * A[k * m + j];
            b[i] -= f * b[k];
        }
    }
    for (size_t k = m; k-- > 0;) {
        double v = b[k];
        for (size_t j = k + 1; j < m; ++j)
            v -= A[k * m + j] * b[j];
        b[k] = v / A[k * m + k];
    }
    return 0;
}

/* T = s^T B^-1 s for the q x q positive definite B (row-major), or -1. */
static double quad_form(const double *s, const double *B, unsigned q)
{
    double Bc[RC_MAX_PARAMS * RC_MAX_PARAMS / 4 + 16], x[RC_MAX_PARAMS];
    if ((size_t)q * q > sizeof Bc / sizeof Bc[0])
        return -1.0;
    memcpy(Bc, B, (size_t)q * q * sizeof *B);
    memcpy(x, s, q * sizeof *s);
    if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)q, 1, Bc, (lapack_int)q, x, 1) != 0)
        return -1.0;
    double t = 0.0;
    for (unsigned a = 0; a < q; ++a)
        t += s[a] * x[a];
    return t;
}

/* The score of each pose in the candidate's q identifiable directions (columns of Zq = Zc V_q), sg, and its
 * leave-the-pose-out version for the CR3 variance, ug (both G x q, row-major). 0, or -1 out of memory. */
static int pose_scores(double *sg, double *ug, const double *Zc, const double *M, const double *ev, unsigned p,
                       unsigned q, size_t ld, const double *r, const double *r1, const ctx *c)
{
    const size_t n = c->n, G = c->n_poses;
    double *Zq = malloc(((size_t)n * q) * sizeof *Zq);
    size_t *first = malloc((G + 1 + n) * sizeof *first);
    if (!Zq || !first) {
        free(Zq);
        free(first);
        return -1;
    }
    size_t *rows = first + G + 1;
    for (size_t i = 0; i < n; ++i)
        for (unsigned a = 0; a < q; ++a) {
            double z = 0.0;
            for (unsigned b = 0; b < p; ++b)
                z += Zc[(size_t)b * ld + i] * M[b * p + (p - 1 - a)];
            Zq[i * q + a] = z;
        }
    /* the rows of each pose (counting sort) */
    memset(first, 0, (G + 1) * sizeof *first);
    for (size_t i = 0; i < n; ++i)
        first[c->pose[i] + 1]++;
    for (size_t g = 0; g < G; ++g)
        first[g + 1] += first[g];
    {
        size_t *fill = malloc(G * sizeof *fill);
        if (!fill) {
            free(Zq);
            free(first);
            return -1;
        }
        memcpy(fill, first, G * sizeof *fill);
        for (size_t i = 0; i < n; ++i)
            rows[fill[c->pose[i]]++] = i;
        free(fill);
    }
    memset(sg, 0, (size_t)G * q * sizeof *sg);
    memset(ug, 0, (size_t)G * q * sizeof *ug);
    for (size_t g = 0; g < G; ++g) {
        const size_t m = first[g + 1] - first[g], *ri = &rows[first[g]];
        double H[MAX_POSE_ROWS * MAX_POSE_ROWS], x[MAX_POSE_ROWS];
        for (size_t u = 0; u < m; ++u)
            for (unsigned a = 0; a < q; ++a)
                sg[g * q + a] += Zq[ri[u] * q + a] * r[ri[u]];
        if (m > MAX_POSE_ROWS) { /* no leverage correction for an outsize pose */
            for (size_t u = 0; u < m; ++u)
                for (unsigned a = 0; a < q; ++a)
                    ug[g * q + a] += Zq[ri[u] * q + a] * r1[ri[u]];
            continue;
        }
        /* (I - H_gg) x = r1_g: the pose's residuals as if it had been left out (CR3) */
        for (size_t u = 0; u < m; ++u) {
            x[u] = r1[ri[u]];
            for (size_t v = 0; v < m; ++v) {
                double h = 0.0;
                for (unsigned a = 0; a < q; ++a)
                    h += Zq[ri[u] * q + a] * Zq[ri[v] * q + a] / ev[p - 1 - a];
                H[u * m + v] = (u == v ? 1.0 : 0.0) - h;
            }
        }
        if (solve_small(H, x, m) != 0)
            for (size_t u = 0; u < m; ++u)
                x[u] = r1[ri[u]];
        for (size_t u = 0; u < m; ++u)
            for (unsigned a = 0; a < q; ++a)
                ug[g * q + a] += Zq[ri[u] * q + a] * x[u];
    }
    free(Zq);
    free(first);
    return 0;
}

int rch_dg_score_test(double *f_stat, unsigned *dof, double *p_value, const rc_model *m0, const rc_model *m1,
                      unsigned nb, unsigned q_ident, unsigned k_fitted, const ctx *c)
{
    const size_t n = c->n, G = c->n_poses;
    unsigned col[RC_MAX_PARAMS], nbf;
    const unsigned nf = free_columns(col, &nbf, m0, nb, c), p = nf - nbf;
    *f_stat = 0.0;
    *dof = 0;
    *p_value = 1.0;
    if (p == 0 || q_ident == 0 || n <= nf || G < 3)
        return -1;
    const size_t ld = n; /* column-major n x nf, then copies */
    double *J = malloc(((size_t)n * (nf + nbf + p) + 2 * n + 2 * (size_t)G * p + nf) * sizeof *J);
    if (!J)
        return -1;
    double *Jb = J + (size_t)n * nf, *Zc = Jb + (size_t)n * nbf, *r = Zc + (size_t)n * p, *r1 = r + n, *sg = r1 + n,
           *ug = sg + (size_t)G * p, *scale = ug + (size_t)G * p;
    double jac[RC_MAX_PARAMS], sv[RC_MAX_PARAMS];
    int rc = -1;
    for (size_t i = 0; i < n; ++i) {
        double l;
        if (rc_meas(&l, jac, m0, &c->s[i]) != RC_OK)
            goto done;
        r[i] = l - c->s[i].value;
        r1[i] = r[i];
        if (m1 && rc_meas(&l, NULL, m1, &c->s[i]) == RC_OK)
            r1[i] = l - c->s[i].value;
        for (unsigned k = 0; k < nf; ++k)
            J[(size_t)k * ld + i] = jac[col[k]];
    }
    for (unsigned k = 0; k < nf; ++k) { /* unit columns: the rank threshold reads relative sizes */
        double ss = 0.0;
        for (size_t i = 0; i < n; ++i)
            ss += J[(size_t)k * ld + i] * J[(size_t)k * ld + i];
        scale[k] = ss > 0.0 ? 1.0 / sqrt(ss) : 1.0;
        for (size_t i = 0; i < n; ++i)
            J[(size_t)k * ld + i] *= scale[k];
    }
    /* Zc = Jc - Jb X, X = argmin |Jb X - Jc| (minimum norm, rank-revealing) */
    memcpy(Jb, J, (size_t)n * nbf * sizeof *J);
    memcpy(Zc, J + (size_t)n * nbf, (size_t)n * p * sizeof *J);
    lapack_int rank;
    if (nbf > 0 && LAPACKE_dgelsd(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)nbf, (lapack_int)p, Jb, (lapack_int)ld,
                                  Zc, (lapack_int)ld, sv, 1e-9, &rank) != 0)
        goto done;
    for (unsigned a = 0; a < p; ++a) { /* Zc now holds X in its first nbf rows: form the projected columns */
        double xa[RC_MAX_PARAMS];
        for (unsigned k = 0; k < nbf; ++k)
            xa[k] = Zc[(size_t)a * ld + k];
        for (size_t i = 0; i < n; ++i) {
            double v = J[(size_t)(nbf + a) * ld + i];
            for (unsigned k = 0; k < nbf; ++k)
                v -= J[(size_t)k * ld + i] * xa[k];
            Zc[(size_t)a * ld + i] = v;
        }
    }
    /* the candidate's identifiable directions: the top q eigenvectors of Zc^T Zc */
    double M[RC_MAX_PARAMS * RC_MAX_PARAMS / 4 + 16], ev[RC_MAX_PARAMS];
    if ((size_t)p * p > sizeof M / sizeof M[0])
        goto done;
    for (unsigned a = 0; a < p; ++a)
        for (unsigned b = 0; b < p; ++b) {
            double v = 0.0;
            for (size_t i = 0; i < n; ++i)
                v += Zc[(size_t)a * ld + i] * Zc[(size_t)b * ld + i];
            M[a * p + b] = v;
        }
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', (lapack_int)p, M, (lapack_int)p, ev) != 0)
        goto done;
    unsigned q = 0; /* eigenvalues ascending: take from the top while clearly above zero */
    while (q < q_ident && q < p && ev[p - 1 - q] > 1e-10 * ev[p - 1] && ev[p - 1 - q] > 1e-14)
        ++q;
    if (q == 0 || G <= (size_t)q + 1)
        goto done;
    if (pose_scores(sg, ug, Zc, M, ev, p, q, ld, r, r1, c) != 0)
        goto done;
    double s[RC_MAX_PARAMS], B[RC_MAX_PARAMS * RC_MAX_PARAMS / 4 + 16];
    memset(s, 0, sizeof s);
    memset(B, 0, (size_t)q * q * sizeof *B);
    for (size_t g = 0; g < G; ++g)
        for (unsigned a = 0; a < q; ++a) {
            s[a] += sg[g * q + a];
            for (unsigned b = 0; b < q; ++b)
                B[a * q + b] += ug[g * q + a] * ug[g * q + b];
        }
    /* CR3 in the tested directions; the current model's own fit shrinks the residuals by (n - K) / (n - 1) */
    const double K = (double)k_fitted, cg = (double)(G - 1) / (double)G * ((double)n - 1.0) /
                                            ((double)n > K + 1.0 ? (double)n - K : 1.0);
    for (unsigned a = 0; a < q * q; ++a)
        B[a] *= cg;
    const double T = quad_form(s, B, q);
    if (T < 0.0)
        goto done;
    *f_stat = T * (double)(G - q) / ((double)q * (double)(G - 1));
    *dof = q;
    *p_value = rch_f_sf(*f_stat, (double)q, (double)(G - q));
    rc = 0;
done:
    free(J);
    return rc;
}
