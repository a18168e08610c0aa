/* SPDX-License-Identifier: MIT */
/* rch_report_chart.c - the report's charts: horizontal rows, bars from zero
 * or dots with 95 % intervals (arrows where an interval leaves the axis),
 * a legend and reference lines; every element through the one SVG writer
 * (files/rch_svg). The colours, one meaning each, named in every legend.
 * Depends on: rch_svg. Memory: none. Errors: none (a value that is not
 * finite is drawn as its row's "missing" text). See rch_report_int.h. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rch_seen.h"

#include "rch_report_int.h"
#include "rch_svg.h"

/* Okabe-Ito */
const char *const rch_rep_colour[C_N] = {"#999999", "#0072B2", "#0072B2", "#E69F00", "#D55E00", "#555555",
                                         "#000000", "#009E73", "#E69F00", "#999999", "#CC79A7"};

unsigned char rch_rep_class_colour(const char *cls)
{
    switch (rch_seen_parse(cls)) { /* the one vocabulary (rch_seen.h); older files' words below */
    case RCH_SEEN_DATA: return C_IDENT;
    case RCH_SEEN_PARTLY: return C_WEAK;
    case RCH_SEEN_PRIOR:
    case RCH_SEEN_UNSEEN: return C_NOTID;
    case RCH_SEEN_HELD: return C_FIXED;
    default: break;
    }
    if (strcmp(cls, "identifiable") == 0 || strcmp(cls, "determined") == 0)
        return C_IDENT;
    if (strcmp(cls, "weak") == 0 || strcmp(cls, "partly") == 0)
        return C_WEAK;
    if (strcmp(cls, "not identifiable") == 0 || strcmp(cls, "prior only") == 0)
        return C_NOTID;
    if (strcmp(cls, "fixed") == 0)
        return C_FIXED;
    return C_UNKNOWN;
}

static void chart_range(const chart *c, double *lo, double *hi)
{
    double a = 0.0, b = 0.0;
    const size_t n = c->n_rows * c->n_sub;
    for (size_t i = 0; i < n; ++i) {
        const double xs[3] = {c->v[i], c->lo ? c->lo[i] : NAN, c->hi ? c->hi[i] : NAN};
        for (int k = 0; k < 3; ++k)
            if (isfinite(xs[k])) {
                a = xs[k] < a ? xs[k] : a;
                b = xs[k] > b ? xs[k] : b;
            }
    }
    for (size_t k = 0; k < c->n_ref; ++k)
        if (isfinite(c->ref[k])) {
            a = c->ref[k] < a ? c->ref[k] : a;
            b = c->ref[k] > b ? c->ref[k] : b;
        }
    if (c->clip > 0.0) {
        a = a < -c->clip ? -c->clip : a;
        b = b > c->clip ? c->clip : b;
    }
    if (!(b - a > 0.0)) {
        a = c->bars ? 0.0 : -1.0;
        b = 1.0;
    }
    if (!c->bars && a < 0.0 && b > 0.0) { /* dots around zero: symmetric axis */
        const double m = -a > b ? -a : b;
        a = -m;
        b = m;
    }
    const double step = rch_svg_nice_step(b - a, 6.0);
    *lo = floor(a / step + 1e-9) * step;
    *hi = ceil(b / step - 1e-9) * step;
}

static double clampd(double x, double a, double b) { return x < a ? a : x > b ? b : x; }

static void chart_axes(FILE *f, const chart *c, double L, double T, double pw, double ph, double lo, double hi)
{
    static const rch_svg_paint zero = {.stroke = "#333"}, grid = {.stroke = "#e4e4e4"},
                               ref = {.stroke = "#444", .dash = "4 3"}, frame = {.stroke = "#999"};
    static const rch_svg_font tick = {.anchor = RCH_SVG_MIDDLE, .fill = "#333"}, axis = {.anchor = RCH_SVG_MIDDLE};
    const double step = rch_svg_nice_step(hi - lo, 6.0);
#define CX(x) (L + ((x) - lo) / (hi - lo) * pw)
    for (int i = 0; i <= 40; ++i) {
        double t = lo + step * i;
        if (t > hi + 1e-9 * step)
            break;
        if (fabs(t) < 1e-9 * step)
            t = 0.0;
        rch_svg_line(f, CX(t), T, CX(t), T + ph, t == 0.0 ? &zero : &grid);
        rch_svg_textf(f, CX(t), T + ph + 14.0, &tick, "%.6g", t);
    }
    for (size_t k = 0; k < c->n_ref; ++k) {
        if (!isfinite(c->ref[k]))
            continue;
        const double x = CX(clampd(c->ref[k], lo, hi));
        const rch_svg_font rf = {.anchor = k ? RCH_SVG_START : RCH_SVG_END, .size_px = 11, .fill = "#333"};
        rch_svg_line(f, x, T - 4.0, x, T + ph, &ref);
        rch_svg_text(f, x, T - 7.0, &rf, c->ref_label[k]);
    }
    rch_svg_rect(f, L, T, pw, ph, &frame, NULL);
    rch_svg_text(f, L + pw / 2.0, T + ph + 32.0, &axis, c->xlabel);
#undef CX
}

