/* SPDX-License-Identifier: MIT */
/* rch_rapid.c - the RAPID reader (rch_rapid.h): tokens, declarations, and
 * every joint target and robtarget literal with its numbers' bytes. */
#include "rch_rapid.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_opt.h"

typedef enum { T_IDENT, T_NUM, T_STR, T_ASSIGN, T_PUNCT } tok_type;

typedef struct {
    tok_type type;
    char ch; /* T_PUNCT: the character */
    size_t off, len;
    unsigned line, col;
} tok;

typedef struct {
    tok *t;
    size_t n, cap;
} toks;

/* a name declared in the module */
typedef struct {
    char name[48];
    char type[32]; /* its declared type */
    int kind;      /* rch_rapid_kind, 0: another type, -1: declared with two types */
    int array;     /* declared with {dims} */
    int rec;       /* its type is the record recs[rec] that holds a target, or -1 */
} decl;

/* a type name the module defines: ALIAS robtarget NAME (kind), or a RECORD
 * with a target field (field names it, kind its kind) */
typedef struct {
    char name[48], field[96];
    int kind;
    int alias; /* 1 ALIAS, 0 RECORD */
} utype;

/* a work object the module declares with a literal wobjdata */
typedef struct {
    char name[48], ufmec[48];
    int robhold, ufprog;
    double uf[7], of[7];
} wobj_decl;

typedef struct {
    const char *text;
    size_t len;
    const char *name;
    toks tk;
    decl *dc;
    size_t ndc, capdc;
    size_t *dnext;           /* (capdc) the next declaration in the same hash bucket */
    size_t dhead[1024];      /* first declaration of each bucket, or (size_t)-1 */
    rch_rapid_targets *out;
    rch_diag *d;
    struct {
        char name[48];
        int robhold;    /* 1 TRUE, 0 FALSE */
        double tf[7];   /* tframe: trans (mm, tool0 frame), rot (quaternion) */
    } tools[32];
    size_t ntools;
    wobj_decl wobjs[32];
    size_t nwobjs;
    utype ut[32]; /* ALIAS and RECORD types (more are not read) */
    size_t nut;
} scan;

static int push_tok(scan *s, tok_type ty, char ch, size_t off, size_t len, unsigned line, unsigned col)
{
    if (s->tk.n == s->tk.cap) {
        const size_t nc = s->tk.cap ? 2 * s->tk.cap : 256;
        tok *nt = realloc(s->tk.t, nc * sizeof *nt);
        if (!nt) {
            rch_diag_set(s->d, s->name, line, col, "out of memory");
            return -1;
        }
        s->tk.t = nt;
        s->tk.cap = nc;
    }
    s->tk.t[s->tk.n++] = (tok){ty, ch, off, len, line, col};
    return 0;
}

static int is_id(int c) { return isalnum(c) || c == '_'; }

/* text -> tokens (comments dropped). 0 or -1. */
static int tokenize(scan *s)
{
    const char *p = s->text;
    size_t i = 0;
    unsigned line = 1, col = 1;
#define ADV(k)                                                                                                     \
    do {                                                                                                           \
        for (size_t a_ = 0; a_ < (k); ++a_, ++i) {                                                                 \
            if (p[i] == '\n') {                                                                                    \
                ++line;                                                                                            \
                col = 1;                                                                                           \
            } else                                                                                                 \
                ++col;                                                                                             \
        }                                                                                                          \
    } while (0)
    while (i < s->len) {
        const unsigned char c = (unsigned char)p[i];
        const size_t b = i;
        const unsigned bl = line, bc = col;
        if (c == '\0') {
            rch_diag_set(s->d, s->name, line, col, "NUL byte in a RAPID module");
            return -1;
        }
        if (isspace(c)) {
            ADV(1);
        } else if (c == '!') { /* comment to the end of the line */
            while (i < s->len && p[i] != '\n') {
                if (p[i] == '\0') {
                    rch_diag_set(s->d, s->name, line, col, "NUL byte in a RAPID module");
                    return -1;
                }
                ADV(1);
            }
        } else if (c == '"') {
            ADV(1);
            for (;;) {
                if (i >= s->len || p[i] == '\n' || p[i] == '\0') {
                    rch_diag_set(s->d, s->name, bl, bc, "string not closed on its line");
                    return -1;
                }
                if (p[i] == '"') {
                    if (i + 1 < s->len && p[i + 1] == '"') {
                        ADV(2);
                        continue;
                    }
                    ADV(1);
                    break;
                }
                ADV(1);
            }
            if (push_tok(s, T_STR, 0, b, i - b, bl, bc) != 0)
                return -1;
        } else if (isdigit(c) || (c == '.' && i + 1 < s->len && isdigit((unsigned char)p[i + 1]))) {
            while (i < s->len) {
                const unsigned char e = (unsigned char)p[i];
                if (is_id(e) || e == '.')
                    ADV(1);
                else if ((e == '+' || e == '-') && (p[i - 1] == 'e' || p[i - 1] == 'E') && isdigit((unsigned char)p[b]))
                    ADV(1);
                else
                    break;
            }
            if (push_tok(s, T_NUM, 0, b, i - b, bl, bc) != 0)
                return -1;
        } else if (is_id(c)) {
            while (i < s->len && is_id((unsigned char)p[i]))
                ADV(1);
            if (push_tok(s, T_IDENT, 0, b, i - b, bl, bc) != 0)
                return -1;
        } else if (c == ':' && i + 1 < s->len && p[i + 1] == '=') {
            ADV(2);
            if (push_tok(s, T_ASSIGN, 0, b, 2, bl, bc) != 0)
                return -1;
        } else {
            ADV(1);
            if (push_tok(s, T_PUNCT, (char)c, b, 1, bl, bc) != 0)
                return -1;
        }
    }
#undef ADV
    return 0;
}

