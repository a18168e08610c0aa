/* SPDX-License-Identifier: MIT */
/* rch_poses_touch.c - a touch run's plan (rch_poses_touch.h): the model the
 * fit of plate touches uses, candidates on the plates' faces solved by the
 * general IK, the I-optimal selection with per-plate quotas, the predicted
 * accuracy at the probe, the tour, the CSV skeleton.
 * Depends on: rc_model (rc_meas, rc_fk, rc_plane_angles), rc_rand; rch_ikg,
 * rch_cell, rch_prior, rch_uncert, rch_stats; rch_poses (order,
 * rch_poses_spd_inverse). Memory: heap for the work, freed before return;
 * the rows in the result (rch_poses_touch_free). Errors: -1 with d set. */
#include "rch_poses_touch.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_ikg.h"
#include "rch_poses_int.h"
#include "rch_stats.h"
#include "rch_uncert.h"

#define DEG_ (PI_ / 180.0)
#define STEP_DEG 1e-4 /* the joints' rounding (the CSV's %.4f) */
#define RCH_TOUCH_SPACING_MM 20.0 /* two touches of a face at most this far apart are kept apart (spread) */

typedef struct touch_work {
    rc_model m, mp;           /* the fit's model; the point model (m + the probe as a tool offset) */
    unsigned nf, np, G;       /* free parameters; plates; groups (plates, + the block's top) */
    unsigned fi[RC_MAX_PARAMS];
    double sc[RC_MAX_PARAMS];
    int tip_first, tool_first, plane_first, off_first;
    double noise;
    double nrm[RCH_TOUCH_MAX_PLATES][3]; /* unit normals */
    size_t n_cand, n;
    rc_sample *cand;          /* (n_cand) q, target = plate, value = height */
    unsigned *group;          /* (n_cand) */
    double *X;                /* (n_cand x nf) scaled rows */
    double *pt;               /* (n_cand x 3) the face point touched */
    double space[RCH_TOUCH_MAX_PLATES + 1]; /* least distance between two touches of a group (mm) */
    double *Q, *M, *C, *B, *T, *u, *v;
    size_t *design, *rnd;
    unsigned char *in;
    size_t cnt[RCH_TOUCH_MAX_PLATES + 1], quota[RCH_TOUCH_MAX_PLATES + 1];
} touch_work;

static void unit(double out[3], const double v[3])
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int r = 0; r < 3; ++r)
        out[r] = v[r] / l;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Two unit vectors spanning the plane of unit normal n. */
static void plane_axes(double u[3], double v[3], const double n[3])
{
    const double a[3] = {fabs(n[0]) < 0.9 ? 1.0 : 0.0, fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    double w[3] = {n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2], n[0] * a[1] - n[1] * a[0]};
    unit(u, w);
    v[0] = n[1] * u[2] - n[2] * u[1];
    v[1] = n[2] * u[0] - n[0] * u[2];
    v[2] = n[0] * u[1] - n[1] * u[0];
}

