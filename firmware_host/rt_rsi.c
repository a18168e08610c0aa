/* SPDX-License-Identifier: MIT */
/* rt_rsi.c - the RSI datagrams and RSI's configuration file (rt_rsi.h). */
#include "rt_rsi.h"

#include <expat.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *rt_rsi_strerror(rt_rsi_status st)
{
    switch (st) {
    case RT_RSI_OK:
        return "ok";
    case RT_RSI_ERR_XML:
        return "not well-formed XML";
    case RT_RSI_ERR_ROOT:
        return "not the robot's datagram (root element)";
    case RT_RSI_ERR_IPOC:
        return "no usable IPOC";
    case RT_RSI_ERR_TOO_LONG:
        return "datagram too long";
    case RT_RSI_ERR_SETPOINT:
        return "setpoint axes unusable";
    case RT_RSI_ERR_CONFIG:
        return "RSI configuration file refused";
    case RT_RSI_ERR_NOMEM:
        return "out of memory";
    }
    return "unknown status";
}

static void set_name(char dst[RT_RSI_NAME], const char *src)
{
    snprintf(dst, RT_RSI_NAME, "%s", src);
}

void rt_rsi_names_default(rt_rsi_names *n)
{
    memset(n, 0, sizeof *n);
    set_name(n->root_in, "Rob");
    set_name(n->root_out, "Sen");
    set_name(n->sentype, "ImFree");
    set_name(n->set_tag, "ASPos");
    set_name(n->act_tag, "AIPos");
    set_name(n->corr_tag, "AK");
    set_name(n->ipoc_tag, "IPOC");
    for (int i = 0; i < RT_RSI_NAX; ++i) {
        char a[8];
        snprintf(a, sizeof a, "A%d", i + 1);
        set_name(n->ax_attr[i], a);
        set_name(n->corr_attr[i], a);
    }
}

/* A name written into the answer unescaped: letters, digits, _ - . only,
 * not starting with a digit, '-' or '.', shorter than RT_RSI_NAME. */
static int xml_name_ok(const char *s, size_t len)
{
    if (len == 0 || len >= RT_RSI_NAME)
        return 0;
    for (size_t i = 0; i < len; ++i) {
        const char c = s[i];
        const int alpha = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_';
        const int other = (c >= '0' && c <= '9') || c == '-' || c == '.';
        if (!alpha && !(i > 0 && other))
            return 0;
    }
    return 1;
}

/* A decimal number, the whole string, finite: digits, sign, point, exponent
 * only (no hex, no inf/nan, no blanks). */
static int parse_num(const char *s, double *out)
{
    if (!*s)
        return -1;
    for (const char *p = s; *p; ++p)
        if (!((*p >= '0' && *p <= '9') || *p == '+' || *p == '-' || *p == '.' || *p == 'e' || *p == 'E'))
            return -1;
    char *end = NULL;
    const double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* ---- the datagram decoder ---- */

struct rt_rsi_dec {
    XML_Parser p;
    rt_rsi_names n;
    rt_rsi_rob *out;
    rt_rsi_status st; /* the first error: the parse is stopped */
    char why[160];
    int depth, in_ipoc, n_ipoc, n_set, n_act;
    char ipoc[32];
    size_t ipoc_len;
    int ipoc_overlong;
};

static void dec_fail(rt_rsi_dec *d, rt_rsi_status st, const char *fmt, ...)
{
    if (d->st != RT_RSI_OK)
        return;
    d->st = st;
    int k = snprintf(d->why, sizeof d->why, "%lu:%lu: ", (unsigned long)XML_GetCurrentLineNumber(d->p),
                     (unsigned long)XML_GetCurrentColumnNumber(d->p) + 1);
    if (k < 0 || (size_t)k >= sizeof d->why)
        k = 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->why + k, sizeof d->why - (size_t)k, fmt, ap);
    va_end(ap);
    XML_StopParser(d->p, XML_FALSE);
}

/* The six axes of an ASPos/AIPos element into v: 0, or -1 with why. */
static int axes(double v[RT_RSI_NAX], char *why, size_t why_len, const rt_rsi_names *n, const char **attr,
                const char *tag)
{
    int seen[RT_RSI_NAX] = {0};
    for (size_t k = 0; attr[k]; k += 2)
        for (int i = 0; i < RT_RSI_NAX; ++i)
            if (strcmp(attr[k], n->ax_attr[i]) == 0) {
                if (parse_num(attr[k + 1], &v[i]) != 0) {
                    snprintf(why, why_len, "%s %s=\"%.32s\" is not a finite decimal number", tag, attr[k],
                             attr[k + 1]);
                    return -1;
                }
                seen[i] = 1;
            }
    for (int i = 0; i < RT_RSI_NAX; ++i)
        if (!seen[i]) {
            snprintf(why, why_len, "%s has no %s", tag, n->ax_attr[i]);
            return -1;
        }
    return 0;
}

