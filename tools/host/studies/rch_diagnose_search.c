/* SPDX-License-Identifier: MIT */
/* rch_diagnose_search.c - the candidate effects of `rcal diagnose` and the
 * search among them: which can be tried on the data, how many directions
 * each adds, its cross-validated held-out gain, the choice of one per step
 * (significance, one-standard-error rule). See rch_diagnose.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose_int.h"
#include "rch_plot.h"
#include "rch_stats.h"

/* Largest joint-side error that is still physical for a gear or joint
 * deflection (deg); a fit beyond it is the solver using the effect for
 * something else (e.g. a huge joint-6 ripple moving an off-axis point). */
#define PLAUSIBLE_DEG 1.0

/* A draw-wire's drum turn (length_periodic's period): the circumference of
 * a drum of 3 to 160 mm diameter, 10 to 500 mm (rcal calibrate takes 1 to
 * 1000 mm: what diagnose proposes, calibrate accepts); a period beyond the
 * lengths' range is a smooth curve, not a turn. */
#define PERIOD_MIN_MM 10.0
#define PERIOD_MAX_MM 500.0

/* The largest joint-angle change of the last effect of m over the samples
 * (deg) when it exceeds PLAUSIBLE_DEG, else 0. */
static double implausible_deg(const rc_model *m, const double (*var)[V_N], size_t n)
{
    const rc_effect *ef = &m->effects[m->n_effects - 1];
    const double *x = &m->x[ef->first];
    double worst = 0.0;
    if (ef->kind == RC_EFF_JOINT_PERIODIC)
        worst = (fabs(x[0]) + fabs(x[1]) + fabs(x[2]) + fabs(x[3])) / DEG;
    else if (ef->kind == RC_EFF_JOINT_COMPLIANCE)
        for (size_t i = 0; i < n; ++i) {
            const double v = fabs(x[0] * var[i][ef->joint == 1 ? V_LEV2 : V_LEV3]) / DEG;
            worst = v > worst ? v : worst;
        }
    return worst > PLAUSIBLE_DEG ? worst : 0.0;
}

int rch_dg_has_effect(const rc_model *m, rc_effect_kind kind, unsigned joint0)
{
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == (uint8_t)kind && m->effects[i].joint == joint0)
            return 1;
    return 0;
}

/* What a candidate acts on: any sensor (the joint side moves the flange
 * every sensor sees), the cable's lengths, the lengths of two or more
 * outlets, or the tracker's positions. A candidate whose sensor is not in
 * the data is not listed. */
enum { ON_ANY = 0, ON_CABLE, ON_OUTLETS, ON_TRACKER };

typedef struct cdef {
    rc_effect_kind kind;
    unsigned joint0;
    unsigned on;
} cdef;

static const cdef all_cands[] = {
    {RC_EFF_LENGTH_OFFSET, 0, ON_CABLE},    {RC_EFF_LENGTH_SCALE, 0, ON_CABLE},
    {RC_EFF_TIME_DRIFT, 0, ON_CABLE},       {RC_EFF_GROUP_OFFSET, 0, ON_CABLE},
    {RC_EFF_JOINT_COMPLIANCE, 1, ON_ANY},   {RC_EFF_JOINT_COMPLIANCE, 2, ON_ANY},
    {RC_EFF_JOINT_PERIODIC, 0, ON_ANY},     {RC_EFF_JOINT_PERIODIC, 1, ON_ANY},
    {RC_EFF_JOINT_PERIODIC, 2, ON_ANY},     {RC_EFF_JOINT_PERIODIC, 3, ON_ANY},
    {RC_EFF_JOINT_PERIODIC, 4, ON_ANY},     {RC_EFF_JOINT_PERIODIC, 5, ON_ANY},
    {RC_EFF_TOOL_OFFSET, 0, ON_CABLE},      {RC_EFF_CABLE_SAG, 0, ON_CABLE},
    {RC_EFF_LENGTH_NONLIN, 0, ON_CABLE},    {RC_EFF_LENGTH_PERIODIC, 0, ON_CABLE},
    {RC_EFF_OUTLET_OFFSET, 0, ON_OUTLETS},  {RC_EFF_OUTLET_SCALE, 0, ON_OUTLETS},
    {RC_EFF_TRACKER_SCALE, 0, ON_TRACKER},
};

