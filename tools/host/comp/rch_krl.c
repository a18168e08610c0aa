/* SPDX-License-Identifier: MIT */
/* rch_krl.c - the KRL reader (see rch_krl.h): lines tokenized (comments,
 * strings, numbers, names), statements recognised (declarations,
 * assignments, motions, frame changes), aggregates read into targets with
 * their frames. Two passes: the first collects the declarations, the FDATs
 * and TOOL_DATA/BASE_DATA; the second follows $TOOL/$BASE line by line.
 * Memory: tokens and targets on the heap. Errors: a target's error, or -1
 * with d set (out of memory, a text too large). */
#include "rch_krl.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

enum { TK_ID = 'i', TK_NUM = 'n', TK_ENUM = 'e', TK_STR = 's' };

typedef struct {
    int kind;        /* TK_* or the punctuation character */
    size_t off, len; /* in the text */
} tok;

#define MAX_NAMES_LEN 48
#define MAX_DATA 65 /* TOOL_DATA[1..64], BASE_DATA[1..64] */

typedef struct {
    char name[MAX_NAMES_LEN];
    int type; /* 1..4 rch_krl_type, 5 FRAME, 6 FDAT, 0 other */
    int tool_no, base_no, ipo_tcp, fdat_ok;
} decl;

typedef struct {
    int known;
    rch_krl_frame f;
    char from[64];
    char why[200];
} fstate;

typedef struct {
    const char *text;
    size_t len;
    tok *tk;
    size_t ntk, cap;
    decl *dl;
    size_t ndl, capdl;
    int have_tool[MAX_DATA], have_base[MAX_DATA];
    rch_krl_frame tool_data[MAX_DATA], base_data[MAX_DATA];
    fstate tool, base;
    rch_krl_targets *out;
    unsigned line;
    size_t line_off; /* the line's first byte */
    int pass;
    int oom;
} scan;

const char *rch_krl_type_name(rch_krl_type t)
{
    switch (t) {
    case RCH_KRL_AXIS: return "AXIS";
    case RCH_KRL_E6AXIS: return "E6AXIS";
    case RCH_KRL_POS: return "POS";
    case RCH_KRL_E6POS: return "E6POS";
    }
    return "target";
}

const char *rch_krl_context_name(rch_krl_context c)
{
    switch (c) {
    case RCH_KRL_DECLARATION: return "declaration";
    case RCH_KRL_ASSIGNMENT: return "assignment";
    case RCH_KRL_MOTION: return "motion";
    case RCH_KRL_CIRC_AUX: return "CIRC auxiliary point";
    }
    return "statement";
}

void rch_krl_free(rch_krl_targets *ts)
{
    free(ts->t);
    ts->t = NULL;
    ts->n = ts->cap = 0;
}

static int tk_is(const scan *s, size_t i, const char *w)
{
    return i < s->ntk && (s->tk[i].kind == TK_ID || s->tk[i].kind == TK_ENUM) && s->tk[i].len == strlen(w) &&
           strncasecmp(s->text + s->tk[i].off, w, s->tk[i].len) == 0;
}

static int tk_ch(const scan *s, size_t i, int ch)
{
    return i < s->ntk && s->tk[i].kind == ch;
}

static void tk_name(char *buf, size_t n, const scan *s, size_t i)
{
    size_t k = s->tk[i].len < n - 1 ? s->tk[i].len : n - 1;
    memcpy(buf, s->text + s->tk[i].off, k);
    buf[k] = '\0';
}

static unsigned tk_col(const scan *s, size_t i)
{
    return (unsigned)(s->tk[i].off - s->line_off) + 1;
}

/* The tokens of text[a..b) (one line), up to a comment. 0, or -1 (memory). */
static int tokenize(scan *s, size_t a, size_t b)
{
    s->ntk = 0;
    size_t i = a;
    while (i < b) {
        const unsigned char ch = (unsigned char)s->text[i];
        if (ch == ';')
            break;
        if (ch == ' ' || ch == '\t' || ch == '\f' || ch == '\v') {
            ++i;
            continue;
        }
        if (s->ntk == s->cap) {
            const size_t nc = s->cap ? 2 * s->cap : 64;
            tok *nt = realloc(s->tk, nc * sizeof *nt);
            if (!nt)
                return -1;
            s->tk = nt;
            s->cap = nc;
        }
        tok *t = &s->tk[s->ntk++];
        t->off = i;
        if (isalpha(ch) || ch == '_' || ch == '$' || ch == '#' || ch >= 0x80) {
            t->kind = ch == '#' ? TK_ENUM : TK_ID;
            ++i;
            while (i < b && (isalnum((unsigned char)s->text[i]) || s->text[i] == '_' || s->text[i] == '$' ||
                             (unsigned char)s->text[i] >= 0x80))
                ++i;
        } else if (isdigit(ch) || (ch == '.' && i + 1 < b && isdigit((unsigned char)s->text[i + 1]))) {
            t->kind = TK_NUM;
            while (i < b && (isdigit((unsigned char)s->text[i]) || s->text[i] == '.'))
                ++i;
            if (i < b && (s->text[i] == 'e' || s->text[i] == 'E')) {
                size_t j = i + 1;
                if (j < b && (s->text[j] == '+' || s->text[j] == '-'))
                    ++j;
                if (j < b && isdigit((unsigned char)s->text[j])) {
                    i = j;
                    while (i < b && isdigit((unsigned char)s->text[i]))
                        ++i;
                }
            }
            /* a number glued to letters (1X) is not a number */
            while (i < b && (isalnum((unsigned char)s->text[i]) || s->text[i] == '_')) {
                t->kind = TK_ID;
                ++i;
            }
        } else if (ch == '"' || ch == '\'') {
            t->kind = ch == '"' ? TK_STR : TK_ID; /* 'B0110' and 'H1F' literals: not decimal numbers */
            ++i;
            while (i < b && (unsigned char)s->text[i] != ch)
                ++i;
            if (i < b)
                ++i;
        } else {
            t->kind = ch;
            ++i;
        }
        t->len = i - t->off;
    }
    return 0;
}

