/* SPDX-License-Identifier: MIT */
/* rch_diagnose.c - the `rcal diagnose` workflow; see rch_diagnose.h. */
#include "rch_diagnose.h"
#include "rch_text.h"
#include "rch_dequant.h"
#include "rch_groups.h"
#include "rch_save.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rc_ident.h"
#include "rc_linalg.h"
#include "rc_rand.h"
#include "rch_calib.h"
#include "rch_start.h"
#include "rch_data.h"
#include "rch_jw.h"
#include "rch_plot.h"
#include "rch_resid.h"
#include "rch_robot.h"
#include "rch_stats.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* ------------------------------------------------------------------ stats */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}


/* ------------------------------------------------------- structure tests */

#define MAXREG 6

/* F test of r (n) against regressors X (n x p, row-major), intercept
 * included. Nearly collinear regressors are dropped (dof counts the rest). */
static void test_regress(rch_diagnose_test *t, const char *name, const double *r, const double *X,
                         unsigned p, size_t n, double alpha_each)
{
    double xm[MAXREG] = {0}, rm = 0.0, A[MAXREG * MAXREG] = {0}, b[MAXREG] = {0}, rss0 = 0.0;
    memset(t, 0, sizeof *t);
    snprintf(t->name, sizeof t->name, "%s", name);
    for (size_t i = 0; i < n; ++i) {
        rm += r[i];
        for (unsigned k = 0; k < p; ++k)
            xm[k] += X[i * p + k];
    }
    rm /= (double)n;
    for (unsigned k = 0; k < p; ++k)
        xm[k] /= (double)n;
    for (size_t i = 0; i < n; ++i) {
        const double ri = r[i] - rm;
        rss0 += ri * ri;
        for (unsigned k = 0; k < p; ++k) {
            const double xk = X[i * p + k] - xm[k];
            b[k] += xk * ri;
            for (unsigned l = 0; l < p; ++l)
                A[k * p + l] += xk * (X[i * p + l] - xm[l]);
        }
    }
    /* Cholesky-like elimination with pivot dropping. */
    unsigned used[MAXREG] = {0}, dof = 0;
    double amax = 0.0;
    for (unsigned k = 0; k < p; ++k)
        if (A[k * p + k] > amax)
            amax = A[k * p + k];
    double expl = 0.0;
    for (unsigned k = 0; k < p; ++k) {
        const double piv = A[k * p + k];
        if (!(piv > 1e-10 * amax) || !(piv > 0.0))
            continue;
        used[k] = 1;
        ++dof;
        expl += b[k] * b[k] / piv;
        for (unsigned i = k + 1; i < p; ++i) {
            const double f = A[i * p + k] / piv;
            b[i] -= f * b[k];
            for (unsigned l = k + 1; l < p; ++l)
                A[i * p + l] -= f * A[k * p + l];
        }
    }
    (void)used;
    const double rss1 = rss0 - expl;
    t->dof1 = dof;
    t->dof2 = n > (size_t)dof + 1 ? (unsigned)(n - dof - 1) : 0;
    if (dof == 0 || t->dof2 == 0 || !(rss0 > 0.0)) {
        t->p_value = 1.0;
        return;
    }
    t->r2 = expl / rss0;
    t->f_stat = (expl / dof) / ((rss1 > 0.0 ? rss1 : 1e-300) / t->dof2);
    t->p_value = rch_f_sf(t->f_stat, dof, t->dof2);
    t->significant = t->p_value < alpha_each;
}

static void test_bias(rch_diagnose_test *t, const double *r, size_t n, double alpha_each)
{
    double m = 0.0, ss = 0.0;
    memset(t, 0, sizeof *t);
    snprintf(t->name, sizeof t->name, "bias (mean residual)");
    for (size_t i = 0; i < n; ++i)
        m += r[i];
    m /= (double)n;
    for (size_t i = 0; i < n; ++i)
        ss += (r[i] - m) * (r[i] - m);
    t->dof1 = 1;
    t->dof2 = n > 1 ? (unsigned)(n - 1) : 0;
    const double tot = ss + (double)n * m * m;
    if (t->dof2 == 0 || !(ss > 0.0)) {
        t->p_value = 1.0;
        return;
    }
    t->r2 = (double)n * m * m / tot;
    t->f_stat = (double)n * m * m / (ss / t->dof2);
    t->p_value = rch_f_sf(t->f_stat, 1.0, t->dof2);
    t->significant = t->p_value < alpha_each;
}

static void test_groups(rch_diagnose_test *t, const double *r, const rc_sample *s, size_t n,
                        unsigned n_groups, double alpha_each)
{
    double *sum = calloc(n_groups, sizeof *sum);
    size_t *cnt = calloc(n_groups, sizeof *cnt);
    memset(t, 0, sizeof *t);
    snprintf(t->name, sizeof t->name, "groups (ANOVA)");
    t->p_value = 1.0;
    if (!sum || !cnt) {
        free(sum);
        free(cnt);
        return;
    }
    double m = 0.0;
    for (size_t i = 0; i < n; ++i) {
        sum[s[i].group] += r[i];
        cnt[s[i].group]++;
        m += r[i];
    }
    m /= (double)n;
    unsigned g_used = 0;
    double ssb = 0.0, ssw = 0.0;
    for (unsigned g = 0; g < n_groups; ++g)
        if (cnt[g]) {
            ++g_used;
            const double gm = sum[g] / (double)cnt[g];
            ssb += (double)cnt[g] * (gm - m) * (gm - m);
        }
    for (size_t i = 0; i < n; ++i) {
        const double gm = sum[s[i].group] / (double)cnt[s[i].group];
        ssw += (r[i] - gm) * (r[i] - gm);
    }
    free(sum);
    free(cnt);
    if (g_used < 2 || n <= g_used || !(ssw > 0.0))
        return;
    t->dof1 = g_used - 1;
    t->dof2 = (unsigned)(n - g_used);
    t->r2 = ssb / (ssb + ssw);
    t->f_stat = (ssb / t->dof1) / (ssw / t->dof2);
    t->p_value = rch_f_sf(t->f_stat, t->dof1, t->dof2);
    t->significant = t->p_value < alpha_each;
}

/* Explanatory variables per sample, from the geometric model. */
typedef struct explain {
    double (*var)[12]; /* (n x 12): lever2, lever3, L, ux, uy, uz, t */
} explain;

enum { V_LEV2 = 0, V_LEV3, V_LEN, V_UX, V_UY, V_UZ, V_T, V_N };

static unsigned groups_usable(unsigned n_groups, size_t n) { return n_groups >= 2 && (size_t)n_groups * 3 <= n; }

/* All structure tests of residuals r (n). Returns the number of tests. */
static unsigned structure_tests(rch_diagnose_test *out, const double *r, const rc_sample *s, size_t n,
                                const double (*var)[V_N], unsigned n_groups, double alpha)
{
    const unsigned n_tests = 12 + groups_usable(n_groups, n);
    const double a_each = alpha / n_tests;
    double *X = malloc((n ? n : 1) * MAXREG * sizeof *X);
    unsigned k = 0;
    if (!X)
        return 0;
    test_bias(&out[k++], r, n, a_each);
    for (unsigned j = 0; j < RC_NJ; ++j) {
        char name[40];
        for (size_t i = 0; i < n; ++i) {
            const double q = s[i].q_rad[j];
            X[i * 4 + 0] = sin(q);
            X[i * 4 + 1] = cos(q);
            X[i * 4 + 2] = sin(2.0 * q);
            X[i * 4 + 3] = cos(2.0 * q);
        }
        snprintf(name, sizeof name, "q%u harmonics (1st, 2nd)", j + 1);
        test_regress(&out[k++], name, r, X, 4, n, a_each);
    }
    for (size_t i = 0; i < n; ++i)
        X[i] = var[i][V_LEV2];
    test_regress(&out[k++], "gravity lever j2", r, X, 1, n, a_each);
    for (size_t i = 0; i < n; ++i)
        X[i] = var[i][V_LEV3];
    test_regress(&out[k++], "gravity lever j3", r, X, 1, n, a_each);
    /* cable length: a smooth shape, not only a slope (a sensor's bow, a drum
     * turn): u, u^2, u^3, sin and cos of 2 pi u, u the length scaled to [0, 1] */
    double lmin = 1e300, lmax = -1e300;
    for (size_t i = 0; i < n; ++i) {
        lmin = var[i][V_LEN] < lmin ? var[i][V_LEN] : lmin;
        lmax = var[i][V_LEN] > lmax ? var[i][V_LEN] : lmax;
    }
    for (size_t i = 0; i < n; ++i) {
        const double u = lmax > lmin ? (var[i][V_LEN] - lmin) / (lmax - lmin) : 0.0;
        X[i * 5 + 0] = u;
        X[i * 5 + 1] = u * u;
        X[i * 5 + 2] = u * u * u;
        X[i * 5 + 3] = sin(2.0 * M_PI * u);
        X[i * 5 + 4] = cos(2.0 * M_PI * u);
    }
    test_regress(&out[k++], "cable length", r, X, 5, n, a_each);
    for (size_t i = 0; i < n; ++i) {
        X[i * 3 + 0] = var[i][V_UX];
        X[i * 3 + 1] = var[i][V_UY];
        X[i * 3 + 2] = var[i][V_UZ];
    }
    test_regress(&out[k++], "cable direction", r, X, 3, n, a_each);
    for (size_t i = 0; i < n; ++i) {
        X[i * 2 + 0] = var[i][V_T];
        X[i * 2 + 1] = var[i][V_T] * var[i][V_T];
    }
    test_regress(&out[k++], "acquisition order (t, t^2)", r, X, 2, n, a_each);
    if (groups_usable(n_groups, n))
        test_groups(&out[k++], r, s, n, n_groups, a_each);
    free(X);
    return k;
}

