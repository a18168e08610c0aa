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
 * The rules every output follows (issue 23), here once:
 * - One command's outputs never name each other: after rch_out_one_command()
 *   (the rcal program calls it; one command per process) every output
 *   opened is remembered, and a later one that names the same file (device
 *   and inode when it exists, else the normalised path: ./x, a//x, d/../x,
 *   a link to it) is refused. rch_outs_distinct() applies the same rule to a
 *   command's output options before any work.
 * - An output through a symbolic link replaces the link's target (the link
 *   stays); an existing file keeps its mode (and owner, where permitted);
 *   a file the user cannot write, or one with no write permission bit at
 *   all (mode 0444, also for root), is refused.
 * - SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGPIPE during a write remove the
 *   temporary files (an async-signal-safe handler unlinks the registered
 *   ones, then the signal is raised again with its default action). Signals
 *   the caller ignores stay ignored. rch_tmp_register() adds a temporary
 *   file written by other means.
 *
 * Host side (prefix rch_). POSIX. */
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
/* Why a writer's output o failed (an errno value, issue 47: "a full disk
 * says 'cannot write' without the reason"): the stream flushed once more so
 * that a failure still in its buffer shows (ENOSPC, EFBIG, EIO, ...); errno
 * as the writer left it otherwise; EIO when nothing says more. Call it
 * before rch_out_abort. */
int rch_out_errno(rch_out *o);

/* A bundle, whole or not at all: every one of the n outputs is flushed and
 * synced first; only when all were written are they renamed into place.
 * 0, or -1 with d set and every temporary removed (and nothing renamed when
 * a write failed). Standard output ("-") is not part of a bundle. */
int rch_out_commit_all(rch_out *o, size_t n, rch_diag *d);

/* 1 when a and b name the same existing file (device and inode), else 0. */
int rch_same_file(const char *a, const char *b);

/* 1 when a and b name the same file: device and inode when both exist,
 * else the same normalised path (directories resolved, the last component
 * through its symbolic links); else 0. */
int rch_path_same(const char *a, const char *b);

/* Remember every output of this process from now on (see above). */
void rch_out_one_command(void);

/* Forget that this command wrote path (a result it replaces with a later
 * one of its own: the calibration's refits rewrite their plot). */
void rch_out_unclaim(const char *path);

/* The command's output options, before any work: paths[n] (NULL entries
 * skipped, "-" ignored) named by whats[n] ("--out"). 0, or -1 with d set
 * ("--residuals x names the same file as --out x"). */
int rch_outs_distinct(const char *const *paths, const char *const *whats, size_t n, rch_diag *d);

/* A temporary file written by other means than rch_out_open, removed on a
 * signal until forgotten. 0, or -1 when the table (64) is full. */
int rch_tmp_register(const char *path);
void rch_tmp_forget(const char *path);

/* A path the user did not give (a file name found inside a file: the
 * provenance of a calibration, a reference in a model): opened only when it
 * is a regular file of at most max_bytes, never a FIFO, a device (/dev/zero)
 * or a directory, and without blocking on the open. The stream, or NULL with
 * why set ("not a regular file (a FIFO)", "larger than the limit ...", the
 * system's reason). A reader still stops after max_bytes (the file may
 * grow). */
#define RCH_UNASKED_MAX_BYTES ((size_t)256 << 20)
FILE *rch_open_regular(const char *path, size_t max_bytes, char *why, size_t why_len);

/* Read a whole file into a NUL-terminated heap buffer, refusing files larger
 * than max_bytes (named in the message). 0, or -1 with d set. */
int rch_read_file(char **text, size_t *len, const char *path, size_t max_bytes, rch_diag *d);

#endif