int rch_poses_touch_check(const rc_model *m, const rch_poses_touch_config *c, rch_diag *d)
{
    if (c->count < 1 || c->count > RCH_POSES_MAX_COUNT) {
        rch_diag_set(d, "", 0, 0, "--count %zu: a plan has 1..%u touches", c->count, RCH_POSES_MAX_COUNT);
        return -1;
    }
    if (c->n_plates < 1 || c->n_plates > RCH_TOUCH_MAX_PLATES) {
        rch_diag_set(d, "", 0, 0, "%u plates: a touch plan needs 1..%d --plate", c->n_plates, RCH_TOUCH_MAX_PLATES);
        return -1;
    }
    for (unsigned k = 0; k < c->n_plates; ++k) {
        const rch_touch_plate *p = &c->plates[k];
        const double l = sqrt(dot3(p->normal, p->normal));
        if (!(l > 1e-9) || !isfinite(l)) {
            rch_diag_set(d, "", 0, 0, "--plate %u (plate %u): its normal (%g, %g, %g) has no direction", k + 1, k,
                         p->normal[0], p->normal[1], p->normal[2]);
            return -1;
        }
        if (!(p->size_mm > 2.0 * c->edge_mm)) {
            rch_diag_set(d, "", 0, 0, "--plate %u (plate %u): size %g mm leaves nothing inside the %g mm edge "
                         "(--edge-mm)", k + 1, k, p->size_mm, c->edge_mm);
            return -1;
        }
    }
    if (!(c->cone_deg > 0.0 && c->cone_deg <= 80.0) || !(c->margin_deg >= 0.0) || !(c->wrist_deg >= 0.0) ||
        c->wrist_deg >= 45.0) {
        rch_diag_set(d, "", 0, 0, "need 0 < --cone-deg <= 80, --margin-deg >= 0 and 0 <= --wrist-deg < 45");
        return -1;
    }
    if (c->min_per_plate < 3) {
        rch_diag_set(d, "", 0, 0, "--min-per-plate %u: a plate's three parameters need at least 3 touches",
                     c->min_per_plate);
        return -1;
    }
    if (c->gauge_mm != 0.0) {
        if (!(c->gauge_mm > 0.0 && c->gauge_mm <= 1000.0) || c->gauge_plate >= c->n_plates) {
            rch_diag_set(d, "", 0, 0, "--gauge-mm %g on plate %u: a height in (0, 1000] mm on one of the %u plates",
                         c->gauge_mm, c->gauge_plate, c->n_plates);
            return -1;
        }
        if (!(c->gauge_size_mm > 2.0 * c->edge_mm) || !(c->gauge_share > 0.0 && c->gauge_share < 1.0)) {
            rch_diag_set(d, "", 0, 0, "--gauge-size-mm %g must exceed twice --edge-mm (%g) and --gauge-share %g lie "
                         "in (0, 1)", c->gauge_size_mm, c->edge_mm, c->gauge_share);
            return -1;
        }
    }
    size_t need = (size_t)c->n_plates * c->min_per_plate;
    if (c->gauge_mm > 0.0)
        need += 3;
    if (c->count < need) {
        rch_diag_set(d, "", 0, 0, "--count %zu: %u plates x %u touches%s need at least %zu", c->count, c->n_plates,
                     c->min_per_plate, c->gauge_mm > 0.0 ? " and 3 on the gauge block" : "", need);
        return -1;
    }
    for (int j = 0; j < RC_NJ; ++j)
        if (!(m->q_min_rad[j] + c->margin_deg * DEG_ < m->q_max_rad[j] - c->margin_deg * DEG_)) {
            rch_diag_set(d, "", 0, 0, "--margin-deg %g leaves no room inside joint %d's limits", c->margin_deg, j + 1);
            return -1;
        }
    return 0;
}

/* The model the fit uses for these plates (tilts as rch_poses_position's, the sensor's effects at the given
 * placements) and the point model. 0 or -1. */
static int touch_setup(touch_work *w, const rc_model *m, const rch_poses_touch_config *c, rch_diag *d)
{
    double mean[RC_MAX_PARAMS], sd[RC_MAX_PARAMS];
    rch_prior_cfg pd;
    w->m = *m;
    w->np = c->n_plates;
    w->G = c->n_plates + (c->gauge_mm > 0.0);
    for (unsigned i = 1; i + 1 < RC_NJ; ++i) {
        int have = 0;
        for (unsigned e = 0; e < w->m.n_effects; ++e)
            have |= w->m.effects[e].kind == RC_EFF_AXIS_TILT && w->m.effects[e].joint == i;
        if (!have && fabs(sin(w->m.x[RC_P_ALPHA(i)])) < 1e-6 &&
            rc_model_add_effect(&w->m, RC_EFF_AXIS_TILT, i, 0) != RC_OK)
            goto cap;
    }
    if (rc_model_add_effect(&w->m, RC_EFF_TOUCH_TIP, 0, 0) != RC_OK)
        goto cap;
    w->tip_first = (int)w->m.effects[w->m.n_effects - 1].first;
    if (rc_model_add_effect(&w->m, RC_EFF_PLANE_NORMALS, 0, 2u * w->np) != RC_OK)
        goto cap;
    w->plane_first = (int)w->m.effects[w->m.n_effects - 1].first;
    if (rc_model_add_effect(&w->m, RC_EFF_PLANE_OFFSETS, 0, w->np) != RC_OK)
        goto cap;
    w->off_first = (int)w->m.effects[w->m.n_effects - 1].first;
    memcpy(&w->m.x[w->tip_first], c->tool_mm, 3 * sizeof(double));
    for (unsigned k = 0; k < w->np; ++k) {
        unit(w->nrm[k], c->plates[k].normal);
        rc_plane_angles(&w->m.x[w->plane_first + 2 * (int)k], &w->m.x[w->plane_first + 2 * (int)k + 1], w->nrm[k]);
        w->m.x[w->off_first + (int)k] = dot3(w->nrm[k], c->plates[k].point_mm);
    }
    if (!c->prior)
        rch_prior_defaults(&pd);
    rch_prior_fill(mean, sd, &w->m, &w->m, c->prior ? c->prior : &pd);
    w->nf = 0;
    for (unsigned k = 0; k < w->m.n_params; ++k) {
        if (k == RC_P_THETA(0) || k == RC_P_D(0))
            continue;
        double s = sd[k];
        if ((int)k >= w->tip_first && (int)k < w->tip_first + 3)
            s = RCH_TOUCH_SD_TIP_MM;
        else if ((int)k >= w->plane_first && (int)k < w->plane_first + 2 * (int)w->np)
            s = RCH_TOUCH_SD_NORMAL_RAD;
        else if ((int)k >= w->off_first && (int)k < w->off_first + (int)w->np)
            s = RCH_TOUCH_SD_OFFSET_MM;
        if (!(s > 0.0))
            continue; /* held by the prior (sd 0): no direction to plan for */
        w->fi[w->nf] = k;
        w->sc[w->nf++] = s;
    }
    w->noise = c->noise_mm > 0.0 ? c->noise_mm : RCH_TOUCH_NOISE_MM;
    w->mp = w->m;
    if (rc_model_add_effect(&w->mp, RC_EFF_TOOL_OFFSET, 0, 0) != RC_OK)
        goto cap;
    w->tool_first = (int)w->mp.effects[w->mp.n_effects - 1].first;
    memcpy(&w->mp.x[w->tool_first], c->tool_mm, 3 * sizeof(double));
    return 0;
cap:
    rch_diag_set(d, "", 0, 0, "cannot add the touch model's effects for %u plates (RC_MAX_PARAMS or RC_MAX_EFFECTS)",
                 c->n_plates);
    return -1;
}