/* Whether the data hold the sensor candidate cd acts on. */
static int cand_relevant(const run_state *S, const cdef *cd)
{
    const rch_diagnose_result *out = S->out;
    unsigned outlets = 0; /* the cable's classes (one per outlet) */
    int tracker = 0;      /* a tracker's rows (n_tracker counts every sensor other than the cable) */
    for (unsigned j = 0; j < out->n_sensors; ++j) {
        outlets += !out->sensors[j].tracker;
        tracker |= strcmp(out->sensors[j].kind, "tracker") == 0;
    }
    return cd->on == ON_ANY || (cd->on == ON_CABLE && out->n_cable > 0) || (cd->on == ON_OUTLETS && outlets > 1) ||
           (cd->on == ON_TRACKER && tracker);
}
#define N_ALL_CANDS (sizeof all_cands / sizeof all_cands[0])
RC_STATIC_ASSERT(sizeof all_cands / sizeof all_cands[0] <= RCH_DIAGNOSE_MAX_CAND, candidates_fit_the_step);
RC_STATIC_ASSERT(sizeof all_cands / sizeof all_cands[0] == RCH_DG_N_CANDS, candidates_counted_in_the_header);

static int is_joint_kind(rc_effect_kind k) { return k == RC_EFF_JOINT_COMPLIANCE || k == RC_EFF_JOINT_PERIODIC; }

static void cand_name(char *buf, size_t len, rc_effect_kind kind, unsigned joint0)
{
    if (is_joint_kind(kind))
        snprintf(buf, len, "%s j%u", rc_effect_name(kind), joint0 + 1);
    else
        snprintf(buf, len, "%s", rc_effect_name(kind));
}

/* Why a candidate adds fewer identifiable directions than parameters. */
static const char *known_reason(rc_effect_kind kind, unsigned joint0, const rc_model *base)
{
    if (kind == RC_EFF_LENGTH_SCALE)
        return "a cable scale error equals a uniformly larger robot (every a, d and the encoder scaled)";
    if (kind == RC_EFF_OUTLET_SCALE)
        return "the outlets' common scale equals a uniformly larger robot; only their differences are seen";
    if (kind == RC_EFF_TRACKER_SCALE)
        return "a tracker scale error equals a uniformly larger robot (every a, d, the targets and the tracker's "
               "position scaled): a length reference (cable lengths, a scale bar) separates them";
    if (kind == RC_EFF_TOOL_OFFSET)
        return "a cable attachment offset in the flange frame trades against a6, d6 and theta6";
    if (kind == RC_EFF_JOINT_PERIODIC && joint0 == 5)
        return "joint 6 turns the flange about its own axis: the cable attachment point does not move";
    if (kind == RC_EFF_LENGTH_OFFSET && rch_dg_has_effect(base, RC_EFF_GROUP_OFFSET, 0))
        return "a common offset of all groups is a length offset";
    if (kind == RC_EFF_GROUP_OFFSET && rch_dg_has_effect(base, RC_EFF_LENGTH_OFFSET, 0))
        return "the sum of the group offsets is the length offset already in the model";
    if (kind == RC_EFF_JOINT_PERIODIC)
        return "part of the periodic terms is confounded with the joint's offset or the geometry";
    if (kind == RC_EFF_GROUP_OFFSET)
        return "their common level is a length offset, which the geometry nearly absorbs";
    return "confounded with the geometry on these poses";
}

static rc_effect_kind cand_kind_of(const rch_diagnose_step *st, int k) { return st->cand[k].kind; }

/* Whether candidate cd can be tried on the data: 1, or 0 with ca->note set.
 * count: its parameter count when it has a variable one (group offsets). */
static int cand_applicable(const run_state *S, const cdef *cd, rch_diagnose_cand *ca, unsigned *count)
{
    const rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    *count = 0;
    if (cd->kind == RC_EFF_GROUP_OFFSET) {
        if (!rch_dg_groups_usable(out->n_groups, n)) {
            snprintf(ca->note, sizeof ca->note, "not applicable: %u groups for %zu samples (need 2..n/3)",
                     out->n_groups, n);
            return 0;
        }
        *count = out->n_groups;
    }
    if (cd->kind == RC_EFF_TIME_DRIFT) {
        double lo = 1e300, hi = -1e300;
        for (size_t i = 0; i < n; ++i) {
            lo = out->s[i].t < lo ? out->s[i].t : lo;
            hi = out->s[i].t > hi ? out->s[i].t : hi;
        }
        if (!(hi > lo)) {
            snprintf(ca->note, sizeof ca->note, "not applicable: no acquisition order");
            return 0;
        }
    }
    return 1;
}

/* Start values of a length_periodic effect (the last effect of m, whose
 * other parameters are those of base): the period of the largest sine in
 * the lengths' residuals L - l(base), after a straight line in L, over
 * periods from 20 mm to the range of the lengths (1 % steps; at most 4000
 * samples, evenly strided), and its two amplitudes. 0, or -1 when the
 * lengths span less than 40 mm. */
