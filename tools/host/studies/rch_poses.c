/* SPDX-License-Identifier: MIT */
/* rch_poses.c - what the pose planner's criteria share (see rch_poses.h):
 * the checks and the cost estimate, the outer-product update, the progress
 * lines, and the result's release. The entry that picks the criterion is
 * rch_poses_plan.c. The criteria live in rch_poses_position.c (the
 * predicted 3-D accuracy, the default) and rch_poses_length.c (D-optimal on
 * the lengths); the choice of outlet places in rch_poses_outlets.c and the
 * RAPID module in rch_poses_rapid.c. What they share: rch_poses_int.h.
 * Depends on: rch_cost (the estimate's words), rch_diag. Memory: none kept
 * here (rch_poses_free releases a result). Errors: -1 with d set. */
#include "rch_poses.h"

#include <stdlib.h>
#include <string.h>

#include "rch_cost.h"
#include "rch_poses_int.h"

void rch_poses_estimate(double *first_s, double *all_s, size_t n, size_t n_cand, unsigned nf, unsigned long passes,
                        int length_criterion)
{
    const double phase = (double)n * (double)n_cand * (double)nf * (double)nf * (length_criterion ? 0.3e-9 : 0.8e-9);
    const double fixed = length_criterion ? 20e-6 * (double)n_cand : 0.0;
    *first_s = fixed + phase * (passes ? 2.0 : 1.0);
    *all_s = fixed + phase * (1.0 + (double)passes);
}

/* The estimate printed (over 10 s) and checked against the limit before the
 * work starts: 0, or -1 with d set (above --max-minutes). */
int rch_poses_plan_cost(const rch_poses_config *c, FILE *progress, size_t n, size_t n_cand, unsigned nf, int length,
                        rch_diag *d)
{
    double first, all;
    char a[32], b[32];
    const double lim_min = c->max_minutes > 0.0 ? c->max_minutes : 60.0;
    rch_poses_estimate(&first, &all, n, n_cand, nf, c->passes, length);
    if (all > 60.0 * lim_min) {
        rch_diag_set(d, "", 0, 0,
                     "a plan of %zu poses from %zu candidates with %lu exchange passes would take about %s (at most %s): "
                     "above the limit of %g min; lower --count, --candidates or --passes, or raise --max-minutes",
                     n, n_cand, c->passes, rch_cost_human(a, sizeof a, first), rch_cost_human(b, sizeof b, all),
                     lim_min);
        return -1;
    }
    if (progress && all > 10.0)
        fprintf(progress, "rcal poses: %zu poses from %zu candidates: about %s with one exchange pass, at most %s "
                          "with all %lu\n",
                n, n_cand, rch_cost_human(a, sizeof a, first), rch_cost_human(b, sizeof b, all), c->passes);
    return 0;
}

void rch_poses_add_outer(double *A, const double *x, double w, unsigned r)
{
    for (unsigned i = 0; i < r; ++i)
        for (unsigned j = 0; j < r; ++j)
            A[i * r + j] += w * x[i] * x[j];
}

void rch_poses_progress(FILE *f, const char *what, size_t k, size_t n)
{
    if (f && n >= 10 && (k + 1) % (n / 10) == 0) {
        fprintf(f, "rcal poses: %s %zu/%zu\n", what, k + 1, n);
        fflush(f);
    }
}

int rch_poses_check_config(const rc_model *m, const rch_poses_config *c, size_t *n_cand, rch_diag *d)
{
    if (c->count < 1 || c->count > RCH_POSES_MAX_COUNT) {
        rch_diag_set(d, "", 0, 0, "--count %zu: a plan has 1..%u poses (the cost grows as poses x candidates x "
                     "passes: rcal poses says its estimate before it starts)", c->count, RCH_POSES_MAX_COUNT);
        return -1;
    }
    *n_cand = c->candidates ? c->candidates : (c->count * 40 > 2000 ? c->count * 40 : 2000);
    if (*n_cand < c->count || *n_cand > RCH_POSES_MAX_CANDIDATES) {
        rch_diag_set(d, "", 0, 0, "--candidates %zu: must be between --count (%zu) and %u", *n_cand, c->count,
                     RCH_POSES_MAX_CANDIDATES);
        return -1;
    }
    if (!(c->len_min_mm < c->len_max_mm) || !(c->margin_deg >= 0)) {
        rch_diag_set(d, "", 0, 0, "need --len-min-mm < --len-max-mm and --margin-deg >= 0");
        return -1;
    }
    for (int j = 0; j < RC_NJ; ++j) {
        const double mg = c->margin_deg * PI_ / 180.0;
        if (!(m->q_min_rad[j] + mg < m->q_max_rad[j] - mg)) {
            rch_diag_set(d, "", 0, 0, "--margin-deg %g leaves no room inside joint %d's limits [%.2f, %.2f] deg",
                         c->margin_deg, j + 1, m->q_min_rad[j] * 180.0 / PI_, m->q_max_rad[j] * 180.0 / PI_);
            return -1;
        }
    }
    return 0;
}

void rch_poses_free(rch_poses_result *res)
{
    free(res->poses);
    memset(res, 0, sizeof *res);
}