static void XMLCALL dec_start(void *ud, const XML_Char *name, const XML_Char **attr)
{
    rt_rsi_dec *d = ud;
    ++d->depth;
    if (d->depth == 1) {
        if (strcmp(name, d->n.root_in) != 0)
            dec_fail(d, RT_RSI_ERR_ROOT, "root element <%.40s>, not <%s>", name, d->n.root_in);
        return;
    }
    if (d->depth != 2)
        return;
    if (strcmp(name, d->n.ipoc_tag) == 0) {
        d->in_ipoc = 1;
        d->ipoc_len = 0;
        if (++d->n_ipoc > 1)
            dec_fail(d, RT_RSI_ERR_IPOC, "a second <%s>", d->n.ipoc_tag);
    } else if (strcmp(name, d->n.set_tag) == 0) {
        if (++d->n_set > 1) {
            d->out->set_ok = 0;
            snprintf(d->out->set_why, sizeof d->out->set_why, "%lu:%lu: a second <%s>",
                     (unsigned long)XML_GetCurrentLineNumber(d->p),
                     (unsigned long)XML_GetCurrentColumnNumber(d->p) + 1, d->n.set_tag);
            return;
        }
        char why[120];
        if (axes(d->out->set_deg, why, sizeof why, &d->n, attr, d->n.set_tag) == 0)
            d->out->set_ok = 1;
        else
            snprintf(d->out->set_why, sizeof d->out->set_why, "%lu:%lu: %s",
                     (unsigned long)XML_GetCurrentLineNumber(d->p),
                     (unsigned long)XML_GetCurrentColumnNumber(d->p) + 1, why);
    } else if (strcmp(name, d->n.act_tag) == 0) {
        char why[120];
        d->out->has_act = ++d->n_act == 1 && axes(d->out->act_deg, why, sizeof why, &d->n, attr, d->n.act_tag) == 0;
    } else if (strcmp(name, "Delay") == 0) {
        for (size_t k = 0; attr[k]; k += 2) {
            double v;
            if (strcmp(attr[k], "D") == 0 && parse_num(attr[k + 1], &v) == 0 && v >= 0 && v < 1e9)
                d->out->delay = (long)v;
        }
    }
}

static void XMLCALL dec_end(void *ud, const XML_Char *name)
{
    rt_rsi_dec *d = ud;
    (void)name;
    if (d->depth == 2 && d->in_ipoc) {
        d->in_ipoc = 0;
        /* digits, blanks around them allowed */
        size_t a = 0, b = d->ipoc_len;
        while (a < b && (d->ipoc[a] == ' ' || d->ipoc[a] == '\t' || d->ipoc[a] == '\n' || d->ipoc[a] == '\r'))
            ++a;
        while (b > a && (d->ipoc[b - 1] == ' ' || d->ipoc[b - 1] == '\t' || d->ipoc[b - 1] == '\n' ||
                         d->ipoc[b - 1] == '\r'))
            --b;
        unsigned long long v = 0;
        int ok = !d->ipoc_overlong && b > a && b - a <= 18;
        for (size_t i = a; ok && i < b; ++i) {
            if (d->ipoc[i] < '0' || d->ipoc[i] > '9')
                ok = 0;
            else
                v = v * 10u + (unsigned)(d->ipoc[i] - '0');
        }
        if (!ok)
            dec_fail(d, RT_RSI_ERR_IPOC, "<%s> is not a decimal counter of at most 18 digits", d->n.ipoc_tag);
        d->out->ipoc = v;
    }
    --d->depth;
}

static void XMLCALL dec_text(void *ud, const XML_Char *s, int len)
{
    rt_rsi_dec *d = ud;
    if (!d->in_ipoc || d->depth != 2 || len <= 0)
        return;
    if (d->ipoc_len + (size_t)len >= sizeof d->ipoc) {
        d->ipoc_overlong = 1;
        return;
    }
    memcpy(d->ipoc + d->ipoc_len, s, (size_t)len);
    d->ipoc_len += (size_t)len;
}

