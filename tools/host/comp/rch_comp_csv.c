/* SPDX-License-Identifier: MIT */
/* rch_comp_csv.c - CSV target lists through the compensation (see
 * rch_comp.h): the fields of a line, its strict numbers, a header's q1..q6
 * (or j1..j6) columns, and each line's joints corrected ("%.6f") with every
 * other field copied.
 * Depends on: one target (rch_comp.c), rch_parse_double (rch_opt).
 * Memory: none. Errors: -1 with d set (file:line:col). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_comp_int.h"
#include "rch_data.h"
#include "rch_opt.h"

/* Split a line at commas. start[k]/len[k]: field k (trimmed); returns the
 * number of fields, or -1 when more than RCH_CPI_MAX_FIELDS. */
int rch_cpi_split_csv(const char *line, size_t n, size_t start[RCH_CPI_MAX_FIELDS], size_t len[RCH_CPI_MAX_FIELDS])
{
    int k = 0;
    size_t i = 0;
    for (;;) {
        if (k >= RCH_CPI_MAX_FIELDS)
            return -1;
        size_t b = i;
        while (b < n && (line[b] == ' ' || line[b] == '\t'))
            ++b;
        size_t e = b;
        while (e < n && line[e] != ',')
            ++e;
        size_t end = e;
        while (end > b && (line[end - 1] == ' ' || line[end - 1] == '\t' || line[end - 1] == '\r'))
            --end;
        start[k] = b;
        len[k] = end - b;
        ++k;
        if (e >= n)
            break;
        i = e + 1;
    }
    return k;
}

/* Parse a number occupying exactly text[0..len) (the strict reader of
 * rch_opt.h: no blanks, no hex, finite). */
int rch_cpi_parse_num(double *v, const char *text, size_t len)
{
    char buf[64];
    if (len == 0 || len >= sizeof buf)
        return -1;
    memcpy(buf, text, len);
    buf[len] = '\0';
    return rch_parse_double(buf, v);
}

int rch_cpi_csv_hold(rch_cpi_ctx *c, rch_diag *d)
{
    c->held_buf = NULL;
    c->held_len = 0;
    c->held = open_memstream(&c->held_buf, &c->held_len);
    if (!c->held) {
        rch_diag_set(d, c->in_name, 0, 0, "out of memory");
        return -1;
    }
    c->held_out = c->out;
    c->out = c->held;
    return 0;
}

static void unhold(rch_cpi_ctx *c, int write)
{
    if (!c->held)
        return;
    const int ok = fclose(c->held) == 0;
    c->out = c->held_out;
    if (write && ok && c->held_len > 0)
        fwrite(c->held_buf, 1, c->held_len, c->out);
    free(c->held_buf);
    c->held = NULL;
    c->held_buf = NULL;
    c->held_len = 0;
}

void rch_cpi_csv_release(rch_cpi_ctx *c)
{
    unhold(c, 1);
}

void rch_cpi_csv_drop(rch_cpi_ctx *c)
{
    unhold(c, 0);
}

