/* SPDX-License-Identifier: MIT */
/* rch_report.c - the HTML report of a calibration; see rch_report.h and
 * docs/report.md (which members are read, and from where). */
#include "rch_report.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rc_version.h"
#include "rch_file.h"
#include "rch_text.h"
#include "rch_json.h"
#include "rch_plot.h"
#include "rch_sha256.h"
#include "rch_svg.h"

#define NA "<span class=\"na\">not in this run</span>"
#define Z95 1.959963984540054 /* two-sided 95 % normal quantile */

/* ---- colours: one meaning each, named in every chart's legend (Okabe-Ito) */
enum {
    C_BEFORE,  /* nominal model */
    C_AFTER,   /* calibrated model */
    C_IDENT,   /* parameter classes */
    C_WEAK,
    C_NOTID,
    C_FIXED,
    C_UNKNOWN,
    C_CHOSEN,  /* diagnosis candidates */
    C_SIGNIF,
    C_NOTSIG,
    C_PRED,    /* predicted uncertainty */
    C_N
};
static const char *const colour[C_N] = {"#999999", "#0072B2", "#0072B2", "#E69F00", "#D55E00", "#555555",
                                        "#000000", "#009E73", "#E69F00", "#999999", "#CC79A7"};

typedef struct {
    FILE *f; /* the HTML */
    const rch_json *cal, *diag, *model;
    const rch_json *unc;  /* uncertainty block: calibration's, else the model file's, or NULL */
    const rch_json *prov; /* provenance block: likewise */
    const char *unc_from, *prov_from;
    const rch_report_cfg *cfg;
    rch_report_result *res;
    char warn[RCH_REPORT_MAX_WARN][640];
    unsigned n_warn;
    const char *section, *where, *how; /* what a "not in this run" here stands for, and how to get it */
} rep;

/* How a run gets what the diagnosis, the model file or a truth holds. */
#define HOW_DIAG "a diagnosis: rcal diagnose --data FILE --json > DIAG.json, then rcal report --diagnosis DIAG.json"
#define HOW_MODEL "the run's model file: rcal report --model MODEL.json (rcal calibrate --out MODEL.json)"
#define HOW_TRUTH "a simulated truth: rcal calibrate --truth TRUTH.json (only a simulation has one: rcal simulate --truth-out)"

/* One place that says "not in this run": counted, and what it stands for
 * recorded once (with how to get it) for the command's summary. */
static void missing(rep *r, const char *what, const char *how)
{
    rch_report_result *res = r->res;
    res->n_missing++;
    if (!what)
        what = "a figure";
    if (!how)
        how = "";
    for (unsigned k = 0; k < res->n_missing_items; ++k)
        if (strcmp(res->missing[k].what, what) == 0 && strcmp(res->missing[k].how, how) == 0)
            return;
    if (res->n_missing_items == RCH_REPORT_MAX_MISSING)
        return;
    snprintf(res->missing[res->n_missing_items].what, sizeof res->missing[0].what, "%s", what);
    snprintf(res->missing[res->n_missing_items].how, sizeof res->missing[0].how, "%s", how);
    res->n_missing_items++;
}

/* The section (or page part) the next places are in: a missing value there
 * is named by it unless a row (kv) names it. */
static void section(rep *r, const char *name, const char *how)
{
    r->section = r->where = name;
    r->how = how;
}

/* ---- JSON access by dotted path ("uncertainty.position95_mm.data_max") */

static const rch_json *jpath(const rch_json *o, const char *path)
{
    char key[128];
    while (o && *path) {
        const char *dot = strchr(path, '.');
        const size_t n = dot ? (size_t)(dot - path) : strlen(path);
        if (n >= sizeof key)
            return NULL;
        memcpy(key, path, n);
        key[n] = '\0';
        o = rch_json_get(o, key);
        path += n + (dot ? 1 : 0);
    }
    return o;
}

static double jnum(const rch_json *o, const char *path)
{
    const rch_json *j = jpath(o, path);
    return j && j->type == RCH_JNUM ? j->num : NAN;
}

static const char *jstr(const rch_json *o, const char *path)
{
    const rch_json *j = jpath(o, path);
    return j && j->type == RCH_JSTR ? j->str : NULL;
}

/* 1 true, 0 false, -1 absent */
static int jbool(const rch_json *o, const char *path)
{
    const rch_json *j = jpath(o, path);
    return j && j->type == RCH_JBOOL ? j->num != 0.0 : -1;
}

static const rch_json *jarr(const rch_json *o, const char *path)
{
    const rch_json *j = jpath(o, path);
    return j && j->type == RCH_JARR ? j : NULL;
}

/* ---- escaping */

const char *rch_report_escape(char *buf, size_t len, const char *s) { return rch_xml_escape(buf, len, s, 0); }

static void put_esc(FILE *f, const char *s) { rch_xml_put(f, s, 0); }

/* A JSON string escaped, or "not in this run". */
static void put_str(rep *r, const char *s)
{
    if (s) {
        put_esc(r->f, s);
    } else {
        fputs(NA, r->f);
        missing(r, r->where, r->how);
    }
}

/* A number with printf format fmt, or "not in this run". */
static void put_num(rep *r, double v, const char *fmt)
{
    if (isfinite(v)) {
        fprintf(r->f, fmt, v);
    } else {
        fputs(NA, r->f);
        missing(r, r->where, r->how);
    }
}

/* Three significant digits without an exponent between 1e-3 and 1e6
 * ("1610 mm", not "1.61e+03 mm"), then `unit`; or "not in this run". */
static void put_sig(rep *r, double v, const char *unit)
{
    const double a = fabs(v);
    if (isfinite(v) && a >= 1e-3 && a < 1e6) {
        const int dec = 2 - (int)floor(log10(a));
        fprintf(r->f, "%.*f%s", dec > 0 ? dec : 0, v, unit);
    } else {
        put_num(r, v, "%.3g");
        if (isfinite(v))
            fputs(unit, r->f);
    }
}

static void put_p(rep *r, double p)
{
    if (isfinite(p) && p <= 0.0)
        fputs("&lt; 1e-300", r->f);
    else
        put_num(r, p, "%.3g");
}

static void csv_num(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.9g", v);
}

static void warnf(rep *r, const char *fmt, ...) RCH_PRINTF(2, 3);
static void warnf(rep *r, const char *fmt, ...)
{
    va_list ap;
    if (r->n_warn >= RCH_REPORT_MAX_WARN)
        return;
    va_start(ap, fmt);
    vsnprintf(r->warn[r->n_warn++], sizeof r->warn[0], fmt, ap);
    va_end(ap);
}

/* ---- charts: horizontal rows, bars from zero or dots with 95 % intervals */

typedef struct {
    const char *title, *xlabel;
    size_t n_rows, n_sub;
    const char *const *label;   /* (n_rows) */
    const double *v;            /* (n_rows x n_sub), NaN: no value */
    const double *lo, *hi;      /* (n_rows x n_sub) interval ends, NaN: none; or NULL */
    const unsigned char *col;   /* (n_rows x n_sub) colour */
    const char *const *missing; /* (n_rows) text where v is NaN, or NULL: "not in this run" */
    int bars;
    const unsigned char *leg; /* (n_leg) colours */
    const char *const *leg_label;
    size_t n_leg;
    double ref[2];
    const char *ref_label[2];
    size_t n_ref;
    double clip; /* > 0: the axis ends at |x| <= clip, longer intervals end in an arrow */
    unsigned width_px;
} chart;

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
    const char *col = colour[c->col[i]];
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

static void chart_svg(rep *r, const chart *c)
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
        const rch_svg_paint sw = {.fill = colour[c->leg[k]]};
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

/* ---- the tables the page, the charts and the CSVs share */

typedef struct {
    const char *label;
    const char *key; /* member of a metrics object */
} metric_def;
static const metric_def metric_defs[] = {
    {"RMSE", "rmse_mm"}, {"mean |e|", "mean_abs_mm"}, {"SD", "sd_mm"}, {"MAX", "max_mm"}};
#define N_METRICS (sizeof metric_defs / sizeof metric_defs[0])

typedef struct {
    char name[64], unit[16], cls[24], comp[24]; /* comp: "fitted", "nominal", "not used" or "" */
    double nominal, value, delta, se, ci_lo, ci_hi; /* NaN when absent */
    double prior_sd;                                /* the prior's sd (the parameter's unit), NaN or 0: none */
} prow;

typedef struct {
    char label[96];
    const char *effect, *note;
    double step, joint, params, ident, rmse_cv, gain, gain_se, z, p;
    int tested, significant, chosen;
} crow;

typedef struct {
    const char *label;
    double v;
    unsigned char col;
} arow;

