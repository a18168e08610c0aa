/* SPDX-License-Identifier: MIT */
/* rch_jw.c - the one JSON writer (see rch_jw.h). */
#include "rch_jw.h"

#include "rc_version.h"
#include "rch_text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rch_jw_init(rch_jw *w, FILE *f, int pretty)
{
    memset(w, 0, sizeof *w);
    w->f = f;
    w->pretty = pretty;
}

static void put(rch_jw *w, const char *s)
{
    if (fputs(s, w->f) == EOF)
        w->err = 1;
}

static void indent(rch_jw *w)
{
    if (!w->pretty)
        return;
    put(w, "\n");
    for (int i = 0; i < w->depth; ++i)
        put(w, "  ");
}

static void write_string(rch_jw *w, const char *s)
{
    char buf[8];
    put(w, "\"");
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
        unsigned char c = *p;
        if (c == '"')
            put(w, "\\\"");
        else if (c == '\\')
            put(w, "\\\\");
        else if (c == '\n')
            put(w, "\\n");
        else if (c == '\t')
            put(w, "\\t");
        else if (c == '\r')
            put(w, "\\r");
        else if (c < 0x20) {
            snprintf(buf, sizeof buf, "\\u%04x", (unsigned)c);
            put(w, buf);
        } else if (c >= 0x80) {
            /* Well-formed UTF-8 is copied; any other byte becomes U+FFFD,
             * so the output is valid UTF-8 whatever the input path holds. */
            size_t n = rch_utf8_len(p);
            if (n) {
                memcpy(buf, p, n);
                buf[n] = '\0';
                put(w, buf);
                p += n - 1;
            } else {
                put(w, "\\ufffd");
            }
        } else {
            buf[0] = (char)c;
            buf[1] = '\0';
            put(w, buf);
        }
    }
    put(w, "\"");
}

/* Comma, indentation and key before a value. */
static void member(rch_jw *w, const char *key)
{
    if (w->depth > 0) {
        int in_obj = w->close[w->depth - 1] == '}';
        if ((key != NULL) != in_obj)
            w->err = 1; /* key in an array, or no key in an object */
        if (w->count[w->depth - 1])
            put(w, ",");
        if (w->count[w->depth - 1] < 255)
            w->count[w->depth - 1]++;
        indent(w);
    } else if (key || w->count[0] == 255) {
        w->err = 1;
    }
    if (key) {
        write_string(w, key);
        put(w, w->pretty ? ": " : ":");
    }
}

static void jw_open(rch_jw *w, const char *key, char o, char c)
{
    char s[2] = {o, '\0'};
    member(w, key);
    put(w, s);
    if (w->depth >= RCH_JW_MAX_DEPTH) {
        w->err = 1;
        return;
    }
    w->close[w->depth] = c;
    w->count[w->depth] = 0;
    w->depth++;
}

void rch_jw_obj(rch_jw *w, const char *key)
{
    jw_open(w, key, '{', '}');
}

void rch_jw_arr(rch_jw *w, const char *key)
{
    jw_open(w, key, '[', ']');
}

void rch_jw_end(rch_jw *w)
{
    if (w->depth <= 0) {
        w->err = 1;
        return;
    }
    int had = w->count[w->depth - 1] > 0;
    char s[2] = {w->close[w->depth - 1], '\0'};
    w->depth--;
    if (had)
        indent(w);
    put(w, s);
    if (w->depth == 0)
        w->count[0] = 255; /* one top-level value */
}

void rch_jw_str(rch_jw *w, const char *key, const char *v)
{
    member(w, key);
    if (v)
        write_string(w, v);
    else
        put(w, "null");
}

void rch_jw_numf(rch_jw *w, const char *key, double v, const char *fmt)
{
    char buf[64];
    member(w, key);
    if (!isfinite(v)) {
        put(w, "null");
        return;
    }
    snprintf(buf, sizeof buf, fmt, v);
    put(w, buf);
}