static void XMLCALL dec_doctype(void *ud, const XML_Char *name, const XML_Char *sys, const XML_Char *pub, int has)
{
    (void)name;
    (void)sys;
    (void)pub;
    (void)has;
    dec_fail(ud, RT_RSI_ERR_XML, "a DOCTYPE (refused: no entities in a datagram)");
}

static void dec_handlers(rt_rsi_dec *d)
{
    XML_SetUserData(d->p, d);
    XML_SetElementHandler(d->p, dec_start, dec_end);
    XML_SetCharacterDataHandler(d->p, dec_text);
    XML_SetStartDoctypeDeclHandler(d->p, dec_doctype);
}

rt_rsi_dec *rt_rsi_dec_new(const rt_rsi_names *n)
{
    rt_rsi_dec *d = calloc(1, sizeof *d);
    if (!d)
        return NULL;
    d->n = *n;
    d->p = XML_ParserCreate("UTF-8");
    if (!d->p) {
        free(d);
        return NULL;
    }
    return d;
}

void rt_rsi_dec_free(rt_rsi_dec *d)
{
    if (d) {
        XML_ParserFree(d->p);
        free(d);
    }
}

rt_rsi_status rt_rsi_decode(rt_rsi_rob *out, char *why, size_t why_len, rt_rsi_dec *d, const char *buf, size_t len)
{
    memset(out, 0, sizeof *out);
    out->delay = -1;
    if (why_len)
        why[0] = '\0';
    if (len > RT_RSI_MAX_DGRAM) {
        snprintf(why, why_len, "%zu bytes, over %d", len, RT_RSI_MAX_DGRAM);
        return RT_RSI_ERR_TOO_LONG;
    }
    if (XML_ParserReset(d->p, "UTF-8") != XML_TRUE)
        return RT_RSI_ERR_NOMEM;
    dec_handlers(d);
    d->out = out;
    d->st = RT_RSI_OK;
    d->why[0] = '\0';
    d->depth = d->in_ipoc = d->n_ipoc = d->n_set = d->n_act = d->ipoc_overlong = 0;
    d->ipoc_len = 0;
    snprintf(out->set_why, sizeof out->set_why, "no <%s>", d->n.set_tag);
    const enum XML_Status xs = XML_Parse(d->p, buf, (int)len, XML_TRUE);
    if (d->st == RT_RSI_OK && xs != XML_STATUS_OK) {
        snprintf(d->why, sizeof d->why, "%lu:%lu: %s", (unsigned long)XML_GetCurrentLineNumber(d->p),
                 (unsigned long)XML_GetCurrentColumnNumber(d->p) + 1, XML_ErrorString(XML_GetErrorCode(d->p)));
        d->st = RT_RSI_ERR_XML;
    }
    if (d->st == RT_RSI_OK && d->n_ipoc == 0) {
        snprintf(d->why, sizeof d->why, "no <%s>", d->n.ipoc_tag);
        d->st = RT_RSI_ERR_IPOC;
    }
    if (d->st != RT_RSI_OK) {
        snprintf(why, why_len, "%s", d->why);
        out->set_ok = 0;
    } else if (out->set_ok)
        out->set_why[0] = '\0';
    return d->st;
}

size_t rt_rsi_encode(char *out, size_t cap, const rt_rsi_names *n, const double ak_deg[RT_RSI_NAX],
                     unsigned long long ipoc)
{
    size_t k = 0;
    int w = snprintf(out, cap, "<%s Type=\"%s\"><%s", n->root_out, n->sentype, n->corr_tag);
    if (w < 0 || (size_t)w >= cap)
        return 0;
    k = (size_t)w;
    for (int i = 0; i < RT_RSI_NAX; ++i) {
        if (!isfinite(ak_deg[i]) || fabs(ak_deg[i]) > 1e6)
            return 0;
        w = snprintf(out + k, cap - k, " %s=\"%.10f\"", n->corr_attr[i], ak_deg[i]);
        if (w < 0 || (size_t)w >= cap - k)
            return 0;
        k += (size_t)w;
    }
    w = snprintf(out + k, cap - k, "/><%s>%llu</%s></%s>", n->ipoc_tag, ipoc, n->ipoc_tag, n->root_out);
    if (w < 0 || (size_t)w >= cap - k)
        return 0;
    return k + (size_t)w;
}

/* ---- RSI's configuration file ---- */