/* Sample s's scaled row (nf): the core's gradient of the plane sensor (rc_meas, the sensor table's hook). */
static int touch_row(double *x, const touch_work *w, const rc_sample *s)
{
    double val, g[RC_MAX_PARAMS];
    if (rc_meas(&val, g, &w->m, s) != RC_OK)
        return -1;
    for (unsigned j = 0; j < w->nf; ++j)
        x[j] = g[w->fi[j]] * w->sc[j] / w->noise;
    return 0;
}

/* The flange origin of q on the outward side of every plate whose disc it lies over. */
static int outside_plates(const touch_work *w, const rch_poses_touch_config *c, const double o[3])
{
    for (unsigned k = 0; k < w->np; ++k) {
        double r[3];
        for (int i = 0; i < 3; ++i)
            r[i] = o[i] - c->plates[k].point_mm[i];
        const double h = dot3(r, w->nrm[k]), rr = dot3(r, r) - h * h;
        if (h <= 0.0 && rr <= 0.25 * c->plates[k].size_mm * c->plates[k].size_mm)
            return 0;
    }
    return 1;
}

/* One valid solution of ik's solutions sol (ns) drawn at random, rounded; -1: none (why counted). */
static int pick_solution(rc_sample *s, touch_work *w, rch_poses_touch_result *res, const rch_poses_touch_config *c,
                         double (*sol)[RC_NJ], int ns, const double probe[3], rc_rng *g)
{
    int ok[RCH_IKG_MAX_SOL], n_ok = 0, why = 0;
    const double mg = c->margin_deg * DEG_, ws = sin(c->wrist_deg * DEG_);
    for (int i = 0; i < ns; ++i) {
        rc_sample t;
        memset(&t, 0, sizeof t);
        int in = 1;
        for (int j = 0; j < RC_NJ && in; ++j) {
            double q = round(sol[i][j] / DEG_ / STEP_DEG) * STEP_DEG * DEG_;
            for (int turn = -1; turn <= 1 && !(q >= w->m.q_min_rad[j] + mg && q <= w->m.q_max_rad[j] - mg); ++turn)
                q = round((sol[i][j] + turn * 2.0 * PI_) / DEG_ / STEP_DEG) * STEP_DEG * DEG_;
            in = q >= w->m.q_min_rad[j] + mg && q <= w->m.q_max_rad[j] - mg;
            t.q_rad[j] = q;
        }
        if (!in || fabs(sin(t.q_rad[4] + w->m.x[RC_P_THETA(4)])) < ws) {
            why = why < 1 ? 1 : why;
            continue;
        }
        double o[3], R[9];
        rc_fk(o, R, &w->m, t.q_rad);
        if (!outside_plates(w, c, o)) {
            why = why < 2 ? 2 : why;
            continue;
        }
        if (rch_cell_any(c->cell)) {
            rch_cell_verdict v;
            rch_cell_check(&v, c->cell, &w->m, t.q_rad, probe, c->tool_mm, 0.0);
            if (v.reason != RCH_CELL_SAFE) {
                why = 3;
                continue;
            }
        }
        memcpy(sol[i], t.q_rad, sizeof t.q_rad);
        ok[n_ok++] = i;
    }
    if (!n_ok) {
        ++*(why == 3 ? &res->rejected_cell : why == 2 ? &res->rejected_plate : &res->rejected_limits);
        return -1;
    }
    memcpy(s->q_rad, sol[ok[rc_rng_below(g, (uint32_t)n_ok)]], sizeof s->q_rad);
    return 0;
}

