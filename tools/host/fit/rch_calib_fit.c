/* SPDX-License-Identifier: MIT */
/* rch_calib_fit.c - one identification on a training set: the BC start,
 * the maximum a posteriori fit with the physical prior and its noise
 * estimate, the cable attachment decided by the evidence, the default run's
 * length-jump check, the --jumps nuisance fit, the before/after metrics,
 * as a plan of stages (fit_plan, run by rch_calib_plan_run; the steering in
 * rch_calib_fit_state, rch_calib_int.h; rch_calib_fit_run).
 *
 * Depends on: the core (rc_solve, rc_normal_eq, rc_prior_*), LAPACKE (the
 * effective number of parameters), rch_start, rch_calib_effects (--fix),
 * rch_prior, rch_jumps, rch_uncert, rch_comp, rch_positions. Memory: scratch
 * freed before returning. Errors: 0, -1 with d set, -2 on a bad --fix name.
 */
#include "rch_calib_int.h"

#include "rch_calib.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <lapacke.h>

#include "rch_calib_effects.h"
#include "rch_comp.h"
#include "rch_prior.h"
#include "rch_start.h"
#include "rch_stats.h"
#include "rch_sensors.h"

/* rc_solve, counted in r->counts (res may be NULL). */
static rc_status solve_counted(rch_calib_result *r, rc_model *m, rc_solve_result *res, rc_solve_work *w,
                               const rc_solve_config *cfg, const rc_sample *s, size_t n)
{
    rc_solve_result local;
    memset(&local, 0, sizeof local);
    rc_solve_result *out = res ? res : &local;
    memset(out, 0, sizeof *out);
    const rc_status st = rc_solve(m, out, w, cfg, s, n);
    r->counts.fits++;
    r->counts.jac_passes += out->cost_evals;
    return st;
}

/* Effective number of parameters of a MAP fit at m: trace(H^-1 A), A = J^T J
 * of the data and H = A + W with W the prior rows' weights (rc_solve.h). The
 * noise estimate SSR / (n - p_eff) counts as fitted only what the data (not
 * the prior) determined. Without a prior: the number of free parameters. */
static double effective_params(const rc_model *m, const rc_solve_config *cfg, const rc_sample *s, size_t n)
{
    uint16_t idx[RC_MAX_PARAMS];
    unsigned nf = 0;
    for (unsigned k = 0; k < m->n_params; ++k)
        if (!cfg->fixed || !cfg->fixed[k])
            idx[nf++] = (uint16_t)k;
    const size_t nn = nf ? (size_t)nf * nf : 1u;
    double *A = malloc(nn * sizeof *A), *H = malloc(nn * sizeof *H);
    double g[RC_MAX_PARAMS], jrow[RC_MAX_PARAMS], cost, pe = (double)nf;
    if (A && H && rc_normal_eq(A, g, &cost, jrow, m, idx, nf, s, n) == RC_OK) {
        memcpy(H, A, (size_t)nf * nf * sizeof *H);
        rc_prior_normal_eq(H, g, &cost, m, idx, nf, cfg); /* H = A + W, the solver's prior rows */
        for (unsigned i = 0; i < nf; ++i) {
            const double sd = cfg->prior_sd ? cfg->prior_sd[idx[i]] : 0.0;
            if (!(sd > 0.0 && isfinite(sd)))
                H[(size_t)i * nf + i] += 1e-12 * (H[(size_t)i * nf + i] + 1e-300); /* a free direction */
        }
        /* H X = A, trace X */
        if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)nf, (lapack_int)nf, H, (lapack_int)nf, A,
                          (lapack_int)nf) == 0) {
            pe = 0.0;
            for (unsigned i = 0; i < nf; ++i)
                pe += A[(size_t)i * nf + i];
        }
    }
    free(A);
    free(H);
    return pe;
}

static int cmp_t(const void *a, const void *b)
{
    double x = ((const rc_sample *)a)->t, y = ((const rc_sample *)b)->t;
    return (x > y) - (x < y);
}

/* A copy of s[0..n) in time order (what a jump search reads), or NULL when
 * out of memory; the caller frees it. */
static rc_sample *by_time(const rc_sample *s, size_t n)
{
    rc_sample *c = malloc((n ? n : 1) * sizeof *c);
    if (c) {
        memcpy(c, s, n * sizeof *c);
        qsort(c, n, sizeof *c, cmp_t);
    }
    return c;
}

/* The jump fit of one pass: the first search finds the change points
 * (rch_jumps_find), every later fit of the same training set refits at them
 * (rch_jumps_refit): the noise passes, the attachment comparison and the
 * final fit move the change points' sizes, not where they are. */
static int jumps_fit(rch_calib_fit_state *f, rch_calib_result *r, rc_solve_work *w, const uint8_t *fixed, const rch_jumps_config *jc,
                     const rc_sample *sorted, char *err, size_t errlen)
{
    if (f->have_jump_at) {
        const int rc = rch_jumps_refit(&r->jumps, &r->before, fixed, sorted, r->n_train, f->jump_at, f->n_jump_at,
                                       jc, w, err, errlen);
        r->jumps.rms_before_mm = f->jump_rms_before_mm; /* the geometry alone, from the search */
        return rc;
    }
    const int rc = rch_jumps_find(&r->jumps, &r->before, fixed, sorted, r->n_train, jc, w, err, errlen);
    if (rc != 0)
        return -1;
    if (isfinite(r->jumps.rms_before_mm)) /* a search linearised at the fit at hand keeps the earlier one */
        f->jump_rms_before_mm = r->jumps.rms_before_mm;
    else
        r->jumps.rms_before_mm = f->jump_rms_before_mm;
    f->n_jump_at = r->jumps.n_jumps;
    memcpy(f->jump_at, r->jumps.at, r->jumps.n_jumps * sizeof f->jump_at[0]);
    f->have_jump_at = 1;
    return 0;
}