static decl *find_decl(scan *s, const char *name)
{
    for (size_t k = 0; k < s->ndl; ++k)
        if (strcasecmp(s->dl[k].name, name) == 0)
            return &s->dl[k];
    return NULL;
}

static decl *add_decl(scan *s, const char *name, int type)
{
    decl *d = find_decl(s, name);
    if (d)
        return d;
    if (s->ndl == s->capdl) {
        const size_t nc = s->capdl ? 2 * s->capdl : 32;
        decl *nd = realloc(s->dl, nc * sizeof *nd);
        if (!nd) {
            s->oom = 1;
            return NULL;
        }
        s->dl = nd;
        s->capdl = nc;
    }
    d = &s->dl[s->ndl++];
    memset(d, 0, sizeof *d);
    snprintf(d->name, sizeof d->name, "%s", name);
    d->type = type;
    return d;
}

static rch_krl_target *new_target(scan *s, size_t i)
{
    if (s->pass != 2 || s->ntk == 0)
        return NULL;
    if (i >= s->ntk)
        i = s->ntk - 1; /* a statement that ends too early: its last token */
    rch_krl_targets *o = s->out;
    if (o->n == o->cap) {
        const size_t nc = o->cap ? 2 * o->cap : 64;
        rch_krl_target *nt = realloc(o->t, nc * sizeof *nt);
        if (!nt) {
            s->oom = 1;
            return NULL;
        }
        o->t = nt;
        o->cap = nc;
    }
    rch_krl_target *t = &o->t[o->n++];
    memset(t, 0, sizeof *t);
    t->line = s->line;
    t->col = tk_col(s, i);
    t->off = s->tk[i].off;
    t->end = s->tk[i].off + s->tk[i].len;
    return t;
}

/* A statement rcal refuses, at token i. */
static void refuse_at(scan *s, size_t i, const char *why)
{
    rch_krl_target *t = new_target(s, i);
    if (t)
        snprintf(t->error, sizeof t->error, "%s", why);
}

/* Index after the '}' matching the '{' at i, or s->ntk + 1 when unmatched. */
static size_t agg_end(const scan *s, size_t i)
{
    int depth = 0;
    for (size_t k = i; k < s->ntk; ++k) {
        if (s->tk[k].kind == '{')
            ++depth;
        else if (s->tk[k].kind == '}' && --depth == 0)
            return k + 1;
    }
    return s->ntk + 1;
}

/* The slot of component name n for axis (1) or Cartesian (0) aggregates,
 * or -1. *axis is set from the name when it is -1. */
static int slot_of(const char *n, int *axis)
{
    static const char *const cart[6] = {"X", "Y", "Z", "A", "B", "C"};
    for (int k = 0; k < 6; ++k)
        if (strcasecmp(n, cart[k]) == 0) {
            if (*axis == -1)
                *axis = 0;
            return *axis == 0 ? k : -1;
        }
    if (strcasecmp(n, "S") == 0 || strcasecmp(n, "T") == 0) {
        if (*axis == -1)
            *axis = 0;
        return *axis == 0 ? (toupper((unsigned char)n[0]) == 'S' ? RCH_KRL_S : RCH_KRL_T) : -1;
    }
    if ((n[0] == 'A' || n[0] == 'a') && n[1] >= '1' && n[1] <= '6' && n[2] == '\0') {
        if (*axis == -1)
            *axis = 1;
        return *axis == 1 ? n[1] - '1' : -1;
    }
    if ((n[0] == 'E' || n[0] == 'e') && n[1] >= '1' && n[1] <= '6' && n[2] == '\0')
        return RCH_KRL_E1 + n[1] - '1';
    return -1;
}

/* Whether the aggregate at [i, e) has a component of a target. */
static int agg_has_target_comp(const scan *s, size_t i, size_t e)
{
    for (size_t k = i + 1; k + 1 < e; ++k)
        if (s->tk[k].kind == TK_ID && (tk_ch(s, k - 1, '{') || tk_ch(s, k - 1, ','))) {
            char n[8];
            int ax = -1;
            if (s->tk[k].len < sizeof n) {
                tk_name(n, sizeof n, s, k);
                if (slot_of(n, &ax) >= 0)
                    return 1;
            }
        }
    return 0;
}

