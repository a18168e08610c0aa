/* SPDX-License-Identifier: MIT */
/* rch_rapid_uses.c - the uses of a RAPID module's targets (see
 * rch_rapid_int.h): the instructions rcal reads with ABB's argument order
 * (the target arguments and the Tool by position, \WObj:= by name), each
 * statement's instruction past the block words, the tool and work object
 * each target is used with, the assignments that pass a target's uses on,
 * and why a robtarget's use cannot be told (use_error).
 * Depends on: the token queries (rch_rapid.c), the declarations
 * (rch_rapid_types.c). Memory: the uses' tables on the heap for the call.
 * Errors: -1 with the scan's diag set (out of memory). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_rapid_int.h"

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

static const instr_desc *find_instr(const rch_rpi_scan *s, size_t i)
{
    for (size_t k = 0; k < sizeof instrs / sizeof instrs[0]; ++k)
        if (rch_rpi_tok_is(s, i, instrs[k].name))
            return &instrs[k];
    return NULL;
}

/* The uses being collected: the named targets by name, each target's state. */
enum { NB = 1024 };
typedef struct {
    rch_rpi_scan *s;
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

/* Target k: a literal of out, or a name declared without one (ps). */
static rch_rapid_target *tgt(const uses *u, size_t k)
{
    return k < u->s->out->n ? &u->s->out->t[k] : &u->ps[k - u->s->out->n];
}

/* Target k is used by instruction instr (line) with tool and wobj, or, bad
 * set, with a tool or work object that cannot be read. */
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
    const rch_rpi_scan *s = u->s;
    if (s->tk.t[j].type != RCH_RPI_IDENT || (j > 0 && (rch_rpi_punct(s, j - 1, '.') || rch_rpi_punct(s, j - 1, '\\'))) ||
        rch_rpi_punct(s, j + 1, '.'))
        return (size_t)-1;
    const rch_rpi_tok *t = &s->tk.t[j];
    for (size_t h = u->head[rch_rpi_hash_ci(s->text + t->off, t->len) % NB]; h != (size_t)-1; h = u->next[h])
        if (strlen(tgt(u, h)->name) == t->len && strncasecmp(tgt(u, h)->name, s->text + t->off, t->len) == 0)
            return h;
    return (size_t)-1;
}

/* Every target the tokens [b, e) name or hold (inline), into idx (at most
 * cap); how many (more are dropped: a statement names few). */
