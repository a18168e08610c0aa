/* SPDX-License-Identifier: MIT */
/* rch_urdf.c - the URDF reader (see rch_urdf.h): the XML read by expat
 * (libexpat, Debian libexpat1-dev), the robot's joints and links kept with
 * where their <origin> start tags sit in the text (for the overlay). */
#include "rch_urdf.h"

#include <expat.h>
#include <math.h>
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

/* -------------------------------------------------------------- the doc */

typedef struct {
    rch_urdf_doc *doc;
    XML_Parser p;
    const char *file;
    rch_diag *d;
    int depth;
    int failed;
    long in_joint; /* index of the <joint> (child of <robot>) being read, or -1 */
} ux;

static void ux_fail(ux *x, const char *fmt, const char *a, const char *b)
{
    if (x->failed)
        return;
    x->failed = 1;
    rch_diag_set(x->d, x->file, (unsigned)XML_GetCurrentLineNumber(x->p),
                 (unsigned)XML_GetCurrentColumnNumber(x->p) + 1u, fmt, a ? a : "", b ? b : "");
    XML_StopParser(x->p, XML_FALSE);
}

static const char *attr(const XML_Char **at, const char *key)
{
    for (size_t k = 0; at[k]; k += 2)
        if (strcmp(at[k], key) == 0)
            return at[k + 1];
    return NULL;
}

/* a name attribute into dst; 0, or -1 (x failed) */
static int name_into(ux *x, char dst[RCH_URDF_NAME_MAX], const char *v, const char *what)
{
    if (strlen(v) >= RCH_URDF_NAME_MAX) {
        ux_fail(x, "%s name too long (over 127 bytes): %.40s...", what, v);
        return -1;
    }
    snprintf(dst, RCH_URDF_NAME_MAX, "%s", v);
    return 0;
}

/* "x y z" into v (3); 0, or -1 (x failed) */
static int triple(ux *x, double v[3], const char *text, const char *what)
{
    const char *s = text;
    for (int k = 0; k < 3; ++k) {
        char *end;
        v[k] = strtod(s, &end);
        if (end == s || !isfinite(v[k])) {
            ux_fail(x, "%s: \"%s\" is not three numbers", what, text);
            return -1;
        }
        s = end;
    }
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r')
        ++s;
    if (*s) {
        ux_fail(x, "%s: \"%s\" is not three numbers", what, text);
        return -1;
    }
    return 0;
}

static void XMLCALL on_start(void *ud, const XML_Char *el, const XML_Char **at)
{
    ux *x = ud;
    rch_urdf_doc *doc = x->doc;
    const int depth = x->depth++;
    if (x->failed)
        return;
    if (depth == 0) {
        if (strcmp(el, "robot") != 0) {
            ux_fail(x, "the root element is <%s>, not <robot>: not a URDF%s", el, NULL);
            return;
        }
        const char *nm = attr(at, "name");
        if (nm)
            name_into(x, doc->robot, nm, "robot");
        return;
    }
    if (depth == 1 && strcmp(el, "link") == 0) {
        if (doc->n_links == RCH_URDF_MAX_LINKS) {
            ux_fail(x, "more than %s links%s", "1024", NULL);
            return;
        }
        const char *nm = attr(at, "name");
        if (!nm) {
            ux_fail(x, "<link> needs a name%s%s", NULL, NULL);
            return;
        }
        name_into(x, doc->link[doc->n_links++], nm, "link");
        return;
    }
    if (depth == 1 && strcmp(el, "joint") == 0) {
        if (doc->n_joints == RCH_URDF_MAX_JOINTS) {
            ux_fail(x, "more than %s joints%s", "512", NULL);
            return;
        }
        rch_urdf_joint *j = &doc->joint[doc->n_joints];
        memset(j, 0, sizeof *j);
        j->line = (unsigned)XML_GetCurrentLineNumber(x->p);
        j->col = (unsigned)XML_GetCurrentColumnNumber(x->p) + 1u;
        j->axis[0] = 1.0; /* URDF's default axis */
        j->tag_end = (size_t)XML_GetCurrentByteIndex(x->p) + (size_t)XML_GetCurrentByteCount(x->p);
        const char *nm = attr(at, "name"), *ty = attr(at, "type");
        if (!nm || !ty) {
            ux_fail(x, "<joint> needs a name and a type%s%s", NULL, NULL);
            return;
        }
        if (name_into(x, j->name, nm, "joint") != 0)
            return;
        if (strlen(ty) >= sizeof j->type) {
            ux_fail(x, "joint type too long: %.40s%s", ty, NULL);
            return;
        }
        snprintf(j->type, sizeof j->type, "%s", ty);
        x->in_joint = (long)doc->n_joints++;
        return;
    }
    if (depth == 2 && x->in_joint >= 0) {
        rch_urdf_joint *j = &doc->joint[x->in_joint];
        if (strcmp(el, "parent") == 0 || strcmp(el, "child") == 0) {
            const char *lk = attr(at, "link");
            if (!lk) {
                ux_fail(x, "<%s> needs a link attribute%s", el, NULL);
                return;
            }
            name_into(x, el[0] == 'p' ? j->parent : j->child, lk, "link");
        } else if (strcmp(el, "origin") == 0) {
            const char *xyz = attr(at, "xyz"), *rpy = attr(at, "rpy");
            if ((xyz && triple(x, j->xyz, xyz, "origin xyz") != 0) || (rpy && triple(x, j->rpy, rpy, "origin rpy") != 0))
                return;
            j->has_origin = 1;
            j->origin_at = (size_t)XML_GetCurrentByteIndex(x->p);
            j->origin_len = (size_t)XML_GetCurrentByteCount(x->p);
        } else if (strcmp(el, "axis") == 0) {
            const char *xyz = attr(at, "xyz");
            if (xyz && triple(x, j->axis, xyz, "axis xyz") != 0)
                return;
        } else if (strcmp(el, "limit") == 0) {
            const char *lo = attr(at, "lower"), *hi = attr(at, "upper");
            j->has_limit = lo || hi;
            j->lower = lo ? strtod(lo, NULL) : 0.0;
            j->upper = hi ? strtod(hi, NULL) : 0.0;
        }
    }
}

