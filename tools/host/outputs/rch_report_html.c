/* SPDX-License-Identifier: MIT */
/* rch_report_html.c - the pieces of the report's page: a value escaped or
 * "not in this run" (counted, with what it stands for and how a run gets
 * it), key-value rows, tables of JSON arrays, the CSS, the page's head and
 * the verdict on the first screen (pass or fail against --tolerance-mm; never
 * a pass when a figure of the page shows the model worse than nominal).
 * Every string from a JSON file goes out through rch_xml_put (files/rch_text).
 * Depends on: rch_text, rch_json (through the model). Memory: none.
 * Errors: none (a write error shows in ferror of the page). See
 * rch_report_int.h. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "rch_report_int.h"
#include "rch_text.h"

void rch_rep_missing(rep *r, const char *what, const char *how)
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

void rch_rep_section(rep *r, const char *name, const char *how)
{
    r->section = r->where = name;
    r->how = how;
}

void rch_rep_put_esc(FILE *f, const char *s) { rch_xml_put(f, s, 0); }

/* A JSON string escaped, or "not in this run". */
void rch_rep_put_str(rep *r, const char *s)
{
    if (s) {
        rch_rep_put_esc(r->f, s);
    } else {
        fputs(NA, r->f);
        rch_rep_missing(r, r->where, r->how);
    }
}

/* A number with printf format fmt, or "not in this run". */
void rch_rep_put_num(rep *r, double v, const char *fmt)
{
    if (isfinite(v)) {
        fprintf(r->f, fmt, v);
    } else {
        fputs(NA, r->f);
        rch_rep_missing(r, r->where, r->how);
    }
}

/* Three significant digits without an exponent between 1e-3 and 1e6
 * ("1610 mm", not "1.61e+03 mm"), then `unit`; or "not in this run". */
void rch_rep_put_sig(rep *r, double v, const char *unit)
{
    const double a = fabs(v);
    if (isfinite(v) && a >= 1e-3 && a < 1e6) {
        const int dec = 2 - (int)floor(log10(a));
        fprintf(r->f, "%.*f%s", dec > 0 ? dec : 0, v, unit);
    } else {
        rch_rep_put_num(r, v, "%.3g");
        if (isfinite(v))
            fputs(unit, r->f);
    }
}

void rch_rep_put_p(rep *r, double p)
{
    if (isfinite(p) && p <= 0.0)
        fputs("&lt; 1e-300", r->f);
    else
        rch_rep_put_num(r, p, "%.3g");
}

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
    "section{background:#fff;border:1px solid #d6dae0;border-radius:6px;padding:8px 16px 12px;margin:12px 0;"
    "overflow-x:auto}main{overflow-wrap:break-word}svg{max-width:100%;height:auto}"
    "h2{font-size:17px;margin:2px 0 8px;padding-bottom:3px;border-bottom:1px solid #e4e7eb}"
    "h3{font-size:14px;margin:10px 0 4px}"
    "table{border-collapse:collapse;font-size:13px;margin:4px 0}"
    "td,th{padding:1px 8px;border-bottom:1px solid #eceef1;text-align:right;vertical-align:top;white-space:nowrap}"
    "td.w{white-space:normal}.two{display:grid;grid-template-columns:1fr 1fr;gap:12px}.two section{margin:0}"
    "th{background:#f1f3f6;font-weight:600}td.l,th.l{text-align:left;white-space:normal}"
    "table.kv th{text-align:left;background:none;color:#445;font-weight:normal;white-space:nowrap}"
    "table.kv td{text-align:left;white-space:normal}"
    ".na{color:#888;font-style:italic}.mono{font-family:ui-monospace,'DejaVu Sans Mono',monospace;"
    "font-size:12px;word-break:break-all}"
    ".row{display:flex;flex-wrap:wrap;gap:14px;align-items:flex-start}"
    ".tw{flex:1 1 100%;min-width:0;max-width:100%;overflow-x:auto}table.p th{white-space:normal}"
    ".note{color:#556;font-size:12.5px;margin:4px 0}"
    ".verdict{font-size:15px;padding:6px 10px;background:#f4f8fb;border-left:4px solid #009E73}"
    "ul.warn{margin:4px 0;padding-left:0;list-style:none}"
    "ul.warn li{background:#fff6e5;border-left:4px solid #E69F00;padding:4px 10px;margin:4px 0}"
    "svg.chart{border:1px solid #e4e7eb;border-radius:4px;background:#fff}"
    ".sw{display:inline-block;width:10px;height:10px;margin-right:4px;vertical-align:baseline}"
    "details summary{cursor:pointer;color:#234}"
    "@media print{body{background:#fff}main{max-width:none;padding:0}section{break-inside:avoid;border:none}}";

