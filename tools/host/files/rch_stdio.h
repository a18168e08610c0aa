/* SPDX-License-Identifier: MIT */
/* rch_stdio.h - the standard descriptors of a program, checked (issue 23).
 *
 * rch_stdio_begin(), first thing in main: descriptors 0, 1 and 2 that are
 * closed are opened on /dev/null (as git does), so that no file a command
 * opens later ever becomes its standard output, and no progress line ever
 * lands in a data file. They are opened in the direction that keeps them
 * useless: 0 write-only, 1 and 2 read-only. A read of standard input or a
 * write to standard output then fails with EBADF exactly as on the closed
 * descriptor, and is reported, instead of succeeding into /dev/null.
 *
 * On glibc standard output is a stream that records the reason (errno) of
 * the first failed write, so the message names it even when the failure
 * happened long before the exit (elsewhere: the errno of the last failure).
 *
 * rch_stdio_end(status), the last thing in main (coreutils' close_stdout is
 * the model): flushes and closes standard output and checks it and standard
 * error; a write that failed (full disk, /dev/full, a closed pipe, a closed
 * descriptor) turns a 0 status into 1, with "PROG: write error on standard
 * output: REASON" on standard error.
 *
 * Host side (prefix rch_). POSIX. */
#ifndef RCH_STDIO_H
#define RCH_STDIO_H

#include <stdio.h>

/* prog: the program name for messages ("rcal"); kept, not copied. */
void rch_stdio_begin(const char *prog);

/* The status main returns: status, or 1 when it was 0 and a write to
 * standard output or standard error failed. */
int rch_stdio_end(int status);

/* The reason of the first failed write on f (an errno value): for the
 * standard output installed by rch_stdio_begin the recorded one, else (and
 * when none was recorded) errno as it is now. */
int rch_stdio_errno(FILE *f);

#endif
