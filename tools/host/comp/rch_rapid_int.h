/* SPDX-License-Identifier: MIT */
/* rch_rapid_int.h - what the RAPID reader's files share: the tokens, the
 * declarations and types a module defines, its tools and work objects, and
 * the passes of rch_rapid_scan (rch_rapid_scan.c) over them: the tokens and
 * their queries (rch_rapid.c), the types and declarations
 * (rch_rapid_types.c), the aggregates classified into target literals
 * (rch_rapid_literal.c), the uses of targets by instructions
 * (rch_rapid_uses.c). Internal to the reader (prefix rch_rpi_), not part of
 * the host library's API (rch_rapid.h is).
 * Depends on: rch_rapid.h, rch_diag. Memory: the token and declaration
 * arrays on the heap, owned by the scan (rch_rapid_scan frees them); the
 * targets in rch_rapid_targets. Errors: -1 with the scan's diag set. */
#ifndef RCH_RAPID_INT_H
#define RCH_RAPID_INT_H

#include <stddef.h>

#include "rch_rapid.h"

typedef enum { RCH_RPI_IDENT, RCH_RPI_NUM, RCH_RPI_STR, RCH_RPI_ASSIGN, RCH_RPI_PUNCT } rch_rpi_tok_type;

typedef struct {
    rch_rpi_tok_type type;
    char ch; /* RCH_RPI_PUNCT: the character */
    size_t off, len;
    unsigned line, col;
} rch_rpi_tok;

typedef struct {
    rch_rpi_tok *t;
    size_t n, cap;
} rch_rpi_toks;

/* a name declared in the module */
typedef struct {
    char name[48];
    char type[32]; /* its declared type */
    int kind;      /* rch_rapid_kind, 0: another type, -1: declared with two types */
    int array;     /* declared with {dims} */
    int rec;       /* its type is the record ut[rec] that holds a target, or -1 */
} rch_rpi_decl;

/* a type name the module defines: ALIAS robtarget NAME (kind), or a RECORD
 * with a target field (field names it, kind its kind) */
typedef struct {
    char name[48], field[96];
    int kind;
    int alias; /* 1 ALIAS, 0 RECORD */
} rch_rpi_utype;

/* a work object the module declares with a literal wobjdata */
typedef struct {
    char name[48], ufmec[48];
    int robhold, ufprog;
    double uf[7], of[7];
} rch_rpi_wobj;

typedef struct {
    const char *text;
    size_t len;
    const char *name;
    rch_rpi_toks tk;
    rch_rpi_decl *dc;
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
    rch_rpi_wobj wobjs[32];
    size_t nwobjs;
    rch_rpi_utype ut[32]; /* ALIAS and RECORD types (more are not read) */
    size_t nut;
} rch_rpi_scan; /* one module being read */

/* rch_rapid.c: the tokens and their queries */
/* text -> tokens (comments dropped). 0 or -1 (d set: NUL byte, string not
 * closed, out of memory). */
int rch_rpi_tokenize(rch_rpi_scan *s);
/* Token i is the identifier w (case-insensitive, as RAPID). */
int rch_rpi_tok_is(const rch_rpi_scan *s, size_t i, const char *w);
/* Token i (i < n) is the punctuation ch. */
int rch_rpi_punct(const rch_rpi_scan *s, size_t i, char ch);
/* Token i's text into buf (n), cut to fit. */
void rch_rpi_tok_name(char *buf, size_t n, const rch_rpi_scan *s, size_t i);
/* Index of the bracket closing the one at i ('[', '(' or '{'), or s->tk.n
 * when it is not closed, a bracket of another kind closes first, or the
 * nesting is deeper than 64. */
size_t rch_rpi_close_of(const rch_rpi_scan *s, size_t i);
/* FNV-1a of p (n) lowercased: the buckets of names. */
unsigned rch_rpi_hash_ci(const char *p, size_t n);

/* rch_rapid_types.c: RECORD, ALIAS and the declarations */
/* ALIAS and RECORD types that hold a target, into s->ut. */
void rch_rpi_collect_types(rch_rpi_scan *s);
/* VAR|PERS|CONST TYPE NAME, into s->dc. 0 or -1 (out of memory). */
int rch_rpi_collect_decls(rch_rpi_scan *s);
/* The ALIAS or RECORD type named at token i, or NULL. */
const rch_rpi_utype *rch_rpi_find_utype(const rch_rpi_scan *s, size_t i);
/* The target kind of the type named at token i: jointtarget, robtarget or
 * an ALIAS of them; 0 for another type. */
int rch_rpi_target_type(const rch_rpi_scan *s, size_t i);
/* The declaration of the name at token i, or NULL. */
const rch_rpi_decl *rch_rpi_find_decl(const rch_rpi_scan *s, size_t i);

/* rch_rapid_literal.c: the target literals */
/* The target the aggregate at token i (closing at c) stands for, from what
 * precedes it, into s->out (tooldata and wobjdata literals into s->tools,
 * s->wobjs). 0 or -1 (out of memory). */
int rch_rpi_classify(rch_rpi_scan *s, size_t i, size_t c);

/* rch_rapid_uses.c: the uses of targets by instructions */
/* Every statement's instruction: the tool and work object of each target's
 * uses, or why they cannot be told (use_error). 0 or -1 (out of memory). */
int rch_rpi_note_uses(rch_rpi_scan *s);

#endif
