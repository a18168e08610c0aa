/* SPDX-License-Identifier: MIT */
/* rch_comp_model.c - the models compensation moves (see rch_comp.h): a
 * model rebuilt without its nuisance effects or its cable attachment, with
 * a TCP as its tool offset (rch_comp_point_model: the point compensation
 * aims), and the determined model of a version-1 or --no-prior file (the
 * parameters tied to weak or null directions held at nominal, named).
 * Depends on: rc_model, rc_rand (lib), rch_uncert. Memory: static samples
 * (a version-1 file; one call at a time). Errors: none (a model is always
 * made; what is held is counted). */
#include "rch_comp.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rc_rand.h"
#include "rc_sensor.h"

void rch_model_rebuild(rc_model *out, const rc_model *m, int drop_nuisance, int drop_point, const double *tool_mm)
{
    double dh[RC_NJ][4];
    for (unsigned i = 0; i < RC_NJ; ++i)
        for (unsigned k = 0; k < 4; ++k)
            dh[i][k] = m->x[4 * i + k];
    rc_model r;
    rc_model_init(&r, (const double(*)[4])dh, &m->x[RC_P_ENC]);
    memcpy(r.q_min_rad, m->q_min_rad, sizeof r.q_min_rad);
    memcpy(r.q_max_rad, m->q_max_rad, sizeof r.q_max_rad);
    if (tool_mm && rc_model_add_effect(&r, RC_EFF_TOOL_OFFSET, 0, 0) == RC_OK)
        memcpy(&r.x[r.effects[0].first], tool_mm, 3 * sizeof r.x[0]);
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        const rc_effect_desc *ds = rc_effect_describe(ef->kind);
        if ((drop_point && ef->kind == RC_EFF_TOOL_OFFSET) || (drop_nuisance && ds && ds->nuisance))
            continue;
        if (rc_model_add_effect(&r, (rc_effect_kind)ef->kind, ef->joint, ef->count) != RC_OK)
            continue;
        rc_effect *ne = &r.effects[r.n_effects - 1];
        memcpy(ne->ref_dh, ef->ref_dh, sizeof ne->ref_dh);
        memcpy(&r.x[ne->first], &m->x[ef->first], ef->count * sizeof r.x[0]);
    }
    *out = r;
}

void rch_comp_point_model(rc_model *out, const rc_model *m, const double *tool_mm)
{
    rch_model_rebuild(out, m, 0, 1, tool_mm);
}

unsigned rch_comp_determined(rc_model *det, rch_model_unc *unc, int *version1, char *held, size_t held_len,
                             const rch_robot *robot, const rc_model *nominal)
{
    *version1 = 0;
    if (robot->unc.present) {
        *unc = robot->unc;
    } else {
        /* version 1: what the nominal model's geometry lets cable lengths see */
        enum { N = 400 };
        static rc_sample s[N];
        rc_model m = *nominal;
        memcpy(&m.x[RC_P_ENC], &robot->model.x[RC_P_ENC], 3 * sizeof m.x[0]);
        memcpy(m.q_min_rad, robot->model.q_min_rad, sizeof m.q_min_rad);
        memcpy(m.q_max_rad, robot->model.q_max_rad, sizeof m.q_max_rad);
        rc_rng g;
        rc_rng_seed(&g, 20261129u);
        size_t k = 0;
        for (size_t i = 0; i < N; ++i) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                s[k].q_rad[j] = m.q_min_rad[j] + (m.q_max_rad[j] - m.q_min_rad[j]) * rc_rng_u01(&g);
            if (rc_meas(&s[k].value, NULL, &m, &s[k]) == RC_OK)
                ++k;
        }
        rch_uncert u;
        char err[128];
        memset(unc, 0, sizeof *unc);
        if (rch_uncert_compute(&u, &m, NULL, s, k, 0, err, sizeof err) == 0) {
            rch_model_unc_from(unc, &u);
            rch_uncert_free(&u);
        }
        memset(unc->cov_dh, 0, sizeof unc->cov_dh);
        /* compensation uses the whole estimate: nothing is held because it
         * shares a weak combination (a fit's weak directions stay where its
         * solver or prior left them) */
        memset(unc->comp_nominal, 0, sizeof unc->comp_nominal);
        *version1 = 1;
    }
    rch_model_unc_determined(det, &robot->model, nominal, unc);
    unsigned n = 0;
    size_t len = 0;
    if (held_len)
        held[0] = '\0';
    for (unsigned k = 0; k < RC_N_DH && k < unc->n; ++k)
        if (unc->comp_nominal[k]) {
            char nm[32];
            rc_param_name(nm, sizeof nm, &robot->model, k);
            if (len < held_len)
                len += (size_t)snprintf(held + len, held_len - len, "%s%s", n ? " " : "", nm);
            ++n;
        }
    return n;
}