static unsigned char class_colour(const char *cls)
{
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

/* Standard error and class of parameter `name`: on the calibration's own
 * params[k] (std_error or se, class), else in uncertainty.parameters[]. */
static void param_unc(const rep *r, const rch_json *pk, prow *p)
{
    const char *cls = jstr(pk, "class"), *comp = jstr(pk, "compensation");
    p->prior_sd = NAN;
    p->se = jnum(pk, "std_error");
    if (!isfinite(p->se))
        p->se = jnum(pk, "se");
    const rch_json *list = jarr(r->unc, "parameters");
    for (size_t i = 0; list && i < list->n; ++i) {
        const char *nm = jstr(list->items[i], "name");
        if (!nm || strcmp(nm, p->name) != 0)
            continue;
        if (!isfinite(p->se))
            p->se = jnum(list->items[i], "std_error");
        const char *post = jstr(list->items[i], "data_vs_prior"); /* a MAP fit: what the data did to the prior */
        if (post && strcmp(post, "no prior") != 0)
            cls = post;
        else if (!cls)
            cls = jstr(list->items[i], "class");
        p->prior_sd = jnum(list->items[i], "prior_sd");
        if (!comp)
            comp = jstr(list->items[i], "compensation");
        break;
    }
    snprintf(p->cls, sizeof p->cls, "%s", cls ? cls : "");
    snprintf(p->comp, sizeof p->comp, "%s", comp ? comp : "");
}

static prow *params_read(const rep *r, size_t *n)
{
    const rch_json *ps = jarr(r->cal, "params");
    *n = 0;
    if (!ps || ps->n == 0)
        return NULL;
    prow *rows = calloc(ps->n, sizeof *rows);
    if (!rows)
        return NULL;
    for (size_t k = 0; k < ps->n; ++k) {
        const rch_json *pk = ps->items[k];
        prow *p = &rows[*n];
        const char *nm = jstr(pk, "name"), *un = jstr(pk, "unit");
        snprintf(p->name, sizeof p->name, "%s", nm ? nm : "?");
        snprintf(p->unit, sizeof p->unit, "%s", un ? un : "");
        p->value = jnum(pk, "value");
        p->delta = jnum(pk, "delta");
        p->nominal = p->value - p->delta;
        param_unc(r, pk, p);
        p->ci_lo = p->delta - Z95 * p->se;
        p->ci_hi = p->delta + Z95 * p->se;
        (*n)++;
    }
    return rows;
}

static crow *cands_read(const rep *r, size_t *n)
{
    const rch_json *cs = jarr(r->diag, "candidates");
    *n = 0;
    if (!cs || cs->n == 0)
        return NULL;
    crow *rows = calloc(cs->n, sizeof *rows);
    if (!rows)
        return NULL;
    for (size_t k = 0; k < cs->n; ++k) {
        const rch_json *c = cs->items[k];
        crow *w = &rows[k];
        w->effect = jstr(c, "effect");
        w->note = jstr(c, "note");
        w->step = jnum(c, "step");
        w->joint = jnum(c, "joint");
        w->params = jnum(c, "params");
        w->ident = jnum(c, "identifiable");
        w->rmse_cv = jnum(c, "rmse_cv_mm");
        w->gain = jnum(c, "gain_mm2");
        w->gain_se = jnum(c, "gain_se_mm2");
        w->z = jnum(c, "z");
        w->p = jnum(c, "p");
        w->tested = jbool(c, "tested") == 1;
        w->significant = jbool(c, "significant") == 1;
        w->chosen = jbool(c, "chosen") == 1;
        char j[24] = "";
        if (isfinite(w->joint))
            snprintf(j, sizeof j, " j%.0f", w->joint);
        snprintf(w->label, sizeof w->label, "%.0f: %s%s", isfinite(w->step) ? w->step : 0.0,
                 w->effect ? w->effect : "?", j);
    }
    *n = cs->n;
    return rows;
}

/* Accuracy figures: predicted 95 % uncertainty and, on a simulation, the
 * flange error against the truth. Rows with no number are left out. */
static size_t accuracy_read(const rep *r, arow out[10])
{
    static const struct {
        const char *label, *path;
        int truth;
        unsigned char col;
    } defs[] = {
        {"95 % inside the data, median", "position95_mm.data_median", 0, C_PRED},
        {"95 % inside the data, max", "position95_mm.data_max", 0, C_PRED},
        {"95 % whole workspace, median", "position95_mm.workspace_median", 0, C_PRED},
        {"95 % whole workspace, max", "position95_mm.workspace_max", 0, C_PRED},
        {"truth, before: RMS", "truth_flange.before_rms_mm", 1, C_BEFORE},
        {"truth, before: max", "truth_flange.before_max_mm", 1, C_BEFORE},
        {"truth, after: RMS", "truth_flange.after_rms_mm", 1, C_AFTER},
        {"truth, after: max", "truth_flange.after_max_mm", 1, C_AFTER},
    };
    size_t n = 0;
    for (size_t k = 0; k < sizeof defs / sizeof defs[0]; ++k) {
        const double v = jnum(defs[k].truth ? r->cal : r->unc, defs[k].path);
        if (isfinite(v)) {
            out[n].label = defs[k].label;
            out[n].v = v;
            out[n].col = defs[k].col;
            n++;
        }
    }
    return n;
}

/* ---- what the page needs before it starts: data hashes and warnings */

#define MAX_DFILES 8
typedef struct {
    const char *file, *sha_rec; /* as recorded; sha_rec NULL when not recorded */
    double samples;
    char sha_now[65];           /* "" when the file cannot be read from here */
    char why[96];               /* why not (a FIFO, a device, too large, ...) */
} dfile;

static size_t data_files(const rep *r, dfile out[MAX_DFILES])
{
    const rch_json *list = jarr(r->prov, "data");
    size_t n = 0;
    for (size_t i = 0; list && i < list->n && n < MAX_DFILES; ++i) {
        const char *file = jstr(list->items[i], "file");
        if (!file)
            continue;
        out[n].file = file;
        out[n].sha_rec = jstr(list->items[i], "sha256");
        out[n].samples = jnum(list->items[i], "samples");
        n++;
    }
    if (n == 0 && jstr(r->cal, "data")) {
        out[0].file = jstr(r->cal, "data");
        out[0].sha_rec = NULL;
        out[0].samples = jnum(r->cal, "n_train") + jnum(r->cal, "n_test");
        n = 1;
    }
    /* names found in the file, not given by the user: a regular file below
     * the size limit only (never a FIFO or /dev/zero, which never end) */
    for (size_t i = 0; i < n; ++i)
        if (rch_sha256_file_unasked(out[i].sha_now, out[i].file, RCH_UNASKED_MAX_BYTES, out[i].why,
                                    sizeof out[i].why) != 0)
            out[i].sha_now[0] = '\0';
    return n;
}

static const char *prov_str(const rep *r, const char *key)
{
    const char *s = jstr(r->prov, key);
    return s ? s : jstr(r->cal, key);
}

static void warn_fit(rep *r)
{
    const double before = jnum(r->cal, "before.rmse_mm"), after = jnum(r->cal, "after.rmse_mm");
    const char *exit_why = jstr(r->cal, "exit");
    if (jbool(r->cal, "converged") == 0)
        warnf(r, "The solver did not converge (exit: %s): the after figures and the parameters are not meaningful.",
              exit_why ? exit_why : "not in this run");
    if (jbool(r->cal, "held_out") == 0)
        warnf(r, "No held-out samples: the before/after figures are on the training data and flatter the model.");
    if (isfinite(before) && isfinite(after) && after > before)
        warnf(r, "The calibrated model is worse than the nominal one on the held-out samples (RMSE %.4f mm against "
                 "%.4f mm).", after, before);
    const double rank = jnum(r->cal, "identifiability.rank"), np = jnum(r->cal, "identifiability.params"),
                 weak = jnum(r->cal, "identifiability.weak");
    const int prior = jbool(jpath(r->cal, "estimation"), "prior") == 1;
    if (isfinite(rank) && isfinite(np) && rank < np)
        warnf(r, "%.0f of %.0f parameter directions are not seen by these data; %s (see the identifiability table).",
              np - rank, np,
              prior ? "the physical prior holds them near nominal and their uncertainty is counted at the prior's "
                      "width"
                    : "the solver left them at their starting values");
    if (isfinite(weak) && weak > 0)
        warnf(r, "%.0f direction(s) are only weakly seen by the data: %s.", weak,
              prior ? "the prior shares in their values" : "their values carry little information");
    const double tb = jnum(r->cal, "truth_flange.before_rms_mm"), ta = jnum(r->cal, "truth_flange.after_rms_mm");
    if (isfinite(tb) && isfinite(ta) && ta > tb)
        warnf(r, "Against the simulated truth the calibrated flange positions are worse than the nominal ones "
                 "(RMS %.4f mm against %.4f mm).", ta, tb);
}

static void warn_params(rep *r, const prow *p, size_t n)
{
    char weak[512] = "", notid[512] = "", far[512] = "";
    int posterior = 0;
    for (size_t k = 0; k < n; ++k) {
        const int po = strcmp(p[k].cls, "prior only") == 0, pa = strcmp(p[k].cls, "partly") == 0;
        posterior |= po || pa || strcmp(p[k].cls, "determined") == 0;
        char *dst = strcmp(p[k].cls, "weak") == 0 || pa   ? weak
                    : strcmp(p[k].cls, "not identifiable") == 0 || po ? notid
                                                                      : NULL;
        if (dst && strlen(dst) + strlen(p[k].name) + 3 < sizeof weak)
            snprintf(dst + strlen(dst), sizeof weak - strlen(dst), "%s%s", dst[0] ? ", " : "", p[k].name);
        if (p[k].prior_sd > 0.0 && fabs(p[k].delta) > 3.0 * p[k].prior_sd && strlen(far) + strlen(p[k].name) + 3 < sizeof far)
            snprintf(far + strlen(far), sizeof far - strlen(far), "%s%s", far[0] ? ", " : "", p[k].name);
    }
    if (notid[0])
        warnf(r, posterior ? "Determined by the prior only (the data did not narrow them; they stay within their "
                             "prior, and compensation uses them as they are): %s."
                           : "Not identifiable (their values mean nothing alone; compensation keeps them nominal): %s.",
              notid);
    if (weak[0])
        warnf(r, posterior ? "Partly determined by the data (the prior shares in their values): %s."
                           : "Weakly identified (large standard error): %s.",
              weak);
    if (far[0])
        warnf(r, "More than 3 prior standard deviations from nominal (a real deviation, or an effect these "
                 "parameters stand in for: run rcal diagnose): %s.", far);
    if (jbool(r->unc, "orientation_determined") == 0)
        warnf(r, "The data do not determine the flange orientation: compensate position only.");
    const double in = jnum(r->unc, "position95_mm.data_max"), ws = jnum(r->unc, "position95_mm.workspace_max");
    if (isfinite(in) && isfinite(ws) && ws > 3.0 * in)
        warnf(r, "The model extrapolates: predicted 95 %% position uncertainty up to %.3g mm over the whole workspace "
                 "against %.3g mm inside the data; trust it only near the measured poses.", ws, in);
}

static void warn_diag(rep *r)
{
    const char *effect = jstr(r->diag, "effect"), *why = jstr(r->diag, "remaining_why");
    if (!r->diag)
        return;
    if (effect && strcmp(effect, "unexplained") == 0)
        warnf(r, "The diagnosis finds error the model does not explain: %s.", why ? why : "not in this run");
    else if (effect && strcmp(effect, "none") != 0) {
        char seq[256] = "";
        const rch_json *q = jarr(r->diag, "sequence");
        for (size_t k = 0; q && k < q->n; ++k)
            if (q->items[k]->type == RCH_JSTR && strlen(seq) + strlen(q->items[k]->str) + 3 < sizeof seq)
                snprintf(seq + strlen(seq), sizeof seq - strlen(seq), "%s%s", k ? ", " : "", q->items[k]->str);
        const double b = jnum(r->diag, "rmse_before_mm"), a = jnum(r->diag, "rmse_after_mm");
        char fig[128] = "";
        if (isfinite(a) && isfinite(b))
            snprintf(fig, sizeof fig, " (held-out RMSE %.4g mm with the geometry alone, %.4g mm with %s)", b, a,
                     q && q->n > 1 ? "them" : "it");
        const rch_json *cj = jarr(r->cal, "length_jumps");
        if (strcmp(effect, "length_jump") == 0 && cj && cj->n)
            ; /* the calibration fitted them: nothing the model misses */
        else
            warnf(r, "The diagnosis finds what the geometric model misses: %s%s. The calibration above does not "
                     "model it: %s.",
                  seq[0] ? seq : effect, fig,
                  strcmp(effect, "length_jump") == 0 ? "calibrate again with --jumps"
                                                     : "calibrate again with --effects naming it (the diagnosis' "
                                                       "Next line gives the command)");
    }
    const double nd = jnum(r->diag, "n"), nc = jnum(r->cal, "n_train") + jnum(r->cal, "n_test");
    const double dropped = jnum(r->cal, "dequantized.refused");
    if (isfinite(nd) && isfinite(nc) && nd != nc && !(isfinite(dropped) && nd == nc + dropped))
        warnf(r, "The diagnosis ran on %.0f samples, the calibration on %.0f: are they from the same data?", nd, nc);
    const double flick = jnum(r->diag, "wrist_flicker_samples");
    if (isfinite(flick) && flick > 0)
        warnf(r, "%.0f sample(s) have a wrist reading that moved by one display step within their set-up.", flick);
}

static void warn_inputs(rep *r, const dfile *df, size_t n_df)
{
    const char *md = jstr(r->model, "calibration.data"), *cd = jstr(r->cal, "data");
    if (md && cd && strcmp(md, cd) != 0)
        warnf(r, "The model file was calibrated on %s, this calibration on %s: the model may be from another run.",
              md, cd);
    for (size_t i = 0; i < n_df; ++i) {
        if (df[i].sha_rec && df[i].sha_now[0] && strcmp(df[i].sha_rec, df[i].sha_now) != 0)
            warnf(r, "The data file %s changed since the calibration (its SHA-256 differs from the one recorded).",
                  df[i].file);
        if (!df[i].sha_now[0])
            warnf(r, "The data file %s was not read (%s): its content cannot be checked.", df[i].file, df[i].why);
    }
    if (!r->prov && !jstr(r->cal, "tool"))
        warnf(r, "No provenance in this run (tool version, command line, data hash, date): the result cannot be "
                 "traced to its data and its program.");
    const rch_json *w = jarr(r->cal, "warnings");
    for (size_t i = 0; w && i < w->n; ++i)
        if (w->items[i]->type == RCH_JSTR)
            warnf(r, "%s", w->items[i]->str);
}

/* ---- the page */

static const char css[] =
    "body{font:14px/1.45 system-ui,-apple-system,'Segoe UI',Helvetica,Arial,sans-serif;margin:0;"
    "background:#eef0f3;color:#1d2330}"
    "main{max-width:1130px;margin:0 auto;padding:10px 20px}"
    "header{padding:6px 0}h1{font-size:22px;margin:6px 0 2px}"
    ".sub{color:#445;margin:0}"
    ".glance{margin:8px 0 0;padding:8px 12px;background:#fff;border-left:5px solid #0072B2;border-radius:4px}"
    ".flag{color:#b34700;font-size:12px}.glance p{margin:4px 0}.glance .big{font-size:16px}"
    ".glance.pass{border-left-color:#009E73}.glance.fail{border-left-color:#D55E00}"
    ".glance.pass b:first-child{color:#007a5a}.glance.fail b:first-child{color:#b34700}.rests{color:#334;font-size:13px}"
    "section{background:#fff;border:1px solid #d6dae0;border-radius:6px;padding:8px 16px 12px;margin:12px 0}"
    "h2{font-size:17px;margin:2px 0 8px;padding-bottom:3px;border-bottom:1px solid #e4e7eb}"
    "h3{font-size:14px;margin:10px 0 4px}"
    "table{border-collapse:collapse;font-size:13px;margin:4px 0}"
    "td,th{padding:1px 8px;border-bottom:1px solid #eceef1;text-align:right;vertical-align:top;white-space:nowrap}"
    "td.w{white-space:normal}.two{display:grid;grid-template-columns:1fr 1fr;gap:12px}.two section{margin:0}"
    "th{background:#f1f3f6;font-weight:600}td.l,th.l{text-align:left}"
    "table.kv th{text-align:left;background:none;color:#445;font-weight:normal;white-space:nowrap}"
    "table.kv td{text-align:left;white-space:normal}"
    ".na{color:#888;font-style:italic}.mono{font-family:ui-monospace,'DejaVu Sans Mono',monospace;"
    "font-size:12px;word-break:break-all}"
    ".row{display:flex;flex-wrap:wrap;gap:14px;align-items:flex-start}"
    ".note{color:#556;font-size:12.5px;margin:4px 0}"
    ".verdict{font-size:15px;padding:6px 10px;background:#f4f8fb;border-left:4px solid #009E73}"
    "ul.warn{margin:4px 0;padding-left:0;list-style:none}"
    "ul.warn li{background:#fff6e5;border-left:4px solid #E69F00;padding:4px 10px;margin:4px 0}"
    "svg.chart{border:1px solid #e4e7eb;border-radius:4px;background:#fff}"
    ".sw{display:inline-block;width:10px;height:10px;margin-right:4px;vertical-align:baseline}"
    "details summary{cursor:pointer;color:#234}"
    "@media print{body{background:#fff}main{max-width:none;padding:0}section{break-inside:avoid;border:none}}";

static void kv(rep *r, const char *key)
{
    fprintf(r->f, "<tr><th>%s</th><td>", key);
    r->where = key;
}

static void kv_end(rep *r)
{
    fputs("</td></tr>\n", r->f);
    r->where = r->section;
}

/* The first screen: the verdict (the accuracy of the compensated robot, 95 %,
 * over the data's poses and the workspace; pass or fail against the user's
 * tolerance), the held-out measurements it is checked on, and what it rests
 * on (the prior, the outlets, every nuisance fitted). */
static void verdict(rep *r, size_t n_warn)
{
    FILE *f = r->f;
    const double in = jnum(r->unc, "position95_mm.data_median"), in_max = jnum(r->unc, "position95_mm.data_max"),
                 ws = jnum(r->unc, "position95_mm.workspace_median");
    const double tol = r->cfg->tolerance_mm;
    const int have = isfinite(in) && isfinite(in_max);
    const int pass = have && tol > 0.0 && in_max <= tol;
    section(r, "the verdict (first screen)", NULL);
    fprintf(f, "<div class=\"glance %s\" id=\"verdict\"><p class=\"big\">",
            !have || !(tol > 0.0) ? "" : pass ? "pass" : "fail");
    if (have && tol > 0.0)
        fprintf(f, "<b>%s</b> against the tolerance of %.4g mm: ", pass ? "PASS" : "FAIL", tol);
    if (have) {
        fputs("predicted from the fit, after compensation the robot lands within &plusmn;<b>", f);
        put_sig(r, in, " mm");
        fputs("</b> (95 %) over the measured region (the median over the data's poses; the largest &plusmn;", f);
        put_sig(r, in_max, " mm");
        fputs("), &plusmn;", f);
        put_sig(r, ws, " mm");
        fputs(" over the whole workspace.", f);
        if (!(tol > 0.0))
            fputs(" <span class=\"note\">(no tolerance given: <code>rcal report --tolerance-mm MM</code> gives a "
                  "pass or fail)</span>",
                  f);
    } else {
        fputs("No predicted accuracy in this run: the calibration output carries no uncertainty (pass the model "
              "file of the run with <code>--model</code>, or calibrate again with <code>rcal calibrate --json</code>).",
              f);
        missing(r, "the predicted accuracy", HOW_MODEL);
    }
    const double b = jnum(r->cal, "before.rmse_mm"), a = jnum(r->cal, "after.rmse_mm");
    const double nt = jnum(r->cal, "after.n");
    fprintf(f, "</p>\n<p>%s: cable-length RMSE <b>",
            jbool(r->cal, "held_out") == 0 ? "Measured on the training samples (none held out)"
                                           : "Measured on samples the fit never saw");
    put_num(r, b, "%.4f");
    fputs(" mm &rarr; ", f);
    put_num(r, a, "%.4f");
    fputs(" mm</b>", f);
    if (isfinite(nt))
        fprintf(f, " (%.0f samples)", nt);
    if (isfinite(a) && isfinite(b) && b > 0)
        fprintf(f, ", %+.1f %%", 100.0 * (a - b) / b);
    fputs(".</p>\n<p class=\"rests\">It rests on: ", f);
    const rch_json *est = jpath(r->cal, "estimation");
    if (jbool(est, "prior") == 1) {
        fputs("the posterior of a fit with the physical prior (link lengths &plusmn;", f);
        put_sig(r, jnum(est, "prior_length_mm"), " mm");
        fputs(", twists &plusmn;", f);
        put_sig(r, jnum(est, "prior_twist_deg"), "&deg;");
        fputs(", joint zeros &plusmn;", f);
        put_sig(r, jnum(est, "prior_offset_deg"), "&deg;");
        fputs(": what the data did not determine counts at the prior's width), the noise estimated from the data (",
              f);
        put_sig(r, jnum(est, "noise_mm"), " mm");
        fputs(")", f);
    } else if (est) {
        fputs("the covariance of a least-squares fit (no prior: directions the data did not determine are held "
              "nominal and not counted)",
              f);
    } else {
        put_str(r, NULL);
    }
    const double outlets = jnum(est, "outlets");
    if (isfinite(outlets))
        fprintf(f, "; %.0f cable outlet%s%s", outlets, outlets == 1 ? "" : "s",
                outlets < 3 ? " (lengths from fewer than three outlets cannot see every rigid motion of the robot "
                              "about them: the figures hold for positions relative to each other)"
                            : "");
    const char *att = jstr(est, "attachment");
    if (att)
        fprintf(f, "; the cable attachment %s",
                strcmp(att, "estimated") == 0 ? "estimated (a vector in the flange frame)" : "at the flange centre");
    const rch_json *jumps = jarr(r->cal, "length_jumps");
    if (jumps && jumps->n)
        fprintf(f, "; %zu length jump%s fitted as nuisance", jumps->n, jumps->n == 1 ? "" : "s");
    const double dq = jnum(r->cal, "dequantized.corrected"), dqr = jnum(r->cal, "dequantized.refused");
    if (isfinite(dq))
        fprintf(f, "; joint angles recovered from x, y, z for %.0f rows (%.0f refused)", dq,
                isfinite(dqr) ? dqr : 0.0);
    const double g = jnum(r->unc, "groups");
    if (isfinite(g) && g > 0)
        fprintf(f, "; %.0f set-up groups (cluster-robust covariance)", g);
    fprintf(f, ".</p>\n<p><a href=\"#warnings\">%zu warning%s</a></p></div>\n", n_warn, n_warn == 1 ? "" : "s");
}

static void page_head(rep *r, size_t n_warn)
{
    FILE *f = r->f;
    const char *data = jstr(r->cal, "data"), *robot = jstr(r->model, "name");
    fputs("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
          "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Calibration report: ",
          f);
    put_esc(f, data ? data : "?");
    fprintf(f, "</title>\n<style>%s</style>\n</head>\n<body>\n<main>\n<header>\n<h1>Calibration report</h1>\n", css);
    fputs("<p class=\"sub\">robot <b>", f);
    section(r, "the robot's name", HOW_MODEL);
    put_str(r, robot ? robot : jstr(r->cal, "robot"));
    section(r, "the page's head", NULL);
    fputs("</b> &middot; data <b>", f);
    put_str(r, data);
    fputs("</b> &middot; method <b>", f);
    put_str(r, jstr(r->cal, "method"));
    fputs("</b> &middot; calibrated ", f);
    put_str(r, prov_str(r, "date"));
    fputs("</p>\n", f);
    verdict(r, n_warn);
    fputs("</header>\n", f);
}

static void sec_data(rep *r, const dfile *df, size_t n_df)
{
    FILE *f = r->f;
    section(r, "section 1 (data)", NULL);
    fputs("<div class=\"two\"><section id=\"data\"><h2>1. Data</h2>\n<table class=\"kv\">\n", f);
    kv(r, "data file");
    put_str(r, jstr(r->cal, "data"));
    kv_end(r);
    kv(r, "samples");
    put_num(r, jnum(r->cal, "n_train") + jnum(r->cal, "n_test"), "%.0f");
    kv_end(r);
    kv(r, "set-up groups");
    r->how = HOW_DIAG; /* the rows up to the files come from a diagnosis when the calibration has none */
    if (isfinite(jnum(r->unc, "groups")) && jnum(r->unc, "groups") > 0) {
        put_num(r, jnum(r->unc, "groups"), "%.0f");
        fputs(" (the covariance's clusters, from the ", f);
        put_str(r, jstr(r->unc, "groups_from"));
        fputs(")", f);
    } else {
        put_num(r, jnum(r->diag, "groups"), "%.0f");
        fputs(r->diag ? " (from the diagnosis)" : "", f);
    }
    kv_end(r);
    /* the nuisance the calibration fitted: every one shown */
    const rch_json *jumps = jarr(r->cal, "length_jumps");
    kv(r, "length jumps (nuisance)");
    if (!jumps)
        fputs("none fitted", f);
    for (size_t k = 0; jumps && k < jumps->n; ++k) {
        const rch_json *jk = jumps->items[k];
        fprintf(f, "%sline %.0f: %+.3f &plusmn; %.3f mm", k ? "<br>" : "", jnum(jk, "line"), jnum(jk, "size_mm"),
                jnum(jk, "se_mm"));
    }
    kv_end(r);
    kv(r, "joint angles");
    if (isfinite(jnum(r->cal, "dequantized.corrected")))
        fprintf(f, "recovered from the file's x, y, z: %.0f rows corrected (RMS %.4f&deg;), %.0f refused and dropped",
                jnum(r->cal, "dequantized.corrected"), jnum(r->cal, "dequantized.dq_rms_deg"),
                jnum(r->cal, "dequantized.refused"));
    else
        fputs("as read (not recovered from x, y, z)", f);
    kv_end(r);
    kv(r, "display resolution");
    fputs("joints ", f);
    if (jnum(r->diag, "q_step_deg") == 0.0)
        fputs("no display step left (recovered from x, y, z, or not rounded)", f);
    else
        put_num(r, jnum(r->diag, "q_step_deg"), "%.4g&deg;");
    fputs(", cable length ", f);
    put_num(r, jnum(r->diag, "len_step_mm"), "%.4g mm");
    kv_end(r);
    kv(r, "noise floor");
    put_num(r, jnum(r->diag, "noise_floor_mm"), "%.4g mm rms");
    if (r->diag) {
        fputs(" (joint display step through the Jacobian ", f);
        put_num(r, jnum(r->diag, "noise_floor_joints_mm"), "%.4g mm");
        fputs(", length step / &radic;12 ", f);
        put_num(r, jnum(r->diag, "noise_floor_length_mm"), "%.4g mm");
        fputs(")", f);
    }
    kv_end(r);
    r->how = NULL;
    for (size_t i = 0; i < n_df; ++i) {
        kv(r, "file, SHA-256");
        fputs("<span class=\"mono\">", f);
        put_esc(f, df[i].file);
        fputs("</span>", f);
        if (isfinite(df[i].samples))
            fprintf(f, ", %.0f samples", df[i].samples);
        fputs("<br>recorded: <span class=\"mono\">", f);
        put_str(r, df[i].sha_rec);
        fputs("</span><br>now: <span class=\"mono\">", f);
        if (df[i].sha_now[0]) {
            fputs(df[i].sha_now, f);
        } else {
            fputs("<span class=\"na\">not read: ", f);
            put_esc(f, df[i].why);
            fputs("</span>", f);
        }
        fputs(df[i].sha_rec && df[i].sha_now[0] ? (strcmp(df[i].sha_rec, df[i].sha_now) ? " (DIFFERS)" : " (same)")
                                                 : "",
              f);
        fputs("</span>", f);
        kv_end(r);
    }
    fputs("</table></section>\n", f);
}

static void sec_split(rep *r)
{
    FILE *f = r->f;
    const double ntr = jnum(r->cal, "n_train"), nte = jnum(r->cal, "n_test");
    section(r, "section 2 (split)", NULL);
    fputs("<section id=\"split\"><h2>2. Split</h2>\n<table class=\"kv\">\n", f);
    kv(r, "training samples");
    put_num(r, ntr, "%.0f");
    kv_end(r);
    kv(r, "held-out samples");
    put_num(r, nte, "%.0f");
    if (isfinite(ntr) && isfinite(nte) && ntr + nte > 0)
        fprintf(f, " (%.1f %% of the data)", 100.0 * nte / (ntr + nte));
    kv_end(r);
    kv(r, "seed");
    put_num(r, jnum(r->cal, "seed"), "%.0f");
    kv_end(r);
    if (r->diag) {
        kv(r, "diagnosis");
        put_num(r, jnum(r->diag, "folds"), "%.0f-fold");
        fputs(" cross-validation, folds random within set-up groups", f);
        kv_end(r);
    }
    fputs("</table>\n<p class=\"note\">", f);
    fputs(jbool(r->cal, "held_out") == 0
              ? "No held-out set: the before/after figures are on the training samples."
              : "The before/after figures are on the held-out samples, which the fit never saw.",
          f);
    fputs("</p></section></div>\n", f);
}

static void metrics_row(rep *r, const char *label, const char *key)
{
    const rch_json *m = jpath(r->cal, key);
    static const char *const keys[] = {"n", "rmse_mm", "mean_abs_mm", "sd_mm", "mean_mm", "max_mm"};
    fprintf(r->f, "<tr><td class=\"l\">%s</td>", label);
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k) {
        fputs("<td>", r->f);
        put_num(r, jnum(m, keys[k]), k ? "%.4f" : "%.0f");
        fputs("</td>", r->f);
    }
    fputs("</tr>\n", r->f);
}

