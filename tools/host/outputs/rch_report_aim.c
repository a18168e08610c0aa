/* SPDX-License-Identifier: MIT */
/* rch_report_aim.c - the figures of the report's headline at the point
 * compensation aims at (issue 47): the flange centre, never the cable
 * attachment or a tracker target the data saw.
 *
 * After compensation: the calibration's own figure at the flange (its
 * "seen_point" names the flange's apart when the point the data see is off
 * it), else its map when that is the flange. Before (uncompensated): with the
 * run's model file, the distance between where the nominal table sends the
 * flange and where the calibrated model (what compensation acts on:
 * rch_comp_determined, the cable attachment removed by
 * rch_comp_point_model) puts it, median and largest over the data's poses
 * (the data files of the provenance, read as they are now), else over random
 * poses in the joint limits. The workspace figure at the flange when the
 * calibration's map is at another point: from the model file's covariance
 * (rch_model_unc_pos95_mm, the same random poses).
 *
 * Depends on: rch_robot (the model file), rch_comp (the point model),
 * rch_data (the data's poses), rch_stats. Memory: heap, freed before return.
 * Errors: none: what cannot be had stays NaN. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_comp.h"
#include "rch_data.h"
#include "rch_report_int.h"
#include "rch_robot.h"
#include "rch_stats.h"

#define AIM_RANDOM_POSES 2000
#define AIM_SEED 20261205u
#define AIM_MAX_POSES 200000

/* The poses of the data files listed in the provenance that can be read
 * from here (lengths or tracker positions), into *q (heap, n x 6). */
static size_t data_poses(double (**q)[RC_NJ], const dfile *df, size_t n_df)
{
    size_t n = 0, cap = 0;
    *q = NULL;
    for (size_t i = 0; i < n_df; ++i) {
        rch_data d;
        rch_diag dg;
        memset(&dg, 0, sizeof dg);
        memset(&d, 0, sizeof d);
        if (df[i].mem) { /* the run's own reading: its rows' joints */
            d.n = df[i].mem->n;
        } else if (rch_data_load(&d, df[i].file, 0, &dg) != 0 &&
                   rch_data_load(&d, df[i].file, RCH_DATA_POSITIONS | RCH_DATA_NO_LEN, &dg) != 0)
            continue;
        for (size_t k = 0; k < d.n && n < AIM_MAX_POSES; ++k) {
            if (n == cap) {
                const size_t nc = cap ? 2 * cap : 1024;
                double(*t)[RC_NJ] = realloc(*q, nc * sizeof **q);
                if (!t)
                    break;
                *q = t;
                cap = nc;
            }
            memcpy((*q)[n++], df[i].mem ? df[i].mem->q_rad[k] : d.s[k].q_rad, sizeof **q);
        }
        if (!df[i].mem)
            rch_data_free(&d);
    }
    return n;
}

