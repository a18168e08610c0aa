/* SPDX-License-Identifier: MIT */
/* rch_krl.c - the KRL reader's tokens, aggregates and targets (see
 * rch_krl.h): a line tokenized (comments, strings, numbers, names), an
 * aggregate read into a target's slots and checked, its frames set; the
 * declarations table and the frame state the statements (rch_krl_stmt.c)
 * keep.
 * Memory: tokens and targets on the heap. Errors: a target's error, or -1
 * with d set (out of memory, a text too large). */
#include "rch_krl_int.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>



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

int rch_krli_tk_is(const rch_krli_scan *s, size_t i, const char *w)
{
    return i < s->ntk && (s->tk[i].kind == TK_ID || s->tk[i].kind == TK_ENUM) && s->tk[i].len == strlen(w) &&
           strncasecmp(s->text + s->tk[i].off, w, s->tk[i].len) == 0;
}

int rch_krli_tk_ch(const rch_krli_scan *s, size_t i, int ch)
{
    return i < s->ntk && s->tk[i].kind == ch;
}

void rch_krli_tk_name(char *buf, size_t n, const rch_krli_scan *s, size_t i)
{
    size_t k = s->tk[i].len < n - 1 ? s->tk[i].len : n - 1;
    memcpy(buf, s->text + s->tk[i].off, k);
    buf[k] = '\0';
}

static unsigned tk_col(const rch_krli_scan *s, size_t i)
{
    return (unsigned)(s->tk[i].off - s->line_off) + 1;
}

/* Token i as a plain decimal integer (digits only, at most 9), or -1. */
int rch_krli_tk_int(const rch_krli_scan *s, size_t i)
{
    if (i >= s->ntk || s->tk[i].kind != TK_NUM || s->tk[i].len > 9)
        return -1;
    char b[16];
    rch_krli_tk_name(b, sizeof b, s, i);
    for (const char *c = b; *c; ++c)
        if (!isdigit((unsigned char)*c))
            return -1;
    return (int)strtol(b, NULL, 10);
}

/* The tokens of text[a..b) (one line), up to a comment. 0, or -1 (memory). */
int rch_krli_tokenize(rch_krli_scan *s, size_t a, size_t b)
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
            rch_krli_tok *nt = realloc(s->tk, nc * sizeof *nt);
            if (!nt)
                return -1;
            s->tk = nt;
            s->cap = nc;
        }
        rch_krli_tok *t = &s->tk[s->ntk++];
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

rch_krli_decl *rch_krli_find_decl(rch_krli_scan *s, const char *name)
{
    for (size_t k = 0; k < s->ndl; ++k)
        if (strcasecmp(s->dl[k].name, name) == 0)
            return &s->dl[k];
    return NULL;
}