void rch_jw_num(rch_jw *w, const char *key, double v)
{
    rch_jw_numf(w, key, v, "%.17g");
}

void rch_jw_int(rch_jw *w, const char *key, long long v)
{
    char buf[32];
    member(w, key);
    snprintf(buf, sizeof buf, "%lld", v);
    put(w, buf);
}

void rch_jw_uint(rch_jw *w, const char *key, unsigned long long v)
{
    char buf[32];
    member(w, key);
    snprintf(buf, sizeof buf, "%llu", v);
    put(w, buf);
}

void rch_jw_bool(rch_jw *w, const char *key, int v)
{
    member(w, key);
    put(w, v ? "true" : "false");
}

void rch_jw_null(rch_jw *w, const char *key)
{
    member(w, key);
    put(w, "null");
}

void rch_jw_nums(rch_jw *w, const char *key, const double *v, size_t n)
{
    int pretty = w->pretty;
    rch_jw_arr(w, key);
    w->pretty = 0; /* short arrays of numbers on one line */
    for (size_t i = 0; i < n; ++i) {
        if (i)
            put(w, pretty ? ", " : ",");
        if (w->count[w->depth - 1] < 255)
            w->count[w->depth - 1]++;
        char buf[64];
        if (isfinite(v[i])) {
            snprintf(buf, sizeof buf, "%.17g", v[i]);
            put(w, buf);
        } else {
            put(w, "null");
        }
    }
    w->count[w->depth - 1] = 0; /* closing bracket on the same line */
    rch_jw_end(w);
    w->pretty = pretty;
}

int rch_jw_finish(rch_jw *w)
{
    put(w, "\n");
    if (fflush(w->f) == EOF)
        w->err = 1;
    return (w->err || w->depth != 0) ? -1 : 0;
}

const char *rch_jw_escape(const char *s, char *buf, size_t len)
{
    size_t o = 0;
    if (len == 0)
        return buf;
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
        char tmp[8];
        unsigned char c = *p;
        if (c == '"' || c == '\\') {
            tmp[0] = '\\';
            tmp[1] = (char)c;
            tmp[2] = '\0';
        } else if (c < 0x20) {
            snprintf(tmp, sizeof tmp, "\\u%04x", (unsigned)c);
        } else if (c >= 0x80) {
            size_t k = rch_utf8_len(p);
            if (k) {
                memcpy(tmp, p, k);
                tmp[k] = '\0';
                p += k - 1;
            } else {
                snprintf(tmp, sizeof tmp, "\\ufffd");
            }
        } else {
            tmp[0] = (char)c;
            tmp[1] = '\0';
        }
        size_t n = strlen(tmp);
        if (o + n >= len)
            break;
        memcpy(buf + o, tmp, n);
        o += n;
    }
    buf[o] = '\0';
    return buf;
}

void rch_jw_begin(rch_jw *w, FILE *f, int pretty, const char *format, int argc, char **argv)
{
    rch_jw_init(w, f, pretty);
    rch_jw_obj(w, NULL);
    rch_jw_header(w, format, argc, argv);
}

void rch_jw_strs(rch_jw *w, const char *const *kv)
{
    for (; kv[0]; kv += 2)
        rch_jw_str(w, kv[0], kv[1]);
}

void rch_jw_header(rch_jw *w, const char *format, int argc, char **argv)
{
    size_t len = 6;
    for (int i = 0; i < argc; ++i)
        len += strlen(argv[i]) + 1;
    char *cmd = malloc(len);
    if (cmd) {
        size_t o = 0;
        memcpy(cmd, "rcal", 4);
        o = 4;
        for (int i = 0; i < argc; ++i) {
            cmd[o++] = ' ';
            memcpy(cmd + o, argv[i], strlen(argv[i]));
            o += strlen(argv[i]);
        }
        cmd[o] = '\0';
    }
    rch_jw_str(w, "format", format);
    rch_jw_str(w, "tool", "rcal " RC_VERSION_STRING);
    rch_jw_str(w, "command", cmd);
    free(cmd);
}