/* Length jumps (nuisance): detected on the training samples in acquisition
 * order and fitted with the geometry; r->model becomes the geometry alone
 * (what predicts a new pose). Held-out samples are labelled with their
 * segment to evaluate; those between a jump and the training samples around
 * it cannot be placed (their segment is a guess) and are counted apart. */
static int fit_jumps(rch_calib_fit_state *f, rch_calib_result *r, rc_solve_work *w, const uint8_t *fixed, const rc_solve_config *scfg,
                     const rc_sample *train, const rc_sample *eval_set, size_t n_eval, rch_diag *d)
{
    rc_sample *tr = malloc(r->n_train * sizeof *tr), *ev = malloc(n_eval * sizeof *ev);
    uint16_t *setup = NULL;
    char err[256];
    int rc = -1;
    if (!tr || !ev) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    memcpy(tr, train, r->n_train * sizeof *tr);
    memcpy(ev, eval_set, n_eval * sizeof *ev);
    qsort(tr, r->n_train, sizeof *tr, cmp_t);
    setup = malloc((r->n_train ? r->n_train : 1) * sizeof *setup);
    if (!setup) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < r->n_train; ++i)
        setup[i] = tr[i].group; /* set-up groups: the clusters of the covariance */
    rch_jumps_config jc;
    memset(&jc, 0, sizeof jc);
    jc.solve = scfg;
    jc.counts = &r->counts;
    rc_model *warm = f->have_jump_at ? malloc(sizeof *warm) : NULL;
    if (warm) { /* the last noise pass's fit at these change points: the final fit starts there */
        *warm = r->jumps.model;
        jc.warm = warm;
    }
    const int jf = jumps_fit(f, r, w, fixed, &jc, tr, err, sizeof err);
    free(warm);
    if (jf != 0) {
        if (r->n_test)
            rch_diag_set(d, "", 0, 0, "length jumps: %s: the training samples, %zu of the %zu rows after %zu held "
                         "out (--test-fraction 0 fits them all; or record more poses)", err, r->n_train,
                         r->n_train + r->n_test, r->n_test);
        else
            rch_diag_set(d, "", 0, 0, "length jumps: %s", err);
        goto done;
    }
    r->have_jumps = 1;
    r->model = r->jumps.geometry;
    rch_stats sa;
    memset(&sa, 0, sizeof sa);
    r->n_ambiguous = 0;
    for (size_t i = 0; i < n_eval; ++i) {
        ev[i].group = (uint16_t)rch_jumps_segment(&r->jumps, ev[i].t);
        int amb = 0;
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
            size_t a = r->jumps.at[k]; /* first training sample after the jump; a - 1 the last before */
            amb |= a > 0 && ev[i].t > tr[a - 1].t && ev[i].t < tr[a].t;
        }
        double l;
        if (!amb && rc_meas(&l, NULL, &r->jumps.model, &ev[i]) == RC_OK)
            rch_stats_add(&sa, l - ev[i].value);
        r->n_ambiguous += (size_t)amb;
    }
    rch_stats_metrics(&r->after_unambiguous, &sa);
    r->after_ok = rc_eval(&r->after_m, &r->jumps.model, ev, n_eval) == RC_OK;
    for (size_t i = 0; i < r->n_train; ++i)
        tr[i].group = (uint16_t)rch_jumps_segment(&r->jumps, tr[i].t);
    rc_eval(&r->train_before, &r->before, tr, r->n_train);
    if (!r->after_ok || rc_eval(&r->train_after, &r->jumps.model, tr, r->n_train) != RC_OK)
        memset(&r->train_after, 0, sizeof r->train_after);
    memcpy(f->fin_fixed, fixed, sizeof f->fin_fixed);
    if (r->jumps.n_jumps) /* the first segment's offset is the reference */
        f->fin_fixed[r->jumps.model.effects[r->jumps.model.n_effects - 1].first] = 1;
    /* the uncertainty stage's: the rows in time order, each in its segment, and their set-up groups */
    f->fin_sorted = tr;
    f->fin_train = tr;
    f->fin_setup = setup;
    f->fin_fit = &r->jumps.model;
    tr = NULL;
    setup = NULL;
    rc = 0;
done:
    free(tr);
    free(ev);
    free(setup);
    return rc;
}

/* One maximum a posteriori fit from r->before (cfg: the prior set up, its
 * noise estimated here): the residuals' sd the prior is weighed against
 * comes from the data: start from the start model's RMS (a weak prior),
 * then SSR / (n - p_eff) of each fit, until it settles (2 %). Every pass
 * starts from the start model, so a pass never inherits the previous one's
 * excursions. With --jumps each pass is a jump search. r->model (and
 * r->jumps), r->noise_mm, r->p_eff, r->noise_passes are set; *chi2 is the
 * MAP objective in units of the noise variance (SSR / noise^2 + prior). */