static int periodic_start(rc_model *m, const rc_model *base, const rc_sample *s, size_t n)
{
    const size_t stride = n > 4000 ? n / 4000 + 1 : 1;
    double lmin = 1e300, lmax = -1e300, ml = 0.0, me = 0.0, sll = 0.0, sle = 0.0, best = -1.0;
    size_t cnt = 0;
    double *e = malloc((n / stride + 1) * 2 * sizeof *e), *len = NULL;
    if (!e)
        return -1;
    len = e + n / stride + 1;
    for (size_t i = 0; i < n; i += stride) {
        double l;
        if (rc_meas(&l, NULL, base, &s[i]) != RC_OK)
            continue;
        len[cnt] = s[i].value;
        e[cnt] = s[i].value - l;
        lmin = len[cnt] < lmin ? len[cnt] : lmin;
        lmax = len[cnt] > lmax ? len[cnt] : lmax;
        ml += len[cnt];
        me += e[cnt];
        cnt++;
    }
    if (cnt < 10 || lmax - lmin < 40.0) {
        free(e);
        return -1;
    }
    ml /= (double)cnt;
    me /= (double)cnt;
    for (size_t i = 0; i < cnt; ++i) {
        sll += (len[i] - ml) * (len[i] - ml);
        sle += (len[i] - ml) * (e[i] - me);
    }
    for (size_t i = 0; i < cnt; ++i) /* detrended */
        e[i] -= me + (sll > 0.0 ? sle / sll : 0.0) * (len[i] - ml);
    const rc_effect *ef = &m->effects[m->n_effects - 1];
    for (unsigned k = 0;; ++k) {
        const double per = 20.0 * pow(1.01, (double)k);
        if (per > lmax - lmin || per > PERIOD_MAX_MM)
            break;
        double ss = 0.0, cc = 0.0, sc = 0.0, se = 0.0, ce = 0.0;
        for (size_t i = 0; i < cnt; ++i) {
            const double ph = 2.0 * M_PI * len[i] / per, sp = sin(ph), cp = cos(ph);
            ss += sp * sp;
            cc += cp * cp;
            sc += sp * cp;
            se += sp * e[i];
            ce += cp * e[i];
        }
        const double det = ss * cc - sc * sc;
        if (!(det > 0.0))
            continue;
        const double a = (cc * se - sc * ce) / det, b = (ss * ce - sc * se) / det;
        const double expl = a * se + b * ce; /* explained sum of squares */
        if (expl > best) {
            best = expl;
            m->x[ef->first] = a;
            m->x[ef->first + 1] = b;
            m->x[ef->first + 2] = per;
        }
    }
    free(e);
    return best > 0.0 ? 0 : -1;
}

/* Fit candidate ci on all samples (into cand_full[ci]) and count the
 * directions it adds that the data identify. 1 when it is worth
 * cross-validating, else 0 with ca->note set. */
