/* SPDX-License-Identifier: MIT */
/* rch_urscript.c - the URScript reader (see rch_urscript.h): the tokens, the
 * bracket frames with their function and argument, and each literal's role.
 * Depends on: rch_diag, rch_opt (rch_parse_double). Memory: the target list
 * on the heap (rch_urs_free). Errors: -1 with d set. */
#include "rch_urscript.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_opt.h"

#define MAX_DEPTH 64

typedef struct {
    size_t pos;
    unsigned line, col;
} cur;

enum { T_NONE = 0, T_NAME, T_NUM, T_STR, T_OP, T_OPEN, T_CLOSE, T_COMMA, T_NL, T_EQ, T_EOF };

typedef struct {
    int type;
    size_t pos, len;
} tok;

typedef struct {
    char kind;        /* '(' or '[' */
    char fn[24];      /* the function called ('(' preceded by a name), else "" */
    int arg;          /* the argument being read */
    char kw[24];      /* its keyword, "" positional */
    int at_start;     /* nothing of the argument read yet */
    long ik;          /* get_inverse_kin: its pose target's index, or -1 */
    int qnear_arg;    /* get_inverse_kin: a qnear argument was given */
    long qnear;       /* ... and its literal's index, or -1 */
    unsigned line, col;
} frame;

typedef struct {
    const char *s;
    size_t len;
    const char *file;
    cur c;
    frame f[MAX_DEPTH];
    int depth;
    tok prev[3];      /* the last significant tokens, prev[0] the latest */
    int skip_bracket; /* the next '[' was named already (a pose that is not a literal) */
    rch_urs_targets *ts;
    rch_diag *d;
} scan;

/* functions whose vector arguments are not targets (a force frame, a
 * selection vector, a payload's centre of gravity, a message) */
static const char *const other_vectors[] = {"force_mode", "force_mode_set_damping", "force_mode_set_gain_scaling",
                                            "set_payload", "set_payload_cog", "set_target_payload", "set_gravity",
                                            "textmsg", "popup", "socket_send_string", "socket_send_line",
                                            "rpc_factory", "write_output_float_register", NULL};

const char *rch_urs_kind_name(rch_urs_kind k)
{
    return k == RCH_URS_POSE ? "pose" : "joint list";
}

const char *rch_urs_role_name(rch_urs_role r)
{
    switch (r) {
    case RCH_URS_MOVE: return "motion argument";
    case RCH_URS_ASSIGN: return "assignment";
    case RCH_URS_IK: return "get_inverse_kin pose";
    case RCH_URS_TCP: return "set_tcp";
    case RCH_URS_QNEAR: return "qnear";
    case RCH_URS_NONE: break;
    }
    return "expression";
}

void rch_urs_free(rch_urs_targets *ts)
{
    free(ts->t);
    ts->t = NULL;
    ts->n = ts->cap = 0;
}

static int peekc(const scan *s, size_t at)
{
    return at < s->len ? (unsigned char)s->s[at] : -1;
}

static void adv(const scan *s, cur *c)
{
    const int ch = peekc(s, c->pos);
    if (ch == '\r') {
        c->pos += peekc(s, c->pos + 1) == '\n' ? 2 : 1;
        ++c->line;
        c->col = 1;
    } else if (ch == '\n') {
        ++c->pos;
        ++c->line;
        c->col = 1;
    } else {
        ++c->pos;
        ++c->col;
    }
}

static int is_alpha(int ch)
{
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_';
}

static int is_digit(int ch)
{
    return ch >= '0' && ch <= '9';
}

/* Skip blanks and comments; newlines too when nl (inside brackets). */
static void skip_space(const scan *s, cur *c, int nl)
{
    for (;;) {
        const int ch = peekc(s, c->pos);
        if (ch == ' ' || ch == '\t' || ch == '\f' || ch == '\v' || (nl && (ch == '\n' || ch == '\r')))
            adv(s, c);
        else if (ch == '#')
            while (peekc(s, c->pos) != -1 && peekc(s, c->pos) != '\n' && peekc(s, c->pos) != '\r')
                adv(s, c);
        else
            return;
    }
}

