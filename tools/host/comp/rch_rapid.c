/* SPDX-License-Identifier: MIT */
/* rch_rapid.c - the RAPID reader's lower parts (see rch_rapid.h): the
 * tokenizer (comments, strings with "", numbers, names, :=, punctuation,
 * each with its line and column), the token queries every pass uses, the
 * names of kinds and contexts, and the targets' release. The entry,
 * rch_rapid_scan, is rch_rapid_scan.c; what the files share:
 * rch_rapid_int.h.
 * Depends on: rch_diag. Memory: the tokens on the heap (s->tk, freed by
 * rch_rapid_scan). Errors: -1 with the scan's diag set. */
#include "rch_rapid.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_rapid_int.h"

static int push_tok(rch_rpi_scan *s, rch_rpi_tok_type ty, char ch, size_t off, size_t len, unsigned line, unsigned col)
{
    if (s->tk.n == s->tk.cap) {
        const size_t nc = s->tk.cap ? 2 * s->tk.cap : 256;
        rch_rpi_tok *nt = realloc(s->tk.t, nc * sizeof *nt);
        if (!nt) {
            rch_diag_set(s->d, s->name, line, col, "out of memory");
            return -1;
        }
        s->tk.t = nt;
        s->tk.cap = nc;
    }
    s->tk.t[s->tk.n++] = (rch_rpi_tok){ty, ch, off, len, line, col};
    return 0;
}

static int is_id(int c) { return isalnum(c) || c == '_'; }

/* text -> tokens (comments dropped). 0 or -1. */
int rch_rpi_tokenize(rch_rpi_scan *s)
{
    const char *p = s->text;
    size_t i = 0;
    unsigned line = 1, col = 1;
    if (s->len >= 3 && memcmp(p, "\xEF\xBB\xBF", 3) == 0)
        i = 3; /* a UTF-8 byte-order mark: skipped (its bytes stay in the text the caller copies) */
    /* a line ends at LF, CRLF (counted at its LF) or a lone CR */
#define EOL_AT(j) (p[j] == '\n' || (p[j] == '\r' && ((j) + 1 >= s->len || p[(j) + 1] != '\n')))
#define ADV(k)                                                                                                     \
    do {                                                                                                           \
        for (size_t a_ = 0; a_ < (k); ++a_, ++i) {                                                                 \
            if (EOL_AT(i)) {                                                                                       \
                ++line;                                                                                            \
                col = 1;                                                                                           \
            } else                                                                                                 \
                ++col;                                                                                             \
        }                                                                                                          \
    } while (0)
    while (i < s->len) {
        const unsigned char c = (unsigned char)p[i];
        const size_t b = i;
        const unsigned bl = line, bc = col;
        if (c == '\0') {
            rch_diag_set(s->d, s->name, line, col, "NUL byte in a RAPID module");
            return -1;
        }
        if (isspace(c)) {
            ADV(1);
        } else if (c == '!') { /* comment to the end of the line */
            while (i < s->len && p[i] != '\n' && p[i] != '\r') {
                if (p[i] == '\0') {
                    rch_diag_set(s->d, s->name, line, col, "NUL byte in a RAPID module");
                    return -1;
                }
                ADV(1);
            }
        } else if (c == '"') {
            ADV(1);
            for (;;) {
                if (i >= s->len || p[i] == '\n' || p[i] == '\r' || p[i] == '\0') {
                    rch_diag_set(s->d, s->name, bl, bc, "string not closed on its line");
                    return -1;
                }
                if (p[i] == '"') {
                    if (i + 1 < s->len && p[i + 1] == '"') {
                        ADV(2);
                        continue;
                    }
                    ADV(1);
                    break;
                }
                ADV(1);
            }
            if (push_tok(s, RCH_RPI_STR, 0, b, i - b, bl, bc) != 0)
                return -1;
        } else if (isdigit(c) || (c == '.' && i + 1 < s->len && isdigit((unsigned char)p[i + 1]))) {
            while (i < s->len) {
                const unsigned char e = (unsigned char)p[i];
                if (is_id(e) || e == '.')
                    ADV(1);
                else if ((e == '+' || e == '-') && (p[i - 1] == 'e' || p[i - 1] == 'E') && isdigit((unsigned char)p[b]))
                    ADV(1);
                else
                    break;
            }
            if (push_tok(s, RCH_RPI_NUM, 0, b, i - b, bl, bc) != 0)
                return -1;
        } else if (is_id(c)) {
            while (i < s->len && is_id((unsigned char)p[i]))
                ADV(1);
            if (push_tok(s, RCH_RPI_IDENT, 0, b, i - b, bl, bc) != 0)
                return -1;
        } else if (c == ':' && i + 1 < s->len && p[i + 1] == '=') {
            ADV(2);
            if (push_tok(s, RCH_RPI_ASSIGN, 0, b, 2, bl, bc) != 0)
                return -1;
        } else {
            ADV(1);
            if (push_tok(s, RCH_RPI_PUNCT, (char)c, b, 1, bl, bc) != 0)
                return -1;
        }
    }
#undef ADV
#undef EOL_AT
    return 0;
}

