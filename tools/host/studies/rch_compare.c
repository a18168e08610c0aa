/* SPDX-License-Identifier: MIT */
/* rch_compare.c - the seven-method comparison protocol (the cases, each
 * method's fit, the summary); its reports are rch_compare_out.c. See
 * rch_compare.h. */
#include "rch_compare.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rch_calib.h"
#include "rch_calib_effects.h"
#include "rch_start.h"
#include "rch_cost.h"
#include "rch_eval.h"
#include "rch_jumps.h"
#include "rch_prior.h"
#include "rch_jw.h"
#include "rch_plot.h"
#include "rch_resid.h"
#include "rch_save.h"
#include "rch_uncert.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

void rch_compare_defaults(rch_compare_config *cfg)
{
    const rch_compare_config def = {.cases = 10, .samples = 300, .test_fraction = 0.1, .seed = 1};
    *cfg = def;
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        cfg->run[i] = 1; /* the seven; the paper variants with --literal */
}

const double rch_compare_table6[8][3] = {{2.18, 2.01, 3.42}, {0.36, 0.30, 0.91}, {0.63, 0.51, 1.52},
                                         {0.73, 0.61, 1.77}, {0.82, 0.66, 1.96}, {0.50, 0.40, 1.31},
                                         {0.34, 0.28, 0.85}, {0.32, 0.26, 0.83}};

