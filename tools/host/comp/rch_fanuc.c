/* SPDX-License-Identifier: MIT */
/* rch_fanuc.c - the Fanuc LS reader (see rch_fanuc.h): the sections, the
 * /MN statements and what each does with a position, the /POS records and
 * their numbers' bytes, the frames file, and W, P, R.
 * Depends on: rch_diag. Memory: the positions and the motion uses on the
 * heap. Errors: -1 with d set (file:line:col). */
#include "rch_fanuc.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* A cursor over the text: byte offset, line and column (1-based). */
typedef struct {
    const char *t;
    size_t n, i;
    unsigned line, col;
    const char *name;
    rch_diag *d;
} cur;

static int at_eol(const cur *c)
{
    return c->i >= c->n || c->t[c->i] == '\n' || c->t[c->i] == '\r';
}

static void adv(cur *c)
{
    if (c->i >= c->n)
        return;
    if (c->t[c->i] == '\r' || c->t[c->i] == '\n') {
        if (c->t[c->i] == '\r' && c->i + 1 < c->n && c->t[c->i + 1] == '\n')
            ++c->i;
        ++c->i;
        ++c->line;
        c->col = 1;
        return;
    }
    ++c->i;
    ++c->col;
}

static void skip_blanks(cur *c)
{
    while (c->i < c->n && (c->t[c->i] == ' ' || c->t[c->i] == '\t'))
        adv(c);
}

static void skip_ws(cur *c)
{
    while (c->i < c->n && (c->t[c->i] == ' ' || c->t[c->i] == '\t' || c->t[c->i] == '\n' || c->t[c->i] == '\r'))
        adv(c);
}

static void next_line(cur *c)
{
    while (!at_eol(c))
        adv(c);
    adv(c);
}

static int err(cur *c, unsigned line, unsigned col, const char *msg)
{
    rch_diag_set(c->d, c->name, line, col, "%s", msg);
    return -1;
}

static int is_ident0(int ch)
{
    return isalpha(ch) || ch == '_' || ch == '$';
}

static int is_ident(int ch)
{
    return isalnum(ch) || ch == '_' || ch == '$' || ch == '.';
}

/* A finite decimal number at the cursor ([+-]digits[.digits] or [+-].digits):
 * its value and bytes. 0, or -1 (d set). */
static int read_num(cur *c, double *v, size_t *off, size_t *len, unsigned *line, unsigned *col)
{
    const size_t s = c->i;
    *line = c->line;
    *col = c->col;
    size_t k = s, digits = 0;
    if (k < c->n && (c->t[k] == '+' || c->t[k] == '-'))
        ++k;
    while (k < c->n && isdigit((unsigned char)c->t[k])) {
        ++k;
        ++digits;
    }
    if (k < c->n && c->t[k] == '.') {
        ++k;
        while (k < c->n && isdigit((unsigned char)c->t[k])) {
            ++k;
            ++digits;
        }
    }
    if (digits == 0 || (k < c->n && (isalpha((unsigned char)c->t[k]) && c->t[k] != 'm' && c->t[k] != 'd' &&
                                     c->t[k] != 'M' && c->t[k] != 'D')) ||
        (k < c->n && (c->t[k] == 'e' || c->t[k] == 'E'))) {
        return err(c, *line, *col, "expected a finite decimal number");
    }
    char buf[64];
    if (k - s >= sizeof buf)
        return err(c, *line, *col, "number too long");
    memcpy(buf, c->t + s, k - s);
    buf[k - s] = '\0';
    *v = strtod(buf, NULL);
    if (!isfinite(*v))
        return err(c, *line, *col, "number out of range");
    *off = s;
    *len = k - s;
    while (c->i < k)
        adv(c);
    return 0;
}

static int read_int(cur *c, long *v)
{
    double x;
    size_t o, l;
    unsigned li, co;
    if (read_num(c, &x, &o, &l, &li, &co) != 0)
        return -1;
    if (x != floor(x) || fabs(x) > 1e6)
        return err(c, li, co, "expected an integer");
    *v = (long)x;
    return 0;
}

/* An identifier at the cursor into w (its case kept); 0, or -1 when none. */
static int read_ident(cur *c, char *w, size_t wn)
{
    if (c->i >= c->n || !is_ident0((unsigned char)c->t[c->i]))
        return -1;
    size_t k = 0;
    while (c->i < c->n && is_ident((unsigned char)c->t[c->i])) {
        if (k + 1 < wn)
            w[k++] = c->t[c->i];
        adv(c);
    }
    w[k] = '\0';
    return 0;
}

