/* SPDX-License-Identifier: MIT */
#include "rch_diag.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void rch_diag_set(rch_diag *d, const char *file, unsigned line, unsigned col, const char *fmt, ...)
{
    va_list ap;
    if (d == NULL)
        return;
    snprintf(d->file, sizeof d->file, "%s", file ? file : "");
    d->line = line;
    d->col = col;
    va_start(ap, fmt);
    vsnprintf(d->msg, sizeof d->msg, fmt, ap);
    va_end(ap);
}

const char *rch_diag_str(const rch_diag *d, char *buf, size_t len)
{
    if (d->line && d->col)
        snprintf(buf, len, "%s:%u:%u: %s", d->file, d->line, d->col, d->msg);
    else if (d->line)
        snprintf(buf, len, "%s:%u: %s", d->file, d->line, d->msg);
    else if (d->file[0])
        snprintf(buf, len, "%s: %s", d->file, d->msg);
    else
        snprintf(buf, len, "%s", d->msg);
    return buf;
}
