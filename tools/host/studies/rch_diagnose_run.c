/* SPDX-License-Identifier: MIT */
/* rch_diagnose_run.c - the `rcal diagnose` workflow (rch_diagnose_run):
 * poses and sensors, display steps and groups, the geometric fit, the noise
 * floor, the folds, the cross-validated geometry, the length jumps, the
 * search (rch_diagnose_search.c), the verdict and the per-sensor figures.
 * See rch_diagnose.h. */
#include "rch_diagnose_int.h"
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
#include "rch_positions.h"
#include "rch_start.h"
#include "rch_data.h"
#include "rch_jw.h"
#include "rch_plot.h"
#include "rch_resid.h"
#include "rch_robot.h"
#include "rch_stats.h"
#include "rch_sensors.h"

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

/* ------------------------------------------------------------- workflow */

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
        const rc_effect_desc *ds = rc_effect_describe(kind);
        if (ds && (ds->side == RC_SIDE_OUTLET || ds->side == RC_SIDE_SENSOR) && kind != RC_EFF_TRACKER_SCALE)
            continue; /* where the sensors stand: not an effect found */
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
            } else if (kind == RC_EFF_LENGTH_SCALE || kind == RC_EFF_OUTLET_SCALE || kind == RC_EFF_TRACKER_SCALE) {
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
    free(S->cls);
    free(S->c.pose);
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
    if (n < 10u * cfg->folds) {
        rch_diag_set(d, "", 0, 0, "%zu residual rows are too few to diagnose with %u folds (need at least %u)", n,
                     cfg->folds, 10u * cfg->folds);
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
    S->cls = calloc(n, 1);
    S->c.pose = calloc(n, sizeof *S->c.pose);
    S->base_folds = calloc(cfg->folds, sizeof *S->base_folds);
    S->cand_folds = calloc((size_t)RCH_DG_N_CANDS * cfg->folds, sizeof *S->cand_folds);
    S->cand_full = calloc(RCH_DG_N_CANDS, sizeof *S->cand_full);
    S->cand_res = calloc(RCH_DG_N_CANDS * n, sizeof *S->cand_res);
    if (!out->s || !out->res_before_mm || !out->res_after_mm || !out->floor_mm || !S->c.w || !S->c.fold ||
        !S->r0 || !S->tmp || !S->var || !S->order || !S->cls || !S->c.pose || !S->base_folds || !S->cand_folds || !S->cand_full ||
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

typedef struct {
    const rc_sample *s;
    size_t i;
} pose_key;

static int same_joints(const rc_sample *a, const rc_sample *b)
{
    for (unsigned j = 0; j < RC_NJ; ++j)
        if (a->q_rad[j] != b->q_rad[j])
            return 0;
    return 1;
}

static int cmp_pose(const void *a, const void *b)
{
    const pose_key *x = a, *y = b;
    for (unsigned j = 0; j < RC_NJ; ++j)
        if (x->s->q_rad[j] != y->s->q_rad[j])
            return x->s->q_rad[j] < y->s->q_rad[j] ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

/* The poses (samples with the same joint readings: the outlets and targets
 * of one pose, numbered by first appearance) and each sample's sensor: the
 * tracker, or the cable outlet it was measured from. 0 or -1 (memory). */
static int phase_sensors(run_state *S)
{
    rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    pose_key *k = malloc((n ? n : 1) * sizeof *k);
    size_t *first = malloc((n ? n : 1) * sizeof *first);
    if (!k || !first) {
        free(k);
        free(first);
        return -1;
    }
    for (size_t i = 0; i < n; ++i) {
        k[i].s = &out->s[i];
        k[i].i = i;
    }
    qsort(k, n, sizeof *k, cmp_pose);
    for (size_t a = 0, b; a < n; a = b) { /* a run of equal joints: its first sample in file order */
        for (b = a + 1; b < n && same_joints(k[b].s, k[a].s); ++b)
            ;
        for (size_t j = a; j < b; ++j)
            first[k[j].i] = k[a].i;
    }
    size_t next = 0;
    for (size_t i = 0; i < n; ++i)
        S->c.pose[i] = first[i] == i ? (unsigned)next++ : S->c.pose[first[i]];
    S->c.n_poses = out->n_poses = next;
    free(k);
    free(first);
    /* a class per cable outlet, one for the tracker (its three coordinates), one per other sensor kind */
    int slot[RC_MAX_OUTLETS + RC_SENSOR_COUNT_];
    for (unsigned j = 0; j < RC_MAX_OUTLETS + RC_SENSOR_COUNT_; ++j)
        slot[j] = -1;
    for (size_t i = 0; i < n; ++i) {
        const int tr = out->s[i].sensor != RC_SENSOR_LENGTH;
        const unsigned key = tr ? RC_MAX_OUTLETS + rch_dg_sensor_class(&out->s[i]) % RC_SENSOR_COUNT_
                                : out->s[i].outlet % RC_MAX_OUTLETS;
        if (slot[key] < 0 && out->n_sensors < RCH_DIAGNOSE_MAX_SENSORS) {
            rch_diagnose_sensor *z = &out->sensors[out->n_sensors];
            z->tracker = tr;
            z->label = tr ? 0u : key;
            slot[key] = (int)out->n_sensors++;
        }
        S->cls[i] = (uint8_t)(slot[key] < 0 ? 0 : slot[key]);
        out->sensors[S->cls[i]].rows++;
        out->n_tracker += (size_t)tr;
        out->n_cable += (size_t)!tr;
    }
    unsigned outlets = 0; /* the cable's classes */
    for (unsigned j = 0; j < out->n_sensors; ++j)
        outlets += !out->sensors[j].tracker;
    for (unsigned j = 0; j < out->n_sensors; ++j) {
        rch_diagnose_sensor *z = &out->sensors[j];
        const rch_sensor_desc *sd = NULL; /* another sensor of the table (rch_sensors.h): a row a sample */
        for (size_t i = 0; z->tracker && i < n && !sd; ++i)
            if (S->cls[i] == j)
                sd = rch_sensor_of_kind(out->s[i].sensor);
        snprintf(z->kind, sizeof z->kind, "%s", sd ? sd->name : z->tracker ? "tracker" : "cable");
        if (sd) {
            snprintf(z->name, sizeof z->name, "%s", sd->name);
        } else if (z->tracker) {
            z->rows /= 3;
            snprintf(z->name, sizeof z->name, "tracker");
        } else if (outlets > 1) {
            snprintf(z->name, sizeof z->name, "cable outlet %u", z->label);
        } else {
            snprintf(z->name, sizeof z->name, "cable");
        }
    }
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
    size_t nl = 0; /* the lengths' step (a tracker's coordinates have none) */
    for (size_t i = 0; i < n; ++i)
        if (out->s[i].sensor == RC_SENSOR_LENGTH)
            S->tmp[nl++] = out->s[i].value;
    out->len_step_mm = S->cfg.len_step_mm > 0.0   ? S->cfg.len_step_mm
                       : S->cfg.len_step_mm < 0.0 || nl == 0 ? 0.0
                                                             : rch_dequant_detect_step(S->tmp, nl);
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
    if (!S->cfg.keep_effects) {
        geometry.n_effects = 0;
        geometry.n_params = RC_N_BASE;
    }
    for (unsigned e = 0; e < geometry.n_effects; ++e) {
        const rc_effect_desc *ds = rc_effect_describe(geometry.effects[e].kind);
        if (ds && ds->side != RC_SIDE_OUTLET && ds->side != RC_SIDE_SENSOR)
            out->n_known++;
    }
    if (rch_calib_bc(&out->geo, S->c.w, &geometry, S->cfg.have_encoder, out->s, out->n, d) != 0)
        return -1;
    memset(S->c.fixed0, 0, sizeof S->c.fixed0); /* what no sample sees: an encoder without lengths, a target unseen */
    rch_pos_fix_unseen(S->c.fixed0, &out->geo, out->s, out->n);
    unsigned n_free = 0;
    for (unsigned k = 0; k < out->geo.n_params; ++k) {
        S->c.have_fixed |= S->c.fixed0[k];
        n_free += !S->c.fixed0[k];
    }
    const size_t need = 2u * n_free + 6u > 10u * S->cfg.folds ? 2u * n_free + 6u : 10u * S->cfg.folds;
    if (out->n < need || out->n_poses < 2u * S->cfg.folds) {
        rch_diag_set(d, "", 0, 0,
                     "%zu residual rows of %zu poses are too few to diagnose %u free parameters with %u folds (need at "
                     "least %zu rows, twice the parameters and 6 more, and %u poses)",
                     out->n, out->n_poses, n_free, S->cfg.folds, need, 2u * S->cfg.folds);
        return -1;
    }
    if (rch_dg_fit(&out->geo, &res, &S->c, NULL, out->s, out->n) != 0) {
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
            rch_diag_set(d, "", 0, 0, "sample %zu: the model cannot predict it (the flange at an outlet)", i + 1);
            return -1;
        }
        for (unsigned j = 0; j < RC_NJ; ++j)
            sq += jac[RC_P_THETA(j)] * jac[RC_P_THETA(j)];
        const int tracker = out->s[i].sensor != RC_SENSOR_LENGTH;
        const double viq = sq * qs * qs / 12.0, vil = tracker ? 0.0 : ls * ls / 12.0 + ln * ln;
        out->floor_mm[i] = sqrt(viq + vil);
        vq += viq;
        vl += vil;
        if (tracker) { /* the position in the tracker's frame: its distance and direction from the tracker */
            for (unsigned k = 0; k < 3; ++k) {
                rc_sample c = out->s[i];
                c.sensor = (uint8_t)(RC_SENSOR_TRACKER_X + k);
                if (rc_meas(&u[k], NULL, g, &c) != RC_OK)
                    u[k] = 0.0;
            }
        } else {
            const double *e = &g->x[RC_P_ENC];
            for (unsigned k = 0; out->s[i].outlet && k < g->n_effects; ++k)
                if (g->effects[k].kind == RC_EFF_OUTLET && g->effects[k].joint == out->s[i].outlet)
                    e = &g->x[g->effects[k].first];
            rc_fk(p, NULL, g, out->s[i].q_rad);
            for (unsigned k = 0; k < 3; ++k)
                u[k] = p[k] - e[k];
        }
        for (unsigned k = 0; k < 3; ++k)
            nu += u[k] * u[k];
        nu = nu > 0.0 ? sqrt(nu) : 1.0;
        S->var[i][V_LEV2] = rc_gravity_lever_m((const double(*)[4])ref, 1, out->s[i].q_rad);
        S->var[i][V_LEV3] = rc_gravity_lever_m((const double(*)[4])ref, 2, out->s[i].q_rad);
        S->var[i][V_LEN] = tracker ? nu : out->s[i].value;
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

/* Fold of every sample: the groups in shuffled order, within each group its
 * poses in shuffled order, dealt round-robin (the counter runs on across
 * groups); every sample of a pose (its outlets, its targets' coordinates) in
 * its pose's fold. 0 or -1 (out of memory). */
static int assign_folds(run_state *S)
{
    const rch_diagnose_result *out = S->out;
    const size_t n = out->n, np = S->c.n_poses;
    const unsigned ng = out->n_groups;
    rc_rng rng;
    rc_rng_seed(&rng, S->cfg.seed ^ 0x6469616700000000ull);
    for (size_t p = 0; p < np; ++p)
        S->order[p] = (unsigned)p;
    shuffle(S->order, np, &rng);
    unsigned *gorder = calloc(ng ? ng : 1, sizeof *gorder), *byg = calloc(np ? np : 1, sizeof *byg);
    unsigned *pgroup = calloc(np ? np : 1, sizeof *pgroup), *pfold = calloc(np ? np : 1, sizeof *pfold);
    size_t *start = calloc((size_t)ng + 1, sizeof *start), *pos = calloc(ng ? ng : 1, sizeof *pos);
    int rc = -1;
    if (!gorder || !byg || !pgroup || !pfold || !start || !pos)
        goto done;
    for (size_t i = n; i-- > 0;) /* a pose's group: its first sample's */
        pgroup[S->c.pose[i]] = out->s[i].group < ng ? out->s[i].group : 0u;
    for (unsigned g = 0; g < ng; ++g)
        gorder[g] = g;
    shuffle(gorder, ng, &rng);
    for (size_t p = 0; p < np; ++p) /* bucket the poses by group, in shuffled order */
        start[pgroup[p] + 1]++;
    for (unsigned g = 0; g < ng; ++g)
        start[g + 1] += start[g];
    for (size_t p = 0; p < np; ++p) {
        const unsigned q = S->order[p], g = pgroup[q];
        byg[start[g] + pos[g]++] = q;
    }
    unsigned counter = 0;
    for (unsigned gi = 0; gi < ng; ++gi)
        for (size_t p = start[gorder[gi]]; p < start[gorder[gi] + 1]; ++p)
            pfold[byg[p]] = counter++ % S->c.k;
    for (size_t i = 0; i < n; ++i) /* every sample of a pose in its pose's fold */
        S->c.fold[i] = pfold[S->c.pose[i]];
    rc = 0;
done:
    free(gorder);
    free(byg);
    free(pgroup);
    free(pfold);
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
    if (rch_dg_cv_run(S->base_folds, S->r0, &S->c) != 0) {
        rch_diag_set(d, "", 0, 0, "a cross-validation fit failed");
        return -1;
    }
    memcpy(out->res_before_mm, S->r0, n * sizeof *S->r0);
    out->rmse_before_mm = rch_rms(S->r0, n);
    out->n_tests = rch_dg_sensor_tests(out->before, S->r0, out->s, n, (const double(*)[V_N])S->var, out->n_groups,
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
            r[m] = l - s[i].value;
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

/* The jumps rcal calibrate fitted on the same inputs (cfg.jumps_given):
 * their change points and sizes into out->jumps, the segments' offsets
 * removed from the lengths (the folds' training copies too). */
static void given_jumps(run_state *S)
{
    rch_diagnose_result *out = S->out;
    const rch_diagnose_cfg *cfg = &S->cfg;
    rch_jumps *j = &out->jumps;
    memset(j, 0, sizeof *j);
    j->n_jumps = cfg->n_given_jumps < RCH_JUMPS_MAX ? cfg->n_given_jumps : RCH_JUMPS_MAX;
    for (unsigned k = 0; k < j->n_jumps; ++k) {
        size_t a = 0;
        while (a < out->n && out->s[a].t < cfg->given_jump_t[k])
            ++a;
        j->at[k] = a;
        j->at_t[k] = cfg->given_jump_t[k];
        j->size_mm[k] = cfg->given_jump_mm[k];
        j->se_mm[k] = cfg->given_jump_se_mm[k];
    }
    for (size_t i = 0; i < out->n; ++i)
        out->s[i].value -= cfg->given_offset_mm[rch_jumps_segment(j, out->s[i].t)];
    for (unsigned f = 0; f < S->c.k; ++f)
        for (size_t i = 0; i < S->c.n_train[f]; ++i)
            S->c.train[f][i].value -= cfg->given_offset_mm[rch_jumps_segment(j, S->c.train[f][i].t)];
}

/* 4b. Length jumps in acquisition order: rcal calibrate's (cfg.jumps_given,
 * from rch_diagnose_inputs), or found here (rch_diagnose_run on samples),
 * removed from the lengths (a nuisance), geometry refitted and
 * cross-validated again. Those above cfg.jump_max_mm are counted. */
static int phase_jumps(run_state *S, rch_diag *d)
{
    rch_diagnose_result *out = S->out;
    const size_t n = out->n;
    char err[256];
    out->jump_max_mm = S->cfg.jump_max_mm > 0.0 ? S->cfg.jump_max_mm : 10.0;
    out->jumps_asked = S->cfg.jumps;
    if (S->cfg.jumps_given) { /* rcal calibrate's jumps: its search and its rule decided */
        out->jumps_by_calibrate = 1;
        if (S->cfg.n_given_jumps == 0)
            return 0;
        given_jumps(S);
        for (unsigned k = 0; k < out->jumps.n_jumps; ++k)
            out->jumps_implausible += fabs(out->jumps.size_mm[k]) > out->jump_max_mm;
        rc_solve_result res;
        if (rch_dg_fit(&out->geo, &res, &S->c, NULL, out->s, n) != 0) {
            rch_diag_set(d, "", 0, 0, "the geometric fit failed (after removing the length jumps)");
            return -1;
        }
        out->jumps.geometry = out->geo;
        out->jumps.rms_after_mm = res.rms_final_mm;
        for (unsigned f = 0; f < S->c.k; ++f)
            S->base_folds[f] = out->geo;
        if (rch_dg_cv_run(S->base_folds, S->r0, &S->c) != 0) {
            rch_diag_set(d, "", 0, 0, "a cross-validation fit failed (after removing the length jumps)");
            return -1;
        }
        out->rmse_jumps_mm = rch_rms(S->r0, n);
        return 0;
    }
    if (S->cfg.no_jumps || out->n_tracker > 0 || (out->n_sensors > 1 && !S->cfg.jumps))
        return 0; /* a tracker's coordinates do not jump like a display's count; several outlets' rows
                     interleave in acquisition order (their jumps only when --jumps says so) */
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
        inside += S->cfg.jumps || big_alone || (!near && sharp_step(&out->jumps.geometry, out->s, n, a, out->jumps.size_mm[k]));
        out->jumps_at_setup_change += (unsigned)(near && !big_alone && !S->cfg.jumps);
    }
    if (inside == 0) {
        out->jumps_confounded = out->jumps.n_jumps;
        out->jumps.n_jumps = 0;
        return 0;
    }
    for (unsigned k = 0; k < out->jumps.n_jumps; ++k)
        out->jumps_implausible += fabs(out->jumps.size_mm[k]) > out->jump_max_mm;
    const rc_effect *e = &out->jumps.model.effects[out->jumps.model.n_effects - 1];
    for (size_t i = 0; i < n; ++i)
        out->s[i].value -= out->jumps.model.x[e->first + rch_jumps_segment(&out->jumps, out->s[i].t)];
    for (unsigned f = 0; f < S->c.k; ++f) /* the folds' training copies too */
        for (size_t i = 0; i < S->c.n_train[f]; ++i)
            S->c.train[f][i].value -=
                out->jumps.model.x[e->first + rch_jumps_segment(&out->jumps, S->c.train[f][i].t)];
    out->geo = out->jumps.geometry;
    for (unsigned f = 0; f < S->c.k; ++f)
        S->base_folds[f] = out->geo;
    if (rch_dg_cv_run(S->base_folds, S->r0, &S->c) != 0) {
        rch_diag_set(d, "", 0, 0, "a cross-validation fit failed (after removing the length jumps)");
        return -1;
    }
    out->rmse_jumps_mm = rch_rms(S->r0, n);
    if (S->cfg.verbose)
        fprintf(stderr, "diagnose: %u length jumps; geometry held-out RMSE %.4f mm without them\n",
                out->jumps.n_jumps, out->rmse_jumps_mm);
    return 0;
}


/* 6. The final model's held-out residuals, structure tests and verdict. */
static void phase_after(run_state *S)
{
    rch_diagnose_result *out = S->out;
    size_t pos = 0;
    int unexpl = 0;
    memcpy(out->res_after_mm, S->r0, out->n * sizeof *S->r0);
    out->rmse_after_mm = rch_rms(S->r0, out->n);
    rch_dg_sensor_tests(out->after, S->r0, out->s, out->n, (const double(*)[V_N])S->var, out->n_groups, S->cfg.alpha);
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
    if (out->jumps.n_jumps > 0 && !S->cfg.jumps) { /* with --jumps they are known: not the verdict */
        snprintf(out->effect, sizeof out->effect, "length_jump");
        out->joint = 0;
    } else if (out->n_chosen == 0) {
        snprintf(out->effect, sizeof out->effect, "%s", unexpl ? "unexplained" : "none");
        out->joint = 0;
    }
}

/* Per sensor: held-out RMS before and after and the floor (3-D for the
 * tracker: the root of the mean squared distance over its position rows). */
static void sensor_figures(run_state *S)
{
    rch_diagnose_result *out = S->out;
    double b[RCH_DIAGNOSE_MAX_SENSORS] = {0}, a[RCH_DIAGNOSE_MAX_SENSORS] = {0}, f[RCH_DIAGNOSE_MAX_SENSORS] = {0};
    for (size_t i = 0; i < out->n; ++i) {
        const unsigned k = S->cls[i];
        b[k] += out->res_before_mm[i] * out->res_before_mm[i];
        a[k] += out->res_after_mm[i] * out->res_after_mm[i];
        f[k] += out->floor_mm[i] * out->floor_mm[i];
    }
    for (unsigned k = 0; k < out->n_sensors; ++k) {
        rch_diagnose_sensor *z = &out->sensors[k];
        const double rows = z->rows ? (double)z->rows : 1.0;
        z->before_mm = sqrt(b[k] / rows);
        z->after_mm = sqrt(a[k] / rows);
        z->floor_mm = sqrt(f[k] / rows);
    }
}

/* 7. Effect parameters (fold jackknife), the effects' size, and the notes on
 * what cable lengths cannot identify. */
static void phase_report(run_state *S)
{
    rch_diagnose_result *out = S->out;
    report_params(out, S->base_folds, S->c.k);
    /* the chosen effects alone set to zero: the outlets' and the tracker's
     * places, the attachment and the geometry stay (zeroing an outlet's
     * place would count metres of "effect") */
    rc_model z = out->final;
    for (unsigned e = 0; e < z.n_effects; ++e) {
        int chosen = 0;
        for (unsigned st = 0; st < out->n_steps; ++st) {
            const rch_diagnose_step *sp = &out->steps[st];
            if (sp->chosen < 0)
                continue;
            const rch_diagnose_cand *c = &sp->cand[sp->chosen];
            chosen |= z.effects[e].kind == (uint8_t)c->kind &&
                      (c->joint == 0 || (unsigned)z.effects[e].joint + 1 == c->joint);
        }
        for (unsigned p = 0; chosen && p < z.effects[e].count; ++p)
            z.x[z.effects[e].first + p] = 0.0;
    }
    double s2 = 0.0;
    for (size_t i = 0; i < out->n; ++i) {
        double la, lb;
        if (rc_meas(&la, NULL, &out->final, &out->s[i]) == RC_OK && rc_meas(&lb, NULL, &z, &out->s[i]) == RC_OK)
            s2 += (la - lb) * (la - lb);
    }
    out->effect_rms_mm = sqrt(s2 / (double)out->n);
    if (out->n_tracker == 0 && out->n_sensors == 1)
        scale_note(out); /* one outlet: the encoder scale against the robot's size */
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
    if (rc == 0 && phase_sensors(&S) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        rc = -1;
    }
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
        rch_dg_phase_search(&S);
        phase_after(&S);
        sensor_figures(&S);
        phase_report(&S);
    }
    out->time_ms = now_ms() - t0;
    run_free(&S);
    return rc;
}