void rch_comp_orient_decide(rch_comp_orient *o, const rch_model_unc *unc, const rc_model *det,
                            const rc_model *nominal, const rc_comp_config *cfg)
{
    memset(o, 0, sizeof *o);
    if (!unc || !unc->present)
        return;
    rc_comp_config pc; /* the position-only mode of the run */
    if (cfg)
        pc = *cfg;
    else
        memset(&pc, 0, sizeof pc);
    pc.flags |= RC_COMP_FLAG_POSITION_ONLY;
    rc_rng g;
    rc_rng_seed(&g, 20261205u);
    double sd = 0.0, st = 0.0;
    unsigned n = 0;
    for (unsigned i = 0; i < RCH_COMP_ORIENT_POSES; ++i) {
        double q[RC_NJ], p[3], Rc[9], Rn[9], D[9], w[3];
        for (unsigned j = 0; j < RC_NJ; ++j)
            q[j] = det->q_min_rad[j] + (det->q_max_rad[j] - det->q_min_rad[j]) * rc_rng_u01(&g);
        /* what position-only compensation leaves: the calibrated orientation at
         * its joints q' (its correction turns the flange too) against the
         * nominal one at the target */
        rc_real qr[RC_NJ], qc[RC_NJ];
        double qcd[RC_NJ];
        rc_comp_result cr;
        for (unsigned j = 0; j < RC_NJ; ++j)
            qr[j] = (rc_real)q[j];
        (void)rc_comp_joint(qc, &cr, det, nominal, qr, NULL, &pc); /* not converged: its best point */
        for (unsigned j = 0; j < RC_NJ; ++j)
            qcd[j] = (double)qc[j];
        rc_fk(p, Rc, det, qcd);
        rc_fk(p, Rn, nominal, q);
        for (int r = 0; r < 3; ++r) /* D = Rc Rn^T: the uncorrected rotation, base frame */
            for (int c = 0; c < 3; ++c)
                D[r * 3 + c] = Rc[r * 3] * Rn[c * 3] + Rc[r * 3 + 1] * Rn[c * 3 + 1] + Rc[r * 3 + 2] * Rn[c * 3 + 2];
        rc_rotvec_from_matrix(w, D);
        const double z[3] = {Rc[2], Rc[5], Rc[8]}; /* the tool's axis: the flange z axis */
        const double wz = w[0] * z[0] + w[1] * z[1] + w[2] * z[2];
        const double a2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - wz * wz;
        const double t = rch_model_unc_rot_trace(unc, det, qcd, 1, z);
        if (!isfinite(a2) || !isfinite(t))
            continue;
        sd += a2 > 0.0 ? a2 : 0.0;
        st += t;
        ++n;
    }
    if (n == 0)
        return;
    o->known = 1;
    o->uncorr_deg = sqrt(sd / n) * 180.0 / 3.14159265358979323846;
    o->unc_deg = sqrt(st / n) * 180.0 / 3.14159265358979323846;
    /* a margin: within RCH_COMP_ORIENT_TIE of each other the two are a tie, decided for position only (the
     * joints move least; a decision must not flip with the last digits of a fit: the real file's model had
     * 0.7931 against 0.7754 deg and full pose moved the wrist by 5.7 deg) */
    o->correct = sd > RCH_COMP_ORIENT_TIE * RCH_COMP_ORIENT_TIE * st;
    o->tie = !o->correct && sd > st;
}

int rch_comp_position_only(const rch_comp_orient *o, int forced_position, int forced_pose, int calibrated,
                           int orientation_determined)
{
    if (forced_position || forced_pose)
        return forced_position;
    if (!calibrated)
        return 0;
    return o && o->known ? !o->correct : !orientation_determined;
}