static void sec_metrics(rep *r)
{
    FILE *f = r->f;
    const int held = jbool(r->cal, "held_out") != 0;
    section(r, "section 3 (before and after)", NULL);
    fputs("<section id=\"metrics\"><h2>3. Before and after calibration</h2>\n<div class=\"row\"><div style=\"flex:1 1 500px\">\n"
          "<table><tr><th class=\"l\">cable-length residual (mm)</th><th>samples</th><th>RMSE</th>"
          "<th>mean |e|</th><th>SD</th><th>mean</th><th>MAX</th></tr>\n",
          f);
    metrics_row(r, held ? "held-out, before (nominal DH)" : "evaluated, before (nominal DH)", "before");
    metrics_row(r, held ? "held-out, after" : "evaluated, after", "after");
    metrics_row(r, "training, before", "train_before");
    metrics_row(r, "training, after", "train_after");
    fputs("</table>\n<p class=\"note\">before: the nominal DH table with the encoder outlet fitted alone; after: "
          "the calibrated model. mean |e| is what the paper's Eq. 20 calls SD; SD here is the standard deviation."
          "</p></div>\n",
          f);
    const char *labels[N_METRICS];
    double v[2 * N_METRICS];
    unsigned char col[2 * N_METRICS];
    for (size_t k = 0; k < N_METRICS; ++k) {
        char path[64];
        labels[k] = metric_defs[k].label;
        snprintf(path, sizeof path, "before.%s", metric_defs[k].key);
        v[2 * k] = jnum(r->cal, path);
        snprintf(path, sizeof path, "after.%s", metric_defs[k].key);
        v[2 * k + 1] = jnum(r->cal, path);
        col[2 * k] = C_BEFORE;
        col[2 * k + 1] = C_AFTER;
    }
    static const unsigned char leg[2] = {C_BEFORE, C_AFTER};
    static const char *const leg_label[2] = {"before (nominal DH)", "after (calibrated)"};
    chart c;
    memset(&c, 0, sizeof c);
    c.title = held ? "Held-out residuals, before and after" : "Residuals (training set), before and after";
    c.xlabel = "cable-length residual (mm)";
    c.n_rows = N_METRICS;
    c.n_sub = 2;
    c.label = labels;
    c.v = v;
    c.col = col;
    c.bars = 1;
    c.leg = leg;
    c.leg_label = leg_label;
    c.n_leg = 2;
    c.width_px = 440;
    chart_svg(r, &c);
    fputs("</div></section>\n", f);
}

