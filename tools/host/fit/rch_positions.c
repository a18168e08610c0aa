/* SPDX-License-Identifier: MIT */
/* rch_positions.c - laser-tracker positions as calibration data (rch_positions.h). */
#include "rch_positions.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_sensor.h"
#include "rch_data.h"
#include "rch_stats.h"

void rch_pos_free(rch_pos *p)
{
    free(p->s);
    free(p->line);
    free(p->file);
    memset(p, 0, sizeof *p);
}

size_t rch_pos_count_lengths(const rc_sample *s, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        k += s[i].sensor == RC_SENSOR_LENGTH;
    return k;
}

size_t rch_pos_count_tracker(const rc_sample *s, size_t n) { return n - rch_pos_count_lengths(s, n); }

int rch_pos_effect_at(const rc_model *m, unsigned kind, unsigned *count)
{
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == kind) {
            if (count)
                *count = m->effects[i].count;
            return m->effects[i].first;
        }
    if (count)
        *count = 0;
    return -1;
}

int rch_pos_add_effects(rc_model *m, unsigned n_targets)
{
    unsigned have = 0;
    const int tg = rch_pos_effect_at(m, RC_EFF_TRACKER_TARGETS, &have);
    if (n_targets * 3u > have) { /* rebuilt with the targets last: the known ones kept */
        rc_model r = *m;
        r.n_effects = 0;
        r.n_params = RC_N_BASE;
        for (unsigned i = 0; i < m->n_effects; ++i) {
            const rc_effect *e = &m->effects[i];
            if (e->kind == RC_EFF_TRACKER_TARGETS)
                continue;
            if (rc_model_add_effect(&r, (rc_effect_kind)e->kind, e->joint, e->count) != RC_OK)
                return -1;
            rc_effect *ne = &r.effects[r.n_effects - 1];
            memcpy(ne->ref_dh, e->ref_dh, sizeof ne->ref_dh);
            memcpy(&r.x[ne->first], &m->x[e->first], e->count * sizeof r.x[0]);
        }
        if (rc_model_add_effect(&r, RC_EFF_TRACKER_TARGETS, 0, 3u * n_targets) != RC_OK)
            return -1;
        if (tg >= 0)
            memcpy(&r.x[r.n_params - 3u * n_targets], &m->x[tg], have * sizeof r.x[0]);
        *m = r;
    }
    if (rch_pos_effect_at(m, RC_EFF_TRACKER_POSITION, NULL) < 0 &&
        rc_model_add_effect(m, RC_EFF_TRACKER_POSITION, 0, 0) != RC_OK)
        return -1;
    if (rch_pos_effect_at(m, RC_EFF_TRACKER_ROTATION, NULL) < 0 &&
        rc_model_add_effect(m, RC_EFF_TRACKER_ROTATION, 0, 0) != RC_OK)
        return -1;
    return 0;
}

/* A measured position: the three samples at s[i..i+2] (x, y, z of one
 * pose and target), 1 when they are one. */
static int is_point(const rc_sample *s, size_t n, size_t i)
{
    return i + 2 < n && s[i].sensor == RC_SENSOR_TRACKER_X && s[i + 1].sensor == RC_SENSOR_TRACKER_Y &&
           s[i + 2].sensor == RC_SENSOR_TRACKER_Z && s[i + 1].t == s[i].t && s[i + 2].t == s[i].t &&
           s[i + 1].target == s[i].target && s[i + 2].target == s[i].target;
}

/* R, T minimising sum |R a_i + T - b_i|^2 (Kabsch): a, b (k x 3). 0 or -1. */
static int kabsch(double R[9], double T[3], const double (*a)[3], const double (*b)[3], size_t k)
{
    double ca[3] = {0, 0, 0}, cb[3] = {0, 0, 0}, H[9] = {0}, S[3], U[9], Vt[9], sup[2];
    if (k < 3)
        return -1;
    for (size_t i = 0; i < k; ++i)
        for (int r = 0; r < 3; ++r) {
            ca[r] += a[i][r] / (double)k;
            cb[r] += b[i][r] / (double)k;
        }
    for (size_t i = 0; i < k; ++i)
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                H[3 * r + c] += (a[i][r] - ca[r]) * (b[i][c] - cb[c]);
    if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', 3, 3, H, 3, S, U, 3, Vt, 3, sup) != 0 || !(S[1] > 1e-9 * S[0]))
        return -1; /* the points on a line: no rotation */
    /* R = V diag(1, 1, det(V U^T)) U^T */
    double D[9], det;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            D[3 * r + c] = 0.0;
            for (int i = 0; i < 3; ++i)
                D[3 * r + c] += Vt[3 * i + r] * U[3 * c + i];
        }
    det = D[0] * (D[4] * D[8] - D[5] * D[7]) - D[1] * (D[3] * D[8] - D[5] * D[6]) + D[2] * (D[3] * D[7] - D[4] * D[6]);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            R[3 * r + c] = 0.0;
            for (int i = 0; i < 3; ++i)
                R[3 * r + c] += Vt[3 * i + r] * (i == 2 ? det : 1.0) * U[3 * c + i];
        }
    for (int r = 0; r < 3; ++r)
        T[r] = cb[r] - (R[3 * r] * ca[0] + R[3 * r + 1] * ca[1] + R[3 * r + 2] * ca[2]);
    return 0;
}

