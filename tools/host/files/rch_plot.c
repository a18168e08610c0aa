/* SPDX-License-Identifier: MIT */
/* rch_plot.c - a small SVG chart writer; see rch_plot.h. */
#include "rch_plot.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rch_svg.h"
#include "rch_text.h"

enum { PLOT_LINE = 0, PLOT_SCATTER = 1 };

typedef struct plot_series {
    int kind;
    char *label;
    double *x; /* (n) */
    double *y; /* (n) */
    size_t n;
} plot_series;

struct rch_plot {
    char *title;
    char *xlabel;
    char *ylabel;
    plot_series *series; /* (n_series) */
    size_t n_series;
    size_t cap_series;
    char *subtitle;
    char **bar_labels; /* (n_bars) */
    double *bar_val;   /* (n_bars) */
    double *bar_err;   /* (n_bars) or NULL */
    size_t n_bars;
    unsigned *bar_cat;    /* (n_bars) category of each bar, or NULL: one colour */
    char *cat_names[4];   /* (n_cat) */
    size_t n_cat;
    int logy;
    int failed;
    unsigned width, height;
    double xlo, xhi, ylo, yhi; /* forced ranges when lo < hi */
};

/* Okabe-Ito palette (colour-blind safe), then a few more distinct colours. */
static const char *const plot_colours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                           "#E69F00", "#56B4E9", "#000000", "#F0E442",
                                           "#7F3C8D", "#8C564B", "#17BECF", "#BCBD22"};
#define PLOT_NCOL (sizeof plot_colours / sizeof plot_colours[0])
/* Bars: one colour, or one per category (lighter than the line colours so
 * reference lines over bars stay visible). */
static const char *const bar_colours[4] = {"#56B4E9", "#E69F00", "#CC79A7", "#F0E442"};

static char *plot_strdup(const char *s)
{
    size_t n;
    char *r;
    if (!s)
        s = "";
    n = strlen(s);
    r = malloc(n + 1);
    if (r)
        memcpy(r, s, n + 1);
    return r;
}

static double *plot_dupd(const double *v, size_t n)
{
    double *r;
    if (n == 0)
        return malloc(sizeof(double)); /* non-NULL marker */
    r = malloc(n * sizeof(double));
    if (r && v)
        memcpy(r, v, n * sizeof(double));
    return r;
}

rch_plot *rch_plot_new(const char *title, const char *xlabel, const char *ylabel)
{
    rch_plot *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->title = plot_strdup(title);
    p->xlabel = plot_strdup(xlabel);
    p->ylabel = plot_strdup(ylabel);
    p->width = 800;
    p->height = 500;
    if (!p->title || !p->xlabel || !p->ylabel) {
        rch_plot_free(p);
        return NULL;
    }
    return p;
}

static void plot_add(rch_plot *p, int kind, const char *label, const double *x, const double *y,
                     size_t n)
{
    plot_series *s;
    if (!p)
        return;
    if ((n > 0 && (!x || !y))) {
        p->failed = 1;
        return;
    }
    if (p->n_series == p->cap_series) {
        size_t cap = p->cap_series ? 2 * p->cap_series : 8;
        plot_series *ns = realloc(p->series, cap * sizeof *ns);
        if (!ns) {
            p->failed = 1;
            return;
        }
        p->series = ns;
        p->cap_series = cap;
    }
    s = &p->series[p->n_series];
    s->kind = kind;
    s->label = plot_strdup(label);
    s->x = plot_dupd(x, n);
    s->y = plot_dupd(y, n);
    s->n = n;
    if (!s->label || !s->x || !s->y) {
        free(s->label);
        free(s->x);
        free(s->y);
        p->failed = 1;
        return;
    }
    p->n_series++;
}

void rch_plot_line(rch_plot *p, const char *label, const double *x, const double *y, size_t n)
{
    plot_add(p, PLOT_LINE, label, x, y, n);
}

void rch_plot_scatter(rch_plot *p, const char *label, const double *x, const double *y, size_t n)
{
    plot_add(p, PLOT_SCATTER, label, x, y, n);
}

static void plot_free_bars(rch_plot *p)
{
    size_t i;
    if (p->bar_labels)
        for (i = 0; i < p->n_bars; i++)
            free(p->bar_labels[i]);
    free(p->bar_labels);
    free(p->bar_val);
    free(p->bar_err);
    free(p->bar_cat);
    for (i = 0; i < p->n_cat; i++)
        free(p->cat_names[i]);
    p->bar_labels = NULL;
    p->bar_val = NULL;
    p->bar_err = NULL;
    p->bar_cat = NULL;
    p->n_cat = 0;
    p->n_bars = 0;
}

