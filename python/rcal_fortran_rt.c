/* SPDX-License-Identifier: MIT */
/* rcal_fortran_rt.c - what the reference LAPACK and BLAS archives linked into
 * librcal_ffi.so need from the Fortran run-time, so that the library needs
 * no libgfortran.so.5 (nor libquadmath.so.0) on the machine it runs on.
 *
 * The run-time's archive libgfortran.a cannot go into a shared object (its
 * objects use initial-exec TLS: "relocation R_X86_64_TPOFF32 ... can not be
 * used when making a shared object"), and the LAPACK routines rcal calls
 * reach it through two doors only (nm -u of the linked library):
 *   - xerbla_, the error handler called on an illegal argument, whose
 *     Fortran WRITE and STOP pull the run-time's I/O: replaced here by one
 *     that prints the same message and returns (LAPACKE then returns the
 *     negative info to its caller; a Fortran STOP would end the Python
 *     process);
 *   - _gfortran_concat_string, the Fortran `//` (DORMQR and its kin pass
 *     SIDE // TRANS to ILAENV for a block size): the same semantics.
 * Both are hidden (not exported). python_venv_install checks with ldd that
 * the installed extension needs no LAPACK, BLAS or Fortran library. Compiled
 * into rcal_ffi only when the reference archives are linked
 * (cmake/rcal_lapack.cmake, RCAL_LAPACK_PINNED). */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#define RCAL_RT_HIDDEN __attribute__((visibility("hidden")))

RCAL_RT_HIDDEN void xerbla_(const char *srname, const int *info, size_t srname_len);
RCAL_RT_HIDDEN void _gfortran_concat_string(size_t destlen, char *dest, size_t len1, const char *s1, size_t len2,
                                            const char *s2);

void xerbla_(const char *srname, const int *info, size_t srname_len)
{
    size_t n = srname_len;
    while (n > 0 && srname[n - 1] == ' ')
        --n;
    fprintf(stderr, " ** On entry to %.*s parameter number %d had an illegal value\n", (int)n, srname,
            info ? *info : 0);
}

/* dest[0..destlen) = s1 // s2, cut at destlen, padded with blanks. */
void _gfortran_concat_string(size_t destlen, char *dest, size_t len1, const char *s1, size_t len2, const char *s2)
{
    size_t n1 = len1 < destlen ? len1 : destlen;
    memmove(dest, s1, n1);
    size_t n2 = len2 < destlen - n1 ? len2 : destlen - n1;
    memmove(dest + n1, s2, n2);
    memset(dest + n1 + n2, ' ', destlen - n1 - n2);
}
