/* SPDX-License-Identifier: MIT */
/* rch_resid.h - per-sample residuals as CSV (issue 13): the one writer
 * behind `--residuals FILE.csv` of calibrate, evaluate, compare and diagnose.
 *
 * What: a table of samples, each with where it came from (1-based data line
 * in its input file, the file when several were merged), its set-up group,
 * its acquisition order t, its joint angles (deg), the measured and the
 * predicted cable length and their difference (mm), the set it belonged to
 * (train, test, validate), for compare its case, and for diagnose the
 * residual after each step. Columns, in this order (the optional ones only
 * when the table has them):
 *   row, [file,] [case,] group, t, q1..q6, measured_mm, predicted_mm,
 *   residual_mm, set, [residual_after_<step>_mm ...]
 * residual_mm = measured_mm - predicted_mm; lengths and residuals with %.17g
 * (the CSV recomputes them to the last bit), angles and t with %.12g.
 * docs/json-formats.md describes the file with the JSON outputs.
 *
 * Depends on: the core (rc_meas), rch_save (the file is written whole or
 * not at all, never over an input). Memory: the table's rows are on the heap
 * (rch_resid_free). Thread safety: none needed (no global state).
 * Errors: 0, or -1 (out of memory; for rch_resid_save with d set).
 *
 * Host side (prefix rch_). */
#ifndef RCH_RESID_H
#define RCH_RESID_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_diag.h"

#define RCH_RESID_MAX_STEPS 16 /* residual_after_* columns */

typedef enum { RCH_RESID_TRAIN = 0, RCH_RESID_TEST, RCH_RESID_VALIDATE } rch_resid_set;

typedef struct rch_resid_row {
    unsigned line;        /* 1-based data line in its input file */
    unsigned file;        /* index into the table's files */
    unsigned case_no;     /* compare: 1-based case */
    rch_resid_set set;
    rc_sample s;          /* as the fit used it: q in rad, measured len_mm, t, group */
    double predicted_mm;  /* the model's cable length (NaN when it has none there) */
    double after_mm[RCH_RESID_MAX_STEPS]; /* diagnose: residual after step k (measured - predicted) */
} rch_resid_row;

typedef struct rch_resid_table {
    rch_resid_row *row;          /* (n) on the heap */
    size_t n, cap;
    const char *const *files;    /* (n_files) input files; a file column when n_files > 1 */
    size_t n_files;
    int with_case;               /* 1: a case column */
    unsigned n_steps;            /* residual_after_* columns */
    char step[RCH_RESID_MAX_STEPS][48]; /* their names, e.g. "geometry", "length_offset" */
} rch_resid_table;

/* An empty table over files (n_files, not copied: they must outlive it). */
void rch_resid_init(rch_resid_table *t, const char *const *files, size_t n_files);
/* Append one row (copied). 0, or -1 out of memory. */
int rch_resid_add(rch_resid_table *t, const rch_resid_row *r);
/* Append samples s (n) with m's predictions: line (n) their data lines,
 * file (n) their file indices or NULL (all file 0). 0, or -1 out of memory. */
int rch_resid_add_model(rch_resid_table *t, const rc_model *m, const rc_sample *s, const unsigned *line,
                        const unsigned *file, size_t n, rch_resid_set set, unsigned case_no);
/* The CSV (header and rows) to f. 0, or -1 on a write error. */
int rch_resid_write(FILE *f, const rch_resid_table *t);
/* rch_resid_write into path, whole or not at all, refused when path names
 * one of inputs (n_inputs). 0, or -1 with d set. */
int rch_resid_save(const char *path, const char *const *inputs, size_t n_inputs, const rch_resid_table *t,
                   rch_diag *d);
/* Adds a residual column named residual_after_<name>_mm (blanks become '_';
 * cut to the column buffer). 0, or -1 when the table has its
 * RCH_RESID_MAX_STEPS columns. */
int rch_resid_add_step(rch_resid_table *t, const char *name);
void rch_resid_free(rch_resid_table *t);

const char *rch_resid_set_name(rch_resid_set set);

#endif