/* The aggregate at [i, e) into t's slots: each component `NAME number`.
 * want_axis: 1 axis, 0 Cartesian, -1 from the names. Returns the kind read
 * (1 axis, 0 Cartesian) or -1 with t->error set. */
static int read_agg(scan *s, rch_krl_target *t, size_t i, size_t e, int want_axis)
{
    int axis = want_axis;
    if (e > s->ntk) {
        snprintf(t->error, sizeof t->error, "the aggregate is not closed on its line ('}' missing)");
        return -1;
    }
    t->end = s->tk[e - 1].off + 1;
    size_t k = i + 1;
    if (k + 1 == e) {
        snprintf(t->error, sizeof t->error, "an empty aggregate");
        return -1;
    }
    while (k + 1 < e) {
        if (s->tk[k].kind != TK_ID || s->tk[k].len > 7) {
            snprintf(t->error, sizeof t->error, "column %u: a component name expected", tk_col(s, k));
            return -1;
        }
        char n[8];
        tk_name(n, sizeof n, s, k);
        const int sl = slot_of(n, &axis);
        if (sl < 0) {
            snprintf(t->error, sizeof t->error, "column %u: component %s is not one of %s", tk_col(s, k), n,
                     axis == 1 ? "A1..A6, E1..E6" : "X, Y, Z, A, B, C, S, T, E1..E6");
            return -1;
        }
        if (t->mask & (1u << sl)) {
            snprintf(t->error, sizeof t->error, "column %u: component %s given twice", tk_col(s, k), n);
            return -1;
        }
        ++k;
        const size_t v0 = k;
        int neg = 0;
        if (tk_ch(s, k, '-') || tk_ch(s, k, '+'))
            neg = s->tk[k++].kind == '-';
        if (!(k < e - 1 && s->tk[k].kind == TK_NUM && (tk_ch(s, k + 1, ',') || k + 1 == e - 1))) {
            snprintf(t->error, sizeof t->error, "column %u: %s is not a literal decimal number", tk_col(s, v0), n);
            return -1;
        }
        char buf[64];
        double v;
        if (s->tk[k].len >= sizeof buf) {
            snprintf(t->error, sizeof t->error, "column %u: %s: number too long", tk_col(s, v0), n);
            return -1;
        }
        tk_name(buf, sizeof buf, s, k);
        char *endp;
        v = strtod(buf, &endp);
        if (*endp != '\0' || !isfinite(v) || fabs(v) > 1e9) {
            snprintf(t->error, sizeof t->error, "column %u: %s is not a finite number", tk_col(s, v0), n);
            return -1;
        }
        if ((sl == RCH_KRL_S || sl == RCH_KRL_T) && (v != floor(v) || neg || v > 255)) {
            snprintf(t->error, sizeof t->error, "column %u: %s must be an integer 0..255", tk_col(s, v0), n);
            return -1;
        }
        t->mask |= 1u << sl;
        t->val[sl] = neg ? -v : v;
        t->num_off[sl] = s->tk[v0].off;
        t->num_len[sl] = s->tk[k].off + s->tk[k].len - s->tk[v0].off;
        t->num_col[sl] = tk_col(s, v0);
        ++k;
        if (k + 1 < e)
            ++k; /* the comma */
    }
    return axis == -1 ? 0 : axis;
}

/* A frame literal {X,Y,Z,A,B,C} (all six, literal numbers) at [i, e). 0 or
 * -1 with why set. */
static int read_frame(scan *s, rch_krl_frame *f, size_t i, size_t e, char *why, size_t why_len)
{
    rch_krl_target t;
    memset(&t, 0, sizeof t);
    if (read_agg(s, &t, i, e, 0) != 0 || (t.mask & 0x3Fu) != 0x3Fu || (t.mask & ~0x3Fu)) {
        snprintf(why, why_len, "%.150s", t.error[0] ? t.error : "a frame needs exactly X, Y, Z, A, B and C");
        return -1;
    }
    memcpy(f->v, t.val, sizeof f->v);
    return 0;
}

/* The checks of a target once read: completeness and external axes. */
static void check_target(rch_krl_target *t)
{
    if (t->error[0])
        return;
    if ((t->mask & 0x3Fu) != 0x3Fu) {
        snprintf(t->error, sizeof t->error,
                 "a partial aggregate (some of %s missing): the controller takes the rest from the robot's position, "
                 "which rcal does not know", t->type <= RCH_KRL_E6AXIS ? "A1..A6" : "X, Y, Z, A, B, C");
        return;
    }
    if (t->type >= RCH_KRL_POS) {
        if (t->context != RCH_KRL_CIRC_AUX && !((t->mask >> RCH_KRL_S) & 1u && (t->mask >> RCH_KRL_T) & 1u)) {
            snprintf(t->error, sizeof t->error, "no Status and Turn (S, T): the branch of the inverse kinematics "
                     "is not named");
            return;
        }
        for (int k = 0; k < 6; ++k)
            if ((t->mask >> (RCH_KRL_E1 + k)) & 1u && t->val[RCH_KRL_E1 + k] != 0.0) {
                snprintf(t->error, sizeof t->error,
                         "column %u: external axis E%d = %g in use: a track moving the base cannot be corrected "
                         "(the model has none; only 0 is accepted)", t->num_col[RCH_KRL_E1 + k], k + 1,
                         t->val[RCH_KRL_E1 + k]);
                return;
            }
    }
}

