/* SPDX-License-Identifier: MIT */
/* rch_ffi_comp.c - compensation of a batch of joint targets through the
 * flat C API (see rch_ffi.h): the model set-up of rch_comp_run (the
 * determined model, the mode, the tool point both models move), the same
 * stream stepped per target, full-precision joints and u95 per target.
 * Depends on: rch_comp, rch_uncert, the core (rc_comp). Memory: the set-up
 * on the heap, freed before return. Errors: a status, the message into err
 * (a target outside the joint limits stops the batch). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_comp.h"
#include "rch_comp.h"
#include "rch_ffi_int.h"
#include "rch_uncert.h"

/* ---- compensation ---- */

/* The compensation set-up of rch_comp_run (rch_comp_run.c): the determined
 * model, the mode, the point both models move. Heap: too large for a
 * thread's stack, and no static state. */
typedef struct {
    rc_model det, nom_pt;
    rch_model_unc unc;
    rc_comp_stream s;
} comp_setup;

int rch_ffi_compensate(const rch_ffi_model *cal, const rch_ffi_model *nominal, double *out_deg, int *status,
                       double *u95_mm, const double *q_deg, size_t n, int position_only, double max_dev_deg,
                       double max_unc_mm, int u95_policy, const double *tool_mm, char *err, size_t err_len)
{
    if (!cal || !out_deg || (!q_deg && n > 0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate: NULL argument");
    if (!(max_dev_deg >= 0.0) || !isfinite(max_dev_deg) || !(max_unc_mm >= 0.0) || position_only < 0 ||
        position_only > 2 || u95_policy < 0 || u95_policy > 2)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "compensate: max_dev_deg and max_unc_mm must be >= 0, position_only 0, 1 or 2, u95_policy 0, 1 "
                    "or 2");
    for (size_t i = 0; i < RC_NJ * n; ++i)
        if (!isfinite(q_deg[i])) {
            if (err && err_len > 0)
                snprintf(err, err_len, "compensate: target %zu: q%u is not finite", i / RC_NJ,
                         (unsigned)(i % RC_NJ) + 1u);
            return RCH_FFI_ERR_ARG;
        }
    for (unsigned k = 0; tool_mm && k < 3; ++k)
        if (!isfinite(tool_mm[k]) || fabs(tool_mm[k]) > 2000.0)
            return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate: tool_mm must be 3 finite numbers within "
                                                              "+-2000 mm");
    comp_setup *cs = malloc(sizeof *cs);
    if (!cs)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    const rch_robot *robot = &cal->robot;
    int version1 = 0;
    char held[256];
    cs->det = robot->model;
    memset(&cs->unc, 0, sizeof cs->unc);
    const int calibrated = robot->has_nominal || robot->unc.present;
    if (calibrated)
        rch_comp_determined(&cs->det, &cs->unc, &version1, held, sizeof held, robot, &robot->nominal);
    const int orient = cs->unc.present && !version1 && cs->unc.orientation_determined;
    rch_comp_point_model(&cs->det, &cs->det, tool_mm);
    rch_comp_point_model(&cs->nom_pt, nominal ? &nominal->robot.model : &robot->nominal, tool_mm);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = (rc_real)(max_dev_deg * DEG);
    rch_comp_orient od; /* the mode as rch_comp_run chooses it */
    memset(&od, 0, sizeof od);
    if (position_only == 0)
        rch_comp_orient_decide(&od, cs->unc.present && !version1 ? &cs->unc : NULL, &cs->det, &cs->nom_pt, &cfg);
    const int pos_only = rch_comp_position_only(&od, position_only == 1, position_only == 2, calibrated, orient);
    cfg.flags = pos_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    const rc_status st0 = rc_comp_stream_init(&cs->s, &cs->det, &cs->nom_pt, &cfg);
    if (st0 != RC_OK) {
        free(cs);
        return fail(RCH_FFI_ERR_NUMERIC, err, err_len, "the model cannot be used for compensation: %s",
                    rc_strerror(st0));
    }
    const rch_model_unc *gate = cs->unc.present && !version1 ? &cs->unc : NULL;
    const double lim = max_unc_mm > 0 ? max_unc_mm : !gate || gate->has_prior ? INFINITY : 1.0;
    const rc_model *m = &cs->det;
    int rc = RCH_FFI_OK;
    for (size_t i = 0; i < n && rc == RCH_FFI_OK; ++i) {
        const double *in = &q_deg[RC_NJ * i];
        rc_real q[RC_NJ], qc[RC_NJ];
        double qd[RC_NJ];
        for (unsigned j = 0; j < RC_NJ && rc == RCH_FFI_OK; ++j) {
            q[j] = (rc_real)(in[j] * DEG);
            qd[j] = (double)q[j];
            if (!(qd[j] >= m->q_min_rad[j] && qd[j] <= m->q_max_rad[j])) {
                if (err && err_len > 0)
                    snprintf(err, err_len, "target %zu: q%u = %g deg is outside the joint limits [%g, %g] deg", i,
                             j + 1, in[j], m->q_min_rad[j] / DEG, m->q_max_rad[j] / DEG);
                rc = RCH_FFI_ERR_RANGE;
            }
        }
        if (rc != RCH_FFI_OK)
            break;
        const double u95 = !gate ? NAN
                           : gate->has_prior ? rch_model_unc_radius95_mm(gate, m, qd)
                                             : rch_model_unc_pos95_mm(gate, m, qd);
        /* no uncertainty: u95 NaN (unknown), beyond any limit the caller sets (as rch_comp.c) */
        const int beyond = gate ? !(u95 <= lim) : isfinite(lim);
        if (beyond && u95_policy == 2) {
            if (err && err_len > 0)
                snprintf(err, err_len, "target %zu: the model's 95 %% position uncertainty at the compensated point is "
                         "%.4f mm here, above %.4f mm (u95_policy refuse: nothing returned)", i, u95, lim);
            rc = RCH_FFI_ERR_RANGE;
            break;
        }
        if (beyond && u95_policy == 0) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                out_deg[RC_NJ * i + j] = in[j]; /* left uncompensated: uncertainty above the limit */
            if (status)
                status[i] = 3;
            if (u95_mm)
                u95_mm[i] = rch_comp_u95_written(u95, 3, 0.0);
            continue;
        }
        rc_comp_result res;
        const rc_status st = rc_comp_stream_step(&cs->s, qc, &res, q);
        for (unsigned j = 0; j < RC_NJ; ++j)
            out_deg[RC_NJ * i + j] = (double)qc[j] / DEG;
        const int how = st != RC_OK ? 2 : res.exit == RC_COMP_POSITION_ONLY ? 1 : 0;
        if (status)
            status[i] = how;
        if (u95_mm)
            u95_mm[i] = rch_comp_u95_written(u95, how, (double)res.pos_err_mm);
    }
    free(cs);
    return rc;
}