/* A point drawn on group gr's face (a plate's disc outside the block, or the block's top): p (3), height. */
static int draw_point(double p[3], double *height, const touch_work *w, const rch_poses_touch_config *c, unsigned gr,
                      rc_rng *g)
{
    const int top = gr == w->np;
    const unsigned k = top ? c->gauge_plate : gr;
    const double *centre = top && c->has_gauge_at ? c->gauge_at_mm : c->plates[k].point_mm;
    const double rad = 0.5 * (top ? c->gauge_size_mm : c->plates[k].size_mm) - c->edge_mm;
    double u[3], v[3];
    plane_axes(u, v, w->nrm[k]);
    const double r = rad * sqrt(rc_rng_u01(g)), a = 2.0 * PI_ * rc_rng_u01(g);
    *height = top ? c->gauge_mm : 0.0;
    for (int i = 0; i < 3; ++i)
        p[i] = centre[i] + r * (cos(a) * u[i] + sin(a) * v[i]) + *height * w->nrm[k][i];
    if (!top && c->gauge_mm > 0.0 && k == c->gauge_plate) { /* not under the block */
        const double *gc = c->has_gauge_at ? c->gauge_at_mm : c->plates[k].point_mm;
        double dd[3];
        for (int i = 0; i < 3; ++i)
            dd[i] = p[i] - gc[i];
        const double h = dot3(dd, w->nrm[k]);
        if (dot3(dd, dd) - h * h < pow(0.5 * c->gauge_size_mm * sqrt(2.0) + c->edge_mm, 2))
            return -1;
    }
    return 0;
}