#define CFG_MAX_RECV 64
typedef struct cfg_ctx {
    XML_Parser p;
    rt_rsi_names *n;
    rt_rsi_net *net;
    const char *path;
    char *msg;
    size_t msg_len;
    int failed;
    char stack[4][16]; /* ROOT CONFIG PORT ... (truncated names: only the known ones matter) */
    int depth;
    char text[128];
    size_t text_len;
    int has_aspos, has_aipos, onlysend;
    /* RECEIVE elements: tag, attribute, index, double */
    struct {
        char tag[RT_RSI_NAME], attr[RT_RSI_NAME];
        long indx;
        unsigned long line;
    } recv[CFG_MAX_RECV];
    int n_recv;
} cfg_ctx;

static void cfg_fail(cfg_ctx *c, const char *fmt, ...)
{
    if (c->failed)
        return;
    c->failed = 1;
    int k = snprintf(c->msg, c->msg_len, "%s:%lu:%lu: ", c->path, (unsigned long)XML_GetCurrentLineNumber(c->p),
                     (unsigned long)XML_GetCurrentColumnNumber(c->p) + 1);
    if (k < 0 || (size_t)k >= c->msg_len)
        k = 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->msg + k, c->msg_len - (size_t)k, fmt, ap);
    va_end(ap);
    XML_StopParser(c->p, XML_FALSE);
}

static const char *cfg_attr(const char **attr, const char *name)
{
    for (size_t k = 0; attr[k]; k += 2)
        if (strcmp(attr[k], name) == 0)
            return attr[k + 1];
    return NULL;
}

static int at(const cfg_ctx *c, const char *a, const char *b, const char *e)
{
    return c->depth == 4 && strcmp(c->stack[0], "ROOT") == 0 && strcmp(c->stack[1], a) == 0 &&
           strcmp(c->stack[2], b) == 0 && strcmp(c->stack[3], e) == 0;
}

static void cfg_element(cfg_ctx *c, const char **attr)
{
    const char *tag = cfg_attr(attr, "TAG"), *type = cfg_attr(attr, "TYPE"), *indx = cfg_attr(attr, "INDX");
    if (!tag) {
        cfg_fail(c, "<ELEMENT> without TAG");
        return;
    }
    if (at(c, "SEND", "ELEMENTS", "ELEMENT")) {
        c->has_aspos |= strcmp(tag, "DEF_ASPos") == 0;
        c->has_aipos |= strcmp(tag, "DEF_AIPos") == 0;
        return;
    }
    if (!at(c, "RECEIVE", "ELEMENTS", "ELEMENT") || !type || strcmp(type, "DOUBLE") != 0)
        return;
    const char *dot = strchr(tag, '.');
    if (!dot)
        return;
    if (!xml_name_ok(tag, (size_t)(dot - tag)) || !xml_name_ok(dot + 1, strlen(dot + 1))) {
        cfg_fail(c, "RECEIVE element TAG=\"%.60s\": not TAG.ATTRIBUTE of XML names (letters, digits, _ - .)", tag);
        return;
    }
    if (c->n_recv >= CFG_MAX_RECV) {
        cfg_fail(c, "more than %d RECEIVE elements of TYPE DOUBLE", CFG_MAX_RECV);
        return;
    }
    double v = 0;
    long ix = c->n_recv + 1000; /* no numeric INDX: the order of the file */
    if (indx && parse_num(indx, &v) == 0 && v >= 0 && v < 1000 && v == floor(v))
        ix = (long)v;
    snprintf(c->recv[c->n_recv].tag, RT_RSI_NAME, "%.*s", (int)(dot - tag), tag);
    snprintf(c->recv[c->n_recv].attr, RT_RSI_NAME, "%s", dot + 1);
    c->recv[c->n_recv].indx = ix;
    c->recv[c->n_recv].line = (unsigned long)XML_GetCurrentLineNumber(c->p);
    c->n_recv++;
}

static void XMLCALL cfg_start(void *ud, const XML_Char *name, const XML_Char **attr)
{
    cfg_ctx *c = ud;
    if (c->depth < 4)
        snprintf(c->stack[c->depth], sizeof c->stack[0], "%s", name);
    ++c->depth;
    c->text_len = 0;
    if (c->depth == 1 && strcmp(name, "ROOT") != 0)
        cfg_fail(c, "root element <%.40s>, not <ROOT> (an RSI Ethernet configuration file)", name);
    else if (c->depth == 4 && strcmp(name, "ELEMENT") == 0)
        cfg_element(c, attr);
}

