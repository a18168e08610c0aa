/* SPDX-License-Identifier: MIT */
/* rch_compare.c - the seven-method comparison protocol; see rch_compare.h. */
#include "rch_compare.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_calib.h"
#include "rch_eval.h"
#include "rch_jw.h"
#include "rch_plot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

void rch_compare_defaults(rch_compare_config *cfg)
{
    const rch_compare_config def = {.cases = 10, .samples = 300, .test_fraction = 0.1, .seed = 1};
    *cfg = def;
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        cfg->run[i] = 1;
}

int rch_compare_methods(int run[RCH_EST_COUNT], const char *list, rch_diag *d)
{
    char buf[256];
    size_t n_sel = 0;
    if (strlen(list) >= sizeof buf) {
        rch_diag_set(d, "", 0, 0, "--methods: list longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        run[i] = 0;
    memcpy(buf, list, strlen(list) + 1);
    for (char *tok = buf, *next; tok; tok = next) {
        int id;
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        id = rch_est_parse(tok);
        if (id < 0) {
            rch_diag_set(d, "", 0, 0, "--methods: %s '%s' (LM, EKF, PF, SCA, QIBAS, SSLM, LTLM or M1..M7)",
                         *tok ? "unknown method" : "empty method name in", *tok ? tok : list);
            return -1;
        }
        run[id] = 1;
        ++n_sel;
    }
    return n_sel ? 0 : -1;
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
    for (int id = 0; id < RCH_EST_COUNT; ++id)
        rch_curve_free(&res->curve[id]);
    free(res->cell);
    free(res->err_case1_mm);
    res->cell = NULL;
    res->err_case1_mm = NULL;
}

/* err (n): model - measured length of every sample, NaN where m fails. */
static void sample_errors(double *err, const rc_model *m, const rc_sample *s, size_t n)
{
    for (size_t k = 0; k < n; ++k) {
        double l;
        err[k] = rc_meas(&l, NULL, m, &s[k]) == RC_OK ? l - s[k].len_mm : NAN;
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

/* Case c: BC from the training part, then every selected method from it;
 * one cell per row. */
static int run_case(rch_compare_result *res, const rch_compare_config *cfg, rch_est_ws *ws,
                    const rch_robot *robot, const rch_holdout *h, unsigned long c, FILE *progress, rch_diag *d)
{
    const unsigned long long cseed = cfg->seed * 1000003ull + c;
    rch_compare_cell *cell = res->cell + c * RCH_COMPARE_ROWS;
    const int first = c == 0 && cfg->curves;
    rc_model start;
    rc_metrics trm;
    if (rch_calib_start(&start, &ws->solve, robot, h->train, h->n_train, d) != 0)
        return -1;
    if (rc_eval(&cell[0].held_out, &start, h->test, h->n_test) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "the start model cannot be evaluated on the held-out samples");
        return -1;
    }
    cell[0].ok = 1;
    cell[0].train_rmse_mm = rc_eval(&trm, &start, h->train, h->n_train) == RC_OK ? trm.rmse_mm : NAN;
    if (first)
        sample_errors(res->err_case1_mm, &start, h->test, h->n_test);
    for (int id = 0; id < RCH_EST_COUNT; ++id) {
        rch_compare_cell *e = &cell[id + 1];
        rc_model m = start;
        rch_est_out out;
        if (!cfg->run[id])
            continue;
        rc_status st = rch_est_run(&m, &out, first ? &res->curve[id] : NULL, ws, (rch_est_id)id, cseed, NULL,
                                   h->train, h->n_train);
        if (st != RC_OK || rc_eval(&e->held_out, &m, h->test, h->n_test) != RC_OK) {
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
        if (id == RCH_EST_LTLM)
            add_ltlm(res, &m);
        if (first)
            sample_errors(res->err_case1_mm + (size_t)(id + 1) * h->n_test, &m, h->test, h->n_test);
    }
    return 0;
}

/* Sizes of a case from the configuration; 0 or -1 with d set. */
static int case_sizes(rch_compare_result *res, const rch_compare_config *cfg, size_t n, rch_diag *d)
{
    size_t sel = 0;
    for (int i = 0; i < RCH_EST_COUNT; ++i)
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
        /* the cost: one fit per case, method and drawn row (about 0.5 ms
         * each on one core): 10 cases x 300 rows x 7 methods is 21000 */
        const double work = (double)cfg->cases * (double)res->n_draw * (double)sel;
        if (work > RCH_COMPARE_MAX_WORK) {
            rch_diag_set(d, "", 0, 0,
                         "%lu cases x %zu rows x %zu methods = %.3g row fits, above the limit of %.0e (about 8 "
                         "min): lower --cases or --samples",
                         cfg->cases, res->n_draw, sel, work, RCH_COMPARE_MAX_WORK);
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
    if (case_sizes(res, cfg, n, d) != 0)
        return -1;
    int rc = -1;
    size_t *idx = malloc((n ? n : 1) * sizeof *idx);
    rch_est_ws *ws = rch_est_ws_new();
    res->cell = calloc(cfg->cases * RCH_COMPARE_ROWS, sizeof *res->cell);
    res->err_case1_mm = malloc(RCH_COMPARE_ROWS * res->n_test * sizeof(double));
    if (!idx || !ws || !res->cell || !res->err_case1_mm) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    res->row[0].used = 1;
    for (int id = 0; id < RCH_EST_COUNT; ++id)
        res->row[id + 1].used = cfg->run[id] != 0;
    for (size_t k = 0; k < RCH_COMPARE_ROWS * res->n_test; ++k)
        res->err_case1_mm[k] = NAN;
    for (unsigned long c = 0; c < cfg->cases; ++c) {
        rch_holdout h;
        /* the case's draw: the first n_test rows of the permutation are held out */
        if (rch_holdout_draw(&h, idx, s, n, res->n_draw, res->n_test, cfg->seed * 1000003ull + c) != 0) {
            rch_diag_set(d, "", 0, 0, "out of memory");
            goto done;
        }
        const int st = run_case(res, cfg, ws, robot, &h, c, progress, d);
        rch_holdout_free(&h);
        if (st != 0) {
            char msg[600];
            rch_diag_str(d, msg, sizeof msg);
            rch_diag_set(d, "", 0, 0, "case %lu: %s", c + 1, msg);
            goto done;
        }
        if (progress)
            fprintf(progress, "case %lu/%lu done\n", c + 1, cfg->cases);
    }
    summarise(res);
    rc = 0;
done:
    rch_est_ws_free(ws);
    free(idx);
    return rc;
}

/* ---- reports ----------------------------------------------------------- */

static void report_rows(FILE *f, const rch_compare_result *res)
{
    const double lm_time = rch_compare_lm_time_ms(res);
    fprintf(f, "Held-out errors, mean +- std over cases (mm); time of the identification alone (ms, one core)\n");
    fprintf(f, "  %-6s %-17s %-17s %-17s %-19s %8s %10s %9s\n", "method", "RMSE", "mean|e| (\"SD\")", "MAX",
            "time (ms)", "x LM", "train RMS", "iters");
    for (int r = 0; r < RCH_COMPARE_ROWS; ++r) {
        const rch_compare_row *s = &res->row[r];
        char tbuf[64], rbuf[32];
        if (!s->used)
            continue;
        snprintf(tbuf, sizeof tbuf, "%s", "-");
        snprintf(rbuf, sizeof rbuf, "%s", "-");
        if (r > 0) {
            snprintf(tbuf, sizeof tbuf, "%8.2f +- %-7.2f", s->time_ms.mean, rch_stats_sd(&s->time_ms));
            if (isfinite(lm_time) && lm_time > 0)
                snprintf(rbuf, sizeof rbuf, "%.2f", s->time_ms.mean / lm_time);
        }
        fprintf(f, "  %-6s %6.4f +- %-7.4f %6.4f +- %-7.4f %6.4f +- %-7.4f %-19s %8s %10.4f %9.0f%s\n",
                rch_compare_row_name(r), s->rmse_mm.mean, rch_stats_sd(&s->rmse_mm), s->mean_abs_mm.mean,
                rch_stats_sd(&s->mean_abs_mm), s->max_mm.mean, rch_stats_sd(&s->max_mm), tbuf, rbuf,
                s->train_rmse_mm.mean, r == 0 ? 0.0 : s->iterations.mean,
                s->failed ? "  (failed in some cases)" : "");
    }
    fprintf(f, "  (BC: nominal DH with the encoder fitted alone; mean|e| is what the paper's Eq. 20 calls SD)\n");
    /* The paper's Table 6 (Liu et al. 2024), as published, beside ours. */
    static const double paper[RCH_COMPARE_ROWS][3] = {{2.18, 2.01, 3.42}, {0.36, 0.30, 0.91}, {0.63, 0.51, 1.52},
                                                      {0.73, 0.61, 1.77}, {0.82, 0.66, 1.96}, {0.50, 0.40, 1.31},
                                                      {0.34, 0.28, 0.85}, {0.32, 0.26, 0.83}};
    fprintf(f, "\nThe paper's Table 6 beside ours (mm; the paper's SD is its Eq. 20, our mean|e|):\n");
    fprintf(f, "  %-6s %22s %22s %22s\n", "method", "RMSE paper / ours", "SD paper / ours", "MAX paper / ours");
    for (int r = 0; r < RCH_COMPARE_ROWS; ++r) {
        const rch_compare_row *s = &res->row[r];
        if (!s->used)
            continue;
        fprintf(f, "  %-6s %12.2f / %-7.3f %12.2f / %-7.3f %12.2f / %-7.3f\n", rch_compare_row_name(r), paper[r][0],
                s->rmse_mm.mean, paper[r][1], s->mean_abs_mm.mean, paper[r][2], s->max_mm.mean);
    }
}

static void report_ltlm(FILE *f, const rch_compare_result *res)
{
    const rch_stats *e = res->ltlm_enc_mm;
    fprintf(f, "\nLTLM identified parameters, the paper's Table 7 form (mean +- std over %u cases):\n", res->n_ltlm);
    fprintf(f, "  joint           a (mm)               d (mm)            alpha (deg)            theta (deg)\n");
    for (unsigned j = 0; j < RC_NJ; ++j) {
        const rch_stats *s = res->ltlm_dh[j];
        fprintf(f, "  %5u %9.4f +- %-7.4f %9.4f +- %-7.4f %10.5f +- %-8.5f %10.5f +- %-8.5f\n", j + 1, s[0].mean,
                rch_stats_sd(&s[0]), s[1].mean, rch_stats_sd(&s[1]), s[2].mean, rch_stats_sd(&s[2]), s[3].mean,
                rch_stats_sd(&s[3]));
    }
    fprintf(f, "  encoder e = (%.3f, %.3f, %.3f) mm  (+- %.3f, %.3f, %.3f)\n", e[0].mean, e[1].mean, e[2].mean,
            rch_stats_sd(&e[0]), rch_stats_sd(&e[1]), rch_stats_sd(&e[2]));
    fprintf(f, "  Parameters the data cannot separate (e.g. d1 against e_z, theta1 against a rotation of e)\n"
               "  stay at their start values; their spread over cases shows how weakly the rest is determined.\n");
}

void rch_compare_report(FILE *f, const rch_compare_result *res, const rch_compare_config *cfg,
                        const char *data_name)
{
    fprintf(f, "rcal compare: %s, %zu rows; %lu cases of %zu random rows (%zu train / %zu held out), seed %llu\n",
            data_name, res->rows_in_data, res->cases, res->n_draw, res->n_train, res->n_test, cfg->seed);
    report_rows(f, res);
    if (res->n_ltlm > 0)
        report_ltlm(f, res);
}

static void json_row(rch_jw *w, const rch_compare_result *res, int r)
{
    const rch_compare_row *s = &res->row[r];
    const double lm_time = rch_compare_lm_time_ms(res);
    rch_jw_obj(w, NULL);
    rch_jw_str(w, "name", rch_compare_row_name(r));
    rch_jw_uint(w, "cases_ok", s->rmse_mm.n);
    rch_jw_numf(w, "rmse_mm", s->rmse_mm.mean, "%.6f");
    rch_jw_numf(w, "rmse_std_mm", rch_stats_sd(&s->rmse_mm), "%.6f");
    rch_jw_numf(w, "mean_abs_mm", s->mean_abs_mm.mean, "%.6f");
    rch_jw_numf(w, "mean_abs_std_mm", rch_stats_sd(&s->mean_abs_mm), "%.6f");
    rch_jw_numf(w, "max_mm", s->max_mm.mean, "%.6f");
    rch_jw_numf(w, "max_std_mm", rch_stats_sd(&s->max_mm), "%.6f");
    rch_jw_numf(w, "train_rmse_mm", s->train_rmse_mm.mean, "%.6f");
    if (r == 0) {
        rch_jw_int(w, "time_ms", 0);
    } else {
        rch_jw_numf(w, "time_ms", s->time_ms.mean, "%.4f");
        rch_jw_numf(w, "time_std_ms", rch_stats_sd(&s->time_ms), "%.4f");
        rch_jw_numf(w, "time_ratio_lm", isfinite(lm_time) && lm_time > 0 ? s->time_ms.mean / lm_time : 0.0, "%.4g");
        rch_jw_numf(w, "iterations", s->iterations.mean, "%.1f");
        rch_jw_numf(w, "cost_evals", s->cost_evals.mean, "%.0f");
        rch_jw_uint(w, "cases_failed", s->failed);
    }
    rch_jw_end(w);
}

static void json_ltlm(rch_jw *w, const rch_compare_result *res)
{
    static const char *const keys[4] = {"a_mm", "d_mm", "alpha_deg", "theta_deg"};
    static const char *const std_keys[4] = {"a_std_mm", "d_std_mm", "alpha_std_deg", "theta_std_deg"};
    rch_jw_obj(w, "ltlm_parameters");
    rch_jw_uint(w, "cases", res->n_ltlm);
    rch_jw_arr(w, "joints");
    for (unsigned j = 0; j < RC_NJ; ++j) {
        rch_jw_obj(w, NULL);
        rch_jw_uint(w, "joint", j + 1);
        for (unsigned k = 0; k < 4; ++k)
            rch_jw_numf(w, keys[k], res->ltlm_dh[j][k].mean, k < 2 ? "%.5f" : "%.6f");
        for (unsigned k = 0; k < 4; ++k)
            rch_jw_numf(w, std_keys[k], rch_stats_sd(&res->ltlm_dh[j][k]), k < 2 ? "%.5f" : "%.6f");
        rch_jw_end(w);
    }
    rch_jw_end(w);
    rch_jw_arr(w, "encoder_mm");
    for (unsigned k = 0; k < 3; ++k)
        rch_jw_numf(w, NULL, res->ltlm_enc_mm[k].mean, "%.4f");
    rch_jw_end(w);
    rch_jw_end(w);
}

int rch_compare_json(FILE *f, const rch_compare_result *res, const rch_compare_config *cfg, const char *data_name)
{
    rch_jw w;
    rch_jw_init(&w, f, 1);
    rch_jw_obj(&w, NULL);
    rch_jw_str(&w, "command", "compare");
    rch_jw_str(&w, "data", data_name);
    rch_jw_uint(&w, "rows_in_file", res->rows_in_data);
    rch_jw_uint(&w, "cases", res->cases);
    rch_jw_uint(&w, "samples", res->n_draw);
    rch_jw_uint(&w, "n_train", res->n_train);
    rch_jw_uint(&w, "n_test", res->n_test);
    rch_jw_numf(&w, "test_fraction", cfg->test_fraction, "%.6g");
    rch_jw_uint(&w, "seed", cfg->seed);
    rch_jw_arr(&w, "methods");
    for (int r = 0; r < RCH_COMPARE_ROWS; ++r)
        if (res->row[r].used)
            json_row(&w, res, r);
    rch_jw_end(&w);
    rch_jw_arr(&w, "cases_rmse_mm"); /* per case: the rows of "methods", null where a method failed */
    for (unsigned long c = 0; c < res->cases; ++c) {
        rch_jw_arr(&w, NULL);
        for (int r = 0; r < RCH_COMPARE_ROWS; ++r)
            if (res->row[r].used) {
                const rch_compare_cell *e = &res->cell[c * RCH_COMPARE_ROWS + (size_t)r];
                rch_jw_numf(&w, NULL, e->ok ? e->held_out.rmse_mm : NAN, "%.6f");
            }
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    if (res->n_ltlm > 0)
        json_ltlm(&w, res);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* ---- plots ------------------------------------------------------------- */

/* A line through (k, y[k]), k = x0, x0 + 1, ... */
static void plot_indexed(rch_plot *p, const char *label, const double *y, size_t n, double x0)
{
    double *x = malloc((n ? n : 1) * sizeof *x);
    if (!x)
        return;
    for (size_t k = 0; k < n; ++k)
        x[k] = x0 + (double)k;
    rch_plot_line(p, label, x, y, n);
    free(x);
}

static rch_plot *plot_convergence(const rch_compare_result *res, const rch_compare_config *cfg, int zoom)
{
    rch_plot *p = rch_plot_new(zoom ? "Training RMS length error per iteration, first 60 iterations (case 1)"
                                    : "Training RMS length error per iteration of each method (case 1)",
                               "iteration (count)", "training RMS length error (mm)");
    for (int id = 0; id < RCH_EST_COUNT; ++id)
        if (cfg->run[id] && res->curve[id].n > 0)
            plot_indexed(p, rch_est_name((rch_est_id)id), res->curve[id].rms_mm, res->curve[id].n, 0.0);
    rch_plot_logy(p, 1);
    if (zoom)
        rch_plot_xrange(p, 0.0, 60.0);
    return p;
}

/* Bars of held-out RMSE (time = 0) or identification time (time = 1, methods only). */
static rch_plot *plot_bars(const rch_compare_result *res, int time)
{
    const char *labels[RCH_COMPARE_ROWS];
    double vals[RCH_COMPARE_ROWS], errs[RCH_COMPARE_ROWS];
    unsigned cat[RCH_COMPARE_ROWS];
    static const char *const cat_names[2] = {"before calibration (nominal model)", "identification method"};
    size_t nb = 0;
    char title[160];
    for (int r = time ? 1 : 0; r < RCH_COMPARE_ROWS; ++r) {
        const rch_compare_row *row = &res->row[r];
        const rch_stats *st = time ? &row->time_ms : &row->rmse_mm;
        if (!row->used || row->rmse_mm.n == 0)
            continue;
        labels[nb] = rch_compare_row_name(r);
        vals[nb] = st->mean;
        errs[nb] = rch_stats_sd(st);
        cat[nb] = r == 0 ? 0u : 1u; /* row 0 is BC, the nominal model */
        ++nb;
    }
    if (time)
        snprintf(title, sizeof title, "Identification time of each method, mean +- std over %lu cases", res->cases);
    else
        snprintf(title, sizeof title, "Held-out RMS length error, mean +- std over %lu cases (%zu train / %zu test samples)",
                 res->cases, res->n_train, res->n_test);
    rch_plot *p = rch_plot_new(title, "method", time ? "identification time (ms)" : "held-out RMS length error (mm)");
    rch_plot_bars(p, labels, vals, errs, nb);
    if (!time) /* the time chart has methods only: one colour */
        rch_plot_bar_categories(p, cat, cat_names, 2);
    rch_plot_logy(p, time);
    return p;
}

static rch_plot *plot_per_sample(const rch_compare_result *res, const rch_compare_config *cfg)
{
    const size_t n = res->n_test;
    rch_plot *p = rch_plot_new("Length error of each held-out sample, before and after calibration (case 1)",
                               "held-out sample (number)", "model - measured cable length (mm)");
    rch_plot_subtitle(p, "the kind of plot of the paper's Fig. 7");
    plot_indexed(p, "before (BC)", res->err_case1_mm, n, 1.0);
    if (cfg->run[RCH_EST_LM])
        plot_indexed(p, "after LM", res->err_case1_mm + (size_t)(RCH_EST_LM + 1) * n, n, 1.0);
    if (cfg->run[RCH_EST_LTLM])
        plot_indexed(p, "after LTLM", res->err_case1_mm + (size_t)(RCH_EST_LTLM + 1) * n, n, 1.0);
    return p;
}

int rch_compare_plots(const rch_compare_result *res, const rch_compare_config *cfg, const rch_plot_dir *pd,
                      rch_diag *d)
{
    if (rch_plot_mkdir(pd->dir) != 0) {
        rch_diag_set(d, "", 0, 0, "cannot use %s as a plot directory: %s", pd->dir, strerror(errno));
        return -1;
    }
    if (pd->log)
        fprintf(pd->log, "\nplots:\n");
    if (rch_plot_save(plot_convergence(res, cfg, 0), pd, "convergence.svg", d) != 0 ||
        rch_plot_save(plot_convergence(res, cfg, 1), pd, "convergence_zoom.svg", d) != 0 ||
        rch_plot_save(plot_bars(res, 0), pd, "rmse_bars.svg", d) != 0 ||
        rch_plot_save(plot_bars(res, 1), pd, "time_bars.svg", d) != 0 ||
        rch_plot_save(plot_per_sample(res, cfg), pd, "per_sample.svg", d) != 0)
        return -1;
    return 0;
}
