/* SPDX-License-Identifier: MIT */
#include "rch_json.h"
#include "rch_file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *s;
    size_t len, pos;
    unsigned line;
    size_t line_start;
    const char *name;
    rch_diag *d;
    int failed;
} jp;

static unsigned json_col(const jp *p) { return (unsigned)(p->pos - p->line_start + 1); }

static void jfail(jp *p, const char *msg)
{
    if (!p->failed)
        rch_diag_set(p->d, p->name, p->line, json_col(p), "%s", msg);
    p->failed = 1;
}

static void jws(jp *p)
{
    while (p->pos < p->len) {
        char c = p->s[p->pos];
        if (c == '\n' || (c == '\r' && (p->pos + 1 >= p->len || p->s[p->pos + 1] != '\n'))) {
            ++p->line; /* LF, CRLF (at its LF) and a lone CR each end a line */
            p->line_start = p->pos + 1;
        } else if (c != ' ' && c != '\t' && c != '\r') {
            break;
        }
        ++p->pos;
    }
}

static rch_json *jnew(jp *p, rch_jtype t)
{
    rch_json *j = calloc(1, sizeof *j);
    if (!j) {
        jfail(p, "out of memory");
        return NULL;
    }
    j->type = t;
    j->line = p->line;
    j->col = json_col(p);
    return j;
}

/* The four hex digits of a \\u escape at p->pos into v. 0 or -1 (failed). */
static int jhex4(jp *p, unsigned *v)
{
    *v = 0;
    if (p->pos + 4 > p->len) {
        jfail(p, "truncated \\u escape");
        return -1;
    }
    for (int k = 0; k < 4; ++k) {
        char h = p->s[p->pos + (size_t)k];
        *v <<= 4;
        if (h >= '0' && h <= '9') *v |= (unsigned)(h - '0');
        else if (h >= 'a' && h <= 'f') *v |= (unsigned)(h - 'a' + 10);
        else if (h >= 'A' && h <= 'F') *v |= (unsigned)(h - 'A' + 10);
        else {
            jfail(p, "bad hex digit in \\u escape");
            return -1;
        }
    }
    p->pos += 4;
    if (*v == 0) {
        jfail(p, "\\u0000 is not allowed");
        return -1;
    }
    return 0;
}

/* One escape at p->pos (at the backslash) appended to o[*n] (room for 3
 * bytes). 0 or -1 (failed). */
static int jescape(jp *p, char *o, size_t *n)
{
    if (p->pos + 1 >= p->len) {
        jfail(p, "unterminated escape");
        return -1;
    }
    char e = p->s[p->pos + 1];
    unsigned v;
    p->pos += 2;
    switch (e) {
    case '"': o[(*n)++] = '"'; return 0;
    case '\\': o[(*n)++] = '\\'; return 0;
    case '/': o[(*n)++] = '/'; return 0;
    case 'b': o[(*n)++] = '\b'; return 0;
    case 'f': o[(*n)++] = '\f'; return 0;
    case 'n': o[(*n)++] = '\n'; return 0;
    case 'r': o[(*n)++] = '\r'; return 0;
    case 't': o[(*n)++] = '\t'; return 0;
    case 'u':
        if (jhex4(p, &v) != 0)
            return -1;
        if (v < 0x80) {
            o[(*n)++] = (char)v;
        } else if (v < 0x800) {
            o[(*n)++] = (char)(0xC0 | (v >> 6));
            o[(*n)++] = (char)(0x80 | (v & 0x3F));
        } else { /* surrogates kept as-is: names only, never interpreted */
            o[(*n)++] = (char)(0xE0 | (v >> 12));
            o[(*n)++] = (char)(0x80 | ((v >> 6) & 0x3F));
            o[(*n)++] = (char)(0x80 | (v & 0x3F));
        }
        return 0;
    default: jfail(p, "unknown escape in string"); return -1;
    }
}