/* A table with one row per object of the JSON array `arr`: one column per
 * jcol, a string ('s'), a number with fmt ('n') or a p-value ('p'). */
typedef struct {
    const char *head, *key;
    char kind;
    const char *fmt;
} jcol;

static void json_table(rep *r, const rch_json *arr, const jcol *cols, size_t n_cols)
{
    FILE *f = r->f;
    fputs("<table><tr>", f);
    for (size_t c = 0; c < n_cols; ++c)
        fprintf(f, "<th%s>%s</th>", cols[c].kind == 's' ? " class=\"l\"" : "", cols[c].head);
    fputs("</tr>\n", f);
    for (size_t k = 0; arr && k < arr->n; ++k) {
        fputs("<tr>", f);
        for (size_t c = 0; c < n_cols; ++c) {
            fputs(cols[c].kind == 's' ? "<td class=\"l\">" : "<td>", f);
            if (cols[c].kind == 's')
                put_str(r, jstr(arr->items[k], cols[c].key));
            else if (cols[c].kind == 'p')
                put_p(r, jnum(arr->items[k], cols[c].key));
            else
                put_num(r, jnum(arr->items[k], cols[c].key), cols[c].fmt);
            fputs("</td>", f);
        }
        fputs("</tr>\n", f);
    }
    fputs("</table>\n", f);
}

