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

#include <stdio.h>
#include <string.h>

#include "rc_rand.h"

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
            if (rc_meas(&s[k].len_mm, NULL, &m, &s[k]) == RC_OK)
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