int rch_rpi_tok_is(const rch_rpi_scan *s, size_t i, const char *w)
{
    const rch_rpi_tok *t = &s->tk.t[i];
    return t->type == RCH_RPI_IDENT && t->len == strlen(w) && strncasecmp(s->text + t->off, w, t->len) == 0;
}

int rch_rpi_punct(const rch_rpi_scan *s, size_t i, char ch)
{
    return i < s->tk.n && s->tk.t[i].type == RCH_RPI_PUNCT && s->tk.t[i].ch == ch;
}

void rch_rpi_tok_name(char *buf, size_t n, const rch_rpi_scan *s, size_t i)
{
    const rch_rpi_tok *t = &s->tk.t[i];
    const size_t k = t->len < n - 1 ? t->len : n - 1;
    memcpy(buf, s->text + t->off, k);
    buf[k] = '\0';
}

/* Index of the bracket closing the one at i ('[', '(' or '{'), or s->tk.n
 * when it is not closed, a bracket of another kind closes first, or the
 * nesting is deeper than 64. */
size_t rch_rpi_close_of(const rch_rpi_scan *s, size_t i)
{
    char open[64];
    size_t depth = 0;
    for (size_t j = i; j < s->tk.n; ++j) {
        const rch_rpi_tok *t = &s->tk.t[j];
        if (t->type != RCH_RPI_PUNCT)
            continue;
        if (t->ch == '[' || t->ch == '(' || t->ch == '{') {
            if (depth == sizeof open)
                return s->tk.n;
            open[depth++] = t->ch;
        } else if (t->ch == ']' || t->ch == ')' || t->ch == '}') {
            char want = '{';
            if (t->ch == ']')
                want = '[';
            else if (t->ch == ')')
                want = '(';
            if (depth == 0 || open[depth - 1] != want)
                return s->tk.n;
            if (--depth == 0)
                return j;
        }
    }
    return s->tk.n;
}

unsigned rch_rpi_hash_ci(const char *p, size_t n)
{
    unsigned h = 2166136261u;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ (unsigned)tolower((unsigned char)p[i])) * 16777619u;
    return h;
}

void rch_rapid_free(rch_rapid_targets *ts)
{
    free(ts->t);
    memset(ts, 0, sizeof *ts);
}

const char *rch_rapid_kind_name(rch_rapid_kind k)
{
    return k == RCH_RAPID_JOINTTARGET ? "jointtarget" : "robtarget";
}

const char *rch_rapid_context_name(rch_rapid_context c)
{
    return c == RCH_RAPID_DECLARATION ? "declaration" : c == RCH_RAPID_ASSIGNMENT ? "assignment" : "inline";
}