static void XMLCALL on_end(void *ud, const XML_Char *el)
{
    ux *x = ud;
    (void)el;
    if (--x->depth == 1)
        x->in_joint = -1;
}

void rch_urdf_doc_free(rch_urdf_doc *doc)
{
    if (doc) {
        free(doc->joint);
        free(doc->link);
        memset(doc, 0, sizeof *doc);
    }
}

int rch_urdf_doc_parse(rch_urdf_doc *doc, const char *text, size_t len, const char *file, rch_diag *d)
{
    memset(doc, 0, sizeof *doc);
    doc->joint = calloc(RCH_URDF_MAX_JOINTS, sizeof *doc->joint);
    doc->link = calloc(RCH_URDF_MAX_LINKS, sizeof *doc->link);
    if (!doc->joint || !doc->link || len > (size_t)1 << 30) {
        rch_diag_set(d, file, 0, 0, doc->joint && doc->link ? "the URDF is over 1 GiB" : "out of memory");
        rch_urdf_doc_free(doc);
        return -1;
    }
    if (memchr(text, '\0', len) != NULL) {
        rch_diag_set(d, file, 0, 0, "a NUL byte: not an XML text");
        rch_urdf_doc_free(doc);
        return -1;
    }
    XML_Parser p = XML_ParserCreate(NULL);
    if (!p) {
        rch_diag_set(d, file, 0, 0, "out of memory");
        rch_urdf_doc_free(doc);
        return -1;
    }
    ux x = {doc, p, file, d, 0, 0, -1};
    XML_SetUserData(p, &x);
    XML_SetElementHandler(p, on_start, on_end);
    /* no external entity is ever loaded (expat's default: none) */
    const enum XML_Status st = XML_Parse(p, text, (int)len, XML_TRUE);
    if (st != XML_STATUS_OK && !x.failed) {
        rch_diag_set(d, file, (unsigned)XML_GetCurrentLineNumber(p), (unsigned)XML_GetCurrentColumnNumber(p) + 1u,
                     "not well-formed XML: %s", XML_ErrorString(XML_GetErrorCode(p)));
        x.failed = 1;
    }
    XML_ParserFree(p);
    if (x.failed) {
        rch_urdf_doc_free(doc);
        return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- chain */

static int movable(const rch_urdf_joint *j) { return strcmp(j->type, "fixed") != 0; }

/* The nearest movable joint above joint k (through fixed joints), or -1 at the root. */
static long upstream(const rch_urdf_doc *x, size_t k)
{
    const char *link = x->joint[k].parent;
    for (size_t step = 0; step <= x->n_joints; ++step) {
        size_t p = 0;
        while (p < x->n_joints && strcmp(x->joint[p].child, link) != 0)
            ++p;
        if (p == x->n_joints)
            return -1;
        if (movable(&x->joint[p]))
            return (long)p;
        link = x->joint[p].parent;
    }
    return -2; /* a loop */
}

int rch_urdf_chain(size_t chain[RC_NJ], const rch_urdf_doc *x, const char *file, rch_diag *d)
{
    size_t mov = 0;
    for (size_t k = 0; k < x->n_joints; ++k) {
        const rch_urdf_joint *j = &x->joint[k];
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
            if (movable(&x->joint[k]) && upstream(x, k) == prev) {
                ++found;
                at = k;
            }
        if (found != 1) {
            rch_diag_set(d, file, 0, 0, "the nominal URDF's movable joints are not one serial chain (%zu joints "
                         "follow %s)", found, prev < 0 ? "the root" : x->joint[prev].name);
            return -1;
        }
        chain[i] = at;
        prev = (long)at;
    }
    return 0;
}

static int chain_names(rch_urdf_names *n, const rch_urdf_doc *x, const char *file, rch_diag *d)
{
    size_t chain[RC_NJ];
    if (rch_urdf_chain(chain, x, file, d) != 0)
        return -1;
    rch_urdf_names_default(n, x->robot);
    set_name(n->base_link, x->joint[chain[0]].parent);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rch_urdf_joint *j = &x->joint[chain[i]];
        set_name(n->joint[i], j->name);
        set_name(n->link[i], j->child);
        n->continuous[i] = strcmp(j->type, "continuous") == 0;
    }
    unsigned written = RC_NJ;
    for (size_t k = 0; k < x->n_joints; ++k)
        if (!movable(&x->joint[k]) && strcmp(x->joint[k].parent, n->link[RC_NJ - 1]) == 0) {
            set_name(n->flange_joint, x->joint[k].name);
            set_name(n->flange_link, x->joint[k].child);
            ++written;
            break;
        }
    n->n_dropped = (unsigned)x->n_joints - written;
    return 0;
}

int rch_urdf_names_parse(rch_urdf_names *n, const char *text, size_t len, const char *file, rch_diag *d)
{
    rch_urdf_doc doc;
    if (rch_urdf_doc_parse(&doc, text, len, file, d) != 0)
        return -1;
    const int rc = chain_names(n, &doc, file, d);
    rch_urdf_doc_free(&doc);
    return rc;
}