static rc_status map_fit(rch_calib_fit_state *f, rch_calib_result *r, rc_solve_work *w, rc_solve_config *pcfg, const uint8_t *fixed,
                         const rc_sample *train, double *chi2)
{
    rc_solve_config cfg = *pcfg;
    rc_status st = RC_OK;
    double ssr = 0.0, chi2_loop = INFINITY;
    {
        /* The residuals' sd the prior is weighed against, from the data: start
         * from the start model's RMS (a weak prior), then SSR / (n - p_eff) of
         * each fit, until it settles (2 %). Every pass starts from the start
         * model, so a pass never inherits the previous one's excursions. */
        rc_metrics m0;
        double noise = rc_eval(&m0, &r->before, train, r->n_train) == RC_OK && m0.rmse_mm > 0.0 ? m0.rmse_mm : 1.0;
        const int warm_first = f->map_warm && r->noise_mm > 0.0;
        if (warm_first)
            noise = r->noise_mm;
        rc_sample *sorted = NULL;
        rc_model *warm = f->jumps ? malloc(sizeof *warm) : NULL;
        if (f->jumps && warm)
            sorted = by_time(train, r->n_train);
        for (unsigned pass = 0; pass < 6; ++pass) {
            cfg.prior_noise_mm = noise;
            f->noise_fit_mm = noise;
            const rc_model *fitm = &r->model;
            const rc_sample *fs = train;
            const uint8_t *fx = fixed;
            uint8_t fxj[RC_MAX_PARAMS];
            if (pass == 0 && !warm_first)
                r->model = r->before; /* later passes start from the previous one's optimum */
            if (f->jumps && sorted) {
                rch_jumps_config jc;
                char err[256];
                memset(&jc, 0, sizeof jc);
                jc.solve = &cfg;
                jc.counts = &r->counts;
                jc.skip_se = 1; /* sizes only: the final fit gives their standard errors */
                /* The change points depend on the prior's weight: searched
                 * again until the noise is near its final value (pass 1),
                 * refitted after, each refit from the previous pass's fit.
                 * Pass 0 only gives pass 1 its noise: when the default run's
                 * check found the points (jumps_auto), pass 0 refits there. */
                if (!f->attach_m0 && (pass == 1 || (pass == 0 && !r->jumps_auto)))
                    f->have_jump_at = 0;
                if ((pass > 0 || warm_first) && f->have_jump_at) {
                    *warm = r->jumps.model;
                    jc.warm = warm;
                } else if (pass == 0 && f->have_jump_at && f->have_check_model) {
                    jc.warm = &f->check_model; /* the check's fit at these points, at its noise */
                } else if (pass > 0 && !f->have_jump_at) {
                    /* the search linearised at the last pass's fit (its geometry, its offsets dropped):
                     * no geometry-alone fit at this noise */
                    *warm = r->jumps.model;
                    jc.warm = warm;
                    jc.warm_role = RCH_WARM_LINEARISE;
                }
                if (jumps_fit(f, r, w, fixed, &jc, sorted, err, sizeof err) != 0)
                    break; /* fit_jumps reports it */
                fitm = &r->jumps.model;
                fs = sorted;
                memset(fxj, 0, sizeof fxj);
                memcpy(fxj, fixed, r->before.n_params);
                if (r->jumps.n_jumps)
                    fxj[r->jumps.model.effects[r->jumps.model.n_effects - 1].first] = 1;
                fx = fxj;
                for (size_t i = 0; i < r->n_train; ++i)
                    sorted[i].group = (uint16_t)rch_jumps_segment(&r->jumps, sorted[i].t);
            } else {
                rc_solve_config wc = cfg; /* a later pass (or a warm first) starts at the fit at hand */
                if (pass > 0 || warm_first)
                    rc_solve_config_warm(&wc);
                st = solve_counted(r, &r->model, &r->solve, w, &wc, train, r->n_train);
                if (st != RC_OK)
                    break;
            }
            rc_solve_config pc = cfg;
            pc.fixed = fx;
            if (rc_cost(&ssr, fitm, fs, r->n_train) != RC_OK)
                break;
            chi2_loop = (ssr + rc_prior_cost(fitm, &pc)) / (noise * noise);
            r->p_eff = effective_params(fitm, &pc, fs, r->n_train);
            r->counts.jac_passes++;
            r->noise_passes = pass + 1;
            const double dof = (double)r->n_train - r->p_eff;
            const double next = dof > 1.0 ? sqrt(ssr / dof) : noise;
            const int settled = fabs(next - noise) <= 0.02 * noise;
            noise = next > 1e-6 ? next : 1e-6;
            if (settled || f->map_one_pass)
                break;
        }
        free(sorted);
        free(warm);
        r->noise_mm = cfg.prior_noise_mm = noise;
        if (st == RC_OK && !f->jumps && !f->map_one_pass) { /* the last pass's optimum, at the settled noise */
            rc_solve_config wc = cfg;
            rc_solve_config_warm(&wc);
            st = solve_counted(r, &r->model, &r->solve, w, &wc, train, r->n_train);
        }
    }
    *chi2 = f->jumps ? chi2_loop : INFINITY;
    if (st == RC_OK && !f->jumps) {
        const rc_model *fitm = &r->model;
        double c = 0.0;
        rc_solve_config pc = cfg;
        uint8_t fxj[RC_MAX_PARAMS];
        memcpy(fxj, fixed, sizeof fxj);
        pc.fixed = fxj;
        if (rc_cost(&c, fitm, train, r->n_train) == RC_OK) /* the SSR does not depend on the order */
            *chi2 = (c + rc_prior_cost(fitm, &pc)) / (cfg.prior_noise_mm * cfg.prior_noise_mm);
    }
    *pcfg = cfg;
    return st;
}

