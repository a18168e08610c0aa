/* SPDX-License-Identifier: MIT */
/* rch_lapack.c - which BLAS/LAPACK runs (rch_lapack.h). */
#define _GNU_SOURCE /* dladdr */
#include "rch_lapack.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Set by tools/CMakeLists.txt from cmake/rcal_lapack.cmake. */
#ifndef RCH_LAPACK_BUILT
#define RCH_LAPACK_BUILT "the system's LAPACKE (not pinned)"
#endif
#ifndef RCH_LAPACK_PINNED
#define RCH_LAPACK_PINNED 0
#endif

/* The Fortran entry points, declared only to take their address (and ILAVER
 * to call it); lapack.h is not included, so their prototypes do not clash. */
void ilaver_(int *major, int *minor, int *patch);
void dgesvd_(void);
void dgemm_(void);

typedef void (*rch_lapack_fn)(void);

/* The object that holds fn: its load address into *base and its real path
 * into file; 0 when dladdr knows it (a static program: it does not). */
static int where(rch_lapack_fn fn, void **base, char *file, size_t len)
{
    Dl_info dl;
    void *p;
    memcpy(&p, &fn, sizeof p); /* a function's address as data (ISO C has no cast for it) */
    file[0] = '\0';
    *base = NULL;
    if (dladdr(p, &dl) == 0 || !dl.dli_fname || !dl.dli_fname[0])
        return -1;
    *base = dl.dli_fbase;
    char real[PATH_MAX];
    const char *name = realpath(dl.dli_fname, real) ? real : dl.dli_fname;
    size_t n = strlen(name);
    if (n >= len)
        n = len - 1; /* truncated */
    memcpy(file, name, n);
    file[n] = '\0';
    return 0;
}

void rch_lapack_get(rch_lapack_info *out)
{
    memset(out, 0, sizeof *out);
    ilaver_(&out->version[0], &out->version[1], &out->version[2]);
    out->pinned = RCH_LAPACK_PINNED;
    out->built = RCH_LAPACK_BUILT;
    char self[RCH_LAPACK_PATH];
    void *b_self, *b_lapack, *b_blas;
    int k_self = where((rch_lapack_fn)rch_lapack_get, &b_self, self, sizeof self);
    int k_lapack = where(dgesvd_, &b_lapack, out->lapack_file, sizeof out->lapack_file);
    int k_blas = where(dgemm_, &b_blas, out->blas_file, sizeof out->blas_file);
    if (k_self != 0 && k_lapack != 0 && k_blas != 0)
        out->linked_in = 1; /* a static program: nothing but itself */
    else
        out->linked_in = k_self == 0 && k_lapack == 0 && k_blas == 0 && b_lapack == b_self && b_blas == b_self;
}

char *rch_lapack_line(char *buf, size_t len, const rch_lapack_info *info)
{
    if (len == 0)
        return buf;
    const int *v = info->version;
    if (info->linked_in)
        snprintf(buf, len, "%sLAPACK %d.%d.%d and BLAS, linked in (%s%s)", info->pinned ? "reference " : "", v[0],
                 v[1], v[2], info->pinned ? "pinned: " : "", info->built);
    else
        snprintf(buf, len, "LAPACK %d.%d.%d from %s, BLAS from %s (%s: %s)", v[0], v[1], v[2],
                 info->lapack_file[0] ? info->lapack_file : "an unknown file",
                 info->blas_file[0] ? info->blas_file : "an unknown file",
                 info->pinned ? "NOT the pinned archives the build linked" : "not pinned, the build linked",
                 info->built);
    return buf;
}
