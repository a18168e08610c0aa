/* SPDX-License-Identifier: MIT */
/* rch_krl_stmt.c - the KRL reader's statements (see rch_krl.h): frame
 * changes ($TOOL, $BASE, BAS, FDAT_ACT), motions (PTP .. SCIRC with their
 * targets and what may follow), declarations and assignments, and the two
 * passes of rch_krl_scan: the first collects the declarations, the FDATs and
 * TOOL_DATA/BASE_DATA; the second follows $TOOL/$BASE line by line.
 * Memory: the scanner on the heap. Errors: a target's error, or -1 with d
 * set. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_krl_int.h"

/* $TOOL or $BASE = rhs at [i, ntk). */
static void frame_assign(rch_krli_scan *s, int tool, size_t i)
{
    rch_krli_fstate *f = tool ? &s->tool : &s->base;
    char from[64], why[200];
    snprintf(from, sizeof from, "at line %u", s->line);
    if (rch_krli_tk_ch(s, i, '{')) {
        const size_t e = rch_krli_agg_end(s, i);
        rch_krl_frame fr;
        if (e == s->ntk && rch_krli_read_frame(s, &fr, i, e, why, sizeof why) == 0)
            rch_krli_set_state(f, 1, &fr, from, NULL);
        else {
            char w2[260];
            snprintf(w2, sizeof w2, "%s at line %u is not a literal frame", tool ? "$TOOL" : "$BASE", s->line);
            rch_krli_set_state(f, 0, NULL, from, w2);
        }
        return;
    }
    int is_tool;
    const int n = rch_krli_data_index(s, i, &is_tool);
    if (n > 0 && i + 4 == s->ntk && is_tool == tool) {
        if (tool ? s->have_tool[n] : s->have_base[n]) {
            snprintf(from, sizeof from, "%s_DATA[%d] (line %u)", tool ? "TOOL" : "BASE", n, s->line);
            rch_krli_set_state(f, 1, tool ? &s->tool_data[n] : &s->base_data[n], from, NULL);
        } else {
            snprintf(why, sizeof why, "%s_DATA[%d] (line %u) is not defined in this file (give the line from "
                     "$config.dat, %s_DATA[%d]={X ..,A ..}, in the program)", tool ? "TOOL" : "BASE", n, s->line,
                     tool ? "TOOL" : "BASE", n);
            rch_krli_set_state(f, 0, NULL, from, why);
        }
        return;
    }
    if (rch_krli_tk_is(s, i, "$NULLFRAME") && i + 1 == s->ntk) {
        rch_krli_set_state(f, 1, NULL, "$NULLFRAME", NULL);
        return;
    }
    snprintf(why, sizeof why, "%s at line %u is set to an expression rcal does not evaluate", tool ? "$TOOL" : "$BASE",
             s->line);
    rch_krli_set_state(f, 0, NULL, from, why);
    rch_krli_refuse_stray(s, i, s->ntk, "a frame expression");
}

static int is_motion(const rch_krli_scan *s, size_t i, int *circ)
{
    static const char *const m[] = {"PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC", "SPL", NULL};
    for (int k = 0; m[k]; ++k)
        if (rch_krli_tk_is(s, i, m[k])) {
            *circ = k == 2 || k == 5;
            return 1;
        }
    return 0;
}

/* A motion's target at [i, ..): an aggregate or a name. Returns the index
 * after it, or 0 after a refusal. */
static size_t motion_target(rch_krli_scan *s, size_t i, rch_krl_context ctx, const char *instr, rch_krl_target **made)
{
    *made = NULL;
    if (rch_krli_tk_ch(s, i, '{')) {
        const size_t e = rch_krli_agg_end(s, i);
        rch_krl_target *t = rch_krli_target_agg(s, i, e, ctx, 0, NULL);
        if (t) {
            snprintf(t->instr, sizeof t->instr, "%s", instr);
            rch_krli_set_frames(s, t, NULL);
            *made = t;
        }
        return e > s->ntk ? 0 : e;
    }
    if (i < s->ntk && s->tk[i].kind == TK_ID) {
        size_t k = i + 1;
        if (rch_krli_tk_ch(s, k, '[')) {
            while (k < s->ntk && !rch_krli_tk_ch(s, k, ']'))
                ++k;
            ++k;
        }
        char n[MAX_NAMES_LEN];
        rch_krli_tk_name(n, sizeof n, s, i);
        const rch_krli_decl *d = rch_krli_find_decl(s, n);
        if (d && d->type == 5) {
            rch_krli_refuse_at(s, i, "a FRAME as a motion target carries no Status and Turn: declare it as POS or "
                                     "E6POS");
            return 0;
        }
        if (k <= s->ntk && (k == s->ntk || rch_krli_tk_ch(s, k, ',') || s->tk[k].kind == TK_ID))
            return k; /* the variable: corrected where it is declared */
    }
    rch_krli_refuse_at(s, i, "the motion's target is an expression (a geometric operator, a function, a component): "
                             "rcal cannot correct it");
    return 0;
}

