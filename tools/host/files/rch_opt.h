/* SPDX-License-Identifier: MIT */
/* rch_opt.h - the one table-driven option parser of every rcal command.
 *
 * A command describes its options in a const table; rch_opt_parse() fills the
 * caller's variables, checks every number strictly (whole string, no leading
 * blank or sign for unsigned, no hex float, no wrap: 4294967297 is refused,
 * not taken modulo 2^32) against the range in the table, accepts both
 * "--name value" and "--name=value", answers -h / --help with a usage text
 * generated from the table, and never calls exit(): the caller returns the
 * status, so every command can be run in-process by a test.
 *
 * Host side (prefix rch_): may use stdio. */
#ifndef RCH_OPT_H
#define RCH_OPT_H

#include <stddef.h>
#include <stdio.h>

typedef enum {
    RCH_OPT_FLAG,   /* no value; out: int*, set to 1 */
    RCH_OPT_STR,    /* out: const char** (points into argv) */
    RCH_OPT_STRS,   /* repeatable; out: rch_opt_strs* (each occurrence appended) */
    RCH_OPT_CHOICE, /* out: const char**; value must be one of choices "a|b|c" */
    RCH_OPT_UINT,   /* out: unsigned long*; decimal digits only, range [min, max] */
    RCH_OPT_INT,    /* out: long*; optional '-', decimal digits, range [min, max] */
    RCH_OPT_DOUBLE, /* out: double*; finite decimal, range [min, max] */
    RCH_OPT_TRIPLE  /* out: double[3]; "X,Y,Z", each finite, range [min, max] */
} rch_opt_kind;

#define RCH_OPT_MAX_STRS 16
typedef struct {
    const char *v[RCH_OPT_MAX_STRS];
    size_t n;
} rch_opt_strs;

/* Option flags. */
#define RCH_OPT_REQUIRED 1u /* missing -> usage error naming it */

typedef struct {
    const char *name;    /* "--samples" */
    rch_opt_kind kind;
    void *out;           /* see rch_opt_kind; its value before parsing is the default shown */
    double min, max;     /* inclusive range for numbers, checked when min < max (so a
                          * table entry that leaves both 0 has no range) */
    const char *arg;     /* value name in the usage ("N", "FILE"); NULL: from the kind */
    const char *help;    /* one line; may be NULL */
    unsigned flags;      /* RCH_OPT_REQUIRED */
    const char *choices; /* RCH_OPT_CHOICE: "lm|ltlm|lm-paper|ltlm-paper" */
} rch_opt;

typedef struct {
    const char *cmd;      /* "simulate" (printed as "rcal simulate") */
    const char *summary;  /* one line: what the command does */
    const char *details;  /* paragraphs after the option list; may be NULL */
    const rch_opt *opts;  /* [n] */
    size_t n;             /* at most 64 */
} rch_cmdspec;

typedef enum {
    RCH_OPT_OK = 0,   /* parsed; run the command */
    RCH_OPT_HELP = 1, /* usage printed on `out`; the command returns 0 */
    RCH_OPT_ERROR = 2 /* message printed on `err`; the command returns 2 */
} rch_opt_status;

/* Parse argv[1..argc-1] (argv[0] is the command name). `seen` (may be NULL)
 * gets bit i set when spec->opts[i] was given. */
rch_opt_status rch_opt_parse(const rch_cmdspec *spec, int argc, char **argv, unsigned long long *seen, FILE *out,
                             FILE *err);

/* The command's entry: rch_opt_parse on stdout/stderr. Returns -1 when the
 * command should run, else its exit status (0 after -h/--help, 2 after a
 * usage error, already reported). */
int rch_opt_main(const rch_cmdspec *spec, int argc, char **argv, unsigned long long *seen);

/* The number of entries of an option table (an array, not a pointer). */
#define RCH_OPT_COUNT(table) (sizeof(table) / sizeof((table)[0]))

/* A command's whole option step in one call: *spec filled with cmd, summary,
 * details (may be NULL) and opts[n] (kept for rch_opt_fail and
 * rch_opt_given), then rch_opt_main. Returns -1 when the command should run,
 * else its exit status (0 after -h/--help, 2 after a usage error, already
 * reported). `seen` as in rch_opt_parse (may be NULL). */
int rch_opt_cmd(rch_cmdspec *spec, const char *cmd, const char *summary, const char *details, const rch_opt *opts,
                size_t n, int argc, char **argv, unsigned long long *seen);

/* The command's failure: "rcal CMD: file:line:col: what" on stderr; returns
 * the exit status 1. */
struct rch_diag;
int rch_opt_fail(const rch_cmdspec *spec, const struct rch_diag *d);

/* The usage text generated from the table (options, value names, ranges,
 * defaults, help lines, details). */
void rch_opt_usage(const rch_cmdspec *spec, FILE *f);

/* The command's manual page, man(7) markup, from the same table (the
 * hidden option --help-roff; the build writes rcal-CMD.1 with it,
 * cmake/rcal_man.cmake). */
void rch_opt_roff(const rch_cmdspec *spec, FILE *f);
/* s escaped for man(7) text: \ as \e, - as \-, a leading . or ' guarded. */
void rch_opt_roff_text(FILE *f, const char *s);
/* The command's case in the bash completion function (the hidden option
 * --help-bash): its options, an option's choices, files for a file's value. */
void rch_opt_bash(const rch_cmdspec *spec, FILE *f);

/* 1 when the option named `name` was given (seen from rch_opt_parse). */
int rch_opt_given(const rch_cmdspec *spec, unsigned long long seen, const char *name);

/* Strict number readers shared with the file parsers: the whole string must
 * be the number (no blanks, no hex, no inf/nan); 0 on success, -1 otherwise. */
int rch_parse_double(const char *s, double *out);
int rch_parse_ulong(const char *s, unsigned long *out);
int rch_parse_long(const char *s, long *out);
/* "X,Y,Z": three finite numbers separated by commas, blanks around them
 * allowed; 0 and out[0..2] set, or -1 and out untouched. */
int rch_parse_triple(const char *s, double out[3]);

#endif