rch_krli_decl *rch_krli_add_decl(rch_krli_scan *s, const char *name, int type)
{
    rch_krli_decl *d = rch_krli_find_decl(s, name);
    if (d)
        return d;
    if (s->ndl == s->capdl) {
        const size_t nc = s->capdl ? 2 * s->capdl : 32;
        rch_krli_decl *nd = realloc(s->dl, nc * sizeof *nd);
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

static rch_krl_target *new_target(rch_krli_scan *s, size_t i)
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
void rch_krli_refuse_at(rch_krli_scan *s, size_t i, const char *why)
{
    rch_krl_target *t = new_target(s, i);
    if (t)
        snprintf(t->error, sizeof t->error, "%s", why);
}

/* Index after the '}' matching the '{' at i, or s->ntk + 1 when unmatched. */
size_t rch_krli_agg_end(const rch_krli_scan *s, size_t i)
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
int rch_krli_slot_of(const char *n, int *axis)
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
int rch_krli_agg_has_target_comp(const rch_krli_scan *s, size_t i, size_t e)
{
    for (size_t k = i + 1; k + 1 < e; ++k)
        if (s->tk[k].kind == TK_ID && (rch_krli_tk_ch(s, k - 1, '{') || rch_krli_tk_ch(s, k - 1, ','))) {
            char n[8];
            int ax = -1;
            if (s->tk[k].len < sizeof n) {
                rch_krli_tk_name(n, sizeof n, s, k);
                if (rch_krli_slot_of(n, &ax) >= 0)
                    return 1;
            }
        }
    return 0;
}

/* The aggregate at [i, e) into t's slots: each component `NAME number`.
 * want_axis: 1 axis, 0 Cartesian, -1 from the names. Returns the kind read
 * (1 axis, 0 Cartesian) or -1 with t->error set. */
static int read_agg(rch_krli_scan *s, rch_krl_target *t, size_t i, size_t e, int want_axis)
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
        rch_krli_tk_name(n, sizeof n, s, k);
        const int sl = rch_krli_slot_of(n, &axis);
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
        if (k < e && s->tk[k].off == s->tk[k - 1].off + s->tk[k - 1].len) {
            /* A1.5 reads as A1 0.5 here, but rewritten (A10.5000) it would not */
            snprintf(t->error, sizeof t->error, "column %u: a blank is needed between %s and its value",
                     tk_col(s, k), n);
            return -1;
        }
        int neg = 0;
        if (rch_krli_tk_ch(s, k, '-') || rch_krli_tk_ch(s, k, '+'))
            neg = s->tk[k++].kind == '-';
        if (!(k < e - 1 && s->tk[k].kind == TK_NUM && (rch_krli_tk_ch(s, k + 1, ',') || k + 1 == e - 1))) {
            snprintf(t->error, sizeof t->error, "column %u: %s is not a literal decimal number", tk_col(s, v0), n);
            return -1;
        }
        char buf[64];
        double v;
        if (s->tk[k].len >= sizeof buf) {
            snprintf(t->error, sizeof t->error, "column %u: %s: number too long", tk_col(s, v0), n);
            return -1;
        }
        rch_krli_tk_name(buf, sizeof buf, s, k);
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
int rch_krli_read_frame(rch_krli_scan *s, rch_krl_frame *f, size_t i, size_t e, char *why, size_t why_len)
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
void rch_krli_set_frames(rch_krli_scan *s, rch_krl_target *t, const rch_krli_decl *fdat)
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
rch_krl_target *rch_krli_target_agg(rch_krli_scan *s, size_t i, size_t e, rch_krl_context ctx, int type,
                                    const char *name)
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

int rch_krli_type_code(const rch_krli_scan *s, size_t i)
{
    static const char *const names[] = {"AXIS", "E6AXIS", "POS", "E6POS", "FRAME", "FDAT"};
    for (int k = 0; k < 6; ++k)
        if (rch_krli_tk_is(s, i, names[k]))
            return k + 1;
    return 0;
}

/* The FDAT's TOOL_NO, BASE_NO, IPO_FRAME from [i, e). */
void rch_krli_read_fdat(rch_krli_scan *s, rch_krli_decl *d, size_t i, size_t e)
{
    int got = 0;
    for (size_t k = i + 1; k + 1 < e && k + 1 < s->ntk; ++k) {
        if ((rch_krli_tk_is(s, k, "TOOL_NO") || rch_krli_tk_is(s, k, "BASE_NO")) && s->tk[k + 1].kind == TK_NUM) {
            const int v = rch_krli_tk_int(s, k + 1);
            if (v < 0)
                continue; /* not a plain integer: the FDAT is not read (refused where it is used) */
            if (rch_krli_tk_is(s, k, "TOOL_NO"))
                d->tool_no = v;
            else
                d->base_no = v;
            got |= rch_krli_tk_is(s, k, "TOOL_NO") ? 1 : 2;
        }
        if (rch_krli_tk_is(s, k, "IPO_FRAME") && rch_krli_tk_is(s, k + 1, "#TCP"))
            d->ipo_tcp = 1;
    }
    d->fdat_ok = got == 3;
}

/* Refuse every aggregate with target components in [a, b) not read as a
 * target (an expression, a statement rcal does not read). */
void rch_krli_refuse_stray(rch_krli_scan *s, size_t a, size_t b, const char *what)
{
    for (size_t k = a; k < b && k < s->ntk; ++k)
        if (s->tk[k].kind == '{') {
            const size_t e = rch_krli_agg_end(s, k);
            if (e <= s->ntk && rch_krli_agg_has_target_comp(s, k, e)) {
                char why[160];
                snprintf(why, sizeof why, "a target aggregate in %s: rcal cannot correct it", what);
                rch_krli_refuse_at(s, k, why);
            }
            k = e - 1;
        }
}

/* TOOL_DATA[n] / BASE_DATA[n] at i (4 tokens): n, or -1. */
int rch_krli_data_index(const rch_krli_scan *s, size_t i, int *is_tool)
{
    if (!(rch_krli_tk_is(s, i, "TOOL_DATA") || rch_krli_tk_is(s, i, "BASE_DATA")) || !rch_krli_tk_ch(s, i + 1, '[') ||
        !(i + 2 < s->ntk && s->tk[i + 2].kind == TK_NUM) || !rch_krli_tk_ch(s, i + 3, ']'))
        return -1;
    const int n = rch_krli_tk_int(s, i + 2);
    *is_tool = rch_krli_tk_is(s, i, "TOOL_DATA");
    return n >= 1 && n < MAX_DATA ? n : -1;
}

void rch_krli_set_state(rch_krli_fstate *f, int known, const rch_krl_frame *fr, const char *from, const char *why)
{
    f->known = known;
    memset(&f->f, 0, sizeof f->f);
    if (fr)
        f->f = *fr;
    snprintf(f->from, sizeof f->from, "%.63s", from);
    snprintf(f->why, sizeof f->why, "%.199s", why ? why : "");
}

