/* SPDX-License-Identifier: MIT */
/* fake_lapack.c - a stand-in for "another BLAS/LAPACK on the machine" (test
 * pkg_lapack_*): built as liblapack.so.3 and libblas.so.3 (SONAMEs of the
 * system's alternatives) into a directory the tests put first on
 * LD_LIBRARY_PATH. Its ILAVER says 0.0.0 and its routines answer 42, so a
 * program that takes its LAPACK from the loader rather than from the
 * reference archives linked in (cmake/rcal_lapack.cmake) is caught: it
 * runs these (a failed assertion) or, when a library it loads needs a
 * routine the fake lacks (Debian's liblapacke.so.3 pulls libtmglib.so.3,
 * which needs cgemv_), does not start ("symbol lookup error"); either way
 * the test fails. The routines rcal's LAPACKE calls are here; FAKE_BLAS
 * builds the BLAS half. */
#include <stddef.h>

#ifdef FAKE_BLAS
void dgemm_(void);
void dgemm_(void)
{
}
#else
void ilaver_(int *major, int *minor, int *patch);
void ilaver_(int *major, int *minor, int *patch)
{
    *major = 0;
    *minor = 0;
    *patch = 0;
}

/* dsyev_(jobz, uplo, n, a, lda, w, work, lwork, info, hidden lengths) */
void dsyev_(const char *jobz, const char *uplo, const int *n, double *a, const int *lda, double *w, double *work,
            const int *lwork, int *info, size_t l1, size_t l2);
void dsyev_(const char *jobz, const char *uplo, const int *n, double *a, const int *lda, double *w, double *work,
            const int *lwork, int *info, size_t l1, size_t l2)
{
    (void)jobz, (void)uplo, (void)a, (void)lda, (void)lwork, (void)l1, (void)l2;
    for (int i = 0; i < *n; ++i)
        w[i] = 42.0;
    work[0] = 3.0 * *n;
    *info = 0;
}

/* the others: info = 0, nothing computed */
#define FAKE(name)                                                                                                  \
    void name(void);                                                                                                \
    void name(void)                                                                                                 \
    {                                                                                                               \
    }
FAKE(dgesvd_)
FAKE(dposv_)
FAKE(dpotrf_)
FAKE(dpotri_)
FAKE(dgelsd_)
FAKE(dgeqrf_)
FAKE(dorgqr_)
#endif
