/* SPDX-License-Identifier: MIT */
/* rch_svg.h - the one writer of SVG markup in the host library.
 *
 * What: the elements every chart is made of (the document, groups, a clip
 * region, rectangles, lines, circles, paths drawn with a pen, text) with
 * their paint and font, plus the two pieces of chart arithmetic the charts
 * share (the 1-2-5 tick step and the viridis colour map). The charts lay
 * out and call these: rch_plot (lines, scatter, bars), rch_plot_rows (the
 * report's rows of values with 95 % intervals) and the grinding study's
 * heat map. No other file of the project prints an SVG tag
 * (scripts/layers.sh checks it).
 *
 * Every text and attribute string goes through rch_xml_put (the one XML
 * escaper); coordinates are pixels printed with two decimals; a non-finite
 * coordinate is written as 0 (never "nan", which no SVG reader accepts).
 *
 * Depends on: the C library (stdio), rch_text. No state; every function
 * writes to the stream it is given and ignores f == NULL. Stream errors are
 * the caller's to check (ferror), as with fprintf.
 */
#ifndef RCH_SVG_H
#define RCH_SVG_H

#include <stddef.h>
#include <stdio.h>

#include "rch_diag.h"

/* Where a text's x coordinate is: its start, middle or end. */
typedef enum { RCH_SVG_START = 0, RCH_SVG_MIDDLE, RCH_SVG_END } rch_svg_anchor;

/* How a shape is filled and stroked. A zero-initialised paint draws nothing
 * visible: set fill and/or stroke. */
typedef struct rch_svg_paint {
    const char *fill;    /* colour ("#0072B2", "white"), NULL: fill="none" */
    const char *stroke;  /* colour, NULL: no stroke */
    double stroke_px;    /* stroke width, 0: the SVG default (1 px) */
    double fill_opacity; /* 0 < o < 1: fill-opacity, otherwise opaque */
    const char *dash;    /* stroke-dasharray ("4 3"), NULL: solid */
    int round_cap;       /* 1: stroke-linecap="round" */
} rch_svg_paint;

/* How a text is set. Zero-initialised: inherited size and colour, anchored
 * at its start, upright. */
typedef struct rch_svg_font {
    double size_px;        /* 0: inherited */
    rch_svg_anchor anchor;
    const char *fill;      /* colour, NULL: inherited */
    int bold, italic;
    double rotate_deg;     /* rotation about (x, y), 0: none */
} rch_svg_font;

/* One drawing. */
typedef struct rch_svg_doc {
    double width_px, height_px;
    const char *cls;         /* class of the <svg> element, NULL: none */
    const char *title;       /* <title> and aria-label (role="img"), NULL: none */
    const char *font_family; /* NULL: "Helvetica, Arial, sans-serif" */
    double font_px;          /* default text size, 0: 12 */
    int in_html;             /* 1: inline in an HTML page (no XML declaration, no xmlns) */
} rch_svg_doc;

/* <svg ...> with a white background over the whole drawing. The element
 * starts with "<svg" then, in this order: xmlns (standalone only), class,
 * width, height, viewBox (sizes as whole pixels). */
void rch_svg_begin(FILE *f, const rch_svg_doc *d);
/* </svg> */
void rch_svg_end(FILE *f);

/* <g class="cls" data-kind="kind"> (either NULL: left out); a tooltip
 * (NULL: none) as its first child <title>. Ended by rch_svg_group_end. */
void rch_svg_group(FILE *f, const char *cls, const char *kind, const char *tip);
void rch_svg_group_end(FILE *f);

/* The rectangle (x, y, w, h) as a clip region named id (letters, digits,
 * '-' and '_'), and a group clipped to it; ended by rch_svg_group_end. */
void rch_svg_clip(FILE *f, const char *id, double x, double y, double w, double h);

/* Shapes. A tooltip tip (NULL: none) becomes the shape's <title> child. */
void rch_svg_rect(FILE *f, double x, double y, double w, double h, const rch_svg_paint *pt, const char *tip);
void rch_svg_line(FILE *f, double x1, double y1, double x2, double y2, const rch_svg_paint *pt);
void rch_svg_circle(FILE *f, double cx, double cy, double r, const rch_svg_paint *pt);

/* A path drawn with a pen: rch_svg_path_begin opens <path fill=... ...
 * d=", move/line add "M x y" / "L x y", close adds "Z", rch_svg_path_end
 * writes the closing quote and "/>". The fill attribute comes first
 * (fill="none" for an unfilled path), so a reader can tell a polyline from
 * a marker by the element's start. */
typedef struct rch_svg_pen {
    FILE *f;
} rch_svg_pen;
void rch_svg_path_begin(rch_svg_pen *pn, FILE *f, const rch_svg_paint *pt);
void rch_svg_path_move(rch_svg_pen *pn, double x, double y);
void rch_svg_path_line(rch_svg_pen *pn, double x, double y);
void rch_svg_path_close(rch_svg_pen *pn);
void rch_svg_path_end(rch_svg_pen *pn);

/* A closed filled polygon through (xy[2k], xy[2k+1]), k < n (one path). */
void rch_svg_polygon(FILE *f, const double *xy, size_t n, const rch_svg_paint *pt);

/* Text s (NULL: empty) at (x, y), XML-escaped. */
void rch_svg_text(FILE *f, double x, double y, const rch_svg_font *ft, const char *s);
/* The same with printf formatting (the result is escaped; at most 511
 * bytes of it are written, cut between whole UTF-8 characters). */
void rch_svg_textf(FILE *f, double x, double y, const rch_svg_font *ft, const char *fmt, ...) RCH_PRINTF(5, 6);

/* ---- chart arithmetic shared by the charts */

/* The 1, 2 or 5 times a power of ten nearest to span / want (about want
 * intervals over span); 1 when span / want is not a positive finite number. */
double rch_svg_nice_step(double span, double want);

/* A perceptually ordered colour map (viridis, 5 stops) at t in [0, 1]
 * (clamped, NaN as 0): "#rrggbb" into out. */
void rch_svg_viridis(char out[8], double t);

#endif
