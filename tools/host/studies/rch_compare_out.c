/* SPDX-License-Identifier: MIT */
/* rch_compare_out.c - what the seven-method comparison reports (see
 * rch_compare.h): the text table (the paper's Table 6 form), the JSON, the
 * convergence curves' CSV, the plots and the residual table. The protocol
 * itself is rch_compare.c. */
#include "rch_compare.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_jw.h"
#include "rch_plot.h"
#include "rch_resid.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

static int jumps_any(const rch_compare_result *res) { return res->jumps; }

static void report_rows(FILE *f, const rch_compare_result *res)
{
    const double lm_time = rch_compare_lm_time_ms(res);
    fprintf(f, "Held-out errors, mean +- std over cases (mm); time of the identification alone (ms, one core)\n");
    fprintf(f, "  %-14s %-17s %-17s %-17s %-19s %8s %10s %9s %6s %9s %9s%s\n", "method", "RMSE", "mean|e| (\"SD\")",
            "MAX", "time (ms)", "x LM", "train RMS", "iters", "moved", "|dlen|mm", "|dang|deg",
            jumps_any(res) ? "  jumps" : "");
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
        char jbuf[32] = "";
        if (jumps_any(res) && r > 0)
            snprintf(jbuf, sizeof jbuf, "  %5.1f", s->n_jumps.mean);
        fprintf(f, "  %-14s %6.4f +- %-7.4f %6.4f +- %-7.4f %6.4f +- %-7.4f %-19s %8s %10.4f %9.0f %6.1f %9.2f %9.2f%s%s\n",
                rch_compare_row_name(r), s->rmse_mm.mean, rch_stats_sd(&s->rmse_mm), s->mean_abs_mm.mean,
                rch_stats_sd(&s->mean_abs_mm), s->max_mm.mean, rch_stats_sd(&s->max_mm), tbuf, rbuf,
                s->train_rmse_mm.mean, r == 0 ? 0.0 : s->iterations.mean, r == 0 ? 0.0 : s->n_moved.mean,
                s->dlen_max_mm.mean, s->dang_max_deg.mean, jbuf, s->failed ? "  (failed in some cases)" : "");
    }
    fprintf(f, "  (BC: nominal DH with the encoder fitted alone; mean|e| is what the paper's Eq. 20 calls SD;\n"
               "   moved: parameters the method moved, for LM/LTLM the rank they found among those they may move;\n"
               "   |dlen|, |dang|: the largest change of a DH length / angle from nominal, mean over the cases (the\n"
               "   paper's Table 7 size); *-paper: the paper's Eq. 10 (mu = 5, no acceptance) and Algorithm I on it,\n"
               "   -deg with the angles in degrees inside Eq. 10; jumps: change points the fit used, mean)\n");
    /* The paper's Table 6 (Liu et al. 2024), as published, beside ours. */
    fprintf(f, "\nThe paper's Table 6 beside ours (mm; the paper's SD is its Eq. 20, our mean|e|):\n");
    fprintf(f, "  %-14s %22s %22s %22s\n", "method", "RMSE paper / ours", "SD paper / ours", "MAX paper / ours");
    for (int r = 0; r < RCH_COMPARE_ROWS; ++r) {
        const rch_compare_row *s = &res->row[r];
        if (!s->used)
            continue;
        const double *paper = rch_compare_table6[r == 0 ? 0 : rch_est_paper_row((rch_est_id)(r - 1))];
        fprintf(f, "  %-14s %12.2f / %-7.3f %12.2f / %-7.3f %12.2f / %-7.3f\n", rch_compare_row_name(r), paper[0],
                s->rmse_mm.mean, paper[1], s->mean_abs_mm.mean, paper[2], s->max_mm.mean);
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
    if (res->params == RCH_PARAMS_COMMON)
        fprintf(f, "parameter set: common -- every method moves the same identifiable subset (%.1f +- %.1f of %u "
                   "parameters over the cases);\n  the population methods in one box +-%g mm / +-%g deg around the "
                   "start (EKF prior sd the same)\n",
                res->n_common.mean, rch_stats_sd(&res->n_common), res->n_params, RCH_COMPARE_COMMON_BOX_MM,
                RCH_COMPARE_COMMON_BOX_DEG);
    else if (cfg->prior)
        fprintf(f, "parameter set: paper with the prior -- every method moves all %u parameters (the prior\n"
                   "  determines what the data do not); the population methods search 3 prior sd around the start\n",
                res->n_params);
    else
        fprintf(f, "parameter set: paper -- LM and LTLM move all %u parameters (own truncation), the other five\n"
                   "  an identifiable subset; the population methods search +-2 mm / +-0.2 deg / encoder +-5 mm\n",
                res->n_params);
    if (cfg->jumps || cfg->prior)
        fprintf(f, "nuisance and prior:%s%s\n",
                cfg->jumps ? " length jumps fitted with every method (rc_solve methods: their own jump search; "
                             "EKF..SSLM: the robust LM's change points, offsets their own);" : "",
                cfg->prior ? " every method but the paper-literal ones maximum a posteriori with the physical prior "
                             "(gauge theta1, d1 held; EKF iterated from the prior)" : "");
    if (cfg->prior)
        fprintf(f, "  prior weighed against a residual sd of %.4f +- %.4f mm (over the cases)\n", res->noise_mm.mean,
                rch_stats_sd(&res->noise_mm));
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
        rch_jw_int(w, "paper_row", rch_est_paper_row((rch_est_id)(r - 1)));
        if (res->jumps)
            rch_jw_numf(w, "jumps", s->n_jumps.mean, "%.2f");
    }
    rch_jw_numf(w, "max_dlen_mm", s->dlen_max_mm.mean, "%.5f");
    rch_jw_numf(w, "max_dang_deg", s->dang_max_deg.mean, "%.5f");
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

