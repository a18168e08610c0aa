/* SPDX-License-Identifier: MIT */
/* rch_save.c - one output file, whole or not at all (see rch_save.h). */
#include "rch_save.h"

#include <errno.h>
#include <string.h>

#include "rch_file.h"

int rch_save(const char *path, const char *what, const char *const *inputs, size_t n_inputs, rch_save_fn write,
             const void *ctx, rch_diag *d)
{
    rch_out o;
    if (rch_out_open(&o, path, what, inputs, n_inputs, d) != 0)
        return -1;
    errno = 0;
    if (write(o.f, ctx) != 0) {
        const int err = rch_out_errno(&o);
        rch_out_abort(&o);
        rch_diag_set(d, path, 0, 0, "cannot write %s: %s; the previous file is unchanged", what, strerror(err));
        return -1;
    }
    return rch_out_commit(&o, d);
}
