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

/* a name declared in the module with a target type */
typedef struct {
    char name[48];
    int kind;  /* rch_rapid_kind, 0: another type, -1: declared with two types */
    int array; /* declared with {dims} */
} decl;

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

static int target_type(const scan *s, size_t i)
{
    if (tok_is(s, i, "jointtarget"))
        return RCH_RAPID_JOINTTARGET;
    if (tok_is(s, i, "robtarget"))
        return RCH_RAPID_ROBTARGET;
    return 0;
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

/* A tooldata literal [robhold, [[x,y,z],[q1..q4]], load]: its frame. */
static void note_tooldata(scan *s, size_t i, size_t c, const char *name)
{
    if (s->ntools == sizeof s->tools / sizeof s->tools[0] || !punct(s, i + 2, ',') || !punct(s, i + 3, '['))
        return;
    const int hold = tok_is(s, i + 1, "TRUE") ? 1 : tok_is(s, i + 1, "FALSE") ? 0 : -1;
    const size_t e = close_of(s, i + 3);
    if (hold < 0 || e >= c)
        return;
    shape sh;
    shape_of(&sh, s, i + 3, e);
    if (!(sh.ng == 2 && sh.nl[0] == 3 && sh.nl[1] == 4))
        return;
    double v[7] = {0};
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
                return;
            memcpy(buf, s->text + t->off, t->len);
            buf[t->len] = '\0';
            if (rch_parse_double(buf, &v[k]) != 0)
                return;
            if (neg)
                v[k] = -v[k];
        }
    snprintf(s->tools[s->ntools].name, sizeof s->tools[0].name, "%s", name);
    s->tools[s->ntools].robhold = hold;
    memcpy(s->tools[s->ntools].tf, v, sizeof v);
    s->ntools++;
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
                if (kind == 0 && tok_is(s, k - 1, "tooldata") && !indexed)
                    note_tooldata(s, i, c, nm);
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

static int is_default(const char *tool, const char *wobj)
{
    return (tool[0] == '\0' || strcasecmp(tool, "tool0") == 0) && (wobj[0] == '\0' || strcasecmp(wobj, "wobj0") == 0);
}

static void note_use(rch_rapid_target *t, const char *tool, const char *wobj, unsigned line)
{
    if (t->use_line == 0 || (is_default(t->tool, t->wobj) && !is_default(tool, wobj))) {
        snprintf(t->tool, sizeof t->tool, "%s", tool);
        snprintf(t->wobj, sizeof t->wobj, "%s", wobj);
        t->use_line = line;
    }
}

/* The Move* instructions: each one's tool (its last positional argument)
 * and work object (\WObj:=) onto the targets it names or holds. */
static int note_uses(scan *s)
{
    rch_rapid_targets *o = s->out;
    enum { NB = 1024 };
    size_t head[NB];
    size_t *next = o->n ? malloc(o->n * sizeof *next) : NULL;
    if (o->n && !next) {
        rch_diag_set(s->d, s->name, 0, 0, "out of memory");
        return -1;
    }
    for (size_t b = 0; b < NB; ++b)
        head[b] = (size_t)-1;
    for (size_t k = 0; k < o->n; ++k) {
        const size_t nl = strlen(o->t[k].name);
        next[k] = (size_t)-1;
        if (nl == 0 || o->t[k].context == RCH_RAPID_INLINE)
            continue;
        const unsigned b = hash_ci(o->t[k].name, nl) % NB;
        next[k] = head[b];
        head[b] = k;
    }
    size_t ti = 0; /* the first target not before the statement */
    for (size_t i = 0; i < s->tk.n;) {
        /* a statement: up to ';' at depth 0 */
        size_t e = i, depth = 0;
        while (e < s->tk.n && !(depth == 0 && punct(s, e, ';'))) {
            if (punct(s, e, '[') || punct(s, e, '(') || punct(s, e, '{'))
                ++depth;
            else if ((punct(s, e, ']') || punct(s, e, ')') || punct(s, e, '}')) && depth > 0)
                --depth;
            ++e;
        }
        size_t mv = i;
        while (mv < e && !(s->tk.t[mv].type == T_IDENT && s->tk.t[mv].len > 4 &&
                           strncasecmp(s->text + s->tk.t[mv].off, "Move", 4) == 0))
            ++mv;
        if (mv < e) {
            char tool[48] = "", wobj[48] = "";
            /* arguments: pieces between commas at depth 0 */
            size_t b = mv + 1;
            while (b < e) {
                size_t c = b;
                depth = 0;
                while (c < e && !(depth == 0 && punct(s, c, ','))) {
                    if (punct(s, c, '[') || punct(s, c, '(') || punct(s, c, '{'))
                        ++depth;
                    else if ((punct(s, c, ']') || punct(s, c, ')') || punct(s, c, '}')) && depth > 0)
                        --depth;
                    if (depth == 0 && punct(s, c, '\\') && c + 3 <= e && c + 2 < s->tk.n && tok_is(s, c + 1, "WObj") &&
                        s->tk.t[c + 2].type == T_ASSIGN && c + 3 < e && s->tk.t[c + 3].type == T_IDENT)
                        tok_name(wobj, sizeof wobj, s, c + 3);
                    ++c;
                }
                if (!punct(s, b, '\\') && s->tk.t[b].type == T_IDENT && (b + 1 == c || punct(s, b + 1, '\\')))
                    tok_name(tool, sizeof tool, s, b); /* the last such positional argument */
                else if (!punct(s, b, '\\'))
                    tool[0] = '\0';
                b = c + 1;
            }
            const unsigned line = s->tk.t[mv].line;
            const size_t from = s->tk.t[mv].off, to = e < s->tk.n ? s->tk.t[e].off : s->len;
            while (ti < o->n && o->t[ti].off < from)
                ++ti;
            for (size_t k = ti; k < o->n && o->t[k].end <= to; ++k)
                note_use(&o->t[k], tool, wobj, line);
            for (size_t k = mv + 1; k < e; ++k) {
                if (s->tk.t[k].type != T_IDENT)
                    continue;
                const tok *t = &s->tk.t[k];
                for (size_t h = head[hash_ci(s->text + t->off, t->len) % NB]; h != (size_t)-1; h = next[h])
                    if (strlen(o->t[h].name) == t->len && strncasecmp(o->t[h].name, s->text + t->off, t->len) == 0)
                        note_use(&o->t[h], tool, wobj, line);
            }
        }
        i = e + 1;
    }
    free(next);
    return 0;
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
    int rc = tokenize(&s) == 0 && collect_decls(&s) == 0 ? 0 : -1;
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
    for (size_t k = 0; rc == 0 && k < out->n; ++k)
        for (size_t j = 0; j < s.ntools; ++j)
            if (strcasecmp(out->t[k].tool, s.tools[j].name) == 0) {
                out->t[k].tool_declared = 1;
                out->t[k].tool_robhold = s.tools[j].robhold;
                memcpy(out->t[k].tool_frame, s.tools[j].tf, sizeof out->t[k].tool_frame);
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