static int cand_identify(run_state *S, unsigned ci, unsigned count, rch_diagnose_cand *ca, rc_solve_result *res)
{
    const cdef *cd = &all_cands[ci];
    const rch_diagnose_result *out = S->out;
    rc_model *full = &S->cand_full[ci];
    *full = S->base;
    if (rc_model_add_effect(full, cd->kind, cd->joint0, count) != RC_OK) {
        snprintf(ca->note, sizeof ca->note, "not applicable: model capacity (RC_MAX_PARAMS %d)", RC_MAX_PARAMS);
        return 0;
    }
    ca->n_params = full->n_params - S->base.n_params;
    const rc_model m0 = *full; /* the candidate at zero: it predicts as the base */
    if (cd->kind == RC_EFF_LENGTH_PERIODIC && periodic_start(full, &S->base, out->s, out->n) != 0) {
        snprintf(ca->note, sizeof ca->note, "not applicable: the lengths span too little for a period");
        return 0;
    }
    if (rch_dg_fit(full, res, &S->c, NULL, out->s, out->n) != 0) {
        snprintf(ca->note, sizeof ca->note, "fit failed");
        return 0;
    }
    const unsigned ra = rch_dg_rank_at(full, full->n_params, out->s, out->n, S->c.w, S->cfg.verbose > 2);
    if (S->base_rank == 0) /* the base's own rank: once a step, at the base's solution */
        S->base_rank = rch_dg_rank_at(&S->base, S->base.n_params, out->s, out->n, S->c.w, 0);
    const unsigned rb = S->base_rank;
    ca->n_ident = ra > rb ? ra - rb : 0;
    if (ca->n_ident > ca->n_params)
        ca->n_ident = ca->n_params;
    if (ca->n_ident == 0) {
        snprintf(ca->note, sizeof ca->note, "not identifiable: %s", known_reason(cd->kind, cd->joint0, &S->base));
        return 0;
    }
    if (ca->n_ident < ca->n_params)
        snprintf(ca->note, sizeof ca->note, "%u of %u parameters identifiable (%s)", ca->n_ident, ca->n_params,
                 known_reason(cd->kind, cd->joint0, &S->base));
    if (cd->kind != RC_EFF_LENGTH_PERIODIC) /* a searched period: its score test would not hold its level */
        ca->scored = rch_dg_score_test(&ca->score_f, &ca->score_dof, &ca->score_p, &m0, full, S->base.n_params,
                                       ca->n_ident, rb, &S->c) == 0;
    if (cd->kind == RC_EFF_LENGTH_PERIODIC) { /* a drum turn: 10 mm .. the lengths' range, at most 500 mm */
        double lmin = 1e300, lmax = -1e300;
        for (size_t i = 0; i < out->n; ++i) {
            lmin = out->s[i].value < lmin ? out->s[i].value : lmin;
            lmax = out->s[i].value > lmax ? out->s[i].value : lmax;
        }
        const double per = fabs(full->x[full->effects[full->n_effects - 1].first + 2]);
        const double hi = lmax - lmin < PERIOD_MAX_MM ? lmax - lmin : PERIOD_MAX_MM;
        if (!(per >= PERIOD_MIN_MM && per <= hi)) {
            ca->implausible = 1;
            snprintf(ca->note, sizeof ca->note,
                     "implausible: fitted period %.4g mm (a drum turn within %.3g .. %.4g mm: the lengths' range, "
                     "at most %.3g)",
                     per, PERIOD_MIN_MM, hi, PERIOD_MAX_MM);
        }
    }
    const double worst_deg = implausible_deg(full, (const double(*)[V_N])S->var, out->n);
    if (worst_deg > 0.0) {
        ca->implausible = 1;
        snprintf(ca->note, sizeof ca->note,
                 "implausible: fitted joint error up to %.3g deg (limit %.3g): it stands in for something else",
                 worst_deg, PLAUSIBLE_DEG);
    }
    return 1;
}

void rch_dg_paired_gain(double *gain_mm2, double *se_mm2, const double *a, const double *b, const ctx *c)
{
    const size_t n = c->n, np = c->n_poses;
    double *dp = calloc(np ? np : 1, sizeof *dp), sd = 0.0, sd2 = 0.0;
    if (!dp || np < 2) {
        free(dp);
        *gain_mm2 = *se_mm2 = 0.0;
        return;
    }
    for (size_t i = 0; i < n; ++i)
        dp[c->pose[i]] += a[i] * a[i] - b[i] * b[i];
    for (size_t p = 0; p < np; ++p) {
        sd += dp[p];
        sd2 += dp[p] * dp[p];
    }
    free(dp);
    const double mean = sd / (double)np; /* per pose; reported per sample */
    const double var_d = (sd2 - (double)np * mean * mean) / (double)(np - 1);
    *gain_mm2 = sd / (double)n;
    *se_mm2 = sqrt(var_d > 0.0 ? var_d / (double)np : 0.0) * ((double)np / (double)n);
}

/* Cross-validate candidate ci (per-fold models from the current ones) and
 * test its held-out gain: paired differences of squared errors. 0 or -1. */
static int cand_cv(run_state *S, unsigned ci, unsigned count, rch_diagnose_cand *ca)
{
    const cdef *cd = &all_cands[ci];
    const size_t n = S->out->n;
    const rc_model *full = &S->cand_full[ci];
    rc_model *fm = &S->cand_folds[(size_t)ci * S->c.k];
    double *rc_ = &S->cand_res[(size_t)ci * n];
    for (unsigned f = 0; f < S->c.k; ++f) {
        fm[f] = S->base_folds[f];
        rc_model_add_effect(&fm[f], cd->kind, cd->joint0, count);
        if (cd->kind == RC_EFF_JOINT_COMPLIANCE) /* same frozen lever geometry as the full model */
            memcpy(fm[f].effects[fm[f].n_effects - 1].ref_dh, full->effects[full->n_effects - 1].ref_dh,
                   sizeof full->effects[0].ref_dh);
        if (cd->kind == RC_EFF_LENGTH_PERIODIC) /* a nonlinear period: start where the full fit ended */
            memcpy(&fm[f].x[fm[f].effects[fm[f].n_effects - 1].first], &full->x[full->effects[full->n_effects - 1].first],
                   3 * sizeof full->x[0]);
    }
    if (rch_dg_cv_run(fm, rc_, &S->c) != 0) {
        snprintf(ca->note, sizeof ca->note, "a cross-validation fit failed");
        return -1;
    }
    double mean, se;
    rch_dg_paired_gain(&mean, &se, S->r0, rc_, &S->c);
    ca->tested = 1;
    ca->rmse_cv_mm = rch_rms(rc_, n);
    ca->gain_mm2 = mean;
    ca->gain_se_mm2 = se;
    ca->z = ca->gain_se_mm2 > 0.0 ? mean / ca->gain_se_mm2 : 0.0;
    ca->p_value = 0.5 * erfc(ca->z / sqrt(2.0));
    return 0;
}