/* The candidates: points on the faces, probe axes in the cone, joints by the IK. 0 or -1. */
static int touch_candidates(touch_work *w, rch_poses_touch_result *res, const rc_model *m0,
                            const rch_poses_touch_config *c, size_t want, FILE *progress, rch_diag *d)
{
    rch_ikg *ik = malloc(sizeof *ik);
    rc_rng g;
    rc_rng_seed(&g, c->seed);
    w->cand = malloc(want * sizeof *w->cand);
    w->group = malloc(want * sizeof *w->group);
    w->X = malloc(want * w->nf * sizeof *w->X);
    w->pt = malloc(want * 3 * sizeof *w->pt);
    if (!ik || !w->cand || !w->group || !w->X || !w->pt) {
        free(ik);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    if (rch_ikg_init(ik, m0, c->tool_mm) != RCH_IKG_OK) { /* the robot as its file gives it */
        free(ik);
        rch_diag_set(d, "", 0, 0, "the robot's table does not compile for the inverse kinematics");
        return -1;
    }
    const double cmin = cos(c->cone_deg * DEG_);
    size_t per_group[RCH_TOUCH_MAX_PLATES + 1] = {0};
    w->n_cand = 0;
    size_t draws = 0; /* a plate whose disc the block covers draws nothing: bounded here */
    while (w->n_cand < want && res->n_tried < 50 * want && ++draws < 200 * want) {
        unsigned gr = rc_rng_below(&g, w->np);
        if (c->gauge_mm > 0.0 && rc_rng_u01(&g) < c->gauge_share)
            gr = w->np;
        const unsigned k = gr == w->np ? c->gauge_plate : gr;
        rc_sample s;
        memset(&s, 0, sizeof s);
        double p[3], u[3], v[3], ax[3], x0[3], y0[3], R[9];
        if (draw_point(p, &s.value, w, c, gr, &g) != 0)
            continue;
        ++res->n_tried;
        plane_axes(u, v, w->nrm[k]);
        const double ct = cmin + (1.0 - cmin) * rc_rng_u01(&g), st = sqrt(1.0 - ct * ct), ph = 2.0 * PI_ * rc_rng_u01(&g);
        for (int i = 0; i < 3; ++i)
            ax[i] = -ct * w->nrm[k][i] + st * (cos(ph) * u[i] + sin(ph) * v[i]);
        plane_axes(x0, y0, ax);
        const double ps = 2.0 * PI_ * rc_rng_u01(&g);
        for (int i = 0; i < 3; ++i) { /* columns x, z x x, z (row-major) */
            const double xi = cos(ps) * x0[i] + sin(ps) * y0[i];
            R[3 * i] = xi;
            R[3 * i + 2] = ax[i];
        }
        for (int i = 0; i < 3; ++i) {
            const int a = (i + 1) % 3, b = (i + 2) % 3;
            R[3 * i + 1] = ax[a] * R[3 * b] - ax[b] * R[3 * a];
        }
        double sol[RCH_IKG_MAX_SOL][RC_NJ];
        int br[RCH_IKG_MAX_SOL];
        const int ns = rch_ikg_all(sol, br, ik, p, R);
        if (ns <= 0) {
            ++res->no_ik;
            continue;
        }
        if (pick_solution(&s, w, res, c, sol, ns, p, &g) != 0)
            continue;
        s.sensor = RC_SENSOR_PLANE;
        s.target = (uint8_t)k;
        if (touch_row(w->X + w->n_cand * w->nf, w, &s) != 0)
            continue;
        w->group[w->n_cand] = gr;
        memcpy(w->pt + 3 * w->n_cand, p, sizeof p);
        w->cand[w->n_cand++] = s;
        ++per_group[gr];
        rch_poses_progress(want >= 2000 ? progress : NULL, "touch candidate", w->n_cand - 1, want);
    }
    free(ik);
    for (unsigned gr = 0; gr < w->G; ++gr)
        if (per_group[gr] < w->quota[gr] || per_group[gr] == 0) {
            if (gr == w->np)
                rch_diag_set(d, "", 0, 0, "the gauge block on plate %u (%g mm high): %zu candidate touches of its top "
                             "for at least %zu: out of reach or against the limits; check --gauge-at, --cone-deg, "
                             "--tool", c->gauge_plate, c->gauge_mm, per_group[gr], w->quota[gr]);
            else
                rch_diag_set(d, "", 0, 0, "--plate %u (plate %u at %g,%g,%g): %zu candidate touches for at least %zu "
                             "(%zu points tried in all: %zu out of reach, %zu against the limits or the wrist, %zu "
                             "with the flange inside a plate, %zu against the cell); check its place, --cone-deg, "
                             "--tool", gr + 1, gr, c->plates[gr].point_mm[0], c->plates[gr].point_mm[1],
                             c->plates[gr].point_mm[2], per_group[gr], w->quota[gr], res->n_tried, res->no_ik,
                             res->rejected_limits, res->rejected_plate, res->rejected_cell);
            return -1;
        }
    if (w->n_cand < w->n) {
        rch_diag_set(d, "", 0, 0, "only %zu candidate touches for %zu: the plates are mostly out of reach", w->n_cand,
                     w->n);
        return -1;
    }
    return 0;
}

/* The probe's point of w's design: the touch_tip columns are the point model's tool offset's, the plates'
 * move no point. */
static rch_poses_point touch_point(const touch_work *w, int *col)
{
    for (unsigned a = 0; a < w->nf; ++a) {
        const int k = (int)w->fi[a];
        col[a] = k >= w->tip_first && k < w->tip_first + 3 ? w->tool_first + (k - w->tip_first)
                 : k < w->plane_first                      ? k
                                                           : -1;
    }
    const rch_poses_point pt = {&w->m, &w->mp, w->nf, col, w->sc};
    return pt;
}

static int touch_refresh(touch_work *w)
{
    return rch_poses_refresh(w->C, w->B, w->T, w->M, w->Q, w->nf);
}

/* How much one row x lowers phi = trace(Q M^-1): x^T B x / (1 + x^T C x). */
static double touch_gain(const touch_work *w, const double *x)
{
    const unsigned nf = w->nf;
    double sc = 0.0, sb = 0.0;
    for (unsigned a = 0; a < nf; ++a) {
        const double *ca = w->C + (size_t)a * nf, *ba = w->B + (size_t)a * nf;
        double su = 0.0, sv = 0.0;
        for (unsigned b = 0; b < nf; ++b) {
            su += ca[b] * x[b];
            sv += ba[b] * x[b];
        }
        sc += x[a] * su;
        sb += x[a] * sv;
    }
    return sb / (1.0 + sc);
}

/* Is candidate i at least its group's spacing from every design slot but skip (n_design slots), and, when
 * the group has two touches so far, as far from their line (three touches span the face)? */
static int spaced(const touch_work *w, size_t i, size_t n_design, size_t skip)
{
    const double *p = w->pt + 3 * i, sp = w->space[w->group[i]];
    const double *two[2] = {NULL, NULL};
    unsigned n_same = 0;
    for (size_t t = 0; t < n_design; ++t) {
        const size_t j = w->design[t];
        if (t == skip || w->group[j] != w->group[i])
            continue;
        const double *q = w->pt + 3 * j;
        if ((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]) < sp * sp)
            return 0;
        if (n_same < 2)
            two[n_same] = q;
        ++n_same;
    }
    if (n_same == 2) {
        double e[3], r[3], l2 = 0.0, h = 0.0, rr = 0.0;
        for (int k = 0; k < 3; ++k) {
            e[k] = two[1][k] - two[0][k];
            r[k] = p[k] - two[0][k];
            l2 += e[k] * e[k];
            h += e[k] * r[k];
            rr += r[k] * r[k];
        }
        if (l2 > 0.0 && rr - h * h / l2 < sp * sp)
            return 0;
    }
    return 1;
}

