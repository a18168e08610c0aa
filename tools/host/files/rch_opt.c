/* SPDX-License-Identifier: MIT */
/* rch_opt.c - table-driven option parser (see rch_opt.h). */
#include "rch_opt.h"

#include "rc_version.h"
#include "rch_diag.h"

#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

int rch_parse_ulong(const char *s, unsigned long *out)
{
    if (!s || !is_digit(*s))
        return -1; /* no blank, no sign, no empty string */
    for (const char *p = s; *p; ++p)
        if (!is_digit(*p))
            return -1;
    errno = 0;
    char *end;
    unsigned long v = strtoul(s, &end, 10);
    if (errno != 0 || *end != '\0')
        return -1; /* ERANGE: never wraps */
    *out = v;
    return 0;
}

int rch_parse_long(const char *s, long *out)
{
    if (!s)
        return -1;
    const char *p = (*s == '-') ? s + 1 : s;
    if (!is_digit(*p))
        return -1;
    for (const char *q = p; *q; ++q)
        if (!is_digit(*q))
            return -1;
    errno = 0;
    char *end;
    long v = strtol(s, &end, 10);
    if (errno != 0 || *end != '\0')
        return -1;
    *out = v;
    return 0;
}

/* Clinger's fast path (1990): a significand m of at most 15 decimal digits
 * and a power of ten 10^e10 with |e10| <= 22 are both exact doubles, so
 * m * 10^e10 (or m / 10^-e10) is one correctly rounded operation: the double
 * strtod gives, for a fraction of its time. Returns 0 and sets *out, or -1
 * (strtod then). Only where doubles are evaluated in double
 * (FLT_EVAL_METHOD 0). */
static int exact_decimal(double *out, uint64_t m, int e10, int neg)
{
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
    static const double p10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                   1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    double v = (double)m;
    if (m != 0) {
        if (e10 < -22 || e10 > 22)
            return -1;
        v = e10 < 0 ? v / p10[-e10] : v * p10[e10];
    }
    *out = neg ? -v : v;
    return 0;
#else
    (void)out;
    (void)m;
    (void)e10;
    (void)neg;
    return -1;
#endif
}

/* Digit c (after the point: frac 1) into the significand m of sig
 * significant digits and its power of ten e10; leading zeros count only in
 * e10, digits past the 15th not at all (the fast path is off then). */
static void add_digit(uint64_t *m, int *sig, int *e10, char c, int frac)
{
    if (*m == 0 && c == '0') {
        *e10 -= frac;
        return;
    }
    if (++*sig <= 15) {
        *m = *m * 10u + (uint64_t)(c - '0');
        *e10 -= frac;
    }
}