static void params_table(rep *r, const prow *p, size_t n)
{
    FILE *f = r->f;
    int have_se = 0, have_cls = 0, have_comp = 0;
    for (size_t k = 0; k < n; ++k) {
        have_se |= isfinite(p[k].se);
        have_cls |= p[k].cls[0] != '\0';
        have_comp |= p[k].comp[0] != '\0';
    }
    fputs("<table><tr><th class=\"l\">parameter</th><th>unit</th><th>nominal</th><th>calibrated</th>"
          "<th>correction</th>",
          f);
    if (have_se)
        fputs("<th>std error</th><th>95 % interval of the correction</th>", f);
    if (have_cls)
        fputs("<th class=\"l\">class</th>", f);
    if (have_comp)
        fputs("<th class=\"l\">compensation uses</th>", f);
    fputs("</tr>\n", f);
    for (size_t k = 0; k < n; ++k) {
        fputs("<tr><td class=\"l\">", f);
        put_esc(f, p[k].name);
        fputs("</td><td>", f);
        put_esc(f, p[k].unit);
        fputs("</td><td>", f);
        put_num(r, p[k].nominal, "%.6g");
        fputs("</td><td>", f);
        put_num(r, p[k].value, "%.6g");
        fputs("</td><td>", f);
        put_num(r, p[k].delta, "%+.4g");
        if (p[k].prior_sd > 0.0 && isfinite(p[k].delta) && fabs(p[k].delta) > 3.0 * p[k].prior_sd)
            fprintf(f, " <span class=\"flag\" title=\"more than 3 prior sd (%.3g) from nominal\">&#9888; &gt; 3 "
                       "prior sd</span>",
                    p[k].prior_sd);
        if (have_se) {
            /* no standard error by design for a parameter the data cannot determine or that was fixed */
            const int none = !isfinite(p[k].se) && (strcmp(p[k].cls, "not identifiable") == 0 ||
                                                    strcmp(p[k].cls, "fixed") == 0);
            fputs("</td><td>", f);
            if (none)
                fputs("&mdash;", f);
            else
                put_sig(r, p[k].se, "");
            fputs("</td><td>", f);
            if (isfinite(p[k].ci_lo))
                fprintf(f, "%+.3g &hellip; %+.3g", p[k].ci_lo, p[k].ci_hi);
            else if (none)
                fputs("&mdash;", f);
            else
                put_num(r, NAN, "");
        }
        if (have_cls) {
            fprintf(f, "</td><td class=\"l\"><span class=\"sw\" style=\"background:%s\"></span>",
                    colour[class_colour(p[k].cls)]);
            put_str(r, p[k].cls[0] ? p[k].cls : NULL);
        }
        if (have_comp) {
            fputs("</td><td class=\"l\">", f);
            put_str(r, p[k].comp[0] ? p[k].comp : NULL);
        }
        fputs("</td></tr>\n", f);
    }
    fputs("</table>\n", f);
    if (!have_se || !have_cls) {
        fprintf(f, "<p class=\"note\" style=\"max-width:520px\">%s%s%s: " NA ".</p>\n", have_se ? "" : "standard errors and 95 % intervals",
                !have_se && !have_cls ? ", " : "", have_cls ? "" : "identifiability class of each parameter");
        missing(r, !have_se ? "standard errors and 95 % intervals of the parameters"
                            : "the identifiability class of each parameter", HOW_MODEL);
    }
}

/* One panel of corrections: the parameters whose unit is `unit`. */
static void params_chart(rep *r, const prow *p, size_t n, const char *unit, const char *title)
{
    const char **labels = calloc(n ? n : 1, sizeof *labels);
    double *v = calloc(n ? 3 * n : 1, sizeof *v);
    unsigned char *col = calloc(n ? n : 1, 1);
    unsigned char leg[C_N];
    const char *leg_label[C_N];
    int used[C_N] = {0};
    size_t m = 0, n_leg = 0;
    double maxd = 0.0;
    if (!labels || !v || !col)
        goto done;
    for (size_t k = 0; k < n; ++k) {
        if (strcmp(p[k].unit, unit) != 0)
            continue;
        labels[m] = p[k].name;
        v[m] = p[k].delta;
        v[n + m] = p[k].ci_lo;
        v[2 * n + m] = p[k].ci_hi;
        col[m] = class_colour(p[k].cls);
        used[col[m]] = 1;
        if (isfinite(p[k].delta) && fabs(p[k].delta) > maxd)
            maxd = fabs(p[k].delta);
        m++;
    }
    if (m == 0)
        goto done;
    static const struct {
        unsigned char c;
        const char *label;
    } classes[] = {{C_IDENT, "identifiable"},
                   {C_WEAK, "weak"},
                   {C_NOTID, "not identifiable"},
                   {C_FIXED, "fixed"},
                   {C_UNKNOWN, "class not in this run"}};
    for (size_t k = 0; k < sizeof classes / sizeof classes[0]; ++k)
        if (used[classes[k].c]) {
            leg[n_leg] = classes[k].c;
            leg_label[n_leg++] = classes[k].label;
        }
    char xlabel[96];
    snprintf(xlabel, sizeof xlabel, "correction (%s), 95 %% interval = \xC2\xB1" "1.96 standard errors", unit);
    chart c;
    memset(&c, 0, sizeof c);
    c.title = title;
    c.xlabel = xlabel;
    c.n_rows = m;
    c.n_sub = 1;
    c.label = labels;
    c.v = v;
    c.lo = v + n;
    c.hi = v + 2 * n;
    c.col = col;
    c.leg = leg;
    c.leg_label = leg_label;
    c.n_leg = n_leg;
    c.clip = maxd > 0.0 ? 3.0 * maxd : 0.0;
    c.width_px = 520;
    chart_svg(r, &c);
done:
    free(labels);
    free(v);
    free(col);
}

static void ident_block(rep *r)
{
    FILE *f = r->f;
    const rch_json *id = jpath(r->cal, "identifiability");
    fputs("<h3>Identifiability at the solution</h3>\n", f);
    if (!id) {
        fputs("<p>", f);
        put_str(r, NULL);
        fputs("</p>\n", f);
        return;
    }
    fputs("<p>rank ", f);
    put_num(r, jnum(id, "rank"), "%.0f");
    fputs(" of ", f);
    put_num(r, jnum(id, "params"), "%.0f");
    fputs(" parameters, ", f);
    put_num(r, jnum(id, "weak"), "%.0f");
    fputs(" weak direction(s); condition number ", f);
    put_num(r, jnum(id, "cond"), "%.3g");
    fputs(" over the identifiable part; observability index O1 ", f);
    put_num(r, jnum(id, "observability"), "%.4g");
    fputs("</p>\n", f);
    const rch_json *dirs = jarr(id, "directions");
    if (!dirs || dirs->n == 0)
        return;
    static const jcol cols[] = {{"direction the data do not (or barely) see", "combo", 's', NULL},
                                {"relative singular value", "sv_rel", 'n', "%.2g"},
                                {"identifiable", "identifiable", 's', NULL}};
    json_table(r, dirs, cols, sizeof cols / sizeof cols[0]);
    const rch_json *sets = jarr(id, "dependent_sets"); /* absent from calibrations written before them */
    if (!sets || sets->n == 0)
        return;
    fputs("<p>What these directions hold: known sets of parameters whose columns are dependent (where several "
          "directions share one singular value the directions above mix them).</p>\n",
          f);
    static const jcol scols[] = {{"parameters", "params", 's', NULL},
                                 {"identifiable", "identifiable", 's', NULL},
                                 {"relative singular value", "sv_rel", 'n', "%.2g"},
                                 {"why", "why", 's', NULL}};
    json_table(r, sets, scols, sizeof scols / sizeof scols[0]);
}

