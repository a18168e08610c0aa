/* SPDX-License-Identifier: MIT */
/* rch_cell.c - capsules, floor and boxes against the straight cable (see
 * rch_cell.h). Depends on: rc_model (rc_model_theta). No heap. */
#include "rch_cell.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const char *rch_cell_reason_name(rch_cell_reason r)
{
    switch (r) {
    case RCH_CELL_SAFE: return "safe";
    case RCH_CELL_BELOW_FLOOR: return "flange or link below the floor";
    case RCH_CELL_LINK_BOX: return "link inside a box";
    case RCH_CELL_CABLE_LINK: return "cable near a link";
    case RCH_CELL_CABLE_BOX: return "cable near a box";
    case RCH_CELL_CABLE_FLOOR: return "cable near the floor";
    }
    return "?";
}

const char *rch_cell_reason_key(rch_cell_reason r)
{
    static const char *const k[RCH_CELL_N_REASONS] = {"safe", "below_floor", "link_in_box", "cable_link",
                                                      "cable_box", "cable_floor"};
    return (unsigned)r < RCH_CELL_N_REASONS ? k[r] : "?";
}

int rch_cell_any(const rch_cell *c)
{
    return c && (c->n_links > 0 || c->has_floor || c->n_boxes > 0);
}

void rch_cell_frames(double frames[7][12], const rc_model *m, const double q_rad[RC_NJ])
{
    double th[RC_NJ];
    rc_model_theta(th, m, q_rad);
    memset(frames[0], 0, sizeof frames[0]);
    frames[0][0] = frames[0][4] = frames[0][8] = 1.0;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double a = m->x[RC_P_A(i)], d = m->x[RC_P_D(i)], al = m->x[RC_P_ALPHA(i)];
        const double ct = cos(th[i]), st = sin(th[i]), ca = cos(al), sa = sin(al);
        /* T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha) */
        const double A[12] = {ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca, a * ct, a * st, d};
        const double *P = frames[i];
        double *N = frames[i + 1];
        for (unsigned r = 0; r < 3; ++r) {
            for (unsigned k = 0; k < 3; ++k)
                N[3 * r + k] = P[3 * r] * A[k] + P[3 * r + 1] * A[3 + k] + P[3 * r + 2] * A[6 + k];
            N[9 + r] = P[9 + r] + P[3 * r] * A[9] + P[3 * r + 1] * A[10] + P[3 * r + 2] * A[11];
        }
    }
}

static void to_base(double out[3], const double f[12], const double p[3])
{
    for (unsigned r = 0; r < 3; ++r)
        out[r] = f[9 + r] + f[3 * r] * p[0] + f[3 * r + 1] * p[1] + f[3 * r + 2] * p[2];
}

void rch_cell_link_base(double a_mm[3], double b_mm[3], const rch_cell *c, unsigned k, const double frames[7][12])
{
    const rch_capsule *l = &c->link[k];
    to_base(a_mm, frames[l->frame], l->from_mm);
    to_base(b_mm, frames[l->frame], l->to_mm);
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double clamp01(double t) { return t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t; }

/* Closest points of two segments (Ericson, Real-Time Collision Detection 5.1.9). */
double rch_cell_seg_seg_mm(const double p0[3], const double p1[3], const double q0[3], const double q1[3])
{
    double d1[3], d2[3], r[3];
    for (unsigned i = 0; i < 3; ++i) {
        d1[i] = p1[i] - p0[i];
        d2[i] = q1[i] - q0[i];
        r[i] = p0[i] - q0[i];
    }
    const double a = dot3(d1, d1), e = dot3(d2, d2), f = dot3(d2, r);
    const double eps = 1e-18;
    double s, t;
    if (a <= eps && e <= eps) {
        s = t = 0.0;
    } else if (a <= eps) {
        s = 0.0;
        t = clamp01(f / e);
    } else {
        const double cc = dot3(d1, r);
        if (e <= eps) {
            t = 0.0;
            s = clamp01(-cc / a);
        } else {
            const double b = dot3(d1, d2), den = a * e - b * b;
            s = den > eps * a * e ? clamp01((b * f - cc * e) / den) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) {
                t = 0.0;
                s = clamp01(-cc / a);
            } else if (t > 1.0) {
                t = 1.0;
                s = clamp01((b - cc) / a);
            }
        }
    }
    double dd = 0.0;
    for (unsigned i = 0; i < 3; ++i) {
        const double x = p0[i] + s * d1[i] - (q0[i] + t * d2[i]);
        dd += x * x;
    }
    return sqrt(dd);
}