/* Before and the workspace figure at the flange, from the model file. */
static void from_model(aim_fig *a, const rep *r, const dfile *df, size_t n_df)
{
    rch_robot *robot = calloc(1, sizeof *robot);
    rch_diag dg;
    memset(&dg, 0, sizeof dg);
    /* a run's own model text: parsed as rch_robot_load parses the file (which refuses one over 64 KiB) */
    const char *mt = r->mem ? r->mem->model_text : NULL;
    const size_t ml = mt ? r->mem->model_len : 0;
    if (!robot || !r->cfg->model_path ||
        (mt ? ml > ((size_t)1 << 16) || rch_robot_parse(robot, mt, ml, r->cfg->model_path, &dg) != 0
            : rch_robot_load(robot, r->cfg->model_path, &dg) != 0)) {
        free(robot);
        return;
    }
    rc_model det, cal, nom;
    rch_model_unc unc;
    int v1 = 0;
    char held[8];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, robot, &robot->nominal);
    rch_comp_point_model(&cal, &det, NULL);
    rch_comp_point_model(&nom, &robot->nominal, NULL);
    memcpy(nom.q_min_rad, robot->model.q_min_rad, sizeof nom.q_min_rad);
    memcpy(nom.q_max_rad, robot->model.q_max_rad, sizeof nom.q_max_rad);
    double(*q)[RC_NJ] = NULL;
    size_t n = data_poses(&q, df, n_df);
    a->before_over_data = n > 0;
    if (n == 0) {
        free(q);
        q = malloc(AIM_RANDOM_POSES * sizeof *q);
        rc_rng g;
        rc_rng_seed(&g, AIM_SEED);
        for (size_t i = 0; q && i < AIM_RANDOM_POSES; ++i)
            for (unsigned j = 0; j < RC_NJ; ++j)
                q[i][j] = nom.q_min_rad[j] + (nom.q_max_rad[j] - nom.q_min_rad[j]) * rc_rng_u01(&g);
        n = q ? AIM_RANDOM_POSES : 0;
    }
    double *v = malloc((n > AIM_RANDOM_POSES ? n : AIM_RANDOM_POSES) * sizeof *v);
    if (v && n) {
        for (size_t i = 0; i < n; ++i) {
            double pc[3], pn[3];
            rc_fk(pc, NULL, &cal, q[i]);
            rc_fk(pn, NULL, &nom, q[i]);
            v[i] = sqrt((pc[0] - pn[0]) * (pc[0] - pn[0]) + (pc[1] - pn[1]) * (pc[1] - pn[1]) +
                        (pc[2] - pn[2]) * (pc[2] - pn[2]));
        }
        rch_median_max(&a->before_median, &a->before_max, v, n);
        a->before_n = n;
    }
    if (v && robot->unc.present && !isfinite(a->ws_median)) {
        rc_rng g;
        rc_rng_seed(&g, AIM_SEED);
        size_t m = 0;
        for (size_t i = 0; i < AIM_RANDOM_POSES; ++i) {
            double qr[RC_NJ];
            for (unsigned j = 0; j < RC_NJ; ++j)
                qr[j] = nom.q_min_rad[j] + (nom.q_max_rad[j] - nom.q_min_rad[j]) * rc_rng_u01(&g);
            const double u = rch_model_unc_pos95_mm(&robot->unc, &cal, qr);
            if (isfinite(u))
                v[m++] = u;
        }
        if (m)
            rch_median_max(&a->ws_median, &a->ws_max, v, m);
    }
    free(v);
    free(q);
    free(robot);
}

void rch_rep_aim(aim_fig *a, const rep *r, const dfile *df, size_t n_df)
{
    memset(a, 0, sizeof *a);
    a->after_median = a->after_max = a->ws_median = a->ws_max = NAN;
    a->before_median = a->before_max = NAN;
    a->point = "the flange centre";
    const char *at = jstr(r->unc, "seen_point.at");
    const double fm = jnum(r->unc, "seen_point.flange_position95_median_mm"),
                 fx = jnum(r->unc, "seen_point.flange_position95_max_mm");
    if (isfinite(fm) && isfinite(fx)) {
        /* the data saw another point (the attachment, tracker targets): the
         * flange's own figure; the map's workspace figure is at that point */
        a->after_median = fm;
        a->after_max = fx;
        a->seen = at && strcmp(at, "attachment") == 0 ? "the cable attachment point"
                  : at && strcmp(at, "targets") == 0  ? "the tracker's targets"
                                                       : "the point the data see";
        a->seen_median = jnum(r->unc, "seen_point.position95_median_mm");
    } else {
        a->after_median = jnum(r->unc, "position95_mm.data_median");
        a->after_max = jnum(r->unc, "position95_mm.data_max");
        a->ws_median = jnum(r->unc, "position95_mm.workspace_median");
        a->ws_max = jnum(r->unc, "position95_mm.workspace_max");
        if (!at) /* a calibration output from before seen_point: the map's point is not named */
            a->point = "the measured point";
    }
    from_model(a, r, df, n_df);
}