int rch_parse_double(const char *s, double *out)
{
    if (!s || !*s)
        return -1;
    /* Only a decimal number: sign, digits, one point, exponent. strtod
     * alone would take blanks, hex floats, "inf" and "nan". The scan also
     * gathers the significand and power of ten for the fast path. */
    const char *p = s;
    const int neg = *p == '-';
    if (*p == '+' || *p == '-')
        ++p;
    uint64_t m = 0;
    int digits = 0, sig = 0, e10 = 0;
    for (; is_digit(*p); ++p, ++digits)
        add_digit(&m, &sig, &e10, *p, 0);
    if (*p == '.')
        for (++p; is_digit(*p); ++p, ++digits)
            add_digit(&m, &sig, &e10, *p, 1);
    if (!digits)
        return -1;
    if (*p == 'e' || *p == 'E') {
        ++p;
        const int eneg = *p == '-';
        if (*p == '+' || *p == '-')
            ++p;
        if (!is_digit(*p))
            return -1;
        int x = 0;
        for (; is_digit(*p); ++p)
            x = x < 100000 ? x * 10 + (*p - '0') : x; /* saturates far outside the fast path */
        e10 += eneg ? -x : x;
    }
    if (*p != '\0')
        return -1;
    if (sig <= 15 && exact_decimal(out, m, e10, neg) == 0)
        return 0;
    errno = 0;
    char *end;
    double v = strtod(s, &end);
    if (*end != '\0' || !isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        return -1;
    *out = v;
    return 0;
}

int rch_parse_triple(const char *s, double out[3])
{
    double v[3];
    char buf[128];
    size_t len = s ? strlen(s) : 0;
    if (!s || len >= sizeof buf)
        return -1;
    memcpy(buf, s, len + 1);
    char *p = buf;
    for (int k = 0; k < 3; ++k) {
        char *sep = strchr(p, ',');
        if ((k < 2) != (sep != NULL))
            return -1;
        if (sep)
            *sep = '\0';
        while (*p == ' ' || *p == '\t')
            ++p;
        char *e = p + strlen(p);
        while (e > p && (e[-1] == ' ' || e[-1] == '\t'))
            *--e = '\0';
        if (rch_parse_double(p, &v[k]) != 0)
            return -1;
        p = sep ? sep + 1 : p;
    }
    memcpy(out, v, sizeof v);
    return 0;
}

static const char *kind_arg(const rch_opt *o)
{
    if (o->arg)
        return o->arg;
    switch (o->kind) {
    case RCH_OPT_FLAG: return NULL;
    case RCH_OPT_STR:
    case RCH_OPT_STRS: return "TEXT";
    case RCH_OPT_CHOICE: return o->choices;
    case RCH_OPT_UINT:
    case RCH_OPT_INT: return "N";
    case RCH_OPT_DOUBLE: return "X";
    case RCH_OPT_TRIPLE: return "X,Y,Z";
    }
    return "VALUE";
}

static int in_range(const rch_opt *o, double v)
{
    return !(o->min < o->max) || (v >= o->min && v <= o->max);
}

static void range_text(const rch_opt *o, char *buf, size_t len)
{
    buf[0] = '\0';
    if (o->min < o->max)
        snprintf(buf, len, " (%.10g to %.10g)", o->min, o->max);
}

static int choice_ok(const char *choices, const char *v)
{
    size_t n = strlen(v);
    const char *p = choices;
    while (p && *p) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == n && n > 0 && strncmp(p, v, n) == 0)
            return 1;
        p = bar ? bar + 1 : NULL;
    }
    return 0;
}

/* Store value v of option o; 0, or -1 with the message on err. */
static int store(const rch_cmdspec *spec, const rch_opt *o, const char *v, FILE *err)
{
    char rng[96];
    range_text(o, rng, sizeof rng);
    switch (o->kind) {
    case RCH_OPT_FLAG: return 0;
    case RCH_OPT_STR:
        if (!*v) {
            fprintf(err, "rcal %s: %s needs a non-empty value\n", spec->cmd, o->name);
            return -1;
        }
        *(const char **)o->out = v;
        return 0;
    case RCH_OPT_STRS: {
        rch_opt_strs *s = o->out;
        if (!*v) {
            fprintf(err, "rcal %s: %s needs a non-empty value\n", spec->cmd, o->name);
            return -1;
        }
        if (s->n >= RCH_OPT_MAX_STRS) {
            fprintf(err, "rcal %s: %s given more than %d times\n", spec->cmd, o->name, RCH_OPT_MAX_STRS);
            return -1;
        }
        s->v[s->n++] = v;
        return 0;
    }
    case RCH_OPT_CHOICE:
        if (!choice_ok(o->choices, v)) {
            fprintf(err, "rcal %s: %s '%s' is not one of %s\n", spec->cmd, o->name, v, o->choices);
            return -1;
        }
        *(const char **)o->out = v;
        return 0;
    case RCH_OPT_UINT: {
        unsigned long u;
        if (rch_parse_ulong(v, &u) != 0 || !in_range(o, (double)u)) {
            fprintf(err, "rcal %s: %s '%s' is %s%s\n", spec->cmd, o->name, v,
                    rch_parse_ulong(v, &u) != 0 ? "not a whole number" : "out of range", *rng ? rng : " (0 or more)");
            return -1;
        }
        *(unsigned long *)o->out = u;
        return 0;
    }
    case RCH_OPT_INT: {
        long l;
        if (rch_parse_long(v, &l) != 0 || !in_range(o, (double)l)) {
            fprintf(err, "rcal %s: %s '%s' is %s%s\n", spec->cmd, o->name, v,
                    rch_parse_long(v, &l) != 0 ? "not a whole number" : "out of range", rng);
            return -1;
        }
        *(long *)o->out = l;
        return 0;
    }
    case RCH_OPT_DOUBLE: {
        double d;
        if (rch_parse_double(v, &d) != 0 || !in_range(o, d)) {
            fprintf(err, "rcal %s: %s '%s' is %s%s\n", spec->cmd, o->name, v,
                    rch_parse_double(v, &d) != 0 ? "not a decimal number" : "out of range", rng);
            return -1;
        }
        *(double *)o->out = d;
        return 0;
    }
    case RCH_OPT_TRIPLE: {
        double t[3];
        if (rch_parse_triple(v, t) != 0 || !in_range(o, t[0]) || !in_range(o, t[1]) || !in_range(o, t[2])) {
            fprintf(err, "rcal %s: %s '%s' is not three numbers X,Y,Z%s\n", spec->cmd, o->name, v, rng);
            return -1;
        }
        memcpy(o->out, t, sizeof t);
        return 0;
    }
    }
    return -1;
}