static int expect(cur *c, char ch, const char *what)
{
    skip_ws(c);
    if (c->i >= c->n || c->t[c->i] != ch) {
        char m[160];
        snprintf(m, sizeof m, "expected '%c' %s", ch, what);
        return err(c, c->line, c->col, m);
    }
    adv(c);
    return 0;
}

/* ---- the /MN section ---- */

typedef enum { T_IDENT, T_NUM, T_PUNCT, T_BRACKET, T_STR } tkind;

typedef struct {
    tkind k;
    char w[40];          /* identifier (of a bracket: the one before '[') */
    unsigned line, col;
    long index;          /* a bracket's leading integer; -1 when its content does not start with one */
    int indirect;        /* a bracket's content holds another bracket (P[R[1]]) */
    char punct;
    double num;          /* a number's value */
} tok;

#define MAX_TOKS 96

typedef struct {
    unsigned idx, line, col;
    int uf, ut; /* active UFRAME_NUM / UTOOL_NUM (-1 unknown) */
} use_rec;

typedef struct {
    use_rec *u;
    size_t n, cap;
} uses;

/* The content of a bracket after '[': the leading integer, nesting, up to
 * the matching ']'. */
static int read_bracket(cur *c, tok *t)
{
    unsigned l0 = c->line, c0 = c->col;
    adv(c); /* '[' */
    skip_blanks(c);
    t->index = -1;
    if (c->i < c->n && isdigit((unsigned char)c->t[c->i])) {
        long v = 0;
        while (c->i < c->n && isdigit((unsigned char)c->t[c->i])) {
            v = v < 100000000 ? v * 10 + (c->t[c->i] - '0') : v;
            adv(c);
        }
        t->index = v;
        skip_blanks(c);
        if (c->i < c->n && c->t[c->i] != ']' && c->t[c->i] != ':' && c->t[c->i] != ',')
            t->index = -1;
    }
    int depth = 1;
    while (c->i < c->n && !at_eol(c)) {
        const char ch = c->t[c->i];
        if (ch == '[') {
            ++depth;
            t->indirect = 1;
        } else if (ch == ']' && --depth == 0) {
            adv(c);
            return 0;
        }
        adv(c);
    }
    return err(c, l0, c0, "'[' not closed on its line");
}

/* One /MN statement's tokens (from after a line's "n:" to its ';'; a line
 * starting with ':' continues it). Returns the count, 0 for a comment or
 * an empty statement (*comment set for a comment), -1 (d set). */
static int read_statement(cur *c, tok *tk, int *comment)
{
    int n = 0;
    *comment = 0;
    skip_blanks(c);
    if (c->i < c->n && (c->t[c->i] == '!' || (c->t[c->i] == '/' && c->i + 1 < c->n && c->t[c->i + 1] == '/'))) {
        *comment = 1;
        next_line(c);
        return 0;
    }
    for (;;) {
        skip_blanks(c);
        if (at_eol(c)) {
            /* a continuation line: blanks then ':' */
            cur save = *c;
            adv(c);
            skip_blanks(c);
            if (c->i < c->n && c->t[c->i] == ':') {
                adv(c);
                continue;
            }
            *c = save;
            return err(c, c->line, c->col, "statement not ended by ';'");
        }
        const char ch = c->t[c->i];
        if (ch == ';') {
            adv(c);
            skip_blanks(c);
            if (!at_eol(c))
                return err(c, c->line, c->col, "text after the statement's ';'");
            adv(c);
            return n;
        }
        if (n == MAX_TOKS)
            return err(c, c->line, c->col, "statement too long");
        tok *t = &tk[n];
        memset(t, 0, sizeof *t);
        t->line = c->line;
        t->col = c->col;
        if (is_ident0((unsigned char)ch)) {
            t->k = T_IDENT;
            read_ident(c, t->w, sizeof t->w);
            if (c->i < c->n && c->t[c->i] == '[') {
                t->k = T_BRACKET;
                if (read_bracket(c, t) != 0)
                    return -1;
            }
        } else if (isdigit((unsigned char)ch) || (ch == '.' && c->i + 1 < c->n && isdigit((unsigned char)c->t[c->i + 1]))) {
            t->k = T_NUM;
            const size_t s0 = c->i;
            while (c->i < c->n && (isdigit((unsigned char)c->t[c->i]) || c->t[c->i] == '.') && c->i - s0 < 30)
                adv(c);
            char nb[32];
            memcpy(nb, c->t + s0, c->i - s0);
            nb[c->i - s0] = '\0';
            t->num = strtod(nb, NULL);
        } else if (ch == '\'' || ch == '"') {
            t->k = T_STR;
            adv(c);
            while (!at_eol(c) && c->t[c->i] != ch)
                adv(c);
            if (at_eol(c))
                return err(c, t->line, t->col, "string not closed on its line");
            adv(c);
        } else if (ch == '[') {
            t->k = T_BRACKET;
            if (read_bracket(c, t) != 0)
                return -1;
        } else {
            t->k = T_PUNCT;
            t->punct = ch;
            adv(c);
        }
        ++n;
    }
}

