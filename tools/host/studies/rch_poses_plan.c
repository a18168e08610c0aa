/* SPDX-License-Identifier: MIT */
/* rch_poses_plan.c - rch_poses_plan (see rch_poses.h): the entry that picks
 * the criterion, the predicted 3-D accuracy (rch_poses_position.c, the
 * default) or D-optimal lengths from one outlet (rch_poses_length.c); on a
 * tool plate, what each further point gains.
 * Memory: the result's poses on the heap (rch_poses_free). Errors: -1 with
 * d set. */
#include <stdlib.h>
#include <string.h>

#include "rch_poses_int.h"

/* What each further point of a tool plate gains: the plan's poses measured
 * on points 0..j only, predicted at the same point (flange or tool). */
static void point_gains(rch_poses_result *res, const rc_model *m, const rch_poses_config *c)
{
    res->n_points = c->n_points;
    rc_sample *rows = c->n_points ? malloc((res->n ? res->n : 1) * sizeof *rows) : NULL;
    for (unsigned j = 1; rows && j <= c->n_points; ++j) {
        rch_poses_config cj = *c;
        cj.n_points = j;
        size_t n = 0;
        for (size_t i = 0; i < res->n; ++i)
            if (res->poses[i].target < j)
                rows[n++] = res->poses[i];
        rch_diag dg;
        res->by_points[j - 1].rows = n;
        res->by_points[j - 1].ok = rch_poses_predict(&res->by_points[j - 1].acc, m, &cj, rows, n, &dg) == 0;
    }
    free(rows);
}

/* The selection ordered for travel (rch_poses_order), or measured only with keep_order. */
static int order_rows(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, rch_diag *d)
{
    if (!c->keep_order)
        return rch_poses_order(res->poses, res->n, m, c->margin_deg, &res->travel, d);
    rch_poses_travel_of(&res->travel, res->poses, res->n, m, c->margin_deg);
    return 0;
}

static int plan_rows(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                     rch_diag *d);

int rch_poses_plan(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                   rch_diag *d)
{
    if (plan_rows(res, m, c, progress, d) != 0)
        return -1;
    if (order_rows(res, m, c, d) != 0) {
        rch_poses_free(res);
        return -1;
    }
    return 0;
}

static int plan_rows(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                     rch_diag *d)
{
    memset(res, 0, sizeof *res);
    if (c->criterion == RCH_POSES_LENGTH) {
        if (c->n_outlets > 1 || c->split) {
            rch_diag_set(d, "", 0, 0, "--criterion length plans for one outlet; several outlets need --criterion "
                                      "position");
            return -1;
        }
        if (c->n_outlets == 1) {
            rc_model one = *m;
            memcpy(&one.x[RC_P_ENC], c->outlet_mm[0], 3 * sizeof(double));
            return rch_poses_plan_length(res, &one, c, progress, d);
        }
        return rch_poses_plan_length(res, m, c, progress, d);
    }
    if (rch_poses_plan_position(res, m, c, progress, d) != 0)
        return -1;
    point_gains(res, m, c);
    return 0;
}