static char *jstring(jp *p)
{
    /* at '"' */
    size_t cap = 32, n = 0;
    char *o = malloc(cap);
    if (!o) {
        jfail(p, "out of memory");
        return NULL;
    }
    ++p->pos;
    for (;;) {
        if (p->pos >= p->len) {
            jfail(p, "unterminated string");
            break;
        }
        unsigned char c = (unsigned char)p->s[p->pos];
        if (c == '"') {
            ++p->pos;
            o[n] = '\0';
            return o;
        }
        if (c < 0x20) {
            jfail(p, "control character in string");
            break;
        }
        if (n + 8 >= cap) {
            if (cap >= 4096) {
                jfail(p, "string longer than 4096 bytes");
                break;
            }
            char *no = realloc(o, cap * 2);
            if (!no) {
                jfail(p, "out of memory");
                break;
            }
            o = no;
            cap *= 2;
        }
        if (c != '\\') {
            o[n++] = (char)c;
            ++p->pos;
        } else if (jescape(p, o, &n) != 0) {
            break;
        }
    }
    free(o);
    return NULL;
}

static rch_json *jvalue(jp *p, int depth);

static int jappend(jp *p, rch_json *j, rch_json *item, char *key)
{
    /* sizeof *ni: one element pointer, as intended */
    rch_json **ni = realloc(j->items, (j->n + 1) * sizeof *ni); /* NOLINT(bugprone-sizeof-expression) */
    if (!ni) {
        jfail(p, "out of memory");
        return -1;
    }
    j->items = ni;
    if (j->type == RCH_JOBJ) {
        char **nk = realloc(j->keys, (j->n + 1) * sizeof *nk);
        if (!nk) {
            jfail(p, "out of memory");
            return -1;
        }
        j->keys = nk;
        j->keys[j->n] = key;
    }
    j->items[j->n++] = item;
    return 0;
}

static rch_json *jcontainer(jp *p, int depth, int obj)
{
    rch_json *j = jnew(p, obj ? RCH_JOBJ : RCH_JARR);
    if (!j)
        return NULL;
    ++p->pos;
    jws(p);
    if (p->pos < p->len && p->s[p->pos] == (obj ? '}' : ']')) {
        ++p->pos;
        return j;
    }
    for (;;) {
        char *key = NULL;
        unsigned kl = 0, kc = 0;
        jws(p);
        if (obj) {
            if (p->pos >= p->len || p->s[p->pos] != '"') {
                jfail(p, "expected a string key");
                goto bad;
            }
            kl = p->line;
            kc = json_col(p);
            key = jstring(p);
            if (!key)
                goto bad;
            for (size_t i = 0; i < j->n; ++i) {
                if (strcmp(j->keys[i], key) == 0) {
                    if (!p->failed)
                        rch_diag_set(p->d, p->name, kl, kc, "duplicate key \"%s\"", key);
                    p->failed = 1;
                    free(key);
                    goto bad;
                }
            }
            jws(p);
            if (p->pos >= p->len || p->s[p->pos] != ':') {
                jfail(p, "expected ':' after key");
                free(key);
                goto bad;
            }
            ++p->pos;
        }
        rch_json *v = jvalue(p, depth + 1);
        if (v && obj) {
            v->key_line = kl;
            v->key_col = kc;
        }
        if (!v || jappend(p, j, v, key) != 0) {
            rch_json_free(v);
            free(key);
            goto bad;
        }
        jws(p);
        if (p->pos < p->len && p->s[p->pos] == ',') {
            ++p->pos;
            continue;
        }
        if (p->pos < p->len && p->s[p->pos] == (obj ? '}' : ']')) {
            ++p->pos;
            return j;
        }
        jfail(p, obj ? "expected ',' or '}'" : "expected ',' or ']'");
        goto bad;
    }
bad:
    rch_json_free(j);
    return NULL;
}

