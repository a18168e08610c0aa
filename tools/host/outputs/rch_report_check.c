/* SPDX-License-Identifier: MIT */
/* rch_report_check.c - sections 5 to 8 of the report: the diagnosis (what
 * the model misses: verdict, candidates' chart and table, the structure of
 * the residuals), the predicted accuracy over the workspace (against a
 * simulated truth when there is one), the warnings and the provenance (with
 * the inputs' hashes and the report's own command line). Depends on: the
 * model, the charts and the page's pieces (rch_report_int.h), rch_sha256,
 * rc_version. Memory: the candidates' chart arrays on the heap, freed
 * before return. Errors: none (an allocation failure leaves a chart out). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_version.h"
#include "rch_report_int.h"
#include "rch_sha256.h"

static void cands_table(rep *r, const crow *c, size_t n)
{
    FILE *f = r->f;
    fputs("<table><tr><th class=\"l\">step: effect</th><th>params (identifiable)</th><th>held-out RMSE (mm)</th>"
          "<th>gain (mm&sup2;)</th><th>&plusmn; SE</th><th>z</th><th>p</th><th class=\"l\">verdict</th>"
          "<th class=\"l\">note</th></tr>\n",
          f);
    for (size_t k = 0; k < n; ++k) {
        fputs("<tr><td class=\"l\">", f);
        rch_rep_put_esc(f, c[k].label);
        fputs("</td><td>", f);
        rch_rep_put_num(r, c[k].params, "%.0f");
        fputs(" (", f);
        rch_rep_put_num(r, c[k].ident, "%.0f");
        fputs(")</td><td>", f);
        if (c[k].tested) {
            rch_rep_put_num(r, c[k].rmse_cv, "%.5f");
            fputs("</td><td>", f);
            rch_rep_put_num(r, c[k].gain, "%.3g");
            fputs("</td><td>", f);
            rch_rep_put_num(r, c[k].gain_se, "%.2g");
            fputs("</td><td>", f);
            rch_rep_put_num(r, c[k].z, "%.2f");
            fputs("</td><td>", f);
            rch_rep_put_p(r, c[k].p);
        } else {
            fputs("not tested</td><td></td><td></td><td></td><td>", f);
        }
        fprintf(f, "</td><td class=\"l\"><span class=\"sw\" style=\"background:%s\"></span>%s</td><td class=\"l w\">",
                rch_rep_colour[c[k].chosen ? C_CHOSEN : c[k].significant ? C_SIGNIF : C_NOTSIG],
                c[k].chosen ? "chosen" : c[k].significant ? "significant" : c[k].tested ? "no gain" : "&mdash;");
        rch_rep_put_esc(f, c[k].note);
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
        rch_rep_chart_svg(r, &ch);
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
        rch_rep_put_str(r, jstr(t, "variable"));
        fputs("</td><td>", f);
        rch_rep_put_num(r, jnum(t, "dof1"), "%.0f");
        fputs(", ", f);
        rch_rep_put_num(r, jnum(t, "dof2"), "%.0f");
        fputs("</td><td>", f);
        rch_rep_put_num(r, jnum(t, "f"), "%.3g");
        fputs("</td><td>", f);
        rch_rep_put_p(r, jnum(t, "p"));
        fputs("</td><td>", f);
        rch_rep_put_num(r, jnum(t, "r2"), "%.3g");
        fputs("</td><td>", f);
        rch_rep_put_num(r, jnum(u, "f"), "%.3g");
        fputs("</td><td>", f);
        rch_rep_put_p(r, jnum(u, "p"));
        fputs("</td></tr>\n", f);
    }
    fputs("</table></details>\n", f);
}

void rch_rep_sec_diag(rep *r, const crow *c, size_t n)
{
    FILE *f = r->f;
    rch_rep_section(r, "section 5 (diagnosis)", NULL);
    fputs("<section id=\"diagnosis\"><h2>5. Diagnosis: what the model misses</h2>\n", f);
    if (!r->diag) {
        rch_rep_section(r, "the diagnosis", HOW_DIAG);
        fputs("<p>", f);
        rch_rep_put_str(r, NULL);
        fputs(": no diagnosis was given (run <code>rcal diagnose --data FILE --json</code> and pass its output "
              "with <code>--diagnosis</code>).</p></section>\n",
              f);
        return;
    }
    const double fl = jnum(r->diag, "noise_floor_mm"), ra = jnum(r->diag, "rmse_after_mm");
    fputs("<p class=\"verdict\">verdict: <b>", f);
    rch_rep_put_str(r, jstr(r->diag, "effect"));
    if (isfinite(jnum(r->diag, "joint")))
        fprintf(f, " (joint %.0f)", jnum(r->diag, "joint"));
    fputs("</b>", f);
    const char *why = jstr(r->diag, "remaining_why");
    if (why && *why) {
        fputs("<br><span class=\"note\">what is left after it: ", f);
        rch_rep_put_esc(f, why);
        fputs("</span>", f);
    }
    fputs("</p>\n<table class=\"kv\">\n", f);
    rch_rep_kv(r, "after the chosen effects");
    rch_rep_put_str(r, jstr(r->diag, "remaining"));
    rch_rep_kv_end(r);
    rch_rep_kv(r, "held-out RMSE");
    fputs("geometry only ", f);
    rch_rep_put_num(r, jnum(r->diag, "rmse_before_mm"), "%.4f mm");
    fputs(", with the chosen effects ", f);
    rch_rep_put_num(r, ra, "%.4f mm");
    if (isfinite(fl) && fl > 0 && isfinite(ra))
        fprintf(f, " = %.2f &times; the noise floor (%.4g mm)", ra / fl, fl);
    rch_rep_kv_end(r);
    rch_rep_kv(r, "effects added, in order");
    const rch_json *seq = jarr(r->diag, "sequence");
    for (size_t k = 0; seq && k < seq->n; ++k) {
        fputs(k ? ", " : "", f);
        rch_rep_put_str(r, seq->items[k]->type == RCH_JSTR ? seq->items[k]->str : NULL);
    }
    fputs(!seq ? NA : seq->n == 0 ? "none" : "", f);
    rch_rep_kv_end(r);
    rch_rep_kv(r, "samples, groups, folds");
    rch_rep_put_num(r, jnum(r->diag, "n"), "%.0f");
    fputs(", ", f);
    rch_rep_put_num(r, jnum(r->diag, "groups"), "%.0f");
    fputs(", ", f);
    rch_rep_put_num(r, jnum(r->diag, "folds"), "%.0f");
    rch_rep_kv_end(r);
    fputs("</table>\n", f);
    const rch_json *ss = jarr(r->diag, "sensors");
    if (ss && ss->n) {
        static const jcol scols[] = {{"sensor", "name", 's', NULL},
                                     {"rows", "rows", 'n', "%.0f"},
                                     {"held-out before (mm)", "before_mm", 'n', "%.4f"},
                                     {"after (mm)", "after_mm", 'n', "%.4f"},
                                     {"floor (mm)", "floor_mm", 'n', "%.4f"}};
        fputs("<h3>Held-out error by sensor (RMS; 3-D for a tracker)</h3>\n", f);
        rch_rep_json_table(r, ss, scols, sizeof scols / sizeof scols[0]);
    }
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
        rch_rep_json_table(r, ps, cols, sizeof cols / sizeof cols[0]);
    }
    structure_table(r);
    const rch_json *notes = jarr(r->diag, "not_identifiable");
    for (size_t k = 0; notes && k < notes->n; ++k) {
        fputs(k ? "<br>" : "<p class=\"note\">Not identifiable from these data: ", f);
        rch_rep_put_str(r, notes->items[k]->type == RCH_JSTR ? notes->items[k]->str : NULL);
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
    rch_rep_chart_svg(r, &c);
}

void rch_rep_sec_accuracy(rep *r, const arow *a, size_t n)
{
    FILE *f = r->f;
    rch_rep_section(r, "section 6 (predicted accuracy)", NULL);
    fputs("<section id=\"accuracy\"><h2>6. Predicted accuracy over the workspace</h2>\n<table class=\"kv\">\n", f);
    const aim_fig *am = &r->aim;
    /* the flange's workspace figure comes from the model file when the data see another point */
    rch_rep_section(r, "section 6 (predicted accuracy)", am->seen ? HOW_MODEL : NULL);
    rch_rep_kv(r, "flange position, 95 %");
    fputs("inside the data &plusmn;", f);
    rch_rep_put_sig(r, am->after_median, " mm");
    fputs(" (median; up to &plusmn;", f);
    rch_rep_put_sig(r, am->after_max, " mm");
    fputs("), whole workspace &plusmn;", f);
    rch_rep_put_sig(r, am->ws_median, " mm");
    fputs(" (median; up to &plusmn;", f);
    rch_rep_put_sig(r, am->ws_max, " mm");
    fputs(")", f);
    rch_rep_kv_end(r);
    if (am->seen) {
        /* the calibration's map is at the point the data see */
        rch_rep_kv(r, "the point the data see, 95 %");
        rch_rep_put_esc(f, am->seen);
        fputs(": inside the data &plusmn;", f);
        rch_rep_put_sig(r, jnum(r->unc, "position95_mm.data_median"), " mm");
        fputs(" (median; up to &plusmn;", f);
        rch_rep_put_sig(r, jnum(r->unc, "position95_mm.data_max"), " mm");
        fputs("), whole workspace &plusmn;", f);
        rch_rep_put_sig(r, jnum(r->unc, "position95_mm.workspace_median"), " mm");
        fputs(" (compensation never aims at it)", f);
        rch_rep_kv_end(r);
    }
    rch_rep_kv(r, "flange, uncompensated");
    if (isfinite(am->before_median)) {
        fputs("the nominal table misses it by ", f);
        rch_rep_put_sig(r, am->before_median, " mm");
        fputs(" (median; up to ", f);
        rch_rep_put_sig(r, am->before_max, " mm");
        fprintf(f, ") over %s%zu poses, as the calibrated model predicts", am->before_over_data ? "the data's " : "",
                am->before_n);
        if (!am->before_over_data)
            fputs(" (random, in the joint limits: the data files cannot be read from here)", f);
    } else {
        fputs(NA, f);
        rch_rep_missing(r, "the uncompensated figure", HOW_MODEL);
    }
    rch_rep_kv_end(r);
    rch_rep_kv(r, "flange orientation, 95 %");
    fputs("inside the data &plusmn;", f);
    rch_rep_put_sig(r, jnum(r->unc, "orientation95_deg.data_median"), "&deg;");
    fputs(" (median; up to &plusmn;", f);
    rch_rep_put_sig(r, jnum(r->unc, "orientation95_deg.data_max"), "&deg;");
    fputs("); orientation determined: ", f);
    const int od = jbool(r->unc, "orientation_determined");
    rch_rep_put_str(r, od < 0 ? NULL : od ? "yes" : "no (compensate position only)");
    rch_rep_kv_end(r);
    rch_rep_kv(r, "against a simulated truth");
    const rch_json *t = rch_rep_jpath(r->cal, "truth_flange");
    if (t) {
        fputs("flange-position error over random poses in the joint limits (base heading and height aligned): "
              "before RMS ",
              f);
        rch_rep_put_num(r, jnum(t, "before_rms_mm"), "%.4f mm");
        fputs(", max ", f);
        rch_rep_put_num(r, jnum(t, "before_max_mm"), "%.4f mm");
        fputs("; after RMS ", f);
        rch_rep_put_num(r, jnum(t, "after_rms_mm"), "%.4f mm");
        fputs(", max ", f);
        rch_rep_put_num(r, jnum(t, "after_max_mm"), "%.4f mm");
    } else {
        fputs(NA " (only a simulation has a truth: <code>rcal calibrate --truth</code>)", f);
        rch_rep_missing(r, "the comparison against a simulated truth", HOW_TRUTH);
    }
    rch_rep_kv_end(r);
    fputs("</table>\n", f);
    if (r->unc)
        fprintf(f, "<p class=\"note\">Uncertainty %s.</p>\n", r->unc_from);
    accuracy_chart(r, a, n);
    fputs("</section>\n", f);
}

