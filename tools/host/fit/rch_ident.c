/* SPDX-License-Identifier: MIT */
#include "rch_ident.h"

#include "rc_ident.h"
#include "rch_jac.h"
#include "rch_positions.h"
#include "rch_sensors.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The problem analysed: the parameters of m the data's sensors see (idx,
 * nf: what only an absent sensor sees, rch_pos_fix_unseen, is not part of
 * it) and the data in words ("cable lengths", "plate touches and tracker
 * positions") for the explanations. */
typedef struct prob {
    const rc_model *m;
    uint16_t idx[RC_MAX_PARAMS];
    unsigned nf;
    char words[160];
} prob;

/* Column of the parameter called name; -1 when none is (or it is not in the problem). */
static int param_index(const prob *p, const char *name)
{
    char buf[64];
    for (unsigned k = 0; k < p->nf; ++k)
        if (strcmp(rc_param_name(buf, sizeof buf, p->m, p->idx[k]), name) == 0)
            return (int)k;
    return -1;
}

/* Component of v (nf) on the parameter called name; 0 when none is. */
static double comp(const double *v, const prob *p, const char *name)
{
    const int k = param_index(p, name);
    return k >= 0 ? v[k] : 0.0;
}

/* Append w to the words of p (" and " between). */
static void add_words(prob *p, const char *w)
{
    const size_t len = strlen(p->words);
    snprintf(p->words + len, sizeof p->words - len, "%s%s", len ? " and " : "", w);
}

/* p from m and the samples s (n). */
static void make_prob(prob *p, const rc_model *m, const rc_sample *s, size_t n)
{
    uint8_t fixed[RC_MAX_PARAMS] = {0};
    memset(p, 0, sizeof *p);
    p->m = m;
    rch_pos_fix_unseen(fixed, m, s, n);
    for (unsigned k = 0; k < m->n_params; ++k)
        if (!fixed[k])
            p->idx[p->nf++] = (uint16_t)k;
    /* the data in words: lengths, the tracker's, then the table's sensors, by their descriptors */
    uint8_t kinds[RC_SENSOR_COUNT_] = {0};
    for (size_t i = 0; i < n; ++i)
        if (s[i].sensor < RC_SENSOR_COUNT_)
            kinds[s[i].sensor] = 1;
    if (kinds[RC_SENSOR_LENGTH])
        add_words(p, "cable lengths");
    if (kinds[RC_SENSOR_TRACKER_X] || kinds[RC_SENSOR_TRACKER_Y] || kinds[RC_SENSOR_TRACKER_Z])
        add_words(p, "tracker positions");
    for (unsigned k = 0; k < RC_SENSOR_COUNT_; ++k) {
        const rch_sensor_desc *sd = rch_sensor_of_kind(k);
        if (kinds[k] && sd)
            add_words(p, sd->words);
    }
}

/* SVD of the column-scaled identification Jacobian of p over the samples (n):
 * sv (np = p->nf) descending (zero beyond n), vt (np x np) row k = direction k;
 * Js (n x np, row-major), when not NULL, gets the scaled Jacobian. */
static int scaled_svd(double *sv, double *vt, double *Js, const prob *p, const rc_sample *s, size_t n)
{
    const unsigned np = p->nf;
    rch_jac jac;
    char err[160];
    double *J, *sup = malloc(np * sizeof *sup);
    int rc = -1;
    memset(&jac, 0, sizeof jac);
    if (!sup || rch_jac_eval(&jac, p->m, p->idx, np, s, n, err, sizeof err) != 0) /* the Jacobian at the solution */
        goto done;
    J = jac.J;
    rc_ident_scale(sup, jac.norm2, np, 1); /* the one column-scaling rule */
    for (unsigned k = 0; k < np; ++k)
        for (size_t i = 0; i < n; ++i)
            J[i * np + k] = sup[k] > 0.0 ? J[i * np + k] / sup[k] : 0.0;
    if (Js)
        memcpy(Js, J, n * np * sizeof *J);
    if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'A', (lapack_int)n, (lapack_int)np, J, (lapack_int)np, sv, NULL, 1, vt,
                       (lapack_int)np, sup) != 0)
        goto done;
    for (unsigned k = np < n ? np : (unsigned)n; k < np; ++k)
        sv[k] = 0.0;
    rc = 0;
done:
    rch_jac_free(&jac);
    free(sup);
    return rc;
}

/* The known causes of unseen directions, in one table: each a set of
 * parameters and why the data cannot separate them ("{data}": the data's
 * sensors in words). A direction of the SVD
 * gets the first reason it lies on (dir_share of its squared length: where
 * several null directions share one singular value the SVD mixes them, and
 * a mix gets no reason rather than a wrong one); the sets with is_set are
 * also tested on their own columns (find_combos), smallest first. */