/* A lower bound of the centred model's MAP objective at its own noise,
 * in units of the attachment model's noise nu1 (what choose_attachment
 * compares), from one fit at nu1 instead of its noise loop. With
 * F_nu(x) = SSR(x) + nu^2 Q(x) (Q the prior's sum of squares), the loop's
 * result is F_nu0(x0) / nu1^2 at its settled noise nu0, the fixed point of
 * g(nu)^2 = SSR(x_nu) / (n - p_eff(nu)) that map_fit reaches from above
 * (from the start model's RMS). A wider noise weighs the prior more: SSR of
 * the optimum does not fall and p_eff does not rise, so g is nondecreasing,
 * and if g(nu1) >= nu1 the iteration from above stops at a nu0 >= nu1.
 * g(nu1) >= nu1 is checked with p_eff taken as 0 (SSR1 / n >= nu1^2, a
 * sufficient test). Then every F_nu0 >= F_nu1 gives F_nu0(x0) >= F_nu1(x1)
 * = F1, and *bound = F1 / nu1^2 (0); -1 when the test or the fit fails
 * (the loop decides). fm: the attachment model's fit (its jump offsets
 * with --jumps), the centred fit's start. */
static int centred_bound(rch_calib_fit_state *f, double *bound, rc_model *fit, rch_calib_result *r, rc_solve_work *w,
                         const rc_solve_config *c0, const uint8_t *fixed, const rc_sample *train, const rc_model *fm,
                         double nu1)
{
    rc_solve_config c = *c0;
    c.prior_noise_mm = nu1;
    rc_model x;
    rch_comp_point_model(&x, fm, NULL); /* the attachment dropped, the rest (jump offsets last) kept */
    uint8_t fx[RC_MAX_PARAMS];
    memset(fx, 0, sizeof fx);
    memcpy(fx, fixed, r->before.n_params);
    double ssr = 0.0;
    int ok = 0;
    if (f->jumps) {
        rc_sample *sorted = by_time(train, r->n_train);
        rch_jumps *jj = malloc(sizeof *jj);
        if (sorted && jj) {
            rch_jumps_config jc;
            char err[128];
            memset(&jc, 0, sizeof jc);
            jc.solve = &c;
            jc.counts = &r->counts;
            jc.skip_se = 1; /* sizes only: the final fit gives their standard errors */
            jc.warm = &x;
            ok = rch_jumps_refit(jj, &r->before, fixed, sorted, r->n_train, f->jump_at, f->n_jump_at, &jc, w, err,
                                 sizeof err) == 0;
            if (ok) {
                x = jj->model;
                ssr = jj->rms_after_mm * jj->rms_after_mm * (double)r->n_train;
                if (f->n_jump_at)
                    fx[x.effects[x.n_effects - 1].first] = 1;
            }
        }
        free(sorted);
        free(jj);
    } else {
        c.fixed = fx;
        ok = solve_counted(r, &x, NULL, w, &c, train, r->n_train) == RC_OK &&
             rc_cost(&ssr, &x, train, r->n_train) == RC_OK;
    }
    if (!ok)
        return -1;
    *fit = x; /* the centred fit at nu1: where the centred noise loop starts when the bound does not decide */
    unsigned n_free = 0;
    for (unsigned k = 0; k < x.n_params; ++k)
        n_free += !fx[k];
    c.fixed = fx;
    if (!(n_free + 1u < r->n_train) || ssr / (double)r->n_train < nu1 * nu1)
        return -1;
    *bound = (ssr + rc_prior_cost(&x, &c)) / (nu1 * nu1);
    return 0;
}

/* The prior's scale at the fit at hand (r->model, or r->jumps.model over
 * the samples in acquisition order, each in its segment, the first
 * segment's offset held, as map_fit fitted it with --jumps), fitted under
 * the sd sd_fit (n_params; the stated r->prior_sd or another scale of it).
 * 0, or -1 when it cannot be estimated. */
static int estimate_scale(rch_calib_fit_state *f, rch_prior_scale *ps, rch_calib_result *r, const uint8_t *fixed, const rc_sample *train,
                          const double *sd_fit)
{
    char err[160];
    r->counts.jac_passes++;
    const rc_model *fm = &r->model;
    const rc_sample *fs = train;
    rc_sample *sorted = NULL;
    uint8_t fxj[RC_MAX_PARAMS];
    memcpy(fxj, fixed, sizeof fxj);
    if (f->jumps) {
        if (!(sorted = malloc(r->n_train * sizeof *sorted)))
            return -1;
        memcpy(sorted, train, r->n_train * sizeof *sorted);
        qsort(sorted, r->n_train, sizeof *sorted, cmp_t);
        for (size_t i = 0; i < r->n_train; ++i)
            sorted[i].group = (uint16_t)rch_jumps_segment(&r->jumps, sorted[i].t);
        if (r->jumps.n_jumps)
            fxj[r->jumps.model.effects[r->jumps.model.n_effects - 1].first] = 1;
        fm = &r->jumps.model;
        fs = sorted;
    }
    const int est = rch_prior_scale_estimate(ps, fm, r->prior_mean, r->prior_sd, sd_fit, fxj, fs, r->n_train,
                                             r->noise_mm, err, sizeof err);
    free(sorted);
    return est;
}

