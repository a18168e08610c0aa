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
#define MAX_TIPS (1 + RC_SENSOR_COUNT_) /* the cable attachment, each table sensor's tip */
#define MAX_SET_PARAMS 5

/* A point of the data's sensors on the flange: its parameters' name ("tool_offset") and its words. */
typedef struct tip {
    char name[32];
    char words[48];
} tip;

/* A known set as used here: its parameters named ("{tip}" resolved), its reason. */
typedef struct inst {
    unsigned set;
    unsigned n;
    char params[MAX_SET_PARAMS][48];
    char why[256];
} inst;

typedef struct prob {
    const rc_model *m;
    uint16_t idx[RC_MAX_PARAMS];
    unsigned nf;
    char words[160];
    unsigned n_tips;
    tip tips[MAX_TIPS];
    unsigned n_inst;
    inst insts[32 * MAX_TIPS];
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
    if (kinds[RC_SENSOR_LENGTH]) { /* the points on the flange: the cable's attachment, each table sensor's tip */
        snprintf(p->tips[p->n_tips].name, sizeof p->tips[0].name, "%s", rc_effect_name(RC_EFF_TOOL_OFFSET));
        snprintf(p->tips[p->n_tips++].words, sizeof p->tips[0].words, "the cable attachment");
    }
    for (unsigned k = 0; k < RC_SENSOR_COUNT_; ++k) {
        const rch_sensor_desc *sd = rch_sensor_of_kind(k);
        if (kinds[k] && sd)
            add_words(p, sd->words);
        if (kinds[k] && sd && sd->tip_effect >= 0 && p->n_tips < MAX_TIPS) {
            snprintf(p->tips[p->n_tips].name, sizeof p->tips[0].name, "%s",
                     rc_effect_name((rc_effect_kind)sd->tip_effect));
            snprintf(p->tips[p->n_tips++].words, sizeof p->tips[0].words, "the %s tip", sd->name);
        }
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
    {{"d6", "{tip}.z"}, RCH_IDENT_WHY_SHARE, 1,
     "d6 and {tip}'s z both move the measured point along the flange axis: only their sum is seen"},
    {{"a6", "{tip}.x"}, RCH_IDENT_WHY_SHARE, 1,
     "a6 and {tip}'s x both move the measured point along the flange's x axis: only their sum is "
     "seen"},
    {{"alpha6", "theta6"}, RCH_IDENT_WHY_SHARE, 1,
     "alpha6 and theta6 turn the flange about its own axes without moving the flange point while a6 is zero: "
     "{data} cannot see them"},
    {{"theta1", "ex", "ey"}, RCH_IDENT_WHY_SHARE, 1,
     "turning the whole robot about its base axis is the same as turning the encoder around it: lengths do not fix "
     "the base heading"},
    {{"alpha6", "{tip}.y", "{tip}.z"}, RCH_IDENT_WHY_SHARE, 1,
     "turning the flange about its x axis moves {tip} as a change of its y and z does"},
    {{"theta6", "{tip}.x", "{tip}.y"}, RCH_IDENT_WHY_SHARE, 1,
     "turning the flange about its axis moves {tip} as a change of its x and y does"},
    /* these trade against many parameters at once: named when they lead a direction */
    {{"length_scale"}, 0.5, 0,
     "an encoder scale error looks like a uniformly larger robot: separate them with one reference length (a gauge "
     "bar or a laser tracker distance)"},
    {{"length_offset"}, 0.5, 0, "a constant cable offset trades against the encoder position and the link lengths"},
};
#define N_KNOWN (sizeof known_sets / sizeof known_sets[0])

/* Replace each "{tok}" of text by val into out (len). */
static void subst(char *out, size_t len, const char *text, const char *tok, const char *val)
{
    size_t pos = 0;
    const size_t tl = strlen(tok);
    out[0] = '\0';
    for (const char *at; (at = strstr(text, tok)) != NULL && pos < len; text = at + tl)
        pos += (size_t)snprintf(out + pos, len - pos, "%.*s%s", (int)(at - text), text, val);
    if (pos < len)
        snprintf(out + pos, len - pos, "%s", text);
}

/* Does known set k name a point on the flange ("{tip}")? */
static int names_tip(unsigned k)
{
    for (unsigned a = 0; a < MAX_SET_PARAMS && known_sets[k].params[a]; ++a)
        if (strncmp(known_sets[k].params[a], "{tip}", 5) == 0)
            return 1;
    return 0;
}

/* pr->insts: the known sets in table order, a set naming "{tip}" once per point of the data's sensors, each
 * kept only when all its parameters are in the problem (a set naming what the data's sensors do not have says
 * nothing here); the reasons in the data's words ("{data}", "{tip}"). */
static void make_insts(prob *pr)
{
    for (unsigned k = 0; k < N_KNOWN; ++k) {
        const unsigned reps = names_tip(k) ? pr->n_tips : 1u;
        for (unsigned t = 0; t < reps && pr->n_inst < sizeof pr->insts / sizeof pr->insts[0]; ++t) {
            inst *in = &pr->insts[pr->n_inst];
            int all = 1;
            in->set = k;
            in->n = 0;
            for (unsigned a = 0; a < MAX_SET_PARAMS && known_sets[k].params[a]; ++a) {
                subst(in->params[a], sizeof in->params[a], known_sets[k].params[a], "{tip}",
                      pr->n_tips ? pr->tips[t].name : "");
                all &= param_index(pr, in->params[a]) >= 0;
                ++in->n;
            }
            if (!all)
                continue;
            char w[256];
            subst(w, sizeof w, known_sets[k].why, "{data}", pr->words);
            subst(in->why, sizeof in->why, w, "{tip}", pr->n_tips ? pr->tips[t].words : "");
            ++pr->n_inst;
        }
    }
}

static void explain(rch_ident_dir *d, const double *v, const prob *pr)
{
    d->why[0] = '\0';
    for (unsigned p = 0; p < pr->n_inst; ++p) {
        const inst *in = &pr->insts[p];
        double s2 = 0.0; /* the squared length of v on the set's parameters */
        for (unsigned k = 0; k < in->n; ++k) {
            const double c = comp(v, pr, in->params[k]);
            s2 += c * c;
        }
        if (s2 >= known_sets[in->set].dir_share) {
            snprintf(d->why, sizeof d->why, "%s", in->why);
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
    unsigned found[sizeof pr->insts / sizeof pr->insts[0]];
    unsigned n_found = 0;
    double *A = malloc(n * MAX_SET_PARAMS * sizeof *A);
    if (!A || s_max <= 0.0 || n < MAX_SET_PARAMS)
        goto done;
    for (unsigned p = 0; p < pr->n_inst; ++p) {
        const inst *in = &pr->insts[p];
        if (!known_sets[in->set].is_set || out->n_combos >= RCH_IDENT_MAX_COMBOS)
            continue;
        int idx[MAX_SET_PARAMS];
        const unsigned k = in->n;
        for (unsigned b = 0; b < k; ++b)
            idx[b] = param_index(pr, in->params[b]); /* every one in the problem (make_insts) */
        int holds = 0; /* a smaller set found already inside this one */
        for (unsigned f = 0; f < n_found && !holds; ++f) {
            unsigned inside = 1;
            for (unsigned a = 0; a < pr->insts[found[f]].n; ++a) {
                unsigned hit = 0;
                for (unsigned b = 0; b < k; ++b)
                    hit |= strcmp(pr->insts[found[f]].params[a], in->params[b]) == 0;
                inside &= hit;
            }
            holds = (int)inside;
        }
        if (holds)
            continue;
        for (size_t i = 0; i < n; ++i)
            for (unsigned b = 0; b < k; ++b)
                A[i * k + b] = Js[i * np + (unsigned)idx[b]];
        double sv[MAX_SET_PARAMS], super[MAX_SET_PARAMS];
        if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'N', (lapack_int)n, (lapack_int)k, A, (lapack_int)k, sv, NULL, 1,
                           NULL, 1, super) != 0)
            continue;
        const double rel = sv[k - 1] / s_max;
        if (!(rel < RC_IDENT_WEAK_REL))
            continue;
        rch_ident_combo *c = &out->combos[out->n_combos++];
        size_t pos = 0;
        for (unsigned b = 0; b < k; ++b)
            pos += (size_t)snprintf(c->params + pos, sizeof c->params - pos, "%s%s", b ? " " : "", in->params[b]);
        c->weak = rel >= RC_IDENT_NULL_REL;
        c->sv_rel = rel;
        snprintf(c->why, sizeof c->why, "%s", in->why);
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
    make_insts(pr);
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