static int ieq(const char *a, const char *b)
{
    return strcasecmp(a, b) == 0;
}

static int has_prefix_ci(const char *w, const char *p)
{
    return strncasecmp(w, p, strlen(p)) == 0;
}

/* A motion option word rcal knows moves nothing at run time. */
static int option_ok(const char *w)
{
    static const char *const ok[] = {"FINE", "CD", "CR", "Wjnt", "Skip", "LBL", "TB", "TA", "DB", "PTH", "COORD",
                                     "RTCP", "EV", "Ind.EV", "max_speed", "sec", "msec", "mm", "cm", "min", "deg",
                                     "inch", "ipm", "BREAK", "R", "AR", "PSPD", "CNT", "ACC", "LPOS", "JPOS",
                                     "Minimal_Rotation", "MROT", "Remote_TCP", "SR", "WJNT",
                                     /* what TB/TA/DB run at a point: calls and outputs, no motion */
                                     "CALL", "DO", "RO", "AO", "GO", "ON", "OFF", "PULSE", "POINT_LOGIC"};
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; ++k)
        if (ieq(w, ok[k]))
            return 1;
    return (has_prefix_ci(w, "CNT") || has_prefix_ci(w, "ACC") || has_prefix_ci(w, "CD") ||
            has_prefix_ci(w, "PSPD") || has_prefix_ci(w, "CR")) &&
           w[strlen(w) - 1] >= '0' && w[strlen(w) - 1] <= '9';
}

static int refuse_tok(cur *c, const tok *t, const char *fmt, const char *a)
{
    char m[400];
    snprintf(m, sizeof m, fmt, a);
    return err(c, t->line, t->col, m);
}

static int add_use(uses *u, unsigned idx, unsigned line, unsigned col, int uf, int ut)
{
    if (u->n == u->cap) {
        const size_t nc = u->cap ? 2 * u->cap : 32;
        use_rec *nu = realloc(u->u, nc * sizeof *nu);
        if (!nu)
            return -1;
        u->u = nu;
        u->cap = nc;
    }
    use_rec r = {idx, line, col, uf, ut};
    u->u[u->n++] = r;
    return 0;
}