int rch_compare_methods(int run[RCH_EST_ALL], const char *list, rch_diag *d)
{
    char buf[256];
    size_t n_sel = 0;
    if (strlen(list) >= sizeof buf) {
        rch_diag_set(d, "", 0, 0, "--methods: list longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    for (int i = 0; i < RCH_EST_ALL; ++i)
        run[i] = 0;
    memcpy(buf, list, strlen(list) + 1);
    for (char *tok = buf, *next; tok; tok = next) {
        int id;
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        id = rch_est_parse(tok);
        if (id < 0) {
            rch_diag_set(d, "", 0, 0,
                         "--methods: %s '%s' (LM, EKF, PF, SCA, QIBAS, SSLM, LTLM or M1..M7, LM-paper, "
                         "LM-paper-deg, LTLM-paper, LTLM-paper-deg)",
                         *tok ? "unknown method" : "empty method name in", *tok ? tok : list);
            return -1;
        }
        run[id] = 1;
        ++n_sel;
    }
    return n_sel ? 0 : -1;
}

const char *rch_compare_params_name(rch_compare_params p) { return p == RCH_PARAMS_COMMON ? "common" : "paper"; }

void rch_compare_model_file(char *buf, size_t len, int row)
{
    if (row <= 0)
        snprintf(buf, len, "BC.json");
    else
        snprintf(buf, len, "M%d-%s.json", rch_est_paper_row((rch_est_id)(row - 1)), rch_est_name((rch_est_id)(row - 1)));
}

size_t rch_compare_model_list(char (*paths)[RCH_COMPARE_PATH_MAX], char (*names)[32], const char *dir)
{
    size_t n = 0;
    for (int r = 1; r < RCH_COMPARE_ROWS; ++r) {
        char file[64];
        rch_compare_model_file(file, sizeof file, r);
        snprintf(paths[n], RCH_COMPARE_PATH_MAX, "%s/%s", dir, file);
        FILE *f = fopen(paths[n], "r");
        if (!f)
            continue; /* a method compare did not run */
        fclose(f);
        snprintf(names[n], 32, "M%d %s", rch_est_paper_row((rch_est_id)(r - 1)), rch_est_name((rch_est_id)(r - 1)));
        ++n;
    }
    return n;
}

const char *rch_compare_row_name(int row) { return row == 0 ? "BC" : rch_est_name((rch_est_id)(row - 1)); }

double rch_compare_lm_time_ms(const rch_compare_result *res)
{
    const rch_compare_row *r = &res->row[RCH_EST_LM + 1];
    return r->used && r->time_ms.n > 0 ? r->time_ms.mean : NAN;
}

int rch_compare_any_failed(const rch_compare_result *res)
{
    for (int r = 1; r < RCH_COMPARE_ROWS; ++r)
        if (res->row[r].used && res->row[r].failed)
            return 1;
    return 0;
}

void rch_compare_free(rch_compare_result *res)
{
    for (int id = 0; id < RCH_EST_ALL; ++id)
        rch_curve_free(&res->curve[id]);
    free(res->cell);
    free(res->err_case1_mm);
    free(res->idx_case1);
    free(res->model_case1);
    res->cell = NULL;
    res->err_case1_mm = NULL;
    res->idx_case1 = NULL;
    res->model_case1 = NULL;
}

/* err (n): model - measured length of every sample, NaN where m fails. */
static void sample_errors(double *err, const rc_model *m, const rc_sample *s, size_t n)
{
    for (size_t k = 0; k < n; ++k) {
        double l;
        err[k] = rc_meas(&l, NULL, m, &s[k]) == RC_OK ? l - s[k].value : NAN;
    }
}

/* Row statistics over the cases, from the per-case cells (ok cells only). */
static void summarise(rch_compare_result *res)
{
    for (int r = 0; r < RCH_COMPARE_ROWS; ++r) {
        rch_compare_row *row = &res->row[r];
        for (unsigned long c = 0; c < res->cases && row->used; ++c) {
            const rch_compare_cell *e = &res->cell[c * RCH_COMPARE_ROWS + (size_t)r];
            if (!e->ok) {
                row->failed++;
                continue;
            }
            rch_stats_add(&row->rmse_mm, e->held_out.rmse_mm);
            rch_stats_add(&row->mean_abs_mm, e->held_out.mean_abs_mm);
            rch_stats_add(&row->max_mm, e->held_out.max_mm);
            if (isfinite(e->train_rmse_mm))
                rch_stats_add(&row->train_rmse_mm, e->train_rmse_mm);
            if (r == 0)
                continue; /* BC: no identification */
            rch_stats_add(&row->time_ms, e->time_ms);
            rch_stats_add(&row->iterations, (double)e->iterations);
            rch_stats_add(&row->cost_evals, (double)e->cost_evals);
            rch_stats_add(&row->n_moved, (double)e->n_moved);
            rch_stats_add(&row->dlen_max_mm, e->dlen_max_mm);
            rch_stats_add(&row->dang_max_deg, e->dang_max_deg);
            rch_stats_add(&row->n_jumps, (double)e->n_jumps);
        }
    }
}

static void add_ltlm(rch_compare_result *res, const rc_model *m)
{
    for (unsigned j = 0; j < RC_NJ; ++j)
        for (unsigned k = 0; k < 4; ++k)
            rch_stats_add(&res->ltlm_dh[j][k], m->x[4 * j + k] / (k >= 2 ? DEG : 1.0));
    for (unsigned k = 0; k < 3; ++k)
        rch_stats_add(&res->ltlm_enc_mm[k], m->x[RC_P_ENC + k]);
    res->n_ltlm++;
}

/* ---- model files (rcal compare --models DIR) ---------------------------- */

typedef struct model_job {
    const char *name;            /* the robot's name */
    const rc_model *m, *nominal;
    const rch_robot_info *info;
} model_job;

typedef struct model_note {
    const char *row, *params;
    unsigned long long seed;
    size_t n_train, n_test;
    double train_rmse_mm, test_rmse_mm;
} model_note;

static void model_note_write(rch_jw *w, const void *ctx)
{
    const model_note *n = ctx;
    rch_jw_str(w, "source", "rcal compare, case 1");
    rch_jw_str(w, "method", n->row);
    rch_jw_str(w, "params", n->params);
    rch_jw_uint(w, "seed", n->seed);
    rch_jw_uint(w, "n_train", n->n_train);
    rch_jw_uint(w, "n_test", n->n_test);
    rch_jw_numf(w, "train_rmse_mm", n->train_rmse_mm, "%.6f");
    rch_jw_numf(w, "held_out_rmse_mm", n->test_rmse_mm, "%.6f");
}

static int model_write_fn(FILE *f, const void *ctx)
{
    const model_job *j = ctx;
    return rch_robot_write(f, j->name, j->m, j->nominal, j->info);
}

/* Row r's model of case 1 into cfg->models_dir: rcal-model/2 with the
 * uncertainty at the fit (classical covariance over the training samples,
 * the parameters the row's set holds fixed counted as fixed); version 1 when
 * the covariance cannot be computed. 0, or -1 with d set. */
static int save_row_model(const rch_compare_config *cfg, const rch_robot *robot, const rc_model *m, int r,
                          const uint8_t *fixed, const rch_holdout *h, const rch_compare_cell *cell, rch_diag *d)
{
    char name[64], path[1200];
    rch_uncert u;
    char err[256];
    static rch_model_unc unc;
    const model_note note = {rch_compare_row_name(r), rch_compare_params_name(cfg->params), cfg->seed * 1000003ull,
                             h->n_train, h->n_test, cell->train_rmse_mm, cell->held_out.rmse_mm};
    rch_robot_info info;
    memset(&info, 0, sizeof info);
    info.write = model_note_write;
    info.ctx = &note;
    if (rch_uncert_compute(&u, m, fixed, h->train, h->n_train, 0, err, sizeof err) == 0) {
        memset(&unc, 0, sizeof unc);
        rch_model_unc_from(&unc, &u);
        if (rch_uncert_map_compute(&unc.map, &u, m, h->train, h->n_train, RCH_CALIB_TRUTH_POSES,
                                   RCH_CALIB_TRUTH_SEED) == 0) {
            unc.orientation_determined = unc.map.rot_det_median_deg < RCH_ORIENT_DETERMINED_DEG;
            info.unc = &unc;
        }
        rch_uncert_free(&u);
    }
    rch_compare_model_file(name, sizeof name, r);
    snprintf(path, sizeof path, "%s/%s", cfg->models_dir, name);
    const model_job job = {robot->name, m, &robot->nominal, &info};
    return rch_save(path, "--models", cfg->inputs, cfg->n_inputs, model_write_fn, &job, d);
}

/* The largest |a, d - nominal| (mm) and |alpha, theta - nominal| (deg) of m. */
static void param_deltas(rch_compare_cell *e, const rc_model *m, const rc_model *nominal)
{
    e->dlen_max_mm = e->dang_max_deg = 0.0;
    for (unsigned k = 0; k < RC_N_DH; ++k) {
        double dv = m->x[k] - nominal->x[k];
        if (k % 4 >= 2) {
            dv = remainder(dv, 2.0 * M_PI) / DEG;
            if (fabs(dv) > e->dang_max_deg)
                e->dang_max_deg = fabs(dv);
        } else if (fabs(dv) > e->dlen_max_mm) {
            e->dlen_max_mm = fabs(dv);
        }
    }
}

static int cmp_t(const void *a, const void *b)
{
    const double x = ((const rc_sample *)a)->t, y = ((const rc_sample *)b)->t;
    return (x > y) - (x < y);
}

/* What a case shares between its methods. */
typedef struct case_ctx {
    rc_sample *sorted;  /* (n_train) training rows in acquisition order (--jumps) */
    rc_sample *lab;     /* (n_train) training rows, labelled by the reference segments */
    rc_sample *test;    /* (n_test) held-out rows, relabelled per model */
    rch_jumps ref;      /* --jumps: the robust LM's search (change points of the rc_est methods) */
    double mean[RC_MAX_PARAMS], sd[RC_MAX_PARAMS]; /* --prior */
    uint8_t fixed_prior[RC_MAX_PARAMS];            /* --prior: the set's fixed plus the gauge */
} case_ctx;

/* Held-out rows placed in the segments of j (acquisition time); no jumps: as drawn. */
static void label_test(case_ctx *cx, const rch_holdout *h, const rch_jumps *j)
{
    memcpy(cx->test, h->test, h->n_test * sizeof *cx->test);
    for (size_t i = 0; j && i < h->n_test; ++i)
        cx->test[i].group = (uint16_t)rch_jumps_segment(j, cx->test[i].t);
}

/* Method id from start on the case's training rows, honouring --jumps:
 * m = the fitted model (with the segment offsets), *jused = its change
 * points (NULL without jumps). */
static rc_status run_method(rc_model *m, rch_est_out *out, rch_jumps *jm, const rch_jumps **jused, rch_curve *curve,
                            rch_est_ws *ws, rch_est_id id, uint64_t seed, const rch_est_opts *eo,
                            const rch_compare_config *cfg, case_ctx *cx, const rch_holdout *h)
{
    *jused = NULL;
    if (!cfg->jumps)
        return rch_est_run(m, out, curve, ws, id, seed, eo, h->train, h->n_train);
    if (rch_est_is_solve(id)) { /* the method runs the jump search itself */
        rc_solve_config sc;
        rch_jumps_config jc;
        char err[256];
        struct timespec t0, t1;
        rch_est_solve_config(&sc, id, seed, eo);
        memset(&jc, 0, sizeof jc);
        jc.solve = &sc;
        memset(out, 0, sizeof *out);
        clock_gettime(CLOCK_MONOTONIC, &t0);
        const int jr = rch_jumps_find(jm, m, eo->fixed, cx->sorted, h->n_train, &jc, &ws->solve, err, sizeof err);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        if (jr != 0)
            return RC_ERR_NUMERIC;
        out->time_ms = (double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) / 1e6;
        out->rms_start_mm = jm->rms_before_mm;
        out->rms_final_mm = jm->rms_after_mm;
        *m = jm->model;
        *jused = jm;
        return RC_OK;
    }
    /* the rc_est methods: the reference change points, offsets fitted by the method */
    uint8_t fx[RC_MAX_PARAMS];
    rch_est_opts o = *eo;
    memset(fx, 0, sizeof fx);
    if (eo->fixed)
        memcpy(fx, eo->fixed, m->n_params);
    if (cx->ref.n_jumps) {
        if (rc_model_add_effect(m, RC_EFF_GROUP_OFFSET, 0, cx->ref.n_jumps + 1) != RC_OK)
            return RC_ERR_CAPACITY;
        const rc_effect *ef = &m->effects[m->n_effects - 1];
        for (unsigned k = ef->first; k < ef->first + ef->count; ++k)
            fx[k] = k == ef->first; /* the first segment is the reference */
    }
    o.fixed = fx;
    *jused = &cx->ref;
    return rch_est_run(m, out, curve, ws, id, seed, &o, cx->lab, h->n_train);
}

/* --jumps and --prior set-up of a case: the sorted and labelled training
 * rows, the prior, its noise (robust LM fits) and the reference change
 * points. 0 or -1 with d set. */
static int case_setup(case_ctx *cx, rch_compare_result *res, const rch_compare_config *cfg, rch_est_ws *ws,
                      const rch_robot *robot, const rc_model *start, rch_est_opts *eo, const rch_holdout *h,
                      rch_diag *d)
{
    char err[256];
    memset(&cx->ref, 0, sizeof cx->ref);
    memcpy(cx->sorted, h->train, h->n_train * sizeof *cx->sorted);
    qsort(cx->sorted, h->n_train, sizeof *cx->sorted, cmp_t);
    rch_est_opts po = *eo;
    if (cfg->prior) {
        memset(cx->mean, 0, sizeof cx->mean);
        memset(cx->sd, 0, sizeof cx->sd);
        memset(cx->fixed_prior, 0, sizeof cx->fixed_prior);
        rch_prior_fill(cx->mean, cx->sd, start, &robot->nominal, &robot->prior);
        if (eo->fixed)
            memcpy(cx->fixed_prior, eo->fixed, start->n_params);
        rch_prior_gauge(cx->fixed_prior);
        rc_metrics m0;
        double noise = rc_eval(&m0, start, h->train, h->n_train) == RC_OK && m0.rmse_mm > 0.0 ? m0.rmse_mm : 1.0;
        po.fixed = cx->fixed_prior;
        po.prior_mean = cx->mean;
        po.prior_sd = cx->sd;
        for (unsigned pass = 0; pass < 4; ++pass) {
            rc_solve_config sc;
            rc_model m = *start;
            double ssr;
            po.prior_noise_mm = noise;
            rch_est_solve_config(&sc, RCH_EST_LM, 0, &po);
            unsigned p = 0;
            if (cfg->jumps) {
                rch_jumps_config jc;
                memset(&jc, 0, sizeof jc);
                jc.solve = &sc;
                if (rch_jumps_find(&cx->ref, start, po.fixed, cx->sorted, h->n_train, &jc, &ws->solve, err,
                                   sizeof err) != 0) {
                    rch_diag_set(d, "", 0, 0, "length jumps: %s", err);
                    return -1;
                }
                m = cx->ref.model;
                for (size_t i = 0; i < h->n_train; ++i)
                    cx->sorted[i].group = (uint16_t)rch_jumps_segment(&cx->ref, cx->sorted[i].t);
                p = cx->ref.n_jumps;
            } else if (rc_solve(&m, NULL, &ws->solve, &sc, h->train, h->n_train) != RC_OK) {
                rch_diag_set(d, "", 0, 0, "the prior's noise cannot be estimated: the robust LM fails");
                return -1;
            }
            if (rc_cost(&ssr, &m, cfg->jumps ? cx->sorted : h->train, h->n_train) != RC_OK)
                return -1;
            for (unsigned k = 0; k < start->n_params; ++k)
                p += !po.fixed[k];
            const double dof = (double)h->n_train - (double)p;
            const double next = dof > 1.0 ? sqrt(ssr / dof) : noise;
            const int settled = fabs(next - noise) <= 0.02 * noise;
            noise = next > 1e-6 ? next : 1e-6;
            if (settled)
                break;
        }
        po.prior_noise_mm = noise;
        rch_stats_add(&res->noise_mm, noise);
    }
    if (cfg->jumps) {
        rc_solve_config sc;
        rch_jumps_config jc;
        rch_est_solve_config(&sc, RCH_EST_LM, 0, &po);
        memset(&jc, 0, sizeof jc);
        jc.solve = &sc;
        if (rch_jumps_find(&cx->ref, start, po.fixed, cx->sorted, h->n_train, &jc, &ws->solve, err, sizeof err) != 0) {
            rch_diag_set(d, "", 0, 0, "length jumps: %s", err);
            return -1;
        }
        memcpy(cx->lab, h->train, h->n_train * sizeof *cx->lab);
        for (size_t i = 0; i < h->n_train; ++i)
            cx->lab[i].group = (uint16_t)rch_jumps_segment(&cx->ref, cx->lab[i].t);
    }
    *eo = po; /* the prior (if any) rides along; every method but the paper-literal ones reads it */
    return 0;
}

/* Case c: BC from the training part, then every selected method from it;
 * one cell per row. */
static int run_case(rch_compare_result *res, const rch_compare_config *cfg, rch_est_ws *ws, case_ctx *cx,
                    const rch_robot *robot, const rch_holdout *h, unsigned long c, FILE *progress, rch_diag *d)
{
    const unsigned long long cseed = cfg->seed * 1000003ull + c;
    rch_compare_cell *cell = res->cell + c * RCH_COMPARE_ROWS;
    const int first = c == 0 && cfg->curves;
    const int save = c == 0 && cfg->models_dir != NULL;
    rc_model start;
    rc_metrics trm;
    uint8_t common[RC_MAX_PARAMS];
    rch_est_opts eo, eo_prior;
    memset(&eo, 0, sizeof eo);
    if (rch_calib_start(&start, &ws->solve, robot, h->train, h->n_train, d) != 0)
        return -1;
    res->n_params = start.n_params;
    if (cfg->params == RCH_PARAMS_COMMON) {
        /* one identifiable set for all seven, at the start on the training part */
        unsigned kept = 0;
        const rc_status sst = rc_est_subset(common, &kept, &ws->est, &start, NULL, 0.0, h->train, h->n_train);
        if (sst != RC_OK) {
            rch_diag_set(d, "", 0, 0, "the common parameter set cannot be found: %s", rc_strerror(sst));
            return -1;
        }
        rch_stats_add(&res->n_common, (double)kept);
        eo.fixed = common;
        eo.same_set = 1;
        eo.bound_len_mm = RCH_COMPARE_COMMON_BOX_MM;
        eo.bound_ang_rad = RCH_COMPARE_COMMON_BOX_DEG * DEG;
        eo.bound_enc_mm = RCH_COMPARE_COMMON_BOX_MM;
        eo.bound_other = 0.0;
    }
    eo_prior = eo;
    if ((cfg->jumps || cfg->prior) && case_setup(cx, res, cfg, ws, robot, &start, &eo_prior, h, d) != 0)
        return -1;
    if (rc_eval(&cell[0].held_out, &start, h->test, h->n_test) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "the start model cannot be evaluated on the held-out samples");
        return -1;
    }
    cell[0].ok = 1;
    cell[0].train_rmse_mm = rc_eval(&trm, &start, h->train, h->n_train) == RC_OK ? trm.rmse_mm : NAN;
    param_deltas(&cell[0], &start, &robot->nominal);
    if (first)
        sample_errors(res->err_case1_mm, &start, h->test, h->n_test);
    if (c == 0) {
        res->model_case1[0] = start;
        res->ok_case1[0] = 1;
    }
    if (save && save_row_model(cfg, robot, &start, 0, eo.fixed, h, &cell[0], d) != 0)
        return -1;
    for (int id = 0; id < RCH_EST_ALL; ++id) {
        rch_compare_cell *e = &cell[id + 1];
        rc_model m = start, geo;
        rch_est_out out;
        rch_jumps jm;
        const rch_jumps *jused = NULL;
        if (!cfg->run[id])
            continue;
        /* the prior: every method but the paper's literal LM and LTLM (see rch_compare.h) */
        const int literal = id == RCH_EST_LM_PAPER || id == RCH_EST_LM_PAPER_DEG || id == RCH_EST_LTLM_PAPER ||
                            id == RCH_EST_LTLM_PAPER_DEG;
        const rch_est_opts *o = cfg->prior && !literal ? &eo_prior : &eo;
        rc_status st = run_method(&m, &out, &jm, &jused, first ? &res->curve[id] : NULL, ws, (rch_est_id)id, cseed,
                                  o, cfg, cx, h);
        if (st == RC_OK && cfg->jumps)
            label_test(cx, h, jused);
        if (st != RC_OK || rc_eval(&e->held_out, &m, cfg->jumps ? cx->test : h->test, h->n_test) != RC_OK) {
            if (progress)
                fprintf(progress, "rcal compare: case %lu: %s failed: %s\n", c + 1, rch_est_name((rch_est_id)id),
                        rc_strerror(st));
            continue;
        }
        e->ok = 1;
        e->time_ms = out.time_ms;
        e->train_rmse_mm = out.rms_final_mm;
        e->iterations = out.iterations;
        e->cost_evals = out.cost_evals;
        e->n_moved = out.n_moved;
        e->n_jumps = jused ? jused->n_jumps : 0;
        param_deltas(e, &m, &robot->nominal);
        if (id == RCH_EST_LTLM)
            add_ltlm(res, &m);
        if (first)
            sample_errors(res->err_case1_mm + (size_t)(id + 1) * h->n_test, &m, cfg->jumps ? cx->test : h->test,
                          h->n_test);
        /* the models kept: the geometry (the segment offsets describe this acquisition only) */
        rch_model_strip_nuisance(&geo, &m);
        if (c == 0) {
            res->model_case1[id + 1] = geo;
            res->ok_case1[id + 1] = 1;
        }
        if (save && save_row_model(cfg, robot, &geo, id + 1, eo.fixed, h, e, d) != 0)
            return -1;
    }
    return 0;
}

double rch_compare_estimate_s(const rch_compare_config *cfg, size_t n)
{
    /* us per drawn row and case, measured with rcal compare --cases 1 --samples 100/300/1000 --methods X on
     * robotcali.csv (both parameter sets alike); the order of rch_est_id */
    static const double us_per_row[RCH_EST_ALL] = {25, 25, 1050, 1450, 600, 30, 250, 80, 80, 375, 375};
    const double rows = (double)(cfg->samples && cfg->samples < n ? cfg->samples : n);
    double per_row = 20.0; /* the start model, the split, the evaluation */
    for (int i = 0; i < RCH_EST_ALL; ++i)
        if (cfg->run[i])
            per_row += us_per_row[i];
    return (double)cfg->cases * (0.005 + rows * per_row * 1e-6) * (cfg->jumps ? 1.2 : 1.0);
}

/* Sizes of a case from the configuration; 0 or -1 with d set. */
static int case_sizes(rch_compare_result *res, const rch_compare_config *cfg, size_t n, rch_diag *d)
{
    size_t sel = 0;
    for (int i = 0; i < RCH_EST_ALL; ++i)
        sel += cfg->run[i] != 0;
    if (sel == 0 || cfg->cases < 1 || cfg->cases > RCH_COMPARE_MAX_CASES ||
        !(cfg->test_fraction > 0.0 && cfg->test_fraction < 1.0)) {
        rch_diag_set(d, "", 0, 0, "need at least one method, 1..%lu cases and a test fraction in (0, 1)",
                     RCH_COMPARE_MAX_CASES);
        return -1;
    }
    res->n_draw = cfg->samples ? cfg->samples : n;
    if (res->n_draw > n) {
        rch_diag_set(d, "", 0, 0, "--samples %zu but the data has %zu rows", res->n_draw, n);
        return -1;
    }
    {
        /* the cost, before the work (rch_compare_estimate_s) */
        const double est_s = rch_compare_estimate_s(cfg, n);
        const double lim_min = cfg->max_minutes > 0.0 ? cfg->max_minutes : RCH_COMPARE_MAX_MINUTES;
        if (est_s > 60.0 * lim_min) {
            char b1[32];
            rch_diag_set(d, "", 0, 0,
                         "%lu cases x %zu rows x %zu methods would take about %s (measured cost per row on the "
                         "reference machine, docs/methods.md), above the limit of %.0f min: lower --cases or "
                         "--samples, or raise --max-minutes",
                         cfg->cases, res->n_draw, sel, rch_cost_human(b1, sizeof b1, est_s), lim_min);
            return -1;
        }
    }
    res->n_test = (size_t)floor(cfg->test_fraction * (double)res->n_draw + 0.5);
    if (res->n_test < 1)
        res->n_test = 1;
    res->n_train = res->n_draw > res->n_test ? res->n_draw - res->n_test : 0;
    if (res->n_train < RC_N_BASE) {
        rch_diag_set(d, "", 0, 0, "%zu training samples per case; at least %d are needed", res->n_train,
                     RC_N_BASE);
        return -1;
    }
    return 0;
}

int rch_compare_run(rch_compare_result *res, const rch_compare_config *cfg, const rch_robot *robot,
                    const rc_sample *s, size_t n, FILE *progress, rch_diag *d)
{
    memset(res, 0, sizeof *res);
    res->rows_in_data = n;
    res->cases = cfg->cases;
    res->params = cfg->params;
    res->jumps = cfg->jumps;
    if (case_sizes(res, cfg, n, d) != 0)
        return -1;
    int rc = -1;
    size_t *idx = malloc((n ? n : 1) * sizeof *idx);
    rch_est_ws *ws = rch_est_ws_new();
    case_ctx *cx = calloc(1, sizeof *cx);
    if (cx) {
        cx->sorted = malloc((res->n_train ? res->n_train : 1) * sizeof *cx->sorted);
        cx->lab = malloc((res->n_train ? res->n_train : 1) * sizeof *cx->lab);
        cx->test = malloc((res->n_test ? res->n_test : 1) * sizeof *cx->test);
    }
    res->cell = calloc(cfg->cases * RCH_COMPARE_ROWS, sizeof *res->cell);
    res->err_case1_mm = malloc(RCH_COMPARE_ROWS * (res->n_test ? res->n_test : 1) * sizeof(double));
    res->idx_case1 = malloc((res->n_draw ? res->n_draw : 1) * sizeof *res->idx_case1);
    res->model_case1 = malloc(RCH_COMPARE_ROWS * sizeof *res->model_case1);
    if (!idx || !ws || !cx || !cx->sorted || !cx->lab || !cx->test || !res->cell || !res->err_case1_mm || !res->idx_case1 || !res->model_case1) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    if (cfg->models_dir && rch_plot_mkdir(cfg->models_dir) != 0) {
        rch_diag_set(d, "", 0, 0, "cannot use %s as a model directory: %s", cfg->models_dir, strerror(errno));
        goto done;
    }
    res->row[0].used = 1;
    for (int id = 0; id < RCH_EST_ALL; ++id)
        res->row[id + 1].used = cfg->run[id] != 0;
    for (size_t k = 0; k < RCH_COMPARE_ROWS * res->n_test; ++k)
        res->err_case1_mm[k] = NAN;
    const double t0_s = rch_cost_now_s();
    for (unsigned long c = 0; c < cfg->cases; ++c) {
        rch_holdout h;
        /* the case's draw: the first n_test rows of the permutation are held out */
        if (rch_holdout_draw(&h, idx, s, n, res->n_draw, res->n_test, cfg->seed * 1000003ull + c) != 0) {
            rch_diag_set(d, "", 0, 0, "out of memory");
            goto done;
        }
        if (c == 0)
            memcpy(res->idx_case1, idx, res->n_draw * sizeof *idx);
        const int st = run_case(res, cfg, ws, cx, robot, &h, c, progress, d);
        rch_holdout_free(&h);
        if (st != 0) {
            char msg[600];
            rch_diag_str(d, msg, sizeof msg);
            rch_diag_set(d, "", 0, 0, "case %lu: %s", c + 1, msg);
            goto done;
        }
        if (progress) {
            char b1[32], b2[32];
            const double el = rch_cost_now_s() - t0_s;
            fprintf(progress, "case %lu/%lu done, %s elapsed, about %s left\n", c + 1, cfg->cases,
                    rch_cost_human(b1, sizeof b1, el),
                    rch_cost_human(b2, sizeof b2, el * (double)(cfg->cases - c - 1) / (double)(c + 1)));
        }
    }
    summarise(res);
    rc = 0;
done:
    if (cx) {
        free(cx->sorted);
        free(cx->lab);
        free(cx->test);
        free(cx);
    }
    rch_est_ws_free(ws);
    free(idx);
    return rc;
}

/* ---- reports ----------------------------------------------------------- */

/* 1 when the rows were fitted with length jumps (some cell used change points, or --jumps ran). */