/* The cable attachment, decided by the data. Lengths cannot tell the flange
 * centre from a point on the flange axis (d6 against the attachment's z,
 * a6 and theta6 against its x, y): with an attachment vector the flange
 * centre is only as well known as the prior of a6, d6. So the vector is
 * kept only when the data need it: its fit (chi2_1) must beat the fit with
 * the cable at the flange centre (chi2_0) by more than its Occam penalty,
 * 2 sum ln(prior sd / posterior sd) over its three components (the Laplace
 * evidence of the two models). Otherwise the model without it is used.
 * r->attach_* record the decision. */
static rc_status choose_attachment(rch_calib_fit_state *f, rch_calib_result *r, rc_solve_work *w, rc_solve_config *cfg, uint8_t *fixed,
                                   const rc_sample *train, double chi2_1)
{
    const rc_model m1 = r->model, before1 = r->before;
    const rch_jumps j1 = r->jumps;
    const rc_solve_result s1 = r->solve;
    const double noise1 = r->noise_mm, peff1 = r->p_eff;
    const unsigned passes1 = r->noise_passes;
    double mean1[RC_MAX_PARAMS], sd1[RC_MAX_PARAMS];
    memcpy(mean1, r->prior_mean, sizeof mean1);
    memcpy(sd1, r->prior_sd, sizeof sd1);
    /* the attachment's posterior sd */
    int first = -1;
    for (unsigned e = 0; e < m1.n_effects; ++e)
        if (m1.effects[e].kind == RC_EFF_TOOL_OFFSET)
            first = m1.effects[e].first;
    if (first < 0)
        return RC_OK;
    rch_uncert u;
    char err[128];
    const rc_model *fm = f->jumps ? &j1.model : &m1;
    uint8_t fx[RC_MAX_PARAMS];
    memcpy(fx, fixed, sizeof fx);
    if (f->jumps && j1.n_jumps)
        fx[j1.model.effects[j1.model.n_effects - 1].first] = 1;
    double occam = 0.0;
    r->counts.jac_passes++;
    if (rch_uncert_compute_map(&u, fm, fx, train, NULL, r->n_train, 0, r->prior_sd, noise1, err, sizeof err) != 0)
        return RC_OK; /* keep the attachment */
    for (int k = 0; k < 3; ++k)
        if (u.se[first + k] > 0.0 && r->prior_sd[first + k] > 0.0)
            occam += log(r->prior_sd[first + k] / u.se[first + k]);
    rch_uncert_free(&u);
    /* Both models are weighed at this robot's prior scale: under the stated
     * sd a d6 3 mm off the drawing costs (3 / 0.5)^2 = 36 of prior the
     * attachment's z takes over at no cost, and a centred cable would be
     * read as off-centre, the flange centre left to the prior (measured:
     * tests/system/sim/truth_study.py --errors wide, a centred robot with d6 -3 mm
     * compensated 2.4 mm off). The attachment fit's objective is taken at
     * the scaled prior without a refit (a bound from above: it leans to the
     * centred model by at most what a refit would gain). */
    rch_prior_scale ps;
    const int scaled = !r->robot.prior.from_file && !r->cfg.prior_stated &&
                       estimate_scale(f, &ps, r, fixed, train, r->prior_sd) == 0;
    if (scaled) {
        double sd_a[RC_MAX_PARAMS];
        rch_prior_scale_apply_fit(sd_a, r->prior_sd, RC_MAX_PARAMS, &ps); /* (the jumps' offsets too) */
        rc_solve_config pa = *cfg, pst = *cfg;
        pa.prior_sd = sd_a;
        pst.prior_sd = r->prior_sd;
        pa.fixed = pst.fixed = fx;
        chi2_1 += (rc_prior_cost(fm, &pa) - rc_prior_cost(fm, &pst)) / (noise1 * noise1);
    }
    /* the model with the cable at the flange centre */
    rc_model m0;
    rch_comp_point_model(&m0, &before1, NULL);
    r->before = m0;
    memset(r->prior_mean, 0, sizeof r->prior_mean);
    memset(r->prior_sd, 0, sizeof r->prior_sd);
    rch_prior_fill(r->prior_mean, r->prior_sd, &r->before, &r->robot.nominal, &r->robot.prior);
    double chi2_0 = INFINITY;
    rc_solve_config c0 = *cfg;
    c0.prior_mean = r->prior_mean;
    c0.prior_sd = r->prior_sd;
    if (scaled) { /* the centred model's fit at the same scale (scale_prior estimates its own after) */
        rch_prior_scale_apply_fit(r->prior_sd_fit, r->prior_sd, RC_MAX_PARAMS, &ps);
        c0.prior_sd = r->prior_sd_fit;
    }
    r->attach_occam = 2.0 * occam;
    r->attach_bound = 0;
    rc_status st = RC_OK;
    double bound = 0.0;
    rc_model xc;
    xc.n_params = 0;
    const int bd = centred_bound(f, &bound, &xc, r, w, &c0, fixed, train, fm, noise1);
    if (bd == 0 && bound - chi2_1 > r->attach_occam) {
        /* the centred model's objective is at least `bound` at its own noise: the attachment is kept, and
         * the centred model's noise loop is not needed to say so */
        r->attach_dchi2 = bound - chi2_1;
        r->attach_bound = 1;
    } else {
        f->attach_m0 = 1; /* at the attachment model's change points */
        if (xc.n_params > 0) { /* the loop from the centred fit at nu1 and nu1: near its fixed point */
            if (f->jumps)
                r->jumps.model = xc;
            else
                r->model = xc;
            r->noise_mm = noise1;
            f->map_warm = 1;
        }
        st = map_fit(f, r, w, &c0, fixed, train, &chi2_0);
        f->attach_m0 = 0;
        f->map_warm = 0;
        /* both objectives in units of the attachment model's noise */
        const double chi2_0n = st == RC_OK ? chi2_0 * (r->noise_mm * r->noise_mm) / (noise1 * noise1) : INFINITY;
        r->attach_dchi2 = chi2_0n - chi2_1;
    }
    if (st == RC_OK && !r->attach_bound && r->attach_dchi2 <= r->attach_occam) {
        r->attach_centred = 1;
        r->robot.model = m0; /* the model file carries no attachment */
        *cfg = c0;
        return RC_OK;
    }
    /* keep the attachment model */
    r->attach_centred = 0;
    r->model = m1;
    r->before = before1;
    r->jumps = j1;
    r->solve = s1;
    r->noise_mm = noise1;
    r->p_eff = peff1;
    r->noise_passes = passes1;
    memcpy(r->prior_mean, mean1, sizeof mean1);
    memcpy(r->prior_sd, sd1, sizeof sd1);
    cfg->prior_noise_mm = noise1;
    return RC_OK;
}