static void motion(rch_krli_scan *s, int circ)
{
    char instr[8];
    rch_krli_tk_name(instr, sizeof instr, s, 0);
    rch_krl_target *aux = NULL, *end = NULL;
    size_t k = motion_target(s, 1, circ ? RCH_KRL_CIRC_AUX : RCH_KRL_MOTION, instr, circ ? &aux : &end);
    if (k == 0)
        return;
    if (circ) {
        if (!rch_krli_tk_ch(s, k, ',')) {
            rch_krli_refuse_at(s, k, "CIRC needs its auxiliary point and its end point");
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
        if (rch_krli_tk_is(s, k, "C_DIS") || rch_krli_tk_is(s, k, "C_PTP") || rch_krli_tk_is(s, k, "C_VEL") ||
            rch_krli_tk_is(s, k, "C_ORI") ||
            rch_krli_tk_is(s, k, "C_SPL") || rch_krli_tk_ch(s, k, ',')) {
            ++k;
            continue;
        }
        if (rch_krli_tk_is(s, k, "CA")) {
            k += 1 + (rch_krli_tk_ch(s, k + 1, '-') || rch_krli_tk_ch(s, k + 1, '+'));
            if (k < s->ntk && s->tk[k].kind == TK_NUM) {
                ++k;
                continue;
            }
        }
        if (rch_krli_tk_is(s, k, "WITH")) {
            for (size_t j = k; j < s->ntk; ++j)
                if (rch_krli_tk_is(s, j, "$TOOL") || rch_krli_tk_is(s, j, "$BASE") ||
                    rch_krli_tk_is(s, j, "$IPO_MODE")) {
                    rch_krli_refuse_at(s, j, "WITH sets the motion's frames: not supported (set $TOOL/$BASE before "
                                             "it)");
                    return;
                }
            rch_krli_refuse_stray(s, k, s->ntk, "a WITH list");
            return;
        }
        rch_krli_refuse_at(s, k, "unexpected after the motion's target");
        return;
    }
}

/* [GLOBAL] DECL [GLOBAL] TYPE NAME[=value], ... at index i (the type). */
static void declaration(rch_krli_scan *s, size_t i)
{
    const int tc = rch_krli_type_code(s, i);
    size_t k = i + 1;
    while (k < s->ntk) {
        if (s->tk[k].kind != TK_ID)
            return;
        char n[MAX_NAMES_LEN];
        rch_krli_tk_name(n, sizeof n, s, k);
        rch_krli_decl *d = s->pass == 1 ? rch_krli_add_decl(s, n, tc) : rch_krli_find_decl(s, n);
        size_t j = k + 1;
        if (rch_krli_tk_ch(s, j, '[')) {
            while (j < s->ntk && !rch_krli_tk_ch(s, j, ']'))
                ++j;
            ++j;
        }
        if (rch_krli_tk_ch(s, j, '=')) {
            ++j;
            size_t e = j;
            if (rch_krli_tk_ch(s, j, '{'))
                e = rch_krli_agg_end(s, j);
            else
                while (e < s->ntk && !rch_krli_tk_ch(s, e, ','))
                    ++e;
            if (e > s->ntk) {
                if (tc >= 1 && tc <= 4)
                    rch_krli_refuse_at(s, j, "the aggregate is not closed on its line ('}' missing)");
                return;
            }
            if (tc == 6 && d && s->pass == 1 && rch_krli_tk_ch(s, j, '{'))
                rch_krli_read_fdat(s, d, j, e);
            if (tc >= 1 && tc <= 4) {
                if (rch_krli_tk_ch(s, j, '{') && s->pass == 2) {
                    rch_krl_target *t = rch_krli_target_agg(s, j, e, RCH_KRL_DECLARATION, tc, n);
                    if (t) {
                        /* a point of KUKA's inline forms: XPn with its FDAT FPn */
                        const rch_krli_decl *f = NULL;
                        if ((n[0] == 'X' || n[0] == 'x') && n[1]) {
                            char fn[MAX_NAMES_LEN];
                            snprintf(fn, sizeof fn, "F%s", n + 1);
                            f = rch_krli_find_decl(s, fn);
                            f = f && f->type == 6 ? f : NULL;
                        }
                        rch_krli_set_frames(s, t, f);
                    }
                } else if (!rch_krli_tk_ch(s, j, '{'))
                    rch_krli_refuse_stray(s, j, e, "a declaration's value");
            }
            k = e;
        } else
            k = j;
        if (!rch_krli_tk_ch(s, k, ','))
            return;
        ++k;
    }
}

/* FDAT_ACT = FPn: the frames of that FDAT (declared in this file), else unknown. */
static void fdat_act(rch_krli_scan *s)
{
    char fn[MAX_NAMES_LEN], why[200];
    if (2 < s->ntk && s->tk[2].kind == TK_ID) {
        rch_krli_tk_name(fn, sizeof fn, s, 2);
        const rch_krli_decl *f = rch_krli_find_decl(s, fn);
        if (f && f->type == 6 && f->fdat_ok && !f->ipo_tcp) {
            const int tn = f->tool_no, bn = f->base_no;
            char from[64];
            snprintf(from, sizeof from, "FDAT %s (line %u)", fn, s->line);
            if (tn == 0 || (tn < MAX_DATA && s->have_tool[tn]))
                rch_krli_set_state(&s->tool, 1, tn ? &s->tool_data[tn] : NULL, from, NULL);
            else {
                snprintf(why, sizeof why, "FDAT %s names TOOL_DATA[%d], not defined in this file", fn, tn);
                rch_krli_set_state(&s->tool, 0, NULL, from, why);
            }
            if (bn == 0 || (bn < MAX_DATA && s->have_base[bn]))
                rch_krli_set_state(&s->base, 1, bn ? &s->base_data[bn] : NULL, from, NULL);
            else {
                snprintf(why, sizeof why, "FDAT %s names BASE_DATA[%d], not defined in this file", fn, bn);
                rch_krli_set_state(&s->base, 0, NULL, from, why);
            }
            return;
        }
        snprintf(why, sizeof why, "FDAT_ACT=%s (line %u): its FDAT is not declared in this file (it is in the "
                 ".dat) or has IPO_FRAME #TCP", fn, s->line);
    } else
        snprintf(why, sizeof why, "FDAT_ACT set to an expression at line %u", s->line);
    rch_krli_set_state(&s->tool, 0, NULL, "FDAT_ACT", why);
    rch_krli_set_state(&s->base, 0, NULL, "FDAT_ACT", why);
    return;
}

/* NAME[..][.member] = rhs at 0. */
static void assignment(rch_krli_scan *s, size_t eq)
{
    char n[MAX_NAMES_LEN];
    rch_krli_tk_name(n, sizeof n, s, 0);
    if (rch_krli_tk_is(s, 0, "$TOOL") || rch_krli_tk_is(s, 0, "$BASE")) {
        if (eq == 1 && s->pass == 2)
            frame_assign(s, rch_krli_tk_is(s, 0, "$TOOL"), 2);
        else if (eq != 1)
            rch_krli_refuse_at(s, 0, "a component of $TOOL or $BASE changed: the frame is then not known to rcal");
        return;
    }
    int is_tool;
    const int di = rch_krli_data_index(s, 0, &is_tool);
    if (di > 0 && eq == 4) {
        if (s->pass == 1) {
            char why[200];
            rch_krl_frame fr;
            const size_t e = rch_krli_agg_end(s, 5);
            if (rch_krli_tk_ch(s, 5, '{') && e == s->ntk && rch_krli_read_frame(s, &fr, 5, e, why, sizeof why) == 0) {
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
    if (rch_krli_tk_is(s, 0, "FDAT_ACT") && eq == 1) {
        fdat_act(s);
        return;
    }
    const rch_krli_decl *d = rch_krli_find_decl(s, n);
    if (eq == 1 && rch_krli_tk_ch(s, 2, '{') && rch_krli_agg_end(s, 2) == s->ntk) {
        const size_t e = s->ntk;
        if (d && d->type == 5)
            return; /* a FRAME variable: a frame, not a target */
        if (d && d->type >= 1 && d->type <= 4) {
            rch_krl_target *t = rch_krli_target_agg(s, 2, e, RCH_KRL_ASSIGNMENT, d->type, n);
            if (t)
                rch_krli_set_frames(s, t, NULL);
            return;
        }
        if (d && d->type != 0) {
            rch_krli_refuse_stray(s, 2, e, "an assignment");
            return;
        }
        if (!rch_krli_agg_has_target_comp(s, 2, e))
            return; /* $VEL={CP 0.2}, ... */
        rch_krl_target *t = rch_krli_target_agg(s, 2, e, RCH_KRL_ASSIGNMENT, 0, n);
        if (t && !t->error[0] && t->type >= RCH_KRL_POS && !d &&
            !((t->mask >> RCH_KRL_S) & 1u && (t->mask >> RCH_KRL_T) & 1u))
            snprintf(t->error, sizeof t->error, "%s is not declared in this file and has no S and T: a FRAME or a "
                     "POS, its type cannot be told", n);
        if (t)
            rch_krli_set_frames(s, t, NULL);
        return;
    }
    /* a member of a target changed (XP1.X = 10) */
    for (size_t k = 1; k + 1 < eq; ++k)
        if (rch_krli_tk_ch(s, k, '.') && s->tk[k + 1].kind == TK_ID) {
            char m[8];
            int ax = -1;
            if (s->tk[k + 1].len < sizeof m) {
                rch_krli_tk_name(m, sizeof m, s, k + 1);
                if (rch_krli_slot_of(m, &ax) >= 0 && (!d || (d->type >= 1 && d->type <= 4) || n[0] != '$')) {
                    rch_krli_refuse_at(s, k + 1, "a target's component assigned: rcal cannot correct it");
                    return;
                }
            }
        }
    rch_krli_refuse_stray(s, eq + 1, s->ntk, "an expression");
}

static void bas_call(rch_krli_scan *s)
{
    /* BAS ( #TOOL , n ) */
    if (!rch_krli_tk_ch(s, 1, '('))
        return;
    if (rch_krli_tk_is(s, 2, "#INITMOV")) {
        rch_krli_set_state(&s->tool, 1, NULL, "$NULLFRAME (BAS #INITMOV)", NULL);
        rch_krli_set_state(&s->base, 1, NULL, "$NULLFRAME (BAS #INITMOV)", NULL);
        return;
    }
    const int tool = rch_krli_tk_is(s, 2, "#TOOL"), base = rch_krli_tk_is(s, 2, "#BASE");
    if (!tool && !base)
        return;
    rch_krli_fstate *f = tool ? &s->tool : &s->base;
    char why[200], from[64];
    if (rch_krli_tk_ch(s, 3, ',') && 4 < s->ntk && s->tk[4].kind == TK_NUM && rch_krli_tk_ch(s, 5, ')')) {
        const int n = rch_krli_tk_int(s, 4);
        snprintf(from, sizeof from, "BAS(#%s,%d) at line %u", tool ? "TOOL" : "BASE", n, s->line);
        if (n == 0) {
            rch_krli_set_state(f, 1, NULL, from, NULL);
            return;
        }
        if (n > 0 && n < MAX_DATA && (tool ? s->have_tool[n] : s->have_base[n])) {
            rch_krli_set_state(f, 1, tool ? &s->tool_data[n] : &s->base_data[n], from, NULL);
            return;
        }
        snprintf(why, sizeof why, "%s_DATA[%d] (BAS at line %u) is not defined in this file", tool ? "TOOL" : "BASE",
                 n, s->line);
    } else
        snprintf(why, sizeof why, "BAS at line %u selects a frame rcal cannot tell", s->line);
    rch_krli_set_state(f, 0, NULL, "BAS", why);
}

static void statement(rch_krli_scan *s)
{
    if (s->ntk == 0)
        return;
    size_t i = 0;
    if (rch_krli_tk_is(s, i, "GLOBAL"))
        ++i;
    if (rch_krli_tk_is(s, i, "DECL")) {
        ++i;
        if (rch_krli_tk_is(s, i, "GLOBAL"))
            ++i;
        if (rch_krli_tk_is(s, i, "CONST"))
            ++i;
        declaration(s, i);
        return;
    }
    if (rch_krli_type_code(s, i) && i + 1 < s->ntk && s->tk[i + 1].kind == TK_ID) {
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
        rch_krli_refuse_at(s, 0, "a relative motion: its end depends on where the robot is, rcal cannot correct it");
        return;
    }
    if (rch_krli_tk_is(s, 0, "BAS")) {
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
            else if (depth == 0 && s->tk[k].kind == '=' && !rch_krli_tk_ch(s, k + 1, '=') &&
                     !rch_krli_tk_ch(s, k - 1, '<') &&
                     !rch_krli_tk_ch(s, k - 1, '>'))
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
        rch_krli_refuse_stray(s, 0, s->ntk, "a statement rcal does not read");
}

static int run_pass(rch_krli_scan *s, int pass)
{
    s->pass = pass;
    s->line = 0;
    rch_krli_set_state(&s->tool, 1, NULL, "$NULLFRAME (default)", NULL);
    rch_krli_set_state(&s->base, 1, NULL, "$NULLFRAME (default)", NULL);
    size_t a = 0;
    while (a < s->len) {
        size_t b = a;
        while (b < s->len && s->text[b] != '\n' && s->text[b] != '\r')
            ++b;
        ++s->line;
        s->line_off = a;
        if (rch_krli_tokenize(s, a, b) != 0)
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
    rch_krli_scan *s = calloc(1, sizeof *s);
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