void rch_plot_bars(rch_plot *p, const char *const *labels, const double *values,
                   const double *errs, size_t n)
{
    size_t i;
    if (!p)
        return;
    plot_free_bars(p);
    if (n == 0)
        return;
    if (!values) {
        p->failed = 1;
        return;
    }
    p->bar_labels = calloc(n, sizeof(char *));
    p->bar_val = plot_dupd(values, n);
    p->bar_err = errs ? plot_dupd(errs, n) : NULL;
    if (!p->bar_labels || !p->bar_val || (errs && !p->bar_err)) {
        plot_free_bars(p); /* n_bars is still 0: frees the arrays only */
        p->failed = 1;
        return;
    }
    p->n_bars = n;
    for (i = 0; i < n; i++) {
        p->bar_labels[i] = plot_strdup(labels ? labels[i] : "");
        if (!p->bar_labels[i])
            p->failed = 1;
    }
}

void rch_plot_bar_categories(rch_plot *p, const unsigned *cat, const char *const *names, size_t n_cat)
{
    size_t i;
    if (!p || p->n_bars == 0)
        return;
    if (!cat || !names || n_cat == 0 || n_cat > 4 || p->bar_cat) {
        p->failed = 1;
        return;
    }
    p->bar_cat = malloc(p->n_bars * sizeof *p->bar_cat);
    if (!p->bar_cat) {
        p->failed = 1;
        return;
    }
    for (i = 0; i < p->n_bars; i++)
        p->bar_cat[i] = cat[i] < n_cat ? cat[i] : 0;
    for (i = 0; i < n_cat; i++) {
        p->cat_names[i] = plot_strdup(names[i]);
        if (!p->cat_names[i])
            p->failed = 1;
        p->n_cat = i + 1;
    }
}

void rch_plot_subtitle(rch_plot *p, const char *subtitle)
{
    if (!p)
        return;
    free(p->subtitle);
    p->subtitle = plot_strdup(subtitle);
    if (!p->subtitle)
        p->failed = 1;
}

void rch_plot_logy(rch_plot *p, int on)
{
    if (p)
        p->logy = on != 0;
}

void rch_plot_size(rch_plot *p, unsigned width_px, unsigned height_px)
{
    if (!p)
        return;
    p->width = width_px < 200 ? 200 : width_px;
    p->height = height_px < 150 ? 150 : height_px;
}

void rch_plot_xrange(rch_plot *p, double lo, double hi)
{
    if (p) {
        p->xlo = lo;
        p->xhi = hi;
    }
}

void rch_plot_yrange(rch_plot *p, double lo, double hi)
{
    if (p) {
        p->ylo = lo;
        p->yhi = hi;
    }
}

void rch_plot_free(rch_plot *p)
{
    size_t i;
    if (!p)
        return;
    for (i = 0; i < p->n_series; i++) {
        free(p->series[i].label);
        free(p->series[i].x);
        free(p->series[i].y);
    }
    free(p->series);
    plot_free_bars(p);
    free(p->title);
    free(p->subtitle);
    free(p->xlabel);
    free(p->ylabel);
    free(p);
}

/* ---- writing ---------------------------------------------------------- */

typedef struct plot_axis {
    double lo, hi; /* data range (in transformed units for log) */
    int log;
} plot_axis;

static double plot_tr(const plot_axis *a, double v)
{
    return a->log ? log10(v) : v;
}

static int plot_ok(const plot_axis *ay, double y)
{
    return isfinite(y) && (!ay->log || y > 0.0);
}