static rch_json *jvalue(jp *p, int depth)
{
    jws(p);
    if (depth > 64) {
        jfail(p, "nesting deeper than 64");
        return NULL;
    }
    if (p->pos >= p->len) {
        jfail(p, "unexpected end of input");
        return NULL;
    }
    char c = p->s[p->pos];
    if (c == '{' || c == '[')
        return jcontainer(p, depth, c == '{');
    if (c == '"') {
        rch_json *j = jnew(p, RCH_JSTR);
        if (j && !(j->str = jstring(p))) {
            free(j);
            return NULL;
        }
        return j;
    }
    static const char *const words[3] = {"true", "false", "null"};
    for (int k = 0; k < 3; ++k) {
        size_t wl = strlen(words[k]);
        if (p->len - p->pos >= wl && memcmp(p->s + p->pos, words[k], wl) == 0) {
            rch_json *j = jnew(p, k == 2 ? RCH_JNULL : RCH_JBOOL);
            if (j)
                j->num = k == 0 ? 1.0 : 0.0;
            p->pos += wl;
            return j;
        }
    }
    if (c == '-' || (c >= '0' && c <= '9')) {
        size_t e = p->pos;
        char buf[64];
        if (e < p->len && p->s[e] == '-')
            ++e;
        if (e >= p->len || !(p->s[e] >= '0' && p->s[e] <= '9')) {
            jfail(p, "bad number");
            return NULL;
        }
        if (p->s[e] == '0' && e + 1 < p->len && p->s[e + 1] >= '0' && p->s[e + 1] <= '9') {
            jfail(p, "leading zero in number");
            return NULL;
        }
        while (e < p->len && ((p->s[e] >= '0' && p->s[e] <= '9') || p->s[e] == '.' || p->s[e] == 'e' ||
                              p->s[e] == 'E' || p->s[e] == '+' || p->s[e] == '-'))
            ++e;
        if (e - p->pos >= sizeof buf) {
            jfail(p, "number too long");
            return NULL;
        }
        memcpy(buf, p->s + p->pos, e - p->pos);
        buf[e - p->pos] = '\0';
        char *end;
        errno = 0;
        double v = strtod(buf, &end);
        if (*end != '\0' || !isfinite(v) || errno == ERANGE || buf[e - p->pos - 1] == '.') {
            jfail(p, "bad number");
            return NULL;
        }
        rch_json *j = jnew(p, RCH_JNUM);
        if (j)
            j->num = v;
        p->pos = e;
        return j;
    }
    jfail(p, "unexpected character");
    return NULL;
}

rch_json *rch_json_parse(const char *text, size_t len, const char *name, rch_diag *d)
{
    jp p = {text, len, 0, 1, 0, name, d, 0};
    if (len >= 3 && (unsigned char)text[0] == 0xEF && (unsigned char)text[1] == 0xBB &&
        (unsigned char)text[2] == 0xBF)
        p.pos = p.line_start = 3;
    rch_json *j = jvalue(&p, 0);
    if (j) {
        jws(&p);
        if (p.pos != p.len) {
            jfail(&p, "trailing characters after the JSON value");
            rch_json_free(j);
            return NULL;
        }
    }
    return j;
}

rch_json *rch_json_load(const char *path, rch_diag *d)
{
    char *buf = NULL;
    size_t len = 0;
    if (rch_read_file(&buf, &len, path, RCH_JSON_MAX_BYTES, d) != 0)
        return NULL;
    rch_json *j = rch_json_parse(buf, len, path, d);
    free(buf);
    return j;
}

void rch_json_free(rch_json *j)
{
    if (!j)
        return;
    for (size_t i = 0; i < j->n; ++i) {
        rch_json_free(j->items[i]);
        if (j->keys)
            free(j->keys[i]);
    }
    free(j->items);
    free(j->keys);
    free(j->str);
    free(j);
}

const rch_json *rch_json_get(const rch_json *obj, const char *key)
{
    if (!obj || obj->type != RCH_JOBJ)
        return NULL;
    for (size_t i = 0; i < obj->n; ++i)
        if (strcmp(obj->keys[i], key) == 0)
            return obj->items[i];
    return NULL;
}
