/* SPDX-License-Identifier: MIT */
/* rch_export.c - URDF and DH-CSV exports of a model (see rch_export.h). */
#include "rch_export.h"
#include "rch_comp.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_file.h"
#include "rch_json.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define RAD2DEG (180.0 / M_PI)

/* ---------------------------------------------------------------- XML out */

/* Length of the valid UTF-8 sequence at s (1..4), or 0 when invalid. */
static size_t utf8_len(const unsigned char *s)
{
    size_t n;
    unsigned c = s[0];
    unsigned long cp;
    if (c < 0x80)
        return 1;
    if (c >= 0xC2 && c <= 0xDF) {
        n = 2;
        cp = c & 0x1Fu;
    } else if (c >= 0xE0 && c <= 0xEF) {
        n = 3;
        cp = c & 0x0Fu;
    } else if (c >= 0xF0 && c <= 0xF4) {
        n = 4;
        cp = c & 0x07u;
    } else {
        return 0;
    }
    for (size_t k = 1; k < n; ++k) {
        if ((s[k] & 0xC0u) != 0x80u)
            return 0;
        cp = (cp << 6) | (s[k] & 0x3Fu);
    }
    if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) || (cp >= 0xD800 && cp <= 0xDFFF) ||
        cp == 0xFFFE || cp == 0xFFFF)
        return 0;
    return n;
}

/* Write s as XML character data or an attribute value: & < > " ' as
 * references; characters XML 1.0 cannot carry at all (controls other than
 * tab, newline, return; invalid UTF-8) as '?'. In a comment (comment != 0)
 * nothing is escaped but "--" never appears and the text never ends in '-'. */
static void xml_put(FILE *f, const char *s, int comment)
{
    const unsigned char *p = (const unsigned char *)(s ? s : "");
    unsigned char prev = 0;
    while (*p) {
        const unsigned c = *p;
        size_t n = utf8_len(p);
        if (n == 0 || (c < 0x20 && c != '\t' && c != '\n' && c != '\r')) {
            fputc('?', f);
            prev = '?';
            ++p;
            continue;
        }
        if (comment) {
            if (c == '-' && (prev == '-' || p[1] == '\0'))
                fputc(' ', f);
            fwrite(p, 1, n, f);
        } else if (c == '&') {
            fputs("&amp;", f);
        } else if (c == '<') {
            fputs("&lt;", f);
        } else if (c == '>') {
            fputs("&gt;", f);
        } else if (c == '"') {
            fputs("&quot;", f);
        } else if (c == '\'') {
            fputs("&apos;", f);
        } else if (c == '\t' || c == '\n' || c == '\r') {
            fprintf(f, "&#%u;", c); /* attribute values normalise raw white space */
        } else {
            fwrite(p, 1, n, f);
        }
        prev = (unsigned char)c;
        p += n;
    }
}

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

/* ---------------------------------------------------------------- origins */

