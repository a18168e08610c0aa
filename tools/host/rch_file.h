/* SPDX-License-Identifier: MIT */
/* rch_file.h - output files that never destroy anything already written.
 *
 * rch_out_open() refuses an output path that names one of the command's
 * inputs (same device and inode, whatever the spelling: ./a.csv, a link, a
 * hard link), then writes to a temporary file in the same directory;
 * rch_out_commit() flushes, fsyncs and renames it into place only after the
 * whole output was written, so the old file survives any failure intact and
 * the new one is complete or absent. rch_out_abort() removes the temporary.
 * Path "-" means standard output (no rename).
 *
 * Host side (prefix rch_): POSIX. */
#ifndef RCH_FILE_H
#define RCH_FILE_H

#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"

typedef struct {
    FILE *f;          /* write here */
    char path[1024];  /* final name */
    char tmp[1024];   /* temporary name ("" for stdout) */
} rch_out;

/* inputs[n_inputs]: paths the command reads (NULL entries skipped). 0, or -1
 * with d set ("--out x.csv is also the input --data x.csv"). `what` names the
 * option in messages ("--out"). */
int rch_out_open(rch_out *o, const char *path, const char *what, const char *const *inputs, size_t n_inputs,
                 rch_diag *d);
int rch_out_commit(rch_out *o, rch_diag *d);
void rch_out_abort(rch_out *o);

/* 1 when a and b name the same existing file (device and inode), else 0. */
int rch_same_file(const char *a, const char *b);

/* Read a whole file into a NUL-terminated heap buffer, refusing files larger
 * than max_bytes (named in the message). 0, or -1 with d set. */
int rch_read_file(char **text, size_t *len, const char *path, size_t max_bytes, rch_diag *d);

#endif