static void chart_cell(FILE *f, const chart *c, size_t i, double y, double L, double pw, double lo, double hi)
{
#define CX(x) (L + ((x) - lo) / (hi - lo) * pw)
    const double v = c->v[i];
    const double a = c->lo ? c->lo[i] : NAN, b = c->hi ? c->hi[i] : NAN;
    const char *col = rch_rep_colour[c->col[i]];
    if (!isfinite(v)) {
        static const rch_svg_font mf = {.size_px = 11, .italic = 1, .fill = "#777"};
        rch_svg_text(f, CX(clampd(0.0, lo, hi)) + 4.0, y + 4.0, &mf,
                     c->missing ? c->missing[i / c->n_sub] : "not in this run");
        return;
    }
    char tip[320];
    int n = snprintf(tip, sizeof tip, "%s: %.6g", c->label[i / c->n_sub], v);
    if (n >= 0 && (size_t)n < sizeof tip && isfinite(a) && isfinite(b))
        snprintf(tip + n, sizeof tip - (size_t)n, " (95 %% interval %.6g to %.6g)", a, b);
    rch_svg_group(f, NULL, NULL, tip);
    const rch_svg_paint fill = {.fill = col}, stroke = {.stroke = col, .stroke_px = 1.6};
    if (c->bars) {
        const double x0 = CX(clampd(0.0, lo, hi)), x1 = CX(clampd(v, lo, hi));
        const rch_svg_font vf = {.size_px = 11, .anchor = v < 0 ? RCH_SVG_END : RCH_SVG_START};
        rch_svg_rect(f, x0 < x1 ? x0 : x1, y - 6.0, fabs(x1 - x0) > 0.5 ? fabs(x1 - x0) : 0.5, 12.0, &fill, NULL);
        rch_svg_textf(f, x1 + (v < 0 ? -3.0 : 3.0), y + 4.0, &vf, "%.4g", v);
    }
    if (isfinite(a) && isfinite(b)) {
        const double xa = CX(clampd(a, lo, hi)), xb = CX(clampd(b, lo, hi));
        rch_svg_pen pn;
        rch_svg_path_begin(&pn, f, &stroke); /* the interval and its end ticks */
        rch_svg_path_move(&pn, xa, y);
        rch_svg_path_line(&pn, xb, y);
        rch_svg_path_move(&pn, xa, y - 4.0);
        rch_svg_path_line(&pn, xa, y + 4.0);
        rch_svg_path_move(&pn, xb, y - 4.0);
        rch_svg_path_line(&pn, xb, y + 4.0);
        rch_svg_path_end(&pn);
        if (a < lo) { /* arrows: the interval goes on beyond the axis */
            const double t[6] = {xa - 1.0, y, xa + 6.0, y - 5.0, xa + 6.0, y + 5.0};
            rch_svg_polygon(f, t, 3, &fill);
        }
        if (b > hi) {
            const double t[6] = {xb + 1.0, y, xb - 6.0, y - 5.0, xb - 6.0, y + 5.0};
            rch_svg_polygon(f, t, 3, &fill);
        }
    }
    if (!c->bars)
        rch_svg_circle(f, CX(clampd(v, lo, hi)), y, 4.0, &fill);
    rch_svg_group_end(f);
#undef CX
}

void rch_rep_chart_svg(rep *r, const chart *c)
{
    FILE *f = r->f;
    size_t maxl = 8, legw = 0;
    for (size_t i = 0; i < c->n_rows; ++i)
        maxl = strlen(c->label[i]) > maxl ? strlen(c->label[i]) : maxl;
    if (maxl > 30)
        maxl = 30;
    const double W = c->width_px, L = 14.0 + 7.2 * (double)maxl, R = 28.0; /* 0.6 em a character: long labels stay on the page */
    const double T = 30.0 + (c->n_leg ? 20.0 : 0.0) + (c->n_ref ? 16.0 : 0.0);
    const double sub_h = 16.0, row_h = sub_h * (double)c->n_sub + 6.0;
    const double pw = W - L - R, ph = row_h * (double)c->n_rows, H = T + ph + 44.0;
    static const rch_svg_font tf = {.size_px = 14, .bold = 1}, lf = {.size_px = 11.5},
                              rf = {.anchor = RCH_SVG_END};
    static const rch_svg_paint band = {.fill = "#f3f5f8"};
    double lo, hi;
    chart_range(c, &lo, &hi);
    const rch_svg_doc doc = {.width_px = W, .height_px = H, .cls = "chart", .title = c->title, .in_html = 1,
                             .font_family = "system-ui, Helvetica, Arial, sans-serif"};
    rch_svg_begin(f, &doc);
    rch_svg_text(f, L, 18.0, &tf, c->title);
    for (size_t k = 0; k < c->n_leg; ++k) {
        const double x = L + (double)legw;
        const rch_svg_paint sw = {.fill = rch_rep_colour[c->leg[k]]};
        rch_svg_rect(f, x, 33.0, 11.0, 11.0, &sw, NULL);
        rch_svg_text(f, x + 15.0, 43.0, &lf, c->leg_label[k]);
        legw += 30 + (size_t)(6.3 * (double)strlen(c->leg_label[k]));
    }
    for (size_t i = 0; i < c->n_rows; ++i) {
        const double y0 = T + row_h * (double)i;
        if (i % 2)
            rch_svg_rect(f, L, y0, pw, row_h, &band, NULL);
        rch_svg_text(f, L - 6.0, y0 + row_h / 2.0 + 4.0, &rf, c->label[i]);
    }
    chart_axes(f, c, L, T, pw, ph, lo, hi);
    for (size_t i = 0; i < c->n_rows; ++i)
        for (size_t k = 0; k < c->n_sub; ++k)
            chart_cell(f, c, i * c->n_sub + k, T + row_h * (double)i + 3.0 + sub_h * ((double)k + 0.5), L, pw, lo,
                       hi);
    rch_svg_end(f);
    r->res->n_plots++;
}