void rch_urdf_origins(rch_urdf_origin origin[RC_NJ + 1], const rc_model *m)
{
    memset(origin, 0, (RC_NJ + 1) * sizeof origin[0]);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double a = m->x[RC_P_A(i)], d = m->x[RC_P_D(i)];
        const double al = m->x[RC_P_ALPHA(i)], th = m->x[RC_P_THETA(i)];
        rch_urdf_origin *o = &origin[i + 1];
        o->xyz_m[0] = a * cos(th) * 1e-3;
        o->xyz_m[1] = a * sin(th) * 1e-3;
        o->xyz_m[2] = d * 1e-3;
        o->rpy_rad[0] = al;
        o->rpy_rad[1] = 0.0;
        o->rpy_rad[2] = th;
    }
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        if (ef->kind != RC_EFF_AXIS_TILT || ef->joint >= RC_NJ)
            continue;
        /* Rz(theta) Rx(alpha) Ry(beta) as URDF's rpy: R = Rz(yaw) Ry(pitch) Rx(roll) */
        rch_urdf_origin *o = &origin[ef->joint + 1];
        const double th = o->rpy_rad[2], al = o->rpy_rad[0], b = m->x[ef->first];
        const double ct = cos(th), st = sin(th), ca = cos(al), sa = sin(al), cb = cos(b), sb = sin(b);
        const double A[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca};
        double R[9];
        for (int r = 0; r < 3; ++r) { /* A Ry(b) */
            R[3 * r] = A[3 * r] * cb - A[3 * r + 2] * sb;
            R[3 * r + 1] = A[3 * r + 1];
            R[3 * r + 2] = A[3 * r] * sb + A[3 * r + 2] * cb;
        }
        o->rpy_rad[2] = atan2(R[3], R[0]);
        o->rpy_rad[1] = atan2(-R[6], sqrt(R[7] * R[7] + R[8] * R[8]));
        o->rpy_rad[0] = atan2(R[7], R[8]);
    }
    for (unsigned e = 0; e < m->n_effects; ++e) {
        if (m->effects[e].kind != RC_EFF_TOOL_OFFSET)
            continue;
        /* xyz += Rz(theta6) Rx(alpha6) t */
        const double *t = &m->x[m->effects[e].first];
        const double ct = cos(origin[RC_NJ].rpy_rad[2]), st = sin(origin[RC_NJ].rpy_rad[2]);
        const double ca = cos(origin[RC_NJ].rpy_rad[0]), sa = sin(origin[RC_NJ].rpy_rad[0]);
        const double R[9] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca};
        for (unsigned r = 0; r < 3; ++r)
            origin[RC_NJ].xyz_m[r] += (R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2]) * 1e-3;
    }
}

/* ------------------------------------------------------- standard errors */

static int se_num(int *has, double *v, const rch_json *j, const char *file, rch_diag *d)
{
    if (!j || j->type == RCH_JNULL)
        return 0;
    if (j->type != RCH_JNUM || !(j->num >= 0.0)) {
        rch_diag_set(d, file, j->line, j->col, "a standard error must be a number >= 0 (or null)");
        return -1;
    }
    *has = 1;
    *v = j->num;
    return 0;
}

int rch_export_se_parse(rch_export_se *se, const char *text, size_t len, const char *file, rch_diag *d)
{
    static const char *const keys[4] = {"a_mm", "d_mm", "alpha_deg", "theta_deg"};
    memset(se, 0, sizeof *se);
    rch_json *root = rch_json_parse(text, len, file, d);
    if (!root)
        return -1;
    int rc = -1;
    const rch_json *blk = NULL, *cal = rch_json_get(root, "calibration");
    const rch_json *where[2] = {root, cal};
    for (int w = 0; w < 2 && !blk; ++w) {
        if (!where[w] || where[w]->type != RCH_JOBJ)
            continue;
        blk = rch_json_get(where[w], "std_error");
        if (!blk)
            blk = rch_json_get(where[w], "standard_error");
    }
    if (!blk) {
        rc = 0;
        goto done;
    }
    const rch_json *dh = blk->type == RCH_JOBJ ? rch_json_get(blk, "dh") : NULL;
    const rch_json *enc = blk->type == RCH_JOBJ ? rch_json_get(blk, "encoder_mm") : NULL;
    if (blk->type != RCH_JOBJ || (dh && (dh->type != RCH_JARR || dh->n != RC_NJ)) ||
        (enc && (enc->type != RCH_JARR || enc->n != 3))) {
        rch_diag_set(d, file, blk->line, blk->col,
                     "the standard-error block must be {\"dh\": [6 rows], \"encoder_mm\": [x, y, z]}");
        goto done;
    }
    se->has = 1;
    for (unsigned i = 0; dh && i < RC_NJ; ++i) {
        const rch_json *row = dh->items[i];
        if (row->type == RCH_JNULL)
            continue;
        if (row->type != RCH_JOBJ) {
            rch_diag_set(d, file, row->line, row->col, "a standard-error dh row must be an object");
            goto done;
        }
        for (unsigned k = 0; k < 4; ++k)
            if (se_num(&se->has_dh[i][k], &se->dh[i][k], rch_json_get(row, keys[k]), file, d) != 0)
                goto done;
    }
    for (unsigned k = 0; enc && k < 3; ++k)
        if (se_num(&se->has_enc[k], &se->enc_mm[k], enc->items[k], file, d) != 0)
            goto done;
    rc = 0;
done:
    rch_json_free(root);
    return rc;
}