/* ------------------------------------------------------------- workflow */

typedef struct ctx {
    const rc_sample *s; /* (n) */
    size_t n;
    unsigned k;                            /* folds */
    unsigned *fold;                        /* (n) fold of each sample */
    rc_sample *train[RCH_DIAGNOSE_MAX_FOLDS]; /* (n_train[f]) */
    size_t n_train[RCH_DIAGNOSE_MAX_FOLDS];
    rc_solve_work *w;
    unsigned max_iter;
    int verbose;
} ctx;

static int fit(rc_model *m, rc_solve_result *res, ctx *c, const uint8_t *fixed, const rc_sample *s,
               size_t n)
{
    rc_solve_config cfg;
    rc_solve_result tmp;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_METHOD_LM;
    cfg.max_iter = fixed || s == c->s ? 200u : c->max_iter; /* cold starts converge fully */
    cfg.fixed = fixed;
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
static int cv_run(rc_model *models, double *res, ctx *c)
{
    for (unsigned f = 0; f < c->k; ++f) {
        if (fit(&models[f], NULL, c, NULL, c->train[f], c->n_train[f]) != 0)
            return -1;
        unseen_groups(&models[f], c->train[f], c->n_train[f]);
    }
    for (size_t i = 0; i < c->n; ++i) {
        double l;
        if (rc_meas(&l, NULL, &models[c->fold[i]], &c->s[i]) != RC_OK)
            return -1;
        res[i] = l - c->s[i].len_mm;
    }
    return 0;
}

/* Rank of the first np parameters of m over the samples: the number of
 * directions rc_ident (the one definition of identifiability) does not call
 * null. dump: print the relative singular values to stderr. */
static unsigned rank_at(const rc_model *m, unsigned np, const rc_sample *s, size_t n, rc_solve_work *w, int dump)
{
    double cost;
    for (unsigned i = 0; i < np; ++i)
        w->idx[i] = (uint16_t)i;
    if (rc_normal_eq(w->A, w->g, &cost, w->jrow, m, w->idx, np, s, n) != RC_OK)
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

/* Largest joint-side error that is still physical for a gear or joint
 * deflection (deg); a fit beyond it is the solver using the effect for
 * something else (e.g. a huge joint-6 ripple moving an off-axis point). */
#define PLAUSIBLE_DEG 1.0

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

static int has_effect(const rc_model *m, rc_effect_kind kind, unsigned joint0)
{
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == (uint8_t)kind && m->effects[i].joint == joint0)
            return 1;
    return 0;
}

typedef struct cdef {
    rc_effect_kind kind;
    unsigned joint0;
} cdef;

static const cdef all_cands[] = {
    {RC_EFF_LENGTH_OFFSET, 0},    {RC_EFF_LENGTH_SCALE, 0},     {RC_EFF_TIME_DRIFT, 0},
    {RC_EFF_GROUP_OFFSET, 0},     {RC_EFF_JOINT_COMPLIANCE, 1}, {RC_EFF_JOINT_COMPLIANCE, 2},
    {RC_EFF_JOINT_PERIODIC, 0},   {RC_EFF_JOINT_PERIODIC, 1},   {RC_EFF_JOINT_PERIODIC, 2},
    {RC_EFF_JOINT_PERIODIC, 3},   {RC_EFF_JOINT_PERIODIC, 4},   {RC_EFF_JOINT_PERIODIC, 5},
    {RC_EFF_TOOL_OFFSET, 0},      {RC_EFF_CABLE_SAG, 0},        {RC_EFF_LENGTH_NONLIN, 0},
    {RC_EFF_LENGTH_PERIODIC, 0},
};
#define N_ALL_CANDS (sizeof all_cands / sizeof all_cands[0])
RC_STATIC_ASSERT(sizeof all_cands / sizeof all_cands[0] <= RCH_DIAGNOSE_MAX_CAND, candidates_fit_the_step);

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
    if (kind == RC_EFF_TOOL_OFFSET)
        return "a cable attachment offset in the flange frame trades against a6, d6 and theta6";
    if (kind == RC_EFF_JOINT_PERIODIC && joint0 == 5)
        return "joint 6 turns the flange about its own axis: the cable attachment point does not move";
    if (kind == RC_EFF_LENGTH_OFFSET && has_effect(base, RC_EFF_GROUP_OFFSET, 0))
        return "a common offset of all groups is a length offset";
    if (kind == RC_EFF_GROUP_OFFSET && has_effect(base, RC_EFF_LENGTH_OFFSET, 0))
        return "the sum of the group offsets is the length offset already in the model";
    if (kind == RC_EFF_JOINT_PERIODIC)
        return "part of the periodic terms is confounded with the joint's offset or the geometry";
    if (kind == RC_EFF_GROUP_OFFSET)
        return "their common level is a length offset, which the geometry nearly absorbs";
    return "confounded with the geometry on these poses";
}

static rc_effect_kind cand_kind_of(const rch_diagnose_step *st, int k) { return st->cand[k].kind; }

static void jack_se(double *value_se, const double *vals, unsigned k)
{
    double m = 0.0, v = 0.0;
    for (unsigned f = 0; f < k; ++f)
        m += vals[f];
    m /= k;
    for (unsigned f = 0; f < k; ++f)
        v += (vals[f] - m) * (vals[f] - m);
    *value_se = sqrt(v * (double)(k - 1) / (double)k);
}

static void group_stats(double *mean, double *sd, double *lo, double *hi, const double *x, unsigned count)
{
    double m = 0.0, v = 0.0, a = 1e300, b = -1e300;
    for (unsigned g = 0; g < count; ++g) {
        m += x[g];
        a = x[g] < a ? x[g] : a;
        b = x[g] > b ? x[g] : b;
    }
    m /= count;
    for (unsigned g = 0; g < count; ++g)
        v += (x[g] - m) * (x[g] - m);
    *mean = m;
    *sd = count > 1 ? sqrt(v / (count - 1)) : 0.0;
    if (lo)
        *lo = a;
    if (hi)
        *hi = b;
}

static void add_param(rch_diagnose_result *r, const char *name, double value, double se, const char *unit)
{
    if (r->n_params >= RCH_DIAGNOSE_MAX_PARAMS)
        return;
    rch_diagnose_param *p = &r->params[r->n_params++];
    snprintf(p->name, sizeof p->name, "%s", name);
    p->value = value;
    p->se = se;
    snprintf(p->unit, sizeof p->unit, "%s", unit);
}

/* Effect parameters of the final model in display units, with fold-jackknife
 * standard errors from the fold models (k). */
static void report_params(rch_diagnose_result *r, const rc_model *fold_models, unsigned k)
{
    const rc_model *m = &r->final;
    double vals[RCH_DIAGNOSE_MAX_FOLDS], se;
    char name[48];
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        const rc_effect_kind kind = (rc_effect_kind)ef->kind;
        if (kind == RC_EFF_GROUP_OFFSET) {
            /* summarise: common level (trades with the geometry) and the
             * spread between set-ups (what the groups really differ by) */
            double vals2[RCH_DIAGNOSE_MAX_FOLDS], se2, mean, sd, lo, hi;
            group_stats(&mean, &sd, &lo, &hi, &m->x[ef->first], ef->count);
            for (unsigned f = 0; f < k; ++f)
                group_stats(&vals[f], &vals2[f], NULL, NULL, &fold_models[f].x[ef->first], ef->count);
            jack_se(&se, vals, k);
            jack_se(&se2, vals2, k);
            add_param(r, "group_offset spread (sd)", sd, se2, "mm");
            add_param(r, "group_offset range (max-min)", hi - lo, 0.0, "mm");
            add_param(r, "group_offset common level", mean, se, "mm");
            continue;
        }
        for (unsigned p = 0; p < ef->count; ++p) {
            const unsigned idx = ef->first + p;
            double scale = 1.0;
            const char *unit = "mm";
            if (kind == RC_EFF_JOINT_PERIODIC) {
                scale = 1e3 / DEG;
                unit = "mdeg";
            } else if (kind == RC_EFF_JOINT_COMPLIANCE) {
                scale = 1e3 / DEG;
                unit = "mdeg/m";
            } else if (kind == RC_EFF_LENGTH_SCALE) {
                scale = 1e6;
                unit = "ppm";
            } else if (kind == RC_EFF_LENGTH_PERIODIC) {
                unit = "mm";
            } else if (kind == RC_EFF_CABLE_SAG || (kind == RC_EFF_LENGTH_NONLIN && p == 1)) {
                unit = "mm/m^3";
            } else if (kind == RC_EFF_LENGTH_NONLIN) {
                unit = "mm/m^2";
            }
            for (unsigned f = 0; f < k; ++f)
                vals[f] = fold_models[f].x[idx] * scale;
            jack_se(&se, vals, k);
            rc_param_name(name, sizeof name, m, idx);
            add_param(r, name, m->x[idx] * scale, se, unit);
        }
    }
}

