/* SPDX-License-Identifier: MIT */
/* rch_jw.h - the one JSON writer of rcal: every string escaped (quotes,
 * backslashes, control characters; well-formed UTF-8 copied, any other
 * byte written as U+FFFD), numbers that
 * are not finite written as null, nesting and commas tracked for the caller.
 *
 * Usage:
 *   rch_jw w; rch_jw_init(&w, f, 1);
 *   rch_jw_obj(&w, NULL);              top-level object
 *     rch_jw_str(&w, "format", "rcal-calibrate/1");
 *     rch_jw_num(&w, "rmse_mm", r);    "%.17g" unless rch_jw_numf gives a format
 *     rch_jw_arr(&w, "x"); rch_jw_num(&w, NULL, 1.0); rch_jw_end(&w);
 *   rch_jw_end(&w);
 *   if (rch_jw_finish(&w) != 0) ... write error or unbalanced nesting
 *
 * Host side (prefix rch_). */
#ifndef RCH_JW_H
#define RCH_JW_H

#include <stdio.h>

#define RCH_JW_MAX_DEPTH 32

typedef struct {
    FILE *f;
    int pretty;                          /* 1: newline + indent per member */
    int depth;
    unsigned char count[RCH_JW_MAX_DEPTH]; /* members written at each level (saturating) */
    char close[RCH_JW_MAX_DEPTH];        /* '}' or ']' */
    int err;                             /* sticky: write error or misuse */
} rch_jw;

void rch_jw_init(rch_jw *w, FILE *f, int pretty);
/* key is NULL inside an array or at the top level. */
void rch_jw_obj(rch_jw *w, const char *key);
void rch_jw_arr(rch_jw *w, const char *key);
void rch_jw_end(rch_jw *w);
void rch_jw_str(rch_jw *w, const char *key, const char *v); /* v NULL -> null */
void rch_jw_num(rch_jw *w, const char *key, double v);      /* not finite -> null */
void rch_jw_numf(rch_jw *w, const char *key, double v, const char *fmt); /* fmt: a printf double format */
void rch_jw_int(rch_jw *w, const char *key, long long v);
void rch_jw_uint(rch_jw *w, const char *key, unsigned long long v);
void rch_jw_bool(rch_jw *w, const char *key, int v);
void rch_jw_null(rch_jw *w, const char *key);
/* An array of n doubles. */
void rch_jw_nums(rch_jw *w, const char *key, const double *v, size_t n);
/* Newline at the end; 0 when everything was written and closed, -1 otherwise. */
int rch_jw_finish(rch_jw *w);

/* The members every command's JSON starts with: "format" (e.g.
 * "rcal-fkcheck/1"), "tool" ("rcal <version>") and "command" (the command
 * line, argv[0] the command's name, joined with blanks). */
void rch_jw_header(rch_jw *w, const char *format, int argc, char **argv);
/* A command's JSON: rch_jw_init on f (pretty as there), the top-level
 * object opened, and rch_jw_header. */
void rch_jw_begin(rch_jw *w, FILE *f, int pretty, const char *format, int argc, char **argv);

/* Several string members in one call: kv is name, value, name, value, ...,
 * ended by a NULL name; each pair as rch_jw_str (a NULL value -> null). */
void rch_jw_strs(rch_jw *w, const char *const *kv);

/* The context of a callback that writes a command's JSON later, e.g. an
 * rch_save_fn writing it beside a report: the result the JSON reports and
 * the command line that made it (for rch_jw_header). */
typedef struct {
    const void *result;
    int argc;
    char **argv;
} rch_jw_cmd;

/* Escape s as a JSON string body into buf (always terminated); returns buf. */
const char *rch_jw_escape(const char *s, char *buf, size_t len);

#endif