/* One statement: its positions recorded, what cannot be corrected refused. */
static int statement(cur *c, const tok *tk, int n, int *uf, int *ut, uses *u, unsigned *n_motion)
{
    if (n == 0)
        return 0;
    const int motion = tk[0].k == T_IDENT && (ieq(tk[0].w, "J") || ieq(tk[0].w, "L") || ieq(tk[0].w, "C") ||
                                             ieq(tk[0].w, "A")) && n > 1 && tk[1].k == T_BRACKET;
    if (motion) {
        const int ntg = ieq(tk[0].w, "C") ? 2 : 1;
        ++*n_motion;
        int k = 1;
        for (; k <= ntg; ++k) {
            if (k >= n || tk[k].k != T_BRACKET)
                return err(c, k < n ? tk[k].line : tk[n - 1].line, k < n ? tk[k].col : tk[n - 1].col,
                           "a circular move (C) names two positions: the second is missing");
            const tok *t = &tk[k];
            if (ieq(t->w, "PR"))
                return refuse_tok(c, t, "a motion to a position register PR[...] cannot be corrected: its value "
                                        "lives in the controller, not in this file%s", "");
            if (!ieq(t->w, "P"))
                return refuse_tok(c, t, "a motion to %s[...]: only P[n] of this file can be corrected", t->w);
            if (t->indirect || t->index < 0)
                return refuse_tok(c, t, "an indirect position P[R[i]] cannot be corrected: which position it "
                                        "names is known only at run time%s", "");
            if (add_use(u, (unsigned)t->index, t->line, t->col, *uf, *ut) != 0)
                return err(c, t->line, t->col, "out of memory");
        }
        for (; k < n; ++k) {
            const tok *t = &tk[k];
            if (t->k == T_BRACKET && (ieq(t->w, "PR") || ieq(t->w, "VR") || ieq(t->w, "P")))
                return refuse_tok(c, t, "%s[...] among a motion's options (an offset, a skip's position) moves "
                                        "or records the target at run time: cannot be corrected from this file",
                                  t->w);
            if ((t->k == T_IDENT || t->k == T_BRACKET) &&
                (ieq(t->w, "Offset") || ieq(t->w, "Tool_Offset") || ieq(t->w, "INC") || ieq(t->w, "VOFFSET") ||
                 ieq(t->w, "VTOOL_OFFSET")))
                return refuse_tok(c, t, "motion option %s moves the target at run time: the corrected target would "
                                        "be moved by an uncorrected amount; refused",
                                  t->w);
            if ((t->k == T_IDENT || t->k == T_BRACKET) && !option_ok(t->w))
                return refuse_tok(c, t, "motion option '%s' is not one rcal knows moves nothing: refused "
                                        "(docs/comp-fanuc.md lists those accepted)",
                                  t->w);
        }
        return 0;
    }
    if (tk[0].k == T_BRACKET && (ieq(tk[0].w, "UFRAME") || ieq(tk[0].w, "UTOOL")))
        return refuse_tok(c, &tk[0], "%s[i]= changes a frame at run time: the frames of this program's positions "
                                     "would not be the ones given; refused",
                          tk[0].w);
    if (tk[0].k == T_IDENT && (ieq(tk[0].w, "UFRAME_NUM") || ieq(tk[0].w, "UTOOL_NUM"))) {
        int *which = ieq(tk[0].w, "UFRAME_NUM") ? uf : ut;
        if (n == 3 && tk[1].k == T_PUNCT && tk[1].punct == '=' && tk[2].k == T_NUM) {
            if (tk[2].num != floor(tk[2].num) || tk[2].num > RCH_FANUC_MAX_FRAMES)
                return refuse_tok(c, &tk[2], "%s must be a frame number 0..61", tk[0].w);
            *which = (int)tk[2].num;
            return 0;
        }
        return refuse_tok(c, &tk[0], "%s set to what is not a literal number (a register): the frame of the "
                                     "positions after it cannot be told from this file; refused",
                          tk[0].w);
    }
    for (int k = 0; k < n; ++k)
        if (tk[k].k == T_BRACKET && ieq(tk[k].w, "P"))
            return refuse_tok(c, &tk[k], "P[...] used outside a motion's target: what the program does with it "
                                         "cannot be told, so it cannot be corrected%s",
                              "");
    return 0;
}

/* The /MN section: from the cursor (the line after "/MN") to the line that
 * starts the next section. */
static int read_mn(cur *c, uses *u, unsigned *n_motion)
{
    int uf = -1, ut = -1;
    tok tk[MAX_TOKS];
    while (c->i < c->n) {
        cur s = *c;
        skip_blanks(c);
        if (at_eol(c)) {
            adv(c);
            continue;
        }
        if (c->t[c->i] == '/') {
            *c = s;
            return 0;
        }
        /* "  12:" */
        size_t dig = 0;
        while (c->i < c->n && isdigit((unsigned char)c->t[c->i])) {
            adv(c);
            ++dig;
        }
        skip_blanks(c);
        if (c->i >= c->n || c->t[c->i] != ':' || dig == 0)
            return err(c, c->line, c->col, "/MN: expected a numbered statement line (\"  12:  ... ;\")");
        adv(c);
        int comment;
        const int n = read_statement(c, tk, &comment);
        if (n < 0)
            return -1;
        if (statement(c, tk, n, &uf, &ut, u, n_motion) != 0)
            return -1;
    }
    return 0;
}

/* ---- the /POS section ---- */

static int find_pos(const rch_fanuc_prog *p, unsigned idx)
{
    for (size_t k = 0; k < p->n; ++k)
        if (p->p[k].idx == idx)
            return (int)k;
    return -1;
}

/* NAME = number unit (unit "mm" or "deg"): the number recorded as k. */
static int field(cur *c, rch_fanuc_pos *q, unsigned k, const char *name, const char *unit)
{
    char w[16];
    skip_ws(c);
    const unsigned l0 = c->line, c0 = c->col;
    if (read_ident(c, w, sizeof w) != 0 || !ieq(w, name)) {
        if (ieq(w, "E1") || ieq(w, "E2") || ieq(w, "E3"))
            return err(c, l0, c0, "extended axes (E1..) cannot be corrected: the model has no track or "
                                  "positioner; refused");
        char m[120];
        snprintf(m, sizeof m, "expected %s = ... %s", name, unit);
        return err(c, l0, c0, m);
    }
    if (expect(c, '=', "after the field's name") != 0)
        return -1;
    skip_ws(c);
    if (read_num(c, &q->val[k], &q->num_off[k], &q->num_len[k], &q->num_line[k], &q->num_col[k]) != 0)
        return -1;
    skip_ws(c);
    const unsigned l1 = c->line, c1 = c->col;
    if (read_ident(c, w, sizeof w) != 0 || !ieq(w, unit)) {
        char m[120];
        snprintf(m, sizeof m, "expected the unit %s after %s's value", unit, name);
        return err(c, l1, c1, m);
    }
    return 0;
}