/* Progress lines of a tested candidate (verbose). */
static void cand_verbose(const run_state *S, unsigned step, unsigned ci, const rch_diagnose_cand *ca,
                         const rc_solve_result *res)
{
    const double *rc_ = &S->cand_res[(size_t)ci * S->out->n];
    fprintf(stderr, "diagnose: step %u %-22s held-out %.4f mm  z %.2f train %.4f\n", step + 1, ca->name,
            ca->rmse_cv_mm, ca->z, res->rms_final_mm);
    if (S->cfg.verbose > 1)
        for (size_t i = 0; i < S->out->n; ++i)
            if (fabs(rc_[i]) > 4.0 || fabs(S->r0[i]) > 4.0)
                fprintf(stderr, "   sample %zu group %u fold %u r0 %.3f rc %.3f\n", i + 1, S->out->s[i].group,
                        S->c.fold[i], S->r0[i], rc_[i]);
}

/* Every candidate not yet in the model, tried in one step. Returns the number
 * cross-validated. */
static unsigned step_candidates(run_state *S, rch_diagnose_step *st, unsigned step)
{
    unsigned n_tested = 0;
    for (unsigned ci = 0; ci < N_ALL_CANDS; ++ci) {
        const cdef *cd = &all_cands[ci];
        rch_diagnose_cand *ca = &st->cand[st->n_cand];
        unsigned count;
        rc_solve_result res;
        memset(ca, 0, sizeof *ca);
        ca->kind = cd->kind;
        ca->joint = is_joint_kind(cd->kind) ? cd->joint0 + 1 : 0;
        cand_name(ca->name, sizeof ca->name, cd->kind, cd->joint0);
        if (rch_dg_has_effect(&S->base, cd->kind, cd->joint0) || !cand_relevant(S, cd))
            continue; /* already in the model, or its sensor is not in the data */
        st->n_cand++;
        if (!cand_applicable(S, cd, ca, &count) || !cand_identify(S, ci, count, ca, &res) ||
            cand_cv(S, ci, count, ca) != 0)
            continue;
        ++n_tested;
        if (S->cfg.verbose)
            cand_verbose(S, step, ci, ca, &res);
    }
    return n_tested;
}

/* One-standard-error rule: among the significant candidates with fewer
 * parameters than the best, the one whose held-out MSE is within one standard
 * error of the best (the fewest parameters, then the largest gain). slot_ci:
 * candidate slot -> all_cands index. */
static int one_se_rule(const run_state *S, const rch_diagnose_step *st, int best, const unsigned *slot_ci)
{
    const size_t n = S->out->n;
    int chosen = best;
    const double *rb = &S->cand_res[(size_t)slot_ci[best] * n];
    for (unsigned k = 0; k < st->n_cand; ++k) {
        const rch_diagnose_cand *ca = &st->cand[k];
        if ((int)k == best || !ca->significant || ca->n_params >= st->cand[best].n_params)
            continue;
        const double *rk = &S->cand_res[(size_t)slot_ci[k] * n];
        double m1, se;
        rch_dg_paired_gain(&m1, &se, rk, rb, &S->c);
        if (m1 <= se &&
            (chosen == best || ca->n_params < st->cand[chosen].n_params ||
             (ca->n_params == st->cand[chosen].n_params && ca->gain_mm2 > st->cand[chosen].gain_mm2)))
            chosen = (int)k;
    }
    return chosen;
}

static int is_scale_kind(rc_effect_kind k)
{
    return k == RC_EFF_LENGTH_SCALE || k == RC_EFF_OUTLET_SCALE || k == RC_EFF_TRACKER_SCALE;
}

