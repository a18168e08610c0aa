/* SPDX-License-Identifier: MIT */
/* rch_report.h - the HTML report of a calibration (issue 13): one
 * self-contained file a user can hand on, built from what the commands
 * already wrote.
 *
 * What: reads the output of `rcal calibrate --json` (required), of
 * `rcal diagnose --json` and a model file (rcal-model/1 or /2; both
 * optional), and writes one HTML page with its CSS inline and every plot as
 * inline SVG (no script, no font, image or link that leaves the file):
 * data summary, split, before/after metrics, the identified parameters with
 * their standard errors, 95 % intervals and identifiability classes, the
 * diagnosis, the predicted accuracy over the workspace, warnings and the
 * provenance. Members a run does not carry (older outputs, a calibration
 * without uncertainty) are shown as "not in this run", so the report keeps
 * working while the JSON grows. The members read, and where each is looked
 * for, are listed in docs/report.md.
 *
 * The data of every plot is written beside the HTML, named from it: page
 * x.html gives x_<plot>.csv (metrics, params, accuracy when the run has
 * accuracy figures, candidates when a diagnosis is given). The page and its
 * CSVs are one bundle, written whole or not at all (rch_out_commit_all).
 *
 * Every string that comes from a JSON file is HTML-escaped (& < > " ' and
 * control characters; bytes that are not UTF-8 become U+FFFD), also inside
 * the SVG text and in tooltips; CSV fields are quoted per RFC 4180.
 *
 * Depends on: rch_json (reader), rch_file (outputs: refuses to write over an
 * input, temporary file + rename, so an old report survives any failure
 * intact), rch_sha256 (the data file's hash as it is now, against the one
 * recorded at calibration time). Memory: heap, freed before return.
 * Thread safety: none needed (no global state).
 * Errors: 0, or -1 with d set ("file:line:col: what"); nothing is left
 * behind on failure (all outputs are committed only once all were written).
 *
 * Host side (prefix rch_): stdio, heap, POSIX. */
#ifndef RCH_REPORT_H
#define RCH_REPORT_H

#include <stddef.h>

#include "rch_diag.h"

#define RCH_REPORT_MAX_CSV 4
#define RCH_REPORT_MAX_WARN 32
#define RCH_REPORT_MAX_MISSING 24

typedef struct {
    const char *cal_path;     /* output of rcal calibrate --json (required) */
    const char *diag_path;    /* output of rcal diagnose --json, or NULL */
    const char *model_path;   /* model file (rcal-model/1 or /2), or NULL */
    const char *out_path;     /* the HTML page (required; not "-": the CSVs go beside it) */
    const char *command_line; /* the report's own command line, shown in the provenance; may be NULL */
    const char *date_utc;     /* "2026-11-29T17:00:00Z" shown as the report's date; NULL: now */
    double tolerance_mm;      /* > 0: the verdict is pass or fail against it (the largest 95 % position
                                 radius after compensation over the data's poses); 0: no verdict */
    /* A run's own report (rch_report_inline): its JSON in memory, as written beside the page; given, it is
     * read from here and cal_path / diag_path only name it (never opened again). */
    const char *cal_text, *diag_text;
    size_t cal_len, diag_len;
} rch_report_cfg;

typedef struct {
    char csv[RCH_REPORT_MAX_CSV][1024]; /* paths of the CSV files written */
    unsigned n_csv;
    unsigned n_plots;                   /* inline SVG charts in the page */
    unsigned n_warnings;                /* entries in the warnings section */
    unsigned n_missing;                 /* places that say "not in this run" */
    struct {
        char what[96]; /* what is missing ("noise floor", "the comparison against a simulated truth") */
        char how[160]; /* how a run gets it ("a diagnosis: ..."), "" when the calibration output has none */
    } missing[RCH_REPORT_MAX_MISSING]; /* each distinct one, in page order */
    unsigned n_missing_items;
} rch_report_result;

/* Read the inputs named in cfg, write the HTML page and its CSV files.
 * 0, or -1 with d set (unreadable or malformed input, an input that is not
 * what its option says, an output that names an input, a write failure). */
int rch_report_write(rch_report_result *res, const rch_report_cfg *cfg, rch_diag *d);

/* One data file of a run in this process, as the run read it: its digest
 * and its rows' joints (rad, one pose a row; NULL with n 0: a file whose
 * rows are no poses, a sensor's). */
typedef struct {
    const char *file;         /* as the run's provenance names it */
    const char *sha256;       /* hex digest of the bytes the run read */
    const double (*q_rad)[6]; /* (n) */
    size_t n;
} rch_report_data;

/* What a run in this process hands its own report (rch_report_inline), so
 * that the report opens none of its inputs: the model file's text as the
 * run wrote it (cfg->model_path only names it) and the data files
 * (data[k] is the k-th data file of the calibration's provenance). The
 * page drawn is the one rch_report_write draws from the files. */
typedef struct {
    const char *model_text; /* or NULL: cfg->model_path read (when given) */
    size_t model_len;
    const rch_report_data *data; /* (n_data) or NULL: each data file hashed and read as it is now */
    size_t n_data;
} rch_report_mem;

/* rch_report_write with the inputs in memory (mem may be NULL: the same as rch_report_write). */
int rch_report_write_mem(rch_report_result *res, const rch_report_cfg *cfg, const rch_report_mem *mem, rch_diag *d);

/* The plot-data file `name` of page: the page's path without .html/.htm,
 * then "_<name>.csv" (x.html, "params" -> x_params.csv). 0, or -1 when it
 * does not fit in cap. */
int rch_report_csv_path(char *buf, size_t cap, const char *page, const char *name);

/* s HTML-escaped into buf (always NUL-terminated; truncated only between
 * whole characters or entities). Returns buf. */
const char *rch_report_escape(char *buf, size_t len, const char *s);

/* --report FILE.html of calibrate and diagnose (rch_report_inline.c): the
 * page of `rcal report` from this run. cal (required) and diag (may be
 * NULL) are the run's results; their JSON, as --json of this command line
 * (argc, argv) prints it, is made in memory, kept beside the page as
 * FILE.calibration.json and FILE.diagnosis.json (never over an input) and
 * handed to rch_report_write as text (not read back). model: the model file
 * written by the run, or NULL. inputs (n_inputs): the run's input files,
 * which no output of the report may replace. quiet: no message on stderr.
 * 0, or 1 with the message on stderr. */
struct rch_calib_result;
struct rch_diagnose_result;
int rch_report_inline(const char *html, const struct rch_calib_result *cal, const struct rch_diagnose_result *diag,
                      int argc, char **argv, const char *model, const char *const *inputs, size_t n_inputs,
                      int quiet);
/* The same with the model file's text as the run wrote it (model_text, model_len; NULL: model is read):
 * calibrate --report, which then opens none of its inputs or outputs again (the data files as the run
 * read them: cal->read_q with cfg.keep_poses). */
int rch_report_inline_model(const char *html, const struct rch_calib_result *cal,
                            const struct rch_diagnose_result *diag, int argc, char **argv, const char *model,
                            const char *model_text, size_t model_len, const char *const *inputs, size_t n_inputs,
                            int quiet);

/* Every file --report HTML writes besides the page (its JSON, the plot
 * data), for the check that a command's outputs never name each other
 * before the work: names[k] (k < RCH_REPORT_BUNDLE). Returns the count. */
#define RCH_REPORT_BUNDLE 6
#define RCH_REPORT_NAME 1100
size_t rch_report_bundle(char names[RCH_REPORT_BUNDLE][RCH_REPORT_NAME], const char *html);


#endif
