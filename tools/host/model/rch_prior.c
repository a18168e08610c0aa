/* SPDX-License-Identifier: MIT */
/* rch_prior.c - the physical prior of a calibration (see rch_prior.h). */
#include "rch_prior.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

void rch_prior_defaults(rch_prior_cfg *p)
{
    memset(p, 0, sizeof *p);
    p->length_mm = RCH_PRIOR_LENGTH_MM;
    p->twist_deg = RCH_PRIOR_TWIST_DEG;
    p->offset_deg = RCH_PRIOR_OFFSET_DEG;
    p->attachment_mm = RCH_PRIOR_ATTACHMENT_MM;
    p->points_mm = RCH_PRIOR_POINTS_MM;
}

void rch_prior_fill(double *mean, double *sd, const rc_model *m, const rc_model *nominal, const rch_prior_cfg *p)
{
    for (unsigned k = 0; k < m->n_params; ++k) {
        mean[k] = m->x[k];
        sd[k] = 0.0;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        mean[RC_P_A(i)] = nominal->x[RC_P_A(i)];
        mean[RC_P_D(i)] = nominal->x[RC_P_D(i)];
        mean[RC_P_ALPHA(i)] = nominal->x[RC_P_ALPHA(i)];
        mean[RC_P_THETA(i)] = nominal->x[RC_P_THETA(i)];
        sd[RC_P_A(i)] = sd[RC_P_D(i)] = p->length_mm;
        sd[RC_P_ALPHA(i)] = p->twist_deg * DEG;
        sd[RC_P_THETA(i)] = p->offset_deg * DEG;
    }
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        const rc_effect_desc *ds = rc_effect_describe(ef->kind);
        if (ef->kind == RC_EFF_TOOL_OFFSET) {
            for (unsigned k = 0; k < ef->count; ++k)
                sd[ef->first + k] = p->attachment_mm;
        } else if (ef->kind == RC_EFF_CABLE_POINTS) { /* the plate's drawing, to its tolerance */
            for (unsigned k = 0; k < ef->count; ++k)
                sd[ef->first + k] = p->points_mm > 0.0 ? p->points_mm : RCH_PRIOR_POINTS_MM;
        } else if (ef->kind == RC_EFF_AXIS_TILT) { /* a twist about the other axis: the twists' tolerance */
            sd[ef->first] = p->twist_deg * DEG;
        } else if (ds && !ds->nuisance && ds->side != RC_SIDE_OUTLET &&
                   (ds->side != RC_SIDE_SENSOR || ef->kind == RC_EFF_TRACKER_SCALE)) {
            /* (the tracker's scale is physical, its frame and targets are where it stands: no prior) */
            /* a physical effect: its plausible range (the table's limit) as
             * 3 sd about its start value, so that a fit cannot trade it into
             * something no sensor or joint does (a 31 m "drum period") */
            for (unsigned k = 0; k < ef->count; ++k)
                sd[ef->first + k] = ds->limit / 3.0;
        }
    }
}

void rch_prior_gauge(uint8_t *fixed)
{
    fixed[RC_P_THETA(0)] = 1;
    fixed[RC_P_D(0)] = 1;
}

rch_prior_class rch_prior_classify(double post_sd, double prior_sd)
{
    if (!(prior_sd > 0.0) || !isfinite(prior_sd) || !isfinite(post_sd))
        return RCH_PRIOR_CLASS_NONE;
    const double r = post_sd / prior_sd;
    return r < RCH_PRIOR_DETERMINED ? RCH_PRIOR_CLASS_DETERMINED
                                    : r < RCH_PRIOR_ONLY ? RCH_PRIOR_CLASS_PARTLY : RCH_PRIOR_CLASS_PRIOR_ONLY;
}

const char *rch_prior_class_name(rch_prior_class c)
{
    switch (c) {
    case RCH_PRIOR_CLASS_NONE: return "no prior";
    case RCH_PRIOR_CLASS_DETERMINED: return "determined";
    case RCH_PRIOR_CLASS_PARTLY: return "partly";
    case RCH_PRIOR_CLASS_PRIOR_ONLY: return "prior only";
    }
    return "?";
}

int rch_prior_outlet_span(double *off_line_mm, const double (*pos_mm)[3], unsigned n)
{
    unsigned a = 0, b = 0;
    double span = 0.0, off = 0.0;
    for (unsigned i = 0; i < n; ++i)
        for (unsigned j = i + 1; j < n; ++j) {
            const double dx = pos_mm[j][0] - pos_mm[i][0], dy = pos_mm[j][1] - pos_mm[i][1],
                         dz = pos_mm[j][2] - pos_mm[i][2], dd = sqrt(dx * dx + dy * dy + dz * dz);
            if (dd > span) {
                span = dd;
                a = i;
                b = j;
            }
        }
    if (off_line_mm)
        *off_line_mm = 0.0;
    if (n <= 1 || !(span > 1e-9))
        return 1;
    double u[3];
    for (int c = 0; c < 3; ++c)
        u[c] = (pos_mm[b][c] - pos_mm[a][c]) / span;
    for (unsigned i = 0; i < n; ++i) {
        double v[3], t = 0.0, d2 = 0.0;
        for (int c = 0; c < 3; ++c) {
            v[c] = pos_mm[i][c] - pos_mm[a][c];
            t += v[c] * u[c];
        }
        for (int c = 0; c < 3; ++c)
            d2 += (v[c] - t * u[c]) * (v[c] - t * u[c]);
        if (sqrt(d2) > off)
            off = sqrt(d2);
    }
    if (off_line_mm)
        *off_line_mm = off;
    return off > RCH_OUTLET_LINE_SHARE * span ? 3 : 2;
}

const char *rch_prior_outlet_span_text(int span)
{
    switch (span) {
    case 1: return "one outlet: the rotation of the whole robot about the outlet is not observable, so the robot's "
                   "placement in the cell is not known from the lengths; compensation is judged on pairwise distances";
    case 2: return "the outlets lie on a line: the rotation of the whole robot about that line is not observable; "
                   "compensation is judged on pairwise distances";
    default: return "three or more outlets not on a line: the robot is fixed in the outlets' frame (their estimated "
                    "positions place it in the cell)";
    }
}