void rch_rep_sec_warnings(rep *r)
{
    FILE *f = r->f;
    fputs("<section id=\"warnings\"><h2>7. Warnings</h2>\n", f);
    if (r->n_warn == 0)
        fputs("<p>none</p>\n", f);
    else
        fputs("<ul class=\"warn\">\n", f);
    for (unsigned k = 0; k < r->n_warn; ++k) {
        fputs("<li>", f);
        rch_rep_put_esc(f, r->warn[k]);
        fputs("</li>\n", f);
    }
    fputs(r->n_warn ? "</ul></section>\n" : "</section>\n", f);
    r->res->n_warnings = r->n_warn;
}

/* text (len): the input in memory (a run's own, never read back), else NULL: hashed from path. */
static void input_row(rep *r, const char *what, const char *path, const rch_json *j, const char *text, size_t len)
{
    char hex[65];
    if (!path)
        return;
    rch_rep_kv(r, what);
    fputs("<span class=\"mono\">", r->f);
    rch_rep_put_esc(r->f, path);
    fputs("</span>, format ", r->f);
    rch_rep_put_str(r, jstr(j, "format"));
    fputs(", SHA-256 <span class=\"mono\">", r->f);
    if (text) {
        rch_sha256 c;
        rch_sha256_init(&c);
        rch_sha256_update(&c, text, len);
        rch_sha256_final(&c, hex);
        fputs(hex, r->f);
    } else
        fputs(rch_sha256_file(hex, path) == 0 ? hex : "?", r->f);
    fputs("</span>", r->f);
    rch_rep_kv_end(r);
}