/* One CSV line (not blank, not a comment). 0 ok, 1 not converged, -1 error. */
int rch_cpi_csv_line(rch_cpi_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    size_t st[RCH_CPI_MAX_FIELDS], ln[RCH_CPI_MAX_FIELDS];
    const int nf = rch_cpi_split_csv(line, n, st, ln);
    if (nf < 0) {
        rch_diag_set(d, c->in_name, lineno, 1, "more than %d fields", RCH_CPI_MAX_FIELDS);
        return -1;
    }
    if (!c->have_header) {
        if (nf != RC_NJ) {
            rch_diag_set(d, c->in_name, lineno, (unsigned)(nf > RC_NJ ? st[RC_NJ] + 1 : n + 1),
                         "expected 6 joint angles q1..q6 in degrees, found %d field%s", nf, nf == 1 ? "" : "s");
            return -1;
        }
    } else if ((unsigned)nf != c->nfields_header) {
        rch_diag_set(d, c->in_name, lineno, (unsigned)((unsigned)nf > c->nfields_header ? st[c->nfields_header] + 1 : n + 1),
                     "expected %u fields as in the header, found %d", c->nfields_header, nf);
        return -1;
    }
    double qd[RC_NJ], qo[RC_NJ];
    unsigned cols[RC_NJ];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const int k = c->have_header ? c->qcol[i] : (int)i;
        cols[i] = (unsigned)st[k] + 1;
        if (rch_cpi_parse_num(&qd[i], line + st[k], ln[k]) != 0) {
            rch_diag_set(d, c->in_name, lineno, cols[i], "q%u: '%.*s' is not a finite number", i + 1,
                         (int)(ln[k] > 40 ? 40 : ln[k]), line + st[k]);
            return -1;
        }
    }
    /* the radians check (rch_data_q_look_rad): a value beyond pi says degrees, and what was held goes out */
    int beyond = 0;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        c->max_abs_deg[i] = fmax(c->max_abs_deg[i], fabs(qd[i]));
        beyond |= !(c->max_abs_deg[i] <= RCH_DATA_RAD_BOUND);
    }
    ++c->n_targets;
    if (beyond)
        rch_cpi_csv_release(c);
    /* the controller's joints (a KUKA's A1, a Fanuc's J3 from the horizon) to the model's and back */
    const rch_ctrl *ctl = c->gate && c->gate->ctrl && !c->gate->ctrl->identity_joints ? c->gate->ctrl : NULL;
    if (ctl) {
        for (unsigned i = 0; i < RC_NJ; ++i)
            qd[i] *= DEG;
        rch_ctrl_to_model(qd, ctl, qd);
        for (unsigned i = 0; i < RC_NJ; ++i)
            qd[i] /= DEG;
    }
    const int r = rch_cpi_compensate(c, qo, qd, lineno, cols, d);
    if (r < 0)
        return r;
    if (ctl) {
        for (unsigned i = 0; i < RC_NJ; ++i)
            qo[i] *= DEG;
        rch_ctrl_from_model(qo, ctl, qo);
        for (unsigned i = 0; i < RC_NJ; ++i)
            qo[i] /= DEG;
    }
    for (int k = 0; k < nf; ++k) {
        int j = -1;
        for (int i = 0; i < RC_NJ; ++i)
            if ((c->have_header ? c->qcol[i] : i) == k)
                j = i;
        if (k > 0)
            fputc(',', c->out);
        if (j >= 0)
            fprintf(c->out, "%.6f", qo[j]);
        else
            fwrite(line + st[k], 1, ln[k], c->out);
    }
    fputs(c->eol ? c->eol : "\n", c->out);
    return r;
}

/* Header line: find q1..q6 (or j1..j6). 0 or -1. */
int rch_cpi_csv_header(rch_cpi_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    size_t st[RCH_CPI_MAX_FIELDS], ln[RCH_CPI_MAX_FIELDS];
    const int nf = rch_cpi_split_csv(line, n, st, ln);
    if (nf < 0) {
        rch_diag_set(d, c->in_name, lineno, 1, "more than %d header fields", RCH_CPI_MAX_FIELDS);
        return -1;
    }
    for (int i = 0; i < RC_NJ; ++i) {
        c->qcol[i] = -1;
        for (int k = 0; k < nf; ++k) {
            char qn[3] = {'q', (char)('1' + i), '\0'}, jn[3] = {'j', (char)('1' + i), '\0'};
            if (ln[k] == 2 && (strncasecmp(line + st[k], qn, 2) == 0 || strncasecmp(line + st[k], jn, 2) == 0)) {
                if (c->qcol[i] >= 0) {
                    rch_diag_set(d, c->in_name, lineno, (unsigned)st[k] + 1, "column q%d appears twice", i + 1);
                    return -1;
                }
                c->qcol[i] = k;
            }
        }
        if (c->qcol[i] < 0) {
            /* a first line of numbers (or nan, inf) is a target, not a header */
            char *end = NULL;
            (void)strtod(line + st[0], &end);
            const int numeric = nf > 0 && end != line + st[0] && (size_t)(end - line) == st[0] + ln[0];
            rch_diag_set(d, c->in_name, lineno, 1, "header has no q%d column (need q1..q6, degrees)%s", i + 1,
                         numeric ? ": this first line holds numbers, a target; put a header line "
                                   "q1,q2,q3,q4,q5,q6 above the targets"
                                 : "");
            return -1;
        }
    }
    c->have_header = 1;
    c->nfields_header = (unsigned)nf;
    fwrite(line, 1, n, c->out);
    fputs(c->eol ? c->eol : "\n", c->out);
    return 0;
}