/* ------------------------------------------------------------------- URDF */

static int joint_side(const rc_effect *e)
{
    return e->kind == RC_EFF_JOINT_COMPLIANCE || e->kind == RC_EFF_JOINT_PERIODIC;
}

static int has_tool(const rc_model *m)
{
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == RC_EFF_TOOL_OFFSET)
            return 1;
    return 0;
}

static void xml_attr(FILE *f, const char *key, const char *v)
{
    fprintf(f, " %s=\"", key);
    xml_put(f, v, 0);
    fputc('"', f);
}

static void write_origin(FILE *f, const rch_urdf_origin *o)
{
    fprintf(f, "    <origin xyz=\"%.17g %.17g %.17g\" rpy=\"%.17g %.17g %.17g\"/>\n", o->xyz_m[0], o->xyz_m[1],
            o->xyz_m[2], o->rpy_rad[0], o->rpy_rad[1], o->rpy_rad[2]);
}

static void write_link(FILE *f, const char *name)
{
    fputs("  <link", f);
    xml_attr(f, "name", name);
    fputs("/>\n", f);
}

static double wrap_deg(double v)
{
    v = fmod(v, 360.0);
    if (v > 180.0)
        v -= 360.0;
    else if (v <= -180.0)
        v += 360.0;
    return v;
}

/* Comment on the origin that carries DH row i (0-based) of the model. */
static void dh_comment(FILE *f, const rch_robot *r, unsigned i)
{
    const double *x = r->model.x, *nx = r->nominal.x;
    fprintf(f,
            "    <!-- DH row %u: a %.9g mm, d %.9g mm, alpha %.9g deg, theta %.9g deg (joint %u's zero offset, "
            "folded into yaw; calibrated - nominal = %.9g deg) -->\n",
            i + 1, x[RC_P_A(i)], x[RC_P_D(i)], x[RC_P_ALPHA(i)] * RAD2DEG, x[RC_P_THETA(i)] * RAD2DEG, i + 1,
            wrap_deg((x[RC_P_THETA(i)] - nx[RC_P_THETA(i)]) * RAD2DEG));
}