static void cfg_text_done(cfg_ctx *c)
{
    if (c->depth != 3 || strcmp(c->stack[0], "ROOT") != 0 || strcmp(c->stack[1], "CONFIG") != 0)
        return;
    char t[128];
    size_t a = 0, b = c->text_len;
    while (a < b && (c->text[a] == ' ' || c->text[a] == '\t' || c->text[a] == '\n' || c->text[a] == '\r'))
        ++a;
    while (b > a && (c->text[b - 1] == ' ' || c->text[b - 1] == '\t' || c->text[b - 1] == '\n' ||
                     c->text[b - 1] == '\r'))
        --b;
    snprintf(t, sizeof t, "%.*s", (int)(b - a), c->text + a);
    const char *e = c->stack[2];
    if (strcmp(e, "SENTYPE") == 0) {
        if (!xml_name_ok(t, strlen(t)))
            cfg_fail(c, "SENTYPE '%.60s' is not a name of letters, digits, _ - .", t);
        else
            set_name(c->n->sentype, t);
    } else if (strcmp(e, "ONLYSEND") == 0) {
        c->onlysend = strcmp(t, "TRUE") == 0;
        if (c->onlysend)
            cfg_fail(c, "ONLYSEND is TRUE: the robot would read no answer, and corrections need one (set FALSE)");
    } else if (strcmp(e, "PORT") == 0) {
        double v;
        if (parse_num(t, &v) != 0 || v < 1 || v > 65535 || v != floor(v))
            cfg_fail(c, "PORT '%.20s' is not a port number 1..65535", t);
        else
            c->net->port = (long)v;
    } else if (strcmp(e, "IP_NUMBER") == 0)
        snprintf(c->net->ip, sizeof c->net->ip, "%.63s", t);
}

static void XMLCALL cfg_end(void *ud, const XML_Char *name)
{
    cfg_ctx *c = ud;
    (void)name;
    cfg_text_done(c);
    c->text_len = 0;
    --c->depth;
}

static void XMLCALL cfg_chars(void *ud, const XML_Char *s, int len)
{
    cfg_ctx *c = ud;
    if (len > 0 && c->text_len + (size_t)len < sizeof c->text) {
        memcpy(c->text + c->text_len, s, (size_t)len);
        c->text_len += (size_t)len;
    }
}

static void XMLCALL cfg_doctype(void *ud, const XML_Char *name, const XML_Char *sys, const XML_Char *pub, int has)
{
    (void)name;
    (void)sys;
    (void)pub;
    (void)has;
    cfg_fail(ud, "a DOCTYPE (refused)");
}

/* The correction group: the RECEIVE tag with exactly six DOUBLE elements (AK
 * when several have six). 0, or -1 with msg. */
static int cfg_corr(cfg_ctx *c)
{
    int chosen = -1, groups = 0;
    for (int i = 0; i < c->n_recv; ++i) {
        int first = 1, count = 0;
        for (int j = 0; j < c->n_recv; ++j) {
            if (strcmp(c->recv[i].tag, c->recv[j].tag) != 0)
                continue;
            first &= j >= i;
            ++count;
        }
        if (!first || count != RT_RSI_NAX)
            continue;
        ++groups;
        if (chosen < 0 || strcmp(c->recv[i].tag, "AK") == 0)
            chosen = i;
    }
    if (chosen < 0) {
        snprintf(c->msg, c->msg_len,
                 "%s: RECEIVE has no group of six DOUBLE elements TAG.A1 .. TAG.A6 (the axis corrections, e.g. "
                 "AK.A1 .. AK.A6 linked to the AXISCORR object)", c->path);
        return -1;
    }
    if (groups > 1 && strcmp(c->recv[chosen].tag, "AK") != 0) {
        snprintf(c->msg, c->msg_len,
                 "%s:%lu: RECEIVE has several groups of six DOUBLE elements and none is AK: which one carries the "
                 "axis corrections is ambiguous", c->path, c->recv[chosen].line);
        return -1;
    }
    set_name(c->n->corr_tag, c->recv[chosen].tag);
    /* the attributes in the order of their INDX */
    int used[CFG_MAX_RECV] = {0};
    for (int a = 0; a < RT_RSI_NAX; ++a) {
        int best = -1;
        for (int j = 0; j < c->n_recv; ++j)
            if (!used[j] && strcmp(c->recv[j].tag, c->n->corr_tag) == 0 &&
                (best < 0 || c->recv[j].indx < c->recv[best].indx))
                best = j;
        if (best < 0) { /* the group has six elements (chosen above): cannot happen, but never index by it */
            snprintf(c->msg, c->msg_len, "%s:%lu: RECEIVE %s has fewer than six elements", c->path,
                     c->recv[chosen].line, c->n->corr_tag);
            return -1;
        }
        used[best] = 1;
        set_name(c->n->corr_attr[a], c->recv[best].attr);
        for (int b = 0; b < a; ++b)
            if (strcmp(c->n->corr_attr[b], c->n->corr_attr[a]) == 0) {
                snprintf(c->msg, c->msg_len, "%s:%lu: RECEIVE names %s.%s twice", c->path, c->recv[best].line,
                         c->n->corr_tag, c->n->corr_attr[a]);
                return -1;
            }
    }
    return 0;
}

