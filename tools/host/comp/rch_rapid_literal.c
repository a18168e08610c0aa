/* SPDX-License-Identifier: MIT */
/* rch_rapid_literal.c - the target literals of a RAPID module (see
 * rch_rapid_int.h): each top-level aggregate classified by its context (a
 * declaration's type, an assigned name's declaration, else its shape) into
 * joint targets and robtargets with every number's bytes, value, line and
 * column, or the reason it cannot be read (shape, not a literal number, a
 * target inside a RECORD, an undeclared name); arrays element by element;
 * the frames of literal tooldata and wobjdata declarations.
 * Depends on: the token queries (rch_rapid.c), the types and declarations
 * (rch_rapid_types.c), rch_parse_double (rch_opt). Memory: the targets on
 * the heap (s->out, rch_rapid_free). Errors: -1 with the scan's diag set
 * (out of memory); a target that cannot be read is listed with its error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_opt.h"
#include "rch_rapid_int.h"

/* The shape of an aggregate of aggregates of leaves, [[a,b],[c,d,e],...]. */
#define MAXG 6
#define MAXL 8
typedef struct {
    int ng;            /* groups; -1: not an aggregate of aggregates of leaves */
    int nl[MAXG];      /* leaves per group (counted past MAXL) */
    size_t lb[MAXG][MAXL], le[MAXG][MAXL]; /* leaf token range [lb, le) */
} shape;

/* Shape of the aggregate at token i (a '['), closing at c. */
static void shape_of(shape *sh, const rch_rpi_scan *s, size_t i, size_t c)
{
    memset(sh, 0, sizeof *sh);
    size_t j = i + 1;
    if (j == c)
        return; /* [] */
    for (;;) {
        if (!rch_rpi_punct(s, j, '[') || sh->ng >= MAXG) {
            sh->ng = -1;
            return;
        }
        const size_t gc = rch_rpi_close_of(s, j);
        if (gc >= c) {
            sh->ng = -1;
            return;
        }
        const int g = sh->ng++;
        size_t k = j + 1;
        while (k < gc) {
            const size_t b = k;
            while (k < gc && !rch_rpi_punct(s, k, ',')) {
                if (rch_rpi_punct(s, k, '[')) { /* nested deeper: not a target */
                    sh->ng = -1;
                    return;
                }
                if (rch_rpi_punct(s, k, '(') || rch_rpi_punct(s, k, '{')) {
                    const size_t cc = rch_rpi_close_of(s, k);
                    if (cc >= gc) { /* not closed inside the group */
                        sh->ng = -1;
                        return;
                    }
                    k = cc;
                }
                ++k;
            }
            if (sh->nl[g] < MAXL) {
                sh->lb[g][sh->nl[g]] = b;
                sh->le[g][sh->nl[g]] = k;
            }
            sh->nl[g]++;
            if (k < gc)
                ++k; /* ',' */
        }
        j = gc + 1;
        if (j >= c)
            return;
        if (!rch_rpi_punct(s, j, ',')) {
            sh->ng = -1;
            return;
        }
        ++j;
    }
}

static int shape_is(const shape *sh, rch_rapid_kind k)
{
    if (k == RCH_RAPID_JOINTTARGET)
        return sh->ng == 2 && sh->nl[0] == 6 && sh->nl[1] == 6;
    return sh->ng == 4 && sh->nl[0] == 3 && sh->nl[1] == 4 && sh->nl[2] == 4 && sh->nl[3] == 6;
}

static void shape_text(char *buf, size_t n, const shape *sh)
{
    if (sh->ng < 0) {
        snprintf(buf, n, "another form");
        return;
    }
    size_t k = (size_t)snprintf(buf, n, "[");
    for (int g = 0; g < sh->ng && k < n; ++g)
        k += (size_t)snprintf(buf + k, n - k, "%s[%d]", g ? "," : "", sh->nl[g]);
    if (k < n)
        snprintf(buf + k, n - k, "]");
}

