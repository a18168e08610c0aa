/* SPDX-License-Identifier: MIT */
/* rch_report_fit.c - sections 1 to 4 of the report: the data (with every
 * nuisance fitted and the data files' hashes, recorded and now), the split,
 * the before/after metrics with their chart, and the identified parameters
 * (table, one chart of corrections per unit, the identifiability at the
 * solution). Depends on: the model, the charts and the page's pieces
 * (rch_report_int.h). Memory: the charts' arrays on the heap, freed before
 * return. Errors: none (an allocation failure leaves a chart out). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_seen.h"

#include "rch_report_int.h"

void rch_rep_sec_data(rep *r, const dfile *df, size_t n_df)
{
    FILE *f = r->f;
    rch_rep_section(r, "section 1 (data)", NULL);
    fputs("<div class=\"two\"><section id=\"data\"><h2>1. Data</h2>\n<table class=\"kv\">\n", f);
    rch_rep_kv(r, "data file");
    rch_rep_put_str(r, jstr(r->cal, "data"));
    rch_rep_kv_end(r);
    rch_rep_kv(r, "samples");
    rch_rep_put_num(r, jnum(r->cal, "n_train") + jnum(r->cal, "n_test"), "%.0f");
    rch_rep_kv_end(r);
    rch_rep_kv(r, "set-up groups");
    r->how = HOW_DIAG; /* the rows up to the files come from a diagnosis when the calibration has none */
    if (isfinite(jnum(r->unc, "groups")) && jnum(r->unc, "groups") > 0) {
        rch_rep_put_num(r, jnum(r->unc, "groups"), "%.0f");
        fputs(" (the covariance's clusters, from the ", f);
        rch_rep_put_str(r, jstr(r->unc, "groups_from"));
        fputs(")", f);
    } else {
        rch_rep_put_num(r, jnum(r->diag, "groups"), "%.0f");
        fputs(r->diag ? " (from the diagnosis)" : "", f);
    }
    rch_rep_kv_end(r);
    /* the nuisance the calibration fitted: every one shown */
    const rch_json *jumps = jarr(r->cal, "length_jumps");
    rch_rep_kv(r, "length jumps (nuisance)");
    if (!jumps)
        fputs("none fitted", f);
    for (size_t k = 0; jumps && k < jumps->n; ++k) {
        const rch_json *jk = jumps->items[k];
        fprintf(f, "%sline %.0f: %+.3f &plusmn; %.3f mm", k ? "<br>" : "", jnum(jk, "line"), jnum(jk, "size_mm"),
                jnum(jk, "se_mm"));
    }
    rch_rep_kv_end(r);
    rch_rep_kv(r, "joint angles");
    if (isfinite(jnum(r->cal, "dequantized.corrected")))
        fprintf(f, "recovered from the file's x, y, z: %.0f rows corrected (RMS %.4f&deg;), %.0f refused and dropped",
                jnum(r->cal, "dequantized.corrected"), jnum(r->cal, "dequantized.dq_rms_deg"),
                jnum(r->cal, "dequantized.refused"));
    else
        fputs("as read (not recovered from x, y, z)", f);
    rch_rep_kv_end(r);
    rch_rep_kv(r, "display resolution");
    fputs("joints ", f);
    if (jnum(r->diag, "q_step_deg") == 0.0)
        fputs("no display step left (recovered from x, y, z, or not rounded)", f);
    else
        rch_rep_put_num(r, jnum(r->diag, "q_step_deg"), "%.4g&deg;");
    fputs(", cable length ", f);
    rch_rep_put_num(r, jnum(r->diag, "len_step_mm"), "%.4g mm");
    rch_rep_kv_end(r);
    rch_rep_kv(r, "noise floor");
    rch_rep_put_num(r, jnum(r->diag, "noise_floor_mm"), "%.4g mm rms");
    if (r->diag) {
        fputs(" (joint display step through the Jacobian ", f);
        rch_rep_put_num(r, jnum(r->diag, "noise_floor_joints_mm"), "%.4g mm");
        fputs(", length step / &radic;12 ", f);
        rch_rep_put_num(r, jnum(r->diag, "noise_floor_length_mm"), "%.4g mm");
        fputs(")", f);
    }
    rch_rep_kv_end(r);
    r->how = NULL;
    for (size_t i = 0; i < n_df; ++i) {
        rch_rep_kv(r, "file, SHA-256");
        fputs("<span class=\"mono\">", f);
        rch_rep_put_esc(f, df[i].file);
        fputs("</span>", f);
        if (isfinite(df[i].samples))
            fprintf(f, ", %.0f samples", df[i].samples);
        fputs("<br>recorded: <span class=\"mono\">", f);
        rch_rep_put_str(r, df[i].sha_rec);
        fputs("</span><br>now: <span class=\"mono\">", f);
        if (df[i].sha_now[0]) {
            fputs(df[i].sha_now, f);
        } else {
            fputs("<span class=\"na\">not read: ", f);
            rch_rep_put_esc(f, df[i].why);
            fputs("</span>", f);
        }
        fputs(df[i].sha_rec && df[i].sha_now[0] ? (strcmp(df[i].sha_rec, df[i].sha_now) ? " (DIFFERS)" : " (same)")
                                                 : "",
              f);
        fputs("</span>", f);
        rch_rep_kv_end(r);
    }
    fputs("</table></section>\n", f);
}