void rch_rep_sec_provenance(rep *r, const dfile *df, size_t n_df, const char *date)
{
    FILE *f = r->f;
    rch_rep_section(r, "section 8 (provenance)", NULL);
    fputs("<section id=\"provenance\"><h2>8. Provenance</h2>\n<table class=\"kv\">\n", f);
    rch_rep_kv(r, "tool version");
    rch_rep_put_str(r, rch_rep_prov_str(r, "tool"));
    rch_rep_kv_end(r);
    rch_rep_kv(r, "command line");
    fputs("<span class=\"mono\">", f);
    /* calibrate's JSON names it "command" (rch_jw_header); older files "command_line" */
    rch_rep_put_str(r, rch_rep_prov_str(r, "command") ? rch_rep_prov_str(r, "command") : rch_rep_prov_str(r, "command_line"));
    fputs("</span>", f);
    rch_rep_kv_end(r);
    rch_rep_kv(r, "date (UTC)");
    rch_rep_put_str(r, rch_rep_prov_str(r, "date"));
    rch_rep_kv_end(r);
    for (size_t i = 0; i < n_df; ++i) {
        rch_rep_kv(r, "data, SHA-256");
        fputs("<span class=\"mono\">", f);
        rch_rep_put_esc(f, df[i].file);
        fputs(": ", f);
        rch_rep_put_str(r, df[i].sha_rec);
        fputs("</span>", f);
        rch_rep_kv_end(r);
    }
    if (r->prov)
        fprintf(f, "<tr><th></th><td class=\"note\">provenance %s</td></tr>\n", r->prov_from);
    const rch_report_cfg *cfg = r->cfg;
    input_row(r, "calibration", cfg->cal_path, r->cal, cfg->cal_text, cfg->cal_len);
    input_row(r, "diagnosis", cfg->diag_path, r->diag, cfg->diag_text, cfg->diag_len);
    input_row(r, "model file", cfg->model_path, r->model, r->mem ? r->mem->model_text : NULL,
              r->mem ? r->mem->model_len : 0);
    rch_rep_kv(r, "this report");
    fputs("<span class=\"mono\">", f);
    rch_rep_put_esc(f, r->cfg->command_line ? r->cfg->command_line : "rcal report");
    fprintf(f, "</span>, rcal %s, ", rc_version());
    rch_rep_put_esc(f, date);
    fputs("; plot data beside it: ", f);
    for (unsigned k = 0; k < r->res->n_csv; ++k) {
        const char *base = strrchr(r->res->csv[k], '/');
        fputs(k ? ", " : "", f);
        rch_rep_put_esc(f, base ? base + 1 : r->res->csv[k]);
    }
    rch_rep_kv_end(r);
    fputs("</table></section>\n</main>\n</body>\n</html>\n", f);
}

