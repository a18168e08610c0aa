/* SPDX-License-Identifier: MIT */
/* rch_report_int.h - what the files of the HTML report share (internal:
 * not installed, not part of rch_report.h).
 *
 * What: the report's model (the run's JSON read into rows: parameters,
 * diagnosis candidates, accuracy figures, data files), the page state `rep`
 * (the HTML stream, the inputs, the warnings, where a "not in this run"
 * stands), the chart description drawn by rch_rep_chart_svg, the colours
 * (one meaning each) and the functions each file offers the others:
 *   rch_report_model.c     the run's JSON into the model (dotted paths, rows)
 *   rch_report_chart.c     the charts (horizontal rows on files/rch_svg)
 *   rch_report_warn.c      the warnings the page lists
 *   rch_report_aim.c       the headline's figures at the flange, before and after
 *   rch_report_html.c      the page's pieces: values or "not in this run",
 *                          key-value rows, JSON tables, CSS, head and verdict
 *   rch_report_fit.c       sections 1-4: data, split, before/after, parameters
 *   rch_report_check.c     sections 5-8: diagnosis, accuracy, warnings, provenance
 *   rch_report_csv.c       the CSV files of the plots
 *   rch_report.c           the job: inputs, outputs opened and committed whole
 * Internal names: rch_rep_ (the public ones are rch_report_).
 *
 * Depends on: rch_json (the model points into the parsed inputs), rch_report.h.
 * Memory: the rows are heap (rch_rep_params_read, rch_rep_cands_read: the
 * caller frees); everything else points into the inputs or is the caller's.
 * Errors: none here: absent members are NaN / NULL and shown as "not in
 * this run" (rch_rep_missing counts them).
 *
 * Host side (prefix rch_): stdio, heap. */
#ifndef RCH_REPORT_INT_H
#define RCH_REPORT_INT_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"
#include "rch_json.h"
#include "rch_report.h"

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
extern const char *const rch_rep_colour[C_N]; /* "#rrggbb" of each C_ */

/* The headline's figures at the point compensation aims at (the flange
 * centre; rch_report_aim.c). NaN where the run has none. */
typedef struct {
    const char *point;               /* "the flange centre" (or "the measured point": an output that names none) */
    double after_median, after_max;  /* 95 % position radius after compensation over the data's poses */
    double ws_median, ws_max;        /* the same over random poses in the joint limits */
    const char *seen;                /* the point the data see when it is not the flange, else NULL */
    double seen_median;              /* its figure (what the headline said before issue 47) */
    double before_median, before_max; /* uncompensated: |flange of the calibrated model - nominal|, mm */
    size_t before_n;                 /* over how many poses */
    int before_over_data;            /* 1: the data's poses, 0: random poses in the joint limits */
} aim_fig;

typedef struct {
    FILE *f; /* the HTML */
    const rch_json *cal, *diag, *model;
    const rch_json *unc;  /* uncertainty block: calibration's, else the model file's, or NULL */
    const rch_json *prov; /* provenance block: likewise */
    const char *unc_from, *prov_from;
    const rch_report_cfg *cfg;
    const rch_report_mem *mem; /* the inputs a run in this process hands over, or NULL (read from the files) */
    rch_report_result *res;
    char warn[RCH_REPORT_MAX_WARN][640];
    unsigned n_warn;
    const char *section, *where, *how; /* what a "not in this run" here stands for, and how to get it */
    aim_fig aim; /* the headline's figures (rch_rep_aim) */
} rep;

/* How a run gets what the diagnosis, the model file or a truth holds. */
#define HOW_DIAG "a diagnosis: rcal diagnose --data FILE --json > DIAG.json, then rcal report --diagnosis DIAG.json"
#define HOW_MODEL "the run's model file: rcal report --model MODEL.json (rcal calibrate --out MODEL.json)"
#define HOW_TRUTH "a simulated truth: rcal calibrate --truth TRUTH.json (only a simulation has one: rcal simulate --truth-out)"

/* ---- the page's state: "not in this run" (rch_report_html.c) */

/* One place that says "not in this run": counted, and what it stands for
 * recorded once (with how to get it) for the command's summary. */
void rch_rep_missing(rep *r, const char *what, const char *how);
/* The section (or page part) the next places are in: a missing value there
 * is named by it unless a row (kv) names it. */
void rch_rep_section(rep *r, const char *name, const char *how);

/* ---- JSON access by dotted path ("uncertainty.position95_mm.data_max"; rch_report_model.c) */

const rch_json *rch_rep_jpath(const rch_json *o, const char *path);

/* A number (NAN when absent or not a number), a string (NULL), a flag (1
 * true, 0 false, -1 absent) and an array (NULL) at a dotted path. */
double rch_rep_jnum(const rch_json *o, const char *path);
const char *rch_rep_jstr(const rch_json *o, const char *path);
int rch_rep_jbool(const rch_json *o, const char *path);
const rch_json *rch_rep_jarr(const rch_json *o, const char *path);
#define jnum rch_rep_jnum
#define jstr rch_rep_jstr
#define jbool rch_rep_jbool
#define jarr rch_rep_jarr

