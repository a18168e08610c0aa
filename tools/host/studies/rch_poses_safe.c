/* SPDX-License-Identifier: MIT */
/* rch_poses_safe.c - the planner's candidate filter for the cable and the
 * cell (issue 48, item 4; see rch_poses.h and rch_cell.h): a candidate whose
 * straight cable comes within the clearance of a link, a box or the floor,
 * or whose flange or a link is below the floor, is not planned.
 * Depends on: rch_cell. Memory: none. */
#include <stdio.h>

#include "rch_poses_int.h"

int rch_poses_safe(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, const rc_sample *q,
                   unsigned k)
{
    ++res->n_checked;
    if (!rch_cell_any(c->cell))
        return 1;
    const double *outlet = c->n_outlets ? c->outlet_mm[k] : &m->x[RC_P_ENC];
    const double flange[3] = {0.0, 0.0, 0.0};
    const unsigned np = c->n_points ? c->n_points : 1u;
    for (unsigned p = 0; p < np; ++p) {
        const double *att = c->n_points ? c->points_mm[p] : c->has_tool ? c->tool_mm : flange;
        rch_cell_verdict v;
        rch_cell_check(&v, c->cell, m, q->q_rad, outlet, att, c->clearance_mm);
        if (v.reason != RCH_CELL_SAFE) {
            ++res->dropped[v.reason];
            return 0;
        }
    }
    return 1;
}

void rch_poses_dropped_str(char *buf, size_t size, const rch_poses_result *res)
{
    size_t at = 0;
    buf[0] = '\0';
    for (unsigned r = 1; r < RCH_CELL_N_REASONS && at < size; ++r)
        if (res->dropped[r])
            at += (size_t)snprintf(buf + at, size - at, "%s%zu %s", at ? ", " : "", res->dropped[r],
                                   rch_cell_reason_name((rch_cell_reason)r));
    if (!at)
        snprintf(buf, size, "none");
}