/* A number at c: [+-]?(digits[.digits]|.digits)([eE][+-]?digits)?; its end,
 * or 0 when there is none. */
static size_t number_end(const scan *s, size_t p)
{
    if (peekc(s, p) == '-' || peekc(s, p) == '+')
        ++p;
    size_t digits = 0;
    while (is_digit(peekc(s, p))) {
        ++p;
        ++digits;
    }
    if (peekc(s, p) == '.') {
        ++p;
        while (is_digit(peekc(s, p))) {
            ++p;
            ++digits;
        }
    }
    if (digits == 0)
        return 0;
    if (peekc(s, p) == 'e' || peekc(s, p) == 'E') {
        size_t q = p + 1;
        if (peekc(s, q) == '-' || peekc(s, q) == '+')
            ++q;
        if (!is_digit(peekc(s, q)))
            return 0;
        while (is_digit(peekc(s, q)))
            ++q;
        p = q;
    }
    if (is_alpha(peekc(s, p)) || is_digit(peekc(s, p)) || peekc(s, p) == '.')
        return 0; /* 1.5x, 1.2.3 */
    return p;
}

static int push_target(scan *s, const rch_urs_target *t)
{
    rch_urs_targets *ts = s->ts;
    if (ts->n == ts->cap) {
        const size_t nc = ts->cap ? 2 * ts->cap : 32;
        rch_urs_target *nt = realloc(ts->t, nc * sizeof *nt);
        if (!nt) {
            rch_diag_set(s->d, s->file, 0, 0, "out of memory");
            return -1;
        }
        ts->t = nt;
        ts->cap = nc;
    }
    ts->t[ts->n++] = *t;
    return 0;
}

/* The literal [ ... ] at c (on '['): its numbers into t (up to six kept, all
 * counted in *count), end after ']'. 1 all elements literal numbers, 0 one
 * is not (why), -1 the bracket is not closed before the text ends. */
static int parse_literal(const scan *s, cur *c, rch_urs_target *t, unsigned *count, char *why, size_t why_len)
{
    adv(s, c); /* '[' */
    *count = 0;
    skip_space(s, c, 1);
    if (peekc(s, c->pos) == ']') {
        adv(s, c);
        return 1;
    }
    for (;;) {
        skip_space(s, c, 1);
        const size_t e = number_end(s, c->pos);
        if (e == 0) {
            snprintf(why, why_len, "element %u (line %u, column %u) is not a literal number", *count + 1, c->line,
                     c->col);
            return peekc(s, c->pos) == -1 ? -1 : 0;
        }
        if (*count < RCH_URS_NUMS) {
            char buf[64];
            const size_t n = e - c->pos;
            double v = 0;
            if (n >= sizeof buf) {
                snprintf(why, why_len, "element %u (line %u, column %u) is too long a number", *count + 1, c->line,
                         c->col);
                return 0;
            }
            memcpy(buf, s->s + c->pos, n);
            buf[n] = '\0';
            if (rch_parse_double(buf[0] == '+' ? buf + 1 : buf, &v) != 0) {
                snprintf(why, why_len, "element %u (line %u, column %u) is not a finite number", *count + 1, c->line,
                         c->col);
                return 0;
            }
            t->num_off[*count] = c->pos;
            t->num_len[*count] = n;
            t->num_line[*count] = c->line;
            t->num_col[*count] = c->col;
            t->val[*count] = v;
        }
        ++*count;
        while (c->pos < e)
            adv(s, c);
        skip_space(s, c, 1);
        const int ch = peekc(s, c->pos);
        if (ch == ']') {
            adv(s, c);
            return 1;
        }
        if (ch != ',') {
            snprintf(why, why_len, "element %u (line %u, column %u) is not a literal number", *count, c->line,
                     c->col);
            return ch == -1 ? -1 : 0;
        }
        adv(s, c);
    }
}