void rch_rep_kv(rep *r, const char *key)
{
    fprintf(r->f, "<tr><th>%s</th><td>", key);
    r->where = key;
}

void rch_rep_kv_end(rep *r)
{
    fputs("</td></tr>\n", r->f);
    r->where = r->section;
}

void rch_rep_json_table(rep *r, const rch_json *arr, const jcol *cols, size_t n_cols)
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
                rch_rep_put_str(r, jstr(arr->items[k], cols[c].key));
            else if (cols[c].kind == 'p')
                rch_rep_put_p(r, jnum(arr->items[k], cols[c].key));
            else
                rch_rep_put_num(r, jnum(arr->items[k], cols[c].key), cols[c].fmt);
            fputs("</td>", f);
        }
        fputs("</tr>\n", f);
    }
    fputs("</table>\n", f);
}

/* The first screen: the verdict (the accuracy of the compensated robot, 95 %,
 * over the data's poses and the workspace; pass or fail against the user's
 * tolerance), the held-out measurements it is checked on, and what it rests
 * on (the prior, the outlets, every nuisance fitted). */
/* The diagnosis on the first screen (when given): its verdict, each sensor's
 * held-out error before and after (3-D for a tracker), what to run next. */
static void diagnosis_glance(rep *r)
{
    FILE *f = r->f;
    if (!r->diag)
        return;
    fputs("<p>Diagnosis: <b>", f);
    rch_rep_put_str(r, jstr(r->diag, "effect"));
    fputs("</b>", f);
    const rch_json *ss = jarr(r->diag, "sensors");
    for (size_t k = 0; ss && k < ss->n; ++k) {
        const rch_json *z = ss->items[k];
        const char *kind = jstr(z, "kind");
        fputs(k ? "; " : "; held-out ", f);
        rch_rep_put_str(r, jstr(z, "name"));
        fputs(kind && strcmp(kind, "tracker") == 0 ? " (3-D) " : " ", f);
        rch_rep_put_num(r, jnum(z, "before_mm"), "%.4f");
        fputs(" &rarr; ", f);
        rch_rep_put_num(r, jnum(z, "after_mm"), "%.4f mm");
    }
    const char *next = jstr(r->diag, "next");
    if (next) {
        fputs(". Next: <code>", f);
        rch_rep_put_esc(f, next);
        fputs("</code>", f);
    }
    fputs(".</p>\n", f);
}

/* One reason more in why (len): "; " before all but the first; n counts. */
static void why_add(char *why, size_t len, unsigned *n, const char *fmt, ...) RCH_PRINTF(4, 5);
static void why_add(char *why, size_t len, unsigned *n, const char *fmt, ...)
{
    const size_t at = strlen(why);
    if (at + 3 < len) {
        va_list ap;
        snprintf(why + at, len - at, "%s", *n ? "; " : "");
        va_start(ap, fmt);
        vsnprintf(why + strlen(why), len - strlen(why), fmt, ap);
        va_end(ap);
    }
    ++*n;
}

/* What the page's own figures say against the nominal model (issue 33):
 * each figure of the calibrated model worse than the nominal one's on the
 * same samples, and a diagnosis that finds error beyond the noise floor
 * that no effect explains. Appended to why (len) as "; "-separated
 * reasons; returns how many. Counted: the held-out cable-length RMSE (the
 * training one when nothing was held out), a validation file's RMSE (when
 * its JSON carries the nominal model's, "validation.before"), the 3-D
 * position error of --positions, every sensor's held-out error in the
 * diagnosis and its RMSE with the chosen effects, the diagnosis saying
 * "unexplained", and the flange against a simulated truth. Equal is not
 * worse. */