/* Compute ranges from data; returns 0 when there is nothing to draw. */
static void plot_ranges(const rch_plot *p, plot_axis *ax, plot_axis *ay)
{
    double xlo = HUGE_VAL, xhi = -HUGE_VAL, ylo = HUGE_VAL, yhi = -HUGE_VAL;
    size_t i, k;
    ax->log = 0;
    ay->log = p->logy;
    for (i = 0; i < p->n_series; i++) {
        const plot_series *s = &p->series[i];
        for (k = 0; k < s->n; k++) {
            if (!isfinite(s->x[k]) || !plot_ok(ay, s->y[k]))
                continue;
            if (s->x[k] < xlo) xlo = s->x[k];
            if (s->x[k] > xhi) xhi = s->x[k];
            if (s->y[k] < ylo) ylo = s->y[k];
            if (s->y[k] > yhi) yhi = s->y[k];
        }
    }
    if (p->n_bars > 0) {
        if (-0.5 < xlo) xlo = -0.5;
        if ((double)p->n_bars - 0.5 > xhi) xhi = (double)p->n_bars - 0.5;
        for (k = 0; k < p->n_bars; k++) {
            double v = p->bar_val[k], e = p->bar_err ? fabs(p->bar_err[k]) : 0.0;
            if (!isfinite(e))
                e = 0.0;
            if (!plot_ok(ay, v))
                continue;
            if (v + e > yhi) yhi = v + e;
            if (v < ylo) ylo = v;
            if (!ay->log && 0.0 < ylo) ylo = 0.0; /* bars start at zero */
        }
    }
    if (p->xlo < p->xhi) {
        xlo = p->xlo;
        xhi = p->xhi;
    }
    if (p->ylo < p->yhi && (!ay->log || p->ylo > 0.0)) {
        ylo = p->ylo;
        yhi = p->yhi;
    }
    if (!(xlo <= xhi)) {
        xlo = 0.0;
        xhi = 1.0;
    }
    if (!(ylo <= yhi)) {
        ylo = ay->log ? 1.0 : 0.0;
        yhi = ay->log ? 10.0 : 1.0;
    }
    if (ay->log) {
        ylo = log10(ylo);
        yhi = log10(yhi);
    }
    if (xhi - xlo <= 0.0) {
        double d = fabs(xlo) > 0.0 ? 0.1 * fabs(xlo) : 1.0;
        xlo -= d;
        xhi += d;
    }
    if (yhi - ylo <= 0.0) {
        double d = ay->log ? 0.5 : (fabs(ylo) > 0.0 ? 0.1 * fabs(ylo) : 1.0);
        ylo -= d;
        yhi += d;
    }
    if (!(p->ylo < p->yhi)) { /* headroom: 4 % (bars keep their zero base) */
        double pad = 0.04 * (yhi - ylo);
        if (!(p->n_bars > 0 && !ay->log && ylo == 0.0))
            ylo -= pad;
        yhi += pad;
    }
    ax->lo = xlo;
    ax->hi = xhi;
    ay->lo = ylo;
    ay->hi = yhi;
}

static void plot_marker(FILE *f, int shape, double x, double y, const char *col)
{
    const rch_svg_paint pt = {.fill = col};
    switch (shape % 4) {
    case 0:
        rch_svg_circle(f, x, y, 3.0, &pt);
        break;
    case 1:
        rch_svg_rect(f, x - 3.0, y - 3.0, 6.0, 6.0, &pt, NULL);
        break;
    case 2: {
        const double tri[6] = {x, y - 4, x + 4, y + 3, x - 4, y + 3};
        rch_svg_polygon(f, tri, 3, &pt);
        break;
    }
    default: {
        const double dia[8] = {x, y - 4, x + 4, y, x, y + 4, x - 4, y};
        rch_svg_polygon(f, dia, 4, &pt);
    }
    }
}

static void plot_fmt(char *buf, size_t len, double v, double step)
{
    if (fabs(v) < 1e-12 * (step > 0 ? step : 1.0))
        v = 0.0;
    snprintf(buf, len, "%g", v);
}

/* One y tick at pixel row py: grid line across the plot (left L, width pw),
 * tick mark, label. */
static void plot_ytick(FILE *f, double L, double pw, double py, const char *label)
{
    static const rch_svg_paint grid = {.stroke = "#e0e0e0"}, tick = {.stroke = "black"};
    static const rch_svg_font ft = {.anchor = RCH_SVG_END};
    rch_svg_line(f, L, py, L + pw, py, &grid);
    rch_svg_line(f, L - 5, py, L, py, &tick);
    rch_svg_text(f, L - 8, py + 4, &ft, label);
}

/* Page layout of one chart: axes, margins (left L, right R, top T, bottom
 * B), plot area pw x ph, pixels per unit, legend size. */
typedef struct plot_frame {
    plot_axis ax, ay;
    double W, H, L, R, T, B, pw, ph, legw, xs, ys;
    size_t nleg;
    int rot_labels; /* bar labels at -45 deg (too long for their slot) */
} plot_frame;

static double plot_px(const plot_frame *fr, double v) { return fr->L + (v - fr->ax.lo) * fr->xs; }
static double plot_py(const plot_frame *fr, double v) { return fr->T + fr->ph - (v - fr->ay.lo) * fr->ys; }

