/* SPDX-License-Identifier: MIT */
/* rch_rapid_scan.c - rch_rapid_scan (see rch_rapid.h): the passes over one
 * module in order, the tokens (rch_rapid.c), the types and declarations
 * (rch_rapid_types.c), every top-level aggregate (rch_rapid_literal.c), the
 * uses (rch_rapid_uses.c), then each target's declared tool and work object
 * frames and the brackets left unopened.
 * Memory: the targets on the heap (rch_rapid_free); nothing else kept.
 * Errors: -1 with d set, nothing half read left in out. */
#include "rch_rapid.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_rapid_int.h"

int rch_rapid_scan(rch_rapid_targets *out, const char *text, size_t len, const char *name, rch_diag *d)
{
    if (len > RCH_RAPID_MAX_BYTES) {
        rch_diag_set(d, name, 0, 0, "a RAPID module of more than %u bytes is refused", RCH_RAPID_MAX_BYTES);
        return -1;
    }
    rch_rpi_scan s;
    memset(&s, 0, sizeof s);
    s.text = text;
    s.len = len;
    s.name = name;
    s.out = out;
    s.d = d;
    int rc = rch_rpi_tokenize(&s) == 0 ? 0 : -1;
    if (rc == 0)
        rch_rpi_collect_types(&s);
    if (rc == 0 && rch_rpi_collect_decls(&s) != 0)
        rc = -1;
    for (size_t i = 0; rc == 0 && i < s.tk.n; ++i) {
        if (!rch_rpi_punct(&s, i, '['))
            continue;
        const size_t c = rch_rpi_close_of(&s, i);
        if (c >= s.tk.n) {
            rch_diag_set(d, name, s.tk.t[i].line, s.tk.t[i].col,
                         "'[' not closed (or a bracket of another kind closes first, or nested deeper than 64)");
            rc = -1;
            break;
        }
        if (rch_rpi_classify(&s, i, c) != 0)
            rc = -1;
        i = c; /* an aggregate's inside is its own */
    }
    if (rc == 0 && rch_rpi_note_uses(&s) != 0)
        rc = -1;
    for (size_t k = 0; rc == 0 && k < out->n; ++k) {
        rch_rapid_target *t = &out->t[k];
        for (size_t j = 0; j < s.ntools; ++j)
            if (strcasecmp(t->tool, s.tools[j].name) == 0) {
                t->tool_declared = 1;
                t->tool_robhold = s.tools[j].robhold;
                memcpy(t->tool_frame, s.tools[j].tf, sizeof t->tool_frame);
            }
        for (size_t j = 0; j < s.nwobjs; ++j)
            if (strcasecmp(t->wobj, s.wobjs[j].name) == 0) {
                t->wobj_declared = 1;
                t->wobj_robhold = s.wobjs[j].robhold;
                t->wobj_ufprog = s.wobjs[j].ufprog;
                snprintf(t->wobj_ufmec, sizeof t->wobj_ufmec, "%s", s.wobjs[j].ufmec);
                memcpy(t->wobj_uframe, s.wobjs[j].uf, sizeof t->wobj_uframe);
                memcpy(t->wobj_oframe, s.wobjs[j].of, sizeof t->wobj_oframe);
            }
    }
    /* a closing bracket with no opening one */
    for (size_t i = 0, depth = 0; rc == 0 && i < s.tk.n; ++i) {
        if (rch_rpi_punct(&s, i, '['))
            ++depth;
        else if (rch_rpi_punct(&s, i, ']') && depth-- == 0) {
            rch_diag_set(d, name, s.tk.t[i].line, s.tk.t[i].col, "']' with no '[' before it");
            rc = -1;
        }
    }
    free(s.tk.t);
    free(s.dc);
    free(s.dnext);
    if (rc != 0)
        rch_rapid_free(out); /* nothing half read is left */
    return rc;
}
