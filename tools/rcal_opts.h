/* rcal_opts.h - tiny option helpers shared by the rcal subcommands. */
#ifndef RCAL_OPTS_H
#define RCAL_OPTS_H

/* The nominal robot shipped in data/, found at run time (rch_paths.h):
 * RCAL_DEFAULT_ROBOT is rch_default_robot(), an expression. */
#include "rch_paths.h"

/* If argv[*i] is NAME, consume its value into *out (advancing *i) and return
 * 1; exits with a usage error when the value is missing or malformed. */
int rcal_opt_str(int argc, char **argv, int *i, const char *name, const char **out);
int rcal_opt_double(int argc, char **argv, int *i, const char *name, double *out);
int rcal_opt_uint(int argc, char **argv, int *i, const char *name, unsigned long *out);
/* Same for a point "X,Y,Z": three finite numbers separated by commas (blanks
 * around the numbers allowed), written to out[0..2]. */
int rcal_opt_triple(int argc, char **argv, int *i, const char *name, double out[3]);
/* Parse "X,Y,Z" as above: 0 and out[0..2] set, or -1 and out untouched
 * (not three numbers, trailing text, out of range or not finite). */
int rcal_parse_triple(const char *s, double out[3]);
/* Print "rcal CMD: unknown option X" and return 2. */
int rcal_opt_unknown(const char *cmd, const char *arg);
int rcal_opt_missing(const char *cmd, const char *opt);

#endif
