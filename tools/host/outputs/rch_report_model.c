/* SPDX-License-Identifier: MIT */
/* rch_report_model.c - the run's JSON read into the report's model: members
 * by dotted path, the parameter rows (with their standard errors and
 * classes, from the calibration or its uncertainty block), the diagnosis'
 * candidates, the accuracy figures and the data files with their hashes now.
 * Depends on: rch_json, rch_sha256, rch_file (the size limit of a file
 * named by an input). Memory: rows on the heap (the caller
 * frees); strings point into the parsed inputs. Errors: none (absent: NaN,
 * NULL, "?"; an allocation failure reads as no rows). See rch_report_int.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_seen.h"

#include "rch_file.h"
#include "rch_report_int.h"
#include "rch_sha256.h"

const rch_json *rch_rep_jpath(const rch_json *o, const char *path)
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

double rch_rep_jnum(const rch_json *o, const char *path)
{
    const rch_json *j = rch_rep_jpath(o, path);
    return j && j->type == RCH_JNUM ? j->num : NAN;
}

const char *rch_rep_jstr(const rch_json *o, const char *path)
{
    const rch_json *j = rch_rep_jpath(o, path);
    return j && j->type == RCH_JSTR ? j->str : NULL;
}

int rch_rep_jbool(const rch_json *o, const char *path)
{
    const rch_json *j = rch_rep_jpath(o, path);
    return j && j->type == RCH_JBOOL ? j->num != 0.0 : -1;
}

const rch_json *rch_rep_jarr(const rch_json *o, const char *path)
{
    const rch_json *j = rch_rep_jpath(o, path);
    return j && j->type == RCH_JARR ? j : NULL;
}

const metric_def rch_rep_metric_defs[RCH_REP_N_METRICS] = {
    {"RMSE", "rmse_mm"}, {"mean |e|", "mean_abs_mm"}, {"SD", "sd_mm"}, {"MAX", "max_mm"}};

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
        const int seen = rch_seen_parse(jstr(list->items[i], "seen")); /* the one class (rch_seen.h) */
        if (seen >= 0)
            cls = rch_seen_words((rch_seen)seen);
        else if (post && strcmp(post, "no prior") != 0)
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

prow *rch_rep_params_read(const rep *r, size_t *n)
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

crow *rch_rep_cands_read(const rep *r, size_t *n)
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
size_t rch_rep_accuracy_read(const rep *r, arow out[10])
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
        /* when the data see another point than the flange (the rows above are at it) */
        {"95 % at the flange, median", "seen_point.flange_position95_median_mm", 0, C_AFTER},
        {"95 % at the flange, max", "seen_point.flange_position95_max_mm", 0, C_AFTER},
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

size_t rch_rep_data_files(const rep *r, dfile out[MAX_DFILES])
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
    /* a run in this process: the digest of the bytes it read (data[i] is the provenance's i-th file) */
    for (size_t i = 0; r->mem && r->mem->data && i < n; ++i)
        if (i < r->mem->n_data && r->mem->data[i].file && strcmp(r->mem->data[i].file, out[i].file) == 0 &&
            r->mem->data[i].sha256)
            out[i].mem = &r->mem->data[i];
    /* names found in the file, not given by the user: a regular file below
     * the size limit only (never a FIFO or /dev/zero, which never end) */
    for (size_t i = 0; i < n; ++i)
        if (out[i].mem)
            snprintf(out[i].sha_now, sizeof out[i].sha_now, "%s", out[i].mem->sha256);
        else if (rch_sha256_file_unasked(out[i].sha_now, out[i].file, RCH_UNASKED_MAX_BYTES, out[i].why,
                                    sizeof out[i].why) != 0)
            out[i].sha_now[0] = '\0';
    return n;
}

const char *rch_rep_prov_str(const rep *r, const char *key)
{
    const char *s = jstr(r->prov, key);
    return s ? s : jstr(r->cal, key);
}