static int tok_is(const scan *s, const tok *t, int type, const char *text)
{
    return t->type == type && (!text || (t->len == strlen(text) && memcmp(s->s + t->pos, text, t->len) == 0));
}

static int in_other_vectors(const scan *s)
{
    for (int k = s->depth - 1; k >= 0; --k)
        for (const char *const *n = other_vectors; *n; ++n)
            if (s->f[k].kind == '(' && strcmp(s->f[k].fn, *n) == 0)
                return 1;
    return 0;
}

/* The role of a literal starting at 'start' (prev tokens before it), whose
 * next significant token after it is at 'after': 1 with t->role, t->instr,
 * t->name set; 0 not a target's place. */
static int literal_role(scan *s, rch_urs_target *t, cur after, int lit)
{
    frame *f = s->depth > 0 ? &s->f[s->depth - 1] : NULL;
    if (f && f->kind == '(') {
        skip_space(s, &after, 1);
        const int nx = peekc(s, after.pos);
        const int whole = f->at_start && (nx == ',' || nx == ')');
        const char *fn = f->fn, *kw = f->kw;
        const int a = f->arg;
        int role = 0;
        if (!strcmp(fn, "movej") || !strcmp(fn, "movel") || !strcmp(fn, "movep"))
            role = (!kw[0] && a == 0) || !strcmp(kw, "q") || !strcmp(kw, "pose") ? RCH_URS_MOVE : 0;
        else if (!strcmp(fn, "movec"))
            role = (!kw[0] && a <= 1) || !strcmp(kw, "pose_via") || !strcmp(kw, "pose_to") ? RCH_URS_MOVE : 0;
        else if (!strcmp(fn, "get_inverse_kin"))
            role = (!kw[0] && a == 0) || !strcmp(kw, "x")       ? RCH_URS_IK
                   : (!kw[0] && a == 1) || !strcmp(kw, "qnear") ? RCH_URS_QNEAR
                   : (!kw[0] && a == 4) || !strcmp(kw, "tcp")   ? -1
                                                                : 0;
        else if (!strcmp(fn, "set_tcp"))
            role = (!kw[0] && a == 0) || !strcmp(kw, "pose") ? RCH_URS_TCP : 0;
        if (role == 0)
            return 0;
        snprintf(t->instr, sizeof t->instr, "%s", fn);
        t->arg = a;
        if (role < 0) {
            snprintf(t->error, sizeof t->error,
                     "get_inverse_kin's tcp argument (another TCP than set_tcp's) is not supported");
            t->role = RCH_URS_IK;
            return 1;
        }
        t->role = (rch_urs_role)role;
        if (lit && !whole)
            snprintf(t->error, sizeof t->error,
                     "part of an expression in %s's argument %d, not the whole argument: not a target rcal can "
                     "correct", fn, a + 1);
        return 1;
    }
    if (f)
        return 0;
    /* name = literal, at the start of a statement, alone on its line */
    if (!(tok_is(s, &s->prev[0], T_EQ, NULL) && s->prev[1].type == T_NAME &&
          (s->prev[2].type == T_NONE || s->prev[2].type == T_NL || tok_is(s, &s->prev[2], T_NAME, "global") ||
           tok_is(s, &s->prev[2], T_NAME, "local"))))
        return 0;
    skip_space(s, &after, 0);
    const int nx = peekc(s, after.pos);
    t->role = RCH_URS_ASSIGN;
    const size_t nl = s->prev[1].len < sizeof t->name ? s->prev[1].len : sizeof t->name - 1;
    memcpy(t->name, s->s + s->prev[1].pos, nl);
    t->name[nl] = '\0';
    if (lit && !(nx == -1 || nx == '\n' || nx == '\r'))
        snprintf(t->error, sizeof t->error,
                 "part of an expression assigned to %s, not the whole value: not a target rcal can correct", t->name);
    return 1;
}

/* A '[' at s->c (pose when 'p' at p_start precedes it). 1 consumed as a
 * literal, 0 not a literal (the caller opens a bracket frame), -1 error. */