/* The Laplace log evidence of a scale candidate (slot k, all_cands index
 * ci) up to a constant common to the step: the held-out fit, -(n/2) ln MSE,
 * and for each parameter it adds the Occam factor ln(se / prior sd) - x^2 /
 * (2 prior sd^2), se its fold-jackknife standard error and the prior the
 * effect's plausible range as 3 sd (rch_prior_fill's). A parameter the data
 * do not determine (se at or above the prior) adds its prior term alone. */
static double scale_log_evidence(const run_state *S, const rch_diagnose_cand *ca, unsigned ci)
{
    const rc_model *m = &S->cand_full[ci];
    const rc_model *folds = &S->cand_folds[(size_t)ci * S->c.k];
    const unsigned k = S->c.k;
    const rc_effect_desc *ds = rc_effect_describe(ca->kind);
    double ev = -0.5 * (double)S->out->n * log(ca->rmse_cv_mm * ca->rmse_cv_mm);
    for (unsigned e = 0; ds && e < m->n_effects; ++e) {
        if (m->effects[e].kind != (uint8_t)ca->kind)
            continue;
        const double sd = ds->limit / 3.0;
        for (unsigned p = 0; p < m->effects[e].count; ++p) {
            const unsigned idx = m->effects[e].first + p;
            double mean = 0.0, v = 0.0;
            for (unsigned f = 0; f < k; ++f)
                mean += folds[f].x[idx] / (double)k;
            for (unsigned f = 0; f < k; ++f)
                v += (folds[f].x[idx] - mean) * (folds[f].x[idx] - mean);
            const double se = sqrt(v * (double)(k - 1) / (double)k);
            if (se > 0.0 && se < sd)
                ev += log(se / sd);
            ev -= m->x[idx] * m->x[idx] / (2.0 * sd * sd);
        }
    }
    return ev;
}

/* Where the tracker and a cable both measure, a scale error of one equals a
 * scale error of the other with the robot scaled: only their ratio is seen.
 * When the best candidate is a scale and other significant scale candidates
 * explain the same (penalised held-out fit within 2 ln n), the one whose
 * prior makes the measured ratio most probable is named (its Laplace
 * evidence): a tracker's scale is known to about 100 ppm, a draw-wire's to
 * per cent, so a ratio of tens of ppm is the tracker's. -1: no such choice,
 * else the slot chosen. */
static int scale_alias_choice(const run_state *S, const rch_diagnose_step *st, int best, const double *crit,
                              const unsigned *slot_ci)
{
    if (S->out->n_tracker == 0 || S->out->n_cable == 0 || !is_scale_kind(st->cand[best].kind))
        return -1;
    const double tie = 2.0 * log((double)S->out->n);
    int pick = -1, others = 0;
    double best_ev = -INFINITY;
    for (unsigned k = 0; k < st->n_cand; ++k) {
        const rch_diagnose_cand *ca = &st->cand[k];
        if (!ca->tested || !ca->significant || !is_scale_kind(ca->kind) || fabs(crit[k] - crit[best]) >= tie)
            continue;
        others += (int)k != best;
        const double ev = scale_log_evidence(S, ca, slot_ci[k]);
        if (ev > best_ev) {
            best_ev = ev;
            pick = (int)k;
        }
    }
    return others > 0 ? pick : -1;
}

/* Per set-up offsets (group_offset) chosen, when one common offset
 * explains the set-ups alike: length_offset. Without the prior its
 * direction is nearly the geometry's (relative singular value ~1e-7 on the
 * IRB120: not identifiable by the rank rule, so not tested), yet its fit
 * moves the lengths as a constant does, and calibrate's prior determines it
 * (every length -5 mm: -4.96 +- 0.11 mm). It is cross-validated here; when
 * its held-out error is within one standard error of the group offsets' and
 * its own held-out gain is significant (the paired z test, Bonferroni as the
 * rest), it is named instead: the simpler cause, which calibrate fits and
 * which predicts at a new pose. -1: keep the group offsets, else its slot. */
static int common_offset_instead(run_state *S, rch_diagnose_step *st, int group, const unsigned *slot_ci,
                                 unsigned n_tested)
{
    const size_t n = S->out->n;
    for (unsigned k = 0; k < st->n_cand; ++k) {
        rch_diagnose_cand *ca = &st->cand[k];
        if (ca->kind != RC_EFF_LENGTH_OFFSET || ca->tested || ca->n_params != 1 ||
            strncmp(ca->note, "not identifiable", 16) != 0)
            continue;
        if (cand_cv(S, slot_ci[k], 0, ca) != 0)
            return -1;
        double m1, se;
        rch_dg_paired_gain(&m1, &se, &S->cand_res[(size_t)slot_ci[k] * n], &S->cand_res[(size_t)slot_ci[group] * n],
                           &S->c);
        ca->p_decision = ca->p_value;
        ca->significant = ca->p_value < S->cfg.alpha / (n_tested ? n_tested : 1) && ca->gain_mm2 > 0.0;
        snprintf(ca->note, sizeof ca->note,
                 "nearly the geometry's direction without a prior (rank rule: not identifiable); tested against "
                 "group_offset: held-out gain z = %.1f",
                 ca->z);
        return ca->significant && m1 <= se ? (int)k : -1;
    }
    return -1;
}

