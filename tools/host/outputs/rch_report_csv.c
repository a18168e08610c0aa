/* SPDX-License-Identifier: MIT */
/* rch_report_csv.c - the data of every plot of the report as CSV beside the
 * page (x.html: x_metrics.csv, x_params.csv, x_accuracy.csv,
 * x_candidates.csv): numbers as %.9g, empty where absent, text fields
 * quoted per RFC 4180 (rch_csv_field). Depends on: rch_plot (the CSV field),
 * the model. Memory: none. Errors: none here (the job checks ferror). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rch_plot.h"
#include "rch_report_int.h"

static void csv_num(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.9g", v);
}

void rch_rep_csv_metrics(FILE *f, const rep *r)
{
    static const char *const sets[4][2] = {
        {"evaluated", "before"}, {"evaluated", "after"}, {"training", "train_before"}, {"training", "train_after"}};
    fputs("set,model,metric,value_mm\n", f);
    for (size_t s = 0; s < 4; ++s)
        for (size_t k = 0; k < N_METRICS; ++k) {
            char path[64];
            snprintf(path, sizeof path, "%s.%s", sets[s][1], rch_rep_metric_defs[k].key);
            fprintf(f, "%s,%s,%s,", s < 2 && jbool(r->cal, "held_out") != 0 ? "held-out" : sets[s][0],
                    strstr(sets[s][1], "before") ? "before" : "after", rch_rep_metric_defs[k].key);
            csv_num(f, jnum(r->cal, path));
            fputc('\n', f);
        }
}

void rch_rep_csv_params(FILE *f, const prow *p, size_t n)
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

void rch_rep_csv_accuracy(FILE *f, const arow *a, size_t n)
{
    fputs("quantity,value_mm\n", f);
    for (size_t k = 0; k < n; ++k) {
        rch_csv_field(f, a[k].label);
        fputc(',', f);
        csv_num(f, a[k].v);
        fputc('\n', f);
    }
}

void rch_rep_csv_cands(FILE *f, const crow *c, size_t n)
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