static size_t mentions(const uses *u, size_t b, size_t e, size_t *idx, size_t cap)
{
    const rch_rpi_scan *s = u->s;
    const rch_rapid_targets *o = s->out;
    size_t n = 0;
    if (b >= e)
        return 0;
    for (size_t j = b; j < e; ++j)
        for (size_t h = named_first(u, j); h != (size_t)-1 && n < cap; h = u->next[h]) {
            const rch_rpi_tok *t = &s->tk.t[j];
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
static size_t piece_end(const rch_rpi_scan *s, size_t b, size_t e)
{
    size_t depth = 0, c = b;
    for (; c < e && !(depth == 0 && rch_rpi_punct(s, c, ',')); ++c) {
        if (rch_rpi_punct(s, c, '[') || rch_rpi_punct(s, c, '(') || rch_rpi_punct(s, c, '{'))
            ++depth;
        else if ((rch_rpi_punct(s, c, ']') || rch_rpi_punct(s, c, ')') || rch_rpi_punct(s, c, '}')) && depth > 0)
            --depth;
    }
    return c;
}

/* The instruction (or CalcJointT) named at token at, its arguments [b, e):
 * its tool (position ds->tool) and work object (\WObj:=) onto the targets of
 * its target arguments. */
static void instr_uses(uses *u, const instr_desc *ds, size_t at, size_t b, size_t e)
{
    rch_rpi_scan *s = u->s;
    const unsigned line = s->tk.t[at].line;
    char tool[48] = "", wobj[48] = "", bad[256] = "";
    size_t pb[8], pe[8]; /* the target arguments' pieces */
    size_t npc = 0;
    int pos = 0, have_tool = ds->tool < 0;
    for (size_t c = b; c < e; c = piece_end(s, c, e) + 1) {
        const size_t ce = piece_end(s, c, e);
        /* \WObj:=NAME anywhere in the piece, at its depth 0 */
        for (size_t j = c, depth = 0; j < ce; ++j) {
            if (rch_rpi_punct(s, j, '[') || rch_rpi_punct(s, j, '(') || rch_rpi_punct(s, j, '{'))
                ++depth;
            else if ((rch_rpi_punct(s, j, ']') || rch_rpi_punct(s, j, ')') || rch_rpi_punct(s, j, '}')) && depth > 0)
                --depth;
            if (depth || !rch_rpi_punct(s, j, '\\') || j + 1 >= ce || !rch_rpi_tok_is(s, j + 1, "WObj"))
                continue;
            if (j + 3 < ce + 1 && j + 2 < ce && s->tk.t[j + 2].type == RCH_RPI_ASSIGN && j + 3 < ce &&
                s->tk.t[j + 3].type == RCH_RPI_IDENT && (j + 4 == ce || rch_rpi_punct(s, j + 4, '\\')))
                rch_rpi_tok_name(wobj, sizeof wobj, s, j + 3);
            else if (!bad[0])
                snprintf(bad, sizeof bad, "the \\WObj argument of %s (line %u) is not a work object's name: rcal cannot "
                         "tell the frame the robtarget is in", ds->name, line);
        }
        if (c < ce && rch_rpi_punct(s, c, '\\'))
            continue; /* an optional argument */
        for (unsigned k = 0; k < ds->npt; ++k)
            if (ds->pt[k] == pos && npc < 8) {
                pb[npc] = c;
                pe[npc++] = ce;
            }
        if (pos == ds->tool) {
            have_tool = 1;
            if (c < ce && s->tk.t[c].type == RCH_RPI_IDENT && (c + 1 == ce || rch_rpi_punct(s, c + 1, '\\'))) {
                rch_rpi_tok_name(tool, sizeof tool, s, c);
                const rch_rpi_decl *dc = rch_rpi_find_decl(s, c);
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
    rch_rpi_tok_name(name, sizeof name, s, at);
    size_t idx[64];
    for (size_t p = 0; p < npc; ++p) {
        const size_t n = mentions(u, pb[p], pe[p], idx, 64);
        for (size_t k = 0; k < n; ++k)
            mark_known(u, idx[k], tool, wobj, name, line, bad[0] ? bad : NULL);
    }
}

static int is_kw(const rch_rpi_scan *s, size_t j, const char *const *kw, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        if (rch_rpi_tok_is(s, j, kw[k]))
            return 1;
    return 0;
}

/* The first token at depth 0 in [j, e) that is one of kw (n), or e. */
static size_t find_kw(const rch_rpi_scan *s, size_t j, size_t e, const char *const *kw, size_t n)
{
    for (size_t depth = 0; j < e; ++j) {
        if (rch_rpi_punct(s, j, '[') || rch_rpi_punct(s, j, '(') || rch_rpi_punct(s, j, '{'))
            ++depth;
        else if ((rch_rpi_punct(s, j, ']') || rch_rpi_punct(s, j, ')') || rch_rpi_punct(s, j, '}')) && depth > 0)
            --depth;
        else if (depth == 0 && (kw ? is_kw(s, j, kw, n) : rch_rpi_punct(s, j, ':')))
            return j;
    }
    return e;
}

/* Past a '(' at j: the token after its ')', or e. */
static size_t past_parens(const rch_rpi_scan *s, size_t j, size_t e)
{
    if (!rch_rpi_punct(s, j, '('))
        return j;
    const size_t c = rch_rpi_close_of(s, j);
    return c < e ? c + 1 : e;
}

/* The statement [i, e)'s instruction: past the block words before it (PROC
 * headers, IF ... THEN, labels, ...). e for a declaration. */
static size_t stmt_head(const rch_rpi_scan *s, size_t i, size_t e)
{
    static const char *const skip[] = {"LOCAL", "TASK", "ENDPROC", "ENDFUNC", "ENDTRAP", "ENDIF", "ENDWHILE",
                                       "ENDFOR", "ENDTEST", "ELSE", "ENDMODULE", "UNDO", "BACKWARD", "ENDRECORD",
                                       "SYSMODULE", "NOSTEPIN", "VIEWONLY", "READONLY", "NOVIEW"};
    static const char *const decl_kw[] = {"VAR", "PERS", "CONST", "ALIAS", "RECORD"};
    static const char *const then_kw[] = {"THEN", "DO"}, *const case_kw[] = {"CASE", "DEFAULT"};
    size_t j = i;
    while (j < e) {
        if (s->tk.t[j].type != RCH_RPI_IDENT)
            return j;
        if (is_kw(s, j, skip, sizeof skip / sizeof skip[0]))
            ++j;
        else if (is_kw(s, j, decl_kw, sizeof decl_kw / sizeof decl_kw[0]))
            return e;
        else if (rch_rpi_tok_is(s, j, "ERROR"))
            j = past_parens(s, j + 1, e);
        else if (rch_rpi_tok_is(s, j, "MODULE") || rch_rpi_tok_is(s, j, "PROC") || rch_rpi_tok_is(s, j, "TRAP"))
            j = past_parens(s, j + 2, e);
        else if (rch_rpi_tok_is(s, j, "FUNC"))
            j = past_parens(s, j + 3, e);
        else if (rch_rpi_tok_is(s, j, "IF") || rch_rpi_tok_is(s, j, "ELSEIF") || rch_rpi_tok_is(s, j, "WHILE") ||
                 rch_rpi_tok_is(s, j, "FOR")) {
            const size_t k = find_kw(s, j + 1, e, then_kw, 2);
            if (k == e) { /* a compact IF: its instruction, if rcal reads it */
                for (size_t m = j + 1; m < e; ++m)
                    if (find_instr(s, m))
                        return m;
                return j;
            }
            j = k + 1;
        } else if (rch_rpi_tok_is(s, j, "TEST")) {
            j = find_kw(s, j + 1, e, case_kw, 2);
        } else if (rch_rpi_tok_is(s, j, "CASE") || rch_rpi_tok_is(s, j, "DEFAULT")) {
            const size_t k = find_kw(s, j + 1, e, NULL, 0);
            j = k < e ? k + 1 : e;
        } else if (rch_rpi_punct(s, j + 1, ':') && j + 1 < e)
            j += 2; /* a label */
        else
            return j;
    }
    return e;
}

/* One statement [i, e): the uses of the targets it names. */
static int stmt_uses(uses *u, size_t i, size_t e)
{
    rch_rpi_scan *s = u->s;
    const size_t h = stmt_head(s, i, e);
    if (h >= e)
        return 0;
    for (size_t j = h; j + 1 < e; ++j) /* CalcJointT(...) anywhere in it */
        if (rch_rpi_tok_is(s, j, "CalcJointT") && rch_rpi_punct(s, j + 1, '(')) {
            const size_t c = rch_rpi_close_of(s, j + 1);
            if (c < e)
                instr_uses(u, &calc_joint_t, j, j + 2, c);
        }
    const unsigned line = s->tk.t[h].line;
    char what[160], nm[48];
    size_t idx[64];
    rch_rpi_tok_name(nm, sizeof nm, s, h);
    const instr_desc *ds = find_instr(s, h);
    if (ds) {
        instr_uses(u, ds, h, h + 1, e);
        return 0;
    }
    if (is_kw(s, h, harmless, sizeof harmless / sizeof harmless[0]))
        return 0;
    /* an assignment NAME[{...}][.field...] := value */
    size_t a = h + 1;
    if (rch_rpi_punct(s, a, '{'))
        a = rch_rpi_close_of(s, a) < e ? rch_rpi_close_of(s, a) + 1 : e;
    const int field = rch_rpi_punct(s, a, '.');
    while (a + 1 < e && rch_rpi_punct(s, a, '.') && s->tk.t[a + 1].type == RCH_RPI_IDENT)
        a += 2;
    if (s->tk.t[h].type == RCH_RPI_IDENT && a < e && s->tk.t[a].type == RCH_RPI_ASSIGN) {
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
    if (rch_rpi_punct(s, h, '%'))
        snprintf(what, sizeof what, "passed to a late-bound procedure call (line %u)", line);
    else if (rch_rpi_tok_is(s, h, "IF"))
        snprintf(what, sizeof what, "named in a compact IF (line %u)", line);
    else if (rch_rpi_tok_is(s, h, "RETURN"))
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
            rch_rpi_tok_name(nm, sizeof nm, u->s, fl->dest);
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
int rch_rpi_note_uses(rch_rpi_scan *s)
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
        const unsigned hb = rch_rpi_hash_ci(o->t[m].name, nl) % NB;
        u.next[m] = u.head[hb];
        u.head[hb] = m;
    }
    for (size_t k = 0; rc == 0 && k < s->ndc; ++k) { /* declared without a literal */
        const rch_rpi_decl *dc = &s->dc[k];
        const unsigned hb = rch_rpi_hash_ci(dc->name, strlen(dc->name)) % NB;
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
        while (e < s->tk.n && !(depth == 0 && rch_rpi_punct(s, e, ';'))) {
            if (rch_rpi_punct(s, e, '[') || rch_rpi_punct(s, e, '(') || rch_rpi_punct(s, e, '{'))
                ++depth;
            else if ((rch_rpi_punct(s, e, ']') || rch_rpi_punct(s, e, ')') || rch_rpi_punct(s, e, '}')) && depth > 0)
                --depth;
            ++e;
        }
        size_t from = i;
        for (size_t j = i; j < e; ++j) { /* a RECORD's fields are no statements */
            if (rch_rpi_tok_is(s, j, "RECORD"))
                in_record = 1;
            else if (rch_rpi_tok_is(s, j, "ENDRECORD")) {
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