static void sec_params(rep *r, const prow *p, size_t n)
{
    FILE *f = r->f;
    section(r, "section 4 (parameters)", NULL);
    fputs("<section id=\"params\"><h2>4. Identified parameters</h2>\n<p>solver ", f);
    put_str(r, jstr(r->cal, "method"));
    fputs(": ", f);
    const rch_json *jumps = jarr(r->cal, "length_jumps");
    if (jumps && jnum(r->cal, "iterations") == 0.0) {
        fprintf(f, "fitted with %zu length jump%s (a change-point search, each candidate a fit)", jumps->n,
                jumps->n == 1 ? "" : "s");
    } else {
        put_num(r, jnum(r->cal, "iterations"), "%.0f iterations");
        fputs(", ", f);
        put_num(r, jnum(r->cal, "cost_evals"), "%.0f passes over the data");
        fputs(", exit: ", f);
        put_str(r, jstr(r->cal, "exit"));
    }
    if (jbool(jpath(r->cal, "estimation"), "prior") == 1)
        fputs(", maximum a posteriori with the physical prior", f);
    fputs(", ", f);
    put_num(r, jnum(r->cal, "time_ms"), "%.1f ms");
    fputs(".<br>standard errors: ", f);
    put_str(r, jstr(r->unc, "covariance"));
    if (r->unc) {
        fputs(" covariance", f);
        const double g = jnum(r->unc, "groups");
        const char *from = jstr(r->unc, "groups_from");
        if (isfinite(g) && g > 0)
            fprintf(f, " over %.0f set-up groups", g);
        if (from) {
            fputs(" (from the ", f);
            put_esc(f, from);
            fputs(")", f);
        }
        fputs(", residual &sigma; ", f);
        put_num(r, jnum(r->unc, "sigma_mm"), "%.4g mm");
        fprintf(f, " (%s)", r->unc_from);
    }
    fputs("</p>\n<div class=\"row\"><div style=\"flex:0 0 auto\">\n", f);
    params_table(r, p, n);
    fputs("<p class=\"note\" style=\"max-width:520px\">correction: against the nominal table (DH) or the encoder outlet's first estimate "
          "(ex, ey, ez).</p>\n</div><div style=\"display:flex;flex-direction:column;gap:10px\">\n",
          f);
    params_chart(r, p, n, "mm", "Corrections, lengths (mm)");
    params_chart(r, p, n, "deg", "Corrections, angles (deg)");
    params_chart(r, p, n, "-", "Corrections, other parameters");
    params_chart(r, p, n, "SI", "Corrections, effect parameters (SI)");
    fputs("</div></div>\n", f);
    ident_block(r);
    fputs("</section>\n", f);
}

static void cands_table(rep *r, const crow *c, size_t n)
{
    FILE *f = r->f;
    fputs("<table><tr><th class=\"l\">step: effect</th><th>params (identifiable)</th><th>held-out RMSE (mm)</th>"
          "<th>gain (mm&sup2;)</th><th>&plusmn; SE</th><th>z</th><th>p</th><th class=\"l\">verdict</th>"
          "<th class=\"l\">note</th></tr>\n",
          f);
    for (size_t k = 0; k < n; ++k) {
        fputs("<tr><td class=\"l\">", f);
        put_esc(f, c[k].label);
        fputs("</td><td>", f);
        put_num(r, c[k].params, "%.0f");
        fputs(" (", f);
        put_num(r, c[k].ident, "%.0f");
        fputs(")</td><td>", f);
        if (c[k].tested) {
            put_num(r, c[k].rmse_cv, "%.5f");
            fputs("</td><td>", f);
            put_num(r, c[k].gain, "%.3g");
            fputs("</td><td>", f);
            put_num(r, c[k].gain_se, "%.2g");
            fputs("</td><td>", f);
            put_num(r, c[k].z, "%.2f");
            fputs("</td><td>", f);
            put_p(r, c[k].p);
        } else {
            fputs("not tested</td><td></td><td></td><td></td><td>", f);
        }
        fprintf(f, "</td><td class=\"l\"><span class=\"sw\" style=\"background:%s\"></span>%s</td><td class=\"l w\">",
                colour[c[k].chosen ? C_CHOSEN : c[k].significant ? C_SIGNIF : C_NOTSIG],
                c[k].chosen ? "chosen" : c[k].significant ? "significant" : c[k].tested ? "no gain" : "&mdash;");
        put_esc(f, c[k].note);
        fputs("</td></tr>\n", f);
    }
    fputs("</table>\n", f);
}

static void cands_chart(rep *r, const crow *c, size_t n)
{
    const char **labels = calloc(n, sizeof *labels), **missing = calloc(n, sizeof *missing);
    double *v = calloc(3 * n, sizeof *v);
    unsigned char *col = calloc(n, 1);
    if (labels && missing && v && col) {
        for (size_t k = 0; k < n; ++k) {
            labels[k] = c[k].label;
            missing[k] = c[k].tested ? "no figure" : "not tested (not identifiable here)";
            v[k] = c[k].tested ? c[k].gain : NAN;
            v[n + k] = c[k].gain - Z95 * c[k].gain_se;
            v[2 * n + k] = c[k].gain + Z95 * c[k].gain_se;
            col[k] = c[k].chosen ? C_CHOSEN : c[k].significant ? C_SIGNIF : C_NOTSIG;
        }
        static const unsigned char leg[3] = {C_CHOSEN, C_SIGNIF, C_NOTSIG};
        static const char *const leg_label[3] = {"chosen", "significant, not chosen", "no significant gain"};
        chart ch;
        memset(&ch, 0, sizeof ch);
        ch.title = "Held-out gain of each candidate effect";
        ch.xlabel = "reduction of the held-out mean squared residual (mm\xC2\xB2), 95 % interval";
        ch.n_rows = n;
        ch.n_sub = 1;
        ch.label = labels;
        ch.v = v;
        ch.lo = v + n;
        ch.hi = v + 2 * n;
        ch.col = col;
        ch.missing = missing;
        ch.leg = leg;
        ch.leg_label = leg_label;
        ch.n_leg = 3;
        ch.width_px = 1060;
        chart_svg(r, &ch);
    }
    free(labels);
    free(missing);
    free(v);
    free(col);
}

static void structure_table(rep *r)
{
    FILE *f = r->f;
    const rch_json *b = jarr(r->diag, "structure_before"), *a = jarr(r->diag, "structure_after");
    size_t sb = 0, sa = 0;
    for (size_t k = 0; b && k < b->n; ++k)
        sb += jbool(b->items[k], "significant") == 1;
    for (size_t k = 0; a && k < a->n; ++k)
        sa += jbool(a->items[k], "significant") == 1;
    fprintf(f, "<details><summary>Structure of the residuals: %zu of %zu tests significant with the geometry alone, "
               "%zu with the chosen effects</summary>\n",
            sb, b ? b->n : 0, sa);
    fputs("<table><tr><th class=\"l\">regressor</th><th>dof</th><th>F before</th><th>p before</th><th>R&sup2; before"
          "</th><th>F after</th><th>p after</th></tr>\n",
          f);
    for (size_t k = 0; b && k < b->n; ++k) {
        const rch_json *t = b->items[k], *u = a && k < a->n ? a->items[k] : NULL;
        fputs("<tr><td class=\"l\">", f);
        put_str(r, jstr(t, "variable"));
        fputs("</td><td>", f);
        put_num(r, jnum(t, "dof1"), "%.0f");
        fputs(", ", f);
        put_num(r, jnum(t, "dof2"), "%.0f");
        fputs("</td><td>", f);
        put_num(r, jnum(t, "f"), "%.3g");
        fputs("</td><td>", f);
        put_p(r, jnum(t, "p"));
        fputs("</td><td>", f);
        put_num(r, jnum(t, "r2"), "%.3g");
        fputs("</td><td>", f);
        put_num(r, jnum(u, "f"), "%.3g");
        fputs("</td><td>", f);
        put_p(r, jnum(u, "p"));
        fputs("</td></tr>\n", f);
    }
    fputs("</table></details>\n", f);
}