static rch_rapid_target *new_target(rch_rpi_scan *s, size_t i, size_t c, rch_rapid_kind kind, rch_rapid_context ctx,
                                    const char *name)
{
    rch_rapid_targets *o = s->out;
    if (o->n == o->cap) {
        const size_t nc = o->cap ? 2 * o->cap : 32;
        rch_rapid_target *nt = realloc(o->t, nc * sizeof *nt);
        if (!nt) {
            rch_diag_set(s->d, s->name, s->tk.t[i].line, s->tk.t[i].col, "out of memory");
            return NULL;
        }
        o->t = nt;
        o->cap = nc;
    }
    rch_rapid_target *t = &o->t[o->n++];
    memset(t, 0, sizeof *t);
    t->kind = kind;
    t->context = ctx;
    t->line = s->tk.t[i].line;
    t->col = s->tk.t[i].col;
    t->off = s->tk.t[i].off;
    t->end = s->tk.t[c].off + 1;
    snprintf(t->name, sizeof t->name, "%s", name ? name : "");
    return t;
}

static const char *const jt_names[] = {"axis 1", "axis 2", "axis 3", "axis 4", "axis 5", "axis 6"};
static const char *const rt_names[] = {"x", "y", "z", "q1", "q2", "q3", "q4", "cf1", "cf4", "cf6", "cfx"};

static void extax_of(rch_rapid_target *t, const rch_rpi_scan *s, const shape *sh);

/* A target literal of kind at tokens [i, c]: its numbers, or its error. */
static int add_target(rch_rpi_scan *s, size_t i, size_t c, rch_rapid_kind kind, rch_rapid_context ctx, const char *name)
{
    shape sh;
    shape_of(&sh, s, i, c);
    rch_rapid_target *t = new_target(s, i, c, kind, ctx, name);
    if (!t)
        return -1;
    if (!shape_is(&sh, kind)) {
        char got[64];
        shape_text(got, sizeof got, &sh);
        snprintf(t->error, sizeof t->error, "a %s is %s; this aggregate is %s", rch_rapid_kind_name(kind),
                 kind == RCH_RAPID_JOINTTARGET ? "[[6 robot axes],[6 external axes]]"
                                               : "[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[6 external axes]]",
                 got);
        return 0;
    }
    const int ng = kind == RCH_RAPID_JOINTTARGET ? 1 : 3; /* groups whose numbers may change */
    unsigned k = 0;
    for (int g = 0; g < ng; ++g)
        for (int l = 0; l < sh.nl[g]; ++l, ++k) {
            size_t b = sh.lb[g][l];
            const size_t e = sh.le[g][l];
            const rch_rpi_tok *tb = &s->tk.t[b];
            const char *nm = kind == RCH_RAPID_JOINTTARGET ? jt_names[k] : rt_names[k];
            size_t nb = b;
            if (e - b == 2 && (rch_rpi_punct(s, b, '-') || rch_rpi_punct(s, b, '+')))
                nb = b + 1;
            char buf[64];
            const rch_rpi_tok *tn = &s->tk.t[nb];
            double v;
            int ok = e > b && nb + 1 == e && tn->type == RCH_RPI_NUM && tn->len < sizeof buf;
            if (ok) {
                memcpy(buf, s->text + tn->off, tn->len);
                buf[tn->len] = '\0';
                ok = rch_parse_double(buf, &v) == 0;
                if (ok && nb > b && rch_rpi_punct(s, b, '-'))
                    v = -v;
            }
            if (!ok) {
                const size_t from = tb->off, to = e > b ? s->tk.t[e - 1].off + s->tk.t[e - 1].len : from;
                const size_t w = to - from > 40 ? 40 : to - from;
                snprintf(t->error, sizeof t->error, "%s (line %u, column %u): '%.*s' is not a literal number", nm,
                         tb->line, tb->col, (int)w, s->text + from);
                t->n = 0;
                return 0;
            }
            t->num_off[k] = tb->off;
            t->num_len[k] = tn->off + tn->len - tb->off;
            t->num_line[k] = tb->line;
            t->num_col[k] = tb->col;
            t->val[k] = v;
        }
    t->n = k;
    if (kind == RCH_RAPID_ROBTARGET)
        extax_of(t, s, &sh);
    return 0;
}