/* Notes on what cable lengths cannot identify, checked on this data. */
static void scale_note(rch_diagnose_result *r)
{
    /* encoder scale 1e-3 versus the robot and the encoder position scaled
     * by 1 + 1e-3: compare the cable lengths they predict. */
    const double sc = 1e-3;
    rc_model a = r->geo, b = r->geo;
    if (rc_model_add_effect(&a, RC_EFF_LENGTH_SCALE, 0, 0) != RC_OK)
        return;
    a.x[a.effects[a.n_effects - 1].first] = sc;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        b.x[RC_P_A(i)] *= 1.0 + sc;
        b.x[RC_P_D(i)] *= 1.0 + sc;
    }
    for (unsigned k = 0; k < 3; ++k)
        b.x[RC_P_ENC + k] *= 1.0 + sc;
    double d2 = 0.0, e2 = 0.0;
    for (size_t i = 0; i < r->n; ++i) {
        double la, lb, l0;
        if (rc_meas(&la, NULL, &a, &r->s[i]) != RC_OK || rc_meas(&lb, NULL, &b, &r->s[i]) != RC_OK ||
            rc_meas(&l0, NULL, &r->geo, &r->s[i]) != RC_OK)
            return;
        d2 += (la - lb) * (la - lb);
        e2 += (la - l0) * (la - l0);
    }
    if (r->n_notes >= RCH_DIAGNOSE_MAX_NOTES)
        return;
    snprintf(r->notes[r->n_notes++], sizeof r->notes[0],
             "encoder scale vs robot size: a cable scale error of 1000 ppm changes the lengths by %.3f mm rms, "
             "but a robot and encoder position 1000 ppm larger predict the same lengths to %.1e mm rms: "
             "not identifiable from cable lengths. A length reference separates them: a gauge of known "
             "length (or two points a known distance apart, e.g. by laser tracker or CMM) measured with the cable.",
             sqrt(e2 / (double)r->n), sqrt(d2 / (double)r->n));
}

/* The state of one diagnosis run, handed from phase to phase. The phases run
 * in order (setup, steps, 1 geometry, 2 floor, 3 folds, 4 cross-validated
 * geometry, 5 candidate search, 6 after, 7 report); each reads what the ones
 * before it left here and in the result. Everything on the heap is freed by
 * run_free. */
typedef struct run_state {
    rch_diagnose_cfg cfg;     /* with the defaults filled in */
    rch_diagnose_result *out; /* the caller's result, filled phase by phase */
    ctx c;                    /* samples (out->s), folds, training sets, solver scratch */
    rc_model base;            /* the model entering the current search step (geometry + chosen effects) */
    rc_model *base_folds;     /* (k) that model fitted on each fold's training samples */
    rc_model *cand_full;      /* (N_ALL_CANDS) each candidate fitted on all samples */
    rc_model *cand_folds;     /* (N_ALL_CANDS x k) each candidate fitted per fold */
    double *cand_res;         /* (N_ALL_CANDS x n) held-out residuals per candidate */
    double *r0;               /* (n) held-out residuals of the current model */
    double *tmp;              /* (n x 6) scratch */
    double (*var)[V_N];       /* (n) explanatory variables of the structure tests */
    unsigned *order;          /* (n) shuffled sample order */
} run_state;

static void run_free(run_state *S)
{
    for (unsigned f = 0; f < RCH_DIAGNOSE_MAX_FOLDS; ++f)
        free(S->c.train[f]);
    free(S->c.w);
    free(S->c.fold);
    free(S->r0);
    free(S->tmp);
    free(S->var);
    free(S->order);
    free(S->base_folds);
    free(S->cand_folds);
    free(S->cand_full);
    free(S->cand_res);
}

/* Defaults, size checks and the allocations. 0 or -1 (d set). */
static int phase_setup(run_state *S, rch_diagnose_result *out, const rc_sample *samples, size_t n,
                       const rch_diagnose_cfg *cfg_in, rch_diag *d)
{
    rch_diagnose_cfg *cfg = &S->cfg;
    *cfg = *cfg_in;
    S->out = out;
    if (cfg->folds == 0)
        cfg->folds = 5;
    if (cfg->max_steps == 0)
        cfg->max_steps = 3;
    if (cfg->max_steps > RCH_DIAGNOSE_MAX_STEPS)
        cfg->max_steps = RCH_DIAGNOSE_MAX_STEPS;
    if (cfg->alpha <= 0.0)
        cfg->alpha = 0.01;
    if (cfg->gap_factor <= 0.0)
        cfg->gap_factor = 1.25;
    if (cfg->folds < 2 || cfg->folds > RCH_DIAGNOSE_MAX_FOLDS) {
        rch_diag_set(d, "", 0, 0, "folds must be within 2..%d", RCH_DIAGNOSE_MAX_FOLDS);
        return -1;
    }
    if (n < 10u * cfg->folds || n < 60) {
        rch_diag_set(d, "", 0, 0, "%zu samples are too few to diagnose (need at least %u)", n,
                     10u * cfg->folds > 60 ? 10u * cfg->folds : 60u);
        return -1;
    }
    out->n = n;
    out->folds = cfg->folds;
    out->s = malloc(n * sizeof *out->s);
    out->res_before_mm = calloc(n, sizeof(double));
    out->res_after_mm = calloc(n, sizeof(double));
    out->floor_mm = calloc(n, sizeof(double));
    S->c.w = malloc(sizeof *S->c.w);
    S->c.fold = calloc(n, sizeof *S->c.fold);
    S->r0 = calloc(n, sizeof *S->r0);
    S->tmp = calloc(n * RC_NJ, sizeof *S->tmp);
    S->var = calloc(n, sizeof *S->var);
    S->order = calloc(n, sizeof *S->order);
    S->base_folds = calloc(cfg->folds, sizeof *S->base_folds);
    S->cand_folds = calloc((size_t)N_ALL_CANDS * cfg->folds, sizeof *S->cand_folds);
    S->cand_full = calloc(N_ALL_CANDS, sizeof *S->cand_full);
    S->cand_res = calloc(N_ALL_CANDS * n, sizeof *S->cand_res);
    if (!out->s || !out->res_before_mm || !out->res_after_mm || !out->floor_mm || !S->c.w || !S->c.fold ||
        !S->r0 || !S->tmp || !S->var || !S->order || !S->base_folds || !S->cand_folds || !S->cand_full ||
        !S->cand_res) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    memcpy(out->s, samples, n * sizeof *samples);
    S->c.s = out->s;
    S->c.n = n;
    S->c.k = cfg->folds;
    S->c.max_iter = cfg->max_iter ? cfg->max_iter : 100u;
    S->c.verbose = cfg->verbose;
    return 0;
}

/* Display steps (given or detected) and the set-up groups (given or by wrist). */
static void phase_steps(run_state *S)
{
    rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    if (S->cfg.groups_given) {
        unsigned g = 0;
        for (size_t i = 0; i < n; ++i)
            g = out->s[i].group > g ? out->s[i].group : g;
        out->n_groups = g + 1;
    }
    for (size_t i = 0; i < n; ++i)
        for (unsigned j = 0; j < RC_NJ; ++j)
            S->tmp[i * RC_NJ + j] = out->s[i].q_rad[j] / DEG;
    out->q_step_deg = S->cfg.q_step_deg > 0.0   ? S->cfg.q_step_deg
                      : S->cfg.q_step_deg < 0.0 ? 0.0
                                                : rch_dequant_detect_step(S->tmp, n * RC_NJ);
    for (size_t i = 0; i < n; ++i)
        S->tmp[i] = out->s[i].len_mm;
    out->len_step_mm = S->cfg.len_step_mm > 0.0   ? S->cfg.len_step_mm
                       : S->cfg.len_step_mm < 0.0 ? 0.0
                                                  : rch_dequant_detect_step(S->tmp, n);
    out->len_noise_mm = S->cfg.len_noise_mm > 0.0 ? S->cfg.len_noise_mm : 0.0;
    if (!S->cfg.groups_given)
        out->n_groups = rch_groups_by_wrist(out->s, n, out->q_step_deg, &out->n_flicker);
}

/* 1. Geometric fit on all samples, from the "before calibration" model of
 * rcal calibrate (rch_calib_bc: nominal geometry, encoder fitted alone). */