/* The robust sd (rch_mad_sd) of the residuals of j->model over the samples
 * tr (n, time order), each in its segment; j->rms_after_mm when memory runs
 * out. */
static double jump_scale(const rch_jumps *j, const rc_sample *tr, size_t n)
{
    double *v = malloc((n ? n : 1) * sizeof *v);
    if (!v)
        return j->rms_after_mm;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        rc_sample c = tr[i];
        c.group = (uint16_t)rch_jumps_segment(j, c.t);
        double l;
        if (rc_meas(&l, NULL, &j->model, &c) == RC_OK && isfinite(l))
            v[m++] = (l - c.value) * rc_sample_weight(&c);
    }
    const double s = m > 10 ? rch_mad_sd(v, m) : j->rms_after_mm;
    free(v);
    return s > 0.0 ? s : j->rms_after_mm;
}

/* The default run looks for length jumps as diagnose does: a model fitted
 * across a jump it does not know is wrong, so rch_calib_save_model refuses it
 * and names --jumps. r->jumps_found, r->jump_check_max_mm. */
static void jump_check(rch_calib_fit_state *f, rch_calib_result *r, rc_solve_work *w, const uint8_t *fixed, const rc_solve_config *cfg,
                       const rc_sample *train)
{
    rc_sample *tr = by_time(train, r->n_train);
    rch_jumps *j = malloc(sizeof *j);
    rc_model keep_model = r->model;
    if (tr && j) {
        rch_jumps_config jc;
        char err[128];
        memset(&jc, 0, sizeof jc);
        rc_solve_config c0 = *cfg;
        c0.prior_noise_mm = f->noise_fit_mm; /* the noise that fit was made at (cfg's is the next pass's) */
        jc.solve = &c0;
        jc.counts = &r->counts;
        jc.skip_se = 1; /* sizes only: the final fit gives their standard errors */
        jc.warm = &keep_model; /* the MAP fit at hand is the search's geometry fit at this prior and noise */
        jc.warm_role = RCH_WARM_OPTIMUM;
        const int found = rch_jumps_find(j, &r->before, fixed, tr, r->n_train, &jc, w, err, sizeof err) == 0;
        if (found) {
            f->n_jump_at = j->n_jumps; /* every change point found: the nuisance fit starts from them */
            f->check_model = j->model;
            f->have_check_model = 1;
            r->jump_check_steps = j->n_jumps;
            f->jump_rms_before_mm = j->rms_before_mm;
            memcpy(f->jump_at, j->at, j->n_jumps * sizeof f->jump_at[0]);
            /* A step can also describe an effect the geometry lacks (a joint
             * compliance leaves steps of a few times the residual, inside
             * set-ups too): a jump counts as a sensor event when it is far
             * above what is left, 8 x the RMS residual with the jumps (measured:
             * the real IRB120 file's two largest are 10.6 and 14.5 x, a third
             * 3.7 x; the step a missing joint compliance leaves, 4.4 x in
             * tests/tools/host/studies/test_diag_roundtrip.c). */
            /* ... on a robust scale of that residual (1.4826 MAD): one misread lifts the RMS and would hide
             * a jump (a 10 mm misread in 600 rows lifted it 0.01 -> 0.4 mm) */
            const double scale = jump_scale(j, tr, r->n_train);
            r->jump_check_scale_mm = scale;
            for (unsigned k = 0; k < j->n_jumps; ++k) {
                if (!(fabs(j->size_mm[k]) > 8.0 * scale))
                    continue;
                r->jumps_found++;
                if (fabs(j->size_mm[k]) > r->jump_check_max_mm)
                    r->jump_check_max_mm = fabs(j->size_mm[k]);
            }
        }
    }
    r->model = keep_model;
    free(tr);
    free(j);
}

/* The prior's scale from this robot's data (rch_prior_scale: type-II ML of
 * the sd of each DH type): when it changes the prior the fit at hand was
 * made under (cfg->prior_sd), the MAP fit again under the estimate's prior
 * (r->prior_sd_fit: the joint zeros may narrow), the uncertainty's (never
 * below the stated sd) in r->prior_sd. A prior the robot file states is
 * kept as stated, and so with --prior-stated. */