/* A robtarget's external axes (group 3): the first one in use (a value
 * other than 9E9, or not a literal number) into t->extax_*. */
static void extax_of(rch_rapid_target *t, const rch_rpi_scan *s, const shape *sh)
{
    for (int l = 0; l < sh->nl[3] && l < MAXL; ++l) {
        const size_t b = sh->lb[3][l], e = sh->le[3][l];
        size_t nb = b;
        if (e - b == 2 && (rch_rpi_punct(s, b, '-') || rch_rpi_punct(s, b, '+')))
            nb = b + 1;
        const rch_rpi_tok *tn = &s->tk.t[nb];
        char buf[64];
        double v = NAN;
        if (e > b && nb + 1 == e && tn->type == RCH_RPI_NUM && tn->len < sizeof buf) {
            memcpy(buf, s->text + tn->off, tn->len);
            buf[tn->len] = '\0';
            if (rch_parse_double(buf, &v) != 0)
                v = NAN;
            else if (nb > b && rch_rpi_punct(s, b, '-'))
                v = -v;
        }
        if (!(fabs(v - 9e9) < 1.0)) {
            t->extax_used = (unsigned)l + 1;
            t->extax_val = v;
            t->extax_line = s->tk.t[b].line;
            t->extax_col = s->tk.t[b].col;
            return;
        }
    }
}

/* The value of a declaration or assignment of a target kind at tokens [i, c]:
 * one target, or, for an array, each element (nested arrays too). */
static int add_value(rch_rpi_scan *s, size_t i, size_t c, rch_rapid_kind kind, int array, rch_rapid_context ctx,
                     const char *name)
{
    if (!array)
        return add_target(s, i, c, kind, ctx, name);
    const size_t n0 = s->out->n;
    const char *bad = NULL;
    size_t j = i + 1;
    while (j < c && !bad) {
        if (!rch_rpi_punct(s, j, '[')) {
            bad = "an array of targets must list aggregates";
            break;
        }
        const size_t e = rch_rpi_close_of(s, j);
        if (e >= c) {
            bad = "brackets of another kind cross this aggregate";
            break;
        }
        shape sh;
        shape_of(&sh, s, j, e);
        /* an element of a 2-D array is itself an array of targets */
        const int deeper = sh.ng < 0 && j + 2 < e && rch_rpi_punct(s, j + 1, '[') && rch_rpi_punct(s, j + 2, '[');
        if (add_value(s, j, e, kind, deeper, ctx, name) != 0)
            return -1;
        j = e + 1;
        if (j < c && rch_rpi_punct(s, j, ','))
            ++j;
        else if (j < c)
            bad = "the elements of an array of targets must be separated by commas";
    }
    if (bad) { /* the whole array, named once */
        s->out->n = n0;
        rch_rapid_target *t = new_target(s, i, c, kind, ctx, name);
        if (!t)
            return -1;
        snprintf(t->error, sizeof t->error, "%s", bad);
    }
    return 0;
}

/* A pose literal [[x,y,z],[q1,q2,q3,q4]] at token i (a '['), closing before
 * c: v (7). The index of its ']', or s->tk.n when it is not one. */
static size_t read_frame(const rch_rpi_scan *s, size_t i, size_t c, double v[7])
{
    if (!rch_rpi_punct(s, i, '['))
        return s->tk.n;
    const size_t e = rch_rpi_close_of(s, i);
    if (e >= c)
        return s->tk.n;
    shape sh;
    shape_of(&sh, s, i, e);
    if (!(sh.ng == 2 && sh.nl[0] == 3 && sh.nl[1] == 4))
        return s->tk.n;
    for (int g = 0, k = 0; g < 2; ++g)
        for (int l = 0; l < sh.nl[g]; ++l, ++k) {
            size_t b = sh.lb[g][l];
            const size_t en = sh.le[g][l];
            int neg = 0;
            if (en - b == 2 && (rch_rpi_punct(s, b, '-') || rch_rpi_punct(s, b, '+'))) {
                neg = rch_rpi_punct(s, b, '-');
                ++b;
            }
            const rch_rpi_tok *t = &s->tk.t[b];
            char buf[64];
            if (!(en == b + 1 && t->type == RCH_RPI_NUM && t->len < sizeof buf))
                return s->tk.n;
            memcpy(buf, s->text + t->off, t->len);
            buf[t->len] = '\0';
            if (rch_parse_double(buf, &v[k]) != 0)
                return s->tk.n;
            if (neg)
                v[k] = -v[k];
        }
    return e;
}