static const struct {
    const char *params[5];
    double dir_share;
    int is_set;
    const char *why;
} known_sets[] = {
    {{"alpha6"}, RCH_IDENT_WHY_SHARE, 1,
     "alpha6 turns the flange about its own x axis after the last translation: it never moves the flange point, so "
     "{data} cannot see it"},
    {{"theta6"}, RCH_IDENT_WHY_SHARE, 1,
     "theta6 only moves the measured point through a6 (zero nominally): the tool orientation about axis 6 is "
     "invisible to a point measurement"},
    {{"d1", "ez"}, RCH_IDENT_WHY_SHARE, 1,
     "moving the robot base up is the same as moving the encoder down: only their difference is measured"},
    {{"d2", "d3"}, RCH_IDENT_WHY_SHARE, 1,
     "joints 2 and 3 are parallel: d2 and d3 shift the arm along the same axis, only their sum counts"},
    {{"d6", "tool_offset.z"}, RCH_IDENT_WHY_SHARE, 1,
     "d6 and the cable attachment's z both move the measured point along the flange axis: only their sum is seen"},
    {{"a6", "tool_offset.x"}, RCH_IDENT_WHY_SHARE, 1,
     "a6 and the cable attachment's x both move the measured point along the flange's x axis: only their sum is "
     "seen"},
    {{"alpha6", "theta6"}, RCH_IDENT_WHY_SHARE, 1,
     "alpha6 and theta6 turn the flange about its own axes without moving the flange point while a6 is zero: "
     "{data} cannot see them"},
    {{"theta1", "ex", "ey"}, RCH_IDENT_WHY_SHARE, 1,
     "turning the whole robot about its base axis is the same as turning the encoder around it: lengths do not fix "
     "the base heading"},
    {{"alpha6", "tool_offset.y", "tool_offset.z"}, RCH_IDENT_WHY_SHARE, 1,
     "turning the flange about its x axis moves the cable attachment as a change of its y and z does"},
    {{"theta6", "tool_offset.x", "tool_offset.y"}, RCH_IDENT_WHY_SHARE, 1,
     "turning the flange about its axis moves the cable attachment as a change of its x and y does"},
    /* these trade against many parameters at once: named when they lead a direction */
    {{"length_scale"}, 0.5, 0,
     "an encoder scale error looks like a uniformly larger robot: separate them with one reference length (a gauge "
     "bar or a laser tracker distance)"},
    {{"length_offset"}, 0.5, 0, "a constant cable offset trades against the encoder position and the link lengths"},
};
#define N_KNOWN (sizeof known_sets / sizeof known_sets[0])

/* The reason of known set k into out (len): its words, "{data}" replaced by the data's (pr->words). */
static void why_of(char *out, size_t len, unsigned k, const prob *pr)
{
    const char *w = known_sets[k].why, *at = strstr(w, "{data}");
    if (at)
        snprintf(out, len, "%.*s%s%s", (int)(at - w), w, pr->words, at + 6);
    else
        snprintf(out, len, "%s", w);
}

/* Are all the parameters of known set k in the problem? */
static int set_present(unsigned k, const prob *pr)
{
    for (unsigned a = 0; a < 5 && known_sets[k].params[a]; ++a)
        if (param_index(pr, known_sets[k].params[a]) < 0)
            return 0;
    return 1;
}

static void explain(rch_ident_dir *d, const double *v, const prob *pr)
{
    d->why[0] = '\0';
    for (unsigned p = 0; p < N_KNOWN; ++p) {
        if (!set_present(p, pr)) /* a set naming a parameter the data's sensors do not have says nothing here */
            continue;
        double s2 = 0.0; /* the squared length of v on the set's parameters */
        for (unsigned k = 0; k < 5 && known_sets[p].params[k]; ++k) {
            const double c = comp(v, pr, known_sets[p].params[k]);
            s2 += c * c;
        }
        if (s2 >= known_sets[p].dir_share) {
            why_of(d->why, sizeof d->why, p, pr);
            return;
        }
    }
}

/* "+0.71 d2 -0.71 d3": the (at most five) components of v (np) of at least
 * 0.1, largest first (as printed, to 2 decimals; equal ones in parameter
 * order), the sign chosen so that the first is positive (a singular
 * vector's sign is arbitrary: the same direction prints the same), then
 * the plain-words reason. */
static void describe(rch_ident_dir *d, const double *v, const prob *pr)
{
    const unsigned np = pr->nf;
    size_t pos = 0;
    unsigned order[RC_MAX_PARAMS];
    for (unsigned i = 0; i < np; ++i)
        order[i] = i;
    for (unsigned i = 1; i < np; ++i) { /* by |component| to 2 decimals, descending; stable */
        const unsigned t = order[i];
        const double key = floor(100.0 * fabs(v[t]) + 0.5);
        unsigned j = i;
        while (j > 0 && floor(100.0 * fabs(v[order[j - 1]]) + 0.5) < key) {
            order[j] = order[j - 1];
            --j;
        }
        order[j] = t;
    }
    const double sign = np && v[order[0]] < 0.0 ? -1.0 : 1.0;
    for (unsigned i = 0; i < np && i < 5; ++i) {
        char name[48];
        if (fabs(v[order[i]]) < 0.1)
            break;
        int w = snprintf(d->combo + pos, sizeof d->combo - pos, "%s%+.2f %s", i ? " " : "", sign * v[order[i]],
                         rc_param_name(name, sizeof name, pr->m, pr->idx[order[i]]));
        if (w < 0 || (size_t)w >= sizeof d->combo - pos)
            break;
        pos += (size_t)w;
    }
    explain(d, v, pr);
}

