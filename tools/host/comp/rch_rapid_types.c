/* SPDX-License-Identifier: MIT */
/* rch_rapid_types.c - the types and declarations of a RAPID module (see
 * rch_rapid_int.h): ALIAS robtarget NAME, RECORD NAME ... ENDRECORD with a
 * field of a target type (nested records too), and every VAR|PERS|CONST
 * TYPE NAME [{dims}] with its kind, hashed by name (a name declared with
 * two types is marked, its assignments are not guessed).
 * Depends on: the token queries (rch_rapid.c). Memory: the declarations on
 * the heap (s->dc, s->dnext, freed by rch_rapid_scan). Errors: -1 with the
 * scan's diag set (out of memory). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_rapid_int.h"

static int base_target_type(const rch_rpi_scan *s, size_t i)
{
    if (rch_rpi_tok_is(s, i, "jointtarget"))
        return RCH_RAPID_JOINTTARGET;
    if (rch_rpi_tok_is(s, i, "robtarget"))
        return RCH_RAPID_ROBTARGET;
    return 0;
}

/* The ALIAS or RECORD type named at token i, or NULL. */
const rch_rpi_utype *rch_rpi_find_utype(const rch_rpi_scan *s, size_t i)
{
    const rch_rpi_tok *t = &s->tk.t[i];
    if (t->type != RCH_RPI_IDENT)
        return NULL;
    for (size_t k = 0; k < s->nut; ++k)
        if (strlen(s->ut[k].name) == t->len && strncasecmp(s->ut[k].name, s->text + t->off, t->len) == 0)
            return &s->ut[k];
    return NULL;
}

/* The target kind of the type named at token i: jointtarget, robtarget or an ALIAS of them. */
int rch_rpi_target_type(const rch_rpi_scan *s, size_t i)
{
    const int k = base_target_type(s, i);
    if (k)
        return k;
    const rch_rpi_utype *u = rch_rpi_find_utype(s, i);
    return u && u->alias ? u->kind : 0;
}

/* ALIAS robtarget NAME; and RECORD NAME ... ENDRECORD with a field of a
 * target type (or of a record that holds one), nested records in any order. */
void rch_rpi_collect_types(rch_rpi_scan *s)
{
    const size_t cap = sizeof s->ut / sizeof s->ut[0];
    for (size_t i = 0; i + 2 < s->tk.n && s->nut < cap; ++i)
        if (rch_rpi_tok_is(s, i, "ALIAS") && s->tk.t[i + 2].type == RCH_RPI_IDENT && base_target_type(s, i + 1)) {
            rch_rpi_utype *u = &s->ut[s->nut++];
            rch_rpi_tok_name(u->name, sizeof u->name, s, i + 2);
            u->field[0] = '\0';
            u->kind = base_target_type(s, i + 1);
            u->alias = 1;
        }
    for (int pass = 0; pass < 4; ++pass)
        for (size_t i = 0; i + 1 < s->tk.n && s->nut < cap; ++i) {
            if (!rch_rpi_tok_is(s, i, "RECORD") || s->tk.t[i + 1].type != RCH_RPI_IDENT || rch_rpi_find_utype(s, i + 1))
                continue;
            /* fields: TYPE NAME [{dims}] ; up to ENDRECORD */
            for (size_t j = i + 2; j + 1 < s->tk.n && !rch_rpi_tok_is(s, j, "ENDRECORD"); ++j) {
                if (s->tk.t[j].type != RCH_RPI_IDENT || s->tk.t[j + 1].type != RCH_RPI_IDENT ||
                    (j > 0 && !rch_rpi_punct(s, j - 1, ';') && j != i + 2))
                    continue;
                const rch_rpi_utype *inner = rch_rpi_find_utype(s, j);
                const int kind = rch_rpi_target_type(s, j);
                if (!kind && !(inner && !inner->alias))
                    continue;
                rch_rpi_utype *u = &s->ut[s->nut++];
                rch_rpi_tok_name(u->name, sizeof u->name, s, i + 1);
                char fn[48];
                rch_rpi_tok_name(fn, sizeof fn, s, j + 1);
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

const rch_rpi_decl *rch_rpi_find_decl(const rch_rpi_scan *s, size_t i)
{
    const rch_rpi_tok *t = &s->tk.t[i];
    const size_t nb = sizeof s->dhead / sizeof s->dhead[0];
    for (size_t k = s->dhead[rch_rpi_hash_ci(s->text + t->off, t->len) % nb]; k != (size_t)-1; k = s->dnext[k])
        if (strlen(s->dc[k].name) == t->len && strncasecmp(s->dc[k].name, s->text + t->off, t->len) == 0)
            return &s->dc[k];
    return NULL;
}

/* Declarations: VAR|PERS|CONST TYPE NAME. Names of target types are kept. */
int rch_rpi_collect_decls(rch_rpi_scan *s)
{
    const size_t nb = sizeof s->dhead / sizeof s->dhead[0];
    for (size_t b = 0; b < nb; ++b)
        s->dhead[b] = (size_t)-1;
    for (size_t i = 0; i + 2 < s->tk.n; ++i) {
        if (!(rch_rpi_tok_is(s, i, "VAR") || rch_rpi_tok_is(s, i, "PERS") || rch_rpi_tok_is(s, i, "CONST")))
            continue;
        if (s->tk.t[i + 1].type != RCH_RPI_IDENT || s->tk.t[i + 2].type != RCH_RPI_IDENT)
            continue;
        const int kind = rch_rpi_target_type(s, i + 1);
        const int array = rch_rpi_punct(s, i + 3, '{');
        const rch_rpi_utype *rt = rch_rpi_find_utype(s, i + 1);
        rch_rpi_decl *old = (rch_rpi_decl *)rch_rpi_find_decl(s, i + 2);
        if (old) {
            if (old->kind != kind || old->array != array)
                old->kind = -1; /* two meanings in one module: its assignments are not guessed */
            continue;
        }
        if (s->ndc == s->capdc) {
            const size_t nc = s->capdc ? 2 * s->capdc : 32;
            rch_rpi_decl *nd = realloc(s->dc, nc * sizeof *nd);
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
        rch_rpi_decl *dn = &s->dc[s->ndc];
        memset(dn, 0, sizeof *dn);
        rch_rpi_tok_name(dn->name, sizeof dn->name, s, i + 2);
        dn->kind = kind;
        dn->array = array;
        rch_rpi_tok_name(dn->type, sizeof dn->type, s, i + 1);
        dn->rec = rt && !rt->alias ? (int)(rt - s->ut) : -1;
        const unsigned h = rch_rpi_hash_ci(dn->name, strlen(dn->name)) % nb;
        s->dnext[s->ndc] = s->dhead[h];
        s->dhead[h] = s->ndc++;
    }
    return 0;
}
