/* SPDX-License-Identifier: MIT */
/* rch_resid.c - per-sample residual CSV (see rch_resid.h). */
#include "rch_resid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_plot.h"
#include "rch_save.h"

#define DEG (3.14159265358979323846 / 180.0)

const char *rch_resid_set_name(rch_resid_set set)
{
    switch (set) {
    case RCH_RESID_TRAIN:
        return "train";
    case RCH_RESID_TEST:
        return "test";
    case RCH_RESID_VALIDATE:
        return "validate";
    }
    return "?";
}

void rch_resid_init(rch_resid_table *t, const char *const *files, size_t n_files)
{
    memset(t, 0, sizeof *t);
    t->files = files;
    t->n_files = n_files;
}

int rch_resid_add(rch_resid_table *t, const rch_resid_row *r)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 256;
        rch_resid_row *p = realloc(t->row, cap * sizeof *p);
        if (!p)
            return -1;
        t->row = p;
        t->cap = cap;
    }
    t->row[t->n++] = *r;
    return 0;
}

int rch_resid_add_model(rch_resid_table *t, const rc_model *m, const rc_sample *s, const unsigned *line,
                        const unsigned *file, size_t n, rch_resid_set set, unsigned case_no)
{
    for (size_t i = 0; i < n; ++i) {
        rch_resid_row r;
        memset(&r, 0, sizeof r);
        r.line = line[i];
        r.file = file ? file[i] : 0u;
        r.case_no = case_no;
        r.set = set;
        r.s = s[i];
        if (rc_meas(&r.predicted_mm, NULL, m, &s[i]) != RC_OK)
            r.predicted_mm = NAN;
        for (unsigned k = 0; k < RCH_RESID_MAX_STEPS; ++k)
            r.after_mm[k] = NAN;
        if (rch_resid_add(t, &r) != 0)
            return -1;
    }
    return 0;
}

/* %.17g, or an empty field for a value that is not finite. */
static void put_num(FILE *f, const char *fmt, double v)
{
    fputc(',', f);
    if (isfinite(v))
        fprintf(f, fmt, v);
}

int rch_resid_write(FILE *f, const rch_resid_table *t)
{
    const int with_file = t->n_files > 1;
    fputs("row", f);
    if (with_file)
        fputs(",file", f);
    if (t->with_case)
        fputs(",case", f);
    fputs(",group,t,q1,q2,q3,q4,q5,q6,measured_mm,predicted_mm,residual_mm,set", f);
    for (unsigned k = 0; k < t->n_steps; ++k) {
        fputs(",", f);
        char name[96];
        snprintf(name, sizeof name, "residual_after_%s_mm", t->step[k]);
        rch_csv_field(f, name);
    }
    fputc('\n', f);
    for (size_t i = 0; i < t->n; ++i) {
        const rch_resid_row *r = &t->row[i];
        fprintf(f, "%u", r->line);
        if (with_file) {
            fputc(',', f);
            rch_csv_field(f, r->file < t->n_files && t->files[r->file] ? t->files[r->file] : "");
        }
        if (t->with_case)
            fprintf(f, ",%u", r->case_no);
        fprintf(f, ",%u", (unsigned)r->s.group);
        put_num(f, "%.12g", r->s.t);
        for (unsigned j = 0; j < RC_NJ; ++j)
            put_num(f, "%.12g", r->s.q_rad[j] / DEG);
        put_num(f, "%.17g", r->s.value);
        put_num(f, "%.17g", r->predicted_mm);
        put_num(f, "%.17g", r->s.value - r->predicted_mm);
        fprintf(f, ",%s", rch_resid_set_name(r->set));
        for (unsigned k = 0; k < t->n_steps; ++k)
            put_num(f, "%.17g", r->after_mm[k]);
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}

static int write_cb(FILE *f, const void *ctx)
{
    return rch_resid_write(f, ctx);
}

int rch_resid_save(const char *path, const char *const *inputs, size_t n_inputs, const rch_resid_table *t,
                   rch_diag *d)
{
    return rch_save(path, "--residuals", inputs, n_inputs, write_cb, t, d);
}

int rch_resid_add_step(rch_resid_table *t, const char *name)
{
    char *dst;
    size_t k = 0;
    if (t->n_steps >= RCH_RESID_MAX_STEPS)
        return -1;
    dst = t->step[t->n_steps++];
    for (; name[k] && k + 1 < sizeof t->step[0]; ++k)
        if (name[k] == ' ')
            dst[k] = '_';
        else
            dst[k] = name[k];
    dst[k] = '\0';
    return 0;
}

void rch_resid_free(rch_resid_table *t)
{
    free(t->row);
    t->row = NULL;
    t->n = t->cap = 0;
}