/* out->combos from the scaled Jacobian Js (n x np) and its largest singular
 * value s_max. */
static void find_combos(rch_ident *out, const double *Js, size_t n, double s_max, const prob *pr)
{
    const unsigned np = pr->nf;
    unsigned found[N_KNOWN];
    unsigned n_found = 0;
    double *A = malloc(n * 5 * sizeof *A);
    if (!A || s_max <= 0.0 || n < 5)
        goto done;
    for (unsigned p = 0; p < N_KNOWN; ++p) {
        if (!known_sets[p].is_set)
            continue;
        int idx[5];
        unsigned k = 0, all = 1;
        for (; k < 5 && known_sets[p].params[k]; ++k)
            all &= (idx[k] = param_index(pr, known_sets[p].params[k])) >= 0;
        if (!all || out->n_combos >= RCH_IDENT_MAX_COMBOS)
            continue;
        int holds = 0; /* a smaller set found already inside this one */
        for (unsigned f = 0; f < n_found && !holds; ++f) {
            unsigned in = 1;
            for (unsigned a = 0; a < 5 && known_sets[found[f]].params[a]; ++a) {
                unsigned hit = 0;
                for (unsigned b = 0; b < k; ++b)
                    hit |= strcmp(known_sets[found[f]].params[a], known_sets[p].params[b]) == 0;
                in &= hit;
            }
            holds = (int)in;
        }
        if (holds)
            continue;
        for (size_t i = 0; i < n; ++i)
            for (unsigned b = 0; b < k; ++b)
                A[i * k + b] = Js[i * np + (unsigned)idx[b]];
        double sv[5], super[5];
        if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'N', (lapack_int)n, (lapack_int)k, A, (lapack_int)k, sv, NULL, 1,
                           NULL, 1, super) != 0)
            continue;
        const double rel = sv[k - 1] / s_max;
        if (!(rel < RC_IDENT_WEAK_REL))
            continue;
        rch_ident_combo *c = &out->combos[out->n_combos++];
        size_t pos = 0;
        for (unsigned b = 0; b < k; ++b)
            pos += (size_t)snprintf(c->params + pos, sizeof c->params - pos, "%s%s", b ? " " : "",
                                    known_sets[p].params[b]);
        c->weak = rel >= RC_IDENT_NULL_REL;
        c->sv_rel = rel;
        why_of(c->why, sizeof c->why, p, pr);
        found[n_found++] = p;
    }
done:
    free(A);
}

int rch_ident_compute(rch_ident *out, const rc_model *m, const rc_sample *s, size_t n)
{
    memset(out, 0, sizeof *out);
    if (n == 0 || m->n_params == 0 || m->n_params > RC_MAX_PARAMS)
        return -1;
    prob *pr = malloc(sizeof *pr);
    if (!pr)
        return -1;
    make_prob(pr, m, s, n);
    const unsigned np = pr->nf;
    out->n_params = np;
    if (np == 0) {
        free(pr);
        return -1;
    }
    double *sv = malloc(np * sizeof *sv), *vt = malloc((size_t)np * np * sizeof *vt);
    double *V = malloc((size_t)np * np * sizeof *V), *Js = malloc(n * np * sizeof *Js);
    int rc = -1;
    if (!sv || !vt || !V || !Js || scaled_svd(sv, vt, Js, pr, s, n) != 0)
        goto done;
    find_combos(out, Js, n, sv[0], pr);
    for (unsigned k = 0; k < np; ++k) /* V: direction k in column k */
        for (unsigned i = 0; i < np; ++i)
            V[(size_t)i * np + k] = vt[(size_t)k * np + i];
    /* the thresholds, classes and figures: rc_ident, the one definition */
    rc_ident *id = &out->core;
    if (rc_ident_classify(id, sv, V, np, n) != RC_OK)
        goto done;
    memcpy(out->sv_rel, id->sv_rel, sizeof out->sv_rel);
    out->rank = id->rank;
    out->n_weak = id->n_weak;
    out->cond = id->cond;
    out->observability = id->observability;
    /* describe the null and weak directions, weakest first */
    for (unsigned k = np; k-- > 0 && out->n_dirs < RCH_IDENT_MAX_DIRS;) {
        if (id->dir_class[k] == RC_IDENT_IDENTIFIABLE)
            break;
        rch_ident_dir *d = &out->dirs[out->n_dirs++];
        d->sv_rel = out->sv_rel[k];
        d->weak = id->dir_class[k] == RC_IDENT_WEAK;
        describe(d, &vt[(size_t)k * np], pr);
    }
    rc = 0;
done:
    free(sv);
    free(vt);
    free(V);
    free(Js);
    free(pr);
    return rc;
}
