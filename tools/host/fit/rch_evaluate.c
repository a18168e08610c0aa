/* SPDX-License-Identifier: MIT */
/* rch_evaluate.c - a model on new data, RMSE and ISO 9283 distance
 * characteristics (see rch_evaluate.h). */
#include "rch_evaluate.h"

#include "rch_start.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_pose(const void *a, const void *b)
{
    const rc_sample *x = a, *y = b;
    if (x->sensor != y->sensor || x->outlet != y->outlet || x->target != y->target) /* another measurand */
        return x->sensor != y->sensor ? (x->sensor < y->sensor ? -1 : 1)
               : x->outlet != y->outlet ? (x->outlet < y->outlet ? -1 : 1)
                                        : (x->target < y->target ? -1 : 1);
    for (int j = 0; j < RC_NJ; ++j)
        if (x->q_rad[j] != y->q_rad[j])
            return x->q_rad[j] < y->q_rad[j] ? -1 : 1;
    return 0;
}

static int same_pose(const rc_sample *a, const rc_sample *b, double tol_rad)
{
    if (a->sensor != b->sensor || a->outlet != b->outlet || a->target != b->target)
        return 0; /* the same joints from another outlet or to another point: not a repeat */
    for (int j = 0; j < RC_NJ; ++j)
        if (fabs(a->q_rad[j] - b->q_rad[j]) > tol_rad)
            return 0;
    return 1;
}

/* Repeated poses: AD and RD (see the header). */
static int iso9283(rch_evaluate_result *out, const rc_model *m, const rc_sample *s, size_t n, double tol_rad)
{
    rc_sample *c = malloc(n * sizeof *c); /* sorted copy: equal poses side by side */
    if (!c)
        return -1;
    memcpy(c, s, n * sizeof *c);
    qsort(c, n, sizeof *c, cmp_pose);
    double ad_sum = 0.0, rd_sum = 0.0;
    for (size_t a = 0; a < n;) {
        size_t b = a + 1;
        while (b < n && same_pose(&c[a], &c[b], tol_rad))
            ++b;
        out->n_poses++;
        size_t k = b - a;
        if (k >= 2) {
            double mean = 0.0, ss = 0.0, l;
            for (size_t i = a; i < b; ++i)
                mean += c[i].value;
            mean /= (double)k;
            for (size_t i = a; i < b; ++i)
                ss += (c[i].value - mean) * (c[i].value - mean);
            if (rc_meas(&l, NULL, m, &c[a]) != RC_OK) {
                free(c);
                return -1;
            }
            double ad = fabs(mean - l), rd = 3.0 * sqrt(ss / (double)(k - 1));
            out->n_repeated++;
            ad_sum += ad;
            rd_sum += rd;
            out->ad_max_mm = fmax(out->ad_max_mm, ad);
            out->rd_max_mm = fmax(out->rd_max_mm, rd);
        }
        a = b;
    }
    if (out->n_repeated) {
        out->ad_mean_mm = ad_sum / (double)out->n_repeated;
        out->rd_mean_mm = rd_sum / (double)out->n_repeated;
    } else {
        out->ad_mean_mm = out->ad_max_mm = out->rd_mean_mm = out->rd_max_mm = NAN;
    }
    free(c);
    return 0;
}

int rch_evaluate(rch_evaluate_result *out, const rc_model *m, const rc_sample *s, size_t n,
                 const rch_evaluate_config *cfg, rc_solve_work *w, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (n == 0) {
        snprintf(err, errlen, "no samples to evaluate");
        return -1;
    }
    rc_model use = *m;
    if (cfg && cfg->refit_encoder) {
        rch_diag dg;
        /* the encoder alone, as the "before calibration" model is made */
        if (n < 10 || rch_calib_bc(&use, w, m, 1, s, n, &dg) != 0) {
            snprintf(err, errlen, "refitting the encoder outlet failed (%zu samples)", n);
            return -1;
        }
        out->encoder_refitted = 1;
        double d2 = 0.0;
        for (int k = 0; k < 3; ++k)
            d2 += (use.x[RC_P_ENC + k] - m->x[RC_P_ENC + k]) * (use.x[RC_P_ENC + k] - m->x[RC_P_ENC + k]);
        out->encoder_shift_mm = sqrt(d2);
    }
    memcpy(out->encoder_mm, &use.x[RC_P_ENC], sizeof out->encoder_mm);
    if (rc_eval(&out->m, &use, s, n) != RC_OK) {
        snprintf(err, errlen, "a sample puts the flange on the encoder outlet: no length derivative");
        return -1;
    }
    double tol = (cfg && cfg->same_pose_deg > 0 ? cfg->same_pose_deg : 1e-6) * 3.14159265358979323846 / 180.0;
    if (iso9283(out, &use, s, n, tol) != 0) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    return 0;
}