static unsigned worse_than_nominal(const rep *r, char *why, size_t len)
{
    unsigned n = 0;
    why[0] = '\0';
    const struct {
        const rch_json *o;
        const char *before, *after, *what;
    } pairs[] = {
        {r->cal, "before.rmse_mm", "after.rmse_mm", "cable-length RMSE"},
        {r->cal, "validation.before.rmse_mm", "validation.residual.rmse_mm", "RMSE on the validation file"},
        {r->cal, "positions.before_mm.rms", "positions.position_error_mm.rms", "3-D position error (rms)"},
        {r->cal, "truth_flange.before_rms_mm", "truth_flange.after_rms_mm", "flange error against the simulated truth"},
        {r->diag, "rmse_before_mm", "rmse_after_mm", "held-out RMSE in the diagnosis"},
    };
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; ++k) {
        const double b = jnum(pairs[k].o, pairs[k].before), a = jnum(pairs[k].o, pairs[k].after);
        if (isfinite(a) && isfinite(b) && a > b)
            why_add(why, len, &n, "%s %.4g mm calibrated against %.4g mm nominal", pairs[k].what, a, b);
    }
    /* the calibration's own judge (rch_calib_judge.c): its noise far beyond what the sensor can produce, or
     * its model worse than the nominal one on its own data */
    const rch_json *jg = rch_rep_jpath(r->cal, "estimation.judge");
    if (jg) {
        const double ra = jnum(jg, "ratio"), fa = jnum(jg, "factor");
        const char *jw = jstr(jg, "why");
        const rch_json *bey = rch_rep_jpath(jg, "beyond"), *wn = rch_rep_jpath(jg, "worse_than_nominal");
        if ((bey && bey->type == RCH_JBOOL && bey->num != 0.0) || (wn && wn->type == RCH_JBOOL && wn->num != 0.0))
            why_add(why, len, &n, "%s", jw ? jw : "the fit's noise is far beyond what its sensor can produce");
        else if (isfinite(ra) && isfinite(fa) && ra > fa)
            why_add(why, len, &n, "the fit's noise is %.3g x what its sensor can produce", ra);
    }
    const rch_json *ss = jarr(r->diag, "sensors");
    for (size_t k = 0; ss && k < ss->n; ++k) {
        const rch_json *z = ss->items[k];
        const double b = jnum(z, "before_mm"), a = jnum(z, "after_mm");
        const char *nm = jstr(z, "name"), *kind = jstr(z, "kind");
        if (isfinite(a) && isfinite(b) && a > b)
            why_add(why, len, &n, "held-out error of %s%s %.4g mm calibrated against %.4g mm nominal",
                    nm ? nm : "a sensor", kind && strcmp(kind, "tracker") == 0 ? " (3-D)" : "", a, b);
    }
    const char *eff = jstr(r->diag, "effect"), *rem = jstr(r->diag, "remaining");
    if ((eff && strcmp(eff, "unexplained") == 0) || (rem && strcmp(rem, "unexplained") == 0)) {
        const double fl = jnum(r->diag, "noise_floor_mm"), ra = jnum(r->diag, "rmse_after_mm");
        if (isfinite(fl) && fl > 0 && isfinite(ra))
            why_add(why, len, &n,
                    "the diagnosis finds structure beyond the noise floor that no effect explains (held-out %.4g mm, "
                    "%.2f x the floor)", ra, ra / fl);
        else
            why_add(why, len, &n, "the diagnosis finds structure beyond the noise floor that no effect explains");
    }
    return n;
}

/* The figures worse_than_nominal reads that no other part of the page
 * shows: a validation file's and the 3-D positions' error, on the first
 * screen. */