static void write_urdf(FILE *f, const rch_export_cfg *cfg, const rch_robot *r, const rch_urdf_names *n,
                       rch_export_result *res)
{
    rch_urdf_origin o[RC_NJ + 1];
    /* the robot compensation uses: its flange, never the cable attachment
     * the calibration measured (named in a comment below) */
    static rc_model pm;
    rch_comp_point_model(&pm, &r->model, NULL);
    rch_urdf_origins(o, &pm);
    fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Generated by rcal export from ", f);
    xml_put(f, cfg->source ? cfg->source : "a model", 1);
    fputs(" (model \"", f);
    xml_put(f, r->name, 1);
    fputs("\"). Kinematics only: no visual, collision or inertial elements.\n"
          "     Layout (docs/export.md): joint i rotates about its z axis by rcal's joint reading q_i; the\n"
          "     origin of joint i+1 (and of the fixed flange joint after joint 6) is DH row i,\n"
          "     Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) = xyz (a cos theta, a sin theta, d), rpy (alpha, 0, theta).\n"
          "     The joint-zero offsets theta_i are folded into those yaw angles, not written as <calibration>:\n"
          "     URDF's calibration element marks reference-switch edges that kinematics consumers do not apply.\n"
          "     Lengths in m, angles in rad. Effort and velocity limits are unknown to rcal (written as 0). -->\n",
          f);
    for (unsigned e = 0; e < r->model.n_effects; ++e) {
        const rc_effect *ef = &r->model.effects[e];
        if (ef->kind == RC_EFF_TOOL_OFFSET || ef->kind == RC_EFF_AXIS_TILT) /* carried by the origins */
            continue;
        fprintf(f, "<!-- Model effect %s%s not carried by this URDF%s -->\n", rc_effect_name((rc_effect_kind)ef->kind),
                joint_side(ef) ? " (joint-side)" : " (cable-length side)",
                joint_side(ef) ? ": forward kinematics from this file differ from rcal's" : "");
        ++res->n_effects_left;
    }
    if (n->n_dropped)
        fprintf(f, "<!-- %u joint(s) of the nominal URDF outside the arm's chain are not written. -->\n",
                n->n_dropped);
    fputs("<robot", f);
    xml_attr(f, "name", n->robot);
    fputs(">\n", f);
    write_link(f, n->base_link);
    for (unsigned i = 0; i <= RC_NJ; ++i) {
        const int flange = i == RC_NJ;
        fputs("  <joint", f);
        xml_attr(f, "name", flange ? n->flange_joint : n->joint[i]);
        xml_attr(f, "type", flange ? "fixed" : n->continuous[i] ? "continuous" : "revolute");
        fputs(">\n", f);
        if (i == 0)
            fputs("    <!-- the base frame is rcal's DH frame 0 -->\n", f);
        else
            dh_comment(f, r, i - 1);
        if (flange && has_tool(&r->model)) {
            for (unsigned e = 0; e < r->model.n_effects; ++e)
                if (r->model.effects[e].kind == RC_EFF_TOOL_OFFSET) {
                    const double *t = &r->model.x[r->model.effects[e].first];
                    fprintf(f, "    <!-- the cable was attached at (%.6g, %.6g, %.6g) mm in this flange frame: "
                               "not a link (the flange is the robot's) -->\n", t[0], t[1], t[2]);
                    break;
                }
        }
        write_origin(f, &o[i]);
        fputs("    <parent", f);
        xml_attr(f, "link", i == 0 ? n->base_link : n->link[i - 1]);
        fputs("/>\n    <child", f);
        xml_attr(f, "link", flange ? n->flange_link : n->link[i]);
        fputs("/>\n", f);
        if (!flange) {
            fputs("    <axis xyz=\"0 0 1\"/>\n", f);
            if (n->continuous[i])
                fputs("    <limit effort=\"0\" velocity=\"0\"/>\n", f);
            else
                fprintf(f, "    <limit lower=\"%.17g\" upper=\"%.17g\" effort=\"0\" velocity=\"0\"/>\n",
                        r->model.q_min_rad[i], r->model.q_max_rad[i]);
        }
        fputs("  </joint>\n", f);
        write_link(f, flange ? n->flange_link : n->link[i]);
        ++res->n_joints;
    }
    fputs("</robot>\n", f);
}

/* -------------------------------------------------------------------- CSV */

static void csv_num(FILE *f, int has, double v)
{
    fputc(',', f);
    if (has)
        fprintf(f, "%.17g", v);
}