/* Set t's frames from the current state (or an FDAT). */
static void set_frames(scan *s, rch_krl_target *t, const decl *fdat)
{
    if (t->type < RCH_KRL_POS || t->error[0])
        return;
    if (fdat) {
        if (fdat->ipo_tcp) {
            snprintf(t->error, sizeof t->error, "its FDAT %s has IPO_FRAME #TCP (an external TCP): not supported",
                     fdat->name);
            return;
        }
        if (!fdat->fdat_ok) {
            snprintf(t->error, sizeof t->error, "its FDAT %s has no literal TOOL_NO and BASE_NO", fdat->name);
            return;
        }
        const int tn = fdat->tool_no, bn = fdat->base_no;
        if ((tn > 0 && (tn >= MAX_DATA || !s->have_tool[tn])) || (bn > 0 && (bn >= MAX_DATA || !s->have_base[bn]))) {
            snprintf(t->error, sizeof t->error,
                     "its FDAT %s names TOOL_DATA[%d] and BASE_DATA[%d]; %s is not defined in this file (give "
                     "the line from $config.dat, TOOL_DATA[n]={X ..,A ..}, in the program)", fdat->name, tn, bn,
                     tn > 0 && (tn >= MAX_DATA || !s->have_tool[tn]) ? "the tool" : "the base");
            return;
        }
        memset(&t->tool, 0, sizeof t->tool);
        memset(&t->base, 0, sizeof t->base);
        if (tn > 0)
            t->tool = s->tool_data[tn];
        if (bn > 0)
            t->base = s->base_data[bn];
        snprintf(t->frames, sizeof t->frames, "FDAT %s (TOOL_NO %d, BASE_NO %d)", fdat->name, tn, bn);
        return;
    }
    if (!s->tool.known || !s->base.known) {
        snprintf(t->error, sizeof t->error, "the %s it is read in is not known here: %s", s->tool.known ? "$BASE" :
                 "$TOOL", s->tool.known ? s->base.why : s->tool.why);
        return;
    }
    t->tool = s->tool.f;
    t->base = s->base.f;
    snprintf(t->frames, sizeof t->frames, "$TOOL %.40s, $BASE %.40s", s->tool.from, s->base.from);
}

/* A target aggregate at [i, e) of the given context and (declared) type
 * (0: from its components). */
static rch_krl_target *target_agg(scan *s, size_t i, size_t e, rch_krl_context ctx, int type, const char *name)
{
    rch_krl_target *t = new_target(s, i);
    if (!t)
        return NULL;
    t->context = ctx;
    snprintf(t->name, sizeof t->name, "%s", name ? name : "");
    const int want = type == 0 ? -1 : type <= RCH_KRL_E6AXIS ? 1 : 0;
    const int axis = read_agg(s, t, i, e, want);
    if (axis < 0) {
        t->type = type ? (rch_krl_type)type : RCH_KRL_E6POS;
        return t;
    }
    if (type)
        t->type = (rch_krl_type)type;
    else
        t->type = axis ? ((t->mask >> RCH_KRL_E1) ? RCH_KRL_E6AXIS : RCH_KRL_AXIS)
                       : ((t->mask >> RCH_KRL_E1) ? RCH_KRL_E6POS : RCH_KRL_POS);
    if ((t->type == RCH_KRL_AXIS || t->type == RCH_KRL_POS) && (t->mask >> RCH_KRL_E1))
        snprintf(t->error, sizeof t->error, "%s has no E1..E6", rch_krl_type_name(t->type));
    check_target(t);
    return t;
}

static int type_code(const scan *s, size_t i)
{
    static const char *const names[] = {"AXIS", "E6AXIS", "POS", "E6POS", "FRAME", "FDAT"};
    for (int k = 0; k < 6; ++k)
        if (tk_is(s, i, names[k]))
            return k + 1;
    return 0;
}

/* The FDAT's TOOL_NO, BASE_NO, IPO_FRAME from [i, e). */
static void read_fdat(scan *s, decl *d, size_t i, size_t e)
{
    int got = 0;
    for (size_t k = i + 1; k + 1 < e && k + 1 < s->ntk; ++k) {
        if ((tk_is(s, k, "TOOL_NO") || tk_is(s, k, "BASE_NO")) && s->tk[k + 1].kind == TK_NUM) {
            char b[16];
            tk_name(b, sizeof b, s, k + 1);
            const int v = atoi(b);
            if (tk_is(s, k, "TOOL_NO"))
                d->tool_no = v;
            else
                d->base_no = v;
            got |= tk_is(s, k, "TOOL_NO") ? 1 : 2;
        }
        if (tk_is(s, k, "IPO_FRAME") && tk_is(s, k + 1, "#TCP"))
            d->ipo_tcp = 1;
    }
    d->fdat_ok = got == 3;
}

/* Refuse every aggregate with target components in [a, b) not read as a
 * target (an expression, a statement rcal does not read). */