static int at_bracket(scan *s, int pose, cur start)
{
    rch_urs_target t;
    memset(&t, 0, sizeof t);
    t.kind = pose ? RCH_URS_POSE : RCH_URS_JOINTS;
    t.qnear = -1;
    t.line = start.line;
    t.col = start.col;
    t.off = start.pos;
    cur c = s->c;
    unsigned count = 0;
    char why[160] = "";
    const int lit = parse_literal(s, &c, &t, &count, why, sizeof why);
    if (lit < 0) {
        rch_diag_set(s->d, s->file, s->c.line, s->c.col, "'[' not closed before the end of the text");
        return -1;
    }
    int role = literal_role(s, &t, lit ? c : s->c, lit);
    if (role && t.role == RCH_URS_ASSIGN && !pose && (!lit || count != RCH_URS_NUMS)) {
        /* a list of another length, or of other things, assigned: not a joint list */
        t.error[0] = '\0';
        role = 0;
        if (!lit || count != RCH_URS_NUMS)
            return 0;
    }
    if (!role) {
        if (pose && !in_other_vectors(s)) {
            const frame *f = s->depth > 0 ? &s->f[s->depth - 1] : NULL;
            snprintf(t.error, sizeof t.error,
                     "a pose literal %s%s%s is not a target rcal can correct (only movej/movel/movep/movec, "
                     "get_inverse_kin, set_tcp arguments and assignments are read): refused",
                     f && f->fn[0] ? "in an argument of " : "in an expression", f && f->fn[0] ? f->fn : "",
                     f && f->fn[0] ? "()" : "");
        } else if (lit && count == RCH_URS_NUMS && !in_other_vectors(s)) {
            snprintf(t.error, sizeof t.error,
                     "a list of six numbers here cannot be told a joint target or not (only movej/movel/movep/movec "
                     "and get_inverse_kin arguments and assignments are read): refused");
        } else
            return 0;
    } else if (!t.error[0] && !lit)
        snprintf(t.error, sizeof t.error, "%s %s: %s", rch_urs_kind_name(t.kind), "not literal", why);
    else if (!t.error[0] && count != RCH_URS_NUMS)
        snprintf(t.error, sizeof t.error, "a %s of %u numbers, not 6", rch_urs_kind_name(t.kind), count);
    else if (!t.error[0] && t.kind == RCH_URS_JOINTS && (t.role == RCH_URS_IK || t.role == RCH_URS_TCP))
        snprintf(t.error, sizeof t.error, "%s takes a pose p[...], not a joint list", t.instr);
    else if (!t.error[0] && t.kind == RCH_URS_POSE && t.role == RCH_URS_QNEAR)
        snprintf(t.error, sizeof t.error, "qnear is a joint list [...], not a pose");
    t.n = t.error[0] ? 0 : RCH_URS_NUMS;
    if (!lit) { /* named where it starts; the frame is read as tokens */
        t.end = s->c.pos + 1;
        return push_target(s, &t) != 0 ? -1 : 0;
    }
    t.end = c.pos;
    frame *f = s->depth > 0 ? &s->f[s->depth - 1] : NULL;
    if (f && t.role == RCH_URS_IK && !t.error[0])
        f->ik = (long)s->ts->n;
    if (f && t.role == RCH_URS_QNEAR)
        f->qnear = (long)s->ts->n;
    if (push_target(s, &t) != 0)
        return -1;
    s->c = c;
    s->prev[2] = s->prev[1];
    s->prev[1] = s->prev[0];
    s->prev[0] = (tok){T_CLOSE, c.pos - 1, 1};
    if (f)
        f->at_start = 0;
    return 1;
}

static void push_tok(scan *s, int type, size_t pos, size_t len)
{
    s->prev[2] = s->prev[1];
    s->prev[1] = s->prev[0];
    s->prev[0] = (tok){type, pos, len};
}

/* get_inverse_kin closed: its pose's seed is its qnear literal; a qnear
 * that is not one leaves the branch unknown. */
