/* SPDX-License-Identifier: MIT */
/* rch_poses_plan.c - rch_poses_plan (see rch_poses.h): the entry that picks
 * the criterion, the predicted 3-D accuracy (rch_poses_position.c, the
 * default) or D-optimal lengths from one outlet (rch_poses_length.c).
 * Memory: the result's poses on the heap (rch_poses_free). Errors: -1 with
 * d set. */
#include <string.h>

#include "rch_poses_int.h"

int rch_poses_plan(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
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
    return rch_poses_plan_position(res, m, c, progress, d);
}

