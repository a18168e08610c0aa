/* SPDX-License-Identifier: MIT */
/* rc_linalg.c - Cholesky and Jacobi eigen-decomposition. */
#include "rc_linalg.h"

#include <math.h>
#include <stddef.h>

rc_status rcu_chol_solve(double *A, double *b, unsigned n)
{
    for (unsigned j = 0; j < n; ++j) {
        double d = A[j * n + j];
        for (unsigned k = 0; k < j; ++k)
            d -= A[j * n + k] * A[j * n + k];
        if (!(d > 0.0) || !isfinite(d))
            return RC_ERR_NUMERIC;
        d = sqrt(d);
        A[j * n + j] = d;
        for (unsigned i = j + 1; i < n; ++i) {
            double s = A[i * n + j];
            for (unsigned k = 0; k < j; ++k)
                s -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = s / d;
        }
    }
    for (unsigned i = 0; i < n; ++i) { /* L y = b */
        double s = b[i];
        for (unsigned k = 0; k < i; ++k)
            s -= A[i * n + k] * b[k];
        b[i] = s / A[i * n + i];
    }
    for (unsigned i = n; i-- > 0;) { /* L^T x = y */
        double s = b[i];
        for (unsigned k = i + 1; k < n; ++k)
            s -= A[k * n + i] * b[k];
        b[i] = s / A[i * n + i];
    }
    return RC_OK;
}

/* Sort eigenpairs descending, moving eigenvector columns along. */
static void sort_desc(double *eval, double *V, unsigned n)
{
    for (unsigned i = 0; i < n; ++i) {
        unsigned best = i;
        for (unsigned j = i + 1; j < n; ++j)
            if (eval[j] > eval[best])
                best = j;
        if (best != i) {
            const double t = eval[i];
            eval[i] = eval[best];
            eval[best] = t;
            for (unsigned k = 0; k < n; ++k) {
                const double v = V[k * n + i];
                V[k * n + i] = V[k * n + best];
                V[k * n + best] = v;
            }
        }
    }
}