static void close_ik(scan *s, const frame *f)
{
    if (f->ik < 0)
        return;
    rch_urs_target *t = &s->ts->t[f->ik];
    if (f->qnear >= 0 && !s->ts->t[f->qnear].error[0])
        t->qnear = f->qnear;
    else if (f->qnear_arg && f->qnear < 0)
    {
        snprintf(t->error, sizeof t->error,
                 "its qnear is not a literal joint list: the branch the controller takes cannot be told");
        t->n = 0;
    }
}

/* A name at 'at' (read to its end here): a pose p[...], a keyword argument's
 * name =, or a name token. 0, or -1 (d set). */
static int at_name(scan *s, cur at)
{
    frame *f = s->depth > 0 ? &s->f[s->depth - 1] : NULL;
    const int ch = peekc(s, at.pos);
    while (is_alpha(peekc(s, s->c.pos)) || is_digit(peekc(s, s->c.pos)))
        adv(s, &s->c);
    const size_t n = s->c.pos - at.pos;
    if (n == 1 && ch == 'p' && peekc(s, s->c.pos) == '[') { /* p[ : a pose */
        const int r = at_bracket(s, 1, at);
        if (r < 0)
            return -1;
        if (r > 0)
            return 0;
        s->skip_bracket = s->ts->n > 0 && s->ts->t[s->ts->n - 1].off == at.pos;
    }
    /* a keyword argument: name = (not ==) at an argument's start */
    if (f && f->kind == '(' && f->at_start) {
        cur k = s->c;
        skip_space(s, &k, 1);
        if (peekc(s, k.pos) == '=' && peekc(s, k.pos + 1) != '=') {
            snprintf(f->kw, sizeof f->kw, "%.*s", (int)(n < 23 ? n : 23), s->s + at.pos);
            if (!strcmp(f->fn, "get_inverse_kin") && (f->arg == 1 || !strcmp(f->kw, "qnear")))
                f->qnear_arg = !strcmp(f->kw, "qnear"); /* the second argument by another name: not qnear */
            adv(s, &k);
            s->c = k;
            push_tok(s, T_EQ, k.pos - 1, 1);
            return 0;
        }
    }
    push_tok(s, T_NAME, at.pos, n);
    if (f)
        f->at_start = 0;
    return 0;
}

/* A closing bracket ch at 'at': its frame closed (get_inverse_kin's seed
 * tied to its pose). 0, or -1 (d set: no frame, or one of the other kind). */
static int close_bracket(scan *s, int ch, cur at)
{
    frame *f = s->depth > 0 ? &s->f[s->depth - 1] : NULL;
    if (!f || f->kind != (ch == ')' ? '(' : '[')) {
        if (f)
            rch_diag_set(s->d, s->file, at.line, at.col, "'%c' closes the '%c' of line %u, column %u", ch, f->kind,
                         f->line, f->col);
        else
            rch_diag_set(s->d, s->file, at.line, at.col, "'%c' with no bracket open", ch);
        return -1;
    }
    if (!strcmp(f->fn, "get_inverse_kin"))
        close_ik(s, f);
    --s->depth;
    adv(s, &s->c);
    push_tok(s, T_CLOSE, at.pos, 1);
    if (s->depth > 0)
        s->f[s->depth - 1].at_start = 0;
    return 0;
}