/* The next field separator: ',' then more, or '}' (the end). 1 more, 0 end. */
static int sep_or_end(cur *c, int *more)
{
    skip_ws(c);
    if (c->i < c->n && c->t[c->i] == ',') {
        adv(c);
        *more = 1;
        return 0;
    }
    if (c->i < c->n && c->t[c->i] == '}') {
        *more = 0;
        return 0;
    }
    return err(c, c->line, c->col, "expected ',' or '}'");
}

/* "'N U T, 0, 0, 0'" at the cursor: the letters and the three turns (as numbers 6..8). */
static int config(cur *c, rch_fanuc_pos *q)
{
    skip_ws(c);
    if (c->i >= c->n || c->t[c->i] != '\'')
        return err(c, c->line, c->col, "expected CONFIG's quoted string 'N U T, 0, 0, 0'");
    adv(c);
    static const char *const letters[3] = {"NF", "UD", "TB"};
    for (int k = 0; k < 3; ++k) {
        skip_blanks(c);
        const int ch = c->i < c->n ? toupper((unsigned char)c->t[c->i]) : 0;
        if (ch == 0 || !strchr(letters[k], ch)) {
            char m[160];
            snprintf(m, sizeof m, "CONFIG letter %d must be %c or %c (%s)", k + 1, letters[k][0], letters[k][1],
                     k == 0 ? "no flip / flip" : k == 1 ? "up / down" : "front (top) / back");
            return err(c, c->line, c->col, m);
        }
        q->cfg[k] = (char)ch;
        adv(c);
    }
    for (int k = 0; k < 3; ++k) {
        skip_blanks(c);
        if (c->i >= c->n || c->t[c->i] != ',')
            return err(c, c->line, c->col, "CONFIG: expected ',' and the turn numbers of J1, J4, J6");
        adv(c);
        skip_blanks(c);
        if (read_num(c, &q->val[6 + k], &q->num_off[6 + k], &q->num_len[6 + k], &q->num_line[6 + k],
                     &q->num_col[6 + k]) != 0)
            return -1;
        if (q->val[6 + k] != floor(q->val[6 + k]) || fabs(q->val[6 + k]) > 8)
            return err(c, q->num_line[6 + k], q->num_col[6 + k], "CONFIG: a turn number is an integer within +-8");
    }
    skip_blanks(c);
    if (c->i >= c->n || c->t[c->i] != '\'')
        return err(c, c->line, c->col, "CONFIG: expected the closing quote after three letters and three turns");
    adv(c);
    return 0;
}

