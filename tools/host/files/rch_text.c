/* SPDX-License-Identifier: MIT */
/* rch_text.c - UTF-8 check, XML escaping and shell quoting (see rch_text.h). */
#include "rch_text.h"

#include <stdio.h>
#include <string.h>

size_t rch_utf8_len(const unsigned char *s)
{
    const unsigned c = s[0];
    size_t n;
    unsigned long cp;
    if (c < 0x80)
        return 1;
    if (c >= 0xC2 && c <= 0xDF)
        n = 2, cp = c & 0x1Fu;
    else if (c >= 0xE0 && c <= 0xEF)
        n = 3, cp = c & 0x0Fu;
    else if (c >= 0xF0 && c <= 0xF4)
        n = 4, cp = c & 0x07u;
    else
        return 0;
    for (size_t i = 1; i < n; ++i) {
        if ((s[i] & 0xC0u) != 0x80u)
            return 0;
        cp = cp << 6 | (s[i] & 0x3Fu);
    }
    if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) || (cp >= 0xD800 && cp <= 0xDFFF))
        return 0;
    return n;
}

const char *rch_xml_piece(char out[8], const char *s, size_t *used, unsigned flags)
{
    const unsigned char *p = (const unsigned char *)s;
    const unsigned c = p[0];
    *used = 1;
    switch (c) {
    case '&': return "&amp;";
    case '<': return "&lt;";
    case '>': return "&gt;";
    case '"': return "&quot;";
    case '\'': return "&#39;";
    case '\t': return flags & RCH_XML_WS_REFS ? "&#9;" : "\t";
    case '\n': return flags & RCH_XML_WS_REFS ? "&#10;" : "\n";
    case '\r': return flags & RCH_XML_WS_REFS ? "&#13;" : "\r";
    default: break;
    }
    if (c < 0x20 || c == 0x7F)
        return "&#xFFFD;";
    const size_t n = rch_utf8_len(p);
    if (n == 0)
        return "&#xFFFD;"; /* one per byte that is no character */
    if (n == 3 && p[0] == 0xEF && p[1] == 0xBF && (p[2] == 0xBE || p[2] == 0xBF)) { /* U+FFFE, U+FFFF */
        *used = n;
        return "&#xFFFD;";
    }
    memcpy(out, s, n);
    out[n] = '\0';
    *used = n;
    return out;
}

void rch_xml_put(FILE *f, const char *s, unsigned flags)
{
    while (s && *s) {
        char tmp[8];
        size_t used;
        fputs(rch_xml_piece(tmp, s, &used, flags), f);
        s += used;
    }
}

const char *rch_xml_escape(char *buf, size_t len, const char *s, unsigned flags)
{
    size_t k = 0;
    if (len == 0)
        return buf;
    buf[0] = '\0';
    while (s && *s) {
        char tmp[8];
        size_t used;
        const char *p = rch_xml_piece(tmp, s, &used, flags);
        const size_t n = strlen(p);
        if (k + n >= len)
            break;
        memcpy(buf + k, p, n + 1);
        k += n;
        s += used;
    }
    return buf;
}

/* Appends s; returns 1 when it did not fit. */
static int cl_put(char *buf, size_t len, size_t *k, const char *s)
{
    while (*s && *k + 1 < len)
        buf[(*k)++] = *s++;
    buf[*k] = '\0';
    return *s != '\0';
}

const char *rch_shell_join(char *buf, size_t len, int argc, const char *const *argv)
{
    size_t k = 0;
    if (len == 0)
        return buf;
    buf[0] = '\0';
    int cut = 0;
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        const int quote = !*a || strpbrk(a, " \t\n'\"\\$`&|;<>()*?[]{}~!#") != NULL;
        cut |= cl_put(buf, len, &k, i ? " " : "");
        cut |= cl_put(buf, len, &k, quote ? "'" : "");
        for (; *a; ++a) {
            const char c[2] = {*a, '\0'};
            cut |= cl_put(buf, len, &k, quote && *a == '\'' ? "'\\''" : c);
        }
        cut |= cl_put(buf, len, &k, quote ? "'" : "");
    }
    if (cut && len > 16) /* never cut silently: the end says so */
        snprintf(buf + len - 16, 16, " ... (cut)");
    return buf;
}