static rc_status scale_prior(rch_calib_fit_state *f, rch_calib_result *r, rc_solve_work *w, rc_solve_config *cfg, const uint8_t *fixed,
                             const rc_sample *train)
{
    if (r->robot.prior.from_file || r->cfg.prior_stated)
        return RC_OK;
    rch_prior_scale ps;
    const double *sd_at = cfg->prior_sd ? cfg->prior_sd : r->prior_sd;
    if (estimate_scale(f, &ps, r, fixed, train, sd_at) != 0)
        return RC_OK; /* the stated prior, as before */
    r->prior_scaled = 1;
    r->prior_scale = ps;
    double sd_fit[RC_MAX_PARAMS];
    rch_prior_scale_apply_fit(sd_fit, r->prior_sd, RC_MAX_PARAMS, &ps); /* (the jumps' offsets too) */
    int changed = 0;
    for (unsigned k = 0; k < RC_MAX_PARAMS; ++k)
        changed |= fabs(sd_fit[k] - sd_at[k]) > 1e-6 * sd_at[k];
    memcpy(r->prior_sd_fit, sd_fit, sizeof sd_fit);
    rch_prior_scale_apply(r->prior_sd, r->prior_sd, RC_MAX_PARAMS, &ps);
    cfg->prior_sd = r->prior_sd_fit;
    if (!changed)
        return RC_OK;
    double chi2 = 0.0;
    f->attach_m0 = 1; /* at the change points already found: another prior moves the geometry, not the jumps */
    f->map_warm = 1;  /* from the fit at hand and its noise: another prior moves both a little */
    const rc_status st = map_fit(f, r, w, cfg, fixed, train, &chi2);
    f->attach_m0 = 0;
    f->map_warm = 0;
    return st;
}


/* The plan of one fit (rch_calib_fit_run): each stage a function of the
 * fit's state f (the steering, rch_calib_fit_state) and the result r (the
 * answers). */

/* start: the BC model, the parameters held, the solver's request with the
 * prior. A new training set's change points are searched (unless the jump
 * check's are kept for the nuisance fit). */
static int stage_start(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    if (!f->keep_jump_at) {
        f->have_jump_at = 0; /* a new training set: its change points are searched */
        f->have_check_model = 0;
    }
    if (rch_calib_start(&r->before, f->w, &r->robot, f->train, r->n_train, d) != 0)
        return -1;
    r->model = r->before;
    uint8_t *fixed = f->fixed;
    memset(fixed, 0, sizeof f->fixed);
    if (r->cfg.fix && rch_calib_fix(fixed, &r->model, r->cfg.fix, d) != 0)
        return -2;
    rch_pos_fix_unseen(fixed, &r->model, f->train, r->n_train); /* what only an absent sensor sees */
    rc_solve_config *cfg = &f->cfg;
    memset(cfg, 0, sizeof *cfg);
    cfg->method = r->cfg.method;
    cfg->fixed = fixed;
    cfg->max_iter = r->cfg.max_iter;
    cfg->seed = r->cfg.seed;
    r->prior_on = !r->cfg.no_prior && (cfg->method == RC_METHOD_LM || cfg->method == RC_METHOD_LTLM);
    if (r->prior_on) {
        memset(r->prior_mean, 0, sizeof r->prior_mean);
        memset(r->prior_sd, 0, sizeof r->prior_sd);
        rch_prior_fill(r->prior_mean, r->prior_sd, &r->before, &r->robot.nominal, &r->robot.prior);
        rch_prior_gauge(fixed);
        cfg->prior_mean = r->prior_mean;
        cfg->prior_sd = r->prior_sd;
    }
    memcpy(r->fixed, fixed, sizeof r->fixed);
    f->st = RC_OK;
    f->checked = 0;
    f->eval_set = r->n_test ? f->test : f->train;
    f->n_eval = r->n_test ? r->n_test : r->n_train;
    return 0;
}

/* map (the jump check's look): the first noise pass alone, when the
 * default run checks for length jumps (a cable's display; several outlets'
 * rows interleave in acquisition order, where a step of the sequence is no
 * display's event: their jumps only with --jumps, as rcal diagnose). It
 * looks at the weakest prior of the loop: when it finds jumps the rest of
 * the loop, fitted across them, would be thrown away; when it does not,
 * the loop goes on from that pass (map_warm: the same passes as one loop). */
static int stage_map_first(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    (void)d;
    if (!(r->prior_on && !f->jumps && !r->cfg.no_jump_check && r->n_train >= 40 && !r->n_pos_rows &&
          rch_sensors_count(f->train, r->n_train) == 0 &&
          r->n_outlets <= 1))
        return 0;
    double chi2_e = 0.0;
    f->map_one_pass = 1;
    f->st = map_fit(f, r, f->w, &f->cfg, f->fixed, f->train, &chi2_e);
    f->map_one_pass = 0;
    f->checked = f->st == RC_OK;
    f->passes0 = r->noise_passes;
    return 0;
}

/* jump_check: length jumps at that first pass's fit; found (and no
 * --residuals): the fit again from its start with them as nuisance, as
 * --jumps does (the default run never hands on a geometry fitted across
 * jumps), at the change points the check found. */
static int stage_jump_check(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    (void)d;
    if (!f->checked)
        return 0;
    jump_check(f, r, f->w, f->fixed, &f->cfg, f->train);
    if (r->jumps_found && !r->cfg.residuals_path) {
        f->jumps = 1;
        r->jumps_auto = 1;
        f->have_jump_at = 1; /* at the change points the check found */
        f->keep_jump_at = 1;
        return RCH_PLAN_AGAIN;
    }
    f->map_warm = 1;
    f->map_passes0 = f->passes0;
    return 0;
}