/* The best available candidate, among the groups short of their quota when the slots left (left) are needed,
 * spaced from the design's slots 0..n_design-1 but skip when one is (spread), else the best unspaced. */
static size_t touch_best(const touch_work *w, size_t left, size_t n_design, size_t skip)
{
    size_t deficit = 0, best = w->n_cand;
    double bg = -1.0;
    for (unsigned gr = 0; gr < w->G; ++gr)
        deficit += w->cnt[gr] < w->quota[gr] ? w->quota[gr] - w->cnt[gr] : 0;
    const int restrict_ = deficit >= left;
    for (int pass = 0; pass < 2 && best == w->n_cand; ++pass)
        for (size_t i = 0; i < w->n_cand; ++i) {
            if (w->in[i] || (restrict_ && w->cnt[w->group[i]] >= w->quota[w->group[i]]))
                continue;
            if (pass == 0 && !spaced(w, i, n_design, skip))
                continue;
            const double gi = touch_gain(w, w->X + i * w->nf);
            if (gi > bg) {
                bg = gi;
                best = i;
            }
        }
    return best;
}

static void touch_take(touch_work *w, size_t t, size_t i, int take)
{
    rch_poses_add_outer(w->M, w->X + i * w->nf, take ? 1.0 : -1.0, w->nf);
    w->in[i] = (unsigned char)take;
    w->cnt[w->group[i]] = take ? w->cnt[w->group[i]] + 1 : w->cnt[w->group[i]] - 1;
    if (take)
        w->design[t] = i;
}

/* Greedy with the quotas, then exchange passes that keep them. 0 or -1 (numeric). */
static int touch_design(touch_work *w, const rch_poses_touch_config *c, FILE *progress)
{
    rch_poses_prior_info(w->M, w->nf);
    for (size_t t = 0; t < w->n; ++t) {
        if (touch_refresh(w) != 0)
            return -1;
        const size_t best = touch_best(w, w->n - t, t, w->n);
        if (best >= w->n_cand)
            return -1;
        touch_take(w, t, best, 1);
        rch_poses_progress(w->n >= 200 ? progress : NULL, "touch design, touch", t, w->n);
    }
    for (unsigned long pass = 0; pass < c->passes; ++pass) {
        unsigned swaps = 0;
        for (size_t t = 0; t < w->n; ++t) {
            const size_t cur = w->design[t];
            touch_take(w, t, cur, 0);
            if (touch_refresh(w) != 0)
                return -1;
            const double gc = touch_gain(w, w->X + cur * w->nf);
            w->in[cur] = 1; /* not a candidate for its own slot */
            const size_t best = touch_best(w, 1, w->n, t);
            w->in[cur] = 0;
            if (best < w->n_cand && touch_gain(w, w->X + best * w->nf) > gc * (1.0 + 1e-9) + 1e-300) {
                touch_take(w, t, best, 1);
                ++swaps;
            } else {
                touch_take(w, t, cur, 1);
            }
        }
        if (!swaps)
            break;
    }
    return 0;
}

static void touch_info(double *M, const touch_work *w, const size_t *idx, size_t n)
{
    rch_poses_prior_info(M, w->nf);
    for (size_t t = 0; t < n; ++t)
        rch_poses_add_outer(M, w->X + idx[t] * w->nf, 1.0, w->nf);
}

/* Each plate's planned points at height 0: the smaller RMS spread of their nominal probe points in the face. */
static void touch_spread(rch_poses_touch_result *res, const touch_work *w)
{
    for (unsigned k = 0; k < w->np; ++k) {
        double u[3], v[3], su = 0, sv = 0, suu = 0, svv = 0, suv = 0;
        size_t n = 0;
        plane_axes(u, v, w->nrm[k]);
        for (size_t i = 0; i < res->n; ++i) {
            const rc_sample *s = &res->rows[i];
            if (s->target != k || s->value != 0.0)
                continue;
            double o[3], R[9], p[3];
            rc_fk(o, R, &w->m, s->q_rad);
            for (int r = 0; r < 3; ++r)
                p[r] = o[r] + R[3 * r] * w->m.x[w->tip_first] + R[3 * r + 1] * w->m.x[w->tip_first + 1] +
                       R[3 * r + 2] * w->m.x[w->tip_first + 2];
            const double a = dot3(p, u), b = dot3(p, v);
            su += a;
            sv += b;
            suu += a * a;
            svv += b * b;
            suv += a * b;
            ++n;
        }
        res->per_plate[k] = n;
        if (n < 2) {
            res->spread_mm[k] = 0.0;
            continue;
        }
        const double dn = (double)n;
        const double cu = suu / dn - su * su / dn / dn, cv = svv / dn - sv * sv / dn / dn,
                     cuv = suv / dn - su * sv / dn / dn;
        const double tr = 0.5 * (cu + cv), det = cu * cv - cuv * cuv, disc = sqrt(fmax(tr * tr - det, 0.0));
        res->spread_mm[k] = sqrt(fmax(tr - disc, 0.0));
    }
}