static void plot_layout(plot_frame *fr, const rch_plot *p)
{
    size_t maxlab = 0;
    fr->L = 75.0;
    fr->R = 20.0;
    fr->T = 45.0;
    fr->B = 60.0;
    fr->legw = 0.0;
    fr->nleg = 0;
    fr->rot_labels = 0;
    fr->W = (double)p->width;
    fr->H = (double)p->height;
    if (p->subtitle && p->subtitle[0])
        fr->T += 16.0;
    plot_ranges(p, &fr->ax, &fr->ay);
    /* legend: one entry per labelled series */
    for (size_t i = 0; i < p->n_series; i++) {
        size_t l = strlen(p->series[i].label);
        if (l > 0) {
            fr->nleg++;
            if (l > maxlab)
                maxlab = l;
        }
    }
    for (size_t i = 0; i < p->n_cat; i++) {
        size_t l = strlen(p->cat_names[i]);
        fr->nleg++;
        if (l > maxlab)
            maxlab = l;
    }
    if (fr->nleg > 0) {
        fr->legw = 40.0 + 7.2 * (double)(maxlab > 48 ? 48 : maxlab);
        fr->R += fr->legw + 10.0;
    }
    if (p->n_bars > 0) {
        size_t ml = 0;
        for (size_t k = 0; k < p->n_bars; k++)
            if (strlen(p->bar_labels[k]) > ml)
                ml = strlen(p->bar_labels[k]);
        if ((double)ml * 7.0 > (fr->W - fr->L - fr->R) / (double)p->n_bars) {
            fr->rot_labels = 1;
            fr->B += 5.0 * (double)(ml > 20 ? 20 : ml);
        }
    }
    if (fr->H - fr->T - fr->B < 60.0)
        fr->B = fr->H - fr->T - 60.0;
    fr->pw = fr->W - fr->L - fr->R;
    fr->ph = fr->H - fr->T - fr->B;
    if (fr->pw < 50.0)
        fr->pw = 50.0;
    fr->xs = fr->pw / (fr->ax.hi - fr->ax.lo);
    fr->ys = fr->ph / (fr->ay.hi - fr->ay.lo);
}

/* y ticks and grid: linear, log by decades, or log over less than a decade. */
static void plot_yticks(FILE *f, const plot_frame *fr)
{
    const plot_axis *ay = &fr->ay;
    double y0, step;
    int guard = 0;
    char buf[64];
    if (ay->log && ay->hi - ay->lo < 0.7) {
        /* less than a decade: linear 1-2-5 ticks placed on the log axis */
        const double vlo = pow(10.0, ay->lo), vhi = pow(10.0, ay->hi);
        step = rch_svg_nice_step(vhi - vlo, 5.0);
        for (y0 = ceil(vlo / step - 1e-9) * step; y0 <= vhi + 1e-9 * step && guard < 100; y0 += step, guard++) {
            if (y0 <= 0.0)
                continue;
            plot_fmt(buf, sizeof buf, y0, step);
            plot_ytick(f, fr->L, fr->pw, plot_py(fr, log10(y0)), buf);
        }
    } else if (ay->log) {
        double span = ay->hi - ay->lo;
        int d0 = (int)floor(ay->lo), d1 = (int)ceil(ay->hi), d;
        static const double sub3[3] = {1.0, 2.0, 5.0};
        static const double sub9[9] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0};
        const double *sub = span < 1.2 ? sub9 : sub3;
        int nsub = span < 1.2 ? 9 : (span < 2.5 ? 3 : 1);
        int every = span > 12 ? (int)ceil(span / 8.0) : 1;
        for (d = d0; d <= d1 && guard < 400; d++, guard++) {
            if ((d - d0) % every != 0)
                continue;
            for (int s = 0; s < nsub; s++) {
                double v = pow(10.0, (double)d) * sub[s], tv = log10(v);
                if (tv < ay->lo - 1e-9 || tv > ay->hi + 1e-9)
                    continue;
                snprintf(buf, sizeof buf, "%g", v);
                plot_ytick(f, fr->L, fr->pw, plot_py(fr, tv), buf);
            }
        }
    } else {
        step = rch_svg_nice_step(ay->hi - ay->lo, 6.0);
        for (y0 = ceil(ay->lo / step - 1e-9) * step; y0 <= ay->hi + 1e-9 * step && guard < 100;
             y0 += step, guard++) {
            plot_fmt(buf, sizeof buf, y0, step);
            plot_ytick(f, fr->L, fr->pw, plot_py(fr, y0), buf);
        }
    }
}

/* x ticks and grid (numeric x axis). */
static void plot_xticks(FILE *f, const plot_frame *fr)
{
    const double step = rch_svg_nice_step(fr->ax.hi - fr->ax.lo, 8.0), T = fr->T, ph = fr->ph;
    int guard = 0;
    char buf[64];
    for (double x0 = ceil(fr->ax.lo / step - 1e-9) * step; x0 <= fr->ax.hi + 1e-9 * step && guard < 100;
         x0 += step, guard++) {
        static const rch_svg_paint grid = {.stroke = "#e0e0e0"}, tick = {.stroke = "black"};
        static const rch_svg_font ft = {.anchor = RCH_SVG_MIDDLE};
        const double px = plot_px(fr, x0);
        rch_svg_line(f, px, T, px, T + ph, &grid);
        rch_svg_line(f, px, T + ph, px, T + ph + 5, &tick);
        plot_fmt(buf, sizeof buf, x0, step);
        rch_svg_text(f, px, T + ph + 18, &ft, buf);
    }
}

