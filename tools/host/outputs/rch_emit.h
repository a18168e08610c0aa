/* SPDX-License-Identifier: MIT */
/* rch_emit.h - C source of the firmware's compiled model tables (prefix rch_emit_).
 *
 * What: writes a header (fw_model_data.h) that defines the calibrated and
 * the nominal model as `static const rc_kin` tables (rc_kin.h: what the
 * compensation needs, nothing of the solver), so a firmware keeps them in
 * flash and never compiles a model at run time. Numbers are written with 17
 * significant digits inside RC_REAL_C(), so a double build reads back the
 * exact values rc_kin_compile gives and a float build the nearest floats.
 *
 * Everything that comes from outside (the model's name, the file names on
 * the command line) is escaped before it reaches the C text: in comments
 * every character other than letters, digits, blank, '/' and a few safe
 * punctuation marks is written as \xNN ('*', a backslash, '?', a newline:
 * nothing can end or open a comment or splice lines); in string literals
 * quotes, backslashes, '?' and every non-printable byte become escapes.
 *
 * Host side: stdio. Memory: none kept. Errors: -1 with rch_diag set (a
 * model that does not compile, a write error).
 */
#ifndef RCH_EMIT_H
#define RCH_EMIT_H

#include <stdio.h>

#include "rc_comp.h"
#include "rch_diag.h"

/* What the header is generated from. */
typedef struct rch_emit_src {
    const char *model_name;  /* the calibrated model's name (any bytes) */
    const char *command;     /* the command line that generated it, for the comment (any bytes) */
    unsigned comp_flags;     /* rc_comp_config.flags the tables are meant for */
} rch_emit_src;

/* The header text for cal and nom into f. 0, or -1 with d set. */
int rch_emit_c(FILE *f, const rch_emit_src *src, const rc_model *cal, const rc_model *nom, rch_diag *d);

/* Text as the inside of a C block comment (no comment delimiters written). */
void rch_emit_comment_text(FILE *f, const char *text);

/* Text as a C string literal, quotes included. */
void rch_emit_string(FILE *f, const char *text);

#endif