static void touch_free_work(touch_work *w)
{
    free(w->cand);
    free(w->group);
    free(w->X);
    free(w->pt);
    free(w->Q);
    free(w->M);
    free(w->C);
    free(w->B);
    free(w->T);
    free(w->design);
    free(w->rnd);
    free(w->in);
}

/* The rows in one tour from home (rch_poses_order: one session, the plate kept in group). 0 or -1. */
static int touch_order(rch_poses_touch_result *res, const rc_model *m, const rch_poses_touch_config *c, rch_diag *d)
{
    for (size_t i = 0; i < res->n; ++i) {
        res->rows[i].group = res->rows[i].target;
        res->rows[i].target = 0;
        res->rows[i].sensor = 0;
    }
    int rc = 0;
    if (c->keep_order)
        rch_poses_travel_of(&res->travel, res->rows, res->n, m, c->margin_deg);
    else
        rc = rch_poses_order(res->rows, res->n, m, c->margin_deg, &res->travel, d);
    for (size_t i = 0; i < res->n; ++i) {
        res->rows[i].target = (uint8_t)res->rows[i].group;
        res->rows[i].group = 0;
        res->rows[i].sensor = RC_SENSOR_PLANE;
    }
    return rc;
}

#define SEED_WORK 0x5851F42D4C957F2Dull
#define SEED_EVAL 0x2545F4914F6CDD1Dull