/* Bar k (value, error bar, value label) when its value can be drawn, and its category label. */
static void plot_bar(FILE *f, const rch_plot *p, const plot_frame *fr, size_t k)
{
    const plot_axis *ay = &fr->ay;
    const double bw = 0.6 * fr->xs, v = p->bar_val[k], cx = plot_px(fr, (double)k);
    const double base = ay->log ? ay->lo : (ay->lo > 0.0 ? ay->lo : (ay->hi < 0.0 ? ay->hi : 0.0));
    const rch_svg_paint bar = {.fill = bar_colours[p->bar_cat ? p->bar_cat[k] : 0], .fill_opacity = 0.85};
    if (plot_ok(ay, v)) {
        double tv = plot_tr(ay, v), top, bot;
        char tip[256];
        if (tv > ay->hi) tv = ay->hi;
        if (tv < ay->lo) tv = ay->lo;
        top = plot_py(fr, tv > base ? tv : base);
        bot = plot_py(fr, tv > base ? base : tv);
        snprintf(tip, sizeof tip, "%s: %g", p->bar_labels[k], v);
        rch_svg_rect(f, cx - bw / 2.0, top, bw, bot - top, &bar, tip);
        if (p->bar_err && isfinite(p->bar_err[k]) && p->bar_err[k] != 0.0) {
            static const rch_svg_paint ebar = {.stroke = "black", .stroke_px = 1.2};
            double e = fabs(p->bar_err[k]), hi = v + e, lo = v - e, yh, yl;
            rch_svg_pen pn;
            yh = plot_tr(ay, hi);
            yl = (ay->log && lo <= 0.0) ? ay->lo : plot_tr(ay, lo);
            if (yh > ay->hi) yh = ay->hi;
            if (yl < ay->lo) yl = ay->lo;
            rch_svg_path_begin(&pn, f, &ebar);
            rch_svg_path_move(&pn, cx, plot_py(fr, yl));
            rch_svg_path_line(&pn, cx, plot_py(fr, yh));
            rch_svg_path_move(&pn, cx - bw / 6.0, plot_py(fr, yl));
            rch_svg_path_line(&pn, cx + bw / 6.0, plot_py(fr, yl));
            rch_svg_path_move(&pn, cx - bw / 6.0, plot_py(fr, yh));
            rch_svg_path_line(&pn, cx + bw / 6.0, plot_py(fr, yh));
            rch_svg_path_end(&pn);
        }
        static const rch_svg_font vf = {.anchor = RCH_SVG_MIDDLE, .size_px = 10};
        rch_svg_textf(f, cx + (p->bar_err ? bw / 4.0 : 0.0), top - 3.0, &vf, "%.3g", v);
    }
    if (fr->rot_labels) {
        static const rch_svg_font rf = {.anchor = RCH_SVG_END, .rotate_deg = -45.0};
        rch_svg_text(f, cx, fr->T + fr->ph + 14, &rf, p->bar_labels[k]);
    } else {
        static const rch_svg_font cf = {.anchor = RCH_SVG_MIDDLE};
        rch_svg_text(f, cx, fr->T + fr->ph + 18, &cf, p->bar_labels[k]);
    }
}

/* Every series, clipped to the plot area. */
static void plot_series_all(FILE *f, const rch_plot *p, const plot_frame *fr)
{
    const plot_axis *ay = &fr->ay;
    rch_svg_clip(f, "plotarea", fr->L, fr->T, fr->pw, fr->ph);
    for (size_t i = 0; i < p->n_series; i++) {
        const plot_series *s = &p->series[i];
        const char *col = plot_colours[i % PLOT_NCOL];
        rch_svg_group(f, "series", NULL, NULL);
        if (s->kind == PLOT_LINE && s->n == 1) {
            /* one point: a marker, not an invisible line */
            if (isfinite(s->x[0]) && plot_ok(ay, s->y[0]))
                plot_marker(f, 0, plot_px(fr, s->x[0]), plot_py(fr, plot_tr(ay, s->y[0])), col);
        } else if (s->kind == PLOT_LINE) {
            const rch_svg_paint line = {.stroke = col, .stroke_px = 1.8};
            rch_svg_pen pn;
            int pen = 0;
            rch_svg_path_begin(&pn, f, &line);
            for (size_t k = 0; k < s->n; k++) {
                if (!isfinite(s->x[k]) || !plot_ok(ay, s->y[k])) {
                    pen = 0;
                    continue;
                }
                (pen ? rch_svg_path_line : rch_svg_path_move)(&pn, plot_px(fr, s->x[k]),
                                                               plot_py(fr, plot_tr(ay, s->y[k])));
                pen = 1;
            }
            rch_svg_path_end(&pn);
        } else {
            for (size_t k = 0; k < s->n; k++)
                if (isfinite(s->x[k]) && plot_ok(ay, s->y[k]))
                    plot_marker(f, (int)i, plot_px(fr, s->x[k]), plot_py(fr, plot_tr(ay, s->y[k])), col);
        }
        rch_svg_group_end(f);
    }
    rch_svg_group_end(f);
}

