/* SPDX-License-Identifier: MIT */
/* rch_lapack.h - which BLAS/LAPACK this program computes with.
 *
 * The build links the reference LAPACK and BLAS archives into every binary
 * (cmake/rcal_lapack.cmake: Debian's liblapack.so.3 / libblas.so.3 are
 * alternatives that another package switches to ATLAS or OpenBLAS, which
 * changes rcal's results). rch_lapack_get() says what runs: the version
 * LAPACK's ILAVER reports and the file that holds dgesvd_ (LAPACK) and
 * dgemm_ (BLAS) at run time, by dladdr, so a build that is not pinned
 * (-DRCAL_PIN_REFERENCE_LAPACK=OFF) names the implementation the loader
 * picked. `rcal --version` prints rch_lapack_line(); Python's rcal.lapack()
 * returns it.
 *
 * Host side: uses dladdr (a GNU extension of the C library).
 */
#ifndef RCH_LAPACK_H
#define RCH_LAPACK_H

#include <stddef.h>

#define RCH_LAPACK_PATH 1024

typedef struct rch_lapack_info {
    int version[3];                   /* ILAVER of the LAPACK that runs (3, 11, 0) */
    int linked_in;                    /* 1: LAPACK and BLAS are inside this program or library */
    int pinned;                       /* 1: the build linked the reference archives (cmake/rcal_lapack.cmake) */
    char lapack_file[RCH_LAPACK_PATH]; /* the file dgesvd_ resolves to (real path; "" when not known) */
    char blas_file[RCH_LAPACK_PATH];   /* the file dgemm_ resolves to (real path; "" when not known) */
    const char *built;                /* what the build linked, one phrase */
} rch_lapack_info;

/* What runs, into *out. Never fails (a file not known is ""). */
void rch_lapack_get(rch_lapack_info *out);

/* One line (no newline) into buf (len bytes, truncated): "reference LAPACK
 * 3.11.0 and BLAS, linked in (pinned: ...)" or "LAPACK 3.10.3 from <file>,
 * BLAS from <file> (NOT pinned: ...)". Returns buf. */
char *rch_lapack_line(char *buf, size_t len, const rch_lapack_info *info);

#endif /* RCH_LAPACK_H */