static const rch_opt *find(const rch_cmdspec *spec, const char *name, size_t len, size_t *idx)
{
    for (size_t i = 0; i < spec->n; ++i)
        if (strlen(spec->opts[i].name) == len && strncmp(spec->opts[i].name, name, len) == 0) {
            *idx = i;
            return &spec->opts[i];
        }
    return NULL;
}

rch_opt_status rch_opt_parse(const rch_cmdspec *spec, int argc, char **argv, unsigned long long *seen_out, FILE *out,
                             FILE *err)
{
    unsigned long long seen = 0;
    if (spec->n > 64) {
        fprintf(err, "rcal %s: internal error: more than 64 options\n", spec->cmd);
        return RCH_OPT_ERROR;
    }
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            rch_opt_usage(spec, out);
            return RCH_OPT_HELP;
        }
        if (strcmp(a, "--help-roff") == 0 || strcmp(a, "--help-bash") == 0) { /* hidden: the build's man page */
            (a[7] == 'r' ? rch_opt_roff : rch_opt_bash)(spec, out);           /* and completion (cmake/rcal_man.cmake) */
            return RCH_OPT_HELP;
        }
        const char *eq = strncmp(a, "--", 2) == 0 ? strchr(a, '=') : NULL;
        size_t len = eq ? (size_t)(eq - a) : strlen(a);
        size_t k = 0;
        const rch_opt *o = find(spec, a, len, &k);
        if (!o) {
            fprintf(err, "rcal %s: unknown %s '%.*s' (rcal %s --help lists the options)\n", spec->cmd,
                    a[0] == '-' ? "option" : "argument", (int)len, a, spec->cmd);
            return RCH_OPT_ERROR;
        }
        if ((seen >> k & 1u) && o->kind != RCH_OPT_STRS) {
            fprintf(err, "rcal %s: %s given twice\n", spec->cmd, o->name);
            return RCH_OPT_ERROR;
        }
        seen |= 1ull << k;
        if (o->kind == RCH_OPT_FLAG) {
            if (eq) {
                fprintf(err, "rcal %s: %s takes no value\n", spec->cmd, o->name);
                return RCH_OPT_ERROR;
            }
            *(int *)o->out = 1;
            continue;
        }
        const char *v = eq ? eq + 1 : NULL;
        if (!v) {
            if (i + 1 >= argc) {
                fprintf(err, "rcal %s: %s needs a value (%s)\n", spec->cmd, o->name, kind_arg(o));
                return RCH_OPT_ERROR;
            }
            v = argv[++i];
        }
        if (store(spec, o, v, err) != 0)
            return RCH_OPT_ERROR;
    }
    for (size_t k = 0; k < spec->n; ++k)
        if ((spec->opts[k].flags & RCH_OPT_REQUIRED) && !(seen >> k & 1u)) {
            fprintf(err, "rcal %s: %s is required (rcal %s --help)\n", spec->cmd, spec->opts[k].name, spec->cmd);
            return RCH_OPT_ERROR;
        }
    if (seen_out)
        *seen_out = seen;
    return RCH_OPT_OK;
}