/* Frame, axis labels and the legend. */
static void plot_frame_legend(FILE *f, const rch_plot *p, const plot_frame *fr)
{
    static const rch_svg_paint frame = {.stroke = "black"}, box = {.fill = "white", .stroke = "#999999"};
    static const rch_svg_font mid = {.anchor = RCH_SVG_MIDDLE}, yl = {.anchor = RCH_SVG_MIDDLE, .rotate_deg = -90.0};
    const double L = fr->L, T = fr->T, pw = fr->pw, ph = fr->ph;
    rch_svg_rect(f, L, T, pw, ph, &frame, NULL);
    rch_svg_text(f, L + pw / 2.0, fr->H - 12.0, &mid, p->xlabel);
    rch_svg_text(f, 16.0, T + ph / 2.0, &yl, p->ylabel);
    if (fr->nleg == 0)
        return;
    double lx = L + pw + 10.0, ly = T;
    rch_svg_rect(f, lx, ly, fr->legw, 8.0 + 18.0 * (double)fr->nleg, &box, NULL);
    for (size_t i = 0; i < p->n_series; i++) {
        const plot_series *s = &p->series[i];
        const char *col = plot_colours[i % PLOT_NCOL];
        const double yy = ly + 16.0;
        if (s->label[0] == '\0')
            continue;
        if (s->kind == PLOT_LINE) {
            const rch_svg_paint swatch = {.stroke = col, .stroke_px = 2.5};
            rch_svg_line(f, lx + 6, yy - 4, lx + 26, yy - 4, &swatch);
        } else {
            plot_marker(f, (int)i, lx + 16, yy - 4, col);
        }
        rch_svg_text(f, lx + 30, yy, NULL, s->label);
        ly += 18.0;
    }
    for (size_t c = 0; c < p->n_cat; c++) {
        const rch_svg_paint swatch = {.fill = bar_colours[c], .fill_opacity = 0.85};
        const double yy = ly + 16.0;
        rch_svg_rect(f, lx + 9, yy - 9, 14, 10, &swatch, NULL);
        rch_svg_text(f, lx + 30, yy, NULL, p->cat_names[c]);
        ly += 18.0;
    }
}

int rch_plot_write_svg_stream(const rch_plot *p, FILE *f)
{
    plot_frame fr;
    if (!p || !f || p->failed) {
        errno = EINVAL;
        return -1;
    }
    plot_layout(&fr, p);
    const rch_svg_doc doc = {.width_px = p->width, .height_px = p->height, .title = p->title};
    static const rch_svg_font tf = {.anchor = RCH_SVG_MIDDLE, .size_px = 16, .bold = 1},
                              sf = {.anchor = RCH_SVG_MIDDLE, .size_px = 12, .fill = "#555555"};
    rch_svg_begin(f, &doc);
    rch_svg_text(f, fr.W / 2.0, 24.0, &tf, p->title);
    if (p->subtitle && p->subtitle[0])
        rch_svg_text(f, fr.W / 2.0, 42.0, &sf, p->subtitle);
    plot_yticks(f, &fr);
    if (p->n_bars == 0)
        plot_xticks(f, &fr); /* numeric x axis unless this is a pure bar chart */
    if (p->n_bars > 0)
        rch_svg_group(f, "bars", NULL, NULL);
    for (size_t k = 0; k < p->n_bars; k++)
        plot_bar(f, p, &fr, k);
    if (p->n_bars > 0)
        rch_svg_group_end(f);
    plot_series_all(f, p, &fr);
    plot_frame_legend(f, p, &fr);
    rch_svg_end(f);
    return ferror(f) ? -1 : 0;
}

int rch_plot_write_svg(const rch_plot *p, const char *path)
{
    FILE *f;
    int rc;
    if (!p || !path) {
        errno = EINVAL;
        return -1;
    }
    f = fopen(path, "w");
    if (!f)
        return -1;
    rc = rch_plot_write_svg_stream(p, f);
    if (fclose(f) != 0)
        rc = -1;
    return rc;
}