rc_status rcu_eig_sym_jacobi(double *eval, double *V, double *A, unsigned n, unsigned max_sweeps)
{
    if (max_sweeps == 0)
        max_sweeps = 60;
    for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < n; ++j)
            V[i * n + j] = (i == j) ? 1.0 : 0.0;
    double total = 0.0;
    for (unsigned i = 0; i < n * n; ++i)
        total += A[i] * A[i];
    if (!isfinite(total))
        return RC_ERR_NUMERIC;
    rc_status st = RC_ERR_NOCONV;
    for (unsigned sweep = 0; sweep < max_sweeps; ++sweep) {
        double off = 0.0;
        for (unsigned p = 0; p < n; ++p)
            for (unsigned q = p + 1; q < n; ++q)
                off += A[p * n + q] * A[p * n + q];
        if (off <= 1e-30 * total || off == 0.0) {
            st = RC_OK;
            break;
        }
        for (unsigned p = 0; p < n; ++p) {
            for (unsigned q = p + 1; q < n; ++q) {
                const double apq = A[p * n + q];
                if (fabs(apq) < 1e-300)
                    continue;
                const double app = A[p * n + p], aqq = A[q * n + q];
                const double theta = (aqq - app) / (2.0 * apq);
                const double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (unsigned k = 0; k < n; ++k) { /* columns p, q */
                    const double akp = A[k * n + p], akq = A[k * n + q];
                    A[k * n + p] = c * akp - s * akq;
                    A[k * n + q] = s * akp + c * akq;
                }
                for (unsigned k = 0; k < n; ++k) { /* rows p, q */
                    const double apk = A[p * n + k], aqk = A[q * n + k];
                    A[p * n + k] = c * apk - s * aqk;
                    A[q * n + k] = s * apk + c * aqk;
                }
                for (unsigned k = 0; k < n; ++k) {
                    const double vkp = V[k * n + p], vkq = V[k * n + q];
                    V[k * n + p] = c * vkp - s * vkq;
                    V[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    for (unsigned i = 0; i < n; ++i)
        eval[i] = A[i * n + i];
    sort_desc(eval, V, n);
    return st;
}


/* Householder reduction of the symmetric V (n x n) to tridiagonal form:
 * diagonal d, sub-diagonal e (e[0] = 0); V receives the transformation. */
static void tridiagonalize(double *V, double *d, double *e, unsigned n)
{
#define VV(r, c) V[(size_t)(r) * n + (c)]
    for (unsigned j = 0; j < n; ++j)
        d[j] = VV(n - 1, j);
    for (unsigned i = n - 1; i > 0; --i) {
        double scale = 0.0, h = 0.0;
        for (unsigned k = 0; k < i; ++k)
            scale += fabs(d[k]);
        if (scale == 0.0) {
            e[i] = d[i - 1];
            for (unsigned j = 0; j < i; ++j) {
                d[j] = VV(i - 1, j);
                VV(i, j) = 0.0;
                VV(j, i) = 0.0;
            }
        } else {
            for (unsigned k = 0; k < i; ++k) {
                d[k] /= scale;
                h += d[k] * d[k];
            }
            double f = d[i - 1], g = sqrt(h);
            if (f > 0.0)
                g = -g;
            e[i] = scale * g;
            h -= f * g;
            d[i - 1] = f - g;
            for (unsigned j = 0; j < i; ++j)
                e[j] = 0.0;
            for (unsigned j = 0; j < i; ++j) {
                f = d[j];
                VV(j, i) = f;
                g = e[j] + VV(j, j) * f;
                for (unsigned k = j + 1; k < i; ++k) {
                    g += VV(k, j) * d[k];
                    e[k] += VV(k, j) * f;
                }
                e[j] = g;
            }
            f = 0.0;
            for (unsigned j = 0; j < i; ++j) {
                e[j] /= h;
                f += e[j] * d[j];
            }
            const double hh = f / (h + h);
            for (unsigned j = 0; j < i; ++j)
                e[j] -= hh * d[j];
            for (unsigned j = 0; j < i; ++j) {
                f = d[j];
                g = e[j];
                for (unsigned k = j; k < i; ++k)
                    VV(k, j) -= f * e[k] + g * d[k];
                d[j] = VV(i - 1, j);
                VV(i, j) = 0.0;
            }
        }
        d[i] = h;
    }
    for (unsigned i = 0; i + 1 < n; ++i) { /* accumulate the transformations */
        VV(n - 1, i) = VV(i, i);
        VV(i, i) = 1.0;
        const double h = d[i + 1];
        if (h != 0.0) {
            for (unsigned k = 0; k <= i; ++k)
                d[k] = VV(k, i + 1) / h;
            for (unsigned j = 0; j <= i; ++j) {
                double g = 0.0;
                for (unsigned k = 0; k <= i; ++k)
                    g += VV(k, i + 1) * VV(k, j);
                for (unsigned k = 0; k <= i; ++k)
                    VV(k, j) -= g * d[k];
            }
        }
        for (unsigned k = 0; k <= i; ++k)
            VV(k, i + 1) = 0.0;
    }
    for (unsigned j = 0; j < n; ++j) {
        d[j] = VV(n - 1, j);
        VV(n - 1, j) = 0.0;
    }
    VV(n - 1, n - 1) = 1.0;
    e[0] = 0.0;
}

/* Implicit QL iterations on the tridiagonal (d, e), rotating V along. */
static rc_status tridiagonal_ql(double *V, double *d, double *e, unsigned n, unsigned max_iter)
{
    for (unsigned i = 1; i < n; ++i)
        e[i - 1] = e[i];
    e[n - 1] = 0.0;
    double f = 0.0, tst1 = 0.0;
    const double eps = 0x1.0p-52;
    for (unsigned l = 0; l < n; ++l) {
        const double t = fabs(d[l]) + fabs(e[l]);
        if (t > tst1)
            tst1 = t;
        unsigned m = l;
        while (m < n - 1 && fabs(e[m]) > eps * tst1)
            ++m;
        if (m > l) {
            unsigned iter = 0;
            do {
                if (++iter > max_iter)
                    return RC_ERR_NOCONV;
                double g = d[l];
                double p = (d[l + 1] - g) / (2.0 * e[l]);
                double r = hypot(p, 1.0);
                if (p < 0.0)
                    r = -r;
                d[l] = e[l] / (p + r);
                d[l + 1] = e[l] * (p + r);
                const double dl1 = d[l + 1];
                double h = g - d[l];
                for (unsigned i = l + 2; i < n; ++i)
                    d[i] -= h;
                f += h;
                p = d[m];
                double c = 1.0, c2 = 1.0, c3 = 1.0, s = 0.0, s2 = 0.0;
                const double el1 = e[l + 1];
                for (unsigned i = m; i-- > l;) {
                    c3 = c2;
                    c2 = c;
                    s2 = s;
                    g = c * e[i];
                    h = c * p;
                    r = hypot(p, e[i]);
                    e[i + 1] = s * r;
                    s = e[i] / r;
                    c = p / r;
                    p = c * d[i] - s * g;
                    d[i + 1] = h + s * (c * g + s * d[i]);
                    for (unsigned k = 0; k < n; ++k) {
                        h = VV(k, i + 1);
                        VV(k, i + 1) = s * VV(k, i) + c * h;
                        VV(k, i) = c * VV(k, i) - s * h;
                    }
                }
                p = -s * s2 * c3 * el1 * e[l] / dl1;
                e[l] = s * p;
                d[l] = c * p;
            } while (fabs(e[l]) > eps * tst1);
        }
        d[l] += f;
        e[l] = 0.0;
    }
    return RC_OK;
#undef VV
}

rc_status rcu_eig_sym(double *eval, double *V, double *A, unsigned n, unsigned max_iter)
{
    if (n == 0)
        return RC_OK;
    double total = 0.0;
    for (size_t i = 0; i < (size_t)n * n; ++i) {
        total += A[i] * A[i];
        V[i] = A[i];
    }
    if (!isfinite(total))
        return RC_ERR_NUMERIC;
    double *e = A; /* A is scratch from here on: its first n entries hold e */
    tridiagonalize(V, eval, e, n);
    rc_status st = tridiagonal_ql(V, eval, e, n, max_iter ? max_iter : 60u);
    sort_desc(eval, V, n);
    return st;
}

double rcu_sym3_eig_max(const double A[9])
{
    const double a00 = A[0], a01 = A[1], a02 = A[2], a11 = A[4], a12 = A[5], a22 = A[8];
    const double p1 = a01 * a01 + a02 * a02 + a12 * a12;
    if (p1 == 0.0) { /* diagonal */
        double mx = a00 > a11 ? a00 : a11;
        mx = mx > a22 ? mx : a22;
        return isfinite(a00 + a11 + a22) ? mx : (double)NAN;
    }
    const double q = (a00 + a11 + a22) / 3.0;
    const double b00 = a00 - q, b11 = a11 - q, b22 = a22 - q;
    const double p = sqrt((b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * p1) / 6.0);
    if (!isfinite(p))
        return (double)NAN;
    /* det(B) / 2 with B = (A - q I) / p */
    const double det = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02) + a02 * (a01 * a12 - b11 * a02);
    double r = det / (2.0 * p * p * p);
    r = r < -1.0 ? -1.0 : r > 1.0 ? 1.0 : r;
    return q + 2.0 * p * cos(acos(r) / 3.0);
}