int rch_opt_main(const rch_cmdspec *spec, int argc, char **argv, unsigned long long *seen)
{
    const rch_opt_status st = rch_opt_parse(spec, argc, argv, seen, stdout, stderr);
    return st == RCH_OPT_OK ? -1 : st == RCH_OPT_HELP ? 0 : 2;
}

int rch_opt_cmd(rch_cmdspec *spec, const char *cmd, const char *summary, const char *details, const rch_opt *opts,
                size_t n, int argc, char **argv, unsigned long long *seen)
{
    spec->cmd = cmd;
    spec->summary = summary;
    spec->details = details;
    spec->opts = opts;
    spec->n = n;
    return rch_opt_main(spec, argc, argv, seen);
}

int rch_opt_fail(const rch_cmdspec *spec, const struct rch_diag *d)
{
    char msg[1024];
    fprintf(stderr, "rcal %s: %s\n", spec->cmd, rch_diag_str(d, msg, sizeof msg));
    return 1;
}

int rch_opt_given(const rch_cmdspec *spec, unsigned long long seen, const char *name)
{
    size_t k = 0;
    return find(spec, name, strlen(name), &k) ? (int)(seen >> k & 1u) : 0;
}

static void default_text(const rch_opt *o, char *buf, size_t len)
{
    buf[0] = '\0';
    switch (o->kind) {
    case RCH_OPT_STR:
    case RCH_OPT_CHOICE: {
        const char *s = *(const char *const *)o->out;
        if (s)
            snprintf(buf, len, " [default %s]", s);
        break;
    }
    case RCH_OPT_UINT: snprintf(buf, len, " [default %lu]", *(const unsigned long *)o->out); break;
    case RCH_OPT_INT: snprintf(buf, len, " [default %ld]", *(const long *)o->out); break;
    case RCH_OPT_DOUBLE: snprintf(buf, len, " [default %.10g]", *(const double *)o->out); break;
    case RCH_OPT_TRIPLE: {
        const double *t = o->out;
        snprintf(buf, len, " [default %.10g,%.10g,%.10g]", t[0], t[1], t[2]);
        break;
    }
    case RCH_OPT_FLAG:
    case RCH_OPT_STRS: break;
    }
}

void rch_opt_usage(const rch_cmdspec *spec, FILE *f)
{
    fprintf(f, "usage: rcal %s [options]\n  %s\n\noptions (--name VALUE or --name=VALUE):\n", spec->cmd,
            spec->summary ? spec->summary : "");
    for (size_t k = 0; k < spec->n; ++k) {
        const rch_opt *o = &spec->opts[k];
        char head[160], rng[96], def[160];
        const char *arg = kind_arg(o);
        snprintf(head, sizeof head, "%s%s%s", o->name, arg ? " " : "", arg ? arg : "");
        range_text(o, rng, sizeof rng);
        default_text(o, def, sizeof def);
        fprintf(f, "  %-28s %s%s%s%s%s\n", head, o->help ? o->help : "", (o->flags & RCH_OPT_REQUIRED) ? " (required)" : "",
                o->kind == RCH_OPT_STRS ? " (repeatable)" : "", rng, def);
    }
    fprintf(f, "  %-28s %s\n", "-h, --help", "this text");
    if (spec->details)
        fprintf(f, "\n%s\n", spec->details);
}

/* Text for man(7): a backslash as \e, every '-' as \- (options stay
 * searchable and copyable), a '.' or '\'' opening a line escaped by \&. */
void rch_opt_roff_text(FILE *f, const char *s)
{
    int line_start = 1;
    for (; *s; ++s) {
        if (line_start && (*s == '.' || *s == '\''))
            fputs("\\&", f);
        line_start = *s == '\n';
        if (*s == '\\')
            fputs("\\e", f);
        else if (*s == '-')
            fputs("\\-", f);
        else
            fputc(*s, f);
    }
}