static int read_bool(const rch_rpi_scan *s, size_t i)
{
    return rch_rpi_tok_is(s, i, "TRUE") ? 1 : rch_rpi_tok_is(s, i, "FALSE") ? 0 : -1;
}

/* A tooldata literal [robhold, [[x,y,z],[q1..q4]], load]: its frame. */
static void note_tooldata(rch_rpi_scan *s, size_t i, size_t c, const char *name)
{
    double v[7] = {0};
    const int hold = read_bool(s, i + 1);
    if (s->ntools == sizeof s->tools / sizeof s->tools[0] || hold < 0 || !rch_rpi_punct(s, i + 2, ',') ||
        read_frame(s, i + 3, c, v) >= c)
        return;
    snprintf(s->tools[s->ntools].name, sizeof s->tools[0].name, "%s", name);
    s->tools[s->ntools].robhold = hold;
    memcpy(s->tools[s->ntools].tf, v, sizeof v);
    s->ntools++;
}

/* A wobjdata literal [robhold, ufprog, ufmec, uframe, oframe]: its frames. */
static void note_wobjdata(rch_rpi_scan *s, size_t i, size_t c, const char *name)
{
    rch_rpi_wobj w;
    memset(&w, 0, sizeof w);
    w.robhold = read_bool(s, i + 1);
    w.ufprog = read_bool(s, i + 3);
    if (s->nwobjs == sizeof s->wobjs / sizeof s->wobjs[0] || w.robhold < 0 || w.ufprog < 0 ||
        !rch_rpi_punct(s, i + 2, ',') ||
        !rch_rpi_punct(s, i + 4, ',') || s->tk.t[i + 5].type != RCH_RPI_STR || !rch_rpi_punct(s, i + 6, ','))
        return;
    const rch_rpi_tok *st = &s->tk.t[i + 5]; /* "..." without its quotes */
    snprintf(w.ufmec, sizeof w.ufmec, "%.*s", (int)(st->len >= 2 ? st->len - 2 : 0), s->text + st->off + 1);
    const size_t e = read_frame(s, i + 7, c, w.uf);
    if (e >= c || !rch_rpi_punct(s, e + 1, ',') || read_frame(s, e + 2, c, w.of) >= c)
        return;
    snprintf(w.name, sizeof w.name, "%s", name);
    s->wobjs[s->nwobjs++] = w;
}

/* A value of a RECORD type that holds a target: listed with its error. */
static int record_target(rch_rpi_scan *s, size_t i, size_t c, const rch_rpi_utype *u, rch_rapid_context ctx,
                         const char *name)
{
    rch_rapid_target *t = new_target(s, i, c, (rch_rapid_kind)u->kind, ctx, name);
    if (!t)
        return -1;
    snprintf(t->error, sizeof t->error,
             "a %s inside the RECORD %.40s (field %.60s): rcal corrects only targets declared as jointtarget, "
             "robtarget or an ALIAS of them; declare it as a %s of its own",
             rch_rapid_kind_name((rch_rapid_kind)u->kind), u->name, u->field,
             rch_rapid_kind_name((rch_rapid_kind)u->kind));
    return 0;
}

/* The target the aggregate at token i (closing at c) stands for, from what
 * precedes it. */
