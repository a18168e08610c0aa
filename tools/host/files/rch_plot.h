/* SPDX-License-Identifier: MIT */
/* rch_plot.h - a small SVG chart writer (lines, scatter, bars).
 *
 * What: one chart per rch_plot object: a title, axis labels, any number of
 * line and scatter series over a common numeric x axis, or one bar series
 * over categories (with optional error bars). Axes carry "nice" ticks
 * (1-2-5 steps; decades on a log y axis), a grid, and a legend naming every
 * series; series get distinct colours (a colour-blind-safe palette) and
 * distinct markers for scatter. All text is XML-escaped. Output is a single
 * self-contained SVG file that any browser opens, written through rch_svg
 * (the one SVG writer).
 *
 * Bars and numeric series in one chart: bars take the categories 0..n-1 as
 * x positions; line/scatter series added to a bar chart are drawn on the same
 * axis (x = category index), e.g. for a reference line.
 *
 * Non-finite points (NaN, inf) are skipped and break a line; on a log y axis
 * points with y <= 0 are skipped too.
 *
 * Depends on: the C library (stdio, stdlib, string, math); rch_svg for the
 * markup, rch_file for the plot-directory helpers. Memory: the chart
 * copies every string and array it is given (callers may free theirs at once);
 * rch_plot_free releases it. Thread safety: one object per thread.
 * Errors: rch_plot_new returns NULL on allocation failure; an allocation
 * failure in an add function is remembered and makes rch_plot_write_svg
 * return -1. rch_plot_write_svg returns 0, or -1 with errno set when the file
 * could not be written. Every function accepts p == NULL and does nothing.
 */
#ifndef RCH_PLOT_H
#define RCH_PLOT_H

#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"
#include "rch_file.h"

typedef struct rch_plot rch_plot;

/* New empty chart; any string may be NULL (treated as ""). */
rch_plot *rch_plot_new(const char *title, const char *xlabel, const char *ylabel);

/* A polyline through (x[k], y[k]), k = 0..n-1; x, y: (n). */
void rch_plot_line(rch_plot *p, const char *label, const double *x, const double *y, size_t n);

/* Markers at (x[k], y[k]); x, y: (n). */
void rch_plot_scatter(rch_plot *p, const char *label, const double *x, const double *y, size_t n);

/* One bar per category: labels (n) under the bars, values (n) bar heights,
 * errs (n) half-lengths of error bars or NULL. Replaces earlier bars. */
void rch_plot_bars(rch_plot *p, const char *const *labels, const double *values,
                   const double *errs, size_t n);

/* Colour the bars by category (call after rch_plot_bars): cat (n_bars)
 * indexes names (n_cat, at most 4); each category gets its own colour and a
 * legend entry. Without it every bar has the same colour (a colour that
 * means nothing is not drawn). */
void rch_plot_bar_categories(rch_plot *p, const unsigned *cat, const char *const *names, size_t n_cat);

/* A second, smaller title line (e.g. the paper figure this corresponds to). */
void rch_plot_subtitle(rch_plot *p, const char *subtitle);

/* Logarithmic y axis (on != 0). Default linear. */
void rch_plot_logy(rch_plot *p, int on);

/* Size in pixels (default 800 x 500). Values below 200 x 150 are raised. */
void rch_plot_size(rch_plot *p, unsigned width_px, unsigned height_px);

/* Force axis ranges (lo < hi; otherwise automatic, which is the default). */
void rch_plot_xrange(rch_plot *p, double lo, double hi);
void rch_plot_yrange(rch_plot *p, double lo, double hi);

/* Write the chart to a file path, or to an open stream. 0 or -1.
 * Each series is drawn inside <g class="series"> (line vertices or one
 * marker per drawable point), the bars inside <g class="bars"> (one <rect>
 * per drawable bar), so a reader can count what is drawn. */
int rch_plot_write_svg(const rch_plot *p, const char *path);
int rch_plot_write_svg_stream(const rch_plot *p, FILE *f);

/* The chart's data as CSV (rch_plot_table_write of its table): one row per
 * point, columns "series", then "category" when there are bars, the x and y
 * axis labels (with their units) and the error-bar half-length when given.
 * Bar rows: series = the y label, x = the bar's index. 0 or -1. */
int rch_plot_write_csv_stream(const rch_plot *p, FILE *f);

void rch_plot_free(rch_plot *p);

/* ---- plot files in a directory (the --plots DIR of the commands) ---- */

/* Create dir and its missing parents (mkdir -p). 0, or -1 with errno set
 * (ENOTDIR when a component exists and is not a directory). */
int rch_plot_mkdir(const char *dir);

/* Where a command writes its plots: every file goes through rch_file (never
 * over one of the command's inputs, temporary file renamed into place only
 * when complete). */
typedef struct rch_plot_dir {
    const char *dir;            /* the directory (rch_plot_mkdir first) */
    const char *const *inputs;  /* (n_inputs) the command's input files; NULL entries skipped */
    size_t n_inputs;
    FILE *log;                  /* gets "  wrote DIR/NAME" per file, or NULL */
} rch_plot_dir;

/* Open DIR/NAME for writing (rch_out_open with the inputs). 0, or -1 with d set. */
int rch_plot_open(rch_out *o, const rch_plot_dir *pd, const char *name, rch_diag *d);
/* Commit a file opened by rch_plot_open (abort it when failed != 0 or on a
 * write error) and log it. 0, or -1 with d set. */
int rch_plot_close(rch_out *o, const rch_plot_dir *pd, int failed, rch_diag *d);

/* Write p as DIR/NAME and its data as DIR/BASE.csv beside it (NAME =
 * BASE.svg; rch_plot_save_csv), then free it (also on failure; p NULL counts
 * as an allocation failure). 0, or -1 with d set ("cannot write DIR/NAME: ..."). */
int rch_plot_save(rch_plot *p, const rch_plot_dir *pd, const char *name, rch_diag *d);

/* The data of one plot as a table: n_rows rows of n_text text cells, then
 * n_num numbers. Column names say what and the unit: "deviation (mm)". */
typedef struct rch_plot_table {
    const char *const *head; /* (n_text + n_num) column names */
    size_t n_text, n_num, n_rows;
    const char *const *text; /* (n_rows x n_text) row-major; NULL when n_text == 0 */
    const double *num;       /* (n_rows x n_num) row-major */
} rch_plot_table;

/* Write t as CSV (RFC 4180 quoting, numbers %.9g, non-finite as nan, inf,
 * -inf). 0 or -1. */
int rch_plot_table_write(FILE *f, const rch_plot_table *t);

/* The one writer of a plot's CSV: t as DIR/BASE.csv for the plot file
 * DIR/NAME (NAME = BASE.svg, or any NAME without .svg: NAME.csv), through
 * rch_plot_open / rch_plot_close. t NULL: an allocation failure. 0, or -1
 * with d set. */
int rch_plot_save_csv(const rch_plot_table *t, const rch_plot_dir *pd, const char *name, rch_diag *d);

/* A p-value as text that never reads "0": "< 1e-300" below 1e-300 (an
 * underflow to 0 included), else %.1e ("3.0e-17"); "-" when not finite.
 * Returns out. */
const char *rch_plot_fmt_p(char *out, size_t len, double p);

/* Write s as one CSV field (RFC 4180: quoted when it holds a comma, quote or
 * line break; NULL is an empty field). The one CSV field writer of the host
 * library (plot data, residual tables, the report's CSVs). */
void rch_csv_field(FILE *f, const char *s);

#endif
