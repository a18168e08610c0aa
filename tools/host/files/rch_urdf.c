/* SPDX-License-Identifier: MIT */
/* rch_urdf.c - the URDF reader (see rch_urdf.h). */
#include "rch_urdf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ names */

static void set_name(char dst[RCH_URDF_NAME_MAX], const char *src)
{
    snprintf(dst, RCH_URDF_NAME_MAX, "%s", src);
}

void rch_urdf_names_default(rch_urdf_names *n, const char *robot)
{
    memset(n, 0, sizeof *n);
    set_name(n->robot, robot && *robot ? robot : "robot");
    set_name(n->base_link, "link_0");
    for (unsigned i = 0; i < RC_NJ; ++i) {
        snprintf(n->joint[i], RCH_URDF_NAME_MAX, "joint_%u", i + 1);
        snprintf(n->link[i], RCH_URDF_NAME_MAX, "link_%u", i + 1);
    }
    set_name(n->flange_joint, "flange_joint");
    set_name(n->flange_link, "flange");
}

/* A small reader of the XML that a URDF is: enough to find the robot name and
 * the joints that are children of <robot>. */
#define UX_MAX_DEPTH 64
#define UX_MAX_JOINTS 512

typedef struct {
    char name[RCH_URDF_NAME_MAX], type[32], parent[RCH_URDF_NAME_MAX], child[RCH_URDF_NAME_MAX];
    unsigned line, col;
} ux_joint;

typedef struct {
    const char *s;
    size_t n, i;
    unsigned line, col;
    const char *file;
    rch_diag *d;
    char stack[UX_MAX_DEPTH][64]; /* element names (truncated) */
    int depth;
    int seen_root;
    char robot[RCH_URDF_NAME_MAX];
    ux_joint *joints; /* (UX_MAX_JOINTS) */
    size_t n_joints;
    int in_joint; /* index of the <joint> being read (child of <robot>), or -1 */
} ux;

static void ux_adv(ux *x, size_t k)
{
    while (k-- > 0 && x->i < x->n) {
        if (x->s[x->i] == '\n') {
            ++x->line;
            x->col = 1;
        } else {
            ++x->col;
        }
        ++x->i;
    }
}

static int ux_at(const ux *x, const char *lit)
{
    size_t k = strlen(lit);
    return x->n - x->i >= k && memcmp(x->s + x->i, lit, k) == 0;
}

static int ux_fail(ux *x, const char *msg, const char *arg)
{
    rch_diag_set(x->d, x->file, x->line, x->col, "%s%s%s", msg, arg ? " " : "", arg ? arg : "");
    return -1;
}

