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

int rcal_parse_triple(const char *s, double out[3])
{
    double v[3];
    const char *p = s;
    for (int k = 0; k < 3; ++k) {
        char *end;
        errno = 0;
        v[k] = strtod(p, &end);
        if (end == p || errno != 0 || !isfinite(v[k]))
            return -1;
        p = end;
        while (*p == ' ' || *p == '\t')
            ++p;
        if (k < 2) {
            if (*p != ',')
                return -1;
            ++p;
        }
    }
    if (*p != '\0')
        return -1;
    memcpy(out, v, sizeof v);
    return 0;
}

int rcal_opt_triple(int argc, char **argv, int *i, const char *name, double out[3])
{
    const char *v = value_of(argc, argv, i, name);
    if (!v)
        return 0;
    if (rcal_parse_triple(v, out) != 0) {
        fprintf(stderr, "rcal: option %s: '%s' is not X,Y,Z (three finite numbers separated by commas)\n", name, v);
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