static int phase_geometry(run_state *S, const rc_model *nominal, rch_diag *d)
{
    rch_diagnose_result *out = S->out;
    rc_model geometry = *nominal;
    rc_solve_result res;
    geometry.n_effects = 0;
    geometry.n_params = RC_N_BASE;
    if (rch_calib_bc(&out->geo, S->c.w, &geometry, S->cfg.have_encoder, out->s, out->n, d) != 0)
        return -1;
    if (fit(&out->geo, &res, &S->c, NULL, out->s, out->n) != 0) {
        rch_diag_set(d, "", 0, 0, "the geometric fit failed");
        return -1;
    }
    out->train_rmse_geo_mm = res.rms_final_mm;
    out->geo_rank = res.rank;
    out->geo_free = res.n_free;
    return 0;
}

/* 2. Noise floor per sample and the explanatory variables. */
static int phase_floor(run_state *S, rch_diag *d)
{
    rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    const double qs = out->q_step_deg * DEG, ls = out->len_step_mm, ln = out->len_noise_mm;
    double jac[RC_MAX_PARAMS], vq = 0.0, vl = 0.0, ref[4][4];
    const rc_model *g = &out->geo;
    for (unsigned i = 0; i < 4; ++i)
        for (unsigned k = 0; k < 4; ++k)
            ref[i][k] = g->x[4 * i + k];
    for (size_t i = 0; i < n; ++i) {
        double l, p[3], u[3], nu = 0.0, sq = 0.0;
        if (rc_meas(&l, jac, g, &out->s[i]) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "sample %zu: the flange meets the encoder outlet", i + 1);
            return -1;
        }
        for (unsigned j = 0; j < RC_NJ; ++j)
            sq += jac[RC_P_THETA(j)] * jac[RC_P_THETA(j)];
        const double viq = sq * qs * qs / 12.0, vil = ls * ls / 12.0 + ln * ln;
        out->floor_mm[i] = sqrt(viq + vil);
        vq += viq;
        vl += vil;
        rc_fk(p, NULL, g, out->s[i].q_rad);
        for (unsigned k = 0; k < 3; ++k) {
            u[k] = p[k] - g->x[RC_P_ENC + k];
            nu += u[k] * u[k];
        }
        nu = sqrt(nu);
        S->var[i][V_LEV2] = rc_gravity_lever_m((const double(*)[4])ref, 1, out->s[i].q_rad);
        S->var[i][V_LEV3] = rc_gravity_lever_m((const double(*)[4])ref, 2, out->s[i].q_rad);
        S->var[i][V_LEN] = out->s[i].len_mm;
        S->var[i][V_UX] = u[0] / nu;
        S->var[i][V_UY] = u[1] / nu;
        S->var[i][V_UZ] = u[2] / nu;
        S->var[i][V_T] = out->s[i].t;
    }
    out->floor_joints_mm = sqrt(vq / (double)n);
    out->floor_len_mm = sqrt(vl / (double)n);
    out->noise_floor_mm = sqrt((vq + vl) / (double)n);
    return 0;
}

/* Fisher-Yates shuffle of v (n) with the generator's bounded draws. */
static void shuffle(unsigned *v, size_t n, rc_rng *rng)
{
    for (size_t i = n; i > 1; --i) {
        const size_t j = rc_rng_below(rng, (uint32_t)i);
        const unsigned t = v[i - 1];
        v[i - 1] = v[j];
        v[j] = t;
    }
}

/* Fold of every sample: the groups in shuffled order, within each group the
 * samples in shuffled order, dealt round-robin (the counter runs on across
 * groups). 0 or -1 (out of memory). */
static int assign_folds(run_state *S)
{
    const rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    const unsigned ng = out->n_groups;
    rc_rng rng;
    rc_rng_seed(&rng, S->cfg.seed ^ 0x6469616700000000ull);
    for (size_t i = 0; i < n; ++i)
        S->order[i] = (unsigned)i;
    shuffle(S->order, n, &rng);
    unsigned *gorder = calloc(ng ? ng : 1, sizeof *gorder), *byg = calloc(n ? n : 1, sizeof *byg);
    size_t *start = calloc((size_t)ng + 1, sizeof *start), *pos = calloc(ng ? ng : 1, sizeof *pos);
    int rc = -1;
    if (!gorder || !byg || !start || !pos)
        goto done;
    for (unsigned g = 0; g < ng; ++g)
        gorder[g] = g;
    shuffle(gorder, ng, &rng);
    for (size_t i = 0; i < n; ++i) /* bucket the samples by group, in shuffled order */
        start[out->s[i].group + 1]++;
    for (unsigned g = 0; g < ng; ++g)
        start[g + 1] += start[g];
    for (size_t i = 0; i < n; ++i) {
        const unsigned s = S->order[i], g = out->s[s].group;
        byg[start[g] + pos[g]++] = s;
    }
    unsigned counter = 0;
    for (unsigned gi = 0; gi < ng; ++gi)
        for (size_t p = start[gorder[gi]]; p < start[gorder[gi] + 1]; ++p)
            S->c.fold[byg[p]] = counter++ % S->c.k;
    rc = 0;
done:
    free(gorder);
    free(byg);
    free(start);
    free(pos);
    return rc;
}

