/* SPDX-License-Identifier: MIT */
/* rch_report.c - the HTML report of a calibration; see rch_report.h and
 * docs/report.md (which members are read, and from where). This file is the
 * job: the inputs loaded and checked for what their option says, the page
 * and its CSVs opened as temporaries (never over an input), written in page
 * order and committed whole or not at all. The rest of the report is split
 * by concept (rch_report_int.h lists the files).
 * Depends on: rch_json, rch_file (outputs), rch_text (escaping). Memory:
 * heap, freed before return. Errors: 0, or -1 with d set. */
#include "rch_report.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rch_file.h"
#include "rch_report_int.h"
#include "rch_text.h"

const char *rch_report_escape(char *buf, size_t len, const char *s) { return rch_xml_escape(buf, len, s, 0); }

/* path's document (text, len: its text in memory, path only its name; NULL: read from path). */
static rch_json *load_kind(const char *path, const char *text, size_t len, const char *opt, const char *need,
                           const char *kind, rch_diag *d)
{
    rch_json *j = text ? rch_json_parse(text, len, path, d) : rch_json_load(path, d);
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
    j->cal = load_kind(cfg->cal_path, cfg->cal_text, cfg->cal_len, "--calibration", "before", "the output of rcal calibrate --json", d);
    if (!j->cal)
        return -1;
    if (cfg->diag_path && !(j->diag = load_kind(cfg->diag_path, cfg->diag_text, cfg->diag_len, "--diagnosis", "candidates",
                                                "the output of rcal diagnose --json", d)))
        return -1;
    const char *mt = r->mem ? r->mem->model_text : NULL;
    if (cfg->model_path && !(j->model = load_kind(cfg->model_path, mt, mt ? r->mem->model_len : 0, "--model", "dh",
                                                  "a model file (rcal-model/1 or /2)", d)))
        return -1;
    r->cal = j->cal;
    r->diag = j->diag;
    r->model = j->model;
    r->unc = rch_rep_jpath(j->cal, "uncertainty");
    r->unc_from = "from the calibration run";
    if (!r->unc && j->model) {
        r->unc = rch_rep_jpath(j->model, "uncertainty");
        r->unc_from = "from the model file";
    }
    r->prov = rch_rep_jpath(j->cal, "provenance");
    r->prov_from = "from the calibration run";
    if (!r->prov && j->model) {
        r->prov = rch_rep_jpath(j->model, "provenance");
        r->prov_from = "from the model file";
    }
    j->p = rch_rep_params_read(r, &j->n_p);
    j->c = rch_rep_cands_read(r, &j->n_c);
    j->n_a = rch_rep_accuracy_read(r, j->a);
    j->n_df = rch_rep_data_files(r, j->df);
    rch_rep_aim(&r->aim, r, j->df, j->n_df);
    return 0;
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
    rch_rep_warn_fit(r);
    rch_rep_warn_params(r, j->p, j->n_p);
    rch_rep_warn_diag(r);
    rch_rep_warn_inputs(r, j->df, j->n_df);
    r->f = j->out[0].f;
    rch_rep_page_head(r, r->n_warn);
    rch_rep_sec_data(r, j->df, j->n_df);
    rch_rep_sec_split(r);
    rch_rep_sec_metrics(r);
    rch_rep_sec_params(r, j->p, j->n_p);
    rch_rep_sec_diag(r, j->c, j->n_c);
    rch_rep_sec_accuracy(r, j->a, j->n_a);
    rch_rep_sec_warnings(r);
    rch_rep_sec_provenance(r, j->df, j->n_df, date);
    unsigned k = 1;
    rch_rep_csv_metrics(j->out[k++].f, r);
    if (j->n_p)
        rch_rep_csv_params(j->out[k++].f, j->p, j->n_p);
    if (j->n_a)
        rch_rep_csv_accuracy(j->out[k++].f, j->a, j->n_a);
    if (j->n_c)
        rch_rep_csv_cands(j->out[k++].f, j->c, j->n_c);
}

int rch_report_write(rch_report_result *res, const rch_report_cfg *cfg, rch_diag *d)
{
    return rch_report_write_mem(res, cfg, NULL, d);
}

int rch_report_write_mem(rch_report_result *res, const rch_report_cfg *cfg, const rch_report_mem *mem, rch_diag *d)
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
    r->mem = mem;
    r->res = res;
    if (job_load(&j, r, cfg, d) != 0 || job_open(&j, r, cfg, d) != 0)
        goto done;
    job_write(&j, r, date);
    for (unsigned k = 0; k < j.n_out; ++k)
        if (ferror(j.out[k].f)) {
            rch_diag_set(d, j.out[k].path, 0, 0, "write error: %s", strerror(rch_out_errno(&j.out[k])));
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