void rch_rep_sec_split(rep *r)
{
    FILE *f = r->f;
    const double ntr = jnum(r->cal, "n_train"), nte = jnum(r->cal, "n_test");
    rch_rep_section(r, "section 2 (split)", NULL);
    fputs("<section id=\"split\"><h2>2. Split</h2>\n<table class=\"kv\">\n", f);
    rch_rep_kv(r, "training samples");
    rch_rep_put_num(r, ntr, "%.0f");
    rch_rep_kv_end(r);
    rch_rep_kv(r, "held-out samples");
    rch_rep_put_num(r, nte, "%.0f");
    if (isfinite(ntr) && isfinite(nte) && ntr + nte > 0)
        fprintf(f, " (%.1f %% of the data)", 100.0 * nte / (ntr + nte));
    rch_rep_kv_end(r);
    rch_rep_kv(r, "seed");
    rch_rep_put_num(r, jnum(r->cal, "seed"), "%.0f");
    rch_rep_kv_end(r);
    if (r->diag) {
        rch_rep_kv(r, "diagnosis");
        rch_rep_put_num(r, jnum(r->diag, "folds"), "%.0f-fold");
        fputs(" cross-validation, folds random within set-up groups", f);
        rch_rep_kv_end(r);
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
    const rch_json *m = rch_rep_jpath(r->cal, key);
    static const char *const keys[] = {"n", "rmse_mm", "mean_abs_mm", "sd_mm", "mean_mm", "max_mm"};
    fprintf(r->f, "<tr><td class=\"l\">%s</td>", label);
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k) {
        fputs("<td>", r->f);
        rch_rep_put_num(r, jnum(m, keys[k]), k ? "%.4f" : "%.0f");
        fputs("</td>", r->f);
    }
    fputs("</tr>\n", r->f);
}