static void glance_extra(rep *r)
{
    FILE *f = r->f;
    const double pb = jnum(r->cal, "positions.before_mm.rms"), pa = jnum(r->cal, "positions.position_error_mm.rms");
    if (isfinite(pa)) {
        fputs("<p>Positions (3-D, rms): <b>", f);
        rch_rep_put_num(r, pb, "%.4f");
        fputs(" mm &rarr; ", f);
        rch_rep_put_num(r, pa, "%.4f");
        fputs(" mm</b>", f);
        const double np = jnum(r->cal, "positions.position_error_mm.points");
        if (isfinite(np))
            fprintf(f, " (%.0f points)", np);
        fputs(".</p>\n", f);
    }
    const double vb = jnum(r->cal, "validation.before.rmse_mm"), va = jnum(r->cal, "validation.residual.rmse_mm");
    if (isfinite(va)) {
        fputs("<p>Validation file <b>", f);
        rch_rep_put_str(r, jstr(r->cal, "validation.data"));
        fputs("</b>: cable-length RMSE <b>", f);
        if (isfinite(vb)) {
            rch_rep_put_num(r, vb, "%.4f");
            fputs(" mm &rarr; ", f);
        }
        rch_rep_put_num(r, va, "%.4f");
        fputs(" mm</b>", f);
        if (!isfinite(vb))
            fputs(" <span class=\"note\">(the nominal model's figure on it is not in this run)</span>", f);
        fputs(".</p>\n", f);
    }
}

/* The first screen's "It rests on:" paragraph: the estimation (prior or
 * least squares), the outlets, the attachment, every nuisance fitted. */
