/* SPDX-License-Identifier: MIT */
#include "rch_ident.h"

#include "rc_ident.h"
#include "rch_jac.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Component of v (n_params) on the parameter called name; 0 when none is. */
static double comp(const double *v, const rc_model *m, const char *name)
{
    char buf[64];
    for (unsigned k = 0; k < m->n_params; ++k)
        if (strcmp(rc_param_name(buf, sizeof buf, m, k), name) == 0)
            return v[k];
    return 0.0;
}

static int has(const double *v, const rc_model *m, const char *name, double thr)
{
    return fabs(comp(v, m, name)) >= thr;
}

static void explain(rch_ident_dir *d, const double *v, const rc_model *m)
{
    const double t = 0.15;
    const char *why = "";
    const double a6 = comp(v, m, "alpha6"), t6 = comp(v, m, "theta6");
    if (fabs(a6) >= t && fabs(t6) >= t && a6 * a6 + t6 * t6 > 0.98)
        why = "alpha6 and theta6 turn the flange about its own axes without moving the flange point while a6 "
              "is zero (both columns are zero, so any mix of them is null): cable lengths cannot see them";
    else if (has(v, m, "alpha6", t) && !has(v, m, "theta6", t) && !has(v, m, "d6", t))
        why = "alpha6 turns the flange about its own x axis after the last translation: it never moves the "
              "flange point, so cable lengths cannot see it";
    else if (has(v, m, "theta6", t) && !has(v, m, "a6", 0.5))
        why = "theta6 only moves the measured point through a6 (zero nominally): the tool orientation about "
              "axis 6 is invisible to a point measurement";
    else if (has(v, m, "d1", t) && has(v, m, "ez", t))
        why = "moving the robot base up is the same as moving the encoder down: only their difference is "
              "measured";
    else if (has(v, m, "theta1", t) && (has(v, m, "ex", t) || has(v, m, "ey", t)))
        why = "turning the whole robot about its base axis is the same as turning the encoder around it: "
              "lengths do not fix the base heading";
    else if (has(v, m, "d2", t) && has(v, m, "d3", t))
        why = "joints 2 and 3 are parallel: d2 and d3 shift the arm along the same axis, only their sum "
              "counts";
    else if (has(v, m, "length_scale", t))
        why = "an encoder scale error looks like a uniformly larger robot: separate them with one reference "
              "length (a gauge bar or a laser tracker distance)";
    else if (has(v, m, "length_offset", t))
        why = "a constant cable offset trades against the encoder position and the link lengths";
    snprintf(d->why, sizeof d->why, "%s", why);
}

/* SVD of the column-scaled identification Jacobian of m over the samples (n):
 * sv (np) descending (zero beyond n), vt (np x np) row k = direction k. */
static int scaled_svd(double *sv, double *vt, const rc_model *m, const rc_sample *s, size_t n)
{
    const unsigned np = m->n_params;
    rch_jac jac;
    char err[160];
    double *J, *sup = malloc(np * sizeof *sup);
    int rc = -1;
    memset(&jac, 0, sizeof jac);
    if (!sup || rch_jac_eval(&jac, m, NULL, np, s, n, err, sizeof err) != 0) /* the Jacobian at the solution */
        goto done;
    J = jac.J;
    rc_ident_scale(sup, jac.norm2, np, 1); /* the one column-scaling rule */
    for (unsigned k = 0; k < np; ++k)
        for (size_t i = 0; i < n; ++i)
            J[i * np + k] = sup[k] > 0.0 ? J[i * np + k] / sup[k] : 0.0;
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

/* "+0.71 d2 -0.71 d3": the (at most five) components of v (np) of at least
 * 0.1, largest first, then the plain-words reason. */
static void describe(rch_ident_dir *d, const double *v, const rc_model *m)
{
    const unsigned np = m->n_params;
    size_t pos = 0;
    unsigned order[RC_MAX_PARAMS];
    for (unsigned i = 0; i < np; ++i)
        order[i] = i;
    for (unsigned i = 0; i < np; ++i) /* by |component|, descending */
        for (unsigned j = i + 1; j < np; ++j)
            if (fabs(v[order[j]]) > fabs(v[order[i]])) {
                unsigned t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
    for (unsigned i = 0; i < np && i < 5; ++i) {
        char name[48];
        if (fabs(v[order[i]]) < 0.1)
            break;
        int w = snprintf(d->combo + pos, sizeof d->combo - pos, "%s%+.2f %s", i ? " " : "", v[order[i]],
                         rc_param_name(name, sizeof name, m, order[i]));
        if (w < 0 || (size_t)w >= sizeof d->combo - pos)
            break;
        pos += (size_t)w;
    }
    explain(d, v, m);
}

int rch_ident_compute(rch_ident *out, const rc_model *m, const rc_sample *s, size_t n)
{
    const unsigned np = m->n_params;
    memset(out, 0, sizeof *out);
    out->n_params = np;
    if (n == 0 || np == 0 || np > RC_MAX_PARAMS)
        return -1;
    double *sv = malloc(np * sizeof *sv), *vt = malloc((size_t)np * np * sizeof *vt);
    double *V = malloc((size_t)np * np * sizeof *V);
    int rc = -1;
    if (!sv || !vt || !V || scaled_svd(sv, vt, m, s, n) != 0)
        goto done;
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
        describe(d, &vt[(size_t)k * np], m);
    }
    rc = 0;
done:
    free(sv);
    free(vt);
    free(V);
    return rc;
}