static int tok_is(const scan *s, size_t i, const char *w)
{
    const tok *t = &s->tk.t[i];
    return t->type == T_IDENT && t->len == strlen(w) && strncasecmp(s->text + t->off, w, t->len) == 0;
}

static int punct(const scan *s, size_t i, char ch)
{
    return i < s->tk.n && s->tk.t[i].type == T_PUNCT && s->tk.t[i].ch == ch;
}

static void tok_name(char *buf, size_t n, const scan *s, size_t i)
{
    const tok *t = &s->tk.t[i];
    const size_t k = t->len < n - 1 ? t->len : n - 1;
    memcpy(buf, s->text + t->off, k);
    buf[k] = '\0';
}

/* Index of the bracket closing the one at i ('[', '(' or '{'), or s->tk.n
 * when it is not closed, a bracket of another kind closes first, or the
 * nesting is deeper than 64. */
static size_t close_of(const scan *s, size_t i)
{
    char open[64];
    size_t depth = 0;
    for (size_t j = i; j < s->tk.n; ++j) {
        const tok *t = &s->tk.t[j];
        if (t->type != T_PUNCT)
            continue;
        if (t->ch == '[' || t->ch == '(' || t->ch == '{') {
            if (depth == sizeof open)
                return s->tk.n;
            open[depth++] = t->ch;
        } else if (t->ch == ']' || t->ch == ')' || t->ch == '}') {
            char want = '{';
            if (t->ch == ']')
                want = '[';
            else if (t->ch == ')')
                want = '(';
            if (depth == 0 || open[depth - 1] != want)
                return s->tk.n;
            if (--depth == 0)
                return j;
        }
    }
    return s->tk.n;
}

static int base_target_type(const scan *s, size_t i)
{
    if (tok_is(s, i, "jointtarget"))
        return RCH_RAPID_JOINTTARGET;
    if (tok_is(s, i, "robtarget"))
        return RCH_RAPID_ROBTARGET;
    return 0;
}

/* The ALIAS or RECORD type named at token i, or NULL. */
static const utype *find_utype(const scan *s, size_t i)
{
    const tok *t = &s->tk.t[i];
    if (t->type != T_IDENT)
        return NULL;
    for (size_t k = 0; k < s->nut; ++k)
        if (strlen(s->ut[k].name) == t->len && strncasecmp(s->ut[k].name, s->text + t->off, t->len) == 0)
            return &s->ut[k];
    return NULL;
}

/* The target kind of the type named at token i: jointtarget, robtarget or an ALIAS of them. */
static int target_type(const scan *s, size_t i)
{
    const int k = base_target_type(s, i);
    if (k)
        return k;
    const utype *u = find_utype(s, i);
    return u && u->alias ? u->kind : 0;
}

/* ALIAS robtarget NAME; and RECORD NAME ... ENDRECORD with a field of a
 * target type (or of a record that holds one), nested records in any order. */
static void collect_types(scan *s)
{
    const size_t cap = sizeof s->ut / sizeof s->ut[0];
    for (size_t i = 0; i + 2 < s->tk.n && s->nut < cap; ++i)
        if (tok_is(s, i, "ALIAS") && s->tk.t[i + 2].type == T_IDENT && base_target_type(s, i + 1)) {
            utype *u = &s->ut[s->nut++];
            tok_name(u->name, sizeof u->name, s, i + 2);
            u->field[0] = '\0';
            u->kind = base_target_type(s, i + 1);
            u->alias = 1;
        }
    for (int pass = 0; pass < 4; ++pass)
        for (size_t i = 0; i + 1 < s->tk.n && s->nut < cap; ++i) {
            if (!tok_is(s, i, "RECORD") || s->tk.t[i + 1].type != T_IDENT || find_utype(s, i + 1))
                continue;
            /* fields: TYPE NAME [{dims}] ; up to ENDRECORD */
            for (size_t j = i + 2; j + 1 < s->tk.n && !tok_is(s, j, "ENDRECORD"); ++j) {
                if (s->tk.t[j].type != T_IDENT || s->tk.t[j + 1].type != T_IDENT || (j > 0 && !punct(s, j - 1, ';') && j != i + 2))
                    continue;
                const utype *inner = find_utype(s, j);
                const int kind = target_type(s, j);
                if (!kind && !(inner && !inner->alias))
                    continue;
                utype *u = &s->ut[s->nut++];
                tok_name(u->name, sizeof u->name, s, i + 1);
                char fn[48];
                tok_name(fn, sizeof fn, s, j + 1);
                if (kind) {
                    snprintf(u->field, sizeof u->field, "%s", fn);
                    u->kind = kind;
                } else {
                    snprintf(u->field, sizeof u->field, "%.40s.%.40s", fn, inner->field);
                    u->kind = inner->kind;
                }
                u->alias = 0;
                break;
            }
        }
}

static unsigned hash_ci(const char *p, size_t n)
{
    unsigned h = 2166136261u;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ (unsigned)tolower((unsigned char)p[i])) * 16777619u;
    return h;
}

static const decl *find_decl(const scan *s, size_t i)
{
    const tok *t = &s->tk.t[i];
    const size_t nb = sizeof s->dhead / sizeof s->dhead[0];
    for (size_t k = s->dhead[hash_ci(s->text + t->off, t->len) % nb]; k != (size_t)-1; k = s->dnext[k])
        if (strlen(s->dc[k].name) == t->len && strncasecmp(s->dc[k].name, s->text + t->off, t->len) == 0)
            return &s->dc[k];
    return NULL;
}