/* One P[n]{ ... }; record. */
static int pos_record(cur *c, rch_fanuc_pos *q)
{
    char w[16];
    memset(q, 0, sizeof *q);
    q->line = c->line;
    q->col = c->col;
    if (read_ident(c, w, sizeof w) != 0 || !ieq(w, "P"))
        return err(c, q->line, q->col, "/POS: expected P[n]{ ... };");
    if (c->i >= c->n || c->t[c->i] != '[')
        return err(c, c->line, c->col, "/POS: expected '[' after P");
    adv(c);
    long idx;
    if (read_int(c, &idx) != 0)
        return -1;
    if (idx < 1 || idx > 100000)
        return err(c, q->line, q->col, "/POS: position number out of range");
    q->idx = (unsigned)idx;
    skip_blanks(c);
    if (c->i < c->n && c->t[c->i] == ':') { /* its comment: "..." or text up to ']' */
        adv(c);
        skip_blanks(c);
        if (c->i < c->n && c->t[c->i] == '"') {
            adv(c);
            while (!at_eol(c) && c->t[c->i] != '"')
                adv(c);
            if (at_eol(c))
                return err(c, c->line, c->col, "/POS: the position's comment is not closed on its line");
            adv(c);
        } else
            while (!at_eol(c) && c->t[c->i] != ']')
                adv(c);
    }
    if (expect(c, ']', "after the position's number") != 0 || expect(c, '{', "to open the position") != 0)
        return -1;
    skip_ws(c);
    const unsigned lg = c->line, cg = c->col;
    if (read_ident(c, w, sizeof w) != 0 || !ieq(w, "GP1"))
        return err(c, lg, cg, "expected GP1: (a position of motion group 1)");
    if (expect(c, ':', "after GP1") != 0)
        return -1;
    const char *fr[2] = {"UF", "UT"};
    for (int k = 0; k < 2; ++k) {
        skip_ws(c);
        const unsigned l0 = c->line, c0 = c->col;
        if (read_ident(c, w, sizeof w) != 0 || !ieq(w, fr[k]))
            return err(c, l0, c0, k == 0 ? "expected UF : n" : "expected UT : n");
        if (expect(c, ':', "after UF/UT") != 0)
            return -1;
        skip_ws(c);
        const unsigned l1 = c->line, c1 = c->col;
        if (c->i < c->n && (c->t[c->i] == 'F' || c->t[c->i] == 'f'))
            return err(c, l1, c1, "UF/UT 'F' (the frame active at run time) cannot be corrected: its frame is not "
                                  "known from the file; refused");
        long v;
        if (read_int(c, &v) != 0)
            return -1;
        if (v < 0 || v > RCH_FANUC_MAX_FRAMES)
            return err(c, l1, c1, "frame number out of range");
        if (k == 0)
            q->uf = (int)v;
        else
            q->ut = (int)v;
        if (expect(c, ',', "after the frame number") != 0)
            return -1;
    }
    skip_ws(c);
    cur peek = *c;
    if (read_ident(&peek, w, sizeof w) == 0 && ieq(w, "CONFIG")) {
        *c = peek;
        if (expect(c, ':', "after CONFIG") != 0 || config(c, q) != 0 || expect(c, ',', "after CONFIG") != 0)
            return -1;
        static const char *const names[6] = {"X", "Y", "Z", "W", "P", "R"};
        for (unsigned k = 0; k < 6; ++k) {
            if (field(c, q, k, names[k], k < 3 ? "mm" : "deg") != 0)
                return -1;
            int more;
            if (sep_or_end(c, &more) != 0)
                return -1;
            if (k < 5 && !more)
                return err(c, c->line, c->col, "a Cartesian position needs X, Y, Z, W, P and R");
            if (k == 5 && more) {
                skip_ws(c);
                return err(c, c->line, c->col, "extended axes (E1..) or more fields after R cannot be corrected: "
                                               "the model has no track or positioner; refused");
            }
        }
        q->n = 9;
    } else {
        static const char *const names[6] = {"J1", "J2", "J3", "J4", "J5", "J6"};
        for (unsigned k = 0; k < 6; ++k) {
            if (field(c, q, k, names[k], "deg") != 0)
                return -1;
            int more;
            if (sep_or_end(c, &more) != 0)
                return -1;
            if (k < 5 && !more)
                return err(c, c->line, c->col, "a joint position needs J1..J6");
            if (k == 5 && more) {
                skip_ws(c);
                return err(c, c->line, c->col, "extended axes (E1..) or more fields after J6 cannot be corrected: "
                                               "the model has no track or positioner; refused");
            }
        }
        q->joint = 1;
        q->n = 6;
    }
    if (expect(c, '}', "to close the position") != 0)
        return -1;
    skip_ws(c);
    if (c->i < c->n && c->t[c->i] == ',') { /* "}, GP2: {...}" style or "},": a second group */
        return err(c, c->line, c->col, "a second motion group (GP2) cannot be corrected; refused");
    }
    if (expect(c, ';', "after the position's '}'") != 0)
        return -1;
    return 0;
}

static int read_pos(cur *c, rch_fanuc_prog *p)
{
    size_t cap = 0;
    for (;;) {
        skip_ws(c);
        if (c->i >= c->n || c->t[c->i] == '/')
            return 0;
        if (p->n == cap) {
            const size_t nc = cap ? 2 * cap : 32;
            rch_fanuc_pos *np = realloc(p->p, nc * sizeof *np);
            if (!np)
                return err(c, c->line, c->col, "out of memory");
            p->p = np;
            cap = nc;
        }
        rch_fanuc_pos *q = &p->p[p->n];
        if (pos_record(c, q) != 0)
            return -1;
        if (find_pos(p, q->idx) >= 0) {
            char m[80];
            snprintf(m, sizeof m, "P[%u] is defined twice", q->idx);
            return err(c, q->line, q->col, m);
        }
        ++p->n;
    }
}