int rch_pos_set_frame(rc_model *m, const double frame[6])
{
    const int tf = rch_pos_effect_at(m, RC_EFF_TRACKER_POSITION, NULL), rf = rch_pos_effect_at(m, RC_EFF_TRACKER_ROTATION, NULL);
    if (tf < 0 || rf < 0)
        return -1;
    memcpy(&m->x[tf], frame, 3 * sizeof frame[0]);
    memcpy(&m->x[rf], frame + 3, 3 * sizeof frame[0]);
    return 0;
}

int rch_pos_frame_given(const rc_model *m)
{
    const int tf = rch_pos_effect_at(m, RC_EFF_TRACKER_POSITION, NULL), rf = rch_pos_effect_at(m, RC_EFF_TRACKER_ROTATION, NULL);
    int given = 0;
    for (int k = 0; k < 3; ++k)
        given |= (tf >= 0 && m->x[tf + k] != 0.0) || (rf >= 0 && m->x[rf + k] != 0.0);
    return given;
}

int rch_pos_start(rc_model *m, const rc_sample *s, size_t n, int keep_frame)
{
    unsigned nt = 0;
    const int tf = rch_pos_effect_at(m, RC_EFF_TRACKER_POSITION, NULL), rf = rch_pos_effect_at(m, RC_EFF_TRACKER_ROTATION, NULL),
              kf = rch_pos_effect_at(m, RC_EFF_TRACKER_TARGETS, &nt);
    nt /= 3;
    if (tf < 0 || rf < 0 || kf < 0)
        return -1;
    rc_model flange = *m; /* rc_fk of the flange: the cable attachment left out */
    for (unsigned i = 0; i < flange.n_effects; ++i)
        if (flange.effects[i].kind == RC_EFF_TOOL_OFFSET)
            memset(&flange.x[flange.effects[i].first], 0, 3 * sizeof flange.x[0]);
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        k += is_point(s, n, i) && s[i].target < nt;
    double (*o)[3] = malloc((k + 1) * sizeof *o), (*R6)[9] = malloc((k + 1) * sizeof *R6),
           (*y)[3] = malloc((k + 1) * sizeof *y), (*a)[3] = malloc((k + 1) * sizeof *a);
    unsigned *tg = malloc((k + 1) * sizeof *tg);
    int rc = -1;
    if (!o || !R6 || !y || !a || !tg)
        goto done;
    k = 0;
    for (size_t i = 0; i < n; ++i)
        if (is_point(s, n, i) && s[i].target < nt) {
            rc_fk(o[k], R6[k], &flange, s[i].q_rad);
            for (int c = 0; c < 3; ++c)
                y[k][c] = s[i + c].value;
            tg[k++] = s[i].target;
        }
    double *t = &m->x[kf], R[9], T[3];
    memset(t, 0, 3 * nt * sizeof *t);
    rc_rotvec_matrix(R, &m->x[rf]);
    memcpy(T, &m->x[tf], sizeof T);
    double moved = INFINITY;
    for (int it = 0; it < (keep_frame ? 1 : 100) && moved > 1e-9; ++it) { /* alternated until the targets settle */
        double before[3 * RC_MAX_TARGETS];
        memcpy(before, t, 3 * nt * sizeof *t);
        for (size_t i = 0; i < k; ++i) { /* the targets' points at the current targets */
            const double *tt = &t[3 * tg[i]], *Q = R6[i];
            for (int r = 0; r < 3; ++r)
                a[i][r] = o[i][r] + Q[3 * r] * tt[0] + Q[3 * r + 1] * tt[1] + Q[3 * r + 2] * tt[2];
        }
        if (!keep_frame && kabsch(R, T, (const double(*)[3])a, (const double(*)[3])y, k) != 0)
            goto done;
        /* each target: the mean of R6^T (R^T (y - T) - o) over its points */
        memset(t, 0, 3 * nt * sizeof *t);
        unsigned cnt[RC_MAX_TARGETS] = {0};
        for (size_t i = 0; i < k; ++i) {
            double v[3], u[3];
            for (int r = 0; r < 3; ++r)
                v[r] = y[i][r] - T[r];
            for (int r = 0; r < 3; ++r)
                u[r] = R[r] * v[0] + R[3 + r] * v[1] + R[6 + r] * v[2] - o[i][r];
            for (int r = 0; r < 3; ++r)
                t[3 * tg[i] + r] += R6[i][r] * u[0] + R6[i][3 + r] * u[1] + R6[i][6 + r] * u[2];
            cnt[tg[i]]++;
        }
        moved = 0.0;
        for (unsigned j = 0; j < nt; ++j)
            for (int r = 0; r < 3; ++r) {
                t[3 * j + r] = cnt[j] ? t[3 * j + r] / cnt[j] : 0.0;
                moved = fmax(moved, fabs(t[3 * j + r] - before[3 * j + r]));
            }
    }
    memcpy(&m->x[tf], T, sizeof T);
    rc_rotvec_from_matrix(&m->x[rf], R);
    rc = 0;
done:
    free(o);
    free(R6);
    free(y);
    free(a);
    free(tg);
    return rc;
}