int rch_urs_scan(rch_urs_targets *ts, const char *text, size_t len, const char *file, unsigned first_line, rch_diag *d)
{
    static scan s; /* one scan at a time: the frames are too large for a small stack */
    memset(&s, 0, sizeof s);
    s.s = text;
    s.len = len;
    s.file = file;
    s.c.line = first_line ? first_line : 1;
    s.c.col = 1;
    s.ts = ts;
    s.d = d;
    if (len > RCH_URS_MAX_BYTES) {
        rch_diag_set(d, file, 0, 0, "a URScript program of more than %u bytes is refused", RCH_URS_MAX_BYTES);
        return -1;
    }
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        s.c.pos = 3;
    for (;;) {
        skip_space(&s, &s.c, s.depth > 0);
        const int ch = peekc(&s, s.c.pos);
        const cur at = s.c;
        if (ch == -1)
            break;
        if (ch == '\0') {
            rch_diag_set(d, file, at.line, at.col, "NUL byte in a URScript program");
            goto fail;
        }
        if (ch == '\n' || ch == '\r') {
            adv(&s, &s.c);
            push_tok(&s, T_NL, at.pos, 1);
            continue;
        }
        frame *f = s.depth > 0 ? &s.f[s.depth - 1] : NULL;
        if (ch == '"' || ch == '\'') {
            adv(&s, &s.c);
            while (peekc(&s, s.c.pos) != ch) {
                const int x = peekc(&s, s.c.pos);
                if (x == -1 || x == '\n' || x == '\r') {
                    rch_diag_set(d, file, at.line, at.col, "string not closed on its line");
                    goto fail;
                }
                adv(&s, &s.c);
            }
            adv(&s, &s.c);
            push_tok(&s, T_STR, at.pos, s.c.pos - at.pos);
        } else if (is_alpha(ch)) {
            if (at_name(&s, at) < 0)
                goto fail;
        } else if (is_digit(ch) || (ch == '.' && is_digit(peekc(&s, s.c.pos + 1)))) {
            size_t e = number_end(&s, s.c.pos);
            if (e == 0) { /* 1.5x: read the run as one token */
                e = s.c.pos + 1;
                while (is_alpha(peekc(&s, e)) || is_digit(peekc(&s, e)) || peekc(&s, e) == '.')
                    ++e;
            }
            while (s.c.pos < e)
                adv(&s, &s.c);
            push_tok(&s, T_NUM, at.pos, e - at.pos);
            if (f)
                f->at_start = 0;
        } else if (ch == '(' || ch == '[') {
            if (ch == '[' && s.skip_bracket)
                s.skip_bracket = 0;
            else if (ch == '[') {
                const int r = at_bracket(&s, 0, at);
                if (r < 0)
                    goto fail;
                if (r > 0)
                    continue;
            }
            if (s.depth == MAX_DEPTH) {
                rch_diag_set(d, file, at.line, at.col, "brackets nested deeper than %d", MAX_DEPTH);
                goto fail;
            }
            if (f)
                f->at_start = 0;
            frame *nf = &s.f[s.depth++];
            memset(nf, 0, sizeof *nf);
            nf->kind = (char)ch;
            nf->at_start = 1;
            nf->ik = nf->qnear = -1;
            nf->line = at.line;
            nf->col = at.col;
            if (ch == '(' && s.prev[0].type == T_NAME)
                snprintf(nf->fn, sizeof nf->fn, "%.*s", (int)(s.prev[0].len < 23 ? s.prev[0].len : 23),
                         text + s.prev[0].pos);
            adv(&s, &s.c);
            push_tok(&s, T_OPEN, at.pos, 1);
        } else if (ch == ')' || ch == ']') {
            if (close_bracket(&s, ch, at) < 0)
                goto fail;
        } else if (ch == ',') {
            adv(&s, &s.c);
            push_tok(&s, T_COMMA, at.pos, 1);
            if (f) {
                ++f->arg;
                f->kw[0] = '\0';
                f->at_start = 1;
                if (!strcmp(f->fn, "get_inverse_kin") && f->arg == 1)
                    f->qnear_arg = 1;
            }
        } else {
            /* an operator: '=' alone is an assignment's, ==, <=, >=, != not */
            const int nx = peekc(&s, s.c.pos + 1);
            const int two = (ch == '=' || ch == '<' || ch == '>' || ch == '!') && nx == '=';
            adv(&s, &s.c);
            if (two)
                adv(&s, &s.c);
            push_tok(&s, ch == '=' && !two ? T_EQ : T_OP, at.pos, two ? 2u : 1u);
            if (f)
                f->at_start = 0;
        }
    }
    if (s.depth > 0) {
        const frame *f = &s.f[s.depth - 1];
        rch_diag_set(d, file, f->line, f->col, "'%c' not closed before the end of the text", f->kind);
        goto fail;
    }
    return 0;
fail:
    return -1;
}