int rch_rpi_classify(rch_rpi_scan *s, size_t i, size_t c)
{
    char nm[48] = "";
    if (i >= 2 && s->tk.t[i - 1].type == RCH_RPI_ASSIGN) {
        size_t k = i - 2; /* the assigned name, past {dims} or {index} */
        int indexed = 0;
        if (rch_rpi_punct(s, k, '}')) {
            size_t depth = 0;
            for (;; --k) {
                if (rch_rpi_punct(s, k, '}'))
                    ++depth;
                else if (rch_rpi_punct(s, k, '{') && --depth == 0)
                    break;
                if (k == 0)
                    break;
            }
            if (k == 0)
                return 0;
            --k;
            indexed = 1;
        }
        if (s->tk.t[k].type == RCH_RPI_IDENT) {
            rch_rpi_tok_name(nm, sizeof nm, s, k);
            /* a declaration: [VAR|PERS|CONST] TYPE NAME */
            if (k >= 2 && s->tk.t[k - 1].type == RCH_RPI_IDENT &&
                (rch_rpi_tok_is(s, k - 2, "VAR") || rch_rpi_tok_is(s, k - 2, "PERS") ||
                 rch_rpi_tok_is(s, k - 2, "CONST"))) {
                const int kind = rch_rpi_target_type(s, k - 1);
                const rch_rpi_utype *u = rch_rpi_find_utype(s, k - 1);
                if (kind == 0 && rch_rpi_tok_is(s, k - 1, "tooldata") && !indexed)
                    note_tooldata(s, i, c, nm);
                if (kind == 0 && rch_rpi_tok_is(s, k - 1, "wobjdata") && !indexed)
                    note_wobjdata(s, i, c, nm);
                if (kind == 0 && u && !u->alias)
                    return record_target(s, i, c, u, RCH_RAPID_DECLARATION, nm);
                if (kind == 0)
                    return 0; /* another type: not a target */
                return add_value(s, i, c, (rch_rapid_kind)kind, indexed, RCH_RAPID_DECLARATION, nm);
            }
            const int field = k > 0 && rch_rpi_punct(s, k - 1, '.');
            const int optarg = k > 0 && rch_rpi_punct(s, k - 1, '\\');
            if (!field && !optarg) {
                const rch_rpi_decl *dc = rch_rpi_find_decl(s, k);
                if (dc && dc->kind > 0)
                    return add_value(s, i, c, (rch_rapid_kind)dc->kind, dc->array && !indexed, RCH_RAPID_ASSIGNMENT,
                                     nm);
                shape sh;
                shape_of(&sh, s, i, c);
                if (dc && dc->kind == 0 && dc->rec >= 0)
                    return record_target(s, i, c, &s->ut[dc->rec], RCH_RAPID_ASSIGNMENT, nm);
                if (dc && dc->kind == 0)
                    return 0; /* declared here with another type */
                if (shape_is(&sh, RCH_RAPID_JOINTTARGET) || shape_is(&sh, RCH_RAPID_ROBTARGET)) {
                    rch_rapid_target *t =
                        new_target(s, i, c, shape_is(&sh, RCH_RAPID_JOINTTARGET) ? RCH_RAPID_JOINTTARGET
                                                                                 : RCH_RAPID_ROBTARGET,
                                   RCH_RAPID_ASSIGNMENT, nm);
                    if (!t)
                        return -1;
                    snprintf(t->error, sizeof t->error,
                             "'%s' has the form of a %s but %s in this module, so its type cannot be told", nm,
                             rch_rapid_kind_name(t->kind), dc ? "is declared with two types" : "is not declared");
                }
                return 0;
            }
        }
    }
    /* inline: the shape decides */
    shape sh;
    shape_of(&sh, s, i, c);
    if (shape_is(&sh, RCH_RAPID_JOINTTARGET))
        return add_target(s, i, c, RCH_RAPID_JOINTTARGET, RCH_RAPID_INLINE, nm);
    if (shape_is(&sh, RCH_RAPID_ROBTARGET))
        return add_target(s, i, c, RCH_RAPID_ROBTARGET, RCH_RAPID_INLINE, nm);
    return 0;
}