int rch_compare_json(FILE *f, const rch_compare_result *res, const rch_compare_config *cfg, const char *data_name,
                     int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, f, 1, "rcal-compare/1", argc, argv);
    rch_jw_str(&w, "data", data_name);
    rch_jw_uint(&w, "rows_in_file", res->rows_in_data);
    rch_jw_uint(&w, "cases", res->cases);
    rch_jw_uint(&w, "samples", res->n_draw);
    rch_jw_uint(&w, "n_train", res->n_train);
    rch_jw_uint(&w, "n_test", res->n_test);
    rch_jw_numf(&w, "test_fraction", cfg->test_fraction, "%.6g");
    rch_jw_uint(&w, "seed", cfg->seed);
    rch_jw_str(&w, "params", rch_compare_params_name(res->params));
    rch_jw_bool(&w, "jumps", cfg->jumps != 0);
    rch_jw_bool(&w, "prior", cfg->prior != 0);
    if (cfg->prior)
        rch_jw_numf(&w, "prior_noise_mm", res->noise_mm.mean, "%.6f");
    /* the paper's Table 6 as published: BC and M1..M7 */
    rch_jw_arr(&w, "paper_table6");
    for (int r = 0; r < 8; ++r) {
        static const char *const names[8] = {"BC", "M1 LM", "M2 EKF", "M3 PF", "M4 SCA", "M5 QIBAS", "M6 SSLM", "M7 LTLM"};
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "name", names[r]);
        rch_jw_numf(&w, "rmse_mm", rch_compare_table6[r][0], "%.2f");
        rch_jw_numf(&w, "sd_mm", rch_compare_table6[r][1], "%.2f");
        rch_jw_numf(&w, "max_mm", rch_compare_table6[r][2], "%.2f");
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
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

/* ---- convergence curves as CSV (beside convergence.svg) ------------------ */

/* One row per method and iteration: method,iteration,train_rmse_mm
 * (iteration 0 is the start). 0, or -1 on a write error. */
static int write_curves_csv(FILE *f, const rch_compare_result *res, const rch_compare_config *cfg)
{
    fprintf(f, "method,iteration,train_rmse_mm\n");
    for (int id = 0; id < RCH_EST_ALL; ++id)
        if (cfg->run[id])
            for (size_t k = 0; k < res->curve[id].n; ++k)
                fprintf(f, "%s,%zu,%.9g\n", rch_est_name((rch_est_id)id), k, res->curve[id].rms_mm[k]);
    return ferror(f) ? -1 : 0;
}

int rch_compare_curves_csv(const rch_compare_result *res, const rch_compare_config *cfg, const rch_plot_dir *pd,
                           rch_diag *d)
{
    rch_out o;
    if (rch_plot_open(&o, pd, "convergence_curves.csv", d) != 0)
        return -1;
    return rch_plot_close(&o, pd, write_curves_csv(o.f, res, cfg) != 0, d);
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
    for (int id = 0; id < RCH_EST_ALL; ++id)
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
        rch_plot_save(plot_per_sample(res, cfg), pd, "per_sample.svg", d) != 0 ||
        rch_compare_curves_csv(res, cfg, pd, d) != 0)
        return -1;
    return 0;
}

int rch_compare_resid(rch_resid_table *t, const rch_compare_result *res, const rc_sample *s, const unsigned *line)
{
    int col[RCH_COMPARE_ROWS];
    t->with_case = 1;
    for (int r = 1; r < RCH_COMPARE_ROWS; ++r) {
        col[r] = -1;
        if (res->row[r].used && t->n_steps < RCH_RESID_MAX_STEPS) {
            col[r] = (int)t->n_steps;
            (void)rch_resid_add_step(t, rch_compare_row_name(r));
        }
    }
    for (size_t i = 0; i < res->n_draw; ++i) {
        const size_t k = res->idx_case1[i];
        rch_resid_row row;
        memset(&row, 0, sizeof row);
        row.line = line[k];
        row.case_no = 1;
        row.set = i < res->n_test ? RCH_RESID_TEST : RCH_RESID_TRAIN;
        row.s = s[k];
        if (!res->ok_case1[0] || rc_meas(&row.predicted_mm, NULL, &res->model_case1[0], &s[k]) != RC_OK)
            row.predicted_mm = NAN;
        for (unsigned c = 0; c < RCH_RESID_MAX_STEPS; ++c)
            row.after_mm[c] = NAN;
        for (int r = 1; r < RCH_COMPARE_ROWS; ++r) {
            double l;
            if (col[r] >= 0 && res->ok_case1[r] && rc_meas(&l, NULL, &res->model_case1[r], &s[k]) == RC_OK)
                row.after_mm[col[r]] = s[k].value - l;
        }
        if (rch_resid_add(t, &row) != 0)
            return -1;
    }
    return 0;
}