void rch_pos_fix_unseen(uint8_t *fixed, const rc_model *m, const rc_sample *s, size_t n)
{
    const size_t nl = rch_pos_count_lengths(s, n);
    uint8_t seen_t[RC_MAX_TARGETS] = {0};
    for (size_t i = 0; i < n; ++i)
        if (s[i].sensor >= RC_SENSOR_TRACKER_X && s[i].sensor <= RC_SENSOR_TRACKER_Z && s[i].target < RC_MAX_TARGETS)
            seen_t[s[i].target] = 1;
    if (nl == 0)
        fixed[RC_P_ENC] = fixed[RC_P_ENC + 1] = fixed[RC_P_ENC + 2] = 1;
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        const rc_effect_desc *ds = rc_effect_describe(e->kind);
        if (!ds)
            continue;
        const int length_only = ds->side == RC_SIDE_LENGTH || ds->side == RC_SIDE_OUTLET || ds->side == RC_SIDE_POINT;
        if ((nl == 0 && length_only) || (nl == n && ds->side == RC_SIDE_SENSOR))
            memset(&fixed[e->first], 1, e->count);
        if (e->kind == RC_EFF_TRACKER_TARGETS)
            for (unsigned j = 0; j < e->count / 3u; ++j)
                if (!seen_t[j])
                    memset(&fixed[e->first + 3u * j], 1, 3);
    }
}

/* A tracker sample's pose number and index, sorted together. */
typedef struct {
    double t;
    size_t i;
} t_index;