/* map: the maximum a posteriori fit with its noise loop (resumed after the
 * check's pass), or plain least squares without the prior. */
static int stage_map(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    (void)d;
    if (!r->prior_on) {
        f->st = solve_counted(r, &r->model, &r->solve, f->w, &f->cfg, f->train, r->n_train);
        return 0;
    }
    f->chi2_1 = 0.0;
    if (f->st == RC_OK)
        f->st = map_fit(f, r, f->w, &f->cfg, f->fixed, f->train, &f->chi2_1);
    f->map_warm = 0;
    r->noise_passes += f->map_passes0;
    f->map_passes0 = 0;
    return 0;
}

/* attachment: the cable attachment decided by the evidence (the default's
 * to decide); the identification's verdict. */
static int stage_attachment(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    if (r->prior_on && f->st == RC_OK && r->attach_auto)
        f->st = choose_attachment(f, r, f->w, &f->cfg, f->fixed, f->train, f->chi2_1);
    if (f->st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "solver failed: %s", rc_strerror(f->st));
        return -1;
    }
    r->finite = 1;
    for (unsigned k = 0; k < r->model.n_params; ++k)
        r->finite &= isfinite(r->model.x[k]) != 0;
    rc_eval(&r->before_m, &r->before, f->eval_set, f->n_eval);
    return 0;
}

/* prior_scale: the prior's scale from the data, the MAP fit again under it
 * (after the jump check: once, on the final model). */
static int stage_prior_scale(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    if (!r->prior_on)
        return 0;
    const rc_status st = scale_prior(f, r, f->w, &f->cfg, f->fixed, f->train);
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "solver failed under the prior's estimated scale: %s", rc_strerror(st));
        return -1;
    }
    r->finite = 1;
    for (unsigned k = 0; k < r->model.n_params; ++k)
        r->finite &= isfinite(r->model.x[k]) != 0;
    return 0;
}

/* jumps: with the jumps as nuisance, their final fit at the change points,
 * the held-out rows placed in their segments. */
static int stage_jumps(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    if (!f->jumps)
        return 0;
    return fit_jumps(f, r, f->w, f->fixed, &f->cfg, f->train, f->eval_set, f->n_eval, d);
}

/* metrics: the before/after figures of the geometry fit (the jumps' are
 * fit_jumps'). */
static int stage_metrics(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    (void)d;
    if (f->jumps)
        return 0;
    r->after_ok = r->finite && rc_eval(&r->after_m, &r->model, f->eval_set, f->n_eval) == RC_OK;
    int train_ok = r->after_ok;
    if (f->eval_set == f->train) { /* nothing held out: the training figures are those */
        r->train_before = r->before_m;
        r->train_after = r->after_m;
    } else {
        rc_eval(&r->train_before, &r->before, f->train, r->n_train);
        train_ok = train_ok && rc_eval(&r->train_after, &r->model, f->train, r->n_train) == RC_OK;
    }
    if (!train_ok)
        memset(&r->train_after, 0, sizeof r->train_after);
    f->fin_train = f->train;
    memcpy(f->fin_fixed, f->fixed, sizeof f->fin_fixed);
    f->fin_fit = &r->model;
    return 0;
}

/* uncertainty: truth, identifiability, uncertainty, validation. */
static int stage_uncertainty(void *run, rch_calib_result *r, rch_diag *d)
{
    rch_calib_fit_state *f = run;
    return rch_calib_finish(r, f->fin_fixed, f->fin_train, f->fin_fit, f->fin_setup, f->validate, d);
}

/* The fit's plan, in order. To add a stage: a function of (state, result)
 * here, its id in rch_calib_stage_id and its name in rch_calib_plan.c. */
static const rch_calib_stage fit_plan[] = {
    {RCH_STAGE_START, stage_start},
    {RCH_STAGE_MAP, stage_map_first},
    {RCH_STAGE_JUMP_CHECK, stage_jump_check},
    {RCH_STAGE_MAP, stage_map},
    {RCH_STAGE_ATTACHMENT, stage_attachment},
    {RCH_STAGE_PRIOR_SCALE, stage_prior_scale},
    {RCH_STAGE_JUMPS, stage_jumps},
    {RCH_STAGE_METRICS, stage_metrics},
    {RCH_STAGE_UNCERTAINTY, stage_uncertainty},
};

int rch_calib_fit_run(rch_calib_result *r, rc_solve_work *w, const rc_sample *train, const rc_sample *test,
                      const struct rch_data *validate, rch_calib_timing *t, rch_diag *d)
{
    rch_calib_fit_state *f = calloc(1, sizeof *f);
    if (!f) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    f->w = w;
    f->train = train;
    f->test = test;
    f->validate = validate;
    f->jumps = r->cfg.jumps || r->jumps_auto; /* (a case copied from one whose check found jumps: as it) */
    const rch_calib_timing t0 = *t;
    const int rc = rch_calib_plan_run(fit_plan, sizeof fit_plan / sizeof fit_plan[0], f, r, t, d);
    r->time_ms = 0.0; /* the identification alone: the MAP fits to the prior's scale and the jumps' refit */
    for (unsigned id = RCH_STAGE_MAP; id <= RCH_STAGE_JUMPS; ++id)
        r->time_ms += t->wall_ms[id] - t0.wall_ms[id];
    free(f->fin_sorted);
    free(f->fin_setup);
    free(f);
    return rc;
}