/* 3. Folds and each fold's training samples. */
static int phase_folds(run_state *S, rch_diag *d)
{
    ctx *c = &S->c;
    if (assign_folds(S) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    for (unsigned f = 0; f < c->k; ++f) {
        size_t nt = 0;
        for (size_t i = 0; i < c->n; ++i)
            nt += c->fold[i] != f;
        c->train[f] = malloc((nt ? nt : 1) * sizeof *c->train[f]);
        if (!c->train[f]) {
            rch_diag_set(d, "", 0, 0, "out of memory");
            return -1;
        }
        c->n_train[f] = 0;
        for (size_t i = 0; i < c->n; ++i)
            if (c->fold[i] != f)
                c->train[f][c->n_train[f]++] = c->s[i];
    }
    return 0;
}

/* 4. Cross-validated geometry: held-out residuals and structure tests. */
static int phase_cv_geometry(run_state *S, rch_diag *d)
{
    rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    for (unsigned f = 0; f < S->c.k; ++f)
        S->base_folds[f] = out->geo;
    if (cv_run(S->base_folds, S->r0, &S->c) != 0) {
        rch_diag_set(d, "", 0, 0, "a cross-validation fit failed");
        return -1;
    }
    memcpy(out->res_before_mm, S->r0, n * sizeof *S->r0);
    out->rmse_before_mm = rch_rms(S->r0, n);
    out->n_tests = structure_tests(out->before, S->r0, out->s, n, (const double(*)[V_N])S->var, out->n_groups,
                                   S->cfg.alpha);
    if (S->cfg.verbose)
        fprintf(stderr, "diagnose: geometry held-out RMSE %.4f mm, floor %.4f mm\n", out->rmse_before_mm,
                out->noise_floor_mm);
    return 0;
}

/* A sharp step inside a set-up: the geometry's residuals of the (up to) 8
 * samples of the same set-up after sample a and before it differ by at
 * least 5 standard errors, the noise taken from the residuals' spread within
 * the two windows, and by the fitted jump size within 30 % of it; and a step
 * fits the window clearly better than a straight line through it (the sums
 * of squares differ by more than 4 noise variances), so that a steep drift,
 * a ramp, is not taken for a jump. A pose-dependent effect read in
 * acquisition order is noise within a set-up and fails; a sensor jump passes. */
static int sharp_step(const rc_model *geo, const rc_sample *s, size_t n, size_t a, double size)
{
    double sum[2] = {0, 0}, sq[2] = {0, 0}, r[16], x[16];
    unsigned cnt[2] = {0, 0}, m = 0;
    for (int side = 0; side < 2; ++side)
        for (size_t k = 0; k < 8; ++k) {
            size_t i = side ? a + k : a - 1 - k;
            if ((side == 0 && k + 1 > a) || i >= n || s[i].group != s[side ? a : a - 1].group)
                break;
            double l;
            if (rc_meas(&l, NULL, geo, &s[i]) != RC_OK)
                return 0;
            r[m] = l - s[i].len_mm;
            x[m++] = (double)i - (double)a;
            sum[side] += r[m - 1];
            sq[side] += r[m - 1] * r[m - 1];
            cnt[side]++;
        }
    if (cnt[0] < 3 || cnt[1] < 3)
        return 0;
    const double m0 = sum[0] / cnt[0], m1 = sum[1] / cnt[1];
    const double ss_step = sq[0] - cnt[0] * m0 * m0 + sq[1] - cnt[1] * m1 * m1;
    const double v = ss_step / (double)(cnt[0] + cnt[1] - 2);
    const double se = sqrt(fmax(v, 0.0) * (1.0 / cnt[0] + 1.0 / cnt[1]));
    double mx = 0.0, mr = 0.0, sxx = 0.0, sxr = 0.0, srr = 0.0;
    for (unsigned k = 0; k < m; ++k) {
        mx += x[k] / m;
        mr += r[k] / m;
    }
    for (unsigned k = 0; k < m; ++k) {
        sxx += (x[k] - mx) * (x[k] - mx);
        sxr += (x[k] - mx) * (r[k] - mr);
        srr += (r[k] - mr) * (r[k] - mr);
    }
    const double ss_ramp = srr - (sxx > 0.0 ? sxr * sxr / sxx : 0.0);
    /* a step the size of the fitted jump, not a slope that a long fit
     * summarised as one (residual = model - L: a jump up in L moves it down) */
    return fabs(m1 - m0) > 5.0 * se && fabs((m0 - m1) - size) < 0.3 * fabs(size) && ss_ramp - ss_step > 4.0 * v;
}

/* 4b. Length jumps in acquisition order: found, removed from the lengths
 * (their offsets fitted on all samples: a nuisance), geometry refitted and
 * cross-validated again. */
static int phase_jumps(run_state *S, rch_diag *d)
{
    rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    char err[256];
    if (S->cfg.no_jumps)
        return 0;
    for (size_t i = 1; i < n; ++i)
        if (out->s[i].t < out->s[i - 1].t)
            return 0; /* not in acquisition order: no change points to look for */
    if (rch_jumps_find(&out->jumps, &out->geo, NULL, out->s, n, NULL, S->c.w, err, sizeof err) != 0 ||
        out->jumps.n_jumps == 0) {
        out->jumps.n_jumps = 0;
        return 0;
    }
    /* A step where the set-up changes is confounded with anything that
     * depends on the set-up (group offsets, wrist-dependent effects): the
     * jumps are taken as a sensor event only when one lies inside a set-up
     * (2 or more samples from its ends) and is a sharp step there. */
    unsigned inside = 0;
    for (unsigned k = 0; k < out->jumps.n_jumps; ++k) {
        size_t a = out->jumps.at[k];
        int near = 0, single = 1;
        for (size_t i = a >= 2 ? a - 2 : 1; i <= a + 1 && i < n; ++i)
            near |= out->s[i].group != out->s[i - 1].group;
        /* Independent poses (no set-ups: every sample its own group around
         * the step) leave nothing set-up dependent to confound a step with:
         * there a jump far above the residual (8 x, rcal calibrate's rule)
         * is a sensor event (issue 23: a 5 mm jump on the ordinary plan was
         * read as time drift). */
        for (size_t i = a >= 3 ? a - 3 : 1; i <= a + 2 && i < n; ++i)
            single &= out->s[i].group != out->s[i - 1].group;
        const int big_alone = near && single && fabs(out->jumps.size_mm[k]) > 8.0 * out->jumps.rms_after_mm;
        inside += big_alone || (!near && sharp_step(&out->jumps.geometry, out->s, n, a, out->jumps.size_mm[k]));
        out->jumps_at_setup_change += (unsigned)(near && !big_alone);
    }
    if (inside == 0) {
        out->jumps_confounded = out->jumps.n_jumps;
        out->jumps.n_jumps = 0;
        return 0;
    }
    const rc_effect *e = &out->jumps.model.effects[out->jumps.model.n_effects - 1];
    for (size_t i = 0; i < n; ++i)
        out->s[i].len_mm -= out->jumps.model.x[e->first + rch_jumps_segment(&out->jumps, out->s[i].t)];
    for (unsigned f = 0; f < S->c.k; ++f) /* the folds' training copies too */
        for (size_t i = 0; i < S->c.n_train[f]; ++i)
            S->c.train[f][i].len_mm -=
                out->jumps.model.x[e->first + rch_jumps_segment(&out->jumps, S->c.train[f][i].t)];
    out->geo = out->jumps.geometry;
    for (unsigned f = 0; f < S->c.k; ++f)
        S->base_folds[f] = out->geo;
    if (cv_run(S->base_folds, S->r0, &S->c) != 0) {
        rch_diag_set(d, "", 0, 0, "a cross-validation fit failed (after removing the length jumps)");
        return -1;
    }
    out->rmse_jumps_mm = rch_rms(S->r0, n);
    if (S->cfg.verbose)
        fprintf(stderr, "diagnose: %u length jumps; geometry held-out RMSE %.4f mm without them\n",
                out->jumps.n_jumps, out->rmse_jumps_mm);
    return 0;
}

/* Whether candidate cd can be tried on the data: 1, or 0 with ca->note set.
 * count: its parameter count when it has a variable one (group offsets). */
static int cand_applicable(const run_state *S, const cdef *cd, rch_diagnose_cand *ca, unsigned *count)
{
    const rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    *count = 0;
    if (cd->kind == RC_EFF_GROUP_OFFSET) {
        if (!groups_usable(out->n_groups, n)) {
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
        len[cnt] = s[i].len_mm;
        e[cnt] = s[i].len_mm - l;
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
        if (per > lmax - lmin)
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
    if (cd->kind == RC_EFF_LENGTH_PERIODIC && periodic_start(full, &S->base, out->s, out->n) != 0) {
        snprintf(ca->note, sizeof ca->note, "not applicable: the lengths span too little for a period");
        return 0;
    }
    if (fit(full, res, &S->c, NULL, out->s, out->n) != 0) {
        snprintf(ca->note, sizeof ca->note, "fit failed");
        return 0;
    }
    const unsigned ra = rank_at(full, full->n_params, out->s, out->n, S->c.w, S->cfg.verbose > 2);
    const unsigned rb = rank_at(full, S->base.n_params, out->s, out->n, S->c.w, 0);
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
    if (cd->kind == RC_EFF_LENGTH_PERIODIC) { /* a drum turn: 10 mm .. the lengths' range */
        double lmin = 1e300, lmax = -1e300;
        for (size_t i = 0; i < out->n; ++i) {
            lmin = out->s[i].len_mm < lmin ? out->s[i].len_mm : lmin;
            lmax = out->s[i].len_mm > lmax ? out->s[i].len_mm : lmax;
        }
        const double per = fabs(full->x[full->effects[full->n_effects - 1].first + 2]);
        if (per < 10.0 || per > lmax - lmin) {
            ca->implausible = 1;
            snprintf(ca->note, sizeof ca->note,
                     "implausible: fitted period %.4g mm (a drum turn within 10 mm .. the lengths' range %.4g mm)",
                     per, lmax - lmin);
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
    if (cv_run(fm, rc_, &S->c) != 0) {
        snprintf(ca->note, sizeof ca->note, "a cross-validation fit failed");
        return -1;
    }
    double sd = 0.0, sd2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double di = S->r0[i] * S->r0[i] - rc_[i] * rc_[i];
        sd += di;
        sd2 += di * di;
    }
    const double mean = sd / (double)n;
    const double var_d = (sd2 - (double)n * mean * mean) / (double)(n - 1);
    ca->tested = 1;
    ca->rmse_cv_mm = rch_rms(rc_, n);
    ca->gain_mm2 = mean;
    ca->gain_se_mm2 = sqrt(var_d > 0.0 ? var_d / (double)n : 0.0);
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
        if (has_effect(&S->base, cd->kind, cd->joint0))
            continue; /* already in the model */
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
        double s1 = 0.0, s2 = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const double di = rk[i] * rk[i] - rb[i] * rb[i];
            s1 += di;
            s2 += di * di;
        }
        const double m1 = s1 / (double)n;
        const double se = sqrt(fmax(s2 - (double)n * m1 * m1, 0.0) / (double)(n - 1) / (double)n);
        if (m1 <= se &&
            (chosen == best || ca->n_params < st->cand[chosen].n_params ||
             (ca->n_params == st->cand[chosen].n_params && ca->gain_mm2 > st->cand[chosen].gain_mm2)))
            chosen = (int)k;
    }
    return chosen;
}

/* Significance (Bonferroni over the tested candidates) and the choice of one
 * step; the chosen candidate becomes the current model. 1 when one was
 * chosen, 0 when the search ends. */
static int step_choose(run_state *S, rch_diagnose_step *st, unsigned n_tested)
{
    rch_diagnose_result *out = S->out;
    int best = -1, second = -1;
    /* Among the significant candidates the simpler cause wins unless the
     * larger one explains clearly more: held-out MSE penalised by the
     * parameters it adds (n ln MSE + p ln n, BIC-like), so 30 set-up offsets
     * do not beat a 2-parameter drift that explains nearly the same. */
    double crit[RCH_DIAGNOSE_MAX_CAND];
    const double nn = (double)out->n;
    for (unsigned k = 0; k < st->n_cand; ++k) {
        rch_diagnose_cand *ca = &st->cand[k];
        if (!ca->tested)
            continue;
        ca->significant = ca->p_value < S->cfg.alpha / n_tested && ca->gain_mm2 > 0.0 && !ca->implausible;
        crit[k] = nn * log(ca->rmse_cv_mm * ca->rmse_cv_mm) + (double)ca->n_ident * log(nn);
        if (!ca->significant)
            continue;
        if (best < 0 || crit[k] < crit[best]) {
            second = best;
            best = (int)k;
        } else if (second < 0 || crit[k] < crit[second]) {
            second = (int)k;
        }
    }
    if (best < 0) {
        snprintf(st->why, sizeof st->why,
                 "no candidate improves the held-out error significantly (one-sided p < %.2g each)",
                 S->cfg.alpha / (n_tested ? n_tested : 1));
        return 0;
    }
    unsigned slot_ci[RCH_DIAGNOSE_MAX_CAND], k = 0;
    for (unsigned ci = 0; ci < N_ALL_CANDS; ++ci)
        if (!has_effect(&S->base, all_cands[ci].kind, all_cands[ci].joint0))
            slot_ci[k++] = ci;
    const int chosen = one_se_rule(S, st, best, slot_ci);
    st->chosen = chosen;
    char cn[40], bn[40]; /* copies: snprintf must not read from the object it writes */
    memcpy(cn, st->cand[chosen].name, sizeof cn);
    memcpy(bn, st->cand[best].name, sizeof bn);
    if (chosen != best)
        snprintf(st->why, sizeof st->why,
                 "%s: significant, and within one standard error of the best (%s) with fewer parameters", cn, bn);
    else if (second >= 0 && crit[second] - crit[best] < 2.0 * log(nn)) {
        char sn[40];
        memcpy(sn, st->cand[second].name, sizeof sn);
        snprintf(st->why, sizeof st->why,
                 "%s, confounded with %s (penalised held-out fit within 2 ln n): both explain the same; an acquisition "
                 "that revisits set-ups in shuffled order would separate them",
                 cn, sn);
    } else
        snprintf(st->why, sizeof st->why, "%s: best significant held-out fit for its parameters (z = %.1f)", cn,
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
static void phase_search(run_state *S)
{
    rch_diagnose_result *out = S->out;
    S->base = out->geo;
    for (unsigned step = 0; step < S->cfg.max_steps; ++step) {
        rch_diagnose_step *st = &out->steps[out->n_steps++];
        memset(st, 0, sizeof *st);
        st->chosen = -1;
        st->rmse_base_mm = rch_rms(S->r0, out->n);
        const unsigned n_tested = step_candidates(S, st, step);
        if (!step_choose(S, st, n_tested))
            break;
    }
    out->final = S->base;
}

/* 6. The final model's held-out residuals, structure tests and verdict. */
static void phase_after(run_state *S)
{
    rch_diagnose_result *out = S->out;
    size_t pos = 0;
    int unexpl = 0;
    memcpy(out->res_after_mm, S->r0, out->n * sizeof *S->r0);
    out->rmse_after_mm = rch_rms(S->r0, out->n);
    structure_tests(out->after, S->r0, out->s, out->n, (const double(*)[V_N])S->var, out->n_groups, S->cfg.alpha);
    out->remaining_why[0] = '\0';
    /* Structure decides, not the size of the residual: residuals with no
     * significant structure against any explanatory variable are noise,
     * whatever their size; their RMS is the noise estimate (the stated
     * resolution and the quantization floor are lower bounds, not the noise). */
    for (unsigned k = 0; k < out->n_tests; ++k)
        if (out->after[k].significant && pos < sizeof out->remaining_why) {
            char pb[16];
            pos += (size_t)snprintf(out->remaining_why + pos, sizeof out->remaining_why - pos,
                                    "%sstructure against %s (p %s%s)", unexpl ? "; " : "", out->after[k].name,
                                    out->after[k].p_value < 1e-300 ? "" : "= ",
                                    rch_plot_fmt_p(pb, sizeof pb, out->after[k].p_value));
            unexpl = 1;
        }
    out->noise_est_mm = out->rmse_after_mm;
    if (!unexpl)
        snprintf(out->remaining_why, sizeof out->remaining_why,
                 "no structure test is significant: the held-out residual is noise, estimated at %.4f mm "
                 "(%.2f x the quantization floor %.4f mm)",
                 out->noise_est_mm, out->noise_est_mm / out->noise_floor_mm, out->noise_floor_mm);
    snprintf(out->remaining, sizeof out->remaining, "%s", unexpl ? "unexplained" : "none");
    if (out->jumps.n_jumps > 0) {
        snprintf(out->effect, sizeof out->effect, "length_jump");
        out->joint = 0;
    } else if (out->n_chosen == 0) {
        snprintf(out->effect, sizeof out->effect, "%s", unexpl ? "unexplained" : "none");
        out->joint = 0;
    }
}

/* 7. Effect parameters (fold jackknife), the effects' size, and the notes on
 * what cable lengths cannot identify. */
static void phase_report(run_state *S)
{
    rch_diagnose_result *out = S->out;
    report_params(out, S->base_folds, S->c.k);
    rc_model z = out->final;
    for (unsigned e = 0; e < z.n_effects; ++e)
        for (unsigned p = 0; p < z.effects[e].count; ++p)
            z.x[z.effects[e].first + p] = 0.0;
    double s2 = 0.0;
    for (size_t i = 0; i < out->n; ++i) {
        double la, lb;
        if (rc_meas(&la, NULL, &out->final, &out->s[i]) == RC_OK && rc_meas(&lb, NULL, &z, &out->s[i]) == RC_OK)
            s2 += (la - lb) * (la - lb);
    }
    out->effect_rms_mm = sqrt(s2 / (double)out->n);
    scale_note(out);
    for (unsigned st = 0; st < out->n_steps; ++st)
        for (unsigned k = 0; k < out->steps[st].n_cand; ++k) {
            const rch_diagnose_cand *ca = &out->steps[st].cand[k];
            if (st == 0 && ca->n_params > 0 && ca->n_ident < ca->n_params && ca->kind != RC_EFF_LENGTH_SCALE &&
                out->n_notes < RCH_DIAGNOSE_MAX_NOTES) {
                char nm[40], nt[160];
                memcpy(nm, ca->name, sizeof nm);
                memcpy(nt, ca->note, sizeof nt);
                snprintf(out->notes[out->n_notes++], sizeof out->notes[0], "%s: %s", nm, nt);
            }
        }
}

int rch_diagnose_run(rch_diagnose_result *out, const rc_sample *samples, size_t n, const rc_model *nominal,
                     const rch_diagnose_cfg *cfg, rch_diag *d)
{
    const double t0 = now_ms();
    run_state S;
    memset(out, 0, sizeof *out);
    memset(&S, 0, sizeof S);
    int rc = phase_setup(&S, out, samples, n, cfg, d);
    if (rc == 0) {
        phase_steps(&S);
        rc = phase_geometry(&S, nominal, d);
    }
    if (rc == 0)
        rc = phase_floor(&S, d);
    if (rc == 0)
        rc = phase_folds(&S, d);
    if (rc == 0)
        rc = phase_cv_geometry(&S, d);
    if (rc == 0)
        rc = phase_jumps(&S, d);
    if (rc == 0) {
        phase_search(&S);
        phase_after(&S);
        phase_report(&S);
    }
    out->time_ms = now_ms() - t0;
    run_free(&S);
    return rc;
}

int rch_diagnose_file(rch_diagnose_result *out, const char *data_path, const char *robot_path,
                      const rch_diagnose_cfg *cfg, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    rch_robot robot;
    rch_data data;
    if (rch_robot_load(&robot, robot_path, d) != 0 || rch_data_load_limited(&data, data_path, 0, &robot.model, d) != 0)
        return -1;
    rch_diagnose_cfg c = *cfg;
    c.groups_given = data.has_group;
    c.have_encoder = robot.has_encoder;
    rch_dequant_result dq;
    memset(&dq, 0, sizeof dq);
    if (cfg->dequantize) {
        /* set-ups from the wrist angles as recorded (on the display grid), before they are recovered */
        if (!c.groups_given) {
            double *q = calloc(data.n * 3 + 1, sizeof *q);
            double step = 0.0;
            for (size_t i = 0; q && i < data.n; ++i)
                for (unsigned j = 0; j < 3; ++j)
                    q[i * 3 + j] = data.s[i].q_rad[3 + j] / DEG;
            if (q)
                step = rch_dequant_detect_step(q, data.n * 3);
            free(q);
            rch_groups_by_wrist(data.s, data.n, step, NULL);
            c.groups_given = 1;
        }
        uint8_t *bad = data.xyz ? calloc(data.n + 1, 1) : NULL;
        if (!bad) {
            rch_diag_set(d, data_path, 0, 0, "--dequantize-joints needs the x, y, z columns");
            rch_data_free(&data);
            return -1;
        }
        rch_dequant(&dq, bad, data.s, data.n, (const double(*)[3])data.xyz, &robot.nominal, 0.0);
        size_t k = 0;
        for (size_t i = 0; i < data.n; ++i)
            if (!bad[i]) {
                data.line[k] = data.line[i];
                data.s[k++] = data.s[i];
            }
        data.n = k;
        free(bad);
        if (c.q_step_deg == 0.0)
            c.q_step_deg = -1.0; /* the joints are no longer on the display grid */
    }
    if (data.n > 100000)
        fprintf(stderr, "rcal diagnose: %zu samples, %u folds: this takes minutes\n", data.n, c.folds ? c.folds : 5u);
    const int rc = rch_diagnose_run(out, data.s, data.n, &robot.nominal, &c, d);
    out->dequant_corrected = dq.n_corrected;
    out->dequant_refused = dq.n_refused;
    for (unsigned k = 0; rc == 0 && k < out->jumps.n_jumps; ++k)
        for (size_t i = 0; i < data.n; ++i)
            if (data.s[i].t == out->jumps.at_t[k]) {
                out->jump_line[k] = data.line[i];
                break;
            }
    rch_data_free(&data);
    return rc;
}

void rch_diagnose_free(rch_diagnose_result *r)
{
    if (!r)
        return;
    free(r->s);
    free(r->res_before_mm);
    free(r->res_after_mm);
    free(r->floor_mm);
    r->s = NULL;
    r->res_before_mm = r->res_after_mm = r->floor_mm = NULL;
}

/* ---------------------------------------------------------------- output */

static void print_tests(FILE *f, const rch_diagnose_test *t, unsigned n)
{
    fprintf(f, "  %-28s %5s %6s %10s %9s %7s\n", "variable", "dof1", "dof2", "F", "p", "R^2");
    char pb[16];
    for (unsigned k = 0; k < n; ++k)
        fprintf(f, "  %-28s %5u %6u %10.2f %9s %6.1f%% %s\n", t[k].name, t[k].dof1, t[k].dof2, t[k].f_stat,
                rch_plot_fmt_p(pb, sizeof pb, t[k].p_value), 100.0 * t[k].r2, t[k].significant ? "STRUCTURE" : "");
}

int rch_diagnose_print(FILE *f, const rch_diagnose_result *r)
{
    fprintf(f, "rcal diagnose: %zu samples, %u set-up groups, %u-fold cross-validation (random within groups)\n",
            r->n, r->n_groups, r->folds);
    if (r->n_flicker)
        fprintf(f, "  %u sample(s) kept in their group although a wrist reading moved by one display step\n",
                r->n_flicker);
    fprintf(f, "\nNoise floor: %.4f mm rms  (joint display step %.3g deg through the Jacobian: %.4f mm; "
               "length step %.3g mm%s: %.4f mm)\n",
            r->noise_floor_mm, r->q_step_deg, r->floor_joints_mm, r->len_step_mm,
            r->len_noise_mm > 0.0 ? " + noise" : "", r->floor_len_mm);
    fprintf(f, "Geometric model (27 parameters, rank %u of %u): training RMSE %.4f mm, held-out RMSE %.4f mm "
               "= %.2f x floor\n",
            r->geo_rank, r->geo_free, r->train_rmse_geo_mm, r->rmse_before_mm,
            r->rmse_before_mm / r->noise_floor_mm);
    fprintf(f, "\nStructure of the held-out residuals (geometry only; F tests, Bonferroni over %u tests):\n",
            r->n_tests);
    print_tests(f, r->before, r->n_tests);
    for (unsigned s = 0; s < r->n_steps; ++s) {
        const rch_diagnose_step *st = &r->steps[s];
        fprintf(f, "\nStep %u: candidates fitted jointly with the geometry (model held-out RMSE %.4f mm)\n", s + 1,
                st->rmse_base_mm);
        fprintf(f, "  %-22s %6s %6s %10s %11s %7s %9s  %s\n", "effect", "params", "ident", "held-out",
                "gain mm^2", "z", "p", "");
        for (unsigned k = 0; k < st->n_cand; ++k) {
            const rch_diagnose_cand *ca = &st->cand[k];
            char pb[16];
            if (ca->tested)
                fprintf(f, "  %-22s %6u %6u %10.4f %11.5f %7.2f %9s  %s%s%s\n", ca->name, ca->n_params,
                        ca->n_ident, ca->rmse_cv_mm, ca->gain_mm2, ca->z, rch_plot_fmt_p(pb, sizeof pb, ca->p_value),
                        (int)k == st->chosen ? "<- CHOSEN" : ca->significant ? "significant" : "",
                        ca->note[0] ? "  " : "", ca->note);
            else
                fprintf(f, "  %-22s %6u %6u %10s %11s %7s %9s  %s\n", ca->name, ca->n_params, ca->n_ident, "-", "-",
                        "-", "-", ca->note);
        }
        fprintf(f, "  -> %s\n", st->chosen >= 0 ? st->why : st->why[0] ? st->why : "stop");
    }
    fprintf(f, "\nVerdict: %s", r->effect);
    if (r->joint)
        fprintf(f, " (joint %u)", r->joint);
    fprintf(f, "\n");
    if (r->dequant_corrected)
        fprintf(f, "Joints recovered from x, y, z: %zu rows corrected, %zu refused as inconsistent.\n",
                r->dequant_corrected, r->dequant_refused);
    if (r->jumps.n_jumps > 0) {
        fprintf(f,
                "Length jumps in acquisition order (the lengths shift at a row and stay shifted: a display "
                "re-zeroed or counts lost; removed as a nuisance before the search below):\n");
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k)
        {
            char where[48] = "";
            if (r->jump_line[k])
                snprintf(where, sizeof where, "line %u, ", r->jump_line[k]);
            fprintf(f, "  at %ssample %zu (1-based, in file order; t %.4f): %+.4f +- %.4f mm\n", where,
                    r->jumps.at[k] + 1, r->jumps.at_t[k], r->jumps.size_mm[k], r->jumps.se_mm[k]);
        }
        fprintf(f, "  geometry held-out RMSE %.4f mm with the jumps in the data, %.4f mm with them removed\n",
                r->rmse_before_mm, r->rmse_jumps_mm);
        if (r->jumps_at_setup_change)
            fprintf(f,
                    "  %u of them fall where the set-up changes: there a jump is confounded with anything that depends "
                    "on the set-up; revisiting set-ups in shuffled order would separate them\n",
                    r->jumps_at_setup_change);
    } else if (r->jumps_confounded) {
        fprintf(f,
                "Steps in acquisition order (%u) were found only where the set-up changes: confounded with set-up "
                "dependent effects (left to the candidates below); revisiting set-ups in shuffled order would "
                "separate them.\n",
                r->jumps_confounded);
    }
    if (r->n_chosen > 0) {
        fprintf(f, "Effects added, in order:");
        for (unsigned s = 0; s < r->n_steps; ++s)
            if (r->steps[s].chosen >= 0)
                fprintf(f, " %s", r->steps[s].cand[r->steps[s].chosen].name);
        fprintf(f, "\nFitted (all samples; +- fold-jackknife standard error):\n");
        for (unsigned k = 0; k < r->n_params; ++k)
            fprintf(f, "  %-28s %12.5f +- %.5f %s\n", r->params[k].name, r->params[k].value, r->params[k].se,
                    r->params[k].unit);
        fprintf(f, "  contribution to the cable length: %.4f mm rms\n", r->effect_rms_mm);
    }
    fprintf(f, "\nHeld-out RMSE: before %.4f mm (%.2f x floor) -> after %.4f mm (%.2f x floor); floor %.4f mm\n",
            r->rmse_before_mm, r->rmse_before_mm / r->noise_floor_mm, r->rmse_after_mm,
            r->rmse_after_mm / r->noise_floor_mm, r->noise_floor_mm);
    fprintf(f, "Remaining: %s%s%s\n", r->remaining, r->remaining_why[0] ? ": " : "", r->remaining_why);
    if (r->n_chosen > 0) {
        fprintf(f, "\nStructure of the held-out residuals after:\n");
        print_tests(f, r->after, r->n_tests);
    }
    fprintf(f, "\nWhat cable lengths cannot identify:\n");
    for (unsigned k = 0; k < r->n_notes; ++k)
        fprintf(f, "  - %s\n", r->notes[k]);
    fprintf(f, "\nTime: %.0f ms\n", r->time_ms);
    return ferror(f) ? -1 : 0;
}

static void json_num(rch_jw *w, const char *key, double v)
{
    rch_jw_numf(w, key, v, "%.6g");
}

static void json_joint(rch_jw *w, unsigned joint)
{
    if (joint)
        rch_jw_uint(w, "joint", joint);
    else
        rch_jw_null(w, "joint");
}

static void json_tests(rch_jw *w, const char *key, const rch_diagnose_test *t, unsigned n)
{
    rch_jw_arr(w, key);
    for (unsigned k = 0; k < n; ++k) {
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "variable", t[k].name);
        rch_jw_uint(w, "dof1", t[k].dof1);
        rch_jw_uint(w, "dof2", t[k].dof2);
        json_num(w, "f", t[k].f_stat);
        json_num(w, "p", t[k].p_value);
        json_num(w, "r2", t[k].r2);
        rch_jw_bool(w, "significant", t[k].significant);
        rch_jw_end(w);
    }
    rch_jw_end(w);
}

static void json_cands(rch_jw *w, const rch_diagnose_result *r)
{
    rch_jw_arr(w, "candidates");
    for (unsigned s = 0; s < r->n_steps; ++s)
        for (unsigned k = 0; k < r->steps[s].n_cand; ++k) {
            const rch_diagnose_cand *ca = &r->steps[s].cand[k];
            rch_jw_obj(w, NULL);
            rch_jw_uint(w, "step", s + 1);
            rch_jw_str(w, "effect", rc_effect_name(ca->kind));
            json_joint(w, ca->joint);
            rch_jw_uint(w, "params", ca->n_params);
            rch_jw_uint(w, "identifiable", ca->n_ident);
            rch_jw_bool(w, "tested", ca->tested);
            if (ca->tested) {
                json_num(w, "rmse_cv_mm", ca->rmse_cv_mm);
                json_num(w, "gain_mm2", ca->gain_mm2);
                json_num(w, "gain_se_mm2", ca->gain_se_mm2);
                json_num(w, "z", ca->z);
                json_num(w, "p", ca->p_value);
            }
            rch_jw_bool(w, "significant", ca->significant);
            rch_jw_bool(w, "chosen", (int)k == r->steps[s].chosen);
            rch_jw_str(w, "note", ca->note);
            rch_jw_end(w);
        }
    rch_jw_end(w);
}

int rch_diagnose_json(FILE *f, const rch_diagnose_result *r, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, f, 0, "rcal-diagnose/1", argc, argv);
    rch_jw_str(&w, "effect", r->effect);
    json_joint(&w, r->joint);
    json_num(&w, "rmse_before_mm", r->rmse_before_mm);
    json_num(&w, "rmse_after_mm", r->rmse_after_mm);
    json_num(&w, "noise_floor_mm", r->noise_floor_mm);
    json_num(&w, "noise_floor_joints_mm", r->floor_joints_mm);
    json_num(&w, "noise_floor_length_mm", r->floor_len_mm);
    json_num(&w, "q_step_deg", r->q_step_deg);
    json_num(&w, "len_step_mm", r->len_step_mm);
    json_num(&w, "train_rmse_geometry_mm", r->train_rmse_geo_mm);
    rch_jw_uint(&w, "n", r->n);
    rch_jw_uint(&w, "groups", r->n_groups);
    rch_jw_uint(&w, "wrist_flicker_samples", r->n_flicker);
    rch_jw_uint(&w, "folds", r->folds);
    rch_jw_str(&w, "remaining", r->remaining);
    rch_jw_str(&w, "remaining_why", r->remaining_why);
    json_num(&w, "noise_est_mm", r->noise_est_mm);
    rch_jw_arr(&w, "length_jumps");
    for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_uint(&w, "sample", r->jumps.at[k]);
        if (r->jump_line[k])
            rch_jw_uint(&w, "line", r->jump_line[k]);
        else
            rch_jw_null(&w, "line");
        json_num(&w, "t", r->jumps.at_t[k]);
        json_num(&w, "size_mm", r->jumps.size_mm[k]);
        json_num(&w, "se_mm", r->jumps.se_mm[k]);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    json_num(&w, "rmse_jumps_removed_mm", r->jumps.n_jumps ? r->rmse_jumps_mm : NAN);
    rch_jw_arr(&w, "sequence");
    for (unsigned s = 0; s < r->n_steps; ++s)
        if (r->steps[s].chosen >= 0)
            rch_jw_str(&w, NULL, r->steps[s].cand[r->steps[s].chosen].name);
    rch_jw_end(&w);
    json_cands(&w, r);
    rch_jw_arr(&w, "params");
    for (unsigned k = 0; k < r->n_params; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "name", r->params[k].name);
        json_num(&w, "value", r->params[k].value);
        json_num(&w, "se", r->params[k].se);
        rch_jw_str(&w, "unit", r->params[k].unit);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    json_num(&w, "effect_rms_mm", r->effect_rms_mm);
    json_tests(&w, "structure_before", r->before, r->n_tests);
    json_tests(&w, "structure_after", r->after, r->n_tests);
    rch_jw_arr(&w, "not_identifiable");
    for (unsigned k = 0; k < r->n_notes; ++k)
        rch_jw_str(&w, NULL, r->notes[k]);
    rch_jw_end(&w);
    json_num(&w, "time_ms", r->time_ms);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* The chosen effects as `rcal calibrate --effects` names them, into list. */
static void chosen_effects(char *list, size_t len, const rch_diagnose_result *r)
{
    size_t pos = 0;
    list[0] = '\0';
    for (unsigned e = 0; e < r->final.n_effects && pos < len; ++e) {
        const rc_effect *ef = &r->final.effects[e];
        const rc_effect_desc *ds = rc_effect_describe(ef->kind);
        if (!ds || ds->nuisance || !ds->user || ef->kind == RC_EFF_TOOL_OFFSET)
            continue;
        if (ds->arg == RC_EFF_ARG_JOINT)
            pos += (size_t)snprintf(list + pos, len - pos, "%s%s:%u", pos ? "," : "", ds->name, ef->joint + 1u);
        else if (ds->arg == RC_EFF_ARG_PERIOD)
            pos += (size_t)snprintf(list + pos, len - pos, "%s%s:%.6g", pos ? "," : "", ds->name,
                                    fabs(r->final.x[ef->first + 2]));
        else
            pos += (size_t)snprintf(list + pos, len - pos, "%s%s", pos ? "," : "", ds->name);
    }
}

int rch_diagnose_next(char *buf, size_t len, const rch_diagnose_result *r, const char *data_path,
                      const char *robot_path)
{
    char list[512];
    chosen_effects(list, sizeof list, r);
    const char *argv[12];
    int n = 0;
    argv[n++] = "rcal";
    argv[n++] = "calibrate";
    argv[n++] = "--data";
    argv[n++] = data_path;
    if (robot_path) {
        argv[n++] = "--robot";
        argv[n++] = robot_path;
    }
    if (strcmp(r->effect, "length_jump") == 0 || r->jumps.n_jumps)
        argv[n++] = "--jumps";
    if (r->dequant_corrected)
        argv[n++] = "--dequantize-joints";
    if (list[0]) {
        argv[n++] = "--effects";
        argv[n++] = list;
    }
    argv[n++] = "--out";
    argv[n++] = "model.json";
    rch_shell_join(buf, len, n, argv);
    return strstr(buf, " ... (cut)") ? -1 : 0;
}

int rch_diagnose_save_model(const rch_diagnose_result *r, const char *data_path, const char *robot_path,
                            const char *path, const char *const *inputs, size_t n_inputs, rch_diag *d)
{
    (void)inputs;
    (void)n_inputs; /* rch_calib_save_model refuses the data and the robot file itself */
    char list[512];
    chosen_effects(list, sizeof list, r);
    static rch_calib_result cr;
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.data_path = data_path;
    cfg.robot_path = robot_path;
    cfg.test_fraction = 0.0;
    cfg.effects = list[0] ? list : NULL;
    cfg.jumps = strcmp(r->effect, "length_jump") == 0 || r->jumps.n_jumps > 0;
    cfg.dequantize = r->dequant_corrected > 0;
    const int rc = rch_calib_run(&cr, &cfg, d);
    if (rc != 0)
        return -1;
    if (!cr.after_ok) {
        rch_diag_set(d, path, 0, 0, "the model with the diagnosed effects (%s) did not fit: not written",
                     list[0] ? list : "none");
        return -1;
    }
    return rch_calib_save_model(&cr, path, d);
}

int rch_diagnose_resid(rch_resid_table *t, const rch_diagnose_result *r, const unsigned *line)
{
    char chain[48] = "";
    size_t len = 0;
    for (unsigned k = 0; k < r->n_steps; ++k) {
        const int c = r->steps[k].chosen;
        if (c >= 0 && len < sizeof chain)
            len += (size_t)snprintf(chain + len, sizeof chain - len, "%s%s", len ? "+" : "", r->steps[k].cand[c].name);
    }
    (void)rch_resid_add_step(t, "geometry_cv");
    if (r->n_chosen > 0) {
        char name[64];
        snprintf(name, sizeof name, "%s_cv", chain);
        (void)rch_resid_add_step(t, name);
    }
    for (size_t i = 0; i < r->n; ++i) {
        rch_resid_row row;
        memset(&row, 0, sizeof row);
        row.line = line[i];
        row.set = RCH_RESID_TRAIN;
        row.s = r->s[i];
        if (rc_meas(&row.predicted_mm, NULL, &r->final, &r->s[i]) != RC_OK)
            row.predicted_mm = NAN;
        for (unsigned c = 0; c < RCH_RESID_MAX_STEPS; ++c)
            row.after_mm[c] = NAN;
        row.after_mm[0] = r->res_before_mm ? -r->res_before_mm[i] : NAN; /* they are model - measured */
        if (r->n_chosen > 0)
            row.after_mm[1] = r->res_after_mm ? -r->res_after_mm[i] : NAN;
        if (rch_resid_add(t, &row) != 0)
            return -1;
    }
    return 0;
}
