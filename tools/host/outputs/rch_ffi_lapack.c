/* SPDX-License-Identifier: MIT */
/* rch_ffi_lapack.c - the flat C API (rch_ffi.h): which BLAS/LAPACK the
 * library computes with (rch_lapack.h). */
#include "rch_ffi.h"

#include "rch_lapack.h"

int rch_ffi_lapack(char *line, size_t len, int *linked_in, int *version)
{
    if (!line && len > 0)
        return RCH_FFI_ERR_ARG;
    rch_lapack_info info;
    rch_lapack_get(&info);
    if (len > 0)
        rch_lapack_line(line, len, &info);
    if (linked_in)
        *linked_in = info.linked_in;
    if (version)
        for (int i = 0; i < 3; ++i)
            version[i] = info.version[i];
    return RCH_FFI_OK;
}