/* Declarations: VAR|PERS|CONST TYPE NAME. Names of target types are kept. */
static int collect_decls(scan *s)
{
    const size_t nb = sizeof s->dhead / sizeof s->dhead[0];
    for (size_t b = 0; b < nb; ++b)
        s->dhead[b] = (size_t)-1;
    for (size_t i = 0; i + 2 < s->tk.n; ++i) {
        if (!(tok_is(s, i, "VAR") || tok_is(s, i, "PERS") || tok_is(s, i, "CONST")))
            continue;
        if (s->tk.t[i + 1].type != T_IDENT || s->tk.t[i + 2].type != T_IDENT)
            continue;
        const int kind = target_type(s, i + 1);
        const int array = punct(s, i + 3, '{');
        const utype *rt = find_utype(s, i + 1);
        decl *old = (decl *)find_decl(s, i + 2);
        if (old) {
            if (old->kind != kind || old->array != array)
                old->kind = -1; /* two meanings in one module: its assignments are not guessed */
            continue;
        }
        if (s->ndc == s->capdc) {
            const size_t nc = s->capdc ? 2 * s->capdc : 32;
            decl *nd = realloc(s->dc, nc * sizeof *nd);
            if (nd)
                s->dc = nd;
            size_t *nn = nd ? realloc(s->dnext, nc * sizeof *nn) : NULL;
            if (!nd || !nn) {
                rch_diag_set(s->d, s->name, s->tk.t[i].line, s->tk.t[i].col, "out of memory");
                return -1;
            }
            s->dnext = nn;
            s->capdc = nc;
        }
        decl *dn = &s->dc[s->ndc];
        memset(dn, 0, sizeof *dn);
        tok_name(dn->name, sizeof dn->name, s, i + 2);
        dn->kind = kind;
        dn->array = array;
        tok_name(dn->type, sizeof dn->type, s, i + 1);
        dn->rec = rt && !rt->alias ? (int)(rt - s->ut) : -1;
        const unsigned h = hash_ci(dn->name, strlen(dn->name)) % nb;
        s->dnext[s->ndc] = s->dhead[h];
        s->dhead[h] = s->ndc++;
    }
    return 0;
}

/* The shape of an aggregate of aggregates of leaves, [[a,b],[c,d,e],...]. */
#define MAXG 6
#define MAXL 8
typedef struct {
    int ng;            /* groups; -1: not an aggregate of aggregates of leaves */
    int nl[MAXG];      /* leaves per group (counted past MAXL) */
    size_t lb[MAXG][MAXL], le[MAXG][MAXL]; /* leaf token range [lb, le) */
} shape;