static void refuse_stray(scan *s, size_t a, size_t b, const char *what)
{
    for (size_t k = a; k < b && k < s->ntk; ++k)
        if (s->tk[k].kind == '{') {
            const size_t e = agg_end(s, k);
            if (e <= s->ntk && agg_has_target_comp(s, k, e)) {
                char why[160];
                snprintf(why, sizeof why, "a target aggregate in %s: rcal cannot correct it", what);
                refuse_at(s, k, why);
            }
            k = e - 1;
        }
}

/* TOOL_DATA[n] / BASE_DATA[n] at i (4 tokens): n, or -1. */
static int data_index(const scan *s, size_t i, int *is_tool)
{
    if (!(tk_is(s, i, "TOOL_DATA") || tk_is(s, i, "BASE_DATA")) || !tk_ch(s, i + 1, '[') ||
        !(i + 2 < s->ntk && s->tk[i + 2].kind == TK_NUM) || !tk_ch(s, i + 3, ']'))
        return -1;
    char b[16];
    if (s->tk[i + 2].len >= sizeof b)
        return -1;
    tk_name(b, sizeof b, s, i + 2);
    const int n = atoi(b);
    *is_tool = tk_is(s, i, "TOOL_DATA");
    return n >= 1 && n < MAX_DATA ? n : -1;
}

static void set_state(fstate *f, int known, const rch_krl_frame *fr, const char *from, const char *why)
{
    f->known = known;
    memset(&f->f, 0, sizeof f->f);
    if (fr)
        f->f = *fr;
    snprintf(f->from, sizeof f->from, "%.63s", from);
    snprintf(f->why, sizeof f->why, "%.199s", why ? why : "");
}

/* $TOOL or $BASE = rhs at [i, ntk). */
static void frame_assign(scan *s, int tool, size_t i)
{
    fstate *f = tool ? &s->tool : &s->base;
    char from[64], why[200];
    snprintf(from, sizeof from, "at line %u", s->line);
    if (tk_ch(s, i, '{')) {
        const size_t e = agg_end(s, i);
        rch_krl_frame fr;
        if (e == s->ntk && read_frame(s, &fr, i, e, why, sizeof why) == 0)
            set_state(f, 1, &fr, from, NULL);
        else {
            char w2[260];
            snprintf(w2, sizeof w2, "%s at line %u is not a literal frame", tool ? "$TOOL" : "$BASE", s->line);
            set_state(f, 0, NULL, from, w2);
        }
        return;
    }
    int is_tool;
    const int n = data_index(s, i, &is_tool);
    if (n > 0 && i + 4 == s->ntk && is_tool == tool) {
        if (tool ? s->have_tool[n] : s->have_base[n]) {
            snprintf(from, sizeof from, "%s_DATA[%d] (line %u)", tool ? "TOOL" : "BASE", n, s->line);
            set_state(f, 1, tool ? &s->tool_data[n] : &s->base_data[n], from, NULL);
        } else {
            snprintf(why, sizeof why, "%s_DATA[%d] (line %u) is not defined in this file (give the line from "
                     "$config.dat, %s_DATA[%d]={X ..,A ..}, in the program)", tool ? "TOOL" : "BASE", n, s->line,
                     tool ? "TOOL" : "BASE", n);
            set_state(f, 0, NULL, from, why);
        }
        return;
    }
    if (tk_is(s, i, "$NULLFRAME") && i + 1 == s->ntk) {
        set_state(f, 1, NULL, "$NULLFRAME", NULL);
        return;
    }
    snprintf(why, sizeof why, "%s at line %u is set to an expression rcal does not evaluate", tool ? "$TOOL" : "$BASE",
             s->line);
    set_state(f, 0, NULL, from, why);
    refuse_stray(s, i, s->ntk, "a frame expression");
}

static int is_motion(const scan *s, size_t i, int *circ)
{
    static const char *const m[] = {"PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC", "SPL", NULL};
    for (int k = 0; m[k]; ++k)
        if (tk_is(s, i, m[k])) {
            *circ = k == 2 || k == 5;
            return 1;
        }
    return 0;
}

/* A motion's target at [i, ..): an aggregate or a name. Returns the index
 * after it, or 0 after a refusal. */
static size_t motion_target(scan *s, size_t i, rch_krl_context ctx, const char *instr, rch_krl_target **made)
{
    *made = NULL;
    if (tk_ch(s, i, '{')) {
        const size_t e = agg_end(s, i);
        rch_krl_target *t = target_agg(s, i, e, ctx, 0, NULL);
        if (t) {
            snprintf(t->instr, sizeof t->instr, "%s", instr);
            set_frames(s, t, NULL);
            *made = t;
        }
        return e > s->ntk ? 0 : e;
    }
    if (i < s->ntk && s->tk[i].kind == TK_ID) {
        size_t k = i + 1;
        if (tk_ch(s, k, '[')) {
            while (k < s->ntk && !tk_ch(s, k, ']'))
                ++k;
            ++k;
        }
        char n[MAX_NAMES_LEN];
        tk_name(n, sizeof n, s, i);
        const decl *d = find_decl(s, n);
        if (d && d->type == 5) {
            refuse_at(s, i, "a FRAME as a motion target carries no Status and Turn: declare it as POS or E6POS");
            return 0;
        }
        if (k <= s->ntk && (k == s->ntk || tk_ch(s, k, ',') || s->tk[k].kind == TK_ID))
            return k; /* the variable: corrected where it is declared */
    }
    refuse_at(s, i, "the motion's target is an expression (a geometric operator, a function, a component): rcal "
                    "cannot correct it");
    return 0;
}