/* Skip past the literal end (e.g. "-->"). */
static int ux_skip_to(ux *x, const char *end, const char *what)
{
    while (x->i < x->n && !ux_at(x, end))
        ux_adv(x, 1);
    if (x->i >= x->n)
        return ux_fail(x, "unterminated", what);
    ux_adv(x, strlen(end));
    return 0;
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

static void ux_ws(ux *x)
{
    while (x->i < x->n && is_space(x->s[x->i]))
        ux_adv(x, 1);
}

/* A name (element or attribute) into buf (cap bytes, truncated). */
static int ux_name(ux *x, char *buf, size_t cap)
{
    size_t k = 0;
    while (x->i < x->n) {
        const char c = x->s[x->i];
        if (is_space(c) || c == '/' || c == '>' || c == '=' || c == '<' || c == '"' || c == '\'')
            break;
        if (k + 1 < cap)
            buf[k++] = c;
        ux_adv(x, 1);
    }
    buf[k] = '\0';
    return k > 0 ? 0 : ux_fail(x, "expected a name", NULL);
}

static void put_utf8(char *buf, size_t cap, size_t *k, unsigned long cp)
{
    unsigned char b[4];
    size_t n;
    if (cp < 0x80) {
        b[0] = (unsigned char)cp;
        n = 1;
    } else if (cp < 0x800) {
        b[0] = (unsigned char)(0xC0 | (cp >> 6));
        b[1] = (unsigned char)(0x80 | (cp & 0x3F));
        n = 2;
    } else if (cp < 0x10000) {
        b[0] = (unsigned char)(0xE0 | (cp >> 12));
        b[1] = (unsigned char)(0x80 | ((cp >> 6) & 0x3F));
        b[2] = (unsigned char)(0x80 | (cp & 0x3F));
        n = 3;
    } else {
        b[0] = (unsigned char)(0xF0 | (cp >> 18));
        b[1] = (unsigned char)(0x80 | ((cp >> 12) & 0x3F));
        b[2] = (unsigned char)(0x80 | ((cp >> 6) & 0x3F));
        b[3] = (unsigned char)(0x80 | (cp & 0x3F));
        n = 4;
    }
    for (size_t j = 0; j < n; ++j) {
        if (*k + 1 < cap)
            buf[*k] = (char)b[j];
        ++*k;
    }
}

/* A quoted attribute value, references decoded, into buf; *len gets the full
 * decoded length (which may exceed cap - 1: then buf is truncated). */
static int ux_value(ux *x, char *buf, size_t cap, size_t *len)
{
    if (x->i >= x->n || (x->s[x->i] != '"' && x->s[x->i] != '\''))
        return ux_fail(x, "expected a quoted attribute value", NULL);
    const char q = x->s[x->i];
    size_t k = 0;
    ux_adv(x, 1);
    while (x->i < x->n && x->s[x->i] != q) {
        const char c = x->s[x->i];
        if (c == '<')
            return ux_fail(x, "'<' inside an attribute value", NULL);
        if (c != '&') {
            if (k + 1 < cap)
                buf[k] = c;
            ++k;
            ux_adv(x, 1);
            continue;
        }
        static const char *const ent[5] = {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;"};
        static const char chr[5] = {'&', '<', '>', '"', '\''};
        int done = 0;
        for (int e = 0; e < 5 && !done; ++e)
            if (ux_at(x, ent[e])) {
                if (k + 1 < cap)
                    buf[k] = chr[e];
                ++k;
                ux_adv(x, strlen(ent[e]));
                done = 1;
            }
        if (done)
            continue;
        if (!ux_at(x, "&#"))
            return ux_fail(x, "unknown entity reference in an attribute value", NULL);
        ux_adv(x, 2);
        const int hex = x->i < x->n && x->s[x->i] == 'x';
        if (hex)
            ux_adv(x, 1);
        unsigned long cp = 0;
        size_t digits = 0;
        while (x->i < x->n && x->s[x->i] != ';') {
            const char c2 = x->s[x->i];
            int v = c2 >= '0' && c2 <= '9' ? c2 - '0'
                    : hex && c2 >= 'a' && c2 <= 'f' ? c2 - 'a' + 10
                    : hex && c2 >= 'A' && c2 <= 'F' ? c2 - 'A' + 10
                                                    : -1;
            if (v < 0 || ++digits > 8)
                return ux_fail(x, "bad character reference", NULL);
            cp = cp * (hex ? 16u : 10u) + (unsigned long)v;
            ux_adv(x, 1);
        }
        if (x->i >= x->n || digits == 0 || cp == 0 || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
            return ux_fail(x, "bad character reference", NULL);
        ux_adv(x, 1);
        put_utf8(buf, cap, &k, cp);
    }
    if (x->i >= x->n)
        return ux_fail(x, "unterminated attribute value", NULL);
    ux_adv(x, 1);
    buf[k < cap ? k : cap - 1] = '\0';
    *len = k;
    return 0;
}

/* Copy an attribute value that must fit a name buffer. */
static int ux_keep(ux *x, char *dst, size_t cap, const char *val, size_t len, const char *attr)
{
    if (len + 1 > cap)
        return ux_fail(x, "attribute value too long:", attr);
    memcpy(dst, val, len + 1);
    return 0;
}

/* A start tag after '<': element name, attributes; handles what the URDF
 * needs. Sets *empty for "/>". */
static int ux_start_tag(ux *x, int *empty)
{
    char el[64], attr[64], val[RCH_URDF_NAME_MAX];
    const unsigned line = x->line, col = x->col;
    if (ux_name(x, el, sizeof el) != 0)
        return -1;
    const int is_root = x->depth == 0, is_joint = x->depth == 1 && strcmp(el, "joint") == 0;
    const int in_joint = x->depth == 2 && x->in_joint >= 0 && (strcmp(el, "parent") == 0 || strcmp(el, "child") == 0);
    if (is_root) {
        if (x->seen_root)
            return ux_fail(x, "a second root element", el);
        if (strcmp(el, "robot") != 0)
            return ux_fail(x, "not a URDF: the root element is not <robot> but", el);
        x->seen_root = 1;
    }
    ux_joint *j = NULL;
    if (is_joint) {
        if (x->n_joints >= UX_MAX_JOINTS)
            return ux_fail(x, "too many joints", NULL);
        j = &x->joints[x->n_joints];
        memset(j, 0, sizeof *j);
        j->line = line;
        j->col = col;
        x->in_joint = (int)x->n_joints++;
    }
    for (;;) {
        ux_ws(x);
        if (x->i >= x->n)
            return ux_fail(x, "unterminated tag", el);
        if (ux_at(x, "/>")) {
            ux_adv(x, 2);
            *empty = 1;
            break;
        }
        if (x->s[x->i] == '>') {
            ux_adv(x, 1);
            *empty = 0;
            break;
        }
        size_t len = 0;
        if (ux_name(x, attr, sizeof attr) != 0)
            return -1;
        ux_ws(x);
        if (x->i >= x->n || x->s[x->i] != '=')
            return ux_fail(x, "expected '=' after the attribute", attr);
        ux_adv(x, 1);
        ux_ws(x);
        if (ux_value(x, val, sizeof val, &len) != 0)
            return -1;
        int rc = 0;
        if (is_root && strcmp(attr, "name") == 0)
            rc = ux_keep(x, x->robot, sizeof x->robot, val, len, attr);
        else if (j && strcmp(attr, "name") == 0)
            rc = ux_keep(x, j->name, sizeof j->name, val, len, attr);
        else if (j && strcmp(attr, "type") == 0)
            rc = ux_keep(x, j->type, sizeof j->type, val, len, attr);
        else if (in_joint && strcmp(attr, "link") == 0) {
            ux_joint *cur = &x->joints[x->in_joint];
            rc = ux_keep(x, el[0] == 'p' ? cur->parent : cur->child, RCH_URDF_NAME_MAX, val, len, attr);
        }
        if (rc != 0)
            return -1;
    }
    if (j && (!j->name[0] || !j->type[0])) {
        rch_diag_set(x->d, x->file, line, col, "a <joint> needs name and type attributes");
        return -1;
    }
    if (*empty) {
        if (is_joint)
            x->in_joint = -1;
        return 0;
    }
    if (x->depth >= UX_MAX_DEPTH)
        return ux_fail(x, "elements nested too deep", NULL);
    snprintf(x->stack[x->depth++], sizeof x->stack[0], "%s", el);
    return 0;
}

static int ux_end_tag(ux *x)
{
    char el[64];
    if (ux_name(x, el, sizeof el) != 0)
        return -1;
    ux_ws(x);
    if (x->i >= x->n || x->s[x->i] != '>')
        return ux_fail(x, "expected '>' closing the end tag", el);
    ux_adv(x, 1);
    if (x->depth == 0 || strcmp(x->stack[x->depth - 1], el) != 0)
        return ux_fail(x, "end tag does not match the open element:", el);
    --x->depth;
    if (x->depth == 1)
        x->in_joint = -1;
    return 0;
}

static int ux_document(ux *x)
{
    while (x->i < x->n) {
        if (x->s[x->i] != '<') {
            if (x->depth == 0 && !is_space(x->s[x->i]))
                return ux_fail(x, "text outside the root element", NULL);
            ux_adv(x, 1);
            continue;
        }
        int rc = 0, empty = 0;
        if (ux_at(x, "<!--"))
            rc = ux_skip_to(x, "-->", "comment");
        else if (ux_at(x, "<?"))
            rc = ux_skip_to(x, "?>", "processing instruction");
        else if (ux_at(x, "<![CDATA["))
            rc = ux_skip_to(x, "]]>", "CDATA section");
        else if (ux_at(x, "<!")) {
            int bracket = 0;
            while (x->i < x->n && !(x->s[x->i] == '>' && bracket == 0)) {
                bracket += x->s[x->i] == '[' ? 1 : x->s[x->i] == ']' ? -1 : 0;
                ux_adv(x, 1);
            }
            if (x->i >= x->n)
                return ux_fail(x, "unterminated declaration", NULL);
            ux_adv(x, 1);
        } else if (ux_at(x, "</")) {
            ux_adv(x, 2);
            rc = ux_end_tag(x);
            if (rc == 0 && x->depth == 0)
                x->in_joint = -1;
        } else {
            ux_adv(x, 1);
            if (x->depth == 0 && x->seen_root)
                return ux_fail(x, "content after the root element", NULL);
            rc = ux_start_tag(x, &empty);
        }
        if (rc != 0)
            return -1;
    }
    if (x->depth != 0)
        return ux_fail(x, "unclosed element at the end:", x->stack[x->depth - 1]);
    if (!x->seen_root)
        return ux_fail(x, "no <robot> element", NULL);
    return 0;
}

static int movable(const ux_joint *j) { return strcmp(j->type, "fixed") != 0; }

/* The nearest movable joint above joint k (through fixed joints), or -1 at the root. */
static long upstream(const ux *x, size_t k)
{
    const char *link = x->joints[k].parent;
    for (size_t step = 0; step <= x->n_joints; ++step) {
        size_t p = 0;
        while (p < x->n_joints && strcmp(x->joints[p].child, link) != 0)
            ++p;
        if (p == x->n_joints)
            return -1;
        if (movable(&x->joints[p]))
            return (long)p;
        link = x->joints[p].parent;
    }
    return -2; /* a loop */
}

static int chain_names(rch_urdf_names *n, const ux *x, const char *file, rch_diag *d)
{
    size_t mov = 0, chain[RC_NJ];
    for (size_t k = 0; k < x->n_joints; ++k) {
        const ux_joint *j = &x->joints[k];
        if (!j->parent[0] || !j->child[0]) {
            rch_diag_set(d, file, j->line, j->col, "joint \"%s\" needs <parent link> and <child link>", j->name);
            return -1;
        }
        if (!movable(j))
            continue;
        if (strcmp(j->type, "revolute") != 0 && strcmp(j->type, "continuous") != 0) {
            rch_diag_set(d, file, j->line, j->col,
                         "joint \"%s\" is %s: rcal's model has six revolute joints", j->name, j->type);
            return -1;
        }
        ++mov;
    }
    if (mov != RC_NJ) {
        rch_diag_set(d, file, 0, 0, "the nominal URDF has %zu revolute/continuous joints, rcal's model 6", mov);
        return -1;
    }
    long prev = -1;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        size_t found = 0, at = 0;
        for (size_t k = 0; k < x->n_joints; ++k)
            if (movable(&x->joints[k]) && upstream(x, k) == prev) {
                ++found;
                at = k;
            }
        if (found != 1) {
            rch_diag_set(d, file, 0, 0, "the nominal URDF's movable joints are not one serial chain (%zu joints "
                         "follow %s)", found, prev < 0 ? "the root" : x->joints[prev].name);
            return -1;
        }
        chain[i] = at;
        prev = (long)at;
    }
    rch_urdf_names_default(n, x->robot);
    set_name(n->base_link, x->joints[chain[0]].parent);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const ux_joint *j = &x->joints[chain[i]];
        set_name(n->joint[i], j->name);
        set_name(n->link[i], j->child);
        n->continuous[i] = strcmp(j->type, "continuous") == 0;
    }
    unsigned written = RC_NJ;
    for (size_t k = 0; k < x->n_joints; ++k)
        if (!movable(&x->joints[k]) && strcmp(x->joints[k].parent, n->link[RC_NJ - 1]) == 0) {
            set_name(n->flange_joint, x->joints[k].name);
            set_name(n->flange_link, x->joints[k].child);
            ++written;
            break;
        }
    n->n_dropped = (unsigned)x->n_joints - written;
    return 0;
}

int rch_urdf_names_parse(rch_urdf_names *n, const char *text, size_t len, const char *file, rch_diag *d)
{
    ux *x = calloc(1, sizeof *x);
    ux_joint *joints = calloc(UX_MAX_JOINTS, sizeof *joints);
    int rc = -1;
    if (!x || !joints) {
        rch_diag_set(d, file, 0, 0, "out of memory");
        goto done;
    }
    x->s = text;
    x->n = len;
    x->line = x->col = 1;
    x->file = file;
    x->d = d;
    x->joints = joints;
    x->in_joint = -1;
    if (memchr(text, '\0', len) != NULL) {
        rch_diag_set(d, file, 0, 0, "a NUL byte: not an XML text");
        goto done;
    }
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        x->i = 3; /* a UTF-8 byte-order mark */
    if (ux_document(x) == 0)
        rc = chain_names(n, x, file, d);
done:
    free(joints);
    free(x);
    return rc;
}
