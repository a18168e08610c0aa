#include "rcal_opts.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *value_of(int argc, char **argv, int *i, const char *name)
{
    if (strcmp(argv[*i], name) != 0)
        return NULL;
    if (*i + 1 >= argc) {
        fprintf(stderr, "rcal: option %s needs a value\n", name);
        exit(2);
    }
    return argv[++*i];
}

int rcal_opt_str(int argc, char **argv, int *i, const char *name, const char **out)
{
    const char *v = value_of(argc, argv, i, name);
    if (!v)
        return 0;
    *out = v;
    return 1;
}

int rcal_opt_double(int argc, char **argv, int *i, const char *name, double *out)
{
    const char *v = value_of(argc, argv, i, name);
    char *end;
    if (!v)
        return 0;
    errno = 0;
    *out = strtod(v, &end);
    if (*v == '\0' || *end != '\0' || errno != 0 || !isfinite(*out)) {
        fprintf(stderr, "rcal: option %s: '%s' is not a number\n", name, v);
        exit(2);
    }
    return 1;
}

int rcal_opt_uint(int argc, char **argv, int *i, const char *name, unsigned long *out)
{
    const char *v = value_of(argc, argv, i, name);
    char *end;
    if (!v)
        return 0;
    errno = 0;
    *out = strtoul(v, &end, 10);
    if (*v == '\0' || *v == '-' || *end != '\0' || errno != 0) {
        fprintf(stderr, "rcal: option %s: '%s' is not a non-negative integer\n", name, v);
        exit(2);
    }
    return 1;
}

int rcal_opt_unknown(const char *cmd, const char *arg)
{
    fprintf(stderr, "rcal %s: unknown option '%s' (see rcal %s --help)\n", cmd, arg, cmd);
    return 2;
}

int rcal_opt_missing(const char *cmd, const char *opt)
{
    fprintf(stderr, "rcal %s: %s is required (see rcal %s --help)\n", cmd, opt, cmd);
    return 2;
}