/* Significance (Bonferroni over the tested candidates) and the choice of one
 * step; the chosen candidate becomes the current model. 1 when one was
 * chosen, 0 when the search ends. */
static int step_choose(run_state *S, rch_diagnose_step *st, unsigned n_tested)
{
    rch_diagnose_result *out = S->out;
    int best = -1, second = -1;
    /* Among the significant candidates the strongest evidence wins (the
     * smallest p of its test, which counts the directions it adds); the
     * held-out MSE penalised by the parameters it adds (n ln MSE + p ln n,
     * BIC-like) breaks ties and says when two explain the same. */
    double crit[RCH_DIAGNOSE_MAX_CAND];
    const double nn = (double)out->n;
    for (unsigned k = 0; k < st->n_cand; ++k) {
        rch_diagnose_cand *ca = &st->cand[k];
        if (!ca->tested)
            continue;
        ca->p_decision = ca->scored ? ca->score_p : ca->p_value;
        ca->significant = ca->p_decision < S->cfg.alpha / n_tested && !ca->implausible &&
                          (ca->scored || ca->gain_mm2 > 0.0);
        crit[k] = nn * log(ca->rmse_cv_mm * ca->rmse_cv_mm) + (double)ca->n_ident * log(nn);
        if (!ca->significant)
            continue;
#define RCH_DG_BEFORE(a, b)                                                                                            \
    (st->cand[a].p_decision < st->cand[b].p_decision ||                                                                \
     (st->cand[a].p_decision == st->cand[b].p_decision && crit[a] < crit[b]))
        if (best < 0 || RCH_DG_BEFORE(k, (unsigned)best)) {
            second = best;
            best = (int)k;
        } else if (second < 0 || RCH_DG_BEFORE(k, (unsigned)second)) {
            second = (int)k;
        }
#undef RCH_DG_BEFORE
    }
    if (best < 0) {
        snprintf(st->why, sizeof st->why,
                 "no candidate is significant (p < %.2g each, Bonferroni)",
                 S->cfg.alpha / (n_tested ? n_tested : 1));
        return 0;
    }
    unsigned slot_ci[RCH_DIAGNOSE_MAX_CAND], k = 0;
    for (unsigned ci = 0; ci < N_ALL_CANDS; ++ci)
        if (!rch_dg_has_effect(&S->base, all_cands[ci].kind, all_cands[ci].joint0) && cand_relevant(S, &all_cands[ci]))
            slot_ci[k++] = ci;
    const int alias = scale_alias_choice(S, st, best, crit, slot_ci);
    int chosen = alias >= 0 ? alias : one_se_rule(S, st, best, slot_ci);
    const int common = st->cand[chosen].kind == RC_EFF_GROUP_OFFSET
                           ? common_offset_instead(S, st, chosen, slot_ci, n_tested)
                           : -1;
    const int group = chosen;
    if (common >= 0)
        chosen = common;
    st->chosen = chosen;
    char cn[40], bn[40]; /* copies: snprintf must not read from the object it writes */
    memcpy(cn, st->cand[chosen].name, sizeof cn);
    memcpy(bn, st->cand[best].name, sizeof bn);
    if (common >= 0) {
        snprintf(st->why, sizeof st->why,
                 "length_offset: one common offset explains the set-ups as well as group_offset (within one "
                 "standard error; held-out gain z = %.1f): the simpler cause, and calibrate fits it",
                 st->cand[chosen].z);
        (void)group;
    } else if (alias >= 0) {
        char on[40];
        memcpy(on, chosen == best && second >= 0 ? st->cand[second].name : bn, sizeof on);
        snprintf(st->why, sizeof st->why,
                 "%s: tracker and cable disagree in scale, only the ratio is seen (%.24s alike); named by the "
                 "priors' evidence (tracker ~100 ppm, draw-wire ~%%)",
                 cn, on);
    } else if (chosen != best)
        snprintf(st->why, sizeof st->why,
                 "%s: significant, and within one standard error of the best (%s) with fewer parameters", cn, bn);
    else if (second >= 0 && fabs(crit[second] - crit[best]) < 2.0 * log(nn)) {
        char sn[40];
        memcpy(sn, st->cand[second].name, sizeof sn);
        snprintf(st->why, sizeof st->why,
                 "%s, confounded with %s (penalised held-out fit within 2 ln n): both explain the same; an acquisition "
                 "that revisits set-ups in shuffled order would separate them",
                 cn, sn);
    } else
        snprintf(st->why, sizeof st->why, "%s: the strongest significant evidence (%s p = %.2g; held-out z = %.1f)",
                 cn, st->cand[chosen].scored ? "score test" : "held-out gain", st->cand[chosen].p_decision,
                 st->cand[chosen].z);
    const unsigned ci = slot_ci[chosen];
    S->base = S->cand_full[ci];
    memcpy(S->base_folds, &S->cand_folds[(size_t)ci * S->c.k], S->c.k * sizeof *S->base_folds);
    memcpy(S->r0, &S->cand_res[(size_t)ci * out->n], out->n * sizeof *S->r0);
    out->n_chosen++;
    if (out->n_chosen == 1) {
        snprintf(out->effect, sizeof out->effect, "%s", rc_effect_name(cand_kind_of(st, chosen)));
        out->joint = st->cand[chosen].joint;
    }
    return 1;
}

