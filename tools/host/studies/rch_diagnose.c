/* SPDX-License-Identifier: MIT */
/* rch_diagnose.c - what the diagnosis's phases and its search share: the
 * fits (one LM fit, the cross-validation over the folds, the rank of a
 * model's parameters by the one definition of identifiability) and the
 * result's release. The workflow is rch_diagnose_run.c; see rch_diagnose.h.
 * Depends on: the core (rc_solve, rc_ident). Memory: rch_dg_rank_at
 * allocates its scratch and frees it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_ident.h"
#include "rch_diagnose_int.h"
#include "rch_inputs.h"

int rch_dg_fit(rc_model *m, rc_solve_result *res, ctx *c, const uint8_t *fixed, const rc_sample *s,
               size_t n)
{
    rc_solve_config cfg;
    rc_solve_result tmp;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_METHOD_LM;
    cfg.max_iter = fixed || s == c->s ? 200u : c->max_iter; /* cold starts converge fully */
    cfg.fixed = fixed ? fixed : c->have_fixed ? c->fixed0 : NULL;
    return rc_solve(m, res ? res : &tmp, c->w, &cfg, s, n) == RC_OK ? 0 : -1;
}

/* A group with no training sample has no fitted offset (the solver leaves
 * it at zero, an arbitrary level): predict it like a new set-up, with the
 * sample-weighted mean offset of the groups that were seen. */
static void unseen_groups(rc_model *m, const rc_sample *train, size_t n)
{
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        if (ef->kind != RC_EFF_GROUP_OFFSET)
            continue;
        size_t *cnt = calloc(ef->count, sizeof *cnt);
        if (!cnt)
            return;
        for (size_t i = 0; i < n; ++i)
            if (train[i].group < ef->count)
                cnt[train[i].group]++;
        double sum = 0.0;
        size_t tot = 0;
        for (unsigned g = 0; g < ef->count; ++g) {
            sum += (double)cnt[g] * m->x[ef->first + g];
            tot += cnt[g];
        }
        for (unsigned g = 0; g < ef->count; ++g)
            if (cnt[g] == 0 && tot > 0)
                m->x[ef->first + g] = sum / (double)tot;
        free(cnt);
    }
}

/* Cross-validate: models (k) in: starts, out: fitted on each fold's training
 * samples; res (n) out: held-out residuals l - L. */
int rch_dg_cv_run(rc_model *models, double *res, ctx *c)
{
    for (unsigned f = 0; f < c->k; ++f) {
        if (rch_dg_fit(&models[f], NULL, c, NULL, c->train[f], c->n_train[f]) != 0)
            return -1;
        unseen_groups(&models[f], c->train[f], c->n_train[f]);
    }
    for (size_t i = 0; i < c->n; ++i) {
        double l;
        if (rc_meas(&l, NULL, &models[c->fold[i]], &c->s[i]) != RC_OK)
            return -1;
        res[i] = l - c->s[i].value;
    }
    return 0;
}

/* Rank of the first np parameters of m over the samples: the number of
 * directions rc_ident (the one definition of identifiability) does not call
 * null. dump: print the relative singular values to stderr. */
unsigned rch_dg_rank_at(const rc_model *m, unsigned np, const rc_sample *s, size_t n, rc_solve_work *w, int dump)
{
    double cost;
    for (unsigned i = 0; i < np; ++i)
        w->lsq.idx[i] = (uint16_t)i;
    if (rc_normal_eq(w->A, w->lsq.g, &cost, w->lsq.jrow, m, w->lsq.idx, np, s, n) != RC_OK)
        return 0;
    double *work = malloc(rc_ident_work_size(np) * sizeof *work);
    rc_ident id;
    const rc_status st = work ? rc_ident_normal(&id, w->V, work, w->A, np, n) : RC_ERR_CAPACITY;
    free(work);
    if (st != RC_OK)
        return 0;
    if (dump)
        for (unsigned k = 0; k < np; ++k)
            fprintf(stderr, "  sv_rel[%u] = %.3e\n", k, id.sv_rel[k]);
    return id.rank;
}

void rch_diagnose_free(rch_diagnose_result *r)
{
    if (!r)
        return;
    free(r->s);
    free(r->res_before_mm);
    free(r->res_after_mm);
    free(r->floor_mm);
    free(r->line);
    free(r->file);
    r->line = r->file = NULL;
    if (r->raw) {
        rch_inputs_free(r->raw);
        free(r->raw);
        r->raw = NULL;
    }
    r->s = NULL;
    r->res_before_mm = r->res_after_mm = r->floor_mm = NULL;
}
