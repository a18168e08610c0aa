/* SPDX-License-Identifier: MIT */
/* rch_diag.h - error reports that say what and where (file, line, column).
 * Host side (prefix rch_): may use stdio and the heap. */
#ifndef RCH_DIAG_H
#define RCH_DIAG_H

#include <stddef.h>

typedef struct rch_diag {
    char file[256];  /* input name, "" when not from a file */
    unsigned line;   /* 1-based, 0 when not applicable */
    unsigned col;    /* 1-based, 0 when not applicable */
    char msg[512];
} rch_diag;

#if defined(__GNUC__)
#define RCH_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define RCH_PRINTF(a, b)
#endif

/* Set the report (d may be NULL: then nothing happens). */
void rch_diag_set(rch_diag *d, const char *file, unsigned line, unsigned col, const char *fmt, ...)
    RCH_PRINTF(5, 6);

/* "file:line:col: msg" into buf; returns buf. */
const char *rch_diag_str(const rch_diag *d, char *buf, size_t len);

#endif