/* 5. Candidate search, one effect per step, at most max_steps. */
/* Gravity loads joints 2 and 3 together: when the search took the
 * compliance of one of them, the other's is added too unless the data
 * identify it not at all, it is implausible, or its held-out error is worse
 * by more than one standard error (z < -1); its effect on the lengths may be
 * below the test's reach while it still moves the flange. One more step in
 * the result, its reason said. */
static void gravity_pair(run_state *S)
{
    rch_diagnose_result *out = S->out;
    const int h2 = rch_dg_has_effect(&S->base, RC_EFF_JOINT_COMPLIANCE, 1),
              h3 = rch_dg_has_effect(&S->base, RC_EFF_JOINT_COMPLIANCE, 2);
    if (h2 == h3 || out->n_steps >= RCH_DIAGNOSE_MAX_STEPS)
        return;
    unsigned ci = 0;
    while (ci < N_ALL_CANDS && !(all_cands[ci].kind == RC_EFF_JOINT_COMPLIANCE && all_cands[ci].joint0 == (h2 ? 2u : 1u)))
        ++ci;
    rch_diagnose_step *st = &out->steps[out->n_steps];
    memset(st, 0, sizeof *st);
    st->chosen = -1;
    st->rmse_base_mm = rch_rms(S->r0, out->n);
    S->base_rank = 0;
    rch_diagnose_cand *ca = &st->cand[0];
    const cdef *cd = &all_cands[ci];
    unsigned count;
    rc_solve_result res;
    ca->kind = cd->kind;
    ca->joint = cd->joint0 + 1;
    cand_name(ca->name, sizeof ca->name, cd->kind, cd->joint0);
    st->n_cand = 1;
    if (!cand_applicable(S, cd, ca, &count) || !cand_identify(S, ci, count, ca, &res) || cand_cv(S, ci, count, ca) != 0 ||
        ca->implausible || ca->z < -1.0)
        return; /* the step is not kept */
    out->n_steps++;
    st->chosen = 0;
    char cn[40];
    memcpy(cn, ca->name, sizeof cn);
    snprintf(st->why, sizeof st->why,
             "%s: gravity loads joints 2 and 3 together; added beside the other (held-out gain z = %.1f, not worse "
             "by one standard error)",
             cn, ca->z);
    S->base = S->cand_full[ci];
    memcpy(S->base_folds, &S->cand_folds[(size_t)ci * S->c.k], S->c.k * sizeof *S->base_folds);
    memcpy(S->r0, &S->cand_res[(size_t)ci * out->n], out->n * sizeof *S->r0);
    out->n_chosen++;
}

void rch_dg_phase_search(run_state *S)
{
    rch_diagnose_result *out = S->out;
    S->base = out->geo;
    for (unsigned step = 0; step < S->cfg.max_steps; ++step) {
        rch_diagnose_step *st = &out->steps[out->n_steps++];
        memset(st, 0, sizeof *st);
        st->chosen = -1;
        st->rmse_base_mm = rch_rms(S->r0, out->n);
        S->base_rank = 0;
        const unsigned n_tested = step_candidates(S, st, step);
        if (!step_choose(S, st, n_tested))
            break;
    }
    gravity_pair(S);
    out->final = S->base;
}