static int cmp_tidx(const void *a, const void *b)
{
    const t_index *x = a, *y = b;
    if (x->t != y->t)
        return x->t < y->t ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

size_t rch_pos_split(size_t *idx, const rc_sample *s, size_t n, size_t want)
{
    const size_t nt = rch_pos_count_tracker(s, n);
    if (nt == 0 || n == 0)
        return want;
    t_index *ti = malloc(nt * sizeof *ti);
    size_t *ord = malloc(nt * sizeof *ord), *start = malloc(n * sizeof *start), *out = malloc(n * sizeof *out);
    uint8_t *taken = calloc(n, 1);
    if (!ti || !ord || !start || !out || !taken) {
        free(ti);
        free(ord);
        free(start);
        free(out);
        free(taken);
        return want;
    }
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        if (s[i].sensor != RC_SENSOR_LENGTH) {
            ti[k].t = s[i].t;
            ti[k++].i = i;
        }
    qsort(ti, nt, sizeof *ti, cmp_tidx);
    for (size_t j = 0; j < nt; ++j)
        ord[j] = ti[j].i;
    free(ti);
    for (size_t a = 0; a < nt;) { /* start[i]: where i's pose begins in ord */
        size_t b = a + 1;
        while (b < nt && s[ord[b]].t == s[ord[a]].t)
            ++b;
        for (size_t j = a; j < b; ++j)
            start[ord[j]] = a;
        a = b;
    }
    size_t m = 0, held = 0;
    for (int side = 0; side < 2; ++side) /* held-out units first, then the rest in the same order */
        for (size_t i = 0; i < n; ++i) {
            const size_t u = idx[i];
            if (taken[u] || (side == 0 && held >= want))
                continue;
            if (s[u].sensor == RC_SENSOR_LENGTH) {
                out[m++] = u;
                taken[u] = 1;
            } else {
                for (size_t j = start[u]; j < nt && s[ord[j]].t == s[u].t; ++j)
                    if (!taken[ord[j]]) {
                        out[m++] = ord[j];
                        taken[ord[j]] = 1;
                    }
            }
            if (side == 0)
                held = m;
        }
    memcpy(idx, out, n * sizeof *idx);
    free(ord);
    free(start);
    free(out);
    free(taken);
    return held;
}

typedef struct {
    double t;
    unsigned target;
    double meas[3], pred[3];
} point;

static int cmp_point(const void *a, const void *b)
{
    const point *x = a, *y = b;
    if (x->t != y->t)
        return x->t < y->t ? -1 : 1;
    return (x->target > y->target) - (x->target < y->target);
}

int rch_pos_errors(rch_pos_err *e, const rc_model *m, const rc_sample *s, size_t n)
{
    memset(e, 0, sizeof *e);
    e->ap_max_mm = e->rp_max_mm = NAN;
    point *p = malloc((n / 3 + 1) * sizeof *p);
    if (!p)
        return -1;
    size_t k = 0;
    rch_stats st;
    memset(&st, 0, sizeof st);
    for (size_t i = 0; i < n; ++i) {
        if (!is_point(s, n, i))
            continue;
        for (int c = 0; c < 3; ++c) {
            p[k].meas[c] = s[i + c].value;
            if (rc_meas(&p[k].pred[c], NULL, m, &s[i + c]) != RC_OK) {
                free(p);
                return -1;
            }
        }
        p[k].t = s[i].t;
        p[k].target = s[i].target;
        const double dx = p[k].pred[0] - p[k].meas[0], dy = p[k].pred[1] - p[k].meas[1],
                     dz = p[k].pred[2] - p[k].meas[2];
        rch_stats_add(&st, sqrt(dx * dx + dy * dy + dz * dz));
        ++k;
        i += 2;
    }
    e->points = k;
    if (k) {
        double ss = 0.0, sum = 0.0, mx = 0.0;
        for (size_t i = 0; i < k; ++i) {
            const double dx = p[i].pred[0] - p[i].meas[0], dy = p[i].pred[1] - p[i].meas[1],
                         dz = p[i].pred[2] - p[i].meas[2], l = sqrt(dx * dx + dy * dy + dz * dz);
            ss += l * l;
            sum += l;
            mx = fmax(mx, l);
        }
        e->rms_mm = sqrt(ss / (double)k);
        e->mean_mm = sum / (double)k;
        e->max_mm = mx;
    }
    qsort(p, k, sizeof *p, cmp_point);
    for (size_t a = 0; a < k;) { /* ISO 9283 over pose-target pairs measured more than once */
        size_t b = a + 1;
        while (b < k && p[b].t == p[a].t && p[b].target == p[a].target)
            ++b;
        if (b - a >= 2) {
            const double c = (double)(b - a);
            double bar[3] = {0, 0, 0}, ls = 0.0, l2 = 0.0, ap = 0.0;
            for (size_t i = a; i < b; ++i)
                for (int r = 0; r < 3; ++r)
                    bar[r] += p[i].meas[r] / c;
            for (int r = 0; r < 3; ++r)
                ap += (bar[r] - p[a].pred[r]) * (bar[r] - p[a].pred[r]);
            for (size_t i = a; i < b; ++i) {
                double l = 0.0;
                for (int r = 0; r < 3; ++r)
                    l += (p[i].meas[r] - bar[r]) * (p[i].meas[r] - bar[r]);
                l = sqrt(l);
                ls += l;
                l2 += l * l;
            }
            const double lm = ls / c, sl = sqrt(fmax(0.0, (l2 - c * lm * lm) / (c - 1.0)));
            e->ap_max_mm = e->repeated ? fmax(e->ap_max_mm, sqrt(ap)) : sqrt(ap);
            e->rp_max_mm = e->repeated ? fmax(e->rp_max_mm, lm + 3.0 * sl) : lm + 3.0 * sl;
            e->repeated++;
        }
        a = b;
    }
    free(p);
    return 0;
}

int rch_pos_evaluate(rch_pos_eval *out, const rc_model *m, const rch_pos *p, int refit_frame, rc_solve_work *w,
                     char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (p->n < 9) {
        snprintf(err, errlen, "%zu positions: at least 3 are needed", p->rows);
        return -1;
    }
    rc_model use = *m;
    unsigned had = 0;
    const int had_frame = rch_pos_effect_at(m, RC_EFF_TRACKER_ROTATION, NULL) >= 0;
    rch_pos_effect_at(m, RC_EFF_TRACKER_TARGETS, &had);
    had /= 3;
    if (rch_pos_add_effects(&use, p->n_targets) != 0) {
        snprintf(err, errlen, "the model has no room for the tracker frame and %u targets", p->n_targets);
        return -1;
    }
    out->frame_fitted = refit_frame || !had_frame;
    out->targets_known = out->frame_fitted ? 0u : (had < p->n_targets ? had : p->n_targets);
    uint8_t seen[RC_MAX_TARGETS] = {0};
    for (size_t i = 0; i < p->n; ++i)
        seen[p->s[i].target < RC_MAX_TARGETS ? p->s[i].target : 0] = 1;
    for (unsigned j = out->targets_known; j < p->n_targets; ++j)
        out->targets_fitted += seen[j]; /* those the data show */
    uint8_t fixed[RC_MAX_PARAMS];
    memset(fixed, 1, sizeof fixed);
    unsigned nt = 0;
    const int tf = rch_pos_effect_at(&use, RC_EFF_TRACKER_POSITION, NULL),
              rf = rch_pos_effect_at(&use, RC_EFF_TRACKER_ROTATION, NULL),
              kf = rch_pos_effect_at(&use, RC_EFF_TRACKER_TARGETS, &nt);
    if (out->frame_fitted) {
        if (rch_pos_start(&use, p->s, p->n, 0) != 0) {
            snprintf(err, errlen, "cannot place the tracker: the positions do not spread in three directions");
            return -1;
        }
        memset(&fixed[tf], 0, 3);
        memset(&fixed[rf], 0, 3);
    }
    for (unsigned j = out->targets_known; j < nt / 3u; ++j)
        memset(&fixed[kf + 3 * (int)j], 0, 3);
    if (!out->frame_fitted && out->targets_fitted) { /* start of the unknown targets at the model's frame */
        rc_model tmp = use;
        if (rch_pos_start(&tmp, p->s, p->n, 1) == 0)
            for (unsigned j = out->targets_known; j < nt / 3u; ++j)
                memcpy(&use.x[kf + 3 * (int)j], &tmp.x[kf + 3 * (int)j], 3 * sizeof use.x[0]);
    }
    rch_pos_fix_unseen(fixed, &use, p->s, p->n);
    if (out->frame_fitted || out->targets_fitted) {
        rc_solve_config cfg;
        rc_solve_result res;
        memset(&cfg, 0, sizeof cfg);
        cfg.method = RC_METHOD_LM;
        cfg.fixed = fixed;
        cfg.snr_min = -1.0;
        const rc_status st = rc_solve(&use, &res, w, &cfg, p->s, p->n);
        if (st != RC_OK) {
            snprintf(err, errlen, "fitting the tracker frame failed: %s", rc_strerror(st));
            return -1;
        }
    }
    memcpy(out->frame, &use.x[tf], 3 * sizeof out->frame[0]);
    memcpy(out->frame + 3, &use.x[rf], 3 * sizeof out->frame[0]);
    rc_metrics mt;
    if (rc_eval(&mt, &use, p->s, p->n) != RC_OK || rch_pos_errors(&out->err, &use, p->s, p->n) != 0) {
        snprintf(err, errlen, "a position names a target the model cannot predict");
        return -1;
    }
    out->rms_component_mm = mt.rmse_mm;
    out->used = use;
    return 0;
}

void rch_pos_err_json(rch_jw *w, const char *name, const rch_pos_err *e)
{
    rch_jw_obj(w, name);
    rch_jw_uint(w, "points", e->points);
    rch_jw_numf(w, "rms", e->rms_mm, "%.6f");
    rch_jw_numf(w, "mean", e->mean_mm, "%.6f");
    rch_jw_numf(w, "max", e->max_mm, "%.6f");
    rch_jw_uint(w, "repeated", e->repeated);
    rch_jw_numf(w, "ap_max", e->ap_max_mm, "%.6f"); /* null without repeats */
    rch_jw_numf(w, "rp_max", e->rp_max_mm, "%.6f");
    rch_jw_end(w);
}