static void sec_diag(rep *r, const crow *c, size_t n)
{
    FILE *f = r->f;
    section(r, "section 5 (diagnosis)", NULL);
    fputs("<section id=\"diagnosis\"><h2>5. Diagnosis: what the model misses</h2>\n", f);
    if (!r->diag) {
        section(r, "the diagnosis", HOW_DIAG);
        fputs("<p>", f);
        put_str(r, NULL);
        fputs(": no diagnosis was given (run <code>rcal diagnose --data FILE --json</code> and pass its output "
              "with <code>--diagnosis</code>).</p></section>\n",
              f);
        return;
    }
    const double fl = jnum(r->diag, "noise_floor_mm"), ra = jnum(r->diag, "rmse_after_mm");
    fputs("<p class=\"verdict\">verdict: <b>", f);
    put_str(r, jstr(r->diag, "effect"));
    if (isfinite(jnum(r->diag, "joint")))
        fprintf(f, " (joint %.0f)", jnum(r->diag, "joint"));
    fputs("</b>", f);
    const char *why = jstr(r->diag, "remaining_why");
    if (why && *why) {
        fputs("<br><span class=\"note\">what is left after it: ", f);
        put_esc(f, why);
        fputs("</span>", f);
    }
    fputs("</p>\n<table class=\"kv\">\n", f);
    kv(r, "after the chosen effects");
    put_str(r, jstr(r->diag, "remaining"));
    kv_end(r);
    kv(r, "held-out RMSE");
    fputs("geometry only ", f);
    put_num(r, jnum(r->diag, "rmse_before_mm"), "%.4f mm");
    fputs(", with the chosen effects ", f);
    put_num(r, ra, "%.4f mm");
    if (isfinite(fl) && fl > 0 && isfinite(ra))
        fprintf(f, " = %.2f &times; the noise floor (%.4g mm)", ra / fl, fl);
    kv_end(r);
    kv(r, "effects added, in order");
    const rch_json *seq = jarr(r->diag, "sequence");
    for (size_t k = 0; seq && k < seq->n; ++k) {
        fputs(k ? ", " : "", f);
        put_str(r, seq->items[k]->type == RCH_JSTR ? seq->items[k]->str : NULL);
    }
    fputs(!seq ? NA : seq->n == 0 ? "none" : "", f);
    kv_end(r);
    kv(r, "samples, groups, folds");
    put_num(r, jnum(r->diag, "n"), "%.0f");
    fputs(", ", f);
    put_num(r, jnum(r->diag, "groups"), "%.0f");
    fputs(", ", f);
    put_num(r, jnum(r->diag, "folds"), "%.0f");
    kv_end(r);
    fputs("</table>\n", f);
    if (n) {
        cands_chart(r, c, n);
        cands_table(r, c, n);
    }
    const rch_json *ps = jarr(r->diag, "params");
    if (ps && ps->n) {
        static const jcol cols[] = {{"name", "name", 's', NULL},
                                    {"value", "value", 'n', "%.5g"},
                                    {"std error", "se", 'n', "%.2g"},
                                    {"unit", "unit", 's', NULL}};
        fputs("<h3>Parameters of the chosen effects</h3>\n", f);
        json_table(r, ps, cols, sizeof cols / sizeof cols[0]);
    }
    structure_table(r);
    const rch_json *notes = jarr(r->diag, "not_identifiable");
    for (size_t k = 0; notes && k < notes->n; ++k) {
        fputs(k ? "<br>" : "<p class=\"note\">Not identifiable from these data: ", f);
        put_str(r, notes->items[k]->type == RCH_JSTR ? notes->items[k]->str : NULL);
        fputs(k + 1 == notes->n ? "</p>\n" : "", f);
    }
    fputs("</section>\n", f);
}

static void accuracy_chart(rep *r, const arow *a, size_t n)
{
    if (n == 0)
        return;
    const char *labels[10];
    double v[10];
    unsigned char col[10], leg[3];
    const char *leg_label[3];
    int used[C_N] = {0};
    size_t n_leg = 0;
    for (size_t k = 0; k < n; ++k) {
        labels[k] = a[k].label;
        v[k] = a[k].v;
        col[k] = a[k].col;
        used[a[k].col] = 1;
    }
    if (used[C_PRED]) {
        leg[n_leg] = C_PRED;
        leg_label[n_leg++] = "predicted 95 % (longest semi-axis)";
    }
    if (used[C_BEFORE]) {
        leg[n_leg] = C_BEFORE;
        leg_label[n_leg++] = "nominal, against the truth";
    }
    if (used[C_AFTER]) {
        leg[n_leg] = C_AFTER;
        leg_label[n_leg++] = "calibrated, against the truth";
    }
    chart c;
    memset(&c, 0, sizeof c);
    c.title = "Flange-position accuracy over the workspace";
    c.xlabel = "predicted 95 % flange-position uncertainty (mm)";
    c.n_rows = n;
    c.n_sub = 1;
    c.label = labels;
    c.v = v;
    c.col = col;
    c.bars = 1;
    c.leg = leg;
    c.leg_label = leg_label;
    c.n_leg = n_leg;
    c.width_px = 700;
    chart_svg(r, &c);
}

static void sec_accuracy(rep *r, const arow *a, size_t n)
{
    FILE *f = r->f;
    section(r, "section 6 (predicted accuracy)", NULL);
    fputs("<section id=\"accuracy\"><h2>6. Predicted accuracy over the workspace</h2>\n<table class=\"kv\">\n", f);
    kv(r, "flange position, 95 %");
    fputs("inside the data &plusmn;", f);
    put_sig(r, jnum(r->unc, "position95_mm.data_median"), " mm");
    fputs(" (median; up to &plusmn;", f);
    put_sig(r, jnum(r->unc, "position95_mm.data_max"), " mm");
    fputs("), whole workspace &plusmn;", f);
    put_sig(r, jnum(r->unc, "position95_mm.workspace_median"), " mm");
    fputs(" (median; up to &plusmn;", f);
    put_sig(r, jnum(r->unc, "position95_mm.workspace_max"), " mm");
    fputs(")", f);
    kv_end(r);
    kv(r, "flange orientation, 95 %");
    fputs("inside the data &plusmn;", f);
    put_sig(r, jnum(r->unc, "orientation95_deg.data_median"), "&deg;");
    fputs(" (median; up to &plusmn;", f);
    put_sig(r, jnum(r->unc, "orientation95_deg.data_max"), "&deg;");
    fputs("); orientation determined: ", f);
    const int od = jbool(r->unc, "orientation_determined");
    put_str(r, od < 0 ? NULL : od ? "yes" : "no (compensate position only)");
    kv_end(r);
    kv(r, "against a simulated truth");
    const rch_json *t = jpath(r->cal, "truth_flange");
    if (t) {
        fputs("flange-position error over random poses in the joint limits (base heading and height aligned): "
              "before RMS ",
              f);
        put_num(r, jnum(t, "before_rms_mm"), "%.4f mm");
        fputs(", max ", f);
        put_num(r, jnum(t, "before_max_mm"), "%.4f mm");
        fputs("; after RMS ", f);
        put_num(r, jnum(t, "after_rms_mm"), "%.4f mm");
        fputs(", max ", f);
        put_num(r, jnum(t, "after_max_mm"), "%.4f mm");
    } else {
        fputs(NA " (only a simulation has a truth: <code>rcal calibrate --truth</code>)", f);
        missing(r, "the comparison against a simulated truth", HOW_TRUTH);
    }
    kv_end(r);
    fputs("</table>\n", f);
    if (r->unc)
        fprintf(f, "<p class=\"note\">Uncertainty %s.</p>\n", r->unc_from);
    accuracy_chart(r, a, n);
    fputs("</section>\n", f);
}

static void sec_warnings(rep *r)
{
    FILE *f = r->f;
    fputs("<section id=\"warnings\"><h2>7. Warnings</h2>\n", f);
    if (r->n_warn == 0)
        fputs("<p>none</p>\n", f);
    else
        fputs("<ul class=\"warn\">\n", f);
    for (unsigned k = 0; k < r->n_warn; ++k) {
        fputs("<li>", f);
        put_esc(f, r->warn[k]);
        fputs("</li>\n", f);
    }
    fputs(r->n_warn ? "</ul></section>\n" : "</section>\n", f);
    r->res->n_warnings = r->n_warn;
}

static void input_row(rep *r, const char *what, const char *path, const rch_json *j)
{
    char hex[65];
    if (!path)
        return;
    kv(r, what);
    fputs("<span class=\"mono\">", r->f);
    put_esc(r->f, path);
    fputs("</span>, format ", r->f);
    put_str(r, jstr(j, "format"));
    fputs(", SHA-256 <span class=\"mono\">", r->f);
    fputs(rch_sha256_file(hex, path) == 0 ? hex : "?", r->f);
    fputs("</span>", r->f);
    kv_end(r);
}

static void sec_provenance(rep *r, const dfile *df, size_t n_df, const char *date)
{
    FILE *f = r->f;
    section(r, "section 8 (provenance)", NULL);
    fputs("<section id=\"provenance\"><h2>8. Provenance</h2>\n<table class=\"kv\">\n", f);
    kv(r, "tool version");
    put_str(r, prov_str(r, "tool"));
    kv_end(r);
    kv(r, "command line");
    fputs("<span class=\"mono\">", f);
    /* calibrate's JSON names it "command" (rch_jw_header); older files "command_line" */
    put_str(r, prov_str(r, "command") ? prov_str(r, "command") : prov_str(r, "command_line"));
    fputs("</span>", f);
    kv_end(r);
    kv(r, "date (UTC)");
    put_str(r, prov_str(r, "date"));
    kv_end(r);
    for (size_t i = 0; i < n_df; ++i) {
        kv(r, "data, SHA-256");
        fputs("<span class=\"mono\">", f);
        put_esc(f, df[i].file);
        fputs(": ", f);
        put_str(r, df[i].sha_rec);
        fputs("</span>", f);
        kv_end(r);
    }
    if (r->prov)
        fprintf(f, "<tr><th></th><td class=\"note\">provenance %s</td></tr>\n", r->prov_from);
    input_row(r, "calibration", r->cfg->cal_path, r->cal);
    input_row(r, "diagnosis", r->cfg->diag_path, r->diag);
    input_row(r, "model file", r->cfg->model_path, r->model);
    kv(r, "this report");
    fputs("<span class=\"mono\">", f);
    put_esc(f, r->cfg->command_line ? r->cfg->command_line : "rcal report");
    fprintf(f, "</span>, rcal %s, ", rc_version());
    put_esc(f, date);
    fputs("; plot data beside it: ", f);
    for (unsigned k = 0; k < r->res->n_csv; ++k) {
        const char *base = strrchr(r->res->csv[k], '/');
        fputs(k ? ", " : "", f);
        put_esc(f, base ? base + 1 : r->res->csv[k]);
    }
    kv_end(r);
    fputs("</table></section>\n</main>\n</body>\n</html>\n", f);
}

/* ---- CSV files of the plots */

static void csv_metrics(FILE *f, const rep *r)
{
    static const char *const sets[4][2] = {
        {"evaluated", "before"}, {"evaluated", "after"}, {"training", "train_before"}, {"training", "train_after"}};
    fputs("set,model,metric,value_mm\n", f);
    for (size_t s = 0; s < 4; ++s)
        for (size_t k = 0; k < N_METRICS; ++k) {
            char path[64];
            snprintf(path, sizeof path, "%s.%s", sets[s][1], metric_defs[k].key);
            fprintf(f, "%s,%s,%s,", s < 2 && jbool(r->cal, "held_out") != 0 ? "held-out" : sets[s][0],
                    strstr(sets[s][1], "before") ? "before" : "after", metric_defs[k].key);
            csv_num(f, jnum(r->cal, path));
            fputc('\n', f);
        }
}

