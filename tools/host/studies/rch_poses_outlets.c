/* SPDX-License-Identifier: MIT */
/* rch_poses_outlets.c - which K of the candidate outlet places give the best
 * predicted 3-D accuracy (rch_poses_choose_outlets, see rch_poses.h): a
 * greedy position plan per combination, every combination up to
 * RCH_POSES_MAX_COMBOS, else greedily one place at a time.
 * Depends on: the position criterion (rch_poses_int.h), rch_prior
 * (rch_prior_outlet_span). Memory: the choice is the caller's (fixed size);
 * each plan's heap freed before the next. Errors: -1 with d set. */
#include <string.h>

#include "rch_poses_int.h"

/* One combination's figure: a greedy plan (no exchange) for those places. */
static int combo_eval(rch_poses_combo *cb, const rc_model *m, const rch_poses_config *c, const double (*cand)[3],
                      unsigned k, rch_diag *d)
{
    rch_poses_config cc = *c;
    rch_poses_result r;
    double pos[RC_MAX_OUTLETS][3];
    memset(&r, 0, sizeof r);
    cc.n_outlets = k;
    cc.passes = 0;
    cb->k = k;
    if (k < 2)
        cc.split = 0;
    for (unsigned j = 0; j < k; ++j) {
        memcpy(cc.outlet_mm[j], cand[cb->idx[j]], sizeof cc.outlet_mm[j]);
        memcpy(pos[j], cand[cb->idx[j]], sizeof pos[j]);
    }
    cb->span = rch_prior_outlet_span(NULL, (const double(*)[3])pos, k);
    if (rch_poses_plan_position(&r, m, &cc, NULL, d) != 0)
        return -1;
    cb->acc = r.plan;
    rch_poses_free(&r);
    return 0;
}

static int better(const rch_poses_accuracy *a, const rch_poses_accuracy *b)
{
    return a->median_mm < b->median_mm || (a->median_mm == b->median_mm && a->p95_mm < b->p95_mm);
}

/* The number of k-combinations of n, saturated at limit + 1. */
static size_t n_choose(unsigned n, unsigned k, size_t limit)
{
    double c = 1.0;
    for (unsigned i = 0; i < k; ++i)
        c = c * (double)(n - i) / (double)(i + 1);
    return c > (double)limit ? limit + 1 : (size_t)(c + 0.5);
}

int rch_poses_choose_outlets(rch_poses_choice *out, const rc_model *m, const rch_poses_config *c,
                             const double (*cand_mm)[3], unsigned n, unsigned k, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    out->k = k;
    out->n_cand = n;
    if (k < 1 || k > n || k > RC_MAX_OUTLETS || n > RCH_POSES_MAX_CANDIDATE_PLACES) {
        rch_diag_set(d, "", 0, 0, "--choose-outlets %u of %u --candidate places: need 1 <= K <= the candidates "
                     "(at most %u) and K <= %d", k, n, RCH_POSES_MAX_CANDIDATE_PLACES, RC_MAX_OUTLETS);
        return -1;
    }
    out->exhaustive = n_choose(n, k, RCH_POSES_MAX_COMBOS) <= RCH_POSES_MAX_COMBOS;
    if (out->exhaustive) {
        unsigned idx[RC_MAX_OUTLETS];
        for (unsigned j = 0; j < k; ++j)
            idx[j] = j;
        for (;;) {
            rch_poses_combo *cb = &out->combos[out->n_combos];
            memcpy(cb->idx, idx, sizeof idx);
            if (combo_eval(cb, m, c, cand_mm, k, d) != 0)
                return -1;
            if (out->n_combos == 0 || better(&cb->acc, &out->combos[out->best].acc))
                out->best = out->n_combos;
            out->n_combos++;
            int j = (int)k - 1; /* next combination in lexicographic order */
            while (j >= 0 && idx[j] == n - k + (unsigned)j)
                --j;
            if (j < 0)
                break;
            idx[j]++;
            for (unsigned l = (unsigned)j + 1; l < k; ++l)
                idx[l] = idx[l - 1] + 1;
        }
        return 0;
    }
    unsigned chosen[RC_MAX_OUTLETS] = {0};
    for (unsigned size = 1; size <= k; ++size) { /* greedy: add the place that helps most */
        size_t best = (size_t)-1;
        for (unsigned p = 0; p < n; ++p) {
            int taken = 0;
            for (unsigned j = 0; j + 1 < size; ++j)
                taken |= chosen[j] == p;
            if (taken)
                continue;
            rch_poses_combo *cb = &out->combos[out->n_combos];
            memcpy(cb->idx, chosen, sizeof chosen);
            cb->idx[size - 1] = p;
            if (combo_eval(cb, m, c, cand_mm, size, d) != 0)
                return -1;
            if (best == (size_t)-1 || better(&cb->acc, &out->combos[best].acc))
                best = out->n_combos;
            out->n_combos++;
        }
        chosen[size - 1] = out->combos[best].idx[size - 1];
        out->best = best;
    }
    return 0;
}
