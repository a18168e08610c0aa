/* SPDX-License-Identifier: MIT */
/* rc_kin_compile.c - the solver model (rc_model, double) compiled into the
 * compensation's constant kinematic table (rc_kin, rc_real). Kept apart from
 * rc_kin.c so that a firmware linking generated tables carries no double
 * code (on a single-precision FPU the conversion would be a library call). */
#include "rc_kin.h"

#include <math.h>
#include <string.h>

#include "rc_model.h"

static int link_set(rc_kin_link *l, const double dh[4])
{
    for (unsigned k = 0; k < 4; ++k)
        if (!isfinite(dh[k]))
            return -1;
    l->a_mm = (rc_real)dh[0];
    l->d_mm = (rc_real)dh[1];
    l->cos_alpha = (rc_real)cos(dh[2]);
    l->sin_alpha = (rc_real)sin(dh[2]);
    l->theta_off_rad = (rc_real)dh[3];
    return 0;
}

static rc_status fail(rc_kin *out, rc_status st)
{
    memset(out, 0, sizeof *out);
    return st;
}

rc_status rc_kin_compile(rc_kin *out, const rc_model *m)
{
    RC_ASSERT(out != NULL && m != NULL);
    memset(out, 0, sizeof *out);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        if (link_set(&out->link[i], &m->x[4 * i]) != 0)
            return fail(out, RC_ERR_RANGE);
        if (!isfinite(m->q_min_rad[i]) || !isfinite(m->q_max_rad[i]) || m->q_min_rad[i] > m->q_max_rad[i])
            return fail(out, RC_ERR_RANGE);
        out->q_min_rad[i] = (rc_real)m->q_min_rad[i];
        out->q_max_rad[i] = (rc_real)m->q_max_rad[i];
    }
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        const double *p = &m->x[e->first];
        if ((unsigned)e->first + e->count > m->n_params)
            return fail(out, RC_ERR_RANGE);
        for (unsigned k = 0; k < e->count; ++k)
            if (!isfinite(p[k]))
                return fail(out, RC_ERR_RANGE);
        switch ((rc_effect_kind)e->kind) {
        case RC_EFF_AXIS_TILT: {
            if (e->joint >= RC_NJ)
                return fail(out, RC_ERR_RANGE);
            const double h = sin(0.5 * p[0]);
            out->link[e->joint].tilt_cm1_rad = (rc_real)(-2.0 * h * h); /* as rc_model.c's model_tilts */
            out->link[e->joint].tilt_sin = (rc_real)sin(p[0]);
            break;
        }
        case RC_EFF_TOOL_OFFSET:
            if (out->has_tool)
                break; /* rc_fk uses the first tool offset */
            for (unsigned k = 0; k < 3; ++k)
                out->tool_mm[k] = (rc_real)p[k];
            out->has_tool = 1;
            break;
        case RC_EFF_JOINT_PERIODIC:
        case RC_EFF_JOINT_COMPLIANCE: {
            if (out->n_jeff >= RC_KIN_MAX_JOINT_EFFECTS || e->joint >= RC_NJ)
                return fail(out, e->joint >= RC_NJ ? RC_ERR_RANGE : RC_ERR_CAPACITY);
            rc_kin_jeffect *je = &out->jeff[out->n_jeff++];
            je->kind = e->kind == RC_EFF_JOINT_PERIODIC ? (uint8_t)RC_KIN_JE_PERIODIC : (uint8_t)RC_KIN_JE_COMPLIANCE;
            je->joint = e->joint;
            for (unsigned k = 0; k < 4 && k < e->count; ++k)
                je->c[k] = (rc_real)p[k];
            if (e->kind == RC_EFF_JOINT_COMPLIANCE) {
                if (out->n_ref >= RC_KIN_MAX_COMPLIANCE)
                    return fail(out, RC_ERR_CAPACITY);
                if (e->joint > 3)
                    return fail(out, RC_ERR_RANGE);
                for (unsigned r = 0; r < 4; ++r)
                    if (link_set(&out->ref[out->n_ref].link[r], e->ref_dh[r]) != 0)
                        return fail(out, RC_ERR_RANGE);
                je->ref = out->n_ref++;
            }
            break;
        }
        default: break; /* length-side effects do not move the flange */
        }
    }
    return RC_OK;
}