static void motion(scan *s, int circ)
{
    char instr[8];
    tk_name(instr, sizeof instr, s, 0);
    rch_krl_target *aux = NULL, *end = NULL;
    size_t k = motion_target(s, 1, circ ? RCH_KRL_CIRC_AUX : RCH_KRL_MOTION, instr, circ ? &aux : &end);
    if (k == 0)
        return;
    if (circ) {
        if (!tk_ch(s, k, ',')) {
            refuse_at(s, k < s->ntk ? k : 0, "CIRC needs its auxiliary point and its end point");
            return;
        }
        const size_t aux_idx = aux ? (size_t)(aux - s->out->t) : 0;
        k = motion_target(s, k + 1, RCH_KRL_MOTION, instr, &end);
        if (k == 0)
            return;
        aux = aux ? &s->out->t[aux_idx] : NULL; /* the array may have moved */
        if (aux && !aux->error[0] && !((aux->mask >> RCH_KRL_S) & 1u)) {
            /* no S and T on the auxiliary point: the end point's branch */
            if (end && !end->error[0] && end->type >= RCH_KRL_POS) {
                aux->val[RCH_KRL_S] = end->val[RCH_KRL_S];
                aux->val[RCH_KRL_T] = end->val[RCH_KRL_T];
            } else if (aux->type >= RCH_KRL_POS)
                snprintf(aux->error, sizeof aux->error, "an auxiliary point without S and T takes its end point's, "
                         "which is not a literal Cartesian target here");
        }
    }
    while (k < s->ntk) {
        if (tk_is(s, k, "C_DIS") || tk_is(s, k, "C_PTP") || tk_is(s, k, "C_VEL") || tk_is(s, k, "C_ORI") ||
            tk_is(s, k, "C_SPL") || tk_ch(s, k, ',')) {
            ++k;
            continue;
        }
        if (tk_is(s, k, "CA")) {
            k += 1 + (tk_ch(s, k + 1, '-') || tk_ch(s, k + 1, '+'));
            if (k < s->ntk && s->tk[k].kind == TK_NUM) {
                ++k;
                continue;
            }
        }
        if (tk_is(s, k, "WITH")) {
            for (size_t j = k; j < s->ntk; ++j)
                if (tk_is(s, j, "$TOOL") || tk_is(s, j, "$BASE") || tk_is(s, j, "$IPO_MODE")) {
                    refuse_at(s, j, "WITH sets the motion's frames: not supported (set $TOOL/$BASE before it)");
                    return;
                }
            refuse_stray(s, k, s->ntk, "a WITH list");
            return;
        }
        refuse_at(s, k, "unexpected after the motion's target");
        return;
    }
}

/* [GLOBAL] DECL [GLOBAL] TYPE NAME[=value], ... at index i (the type). */
static void declaration(scan *s, size_t i)
{
    const int tc = type_code(s, i);
    size_t k = i + 1;
    while (k < s->ntk) {
        if (s->tk[k].kind != TK_ID)
            return;
        char n[MAX_NAMES_LEN];
        tk_name(n, sizeof n, s, k);
        decl *d = s->pass == 1 ? add_decl(s, n, tc) : find_decl(s, n);
        size_t j = k + 1;
        if (tk_ch(s, j, '[')) {
            while (j < s->ntk && !tk_ch(s, j, ']'))
                ++j;
            ++j;
        }
        if (tk_ch(s, j, '=')) {
            ++j;
            size_t e = j;
            if (tk_ch(s, j, '{'))
                e = agg_end(s, j);
            else
                while (e < s->ntk && !tk_ch(s, e, ','))
                    ++e;
            if (e > s->ntk) {
                if (tc >= 1 && tc <= 4)
                    refuse_at(s, j, "the aggregate is not closed on its line ('}' missing)");
                return;
            }
            if (tc == 6 && d && s->pass == 1 && tk_ch(s, j, '{'))
                read_fdat(s, d, j, e);
            if (tc >= 1 && tc <= 4) {
                if (tk_ch(s, j, '{') && s->pass == 2) {
                    rch_krl_target *t = target_agg(s, j, e, RCH_KRL_DECLARATION, tc, n);
                    if (t) {
                        /* a point of KUKA's inline forms: XPn with its FDAT FPn */
                        const decl *f = NULL;
                        if ((n[0] == 'X' || n[0] == 'x') && n[1]) {
                            char fn[MAX_NAMES_LEN];
                            snprintf(fn, sizeof fn, "F%s", n + 1);
                            f = find_decl(s, fn);
                            f = f && f->type == 6 ? f : NULL;
                        }
                        set_frames(s, t, f);
                    }
                } else if (!tk_ch(s, j, '{'))
                    refuse_stray(s, j, e, "a declaration's value");
            }
            k = e;
        } else
            k = j;
        if (!tk_ch(s, k, ','))
            return;
        ++k;
    }
}

