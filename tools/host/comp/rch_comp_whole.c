/* SPDX-License-Identifier: MIT */
/* rch_comp_whole.c - what every program read whole shares (RAPID, KRL,
 * URScript, Fanuc LS; rch_comp_int.h): the rest of the input read into
 * memory, the numbers' replacements collected, the refusal said once, the
 * text written with only the replaced bytes changed.
 * Memory: the text and the edits malloc'd (freed here / by the caller). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_comp_int.h"

int rch_cpi_whole(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, size_t max_bytes,
                  const char *what, rch_cpi_text_fn fn, rch_diag *d)
{
    size_t cap = got + 65536, n = got;
    char *buf = malloc(cap);
    if (!buf) {
        rch_diag_set(d, c->in_name, lineno, 1, "out of memory");
        return -1;
    }
    memcpy(buf, line, got);
    for (;;) {
        if (n == cap) {
            if (cap > max_bytes) {
                free(buf);
                rch_diag_set(d, c->in_name, 0, 0, "%s of more than %zu bytes is refused", what, max_bytes);
                return -1;
            }
            char *nb = realloc(buf, 2 * cap);
            if (!nb) {
                free(buf);
                rch_diag_set(d, c->in_name, lineno, 1, "out of memory");
                return -1;
            }
            buf = nb;
            cap *= 2;
        }
        const size_t k = fread(buf + n, 1, cap - n, in);
        n += k;
        if (k == 0)
            break;
    }
    const int rc = fn(c, buf, n, lineno - 1, d);
    free(buf);
    return rc;
}

int rch_cpi_edit_add(rch_cpi_edits *e, size_t off, size_t len, const char *fmt, double v)
{
    if (e->n == e->cap) {
        const size_t nc = e->cap ? 2 * e->cap : 64;
        rch_cpi_edit *ne = realloc(e->ed, nc * sizeof *ne);
        if (!ne)
            return -1;
        e->ed = ne;
        e->cap = nc;
    }
    rch_cpi_edit *x = &e->ed[e->n++];
    x->off = off;
    x->len = len;
    snprintf(x->rep, sizeof x->rep, fmt, v);
    return 0;
}

void rch_cpi_edits_free(rch_cpi_edits *e)
{
    free(e->ed);
    memset(e, 0, sizeof *e);
}

static int edit_cmp(const void *a, const void *b)
{
    const size_t x = ((const rch_cpi_edit *)a)->off, y = ((const rch_cpi_edit *)b)->off;
    return x < y ? -1 : x > y;
}

void rch_cpi_edits_write(rch_cpi_ctx *c, const char *text, size_t len, rch_cpi_edits *e)
{
    qsort(e->ed, e->n, sizeof *e->ed, edit_cmp); /* in the text's order, whatever order they were found in */
    size_t at = 0;
    for (size_t k = 0; k < e->n; ++k) {
        fwrite(text + at, 1, e->ed[k].off - at, c->out);
        fputs(e->ed[k].rep, c->out);
        at = e->ed[k].off + e->ed[k].len;
    }
    fwrite(text + at, 1, len - at, c->out); /* the input's bytes: its BOM and line ends as they were */
}

void rch_cpi_refused(rch_cpi_ctx *c, rch_diag *d, unsigned long n_bad, const char *noun)
{
    if (c->warn) { /* each is named above; the error says how many, once */
        rch_diag_set(d, c->in_name, 0, 0, "%lu %s%s cannot be corrected (each named above with its line, column "
                     "and reason); nothing written", n_bad, noun, n_bad == 1 ? "" : "s");
        return;
    }
    char more[96];
    if (n_bad > 1)
        snprintf(more, sizeof more, " (and %lu more %ss; nothing written)", n_bad - 1, noun);
    else
        snprintf(more, sizeof more, " (nothing written)");
    strncat(d->msg, more, sizeof d->msg - strlen(d->msg) - 1);
}