static void write_csv(FILE *f, const rch_export_cfg *cfg, const rch_robot *r, rch_export_result *res)
{
    static const char *const names[4] = {"a", "d", "alpha", "theta"};
    const rch_export_se *se = cfg->se && cfg->se->has ? cfg->se : NULL;
    fputs("joint,name,unit,nominal,calibrated,correction,standard_error\n", f);
    for (unsigned i = 0; i < RC_NJ; ++i)
        for (unsigned k = 0; k < 4; ++k) {
            const int ang = k >= 2;
            const double s = ang ? RAD2DEG : 1.0;
            const double nom = r->nominal.x[4 * i + k] * s, cal = r->model.x[4 * i + k] * s;
            const double corr = ang ? wrap_deg(cal - nom) : cal - nom;
            fprintf(f, "%u,%s,%s", i + 1, names[k], ang ? "deg" : "mm");
            csv_num(f, 1, nom);
            csv_num(f, 1, cal);
            csv_num(f, 1, corr);
            csv_num(f, se && se->has_dh[i][k], se ? se->dh[i][k] : 0.0);
            fputc('\n', f);
            ++res->n_rows;
        }
    for (unsigned k = 0; r->has_encoder && k < 3; ++k) {
        fprintf(f, "encoder,%c,mm,", "xyz"[k]);
        csv_num(f, 1, r->model.x[RC_P_ENC + k]);
        fputc(',', f);
        csv_num(f, se && se->has_enc[k], se ? se->enc_mm[k] : 0.0);
        fputc('\n', f);
        ++res->n_rows;
    }
    for (unsigned e = 0; e < r->model.n_effects; ++e) {
        const rc_effect *ef = &r->model.effects[e];
        for (unsigned k = ef->first; k < (unsigned)ef->first + ef->count; ++k) {
            char name[64];
            const int unit = rc_param_unit(&r->model, k);
            const double s = unit == 1 ? RAD2DEG : 1.0;
            const char *u = unit == 0 ? "mm" : unit == 1 ? "deg" : ef->kind == RC_EFF_JOINT_COMPLIANCE ? "rad/m" : "1";
            fprintf(f, "effect,%s,%s", rc_param_name(name, sizeof name, &r->model, k), u);
            csv_num(f, 1, 0.0);
            csv_num(f, 1, r->model.x[k] * s);
            csv_num(f, 1, r->model.x[k] * s);
            fputs(",\n", f);
            ++res->n_rows;
        }
    }
    res->has_se = se != NULL;
}

/* -------------------------------------------------------------- entries */

int rch_export_write(rch_export_result *res, FILE *f, const rch_export_cfg *cfg, const rch_robot *r, rch_diag *d)
{
    memset(res, 0, sizeof *res);
    if (cfg->format == RCH_EXPORT_URDF) {
        for (unsigned e = 0; e < r->model.n_effects; ++e)
            if (joint_side(&r->model.effects[e]) && !cfg->drop_joint_effects) {
                rch_diag_set(d, cfg->source ? cfg->source : "", 0, 0,
                             "the model has a %s effect on joint %u, which a URDF cannot express: refused "
                             "(--drop-joint-effects writes the geometry alone)",
                             rc_effect_name((rc_effect_kind)r->model.effects[e].kind), r->model.effects[e].joint + 1u);
                return -1;
            }
        rch_urdf_names gen;
        if (!cfg->names)
            rch_urdf_names_default(&gen, r->name);
        write_urdf(f, cfg, r, cfg->names ? cfg->names : &gen, res);
    } else {
        write_csv(f, cfg, r, res);
    }
    if (fflush(f) != 0 || ferror(f)) {
        rch_diag_set(d, "", 0, 0, "write error");
        return -1;
    }
    return 0;
}

int rch_export_file(rch_export_result *res, FILE *f, rch_export_format format, const char *model_path,
                    const char *nominal_urdf, int drop_joint_effects, rch_diag *d)
{
    char *text = NULL;
    size_t len = 0;
    rch_robot *r = malloc(sizeof *r);
    rch_urdf_names *names = malloc(sizeof *names);
    rch_export_se se;
    int rc = -1;
    memset(res, 0, sizeof *res);
    if (!r || !names) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    if (rch_read_file(&text, &len, model_path, (size_t)1 << 20, d) != 0 ||
        rch_robot_parse(r, text, len, model_path, d) != 0 || rch_export_se_parse(&se, text, len, model_path, d) != 0)
        goto done;
    free(text);
    text = NULL;
    if (nominal_urdf && (rch_read_file(&text, &len, nominal_urdf, (size_t)16 << 20, d) != 0 ||
                         rch_urdf_names_parse(names, text, len, nominal_urdf, d) != 0))
        goto done;
    const rch_export_cfg cfg = {format, nominal_urdf ? names : NULL, &se, model_path, drop_joint_effects};
    rc = rch_export_write(res, f, &cfg, r, d);
done:
    free(text);
    free(names);
    free(r);
    return rc;
}