/* NAME[..][.member] = rhs at 0. */
static void assignment(scan *s, size_t eq)
{
    char n[MAX_NAMES_LEN];
    tk_name(n, sizeof n, s, 0);
    if (tk_is(s, 0, "$TOOL") || tk_is(s, 0, "$BASE")) {
        if (eq == 1 && s->pass == 2)
            frame_assign(s, tk_is(s, 0, "$TOOL"), 2);
        else if (eq != 1)
            refuse_at(s, 0, "a component of $TOOL or $BASE changed: the frame is then not known to rcal");
        return;
    }
    int is_tool;
    const int di = data_index(s, 0, &is_tool);
    if (di > 0 && eq == 4) {
        if (s->pass == 1) {
            char why[200];
            rch_krl_frame fr;
            const size_t e = agg_end(s, 5);
            if (tk_ch(s, 5, '{') && e == s->ntk && read_frame(s, &fr, 5, e, why, sizeof why) == 0) {
                if (is_tool) {
                    s->tool_data[di] = fr;
                    s->have_tool[di] = 1;
                } else {
                    s->base_data[di] = fr;
                    s->have_base[di] = 1;
                }
            }
        }
        return;
    }
    if (s->pass != 2)
        return;
    if (tk_is(s, 0, "FDAT_ACT") && eq == 1) {
        char fn[MAX_NAMES_LEN], why[200];
        if (2 < s->ntk && s->tk[2].kind == TK_ID) {
            tk_name(fn, sizeof fn, s, 2);
            const decl *f = find_decl(s, fn);
            if (f && f->type == 6 && f->fdat_ok && !f->ipo_tcp) {
                const int tn = f->tool_no, bn = f->base_no;
                char from[64];
                snprintf(from, sizeof from, "FDAT %s (line %u)", fn, s->line);
                if (tn == 0 || (tn < MAX_DATA && s->have_tool[tn]))
                    set_state(&s->tool, 1, tn ? &s->tool_data[tn] : NULL, from, NULL);
                else {
                    snprintf(why, sizeof why, "FDAT %s names TOOL_DATA[%d], not defined in this file", fn, tn);
                    set_state(&s->tool, 0, NULL, from, why);
                }
                if (bn == 0 || (bn < MAX_DATA && s->have_base[bn]))
                    set_state(&s->base, 1, bn ? &s->base_data[bn] : NULL, from, NULL);
                else {
                    snprintf(why, sizeof why, "FDAT %s names BASE_DATA[%d], not defined in this file", fn, bn);
                    set_state(&s->base, 0, NULL, from, why);
                }
                return;
            }
            snprintf(why, sizeof why, "FDAT_ACT=%s (line %u): its FDAT is not declared in this file (it is in the "
                     ".dat) or has IPO_FRAME #TCP", fn, s->line);
        } else
            snprintf(why, sizeof why, "FDAT_ACT set to an expression at line %u", s->line);
        set_state(&s->tool, 0, NULL, "FDAT_ACT", why);
        set_state(&s->base, 0, NULL, "FDAT_ACT", why);
        return;
    }
    const decl *d = find_decl(s, n);
    if (eq == 1 && tk_ch(s, 2, '{') && agg_end(s, 2) == s->ntk) {
        const size_t e = s->ntk;
        if (d && d->type == 5)
            return; /* a FRAME variable: a frame, not a target */
        if (d && d->type >= 1 && d->type <= 4) {
            rch_krl_target *t = target_agg(s, 2, e, RCH_KRL_ASSIGNMENT, d->type, n);
            if (t)
                set_frames(s, t, NULL);
            return;
        }
        if (d && d->type != 0) {
            refuse_stray(s, 2, e, "an assignment");
            return;
        }
        if (!agg_has_target_comp(s, 2, e))
            return; /* $VEL={CP 0.2}, ... */
        rch_krl_target *t = target_agg(s, 2, e, RCH_KRL_ASSIGNMENT, 0, n);
        if (t && !t->error[0] && t->type >= RCH_KRL_POS && !d &&
            !((t->mask >> RCH_KRL_S) & 1u && (t->mask >> RCH_KRL_T) & 1u))
            snprintf(t->error, sizeof t->error, "%s is not declared in this file and has no S and T: a FRAME or a "
                     "POS, its type cannot be told", n);
        if (t)
            set_frames(s, t, NULL);
        return;
    }
    /* a member of a target changed (XP1.X = 10) */
    for (size_t k = 1; k + 1 < eq; ++k)
        if (tk_ch(s, k, '.') && s->tk[k + 1].kind == TK_ID) {
            char m[8];
            int ax = -1;
            if (s->tk[k + 1].len < sizeof m) {
                tk_name(m, sizeof m, s, k + 1);
                if (slot_of(m, &ax) >= 0 && (!d || (d->type >= 1 && d->type <= 4) || n[0] != '$')) {
                    refuse_at(s, k + 1, "a target's component assigned: rcal cannot correct it");
                    return;
                }
            }
        }
    refuse_stray(s, eq + 1, s->ntk, "an expression");
}

