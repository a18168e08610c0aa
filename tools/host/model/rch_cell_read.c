/* SPDX-License-Identifier: MIT */
/* rch_cell_read.c - the robot file's "links" and "cell" members into an
 * rch_cell (docs/model-format.md, "Links and cell"). Split from
 * rch_robot.c (which calls it) by concept: the cell's geometry.
 * Depends on: rch_json, rch_diag. Errors: -1 with d set at the value's
 * file:line:col. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rch_cell.h"
#include "rch_cell_read.h"

static int keys_ok(const rch_json *o, const char *const *known, const char *where, const char *file, rch_diag *d)
{
    for (size_t i = 0; i < o->n; ++i) {
        size_t m = 0;
        while (known[m] && strcmp(known[m], o->keys[i]) != 0)
            ++m;
        if (!known[m]) {
            char list[256] = "";
            size_t at = 0;
            for (size_t j = 0; known[j] && at < sizeof list; ++j)
                at += (size_t)snprintf(list + at, sizeof list - at, "%s%s", j ? ", " : "", known[j]);
            rch_diag_set(d, file, o->items[i]->key_line ? o->items[i]->key_line : o->line,
                         o->items[i]->key_line ? o->items[i]->key_col : o->col,
                         "unknown key \"%.60s\" in %s (its keys: %s)", o->keys[i], where, list);
            return -1;
        }
    }
    return 0;
}

static int vec3(double v[3], const rch_json *j, const char *what, const char *file, const rch_json *at, rch_diag *d)
{
    if (!j) {
        rch_diag_set(d, file, at->line, at->col, "%s is missing ([x, y, z] in mm)", what);
        return -1;
    }
    if (j->type != RCH_JARR || j->n != 3) {
        rch_diag_set(d, file, j->line, j->col, "%s must be [x, y, z] (mm)", what);
        return -1;
    }
    for (unsigned k = 0; k < 3; ++k) {
        if (j->items[k]->type != RCH_JNUM || !isfinite(j->items[k]->num) || fabs(j->items[k]->num) > 1e5) {
            rch_diag_set(d, file, j->items[k]->line, j->items[k]->col, "%s: a number of mm (|x| <= 1e5) expected",
                         what);
            return -1;
        }
        v[k] = j->items[k]->num;
    }
    return 0;
}

static void name_of(char out[32], const rch_json *o, const char *dflt, unsigned k)
{
    const rch_json *nm = rch_json_get(o, "name");
    if (nm && nm->type == RCH_JSTR)
        snprintf(out, 32, "%.31s", nm->str);
    else
        snprintf(out, 32, "%s %u", dflt, k + 1);
}

static int read_links(rch_cell *c, const rch_json *links, const char *file, rch_diag *d)
{
    static const char *const keys[] = {"name", "frame", "from_mm", "to_mm", "radius_mm", NULL};
    if (links->type != RCH_JARR || links->n > RCH_CELL_MAX_LINKS) {
        rch_diag_set(d, file, links->line, links->col, "\"links\" must be an array of at most %u capsules",
                     RCH_CELL_MAX_LINKS);
        return -1;
    }
    for (size_t k = 0; k < links->n; ++k) {
        const rch_json *o = links->items[k];
        rch_capsule *l = &c->link[k];
        char where[48];
        snprintf(where, sizeof where, "link %zu", k + 1);
        if (o->type != RCH_JOBJ) {
            rch_diag_set(d, file, o->line, o->col, "%s must be an object {frame, from_mm, to_mm, radius_mm}", where);
            return -1;
        }
        if (keys_ok(o, keys, where, file, d) != 0)
            return -1;
        const rch_json *fr = rch_json_get(o, "frame"), *r = rch_json_get(o, "radius_mm");
        if (!fr || fr->type != RCH_JNUM || fr->num != floor(fr->num) || fr->num < 0 || fr->num > 6) {
            rch_diag_set(d, file, fr ? fr->line : o->line, fr ? fr->col : o->col,
                         "%s: \"frame\" must be 0 (the base) .. 6 (the flange)", where);
            return -1;
        }
        if (!r || r->type != RCH_JNUM || !(r->num >= 0.0 && r->num <= 5000.0)) {
            rch_diag_set(d, file, r ? r->line : o->line, r ? r->col : o->col,
                         "%s: \"radius_mm\" must be a number in [0, 5000]", where);
            return -1;
        }
        l->frame = (unsigned)fr->num;
        l->radius_mm = r->num;
        if (vec3(l->from_mm, rch_json_get(o, "from_mm"), "\"from_mm\"", file, o, d) != 0 ||
            vec3(l->to_mm, rch_json_get(o, "to_mm"), "\"to_mm\"", file, o, d) != 0)
            return -1;
        name_of(l->name, o, "link", (unsigned)k);
    }
    c->n_links = (unsigned)links->n;
    return 0;
}

static int read_floor(rch_cell *c, const rch_json *fl, const char *file, rch_diag *d)
{
    static const char *const keys[] = {"point_mm", "normal", NULL};
    if (fl->type != RCH_JOBJ) {
        rch_diag_set(d, file, fl->line, fl->col, "\"floor\" must be an object {point_mm, normal}");
        return -1;
    }
    if (keys_ok(fl, keys, "\"floor\"", file, d) != 0)
        return -1;
    const double zero[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    memcpy(c->floor_point_mm, zero, sizeof zero);
    memcpy(c->floor_normal, up, sizeof up);
    const rch_json *p = rch_json_get(fl, "point_mm"), *n = rch_json_get(fl, "normal");
    if ((p && vec3(c->floor_point_mm, p, "\"floor\" \"point_mm\"", file, fl, d) != 0) ||
        (n && vec3(c->floor_normal, n, "\"floor\" \"normal\"", file, fl, d) != 0))
        return -1;
    const double len = sqrt(c->floor_normal[0] * c->floor_normal[0] + c->floor_normal[1] * c->floor_normal[1] +
                            c->floor_normal[2] * c->floor_normal[2]);
    if (!(len > 1e-9)) {
        rch_diag_set(d, file, n ? n->line : 0, n ? n->col : 0, "\"floor\" \"normal\" must not be zero");
        return -1;
    }
    for (unsigned k = 0; k < 3; ++k)
        c->floor_normal[k] /= len;
    c->has_floor = 1;
    return 0;
}

static int read_boxes(rch_cell *c, const rch_json *bx, const char *file, rch_diag *d)
{
    static const char *const keys[] = {"name", "min_mm", "max_mm", NULL};
    if (bx->type != RCH_JARR || bx->n > RCH_CELL_MAX_BOXES) {
        rch_diag_set(d, file, bx->line, bx->col, "\"boxes\" must be an array of at most %u boxes",
                     RCH_CELL_MAX_BOXES);
        return -1;
    }
    for (size_t k = 0; k < bx->n; ++k) {
        const rch_json *o = bx->items[k];
        rch_box *b = &c->box[k];
        char where[48];
        snprintf(where, sizeof where, "box %zu", k + 1);
        if (o->type != RCH_JOBJ) {
            rch_diag_set(d, file, o->line, o->col, "%s must be an object {min_mm, max_mm}", where);
            return -1;
        }
        if (keys_ok(o, keys, where, file, d) != 0 ||
            vec3(b->min_mm, rch_json_get(o, "min_mm"), "\"min_mm\"", file, o, d) != 0 ||
            vec3(b->max_mm, rch_json_get(o, "max_mm"), "\"max_mm\"", file, o, d) != 0)
            return -1;
        for (unsigned i = 0; i < 3; ++i)
            if (!(b->min_mm[i] < b->max_mm[i])) {
                rch_diag_set(d, file, o->line, o->col, "%s: min_mm must be below max_mm on every axis", where);
                return -1;
            }
        name_of(b->name, o, "box", (unsigned)k);
    }
    c->n_boxes = (unsigned)bx->n;
    return 0;
}

int rch_cell_read(rch_cell *out, const rch_json *links, const rch_json *cell, const char *file, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    if (links && read_links(out, links, file, d) != 0)
        return -1;
    if (!cell)
        return 0;
    static const char *const keys[] = {"floor", "boxes", NULL};
    if (cell->type != RCH_JOBJ) {
        rch_diag_set(d, file, cell->line, cell->col, "\"cell\" must be an object {floor, boxes}");
        return -1;
    }
    if (keys_ok(cell, keys, "\"cell\"", file, d) != 0)
        return -1;
    const rch_json *fl = rch_json_get(cell, "floor"), *bx = rch_json_get(cell, "boxes");
    if ((fl && read_floor(out, fl, file, d) != 0) || (bx && read_boxes(out, bx, file, d) != 0))
        return -1;
    return 0;
}
