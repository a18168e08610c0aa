/* rc_linalg.c - Cholesky and Jacobi eigen-decomposition. */
#include "rc_linalg.h"

#include <math.h>

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

rc_status rcu_eig_sym(double *eval, double *V, double *A, unsigned n, unsigned max_sweeps)
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
    /* selection sort, descending, moving eigenvector columns along */
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
    return st;
}
