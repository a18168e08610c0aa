/* SPDX-License-Identifier: MIT */
/* rch_krl_int.h - what the KRL reader's two files share (prefix rch_krli_,
 * internal to rch_krl.c and rch_krl_stmt.c): the tokens of a line, the
 * scanner's state (declarations, TOOL_DATA/BASE_DATA, $TOOL and $BASE in
 * effect), and the token, aggregate and target helpers of rch_krl.c that
 * the statements (rch_krl_stmt.c) use. Not part of the host library's API
 * (rch_krl.h is). */
#ifndef RCH_KRL_INT_H
#define RCH_KRL_INT_H

#include <stddef.h>

#include "rch_krl.h"

enum { TK_ID = 'i', TK_NUM = 'n', TK_ENUM = 'e', TK_STR = 's' };

typedef struct {
    int kind;        /* TK_* or the punctuation character */
    size_t off, len; /* in the text */
} rch_krli_tok;

#define MAX_NAMES_LEN 48
#define MAX_DATA 65 /* TOOL_DATA[1..64], BASE_DATA[1..64] */

typedef struct {
    char name[MAX_NAMES_LEN];
    int type; /* 1..4 rch_krl_type, 5 FRAME, 6 FDAT, 0 other */
    int tool_no, base_no, ipo_tcp, fdat_ok;
} rch_krli_decl;

typedef struct {
    int known;
    rch_krl_frame f;
    char from[64];
    char why[200];
} rch_krli_fstate;

typedef struct {
    const char *text;
    size_t len;
    rch_krli_tok *tk;
    size_t ntk, cap;
    rch_krli_decl *dl;
    size_t ndl, capdl;
    int have_tool[MAX_DATA], have_base[MAX_DATA];
    rch_krl_frame tool_data[MAX_DATA], base_data[MAX_DATA];
    rch_krli_fstate tool, base;
    rch_krl_targets *out;
    unsigned line;
    size_t line_off; /* the line's first byte */
    int pass;
    int oom;
} rch_krli_scan;

int rch_krli_tk_is(const rch_krli_scan *s, size_t i, const char *w);
int rch_krli_tk_ch(const rch_krli_scan *s, size_t i, int ch);
void rch_krli_tk_name(char *buf, size_t n, const rch_krli_scan *s, size_t i);
int rch_krli_tk_int(const rch_krli_scan *s, size_t i);
int rch_krli_tokenize(rch_krli_scan *s, size_t a, size_t b);
rch_krli_decl *rch_krli_find_decl(rch_krli_scan *s, const char *name);
rch_krli_decl *rch_krli_add_decl(rch_krli_scan *s, const char *name, int type);
void rch_krli_refuse_at(rch_krli_scan *s, size_t i, const char *why);
size_t rch_krli_agg_end(const rch_krli_scan *s, size_t i);
int rch_krli_slot_of(const char *n, int *axis);
int rch_krli_agg_has_target_comp(const rch_krli_scan *s, size_t i, size_t e);
int rch_krli_read_frame(rch_krli_scan *s, rch_krl_frame *f, size_t i, size_t e, char *why, size_t why_len);
void rch_krli_set_frames(rch_krli_scan *s, rch_krl_target *t, const rch_krli_decl *fdat);
rch_krl_target *rch_krli_target_agg(rch_krli_scan *s, size_t i, size_t e, rch_krl_context ctx, int type,
                                    const char *name);
int rch_krli_type_code(const rch_krli_scan *s, size_t i);
void rch_krli_read_fdat(rch_krli_scan *s, rch_krli_decl *d, size_t i, size_t e);
void rch_krli_refuse_stray(rch_krli_scan *s, size_t a, size_t b, const char *what);
int rch_krli_data_index(const rch_krli_scan *s, size_t i, int *is_tool);
void rch_krli_set_state(rch_krli_fstate *f, int known, const rch_krl_frame *fr, const char *from, const char *why);

#endif