void rch_rep_sec_metrics(rep *r)
{
    FILE *f = r->f;
    const int held = jbool(r->cal, "held_out") != 0;
    rch_rep_section(r, "section 3 (before and after)", NULL);
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
        labels[k] = rch_rep_metric_defs[k].label;
        snprintf(path, sizeof path, "before.%s", rch_rep_metric_defs[k].key);
        v[2 * k] = jnum(r->cal, path);
        snprintf(path, sizeof path, "after.%s", rch_rep_metric_defs[k].key);
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
    rch_rep_chart_svg(r, &c);
    fputs("</div></section>\n", f);
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
    fputs("<table class=\"p\"><tr><th class=\"l\">parameter</th><th>unit</th><th>nominal</th><th>calibrated</th>"
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
        rch_rep_put_esc(f, p[k].name);
        fputs("</td><td>", f);
        rch_rep_put_esc(f, p[k].unit);
        fputs("</td><td>", f);
        rch_rep_put_num(r, p[k].nominal, "%.6g");
        fputs("</td><td>", f);
        rch_rep_put_num(r, p[k].value, "%.6g");
        fputs("</td><td>", f);
        rch_rep_put_num(r, p[k].delta, "%+.4g");
        if (p[k].prior_sd > 0.0 && isfinite(p[k].delta) && fabs(p[k].delta) > 3.0 * p[k].prior_sd)
            fprintf(f, " <span class=\"flag\" title=\"more than 3 prior sd (%.3g) from nominal\">&#9888; &gt; 3 "
                       "prior sd</span>",
                    p[k].prior_sd);
        if (have_se) {
            /* no standard error by design for a parameter the data cannot determine or that was fixed */
            const int none = !isfinite(p[k].se) && (strcmp(p[k].cls, "not identifiable") == 0 ||
                                                    strcmp(p[k].cls, "fixed") == 0 ||
                                                    rch_seen_parse(p[k].cls) == RCH_SEEN_UNSEEN ||
                                                    rch_seen_parse(p[k].cls) == RCH_SEEN_HELD);
            fputs("</td><td>", f);
            if (none)
                fputs("&mdash;", f);
            else
                rch_rep_put_sig(r, p[k].se, "");
            fputs("</td><td>", f);
            if (isfinite(p[k].ci_lo))
                fprintf(f, "%+.3g &hellip; %+.3g", p[k].ci_lo, p[k].ci_hi);
            else if (none)
                fputs("&mdash;", f);
            else
                rch_rep_put_num(r, NAN, "");
        }
        if (have_cls) {
            fprintf(f, "</td><td class=\"l\"><span class=\"sw\" style=\"background:%s\"></span>",
                    rch_rep_colour[rch_rep_class_colour(p[k].cls)]);
            rch_rep_put_str(r, p[k].cls[0] ? p[k].cls : NULL);
        }
        if (have_comp) {
            fputs("</td><td class=\"l\">", f);
            rch_rep_put_str(r, p[k].comp[0] ? p[k].comp : NULL);
        }
        fputs("</td></tr>\n", f);
    }
    fputs("</table>\n", f);
    if (!have_se || !have_cls) {
        fprintf(f, "<p class=\"note\" style=\"max-width:520px\">%s%s%s: " NA ".</p>\n", have_se ? "" : "standard errors and 95 % intervals",
                !have_se && !have_cls ? ", " : "", have_cls ? "" : "identifiability class of each parameter");
        rch_rep_missing(r, !have_se ? "standard errors and 95 % intervals of the parameters"
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
        col[m] = rch_rep_class_colour(p[k].cls);
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
    } classes[] = {{C_IDENT, "determined"},
                   {C_WEAK, "partly"},
                   {C_NOTID, "prior only"},
                   {C_FIXED, "held"},
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
    rch_rep_chart_svg(r, &c);
done:
    free(labels);
    free(v);
    free(col);
}

static void ident_block(rep *r)
{
    FILE *f = r->f;
    const rch_json *id = rch_rep_jpath(r->cal, "identifiability");
    fputs("<h3>Identifiability at the solution</h3>\n", f);
    if (!id) {
        fputs("<p>", f);
        rch_rep_put_str(r, NULL);
        fputs("</p>\n", f);
        return;
    }
    fputs("<p>rank ", f);
    rch_rep_put_num(r, jnum(id, "rank"), "%.0f");
    fputs(" of ", f);
    rch_rep_put_num(r, jnum(id, "params"), "%.0f");
    fputs(" parameters, ", f);
    rch_rep_put_num(r, jnum(id, "weak"), "%.0f");
    fputs(" weak direction(s); condition number ", f);
    rch_rep_put_num(r, jnum(id, "cond"), "%.3g");
    fputs(" over the identifiable part; observability index O1 ", f);
    rch_rep_put_num(r, jnum(id, "observability"), "%.4g");
    fputs("</p>\n", f);
    const rch_json *dirs = jarr(id, "directions");
    if (!dirs || dirs->n == 0)
        return;
    static const jcol cols[] = {{"direction the data do not (or barely) see", "combo", 's', NULL},
                                {"relative singular value", "sv_rel", 'n', "%.2g"},
                                {"identifiable", "identifiable", 's', NULL}};
    rch_rep_json_table(r, dirs, cols, sizeof cols / sizeof cols[0]);
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
    rch_rep_json_table(r, sets, scols, sizeof scols / sizeof scols[0]);
}

void rch_rep_sec_params(rep *r, const prow *p, size_t n)
{
    FILE *f = r->f;
    rch_rep_section(r, "section 4 (parameters)", NULL);
    fputs("<section id=\"params\"><h2>4. Identified parameters</h2>\n<p>solver ", f);
    rch_rep_put_str(r, jstr(r->cal, "method"));
    fputs(": ", f);
    const rch_json *jumps = jarr(r->cal, "length_jumps");
    if (jumps && jnum(r->cal, "iterations") == 0.0) {
        fprintf(f, "fitted with %zu length jump%s (a change-point search, each candidate a fit)", jumps->n,
                jumps->n == 1 ? "" : "s");
    } else {
        rch_rep_put_num(r, jnum(r->cal, "iterations"), "%.0f iterations");
        fputs(", ", f);
        rch_rep_put_num(r, jnum(r->cal, "cost_evals"), "%.0f passes over the data");
        fputs(", exit: ", f);
        rch_rep_put_str(r, jstr(r->cal, "exit"));
    }
    if (jbool(rch_rep_jpath(r->cal, "estimation"), "prior") == 1)
        fputs(", maximum a posteriori with the physical prior", f);
    fputs(", ", f);
    rch_rep_put_num(r, jnum(r->cal, "time_ms"), "%.1f ms");
    fputs(".<br>standard errors: ", f);
    rch_rep_put_str(r, jstr(r->unc, "covariance"));
    if (r->unc) {
        fputs(" covariance", f);
        const double g = jnum(r->unc, "groups");
        const char *from = jstr(r->unc, "groups_from");
        if (isfinite(g) && g > 0)
            fprintf(f, " over %.0f set-up groups", g);
        if (from) {
            fputs(" (from the ", f);
            rch_rep_put_esc(f, from);
            fputs(")", f);
        }
        fputs(", residual &sigma; ", f);
        rch_rep_put_num(r, jnum(r->unc, "sigma_mm"), "%.4g mm");
        fprintf(f, " (%s)", r->unc_from);
    }
    /* the table scrolls inside its own box, never past the page's edge (issue 47: a plate's 37 rows and
     * their flags cut at the right edge) */
    fputs("</p>\n<div class=\"row\"><div class=\"tw\">\n", f);
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
