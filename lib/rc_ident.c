/* SPDX-License-Identifier: MIT */
/* rc_ident.c - what the data can identify (see rc_ident.h for the thresholds). */
#include "rc_ident.h"

#include <math.h>
#include <string.h>

#include "rc_linalg.h"

const char *rc_ident_class_str(rc_ident_class c)
{
    switch (c) {
    case RC_IDENT_IDENTIFIABLE:
        return "identifiable";
    case RC_IDENT_WEAK:
        return "weak";
    case RC_IDENT_NONE:
        return "not identifiable";
    }
    return "unknown";
}

size_t rc_ident_work_size(unsigned n)
{
    return (size_t)n * n + n;
}

void rc_ident_scale(double *D, const double *col_sq, unsigned n, size_t stride)
{
    RC_ASSERT(D != NULL && col_sq != NULL);
    double amax = 0.0;
    for (unsigned i = 0; i < n; ++i)
        if (col_sq[i * stride] > amax)
            amax = col_sq[i * stride];
    const double zero = RC_IDENT_ZERO_COL * RC_IDENT_ZERO_COL * amax;
    for (unsigned i = 0; i < n; ++i) {
        const double a = col_sq[i * stride];
        D[i] = a > zero && a > 0.0 ? sqrt(a) : 0.0;
    }
}

/* s_k from vals: the singular value itself, or sqrt of an eigenvalue
 * (negative rounding-level eigenvalues count as zero). */
static double sv_of(const double *vals, int eig, unsigned k)
{
    return eig ? (vals[k] > 0.0 ? sqrt(vals[k]) : 0.0) : vals[k];
}

int rc_ident_eig_is_null(double ev, double ev_max)
{
    if (!(ev_max > 0.0))
        return 1;
    const double sk = ev > 0.0 ? sqrt(ev) : 0.0;
    return !(sk / sqrt(ev_max) >= RC_IDENT_NULL_REL);
}

static rc_status classify(rc_ident *out, const double *vals, int eig, const double *V, unsigned n, size_t n_rows)
{
    RC_ASSERT(out != NULL && vals != NULL && V != NULL);
    memset(out, 0, sizeof *out);
    if (n == 0 || n > RC_MAX_PARAMS)
        return RC_ERR_ARG;
    out->n = n;
    for (unsigned k = 0; k < n; ++k)
        if (!isfinite(vals[k]) || (!eig && !(vals[k] >= 0.0)))
            return RC_ERR_NUMERIC;
    const double smax = sv_of(vals, eig, 0);
    double logsum = 0.0;
    for (unsigned k = 0; k < n; ++k) {
        const double sk = sv_of(vals, eig, k);
        out->sv_rel[k] = smax > 0.0 ? sk / smax : 0.0;
        /* from eigenvalues, the test the solvers use (the same expression) */
        const int null =
            eig ? rc_ident_eig_is_null(vals[k], vals[0]) : !(smax > 0.0 && out->sv_rel[k] >= RC_IDENT_NULL_REL);
        if (!null) {
            ++out->rank;
            logsum += log(sk);
            out->cond = smax / sk;
            if (out->sv_rel[k] < RC_IDENT_WEAK_REL) {
                ++out->n_weak;
                out->dir_class[k] = (uint8_t)RC_IDENT_WEAK;
            } else {
                out->dir_class[k] = (uint8_t)RC_IDENT_IDENTIFIABLE;
            }
        } else {
            out->dir_class[k] = (uint8_t)RC_IDENT_NONE;
        }
    }
    out->n_null = n - out->rank;
    out->log_det = 2.0 * logsum;
    out->observability =
        out->rank > 0 && n_rows > 0 ? exp(logsum / (double)out->rank) / sqrt((double)n_rows) : 0.0;
    for (unsigned i = 0; i < n; ++i) {
        double share_null = 0.0, share_weak = 0.0;
        for (unsigned k = 0; k < n; ++k) {
            const double v2 = V[(size_t)i * n + k] * V[(size_t)i * n + k];
            if (out->dir_class[k] == (uint8_t)RC_IDENT_NONE)
                share_null += v2;
            if (out->dir_class[k] != (uint8_t)RC_IDENT_IDENTIFIABLE)
                share_weak += v2;
        }
        out->param_class[i] = (uint8_t)(share_null >= RC_IDENT_SHARE   ? RC_IDENT_NONE
                                         : share_weak >= RC_IDENT_SHARE ? RC_IDENT_WEAK
                                                                        : RC_IDENT_IDENTIFIABLE);
    }
    return RC_OK;
}

rc_status rc_ident_classify(rc_ident *out, const double *sv, const double *V, unsigned n, size_t n_rows)
{
    return classify(out, sv, 0, V, n, n_rows);
}

rc_status rc_ident_classify_eig(rc_ident *out, const double *ev, const double *V, unsigned n, size_t n_rows)
{
    return classify(out, ev, 1, V, n, n_rows);
}

rc_status rc_ident_normal(rc_ident *out, double *V, double *work, const double *AtA, unsigned n, size_t n_rows)
{
    RC_ASSERT(out != NULL && V != NULL && work != NULL && AtA != NULL);
    memset(out, 0, sizeof *out);
    if (n == 0 || n > RC_MAX_PARAMS)
        return RC_ERR_ARG;
    double *A = work, *D = work + (size_t)n * n;
    /* D_i = column norm; a zero column gets D_i = 0 and its row and column
     * of the scaled matrix are zero */
    rc_ident_scale(D, AtA, n, (size_t)n + 1);
    for (unsigned i = 0; i < n; ++i)
        for (unsigned k = 0; k < n; ++k) {
            const double d = D[i] * D[k];
            const double a = AtA[(size_t)i * n + k];
            if (!isfinite(a))
                return RC_ERR_NUMERIC;
            A[(size_t)i * n + k] = d > 0.0 ? a / d : 0.0;
        }
    /* D is free again: it receives the eigenvalues */
    rc_status st = rcu_eig_sym(D, V, A, n, 0);
    if (st != RC_OK)
        return st;
    return rc_ident_classify_eig(out, D, V, n, n_rows);
}