/* The section keyword at the cursor (a line starting with '/'): its name. */
static int section(cur *c, char *w, size_t wn)
{
    skip_ws(c);
    if (c->i >= c->n || c->t[c->i] != '/')
        return -1;
    adv(c);
    return read_ident(c, w, wn);
}

int rch_fanuc_scan(rch_fanuc_prog *prog, const char *text, size_t len, const char *name, rch_diag *d)
{
    memset(prog, 0, sizeof *prog);
    cur c = {text, len, 0, 1, 1, name, d};
    if (len > RCH_FANUC_MAX_BYTES)
        return err(&c, 0, 0, "a program of more than 16 MiB is refused");
    const void *nul = memchr(text, '\0', len);
    if (nul) {
        cur z = c;
        while (z.i < (size_t)((const char *)nul - text))
            adv(&z);
        return err(&z, z.line, z.col, "NUL byte in a text program");
    }
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        c.i = 3;
    char w[40];
    unsigned l0, c0;
    skip_ws(&c);
    l0 = c.line;
    c0 = c.col;
    if (section(&c, w, sizeof w) != 0 || !ieq(w, "PROG"))
        return err(&c, l0, c0, "a Fanuc LS program starts with /PROG name");
    skip_blanks(&c);
    size_t k = 0;
    while (!at_eol(&c) && c.t[c.i] != ' ' && c.t[c.i] != '\t' && k + 1 < sizeof prog->name) {
        prog->name[k++] = c.t[c.i];
        adv(&c);
    }
    prog->name[k] = '\0';
    if (k == 0)
        return err(&c, c.line, c.col, "/PROG: the program's name is missing");
    next_line(&c);
    uses u = {NULL, 0, 0};
    int seen_mn = 0, seen_pos = 0, seen_end = 0, rc = 0;
    while (rc == 0) {
        skip_ws(&c);
        if (c.i >= c.n)
            break;
        l0 = c.line;
        c0 = c.col;
        if (seen_end) {
            rc = err(&c, l0, c0, "text after /END");
            break;
        }
        if (section(&c, w, sizeof w) != 0) {
            rc = err(&c, l0, c0, "expected a section (/ATTR, /APPL, /MN, /POS, /END)");
            break;
        }
        if (ieq(w, "ATTR") || ieq(w, "APPL")) {
            if (seen_mn) {
                rc = err(&c, l0, c0, "/ATTR or /APPL after /MN: sections out of order");
                break;
            }
            /* copied, not read: up to the next line starting with '/' */
            next_line(&c);
            for (;;) {
                cur s = c;
                skip_blanks(&c);
                if (c.i >= c.n || c.t[c.i] == '/') {
                    c = s;
                    break;
                }
                next_line(&c);
            }
        } else if (ieq(w, "MN")) {
            if (seen_mn) {
                rc = err(&c, l0, c0, "a second /MN");
                break;
            }
            seen_mn = 1;
            next_line(&c);
            rc = read_mn(&c, &u, &prog->n_motion);
        } else if (ieq(w, "POS")) {
            if (!seen_mn || seen_pos) {
                rc = err(&c, l0, c0, seen_pos ? "a second /POS" : "/POS before /MN: sections out of order");
                break;
            }
            seen_pos = 1;
            next_line(&c);
            rc = read_pos(&c, prog);
        } else if (ieq(w, "END")) {
            if (!seen_mn) {
                rc = err(&c, l0, c0, "/END before /MN");
                break;
            }
            seen_end = 1;
            next_line(&c);
        } else {
            char m[160];
            snprintf(m, sizeof m, "unknown section /%.40s (rcal reads /PROG, /ATTR, /APPL, /MN, /POS, /END)", w);
            rc = err(&c, l0, c0, m);
        }
    }
    if (rc == 0 && !seen_end)
        rc = err(&c, c.line, c.col, seen_mn ? "the program does not end with /END" : "no /MN section");
    for (size_t i = 0; rc == 0 && i < u.n; ++i) {
        const use_rec *r = &u.u[i];
        const int k2 = find_pos(prog, r->idx);
        if (k2 < 0) {
            char m[120];
            snprintf(m, sizeof m, "P[%u] is not in the /POS section: nothing to correct it from", r->idx);
            rc = err(&c, r->line, r->col, m);
            break;
        }
        rch_fanuc_pos *q = &prog->p[k2];
        if ((r->uf >= 0 && r->uf != q->uf) || (r->ut >= 0 && r->ut != q->ut)) {
            char m[240];
            snprintf(m, sizeof m, "P[%u] is recorded in UF %d, UT %d, but UFRAME_NUM=%d, UTOOL_NUM=%d are active "
                     "here (the controller stops: frame mismatch); refused", r->idx, q->uf, q->ut, r->uf, r->ut);
            rc = err(&c, r->line, r->col, m);
            break;
        }
        if (q->n_uses++ == 0) {
            q->use_line = r->line;
            q->use_col = r->col;
        }
    }
    free(u.u);
    if (rc != 0)
        rch_fanuc_free(prog);
    return rc;
}

