/* SPDX-License-Identifier: MIT */
/* rch_diagnose_tests.c - the structure tests of `rcal diagnose`: F tests of
 * held-out residuals against explanatory variables (intercept included),
 * the groups' one-way ANOVA, Bonferroni over the tests. See rch_diagnose.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose_int.h"
#include "rch_stats.h"
#include "rch_sensors.h"

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

unsigned rch_dg_groups_usable(unsigned n_groups, size_t n) { return n_groups >= 2 && (size_t)n_groups * 3 <= n; }

/* All structure tests of residuals r (n). Returns the number of tests. */
unsigned rch_dg_structure_tests(rch_diagnose_test *out, const double *r, const rc_sample *s, size_t n,
                                const double (*var)[V_N], unsigned n_groups, double alpha)
{
    const unsigned n_tests = 12 + rch_dg_groups_usable(n_groups, n);
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
    if (rch_dg_groups_usable(n_groups, n))
        test_groups(&out[k++], r, s, n, n_groups, a_each);
    free(X);
    return k;
}

/* The tests of one subset of the samples (sel: 1 = in it): the structure
 * tests with a Bonferroni share a_each, names prefixed, plus an ANOVA over
 * the label each sample's key gives (outlet, coordinate, target) when the
 * subset holds two or more. Returns the tests written. */
typedef unsigned (*sample_key)(const rc_sample *s);
static unsigned key_outlet(const rc_sample *s) { return s->outlet; }
static unsigned key_coordinate(const rc_sample *s) { return (unsigned)(s->sensor - RC_SENSOR_TRACKER_X); }
static unsigned key_target(const rc_sample *s) { return s->target; }

static unsigned anova_by(rch_diagnose_test *t, const char *name, const double *r, const rc_sample *s, size_t n,
                         sample_key key, double a_each)
{
    unsigned mx = 0;
    for (size_t i = 0; i < n; ++i)
        mx = key(&s[i]) > mx ? key(&s[i]) : mx;
    if (mx == 0)
        return 0;
    rc_sample *c = malloc(n * sizeof *c);
    if (!c)
        return 0;
    for (size_t i = 0; i < n; ++i) {
        c[i] = s[i];
        c[i].group = (uint16_t)key(&s[i]);
    }
    test_groups(t, r, c, n, mx + 1, a_each);
    snprintf(t->name, sizeof t->name, "%s", name);
    free(c);
    return 1;
}

unsigned rch_dg_sensor_class(const rc_sample *s)
{
    return s->sensor >= RC_SENSOR_TRACKER_X && s->sensor <= RC_SENSOR_TRACKER_Z ? (unsigned)RC_SENSOR_TRACKER_X
                                                                                : s->sensor;
}

unsigned rch_dg_sensor_tests(rch_diagnose_test *out, const double *r, const rc_sample *s, size_t n,
                             const double (*var)[V_N], unsigned n_groups, double alpha)
{
    size_t nk[RC_SENSOR_COUNT_] = {0};     /* rows of each class */
    unsigned labels[RC_SENSOR_COUNT_] = {0}; /* the outlets (cable), the targets, another sensor's labels */
    for (size_t i = 0; i < n; ++i) {
        const unsigned c = rch_dg_sensor_class(&s[i]) % RC_SENSOR_COUNT_;
        const unsigned l = c == RC_SENSOR_LENGTH ? s[i].outlet : s[i].target;
        ++nk[c];
        if (l + 1u > labels[c])
            labels[c] = l + 1u;
    }
    if (nk[RC_SENSOR_LENGTH] == n && labels[RC_SENSOR_LENGTH] <= 1) /* one outlet's lengths: as they always were */
        return rch_dg_structure_tests(out, r, s, n, var, n_groups, alpha);
    double *rs = malloc((n ? n : 1) * sizeof *rs);
    rc_sample *ss = malloc((n ? n : 1) * sizeof *ss);
    double (*vs)[V_N] = malloc((n ? n : 1) * sizeof *vs);
    unsigned k = 0;
    if (!rs || !ss || !vs)
        goto done;
    /* Bonferroni over every test of every class: each one's own count of structure tests (12 or 13; another
     * sensor of the table (rch_sensors.h) without the two against a place) and its ANOVAs */
    const unsigned per = 12u + rch_dg_groups_usable(n_groups, n);
    unsigned total = 0;
    for (unsigned c = 0; c < RC_SENSOR_COUNT_; ++c)
        if (nk[c] > 0)
            total += c == RC_SENSOR_LENGTH      ? per + (labels[c] > 1)
                     : c == RC_SENSOR_TRACKER_X ? per + 1u + (labels[c] > 1)
                                                : per - 2u + (labels[c] > 1);
    const double a_each = alpha / (double)total;
    for (unsigned cls = 0; cls < RC_SENSOR_COUNT_; ++cls) {
        if (nk[cls] == 0)
            continue;
        const int tracker = cls != RC_SENSOR_LENGTH; /* not the cable: no outlet, a target or a label */
        size_t m = 0;
        for (size_t i = 0; i < n; ++i)
            if (rch_dg_sensor_class(&s[i]) == cls) {
                rs[m] = r[i];
                ss[m] = s[i];
                memcpy(vs[m], var[i], sizeof vs[m]);
                ++m;
            }
        unsigned g = 0; /* the subset's groups, renumbered densely */
        for (size_t i = 0; i < m; ++i)
            g = ss[i].group + 1u > g ? ss[i].group + 1u : g;
        const unsigned k0 = k;
        k += rch_dg_structure_tests(out + k, rs, ss, m, (const double(*)[V_N])vs, g, a_each * (double)per);
        /* another sensor of the table (rch_sensors.h): its name; it has no distance or direction from a place */
        const rch_sensor_desc *sd = tracker ? rch_sensor_of_kind(cls) : NULL;
        unsigned kept = k0;
        for (unsigned j = k0; j < k; ++j) { /* names say the sensor; the cable's "length" is the tracker's distance */
            char nm[40];
            const char *base = out[j].name;
            const int place = strcmp(base, "cable length") == 0 || strcmp(base, "cable direction") == 0;
            if (sd && place)
                continue; /* dropped */
            if (tracker && strcmp(base, "cable length") == 0)
                base = "distance from the tracker";
            else if (tracker && strcmp(base, "cable direction") == 0)
                base = "direction from the tracker";
            snprintf(nm, sizeof nm, "%s: %.30s", sd ? sd->name : tracker ? "tracker" : "cable", base);
            out[kept] = out[j];
            memcpy(out[kept++].name, nm, sizeof nm);
        }
        k = kept;
        if (!tracker && labels[cls] > 1)
            k += anova_by(&out[k], "cable: outlet (ANOVA)", rs, ss, m, key_outlet, a_each);
        if (tracker && !sd) {
            k += anova_by(&out[k], "tracker: coordinate x, y, z (ANOVA)", rs, ss, m, key_coordinate, a_each);
            if (labels[cls] > 1)
                k += anova_by(&out[k], "tracker: target (ANOVA)", rs, ss, m, key_target, a_each);
        } else if (sd && labels[cls] > 1) { /* its label: a plate's own offset the model lacks, one plate misread */
            char nm[40];
            snprintf(nm, sizeof nm, "%s: %s (ANOVA)", sd->name, sd->label);
            k += anova_by(&out[k], nm, rs, ss, m, key_target, a_each);
        }
    }
done:
    free(rs);
    free(ss);
    free(vs);
    return k;
}