/* Shape of the aggregate at token i (a '['), closing at c. */
static void shape_of(shape *sh, const scan *s, size_t i, size_t c)
{
    memset(sh, 0, sizeof *sh);
    size_t j = i + 1;
    if (j == c)
        return; /* [] */
    for (;;) {
        if (!punct(s, j, '[') || sh->ng >= MAXG) {
            sh->ng = -1;
            return;
        }
        const size_t gc = close_of(s, j);
        if (gc >= c) {
            sh->ng = -1;
            return;
        }
        const int g = sh->ng++;
        size_t k = j + 1;
        while (k < gc) {
            const size_t b = k;
            while (k < gc && !punct(s, k, ',')) {
                if (punct(s, k, '[')) { /* nested deeper: not a target */
                    sh->ng = -1;
                    return;
                }
                if (punct(s, k, '(') || punct(s, k, '{')) {
                    const size_t cc = close_of(s, k);
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
        if (!punct(s, j, ',')) {
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

static rch_rapid_target *new_target(scan *s, size_t i, size_t c, rch_rapid_kind kind, rch_rapid_context ctx,
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

/* A target literal of kind at tokens [i, c]: its numbers, or its error. */
static int add_target(scan *s, size_t i, size_t c, rch_rapid_kind kind, rch_rapid_context ctx, const char *name)
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
            const tok *tb = &s->tk.t[b];
            const char *nm = kind == RCH_RAPID_JOINTTARGET ? jt_names[k] : rt_names[k];
            size_t nb = b;
            if (e - b == 2 && (punct(s, b, '-') || punct(s, b, '+')))
                nb = b + 1;
            char buf[64];
            const tok *tn = &s->tk.t[nb];
            double v;
            int ok = e > b && nb + 1 == e && tn->type == T_NUM && tn->len < sizeof buf;
            if (ok) {
                memcpy(buf, s->text + tn->off, tn->len);
                buf[tn->len] = '\0';
                ok = rch_parse_double(buf, &v) == 0;
                if (ok && nb > b && punct(s, b, '-'))
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
    return 0;
}

/* The value of a declaration or assignment of a target kind at tokens [i, c]:
 * one target, or, for an array, each element (nested arrays too). */
static int add_value(scan *s, size_t i, size_t c, rch_rapid_kind kind, int array, rch_rapid_context ctx,
                     const char *name)
{
    if (!array)
        return add_target(s, i, c, kind, ctx, name);
    const size_t n0 = s->out->n;
    const char *bad = NULL;
    size_t j = i + 1;
    while (j < c && !bad) {
        if (!punct(s, j, '[')) {
            bad = "an array of targets must list aggregates";
            break;
        }
        const size_t e = close_of(s, j);
        if (e >= c) {
            bad = "brackets of another kind cross this aggregate";
            break;
        }
        shape sh;
        shape_of(&sh, s, j, e);
        /* an element of a 2-D array is itself an array of targets */
        const int deeper = sh.ng < 0 && j + 2 < e && punct(s, j + 1, '[') && punct(s, j + 2, '[');
        if (add_value(s, j, e, kind, deeper, ctx, name) != 0)
            return -1;
        j = e + 1;
        if (j < c && punct(s, j, ','))
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
static size_t read_frame(const scan *s, size_t i, size_t c, double v[7])
{
    if (!punct(s, i, '['))
        return s->tk.n;
    const size_t e = close_of(s, i);
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
            if (en - b == 2 && (punct(s, b, '-') || punct(s, b, '+'))) {
                neg = punct(s, b, '-');
                ++b;
            }
            const tok *t = &s->tk.t[b];
            char buf[64];
            if (!(en == b + 1 && t->type == T_NUM && t->len < sizeof buf))
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

static int read_bool(const scan *s, size_t i)
{
    return tok_is(s, i, "TRUE") ? 1 : tok_is(s, i, "FALSE") ? 0 : -1;
}

/* A tooldata literal [robhold, [[x,y,z],[q1..q4]], load]: its frame. */
static void note_tooldata(scan *s, size_t i, size_t c, const char *name)
{
    double v[7] = {0};
    const int hold = read_bool(s, i + 1);
    if (s->ntools == sizeof s->tools / sizeof s->tools[0] || hold < 0 || !punct(s, i + 2, ',') ||
        read_frame(s, i + 3, c, v) >= c)
        return;
    snprintf(s->tools[s->ntools].name, sizeof s->tools[0].name, "%s", name);
    s->tools[s->ntools].robhold = hold;
    memcpy(s->tools[s->ntools].tf, v, sizeof v);
    s->ntools++;
}

/* A wobjdata literal [robhold, ufprog, ufmec, uframe, oframe]: its frames. */
static void note_wobjdata(scan *s, size_t i, size_t c, const char *name)
{
    wobj_decl w;
    memset(&w, 0, sizeof w);
    w.robhold = read_bool(s, i + 1);
    w.ufprog = read_bool(s, i + 3);
    if (s->nwobjs == sizeof s->wobjs / sizeof s->wobjs[0] || w.robhold < 0 || w.ufprog < 0 || !punct(s, i + 2, ',') ||
        !punct(s, i + 4, ',') || s->tk.t[i + 5].type != T_STR || !punct(s, i + 6, ','))
        return;
    const tok *st = &s->tk.t[i + 5]; /* "..." without its quotes */
    snprintf(w.ufmec, sizeof w.ufmec, "%.*s", (int)(st->len >= 2 ? st->len - 2 : 0), s->text + st->off + 1);
    const size_t e = read_frame(s, i + 7, c, w.uf);
    if (e >= c || !punct(s, e + 1, ',') || read_frame(s, e + 2, c, w.of) >= c)
        return;
    snprintf(w.name, sizeof w.name, "%s", name);
    s->wobjs[s->nwobjs++] = w;
}

/* A value of a RECORD type that holds a target: listed with its error. */
static int record_target(scan *s, size_t i, size_t c, const utype *u, rch_rapid_context ctx, const char *name)
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
static int classify(scan *s, size_t i, size_t c)
{
    char nm[48] = "";
    if (i >= 2 && s->tk.t[i - 1].type == T_ASSIGN) {
        size_t k = i - 2; /* the assigned name, past {dims} or {index} */
        int indexed = 0;
        if (punct(s, k, '}')) {
            size_t depth = 0;
            for (;; --k) {
                if (punct(s, k, '}'))
                    ++depth;
                else if (punct(s, k, '{') && --depth == 0)
                    break;
                if (k == 0)
                    break;
            }
            if (k == 0)
                return 0;
            --k;
            indexed = 1;
        }
        if (s->tk.t[k].type == T_IDENT) {
            tok_name(nm, sizeof nm, s, k);
            /* a declaration: [VAR|PERS|CONST] TYPE NAME */
            if (k >= 2 && s->tk.t[k - 1].type == T_IDENT &&
                (tok_is(s, k - 2, "VAR") || tok_is(s, k - 2, "PERS") || tok_is(s, k - 2, "CONST"))) {
                const int kind = target_type(s, k - 1);
                const utype *u = find_utype(s, k - 1);
                if (kind == 0 && tok_is(s, k - 1, "tooldata") && !indexed)
                    note_tooldata(s, i, c, nm);
                if (kind == 0 && tok_is(s, k - 1, "wobjdata") && !indexed)
                    note_wobjdata(s, i, c, nm);
                if (kind == 0 && u && !u->alias)
                    return record_target(s, i, c, u, RCH_RAPID_DECLARATION, nm);
                if (kind == 0)
                    return 0; /* another type: not a target */
                return add_value(s, i, c, (rch_rapid_kind)kind, indexed, RCH_RAPID_DECLARATION, nm);
            }
            const int field = k > 0 && punct(s, k - 1, '.');
            const int optarg = k > 0 && punct(s, k - 1, '\\');
            if (!field && !optarg) {
                const decl *dc = find_decl(s, k);
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

/* The instructions whose target arguments and tool rcal reads, with ABB's
 * argument order (RAPID reference manual): the positional arguments counted
 * from 0, every optional one (\Conc, \ID:=, \T:=, \WObj:=, ...) skipped. */
typedef struct {
    const char *name;
    unsigned char pt[3], npt; /* positions of its target arguments */
    signed char tool;         /* position of its Tool, -1: none */
} instr_desc;

static const instr_desc instrs[] = {
    {"MoveL", {0}, 1, 3},          {"MoveJ", {0}, 1, 3},          {"MoveC", {0, 1}, 2, 4},
    {"MoveAbsJ", {0}, 1, 3},       {"MoveLDO", {0}, 1, 3},        {"MoveJDO", {0}, 1, 3},
    {"MoveCDO", {0, 1}, 2, 4},     {"MoveLAO", {0}, 1, 3},        {"MoveJAO", {0}, 1, 3},
    {"MoveCAO", {0, 1}, 2, 4},     {"MoveLGO", {0}, 1, 3},        {"MoveJGO", {0}, 1, 3},
    {"MoveCGO", {0, 1}, 2, 4},     {"MoveLSync", {0}, 1, 3},      {"MoveJSync", {0}, 1, 3},
    {"MoveCSync", {0, 1}, 2, 4},   {"TriggL", {0}, 1, 4},         {"TriggJ", {0}, 1, 4},
    {"TriggC", {0, 1}, 2, 5},      {"TriggLIOs", {0}, 1, 3},      {"TriggJIOs", {0}, 1, 3},
    {"SearchL", {1, 2}, 2, 4},     {"SearchC", {1, 2, 3}, 3, 5},  {"ArcL", {0}, 1, 6},
    {"ArcLStart", {0}, 1, 6},      {"ArcLEnd", {0}, 1, 6},        {"ArcC", {0, 1}, 2, 7},
    {"ArcCStart", {0, 1}, 2, 7},   {"ArcCEnd", {0, 1}, 2, 7},     {"ContactL", {0}, 1, 2},
    {"MoveExtJ", {0}, 1, -1},      {"SearchExtJ", {1, 2}, 2, -1},
};
/* the function CalcJointT(Rob_target, Tool [\WObj]) */
static const instr_desc calc_joint_t = {"CalcJointT", {0}, 1, 1};
/* instructions that only show a target */
static const char *const harmless[] = {"TPWrite", "Write", "ErrWrite"};

static const instr_desc *find_instr(const scan *s, size_t i)
{
    for (size_t k = 0; k < sizeof instrs / sizeof instrs[0]; ++k)
        if (tok_is(s, i, instrs[k].name))
            return &instrs[k];
    return NULL;
}

/* The uses being collected: the named targets by name, each target's state. */
enum { NB = 1024 };
typedef struct {
    scan *s;
    size_t head[NB];
    rch_rapid_target *ps; /* (nps) the names declared with a target type and no literal (VAR robtarget p;):
                             their uses, for the targets assigned to them; index out->n + k */
    size_t nps;
    size_t *next; /* (out->n + nps) the next named target in the bucket */
    int *known;   /* (out->n + nps) a motion instruction's use is noted */
    char (*unk)[160]; /* (out->n + nps) its first use rcal cannot read */
    struct flow {
        size_t src, dest; /* a target's index, the assigned name's token */
        unsigned line;
    } *fl;
    size_t nfl, capfl;
} uses;

static int same_name(const char *a, const char *b, const char *dflt)
{
    return strcasecmp(a[0] ? a : dflt, b[0] ? b : dflt) == 0;
}

static void use_text(char *buf, size_t n, const char *tool, const char *wobj)
{
    snprintf(buf, n, "%.40s%s%.40s", tool, wobj[0] ? " \\WObj:=" : "", wobj);
}

/* Target k is used by instruction instr (line) with tool and wobj, or, bad
 * set, with a tool or work object that cannot be read. */
static rch_rapid_target *tgt(const uses *u, size_t k)
{
    return k < u->s->out->n ? &u->s->out->t[k] : &u->ps[k - u->s->out->n];
}

static void mark_known(uses *u, size_t k, const char *tool, const char *wobj, const char *instr, unsigned line,
                       const char *bad)
{
    rch_rapid_target *t = tgt(u, k);
    if (t->use_error[0])
        return;
    if (bad) {
        snprintf(t->use_error, sizeof t->use_error, "%s", bad);
        return;
    }
    if (!u->known[k]) {
        u->known[k] = 1;
        snprintf(t->tool, sizeof t->tool, "%s", tool);
        snprintf(t->wobj, sizeof t->wobj, "%s", wobj);
        snprintf(t->use_instr, sizeof t->use_instr, "%s", instr);
        t->use_line = line;
        return;
    }
    if (same_name(t->tool, tool, "tool0") && same_name(t->wobj, wobj, "wobj0"))
        return;
    char a[100], b[100];
    use_text(a, sizeof a, t->tool, t->wobj);
    use_text(b, sizeof b, tool, wobj);
    snprintf(t->use_error, sizeof t->use_error,
             "used with %.90s (%.23s, line %u) and with %.90s (%.23s, line %u): its correction depends on the tool and work "
             "object, so one robtarget cannot serve both; give each use its own robtarget",
             a, t->use_instr, t->use_line, b, instr, line);
}

static void mark_unknown(uses *u, size_t k, const char *what)
{
    if (!u->unk[k][0])
        snprintf(u->unk[k], sizeof u->unk[k], "%s", what);
}

/* The index of the first target at or after text offset off. */
static size_t first_at(const rch_rapid_targets *o, size_t off)
{
    size_t lo = 0, hi = o->n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (o->t[mid].off < off)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The named targets token j names (not a field .x, an optional argument's
 * name \x, nor a component x.trans): their first index or (size_t)-1. */
static size_t named_first(const uses *u, size_t j)
{
    const scan *s = u->s;
    if (s->tk.t[j].type != T_IDENT || (j > 0 && (punct(s, j - 1, '.') || punct(s, j - 1, '\\'))) || punct(s, j + 1, '.'))
        return (size_t)-1;
    const tok *t = &s->tk.t[j];
    for (size_t h = u->head[hash_ci(s->text + t->off, t->len) % NB]; h != (size_t)-1; h = u->next[h])
        if (strlen(tgt(u, h)->name) == t->len && strncasecmp(tgt(u, h)->name, s->text + t->off, t->len) == 0)
            return h;
    return (size_t)-1;
}

/* Every target the tokens [b, e) name or hold (inline), into idx (at most
 * cap); how many (more are dropped: a statement names few). */
static size_t mentions(const uses *u, size_t b, size_t e, size_t *idx, size_t cap)
{
    const scan *s = u->s;
    const rch_rapid_targets *o = s->out;
    size_t n = 0;
    if (b >= e)
        return 0;
    for (size_t j = b; j < e; ++j)
        for (size_t h = named_first(u, j); h != (size_t)-1 && n < cap; h = u->next[h]) {
            const tok *t = &s->tk.t[j];
            if (strlen(tgt(u, h)->name) == t->len && strncasecmp(tgt(u, h)->name, s->text + t->off, t->len) == 0)
                idx[n++] = h;
        }
    const size_t to = s->tk.t[e - 1].off + s->tk.t[e - 1].len;
    for (size_t k = first_at(o, s->tk.t[b].off); k < o->n && o->t[k].end <= to && n < cap; ++k)
        if (o->t[k].context == RCH_RAPID_INLINE)
            idx[n++] = k;
    return n;
}

/* The end of the piece of arguments starting at b: the next ',' at depth 0, or e. */
static size_t piece_end(const scan *s, size_t b, size_t e)
{
    size_t depth = 0, c = b;
    for (; c < e && !(depth == 0 && punct(s, c, ',')); ++c) {
        if (punct(s, c, '[') || punct(s, c, '(') || punct(s, c, '{'))
            ++depth;
        else if ((punct(s, c, ']') || punct(s, c, ')') || punct(s, c, '}')) && depth > 0)
            --depth;
    }
    return c;
}

/* The instruction (or CalcJointT) named at token at, its arguments [b, e):
 * its tool (position ds->tool) and work object (\WObj:=) onto the targets of
 * its target arguments. */
static void instr_uses(uses *u, const instr_desc *ds, size_t at, size_t b, size_t e)
{
    scan *s = u->s;
    const unsigned line = s->tk.t[at].line;
    char tool[48] = "", wobj[48] = "", bad[256] = "";
    size_t pb[8], pe[8]; /* the target arguments' pieces */
    size_t npc = 0;
    int pos = 0, have_tool = ds->tool < 0;
    for (size_t c = b; c < e; c = piece_end(s, c, e) + 1) {
        const size_t ce = piece_end(s, c, e);
        /* \WObj:=NAME anywhere in the piece, at its depth 0 */
        for (size_t j = c, depth = 0; j < ce; ++j) {
            if (punct(s, j, '[') || punct(s, j, '(') || punct(s, j, '{'))
                ++depth;
            else if ((punct(s, j, ']') || punct(s, j, ')') || punct(s, j, '}')) && depth > 0)
                --depth;
            if (depth || !punct(s, j, '\\') || j + 1 >= ce || !tok_is(s, j + 1, "WObj"))
                continue;
            if (j + 3 < ce + 1 && j + 2 < ce && s->tk.t[j + 2].type == T_ASSIGN && j + 3 < ce &&
                s->tk.t[j + 3].type == T_IDENT && (j + 4 == ce || punct(s, j + 4, '\\')))
                tok_name(wobj, sizeof wobj, s, j + 3);
            else if (!bad[0])
                snprintf(bad, sizeof bad, "the \\WObj argument of %s (line %u) is not a work object's name: rcal cannot "
                         "tell the frame the robtarget is in", ds->name, line);
        }
        if (c < ce && punct(s, c, '\\'))
            continue; /* an optional argument */
        for (unsigned k = 0; k < ds->npt; ++k)
            if (ds->pt[k] == pos && npc < 8) {
                pb[npc] = c;
                pe[npc++] = ce;
            }
        if (pos == ds->tool) {
            have_tool = 1;
            if (c < ce && s->tk.t[c].type == T_IDENT && (c + 1 == ce || punct(s, c + 1, '\\'))) {
                tok_name(tool, sizeof tool, s, c);
                const decl *dc = find_decl(s, c);
                if (dc && strcasecmp(dc->type, "tooldata") != 0 && !bad[0])
                    snprintf(bad, sizeof bad, "the argument in the Tool position of %s (line %u) is %s, declared "
                             "here as %s: rcal cannot tell the tool", ds->name, line, tool, dc->type);
            } else if (!bad[0]) {
                snprintf(bad, sizeof bad, "the Tool argument of %s (line %u) is not a tool's name: rcal cannot tell "
                         "the TCP the robtarget is a pose of", ds->name, line);
            }
        }
        ++pos;
    }
    if (!have_tool && !bad[0])
        snprintf(bad, sizeof bad, "%s (line %u) has no Tool argument (rcal reads it as argument %d)", ds->name, line,
                 ds->tool + 1);
    char name[24];
    tok_name(name, sizeof name, s, at);
    size_t idx[64];
    for (size_t p = 0; p < npc; ++p) {
        const size_t n = mentions(u, pb[p], pe[p], idx, 64);
        for (size_t k = 0; k < n; ++k)
            mark_known(u, idx[k], tool, wobj, name, line, bad[0] ? bad : NULL);
    }
}

static int is_kw(const scan *s, size_t j, const char *const *kw, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        if (tok_is(s, j, kw[k]))
            return 1;
    return 0;
}

/* The first token at depth 0 in [j, e) that is one of kw (n), or e. */
static size_t find_kw(const scan *s, size_t j, size_t e, const char *const *kw, size_t n)
{
    for (size_t depth = 0; j < e; ++j) {
        if (punct(s, j, '[') || punct(s, j, '(') || punct(s, j, '{'))
            ++depth;
        else if ((punct(s, j, ']') || punct(s, j, ')') || punct(s, j, '}')) && depth > 0)
            --depth;
        else if (depth == 0 && (kw ? is_kw(s, j, kw, n) : punct(s, j, ':')))
            return j;
    }
    return e;
}

/* Past a '(' at j: the token after its ')', or e. */
static size_t past_parens(const scan *s, size_t j, size_t e)
{
    if (!punct(s, j, '('))
        return j;
    const size_t c = close_of(s, j);
    return c < e ? c + 1 : e;
}

/* The statement [i, e)'s instruction: past the block words before it (PROC
 * headers, IF ... THEN, labels, ...). e for a declaration. */
static size_t stmt_head(const scan *s, size_t i, size_t e)
{
    static const char *const skip[] = {"LOCAL", "TASK", "ENDPROC", "ENDFUNC", "ENDTRAP", "ENDIF", "ENDWHILE",
                                       "ENDFOR", "ENDTEST", "ELSE", "ENDMODULE", "UNDO", "BACKWARD", "ENDRECORD",
                                       "SYSMODULE", "NOSTEPIN", "VIEWONLY", "READONLY", "NOVIEW"};
    static const char *const decl_kw[] = {"VAR", "PERS", "CONST", "ALIAS", "RECORD"};
    static const char *const then_kw[] = {"THEN", "DO"}, *const case_kw[] = {"CASE", "DEFAULT"};
    size_t j = i;
    while (j < e) {
        if (s->tk.t[j].type != T_IDENT)
            return j;
        if (is_kw(s, j, skip, sizeof skip / sizeof skip[0]))
            ++j;
        else if (is_kw(s, j, decl_kw, sizeof decl_kw / sizeof decl_kw[0]))
            return e;
        else if (tok_is(s, j, "ERROR"))
            j = past_parens(s, j + 1, e);
        else if (tok_is(s, j, "MODULE") || tok_is(s, j, "PROC") || tok_is(s, j, "TRAP"))
            j = past_parens(s, j + 2, e);
        else if (tok_is(s, j, "FUNC"))
            j = past_parens(s, j + 3, e);
        else if (tok_is(s, j, "IF") || tok_is(s, j, "ELSEIF") || tok_is(s, j, "WHILE") || tok_is(s, j, "FOR")) {
            const size_t k = find_kw(s, j + 1, e, then_kw, 2);
            if (k == e) { /* a compact IF: its instruction, if rcal reads it */
                for (size_t m = j + 1; m < e; ++m)
                    if (find_instr(s, m))
                        return m;
                return j;
            }
            j = k + 1;
        } else if (tok_is(s, j, "TEST")) {
            j = find_kw(s, j + 1, e, case_kw, 2);
        } else if (tok_is(s, j, "CASE") || tok_is(s, j, "DEFAULT")) {
            const size_t k = find_kw(s, j + 1, e, NULL, 0);
            j = k < e ? k + 1 : e;
        } else if (punct(s, j + 1, ':') && j + 1 < e)
            j += 2; /* a label */
        else
            return j;
    }
    return e;
}

/* One statement [i, e): the uses of the targets it names. */
static int stmt_uses(uses *u, size_t i, size_t e)
{
    scan *s = u->s;
    const size_t h = stmt_head(s, i, e);
    if (h >= e)
        return 0;
    for (size_t j = h; j + 1 < e; ++j) /* CalcJointT(...) anywhere in it */
        if (tok_is(s, j, "CalcJointT") && punct(s, j + 1, '(')) {
            const size_t c = close_of(s, j + 1);
            if (c < e)
                instr_uses(u, &calc_joint_t, j, j + 2, c);
        }
    const unsigned line = s->tk.t[h].line;
    char what[160], nm[48];
    size_t idx[64];
    tok_name(nm, sizeof nm, s, h);
    const instr_desc *ds = find_instr(s, h);
    if (ds) {
        instr_uses(u, ds, h, h + 1, e);
        return 0;
    }
    if (is_kw(s, h, harmless, sizeof harmless / sizeof harmless[0]))
        return 0;
    /* an assignment NAME[{...}][.field...] := value */
    size_t a = h + 1;
    if (punct(s, a, '{'))
        a = close_of(s, a) < e ? close_of(s, a) + 1 : e;
    const int field = punct(s, a, '.');
    while (a + 1 < e && punct(s, a, '.') && s->tk.t[a + 1].type == T_IDENT)
        a += 2;
    if (s->tk.t[h].type == T_IDENT && a < e && s->tk.t[a].type == T_ASSIGN) {
        const size_t n = mentions(u, a + 1, e, idx, 64);
        for (size_t k = 0; k < n; ++k) {
            if (!field) {
                if (u->nfl == u->capfl) {
                    const size_t nc = u->capfl ? 2 * u->capfl : 64;
                    struct flow *nf = realloc(u->fl, nc * sizeof *nf);
                    if (!nf)
                        return -1;
                    u->fl = nf;
                    u->capfl = nc;
                }
                u->fl[u->nfl++] = (struct flow){idx[k], h, line};
                continue;
            }
            snprintf(what, sizeof what, "assigned to a field of %s (line %u)", nm, line);
            mark_unknown(u, idx[k], what);
        }
        return 0;
    }
    if (punct(s, h, '%'))
        snprintf(what, sizeof what, "passed to a late-bound procedure call (line %u)", line);
    else if (tok_is(s, h, "IF"))
        snprintf(what, sizeof what, "named in a compact IF (line %u)", line);
    else if (tok_is(s, h, "RETURN"))
        snprintf(what, sizeof what, "returned by a FUNC (line %u)", line);
    else
        snprintf(what, sizeof what, "passed to %s (line %u), which is not a motion instruction rcal reads (a user "
                 "PROC or another instruction)", nm, line);
    const size_t n = mentions(u, h, e, idx, 64);
    for (size_t k = 0; k < n; ++k)
        mark_unknown(u, idx[k], what);
    return 0;
}

/* Assignments: a target assigned to a robtarget of the module takes that
 * one's uses; assigned to anything else, its use is unknown. */
static void flow_uses(uses *u)
{
    for (int pass = 0; pass < 4; ++pass)
        for (size_t f = 0; f < u->nfl; ++f) {
            const struct flow *fl = &u->fl[f];
            const size_t d = named_first(u, fl->dest);
            char nm[48], what[160];
            tok_name(nm, sizeof nm, u->s, fl->dest);
            const rch_rapid_target *td = d == (size_t)-1 ? NULL : tgt(u, d), *ts = tgt(u, fl->src);
            if (!td || td->kind != ts->kind) {
                snprintf(what, sizeof what, "assigned to %s (line %u), which is not a %s of this module", nm, fl->line,
                         rch_rapid_kind_name(ts->kind));
                mark_unknown(u, fl->src, what);
            } else if (strcasecmp(td->name, ts->name) != 0) {
                if (u->known[d])
                    mark_known(u, fl->src, td->tool, td->wobj, td->use_instr, td->use_line, NULL);
                else if (u->unk[d][0]) {
                    snprintf(what, sizeof what, "assigned to %.40s (line %u), which is %.80s", nm, fl->line, u->unk[d]);
                    mark_unknown(u, fl->src, what);
                }
            }
        }
}

/* Every statement's instruction: the tool and work object of each target's
 * uses, or why they cannot be told (use_error). */
static int note_uses(scan *s)
{
    rch_rapid_targets *o = s->out;
    uses u;
    memset(&u, 0, sizeof u);
    u.s = s;
    const size_t n = o->n + s->ndc + 1;
    u.next = malloc(n * sizeof *u.next);
    u.known = calloc(n, sizeof *u.known);
    u.unk = calloc(n, sizeof *u.unk);
    u.ps = calloc(s->ndc + 1, sizeof *u.ps);
    int rc = u.next && u.known && u.unk && u.ps ? 0 : -1;
    for (size_t b = 0; b < NB; ++b)
        u.head[b] = (size_t)-1;
    for (size_t k = 0; rc == 0 && k < o->n; ++k) { /* in reverse text order: the first is found first */
        const size_t m = o->n - 1 - k;
        const size_t nl = strlen(o->t[m].name);
        u.next[m] = (size_t)-1;
        if (nl == 0 || o->t[m].context == RCH_RAPID_INLINE)
            continue;
        const unsigned hb = hash_ci(o->t[m].name, nl) % NB;
        u.next[m] = u.head[hb];
        u.head[hb] = m;
    }
    for (size_t k = 0; rc == 0 && k < s->ndc; ++k) { /* declared without a literal */
        const decl *dc = &s->dc[k];
        const unsigned hb = hash_ci(dc->name, strlen(dc->name)) % NB;
        size_t h = u.head[hb];
        while (h != (size_t)-1 && strcasecmp(tgt(&u, h)->name, dc->name) != 0)
            h = u.next[h];
        if (dc->kind <= 0 || h != (size_t)-1)
            continue;
        rch_rapid_target *p = &u.ps[u.nps];
        snprintf(p->name, sizeof p->name, "%s", dc->name);
        p->kind = (rch_rapid_kind)dc->kind;
        p->context = RCH_RAPID_DECLARATION;
        const size_t m = o->n + u.nps++;
        u.next[m] = u.head[hb];
        u.head[hb] = m;
    }
    int in_record = 0;
    for (size_t i = 0; rc == 0 && i < s->tk.n;) {
        /* a statement: up to ';' at depth 0 */
        size_t e = i, depth = 0;
        while (e < s->tk.n && !(depth == 0 && punct(s, e, ';'))) {
            if (punct(s, e, '[') || punct(s, e, '(') || punct(s, e, '{'))
                ++depth;
            else if ((punct(s, e, ']') || punct(s, e, ')') || punct(s, e, '}')) && depth > 0)
                --depth;
            ++e;
        }
        size_t from = i;
        for (size_t j = i; j < e; ++j) { /* a RECORD's fields are no statements */
            if (tok_is(s, j, "RECORD"))
                in_record = 1;
            else if (tok_is(s, j, "ENDRECORD")) {
                in_record = 0;
                from = j + 1;
            }
        }
        if (!in_record)
            rc = stmt_uses(&u, from, e);
        i = e + 1;
    }
    if (rc == 0)
        flow_uses(&u);
    for (size_t k = 0; rc == 0 && k < o->n; ++k) {
        rch_rapid_target *t = &o->t[k];
        if (t->kind != RCH_RAPID_ROBTARGET)
            t->use_error[0] = '\0';
        else if (!t->use_error[0] && !u.known[k] && u.unk[k][0])
            snprintf(t->use_error, sizeof t->use_error,
                     "%.150s: the tool and work object it is used with cannot be told (no motion instruction of this "
                     "module uses it); move to it with its tool in this module, or give that PROC its own robtarget "
                     "argument used there", u.unk[k]);
    }
    if (rc != 0)
        rch_diag_set(s->d, s->name, 0, 0, "out of memory");
    free(u.ps);
    free(u.next);
    free(u.known);
    free(u.unk);
    free(u.fl);
    return rc;
}

int rch_rapid_scan(rch_rapid_targets *out, const char *text, size_t len, const char *name, rch_diag *d)
{
    if (len > RCH_RAPID_MAX_BYTES) {
        rch_diag_set(d, name, 0, 0, "a RAPID module of more than %u bytes is refused", RCH_RAPID_MAX_BYTES);
        return -1;
    }
    scan s;
    memset(&s, 0, sizeof s);
    s.text = text;
    s.len = len;
    s.name = name;
    s.out = out;
    s.d = d;
    int rc = tokenize(&s) == 0 ? 0 : -1;
    if (rc == 0)
        collect_types(&s);
    if (rc == 0 && collect_decls(&s) != 0)
        rc = -1;
    for (size_t i = 0; rc == 0 && i < s.tk.n; ++i) {
        if (!punct(&s, i, '['))
            continue;
        const size_t c = close_of(&s, i);
        if (c >= s.tk.n) {
            rch_diag_set(d, name, s.tk.t[i].line, s.tk.t[i].col,
                         "'[' not closed (or a bracket of another kind closes first, or nested deeper than 64)");
            rc = -1;
            break;
        }
        if (classify(&s, i, c) != 0)
            rc = -1;
        i = c; /* an aggregate's inside is its own */
    }
    if (rc == 0 && note_uses(&s) != 0)
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
        if (punct(&s, i, '['))
            ++depth;
        else if (punct(&s, i, ']') && depth-- == 0) {
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

void rch_rapid_free(rch_rapid_targets *ts)
{
    free(ts->t);
    memset(ts, 0, sizeof *ts);
}

const char *rch_rapid_kind_name(rch_rapid_kind k)
{
    return k == RCH_RAPID_JOINTTARGET ? "jointtarget" : "robtarget";
}

const char *rch_rapid_context_name(rch_rapid_context c)
{
    return c == RCH_RAPID_DECLARATION ? "declaration" : c == RCH_RAPID_ASSIGNMENT ? "assignment" : "inline";
}
