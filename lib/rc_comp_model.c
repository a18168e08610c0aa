/* SPDX-License-Identifier: MIT */
/* rc_comp_model.c - the compensation on the solver's rc_model: compile it
 * into an rc_kin (rc_kin_compile), then run the engine of rc_comp.c. Host
 * code calls these; firmware links generated rc_kin tables and the engine
 * alone. The single-call wrappers keep their compiled tables and scratch on
 * the stack (about 6 KB in double: scripts/stack_usage.sh); the stream keeps
 * them in itself. */
#include "rc_comp.h"

#include <math.h>
#include <string.h>

/* 1 when q (6) is finite and inside m's joint limits. */
static int model_within_limits(const rc_model *m, const rc_real q[RC_NJ])
{
    for (unsigned i = 0; i < RC_NJ; ++i)
        if (!isfinite(q[i]) || (double)q[i] < m->q_min_rad[i] || (double)q[i] > m->q_max_rad[i])
            return 0;
    return 1;
}

static int finite_n(const rc_real *v, unsigned n)
{
    for (unsigned i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* A model that does not compile: the answer the engine gives for a model
 * with non-finite values (q_out = fallback, exit NONFINITE). */
static rc_status model_broken(rc_real q_out[RC_NJ], rc_comp_result *res, const rc_real fallback[RC_NJ])
{
    memcpy(q_out, fallback, RC_NJ * sizeof q_out[0]);
    if (res != NULL) {
        memset(res, 0, sizeof *res);
        res->exit = RC_COMP_NONFINITE;
    }
    return RC_ERR_NUMERIC;
}

rc_status rc_comp_pose(rc_real q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *m, const rc_real pos_mm[3],
                       const rc_real rot[9], const rc_real seed_rad[RC_NJ], const rc_comp_config *cfg)
{
    rc_kin k;
    rc_comp_work w;
    RC_ASSERT(q_out_rad != NULL && m != NULL && pos_mm != NULL && seed_rad != NULL);
    if (rc_kin_compile(&k, m) != RC_OK) {
        if (!model_within_limits(m, seed_rad) || !finite_n(pos_mm, 3) || (rot != NULL && !finite_n(rot, 9))) {
            /* as the engine: q_out = seed clamped (zeros if not finite) */
            for (unsigned i = 0; i < RC_NJ; ++i) {
                double v = finite_n(seed_rad, RC_NJ) ? (double)seed_rad[i] : 0.0;
                if (finite_n(seed_rad, RC_NJ))
                    v = v < m->q_min_rad[i] ? m->q_min_rad[i] : (v > m->q_max_rad[i] ? m->q_max_rad[i] : v);
                q_out_rad[i] = (rc_real)v;
            }
            if (res != NULL) {
                memset(res, 0, sizeof *res);
                res->exit = RC_COMP_BAD_INPUT;
            }
            return RC_ERR_RANGE;
        }
        return model_broken(q_out_rad, res, seed_rad);
    }
    return rc_comp_kin_pose(q_out_rad, res, &w, &k, pos_mm, rot, seed_rad, cfg);
}

rc_status rc_comp_joint(rc_real q_out_rad[RC_NJ], rc_comp_result *res, const rc_model *cal, const rc_model *nom,
                        const rc_real q_rad[RC_NJ], const rc_real seed_rad[RC_NJ], const rc_comp_config *cfg)
{
    rc_kin kc, kn;
    rc_comp_work w;
    RC_ASSERT(q_out_rad != NULL && cal != NULL && nom != NULL && q_rad != NULL);
    if (rc_kin_compile(&kc, cal) != RC_OK || rc_kin_compile(&kn, nom) != RC_OK) {
        if (!model_within_limits(cal, q_rad) || (seed_rad != NULL && !finite_n(seed_rad, RC_NJ))) {
            const int ok = finite_n(q_rad, RC_NJ);
            for (unsigned i = 0; i < RC_NJ; ++i)
                q_out_rad[i] = ok ? q_rad[i] : RC_REAL_C(0.0);
            if (res != NULL) {
                memset(res, 0, sizeof *res);
                res->exit = RC_COMP_BAD_INPUT;
            }
            return RC_ERR_RANGE;
        }
        return model_broken(q_out_rad, res, q_rad);
    }
    return rc_comp_kin_joint(q_out_rad, res, &w, &kc, &kn, q_rad, seed_rad, cfg);
}

#if RC_COMP_STREAM_OWN_MODELS
rc_status rc_comp_stream_init(rc_comp_stream *s, const rc_model *cal, const rc_model *nom, const rc_comp_config *cfg)
{
    RC_ASSERT(s != NULL && cal != NULL && nom != NULL);
    memset(s, 0, sizeof *s);
    if (cfg != NULL)
        s->cfg = *cfg;
    s->cal = NULL; /* the step uses own[0] and own[1] */
    s->nom = NULL;
    rc_status st = rc_kin_compile(&s->own[0], cal);
    const rc_status sn = rc_kin_compile(&s->own[1], nom);
    if (st == RC_OK)
        st = sn;
    if (st != RC_OK) {
        /* keep the limits so that bad targets are still told apart */
        for (unsigned i = 0; i < RC_NJ; ++i) {
            s->own[0].q_min_rad[i] = (rc_real)cal->q_min_rad[i];
            s->own[0].q_max_rad[i] = (rc_real)cal->q_max_rad[i];
        }
    }
    s->model_status = st;
    return st;
}
#endif