static void rests_on(rep *r)
{
    FILE *f = r->f;
    fputs("<p class=\"rests\">It rests on: ", f);
    const rch_json *est = rch_rep_jpath(r->cal, "estimation");
    if (jbool(est, "prior") == 1) {
        fputs("the posterior of a fit with the physical prior (link lengths &plusmn;", f);
        rch_rep_put_sig(r, jnum(est, "prior_length_mm"), " mm");
        fputs(", twists &plusmn;", f);
        rch_rep_put_sig(r, jnum(est, "prior_twist_deg"), "&deg;");
        fputs(", joint zeros &plusmn;", f);
        rch_rep_put_sig(r, jnum(est, "prior_offset_deg"), "&deg;");
        fputs(": what the data did not determine counts at the prior's width), the noise estimated from the data (",
              f);
        rch_rep_put_sig(r, jnum(est, "noise_mm"), " mm");
        fputs(")", f);
    } else if (est) {
        fputs("the covariance of a least-squares fit (no prior: directions the data did not determine are held "
              "nominal and not counted)",
              f);
    } else {
        rch_rep_put_str(r, NULL);
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
    fputs(".</p>\n", f);
}

static void verdict(rep *r, size_t n_warn)
{
    FILE *f = r->f;
    const aim_fig *am = &r->aim; /* at the flange centre: what compensation aims at */
    const double in = am->after_median, in_max = am->after_max, ws = am->ws_median;
    const double tol = r->cfg->tolerance_mm;
    const int have = isfinite(in) && isfinite(in_max);
    char why[1024];
    const unsigned n_worse = worse_than_nominal(r, why, sizeof why);
    const int pass = have && tol > 0.0 && in_max <= tol && n_worse == 0;
    rch_rep_section(r, "the verdict (first screen)", NULL);
    fprintf(f, "<div class=\"glance %s\" id=\"verdict\"><p class=\"big\">",
            n_worse ? "fail" : !have || !(tol > 0.0) ? "" : pass ? "pass" : "fail");
    if (n_worse) {
        if (have && tol > 0.0)
            fprintf(f, "<b>FAIL</b> against the tolerance of %.4g mm%s: ", tol,
                    in_max <= tol ? ", although the predicted accuracy is within it" : "");
        else
            fputs("<b>NOT PASSED</b>: ", f);
        fputs("this page shows the calibrated model worse than the nominal one (<span id=\"verdict-why\">", f);
        rch_rep_put_esc(f, why);
        fputs("</span>).</p>\n<p>", f);
    } else if (have && tol > 0.0)
        fprintf(f, "<b>%s</b> against the tolerance of %.4g mm: ", pass ? "PASS" : "FAIL", tol);
    if (have) {
        fprintf(f, "predicted from the fit, after compensation %s (the point compensation aims at) lands within "
                   "&plusmn;<b id=\"aim-after\">", am->point);
        rch_rep_put_sig(r, in, " mm");
        fputs("</b> (95 %) over the measured region (the median over the data's poses; the largest &plusmn;", f);
        rch_rep_put_sig(r, in_max, " mm");
        fputs(")", f);
        if (isfinite(ws)) {
            fputs(", &plusmn;", f);
            rch_rep_put_sig(r, ws, " mm");
            fputs(" over the whole workspace", f);
        }
        fputs("; <span id=\"aim-before\">before compensation ", f);
        if (isfinite(am->before_median)) {
            fputs("it misses by <strong>", f); /* not a <b>: the verdict colours its first <b> */
            rch_rep_put_sig(r, am->before_median, " mm");
            fputs("</strong> (the median over ", f);
            if (am->before_over_data)
                fprintf(f, "the data's %zu poses", am->before_n);
            else
                fprintf(f, "%zu random poses in the joint limits", am->before_n);
            fputs("; the largest ", f);
            rch_rep_put_sig(r, am->before_max, " mm");
            fputs(": where the nominal table sends it against where the calibrated model puts it)", f);
        } else {
            fputs(NA, f);
            rch_rep_missing(r, "the uncompensated figure", HOW_MODEL);
        }
        fputs("</span>.", f);
        if (am->seen) {
            fprintf(f, " <span class=\"note\">(the data see %s: &plusmn;", am->seen);
            rch_rep_put_sig(r, am->seen_median, " mm");
            fputs(" there; compensation never aims at it)</span>", f);
        }
        if (!(tol > 0.0))
            fputs(" <span class=\"note\">(no tolerance given: <code>rcal report --tolerance-mm MM</code> gives a "
                  "pass or fail)</span>",
                  f);
    } else {
        fputs("No predicted accuracy in this run: the calibration output carries no uncertainty (pass the model "
              "file of the run with <code>--model</code>, or calibrate again with <code>rcal calibrate --json</code>).",
              f);
        rch_rep_missing(r, "the predicted accuracy", HOW_MODEL);
    }
    const double b = jnum(r->cal, "before.rmse_mm"), a = jnum(r->cal, "after.rmse_mm");
    const double nt = jnum(r->cal, "after.n");
    fprintf(f, "</p>\n<p>%s: cable-length RMSE <b>",
            jbool(r->cal, "held_out") == 0 ? "Measured on the training samples (none held out)"
                                           : "Measured on samples the fit never saw");
    rch_rep_put_num(r, b, "%.4f");
    fputs(" mm &rarr; ", f);
    rch_rep_put_num(r, a, "%.4f");
    fputs(" mm</b>", f);
    if (isfinite(nt))
        fprintf(f, " (%.0f samples)", nt);
    if (isfinite(a) && isfinite(b) && b > 0)
        fprintf(f, ", %+.1f %%", 100.0 * (a - b) / b);
    fputs(".</p>\n", f);
    rests_on(r);
    glance_extra(r);
    diagnosis_glance(r);
    fprintf(f, "<p><a href=\"#warnings\">%zu warning%s</a></p></div>\n", n_warn, n_warn == 1 ? "" : "s");
}

void rch_rep_page_head(rep *r, size_t n_warn)
{
    FILE *f = r->f;
    const char *data = jstr(r->cal, "data"), *robot = jstr(r->model, "name");
    fputs("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
          "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Calibration report: ",
          f);
    rch_rep_put_esc(f, data ? data : "?");
    fprintf(f, "</title>\n<style>%s</style>\n</head>\n<body>\n<main>\n<header>\n<h1>Calibration report</h1>\n", css);
    fputs("<p class=\"sub\">robot <b>", f);
    rch_rep_section(r, "the robot's name", HOW_MODEL);
    rch_rep_put_str(r, robot ? robot : jstr(r->cal, "robot"));
    rch_rep_section(r, "the page's head", NULL);
    fputs("</b> &middot; data <b>", f);
    rch_rep_put_str(r, data);
    fputs("</b> &middot; method <b>", f);
    rch_rep_put_str(r, jstr(r->cal, "method"));
    fputs("</b> &middot; calibrated ", f);
    rch_rep_put_str(r, rch_rep_prov_str(r, "date"));
    fputs("</p>\n", f);
    verdict(r, n_warn);
    fputs("</header>\n", f);
}