static int touch_run(rch_poses_touch_result *res, touch_work *w, const rc_model *m, const rch_poses_touch_config *c,
                     FILE *progress, rch_diag *d)
{
    size_t want = c->candidates ? c->candidates : (c->count * 40 > 2000 ? c->count * 40 : 2000);
    if (want < c->count || want > RCH_POSES_MAX_CANDIDATES) {
        rch_diag_set(d, "", 0, 0, "--candidates %zu: must be between --count (%zu) and %u", want, c->count,
                     RCH_POSES_MAX_CANDIDATES);
        return -1;
    }
    if (rch_poses_touch_check(m, c, d) != 0 || touch_setup(w, m, c, d) != 0)
        return -1;
    w->n = c->count;
    for (unsigned k = 0; k < w->np; ++k) { /* spacing: the usable disc shared out among the plan's touches */
        w->quota[k] = c->min_per_plate;
        const double r = 0.5 * c->plates[k].size_mm - c->edge_mm;
        w->space[k] = fmin(RCH_TOUCH_SPACING_MM, r / sqrt((double)c->count / w->G + 1.0));
    }
    if (c->gauge_mm > 0.0)
        w->space[w->np] = fmin(RCH_TOUCH_SPACING_MM, (0.5 * c->gauge_size_mm - c->edge_mm) /
                                                         sqrt(c->gauge_share * (double)c->count + 1.0));
    if (c->gauge_mm > 0.0) {
        const size_t share = (size_t)ceil(c->gauge_share * (double)c->count);
        w->quota[w->np] = share > 3 ? share : 3;
    }
    size_t need = 0;
    for (unsigned gr = 0; gr < w->G; ++gr)
        need += w->quota[gr];
    if (need > w->n) {
        rch_diag_set(d, "", 0, 0, "--count %zu: the quotas (%u per plate, %zu on the gauge block) need %zu", w->n,
                     c->min_per_plate, c->gauge_mm > 0.0 ? w->quota[w->np] : (size_t)0, need);
        return -1;
    }
    rch_poses_config cost;
    memset(&cost, 0, sizeof cost);
    cost.passes = c->passes;
    if (rch_poses_plan_cost(&cost, progress, w->n, want, w->nf, 0, d) != 0 ||
        touch_candidates(w, res, m, c, want, progress, d) != 0)
        return -1;
    const size_t mm = (size_t)w->nf * w->nf + 1; /* + 1: never malloc(0) */
    w->Q = malloc(mm * sizeof *w->Q);
    w->M = malloc(mm * sizeof *w->M);
    w->C = malloc(mm * sizeof *w->C);
    w->B = malloc(mm * sizeof *w->B);
    w->T = malloc(mm * sizeof *w->T);
    w->design = malloc(w->n * sizeof *w->design);
    w->rnd = malloc(w->n * sizeof *w->rnd);
    w->in = calloc(w->n_cand, 1);
    res->rows = malloc(w->n * sizeof *res->rows);
    if (!w->Q || !w->M || !w->C || !w->B || !w->T || !w->design || !w->rnd || !w->in || !res->rows) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    int col[RC_MAX_PARAMS];
    const rch_poses_point pt = touch_point(w, col);
    rch_poses_workspace_q(w->Q, &pt, c->n_work ? c->n_work : 300, c->seed ^ SEED_WORK);
    if (touch_design(w, c, progress) != 0) {
        rch_diag_set(d, "", 0, 0, "the design's information matrix is not positive definite (numeric failure)");
        return -1;
    }
    rc_rng g2; /* n random distinct candidates */
    rc_rng_seed(&g2, c->seed ^ 0x9E3779B97F4A7C15ull);
    memset(w->in, 0, w->n_cand);
    size_t rpp[RCH_TOUCH_MAX_PLATES] = {0};
    for (size_t t = 0; t < w->n; ++t) {
        size_t i;
        do
            i = rc_rng_below(&g2, (uint32_t)w->n_cand);
        while (w->in[i]);
        w->in[i] = 1;
        w->rnd[t] = i;
        if (w->cand[i].value == 0.0)
            ++rpp[w->cand[i].target];
    }
    res->random_per_plate_min = rpp[0];
    for (unsigned k = 1; k < w->np; ++k)
        res->random_per_plate_min = rpp[k] < res->random_per_plate_min ? rpp[k] : res->random_per_plate_min;
    const size_t n_eval = c->n_eval ? c->n_eval : 1000;
    touch_info(w->M, w, w->design, w->n);
    if (rch_poses_point_accuracy(&res->plan, &pt, w->M, n_eval, c->seed ^ SEED_EVAL) != 0)
        goto numeric;
    touch_info(w->M, w, w->rnd, w->n);
    if (rch_poses_point_accuracy(&res->random, &pt, w->M, n_eval, c->seed ^ SEED_EVAL) != 0)
        goto numeric;
    for (size_t t = 0; t < w->n; ++t)
        res->rows[t] = w->cand[w->design[t]];
    res->n = w->n;
    res->n_candidates = w->n_cand;
    res->n_params = w->m.n_params;
    res->nf = w->nf;
    touch_spread(res, w);
    for (size_t t = 0; t < res->n; ++t)
        res->gauge_rows += res->rows[t].value != 0.0;
    for (unsigned k = 0; k < w->np; ++k)
        if (res->spread_mm[k] < 1.0) {
            rch_diag_set(d, "", 0, 0, "plate %u: its %zu planned touches spread %.3f mm in their narrower direction "
                         "(at least 1 mm: the fit refuses less); raise --count or its size", k, res->per_plate[k],
                         res->spread_mm[k]);
            return -1;
        }
    return touch_order(res, m, c, d);
numeric:
    rch_diag_set(d, "", 0, 0, "the predicted accuracy could not be computed (numeric failure)");
    return -1;
}

int rch_poses_touch_plan(rch_poses_touch_result *res, const rc_model *m, const rch_poses_touch_config *c,
                         FILE *progress, rch_diag *d)
{
    touch_work *w = calloc(1, sizeof *w);
    memset(res, 0, sizeof *res);
    if (!w) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    const int rc = touch_run(res, w, m, c, progress, d);
    if (rc != 0)
        rch_poses_touch_free(res);
    touch_free_work(w);
    free(w);
    return rc;
}

void rch_poses_touch_free(rch_poses_touch_result *res)
{
    free(res->rows);
    memset(res, 0, sizeof *res);
}

int rch_poses_touch_write_csv(FILE *f, const rc_sample *rows, size_t n, int with_height)
{
    if (fprintf(f, "pose,plane,q1,q2,q3,q4,q5,q6%s\n", with_height ? ",height_mm" : "") < 0)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        if (fprintf(f, "%zu,%u", i, (unsigned)rows[i].target) < 0)
            return -1;
        for (int j = 0; j < RC_NJ; ++j)
            if (fprintf(f, ",%.4f", rows[i].q_rad[j] / DEG_) < 0)
                return -1;
        if (with_height && fprintf(f, ",%.3f", rows[i].value) < 0)
            return -1;
        if (fputc('\n', f) == EOF)
            return -1;
    }
    return 0;
}
