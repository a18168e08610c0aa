/* SPDX-License-Identifier: MIT */
/* rch_save.h - write one output file whole or not at all, through a writer
 * callback: rch_out_open (refuses a path naming an input; temporary file),
 * the writer, then rch_out_commit (rename into place) or rch_out_abort.
 * (A candidate for rch_file.h; kept apart because rch_file belongs to the
 * shared infrastructure.)
 *
 * Host side (prefix rch_). */
#ifndef RCH_SAVE_H
#define RCH_SAVE_H

#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"

/* Writes the whole content to f; 0, or -1 on a write error. */
typedef int (*rch_save_fn)(FILE *f, const void *ctx);

/* 0, or -1 with d set (input named as output, I/O error, writer failed);
 * on failure the file at path is untouched. what names the option ("--out"). */
int rch_save(const char *path, const char *what, const char *const *inputs, size_t n_inputs, rch_save_fn write,
             const void *ctx, rch_diag *d);

#endif