rt_rsi_status rt_rsi_config_read(rt_rsi_names *n, rt_rsi_net *net, char *msg, size_t msg_len, const char *text,
                                 size_t len, const char *path)
{
    static cfg_ctx c; /* 8 kB: not on the stack */
    memset(&c, 0, sizeof c);
    rt_rsi_names_default(n);
    net->ip[0] = '\0';
    net->port = -1;
    c.n = n;
    c.net = net;
    c.path = path;
    c.msg = msg;
    c.msg_len = msg_len;
    if (len > (size_t)1 << 20) {
        snprintf(msg, msg_len, "%s: %zu bytes: not an RSI configuration file (over 1 MB)", path, len);
        return RT_RSI_ERR_CONFIG;
    }
    c.p = XML_ParserCreate(NULL);
    if (!c.p)
        return RT_RSI_ERR_NOMEM;
    XML_SetUserData(c.p, &c);
    XML_SetElementHandler(c.p, cfg_start, cfg_end);
    XML_SetCharacterDataHandler(c.p, cfg_chars);
    XML_SetStartDoctypeDeclHandler(c.p, cfg_doctype);
    const enum XML_Status xs = XML_Parse(c.p, text, (int)len, XML_TRUE);
    if (!c.failed && xs != XML_STATUS_OK) {
        snprintf(msg, msg_len, "%s:%lu:%lu: %s", path, (unsigned long)XML_GetCurrentLineNumber(c.p),
                 (unsigned long)XML_GetCurrentColumnNumber(c.p) + 1, XML_ErrorString(XML_GetErrorCode(c.p)));
        c.failed = 1;
    }
    XML_ParserFree(c.p);
    if (c.failed)
        return RT_RSI_ERR_CONFIG;
    if (!c.has_aspos) {
        snprintf(msg, msg_len,
                 "%s: SEND has no DEF_ASPos: rcal-rt compensates the program's setpoint axes and needs them "
                 "(<ELEMENT TAG=\"DEF_ASPos\" TYPE=\"DOUBLE\" INDX=\"INTERNAL\" />)", path);
        return RT_RSI_ERR_CONFIG;
    }
    if (cfg_corr(&c) != 0)
        return RT_RSI_ERR_CONFIG;
    return RT_RSI_OK;
}

/* ---- latency histogram ---- */

int rt_rsi_hist_init(rt_rsi_hist *h)
{
    memset(h, 0, sizeof *h);
    h->bin = calloc(RT_RSI_HIST_BINS, sizeof *h->bin);
    return h->bin ? 0 : -1;
}

void rt_rsi_hist_free(rt_rsi_hist *h)
{
    free(h->bin);
    h->bin = NULL;
}

void rt_rsi_hist_add(rt_rsi_hist *h, double us)
{
    if (!(us >= 0))
        us = 0;
    h->n++;
    h->sum_us += us;
    if (us > h->max_us)
        h->max_us = us;
    const double b = us * 10.0;
    if (b >= RT_RSI_HIST_BINS)
        h->over++;
    else
        h->bin[(size_t)b]++;
}

double rt_rsi_hist_pct(const rt_rsi_hist *h, double p)
{
    if (h->n == 0)
        return 0.0;
    unsigned long k = (unsigned long)ceil(p / 100.0 * (double)h->n), acc = 0;
    if (k < 1)
        k = 1;
    for (size_t i = 0; i < RT_RSI_HIST_BINS; ++i) {
        acc += h->bin[i];
        if (acc >= k)
            return (double)(i + 1) / 10.0;
    }
    return h->max_us;
}