void rch_opt_roff(const rch_cmdspec *spec, FILE *f)
{
    fputs(".\\\" generated by rcal ", f);
    rch_opt_roff_text(f, spec->cmd);
    fputs(" \\-\\-help\\-roff from its option table; do not edit\n.TH RCAL\\-", f);
    for (const char *c = spec->cmd; *c; ++c)
        fputc(*c >= 'a' && *c <= 'z' ? *c - 'a' + 'A' : *c, f);
    fprintf(f, " 1 \"\" \"rcal %s\" \"rcal manual\"\n.SH NAME\nrcal\\-", RC_VERSION_STRING);
    rch_opt_roff_text(f, spec->cmd);
    fputs(" \\- ", f);
    rch_opt_roff_text(f, spec->summary ? spec->summary : "");
    fputs("\n.nh\n.ad l\n.SH SYNOPSIS\n.B rcal ", f);
    rch_opt_roff_text(f, spec->cmd);
    fputs("\n[\\fIoptions\\fR]\n.SH DESCRIPTION\n", f);
    rch_opt_roff_text(f, spec->summary ? spec->summary : "");
    fputs(".\n.SH OPTIONS\nEach value is given as \\fB\\-\\-name VALUE\\fR or \\fB\\-\\-name=VALUE\\fR; numbers are "
          "checked whole against the range shown.\n",
          f);
    for (size_t k = 0; k < spec->n; ++k) {
        const rch_opt *o = &spec->opts[k];
        char rng[96], def[160];
        const char *arg = kind_arg(o);
        range_text(o, rng, sizeof rng);
        default_text(o, def, sizeof def);
        fputs(".TP\n\\fB", f);
        rch_opt_roff_text(f, o->name);
        fputs("\\fR", f);
        if (arg) {
            fputs(" \\fI", f);
            rch_opt_roff_text(f, arg);
            fputs("\\fR", f);
        }
        fputs("\n", f);
        rch_opt_roff_text(f, o->help ? o->help : "");
        if (o->flags & RCH_OPT_REQUIRED)
            fputs(" (required)", f);
        if (o->kind == RCH_OPT_STRS)
            fputs(" (repeatable)", f);
        rch_opt_roff_text(f, rng);
        rch_opt_roff_text(f, def);
        fputs("\n", f);
    }
    fputs(".TP\n\\fB\\-h\\fR, \\fB\\-\\-help\\fR\nprint the options and exit\n", f);
    if (spec->details) {
        fputs(".SH DETAILS\n.nf\n", f);
        rch_opt_roff_text(f, spec->details);
        fputs("\n.fi\n", f);
    }
    fputs(".SH EXIT STATUS\n0 on success, 1 when the work fails (the message names what and where), 2 on a usage "
          "error.\n.SH SEE ALSO\n\\fBrcal\\fR(1)\n",
          f);
}

/* One case of the completion function the build writes
 * (share/bash-completion/completions/rcal): $cur is the word completed,
 * $prev the one before it. */
void rch_opt_bash(const rch_cmdspec *spec, FILE *f)
{
    fputs("            opts='", f);
    for (size_t k = 0; k < spec->n; ++k)
        fprintf(f, "%s ", spec->opts[k].name);
    fputs("--help'\n            case \"$prev\" in\n", f);
    for (size_t k = 0; k < spec->n; ++k) {
        const rch_opt *o = &spec->opts[k];
        if (o->kind == RCH_OPT_CHOICE) {
            fprintf(f, "                %s) COMPREPLY=($(compgen -W '", o->name);
            for (const char *c = o->choices ? o->choices : ""; *c; ++c)
                fputc(*c == '|' ? ' ' : *c, f);
            fputs("' -- \"$cur\")); return ;;\n", f);
        } else if (o->kind == RCH_OPT_STR || o->kind == RCH_OPT_STRS) {
            fprintf(f, "                %s) COMPREPLY=($(compgen -f -- \"$cur\")); return ;;\n", o->name);
        } else if (o->kind != RCH_OPT_FLAG) {
            fprintf(f, "                %s) return ;;\n", o->name);
        }
    }
    fputs("            esac\n", f);
}
