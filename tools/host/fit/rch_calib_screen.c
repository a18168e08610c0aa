/* SPDX-License-Identifier: MIT */
/* rch_calib_screen.c - the rows a calibration cannot reconcile with the
 * rest (issue 33): found after the fit by a stated rule, named by file and
 * line with their residual and what they are likely to be, left out of the
 * refit; a file with too many of them refused.
 *
 * The rule: each row's residual under the fitted model (a length, or the
 * largest coordinate of a tracker position) against a robust scale of its
 * sensor's residuals, s = 1.4826 median |r - median r| (the standard
 * deviation for Gaussian residuals, not inflated by the rows it looks for);
 * a row beyond RCH_SCREEN_K s and beyond RCH_SCREEN_FLOOR_MM is out. More
 * than RCH_SCREEN_MAX_SHARE of the rows out: the file is refused. What an
 * out row likely is: a length that another outlet's place explains to
 * within 3 s is a wrong outlet label; three or more out rows in a row of the
 * file are a different session (a block); otherwise an outlier.
 * Depends on: the core (rc_meas), rch_calib_int.h. Memory: scratch freed
 * before return. Errors: -1 with d set (refused, or out of memory). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_calib.h"
#include "rch_calib_int.h"
#include "rch_stats.h"

/* Whether another outlet of m explains sample s's length to within tol:
 * its label (1..) or 0. */
static unsigned other_outlet(const rc_model *m, const rc_sample *s, double tol, const uint8_t *label, unsigned n_out)
{
    for (unsigned k = 0; k < n_out; ++k) {
        if (k == s->outlet)
            continue;
        rc_sample c = *s;
        c.outlet = (uint8_t)k;
        double l;
        if (rc_meas(&l, NULL, m, &c) == RC_OK && fabs(l - s->value) < tol)
            return (unsigned)label[k] + 1u;
    }
    return 0;
}

int rch_calib_screen(rch_calib_result *r, uint8_t *drop, const rc_sample *s, size_t n, const unsigned *line,
                     const unsigned *file_of, rch_diag *d)
{
    rch_calib_screen_result *z = &r->screen;
    memset(z, 0, sizeof *z);
    memset(drop, 0, n ? n : 1);
    double *res = malloc((n ? n : 1) * sizeof *res), *tmp = malloc((n ? n : 1) * sizeof *tmp);
    if (!res || !tmp) {
        free(res);
        free(tmp);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    /* under the fit at hand: with length jumps fitted, their segment offsets too (an outlier must not hide
     * behind a jump the screen does not know, nor a jump be taken for a block of outliers) */
    const rc_model *fm = r->have_jumps ? &r->jumps.model : &r->model;
    for (size_t i = 0; i < n; ++i) {
        double l;
        rc_sample c = s[i];
        const unsigned seg = r->have_jumps ? rch_jumps_segment(&r->jumps, c.t) : 0u;
        c.group = (uint16_t)seg;
        res[i] = rc_meas(&l, NULL, fm, &c) == RC_OK ? (l - s[i].value) * rc_sample_weight(&s[i]) : NAN;
        /* a row the fit did not see just before a jump's first training row may lie after the jump (the
         * change point is known only between training rows): the segment that explains it (a misread stays
         * far under both); only for the last few rows before it */
        if (r->have_jumps && seg < r->jumps.n_jumps && isfinite(res[i]) && fabs(res[i]) > RCH_SCREEN_FLOOR_MM) {
            unsigned between = 0;
            for (size_t k = 0; k < n && between <= 2; ++k)
                between += s[k].t > c.t && s[k].t < r->jumps.at_t[seg];
            c.group = (uint16_t)(seg + 1);
            if (between <= 2 && rc_meas(&l, NULL, fm, &c) == RC_OK &&
                fabs((l - s[i].value) * rc_sample_weight(&s[i])) < fabs(res[i]))
                res[i] = (l - s[i].value) * rc_sample_weight(&s[i]);
        }
    }
    double scale[2] = {0.0, 0.0}; /* cable, tracker */
    for (int tr = 0; tr < 2; ++tr) {
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if ((s[i].sensor != RC_SENSOR_LENGTH) == tr && isfinite(res[i]))
                tmp[m++] = res[i];
        scale[tr] = rch_mad_sd(tmp, m);
    }
    free(tmp);
    size_t rows = 0, out_rows = 0;
    for (size_t i = 0; i < n; ++i) {
        const int tr = s[i].sensor != RC_SENSOR_LENGTH;
        /* a tracker row is its three coordinates (consecutive samples of one line) */
        const size_t width = tr && i + 2 < n && line[i + 1] == line[i] && line[i + 2] == line[i] ? 3 : 1;
        double worst = 0.0;
        for (size_t k = i; k < i + width; ++k)
            worst = fmax(worst, isfinite(res[k]) ? fabs(res[k]) : INFINITY);
        const double lim = fmax(RCH_SCREEN_K * scale[tr], RCH_SCREEN_FLOOR_MM);
        rows++;
        if (worst > lim) {
            out_rows++;
            for (size_t k = i; k < i + width; ++k)
                drop[k] = 1;
            if (z->n_named < RCH_SCREEN_MAX_NAMED) {
                rch_screen_row *w = &z->row[z->n_named++];
                w->line = line[i];
                w->file = file_of ? file_of[i] : 0;
                w->residual_mm = worst;
                w->scale_mm = scale[tr];
                w->tracker = tr;
                w->sensor = s[i].sensor;
                w->label_fits = tr ? 0 : other_outlet(fm, &s[i], 3.0 * scale[tr] + RCH_SCREEN_FLOOR_MM,
                                                       r->outlet_label, r->n_outlets);
            }
        }
        i += width - 1;
    }
    free(res);
    z->rows = rows;
    z->out = out_rows;
    z->scale_mm[0] = scale[0];
    z->scale_mm[1] = scale[1];
    for (unsigned a = 0, e; a < z->n_named; a = e + 1) { /* three or more in a row of one file: a block */
        for (e = a; e + 1 < z->n_named && z->row[e + 1].file == z->row[e].file && z->row[e + 1].line - z->row[e].line <= 3u;
             ++e)
            ;
        for (unsigned j = a; e - a + 1 >= 3 && j <= e; ++j)
            z->row[j].block = 1;
    }
    if (out_rows > 0 && (double)out_rows > RCH_SCREEN_MAX_SHARE * (double)rows) {
        rch_diag_set(d, "", 0, 0,
                     "%zu of %zu rows (%.0f %%) cannot be reconciled with the rest (beyond %.0f x their robust scale "
                     "%.4g mm; the first at line %u, %.4g mm off): not fitted. Wrong units, labels or columns, or "
                     "another robot's or session's data in the file; --no-screen fits them all",
                     out_rows, rows, 100.0 * (double)out_rows / (double)rows, RCH_SCREEN_K,
                     z->row[0].tracker ? scale[1] : scale[0], z->row[0].line, z->row[0].residual_mm);
        return -1;
    }
    return (int)out_rows;
}

const char *rch_screen_kind(const rch_screen_row *w)
{
    return w->label_fits ? "wrong outlet label" : w->block ? "a different session (a block of rows)" : "outlier";
}