static void csv_params(FILE *f, const prow *p, size_t n)
{
    fputs("name,unit,nominal,calibrated,correction,std_error,ci95_low,ci95_high,class,compensation\n", f);
    for (size_t k = 0; k < n; ++k) {
        const double v[6] = {p[k].nominal, p[k].value, p[k].delta, p[k].se, p[k].ci_lo, p[k].ci_hi};
        rch_csv_field(f, p[k].name);
        fputc(',', f);
        rch_csv_field(f, p[k].unit);
        for (size_t i = 0; i < 6; ++i) {
            fputc(',', f);
            csv_num(f, v[i]);
        }
        fputc(',', f);
        rch_csv_field(f, p[k].cls);
        fputc(',', f);
        rch_csv_field(f, p[k].comp);
        fputc('\n', f);
    }
}

static void csv_accuracy(FILE *f, const arow *a, size_t n)
{
    fputs("quantity,value_mm\n", f);
    for (size_t k = 0; k < n; ++k) {
        rch_csv_field(f, a[k].label);
        fputc(',', f);
        csv_num(f, a[k].v);
        fputc('\n', f);
    }
}

static void csv_cands(FILE *f, const crow *c, size_t n)
{
    fputs("step,effect,joint,params,identifiable,tested,rmse_cv_mm,gain_mm2,gain_se_mm2,gain_ci95_low,"
          "gain_ci95_high,z,p,significant,chosen,note\n",
          f);
    for (size_t k = 0; k < n; ++k) {
        const double v[4] = {c[k].step, c[k].joint, c[k].params, c[k].ident};
        const double w[7] = {c[k].rmse_cv, c[k].gain, c[k].gain_se, c[k].gain - Z95 * c[k].gain_se,
                             c[k].gain + Z95 * c[k].gain_se, c[k].z, c[k].p};
        csv_num(f, v[0]);
        fputc(',', f);
        rch_csv_field(f, c[k].effect);
        for (size_t i = 1; i < 4; ++i) {
            fputc(',', f);
            csv_num(f, v[i]);
        }
        fprintf(f, ",%d", c[k].tested);
        for (size_t i = 0; i < 7; ++i) {
            fputc(',', f);
            if (c[k].tested)
                csv_num(f, w[i]);
        }
        fprintf(f, ",%d,%d,", c[k].significant, c[k].chosen);
        rch_csv_field(f, c[k].note);
        fputc('\n', f);
    }
}

/* ---- driver */

static rch_json *load_kind(const char *path, const char *opt, const char *need, const char *kind, rch_diag *d)
{
    rch_json *j = rch_json_load(path, d);
    if (j && (j->type != RCH_JOBJ || !rch_json_get(j, need))) {
        rch_diag_set(d, path, 0, 0, "%s: not %s (it has no member \"%s\")", opt, kind, need);
        rch_json_free(j);
        return NULL;
    }
    return j;
}

typedef struct {
    rch_json *cal, *diag, *model;
    prow *p;
    crow *c;
    size_t n_p, n_c, n_a, n_df;
    arow a[10];
    dfile df[MAX_DFILES];
    rch_out out[1 + RCH_REPORT_MAX_CSV];
    unsigned n_out;
} job;

static void job_free(job *j)
{
    for (unsigned k = 0; k < j->n_out; ++k)
        rch_out_abort(&j->out[k]);
    rch_json_free(j->cal);
    rch_json_free(j->diag);
    rch_json_free(j->model);
    free(j->p);
    free(j->c);
}

static int job_load(job *j, rep *r, const rch_report_cfg *cfg, rch_diag *d)
{
    j->cal = load_kind(cfg->cal_path, "--calibration", "before", "the output of rcal calibrate --json", d);
    if (!j->cal)
        return -1;
    if (cfg->diag_path && !(j->diag = load_kind(cfg->diag_path, "--diagnosis", "candidates",
                                                "the output of rcal diagnose --json", d)))
        return -1;
    if (cfg->model_path &&
        !(j->model = load_kind(cfg->model_path, "--model", "dh", "a model file (rcal-model/1 or /2)", d)))
        return -1;
    r->cal = j->cal;
    r->diag = j->diag;
    r->model = j->model;
    r->unc = jpath(j->cal, "uncertainty");
    r->unc_from = "from the calibration run";
    if (!r->unc && j->model) {
        r->unc = jpath(j->model, "uncertainty");
        r->unc_from = "from the model file";
    }
    r->prov = jpath(j->cal, "provenance");
    r->prov_from = "from the calibration run";
    if (!r->prov && j->model) {
        r->prov = jpath(j->model, "provenance");
        r->prov_from = "from the model file";
    }
    j->p = params_read(r, &j->n_p);
    j->c = cands_read(r, &j->n_c);
    j->n_a = accuracy_read(r, j->a);
    j->n_df = data_files(r, j->df);
    return 0;
}

int rch_report_csv_path(char *buf, size_t cap, const char *page, const char *name)
{
    size_t n = strlen(page);
    if (n > 5 && strcmp(page + n - 5, ".html") == 0)
        n -= 5;
    else if (n > 4 && strcmp(page + n - 4, ".htm") == 0)
        n -= 4;
    const int w = snprintf(buf, cap, "%.*s_%s.csv", (int)n, page, name);
    return w >= 0 && (size_t)w < cap ? 0 : -1;
}

/* Open the HTML and the CSVs beside it (temporary files until committed). */
static int job_open(job *j, rep *r, const rch_report_cfg *cfg, rch_diag *d)
{
    const char *inputs[3 + MAX_DFILES] = {cfg->cal_path, cfg->diag_path, cfg->model_path};
    for (size_t i = 0; i < j->n_df; ++i)
        inputs[3 + i] = j->df[i].file;
    const size_t n_in = 3 + j->n_df;
    if (rch_out_open(&j->out[0], cfg->out_path, "--out", inputs, n_in, d) != 0)
        return -1;
    j->n_out = 1;
    const char *names[RCH_REPORT_MAX_CSV];
    unsigned n = 0;
    names[n++] = "metrics";
    if (j->n_p)
        names[n++] = "params";
    if (j->n_a)
        names[n++] = "accuracy";
    if (j->n_c)
        names[n++] = "candidates";
    for (unsigned k = 0; k < n; ++k) {
        char *path = r->res->csv[k];
        if (rch_report_csv_path(path, sizeof r->res->csv[k], cfg->out_path, names[k]) != 0) {
            rch_diag_set(d, cfg->out_path, 0, 0, "--out: path too long for the plot data beside it");
            return -1;
        }
        if (rch_path_same(path, cfg->out_path)) {
            rch_diag_set(d, path, 0, 0, "--out: the page would be overwritten by its own plot data; name it "
                                        "otherwise");
            return -1;
        }
        if (rch_out_open(&j->out[j->n_out], path, "--out (plot data beside the page)", inputs, n_in, d) != 0)
            return -1;
        j->n_out++;
        r->res->n_csv++;
    }
    return 0;
}

static void job_write(job *j, rep *r, const char *date)
{
    warn_fit(r);
    warn_params(r, j->p, j->n_p);
    warn_diag(r);
    warn_inputs(r, j->df, j->n_df);
    r->f = j->out[0].f;
    page_head(r, r->n_warn);
    sec_data(r, j->df, j->n_df);
    sec_split(r);
    sec_metrics(r);
    sec_params(r, j->p, j->n_p);
    sec_diag(r, j->c, j->n_c);
    sec_accuracy(r, j->a, j->n_a);
    sec_warnings(r);
    sec_provenance(r, j->df, j->n_df, date);
    unsigned k = 1;
    csv_metrics(j->out[k++].f, r);
    if (j->n_p)
        csv_params(j->out[k++].f, j->p, j->n_p);
    if (j->n_a)
        csv_accuracy(j->out[k++].f, j->a, j->n_a);
    if (j->n_c)
        csv_cands(j->out[k++].f, j->c, j->n_c);
}

int rch_report_write(rch_report_result *res, const rch_report_cfg *cfg, rch_diag *d)
{
    memset(res, 0, sizeof *res);
    if (!cfg || !cfg->cal_path || !cfg->out_path) {
        rch_diag_set(d, "", 0, 0, "report: --calibration and --out are required");
        return -1;
    }
    if (strcmp(cfg->out_path, "-") == 0) {
        rch_diag_set(d, "", 0, 0, "--out: the report needs a file (its plot data are written beside it)");
        return -1;
    }
    char date[32];
    if (cfg->date_utc) {
        snprintf(date, sizeof date, "%s", cfg->date_utc);
    } else {
        const time_t t = time(NULL);
        struct tm tm;
        if (!gmtime_r(&t, &tm) || strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm) == 0)
            snprintf(date, sizeof date, "?");
    }
    rep *r = calloc(1, sizeof *r);
    job j;
    memset(&j, 0, sizeof j);
    int rc = -1;
    if (!r) {
        rch_diag_set(d, "", 0, 0, "report: out of memory");
        return -1;
    }
    r->cfg = cfg;
    r->res = res;
    if (job_load(&j, r, cfg, d) != 0 || job_open(&j, r, cfg, d) != 0)
        goto done;
    job_write(&j, r, date);
    for (unsigned k = 0; k < j.n_out; ++k)
        if (ferror(j.out[k].f)) {
            rch_diag_set(d, j.out[k].path, 0, 0, "write error");
            goto done;
        }
    /* whole or not at all: every file written and synced before any is renamed */
    if (rch_out_commit_all(j.out, j.n_out, d) != 0)
        goto done;
    j.n_out = 0;
    rc = 0;
done:
    job_free(&j);
    free(r);
    if (rc != 0)
        memset(res, 0, sizeof *res);
    return rc;
}