static void bas_call(scan *s)
{
    /* BAS ( #TOOL , n ) */
    if (!tk_ch(s, 1, '('))
        return;
    if (tk_is(s, 2, "#INITMOV")) {
        set_state(&s->tool, 1, NULL, "$NULLFRAME (BAS #INITMOV)", NULL);
        set_state(&s->base, 1, NULL, "$NULLFRAME (BAS #INITMOV)", NULL);
        return;
    }
    const int tool = tk_is(s, 2, "#TOOL"), base = tk_is(s, 2, "#BASE");
    if (!tool && !base)
        return;
    fstate *f = tool ? &s->tool : &s->base;
    char why[200], from[64];
    if (tk_ch(s, 3, ',') && 4 < s->ntk && s->tk[4].kind == TK_NUM && tk_ch(s, 5, ')')) {
        char b[16];
        tk_name(b, sizeof b, s, 4);
        const int n = atoi(b);
        snprintf(from, sizeof from, "BAS(#%s,%d) at line %u", tool ? "TOOL" : "BASE", n, s->line);
        if (n == 0) {
            set_state(f, 1, NULL, from, NULL);
            return;
        }
        if (n > 0 && n < MAX_DATA && (tool ? s->have_tool[n] : s->have_base[n])) {
            set_state(f, 1, tool ? &s->tool_data[n] : &s->base_data[n], from, NULL);
            return;
        }
        snprintf(why, sizeof why, "%s_DATA[%d] (BAS at line %u) is not defined in this file", tool ? "TOOL" : "BASE",
                 n, s->line);
    } else
        snprintf(why, sizeof why, "BAS at line %u selects a frame rcal cannot tell", s->line);
    set_state(f, 0, NULL, "BAS", why);
}

static void statement(scan *s)
{
    if (s->ntk == 0)
        return;
    size_t i = 0;
    if (tk_is(s, i, "GLOBAL"))
        ++i;
    if (tk_is(s, i, "DECL")) {
        ++i;
        if (tk_is(s, i, "GLOBAL"))
            ++i;
        if (tk_is(s, i, "CONST"))
            ++i;
        declaration(s, i);
        return;
    }
    if (type_code(s, i) && i + 1 < s->ntk && s->tk[i + 1].kind == TK_ID) {
        declaration(s, i);
        return;
    }
    int circ;
    if (s->pass == 2 && is_motion(s, 0, &circ)) {
        motion(s, circ);
        return;
    }
    if (s->pass == 2 && s->tk[0].kind == TK_ID && s->tk[0].len > 4 &&
        strncasecmp(s->text + s->tk[0].off + s->tk[0].len - 4, "_REL", 4) == 0) {
        refuse_at(s, 0, "a relative motion: its end depends on where the robot is, rcal cannot correct it");
        return;
    }
    if (tk_is(s, 0, "BAS")) {
        if (s->pass == 2)
            bas_call(s);
        return;
    }
    /* an assignment: the first '=' at depth 0 after a name */
    if (s->tk[0].kind == TK_ID) {
        size_t k = 1;
        int depth = 0;
        for (; k < s->ntk; ++k) {
            if (s->tk[k].kind == '[')
                ++depth;
            else if (s->tk[k].kind == ']')
                --depth;
            else if (depth == 0 && s->tk[k].kind == '=' && !tk_ch(s, k + 1, '=') && !tk_ch(s, k - 1, '<') &&
                     !tk_ch(s, k - 1, '>'))
                break;
            else if (depth == 0 && !(s->tk[k].kind == '.' || s->tk[k].kind == TK_ID || s->tk[k].kind == TK_NUM ||
                                     s->tk[k].kind == ','))
                k = s->ntk;
        }
        if (k < s->ntk && s->tk[k].kind == '=') {
            assignment(s, k);
            return;
        }
    }
    if (s->pass == 2)
        refuse_stray(s, 0, s->ntk, "a statement rcal does not read");
}

static int run_pass(scan *s, int pass)
{
    s->pass = pass;
    s->line = 0;
    set_state(&s->tool, 1, NULL, "$NULLFRAME (default)", NULL);
    set_state(&s->base, 1, NULL, "$NULLFRAME (default)", NULL);
    size_t a = 0;
    while (a < s->len) {
        size_t b = a;
        while (b < s->len && s->text[b] != '\n' && s->text[b] != '\r')
            ++b;
        ++s->line;
        s->line_off = a;
        if (tokenize(s, a, b) != 0)
            return -1;
        statement(s);
        if (s->oom)
            return -1;
        a = b;
        if (a < s->len && s->text[a] == '\r') {
            ++a;
            if (a < s->len && s->text[a] == '\n')
                ++a;
        } else if (a < s->len)
            ++a;
    }
    return 0;
}

int rch_krl_scan(rch_krl_targets *out, const char *text, size_t len, const char *name, rch_diag *d)
{
    if (len > RCH_KRL_MAX_BYTES) {
        rch_diag_set(d, name, 0, 0, "a KRL file of more than %u bytes is refused", RCH_KRL_MAX_BYTES);
        return -1;
    }
    scan *s = calloc(1, sizeof *s);
    if (!s) {
        rch_diag_set(d, name, 0, 0, "out of memory");
        return -1;
    }
    s->text = text;
    s->len = len;
    s->out = out;
    int rc = run_pass(s, 1) == 0 && run_pass(s, 2) == 0 ? 0 : -1;
    if (rc != 0)
        rch_diag_set(d, name, s->line, 1, "out of memory");
    free(s->tk);
    free(s->dl);
    free(s);
    return rc;
}