int rch_ffi_compensate_mode(const rch_ffi_model *cal, const rch_ffi_model *nominal, int position_only,
                            double max_dev_deg, const double *tool_mm, double out[4], char *err, size_t err_len)
{
    if (!cal || !out)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate_mode: NULL argument");
    if (position_only < 0 || position_only > 2 || !(max_dev_deg >= 0.0) || !isfinite(max_dev_deg))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "compensate_mode: position_only must be 0, 1 or 2, max_dev_deg finite and >= 0");
    comp_setup *cs = malloc(sizeof *cs);
    if (!cs)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    const rch_robot *robot = &cal->robot;
    int version1 = 0;
    char held[256];
    cs->det = robot->model;
    memset(&cs->unc, 0, sizeof cs->unc);
    const int calibrated = robot->has_nominal || robot->unc.present;
    if (calibrated)
        rch_comp_determined(&cs->det, &cs->unc, &version1, held, sizeof held, robot, &robot->nominal);
    rch_comp_point_model(&cs->det, &cs->det, tool_mm);
    rch_comp_point_model(&cs->nom_pt, nominal ? &nominal->robot.model : &robot->nominal, tool_mm);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = (rc_real)(max_dev_deg * DEG);
    rch_comp_orient od;
    memset(&od, 0, sizeof od);
    if (position_only == 0)
        rch_comp_orient_decide(&od, cs->unc.present && !version1 ? &cs->unc : NULL, &cs->det, &cs->nom_pt, &cfg);
    out[0] = rch_comp_position_only(&od, position_only == 1, position_only == 2, calibrated,
                                    cs->unc.present && !version1 && cs->unc.orientation_determined);
    out[1] = position_only ? 0.0 : od.known ? 1.0 : 2.0;
    out[2] = od.known ? od.uncorr_deg : NAN;
    out[3] = od.known ? od.unc_deg : NAN;
    free(cs);
    return RCH_FFI_OK;
}