/* ---- data as CSV -------------------------------------------------------- */

void rch_csv_field(FILE *f, const char *s)
{
    if (!s)
        s = "";
    if (strpbrk(s, ",\"\r\n") == NULL) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

int rch_plot_table_write(FILE *f, const rch_plot_table *t)
{
    const size_t nc = t ? t->n_text + t->n_num : 0;
    if (!f || !t || nc == 0 || !t->head || (t->n_rows > 0 && ((t->n_text > 0 && !t->text) || (t->n_num > 0 && !t->num)))) {
        errno = EINVAL;
        return -1;
    }
    for (size_t c = 0; c < nc; c++) {
        if (c)
            fputc(',', f);
        rch_csv_field(f, t->head[c]);
    }
    fputc('\n', f);
    for (size_t r = 0; r < t->n_rows; r++) {
        for (size_t c = 0; c < t->n_text; c++) {
            if (c)
                fputc(',', f);
            rch_csv_field(f, t->text[r * t->n_text + c]);
        }
        for (size_t c = 0; c < t->n_num; c++) {
            const double v = t->num[r * t->n_num + c];
            if (c || t->n_text)
                fputc(',', f);
            if (isnan(v))
                fputs("nan", f);
            else if (isinf(v))
                fputs(v > 0 ? "inf" : "-inf", f);
            else
                fprintf(f, "%.9g", v);
        }
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}

/* The chart as a table (see rch_plot_write_csv_stream); heap arrays in t
 * and the column names in head (4 + 1 slots, err_head holds the error
 * column's name). 0, or -1 on allocation failure (t freed). */
typedef struct plot_csv {
    rch_plot_table t;
    const char *head[5];
    char err_head[300];
    const char **text;
    double *num;
} plot_csv;

static void plot_csv_free(plot_csv *c)
{
    free(c->text);
    free(c->num);
    c->text = NULL;
    c->num = NULL;
}

static int plot_csv_make(plot_csv *c, const rch_plot *p)
{
    size_t rows = p->n_bars, k = 0, h = 0;
    const int bars = p->n_bars > 0, errs = bars && p->bar_err;
    for (size_t i = 0; i < p->n_series; i++)
        rows += p->series[i].n;
    memset(c, 0, sizeof *c);
    c->head[h++] = "series";
    if (bars)
        c->head[h++] = "category";
    c->head[h++] = p->xlabel[0] ? p->xlabel : "x";
    c->head[h++] = p->ylabel[0] ? p->ylabel : "y";
    if (errs) {
        snprintf(c->err_head, sizeof c->err_head, "+- %s (error bar half-length)", p->ylabel[0] ? p->ylabel : "y");
        c->head[h++] = c->err_head;
    }
    c->t.head = c->head;
    c->t.n_text = bars ? 2 : 1;
    c->t.n_num = errs ? 3 : 2;
    c->t.n_rows = rows;
    c->text = malloc((rows ? rows : 1) * c->t.n_text * sizeof *c->text);
    c->num = malloc((rows ? rows : 1) * c->t.n_num * sizeof *c->num);
    if (!c->text || !c->num) {
        plot_csv_free(c);
        return -1;
    }
    for (size_t b = 0; b < p->n_bars; b++, k++) {
        c->text[k * c->t.n_text] = p->ylabel[0] ? p->ylabel : "bars";
        c->text[k * c->t.n_text + 1] = p->bar_labels[b];
        c->num[k * c->t.n_num] = (double)b;
        c->num[k * c->t.n_num + 1] = p->bar_val[b];
        if (errs)
            c->num[k * c->t.n_num + 2] = p->bar_err[b];
    }
    for (size_t i = 0; i < p->n_series; i++) {
        const plot_series *s = &p->series[i];
        for (size_t j = 0; j < s->n; j++, k++) {
            c->text[k * c->t.n_text] = s->label;
            if (bars)
                c->text[k * c->t.n_text + 1] = "";
            c->num[k * c->t.n_num] = s->x[j];
            c->num[k * c->t.n_num + 1] = s->y[j];
            if (errs)
                c->num[k * c->t.n_num + 2] = NAN;
        }
    }
    c->t.text = c->text;
    c->t.num = c->num;
    return 0;
}

int rch_plot_write_csv_stream(const rch_plot *p, FILE *f)
{
    plot_csv c;
    int rc;
    if (!p || !f || p->failed || plot_csv_make(&c, p) != 0) {
        errno = p && p->failed ? ENOMEM : EINVAL;
        return -1;
    }
    rc = rch_plot_table_write(f, &c.t);
    plot_csv_free(&c);
    return rc;
}

const char *rch_plot_fmt_p(char *out, size_t len, double p)
{
    if (!out || len == 0)
        return out;
    if (!isfinite(p))
        snprintf(out, len, "-");
    else if (p < 1e-300)
        snprintf(out, len, "< 1e-300");
    else
        snprintf(out, len, "%.1e", p);
    return out;
}

int rch_plot_mkdir(const char *dir)
{
    char buf[4096];
    struct stat sb;
    size_t n = dir ? strlen(dir) : 0;
    if (n == 0 || n >= sizeof buf) {
        errno = n ? ENAMETOOLONG : EINVAL;
        return -1;
    }
    memcpy(buf, dir, n + 1);
    for (size_t i = 1; i <= n; ++i) {
        if (buf[i] != '/' && buf[i] != '\0')
            continue;
        const char c = buf[i];
        buf[i] = '\0';
        if (stat(buf, &sb) != 0) {
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
        } else if (!S_ISDIR(sb.st_mode)) {
            errno = ENOTDIR;
            return -1;
        }
        buf[i] = c;
    }
    return 0;
}

int rch_plot_open(rch_out *o, const rch_plot_dir *pd, const char *name, rch_diag *d)
{
    char path[1024];
    if ((size_t)snprintf(path, sizeof path, "%s/%s", pd->dir, name) >= sizeof path) {
        memset(o, 0, sizeof *o);
        rch_diag_set(d, "", 0, 0, "cannot write %s/%s: path too long", pd->dir, name);
        return -1;
    }
    return rch_out_open(o, path, "plot file", pd->inputs, pd->n_inputs, d);
}

int rch_plot_close(rch_out *o, const rch_plot_dir *pd, int failed, rch_diag *d)
{
    if (failed && !ferror(o->f)) { /* the writer failed, not the stream */
        rch_diag_set(d, "", 0, 0, "cannot write %s: out of memory", o->path);
        rch_out_abort(o);
        return -1;
    }
    if (rch_out_commit(o, d) != 0) /* a write error with its reason (a full disk is not memory) */
        return -1;
    if (pd->log)
        fprintf(pd->log, "  wrote %s\n", o->path);
    return 0;
}

/* NAME with .svg (when it ends so) replaced by .csv. 0, or -1 with d set. */
static int plot_csv_name(char *csv, size_t len, const rch_plot_dir *pd, const char *name, rch_diag *d)
{
    if (!name)
        name = "";
    size_t n = strlen(name);
    if (n >= 4 && strcmp(name + n - 4, ".svg") == 0)
        n -= 4;
    if (n + 5 > len || n > 4096) {
        rch_diag_set(d, "", 0, 0, "cannot write %s/%s: name too long", pd->dir, name);
        return -1;
    }
    snprintf(csv, len, "%.*s.csv", (int)n, name);
    return 0;
}

int rch_plot_save_csv(const rch_plot_table *t, const rch_plot_dir *pd, const char *name, rch_diag *d)
{
    char csv[512];
    rch_out o;
    if (plot_csv_name(csv, sizeof csv, pd, name, d) != 0)
        return -1;
    if (!t) {
        rch_diag_set(d, "", 0, 0, "cannot write %s/%s: out of memory", pd->dir, csv);
        return -1;
    }
    if (rch_plot_open(&o, pd, csv, d) != 0)
        return -1;
    return rch_plot_close(&o, pd, rch_plot_table_write(o.f, t) != 0, d);
}

int rch_plot_save(rch_plot *p, const rch_plot_dir *pd, const char *name, rch_diag *d)
{
    rch_out o;
    plot_csv c;
    char csv[512];
    int rc = -1;
    if (!p || p->failed)
        rch_diag_set(d, "", 0, 0, "cannot write %s/%s: out of memory", pd->dir, name);
    else if (plot_csv_name(csv, sizeof csv, pd, name, d) == 0 && rch_plot_open(&o, pd, name, d) == 0) {
        /* both names are checked against the inputs before either file is written */
        rch_out oc;
        if (rch_plot_open(&oc, pd, csv, d) != 0) {
            rch_out_abort(&o);
        } else if (plot_csv_make(&c, p) != 0) {
            rch_out_abort(&o);
            rch_out_abort(&oc);
            rch_diag_set(d, "", 0, 0, "cannot write %s/%s: out of memory", pd->dir, csv);
        } else {
            const int svg_failed = rch_plot_write_svg_stream(p, o.f) != 0, csv_failed = rch_plot_table_write(oc.f, &c.t) != 0;
            plot_csv_free(&c);
            if (rch_plot_close(&o, pd, svg_failed, d) != 0)
                rch_out_abort(&oc);
            else
                rc = rch_plot_close(&oc, pd, csv_failed, d);
        }
    }
    rch_plot_free(p);
    return rc;
}