void rch_fanuc_free(rch_fanuc_prog *prog)
{
    free(prog->p);
    prog->p = NULL;
    prog->n = 0;
}

/* ---- the frames file ---- */

int rch_fanuc_frames_parse(rch_fanuc_frames *f, const char *text, size_t len, const char *name, rch_diag *d)
{
    memset(f, 0, sizeof *f);
    f->has_uf[0] = f->has_ut[0] = 1;
    cur c = {text, len, 0, 1, 1, name, d};
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        c.i = 3;
    while (c.i < c.n) {
        skip_blanks(&c);
        if (at_eol(&c) || c.t[c.i] == '#') {
            next_line(&c);
            continue;
        }
        const unsigned l0 = c.line, c0 = c.col;
        char w[16];
        if (read_ident(&c, w, sizeof w) != 0 || !(ieq(w, "uframe") || ieq(w, "utool")))
            return err(&c, l0, c0, "frames: expected uframe or utool (uframe,n,x_mm,y_mm,z_mm,w_deg,p_deg,r_deg)");
        const int uf = ieq(w, "uframe");
        skip_blanks(&c);
        if (c.i >= c.n || c.t[c.i] != ',')
            return err(&c, c.line, c.col, "frames: expected ','");
        adv(&c);
        skip_blanks(&c);
        const unsigned l1 = c.line, c1 = c.col;
        long n;
        if (read_int(&c, &n) != 0)
            return -1;
        if (n < 1 || n > RCH_FANUC_MAX_FRAMES)
            return err(&c, l1, c1, "frames: a frame number is 1..61 (0, the world or the faceplate, is fixed)");
        if (uf ? f->has_uf[n] : f->has_ut[n])
            return err(&c, l1, c1, "frames: this frame is given twice");
        double *v = uf ? f->uf[n] : f->ut[n];
        for (int k = 0; k < 6; ++k) {
            skip_blanks(&c);
            if (c.i >= c.n || c.t[c.i] != ',')
                return err(&c, c.line, c.col, "frames: expected ',' and six numbers x, y, z (mm), w, p, r (deg)");
            adv(&c);
            skip_blanks(&c);
            size_t o, l;
            unsigned li, co;
            if (read_num(&c, &v[k], &o, &l, &li, &co) != 0)
                return -1;
        }
        skip_blanks(&c);
        if (!at_eol(&c))
            return err(&c, c.line, c.col, "frames: more than six numbers");
        if (uf)
            f->has_uf[n] = 1;
        else
            f->has_ut[n] = 1;
        next_line(&c);
    }
    return 0;
}

/* ---- W, P, R ---- */

void rch_fanuc_wpr_to_rot(double R[9], const double wpr_deg[3])
{
    const double cw = cos(wpr_deg[0] * DEG), sw = sin(wpr_deg[0] * DEG);
    const double cp = cos(wpr_deg[1] * DEG), sp = sin(wpr_deg[1] * DEG);
    const double cr = cos(wpr_deg[2] * DEG), sr = sin(wpr_deg[2] * DEG);
    R[0] = cr * cp;
    R[1] = cr * sp * sw - sr * cw;
    R[2] = cr * sp * cw + sr * sw;
    R[3] = sr * cp;
    R[4] = sr * sp * sw + cr * cw;
    R[5] = sr * sp * cw - cr * sw;
    R[6] = -sp;
    R[7] = cp * sw;
    R[8] = cp * cw;
}

void rch_fanuc_rot_to_wpr(double wpr_deg[3], const double R[9])
{
    const double p = atan2(-R[6], sqrt(R[0] * R[0] + R[3] * R[3]));
    double w, r;
    if (fabs(cos(p)) > 1e-9) {
        w = atan2(R[7], R[8]);
        r = atan2(R[3], R[0]);
    } else { /* gimbal lock: w and r about the same axis; r = 0 */
        r = 0.0;
        w = p > 0 ? atan2(R[1], R[4]) : -atan2(R[1], R[4]);
    }
    wpr_deg[0] = w / DEG;
    wpr_deg[1] = p / DEG;
    wpr_deg[2] = r / DEG;
}