/* ---- the model: the tables the page, the charts and the CSVs share (rch_report_model.c) */

typedef struct {
    const char *label;
    const char *key; /* member of a metrics object */
} metric_def;
#define RCH_REP_N_METRICS 4
extern const metric_def rch_rep_metric_defs[RCH_REP_N_METRICS];
#define N_METRICS ((size_t)RCH_REP_N_METRICS)

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

#define MAX_DFILES 8
typedef struct {
    const char *file, *sha_rec; /* as recorded; sha_rec NULL when not recorded */
    double samples;
    char sha_now[65];           /* "" when the file cannot be read from here */
    char why[96];               /* why not (a FIFO, a device, too large, ...) */
    const rch_report_data *mem; /* the run's own reading of it (rch_report_mem), or NULL: the file as it is now */
} dfile;

/* The calibration's parameters (n rows, heap; NULL with *n 0 when none). */
prow *rch_rep_params_read(const rep *r, size_t *n);
/* The diagnosis' candidates (n rows, heap; NULL with *n 0 when none). */
crow *rch_rep_cands_read(const rep *r, size_t *n);
/* Accuracy figures: predicted 95 % uncertainty and, on a simulation, the
 * flange error against the truth. Rows with no number are left out. */
size_t rch_rep_accuracy_read(const rep *r, arow out[10]);
/* The data files of the provenance (else the calibration's "data"), each
 * hashed as it is now where it can be read. */
size_t rch_rep_data_files(const rep *r, dfile out[MAX_DFILES]);
/* A provenance member, else the calibration's own. */
const char *rch_rep_prov_str(const rep *r, const char *key);

/* The headline's figures at the flange centre, after and before
 * compensation (rch_report_aim.c; the model file of --model for before). */
void rch_rep_aim(aim_fig *a, const rep *r, const dfile *df, size_t n_df);

/* ---- charts: horizontal rows, bars from zero or dots with 95 % intervals (rch_report_chart.c) */

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

/* The chart into the page (counted in res->n_plots). */
void rch_rep_chart_svg(rep *r, const chart *c);
/* The colour of an identifiability or data-vs-prior class. */
unsigned char rch_rep_class_colour(const char *cls);

/* ---- warnings (rch_report_warn.c): each into r->warn */

void rch_rep_warn_fit(rep *r);
void rch_rep_warn_params(rep *r, const prow *p, size_t n);
void rch_rep_warn_diag(rep *r);
void rch_rep_warn_inputs(rep *r, const dfile *df, size_t n_df);

/* ---- the page's pieces (rch_report_html.c) */

void rch_rep_put_esc(FILE *f, const char *s);
/* A JSON string escaped, or "not in this run". */
void rch_rep_put_str(rep *r, const char *s);
/* A number with printf format fmt, or "not in this run". */
void rch_rep_put_num(rep *r, double v, const char *fmt);
/* Three significant digits without an exponent between 1e-3 and 1e6
 * ("1610 mm", not "1.61e+03 mm"), then `unit`; or "not in this run". */
void rch_rep_put_sig(rep *r, double v, const char *unit);
/* A p-value ("< 1e-300" at 0). */
void rch_rep_put_p(rep *r, double p);
/* A key-value row: opened (a missing value in it is named by key), closed. */
void rch_rep_kv(rep *r, const char *key);
void rch_rep_kv_end(rep *r);

/* A table with one row per object of the JSON array `arr`: one column per
 * jcol, a string ('s'), a number with fmt ('n') or a p-value ('p'). */
typedef struct {
    const char *head, *key;
    char kind;
    const char *fmt;
} jcol;


void rch_rep_json_table(rep *r, const rch_json *arr, const jcol *cols, size_t n_cols);
/* From <!DOCTYPE html> to the end of the header with the verdict. */
void rch_rep_page_head(rep *r, size_t n_warn);

/* ---- the sections (rch_report_fit.c: 1-4, rch_report_check.c: 5-8) */

void rch_rep_sec_data(rep *r, const dfile *df, size_t n_df);
void rch_rep_sec_split(rep *r);
void rch_rep_sec_metrics(rep *r);
void rch_rep_sec_params(rep *r, const prow *p, size_t n);
void rch_rep_sec_diag(rep *r, const crow *c, size_t n);
void rch_rep_sec_accuracy(rep *r, const arow *a, size_t n);
void rch_rep_sec_warnings(rep *r);
/* Section 8 and the end of the page (date: the report's own). */
void rch_rep_sec_provenance(rep *r, const dfile *df, size_t n_df, const char *date);

/* ---- the CSV files of the plots (rch_report_csv.c) */

void rch_rep_csv_metrics(FILE *f, const rep *r);
void rch_rep_csv_params(FILE *f, const prow *p, size_t n);
void rch_rep_csv_accuracy(FILE *f, const arow *a, size_t n);
void rch_rep_csv_cands(FILE *f, const crow *c, size_t n);

#endif