double rch_cell_floor_mm(const rch_cell *c, const double p[3])
{
    double v[3] = {p[0] - c->floor_point_mm[0], p[1] - c->floor_point_mm[1], p[2] - c->floor_point_mm[2]};
    return dot3(v, c->floor_normal);
}

static double point_box(const double p[3], const rch_box *b)
{
    double dd = 0.0;
    for (unsigned i = 0; i < 3; ++i) {
        const double x = p[i] < b->min_mm[i] ? b->min_mm[i] - p[i] : p[i] > b->max_mm[i] ? p[i] - b->max_mm[i] : 0.0;
        dd += x * x;
    }
    return sqrt(dd);
}

static double seg_box_at(const double p0[3], const double p1[3], const rch_box *b, double t)
{
    const double p[3] = {p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1]), p0[2] + t * (p1[2] - p0[2])};
    return point_box(p, b);
}

/* The distance of a point moving along the segment from a convex set is a
 * convex function of t: golden-section search finds its minimum. */
double rch_cell_seg_box_mm(const double p0[3], const double p1[3], const rch_box *b)
{
    const double g = 0.6180339887498949;
    double lo = 0.0, hi = 1.0;
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = seg_box_at(p0, p1, b, x1), f2 = seg_box_at(p0, p1, b, x2);
    for (unsigned it = 0; it < 60 && hi - lo > 1e-12; ++it) {
        if (f1 <= f2) {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = seg_box_at(p0, p1, b, x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = seg_box_at(p0, p1, b, x2);
        }
    }
    double best = f1 < f2 ? f1 : f2;
    const double e0 = seg_box_at(p0, p1, b, 0.0), e1 = seg_box_at(p0, p1, b, 1.0);
    best = e0 < best ? e0 : best;
    return e1 < best ? e1 : best;
}

static int set(rch_cell_verdict *out, rch_cell_reason r, int which, double dist)
{
    out->reason = r;
    out->which = which;
    out->dist_mm = dist;
    return 1;
}

static int check_arm(rch_cell_verdict *out, const rch_cell *c, const double fr[7][12], const double flange[3],
                     const double att[3])
{
    if (c->has_floor) {
        const double df = rch_cell_floor_mm(c, flange), da = rch_cell_floor_mm(c, att);
        if (df < 0.0)
            return set(out, RCH_CELL_BELOW_FLOOR, -1, df);
        if (da < 0.0)
            return set(out, RCH_CELL_BELOW_FLOOR, -1, da);
        for (unsigned k = 0; k < c->n_links; ++k) {
            double a[3], b[3];
            if (c->link[k].frame == 0)
                continue; /* the base stands on the floor */
            rch_cell_link_base(a, b, c, k, fr);
            const double fa = rch_cell_floor_mm(c, a), fb = rch_cell_floor_mm(c, b);
            const double lo = (fa < fb ? fa : fb) - c->link[k].radius_mm;
            if (lo < 0.0)
                return set(out, RCH_CELL_BELOW_FLOOR, (int)k, lo);
        }
    }
    for (unsigned k = 0; k < c->n_links; ++k) {
        double a[3], b[3];
        if (c->link[k].frame == 0)
            continue;
        rch_cell_link_base(a, b, c, k, fr);
        for (unsigned j = 0; j < c->n_boxes; ++j) {
            const double dist = rch_cell_seg_box_mm(a, b, &c->box[j]) - c->link[k].radius_mm;
            if (dist < 0.0)
                return set(out, RCH_CELL_LINK_BOX, (int)j, dist);
        }
    }
    return 0;
}

static int check_cable(rch_cell_verdict *out, const rch_cell *c, const double fr[7][12], const double outlet[3],
                       const double att[3], double clr)
{
    for (unsigned k = 0; k < c->n_links; ++k) {
        double a[3], b[3];
        if (c->link[k].frame == 6)
            continue; /* the cable is hooked on it */
        rch_cell_link_base(a, b, c, k, fr);
        const double dist = rch_cell_seg_seg_mm(outlet, att, a, b) - c->link[k].radius_mm;
        if (dist < clr)
            return set(out, RCH_CELL_CABLE_LINK, (int)k, dist);
    }
    for (unsigned j = 0; j < c->n_boxes; ++j) {
        const double dist = rch_cell_seg_box_mm(outlet, att, &c->box[j]);
        if (dist < clr)
            return set(out, RCH_CELL_CABLE_BOX, (int)j, dist);
    }
    if (c->has_floor) {
        const double da = rch_cell_floor_mm(c, att), dout = rch_cell_floor_mm(c, outlet);
        if (dout < 0.0)
            return set(out, RCH_CELL_CABLE_FLOOR, -1, dout);
        if (da < clr)
            return set(out, RCH_CELL_CABLE_FLOOR, -1, da);
    }
    return 0;
}

void rch_cell_check(rch_cell_verdict *out, const rch_cell *c, const rc_model *m, const double q_rad[RC_NJ],
                    const double outlet_mm[3], const double attach_flange_mm[3], double clearance_mm)
{
    double fr[7][12], flange[3], att[3];
    set(out, RCH_CELL_SAFE, -1, 0.0);
    if (!rch_cell_any(c))
        return;
    rch_cell_frames(fr, m, q_rad);
    to_base(flange, fr[6], (const double[3]){0.0, 0.0, 0.0});
    to_base(att, fr[6], attach_flange_mm);
    if (check_arm(out, c, (const double(*)[12])fr, flange, att))
        return;
    check_cable(out, c, (const double(*)[12])fr, outlet_mm, att, clearance_mm);
}

int rch_cell_row_refused(char *why, size_t size, const rch_cell *c, const rc_model *m, const rc_sample *s,
                         unsigned outlet)
{
    double att[3] = {0.0, 0.0, 0.0};
    const double *out = &m->x[RC_P_ENC];
    rch_cell_verdict v;
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        if (ef->kind == RC_EFF_OUTLET && outlet > 0 && ef->joint == outlet)
            out = &m->x[ef->first];
        else if (ef->kind == RC_EFF_TOOL_OFFSET)
            memcpy(att, &m->x[ef->first], sizeof att);
    }
    for (unsigned e = 0; e < m->n_effects; ++e) /* a plate's point before the tool point */
        if (m->effects[e].kind == RC_EFF_CABLE_POINTS && 3u * s->target + 3u <= m->effects[e].count)
            memcpy(att, &m->x[m->effects[e].first + 3u * s->target], sizeof att);
    rch_cell_check(&v, c, m, s->q_rad, out, att, 0.0);
    if (v.reason == RCH_CELL_SAFE)
        return 0;
    const char *what = v.reason == RCH_CELL_CABLE_FLOOR || (v.reason == RCH_CELL_BELOW_FLOOR && v.which < 0)
                           ? "the floor"
                           : v.reason == RCH_CELL_CABLE_BOX || v.reason == RCH_CELL_LINK_BOX ? "box" : "link";
    const char *nm = v.which < 0 ? ""
                     : (v.reason == RCH_CELL_CABLE_BOX || v.reason == RCH_CELL_LINK_BOX) ? c->box[v.which].name
                                                                                          : c->link[v.which].name;
    snprintf(why, size, "%s: %.2f mm %s %s%s%s%s", rch_cell_reason_name(v.reason), fabs(v.dist_mm),
             v.dist_mm < 0.0 ? "inside" : "from", what, v.which < 0 ? "" : " (", nm, v.which < 0 ? "" : ")");
    return 1;
}
