/* SPDX-License-Identifier: MIT */
/* rch_bench.c - calibration speed in one process (see rch_bench.h). */
#include "rch_bench.h"
#include "rch_diagnose.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rch_calib.h"
#include "rch_start.h"
#include "rch_data.h"
#include "rch_robot.h"

static const rc_method k_methods[RCH_BENCH_N_METHODS] = {RC_METHOD_LM, RC_METHOD_LTLM, RC_METHOD_LM_PAPER,
                                                         RC_METHOD_LTLM_PAPER};

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sort t (n >= 1) and give its median, minimum and maximum. */
static void med_range(double *med, double *mn, double *mx, double *t, size_t n)
{
    qsort(t, n, sizeof *t, cmp_double);
    *med = t[n / 2];
    if (mn)
        *mn = t[0];
    if (mx)
        *mx = t[n - 1];
}

/* Full calibrations of data with one method, runs times; t_start, t_solve
 * (runs) scratch. 0 or -1 with d set. */
static int bench_method(rch_bench_row *row, rc_method method, unsigned long runs, rc_solve_work *w,
                        const rch_robot *robot, const rch_data *data, double *t_start, double *t_solve, rch_diag *d)
{
    rc_solve_result res;
    memset(&res, 0, sizeof res);
    for (unsigned long r = 0; r < runs; ++r) {
        rc_model m;
        const double t0 = now_ms();
        if (rch_calib_start(&m, w, robot, data->s, data->n, d) != 0)
            return -1;
        const double t1 = now_ms();
        rc_solve_config cfg;
        memset(&cfg, 0, sizeof cfg);
        cfg.method = method;
        cfg.seed = 1;
        rc_solve(&m, &res, w, &cfg, data->s, data->n);
        const double t2 = now_ms();
        t_start[r] = t1 - t0;
        t_solve[r] = t2 - t1;
    }
    row->method = method;
    med_range(&row->start_ms, NULL, NULL, t_start, runs);
    med_range(&row->solve_ms, &row->solve_min_ms, &row->solve_max_ms, t_solve, runs);
    row->iterations = res.iterations;
    row->train_rms_mm = res.rms_final_mm;
    return 0;
}

/* The whole calibrate path (rch_calib_run, every sample in training),
 * runs times, by default or (least_squares) with --no-prior --no-jump-check;
 * t (runs) scratch; med, lo, hi: the median and range. */
static int bench_calibrate(double *med, double *lo, double *hi, rch_bench_result *split, const rch_bench_cfg *cfg,
                           int least_squares, double *t, rch_diag *d)
{
    rch_calib_result *cr = malloc(sizeof *cr);
    double *ts = malloc(cfg->runs * RCH_BENCH_N_SPLIT * sizeof *ts); /* (RCH_BENCH_N_SPLIT x runs) */
    if (!cr || !ts) {
        free(cr);
        free(ts);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    rch_calib_cfg cc;
    rch_calib_cfg_init(&cc); /* rcal calibrate --test-fraction 0 */
    cc.data_path = cfg->data_path;
    cc.robot_path = cfg->robot_path;
    cc.test_fraction = 0.0;
    cc.no_prior = cc.no_jump_check = least_squares;
    for (unsigned long k = 0; k < cfg->runs; ++k) {
        const double t0 = now_ms();
        const int rc = rch_calib_run(cr, &cc, d);
        t[k] = now_ms() - t0;
        double tw = 0.0;
        if (rc == 0 && split) { /* writing the model file: to a temporary file */
            FILE *f = tmpfile();
            const double t1 = now_ms();
            if (f) {
                rch_calib_write_model(f, cr);
                fclose(f);
            }
            tw = now_ms() - t1;
        }
        if (rc != 0) {
            free(cr);
            free(ts);
            return -1;
        }
        const double *sw = cr->timing.wall_ms; /* the plan's stages (rch_calib_timing) in the bench's split */
        const double fits = sw[RCH_STAGE_MAP] + sw[RCH_STAGE_ATTACHMENT] + sw[RCH_STAGE_PRIOR_SCALE] +
                            sw[RCH_STAGE_JUMPS] + sw[RCH_STAGE_SYSTEMATIC] + sw[RCH_STAGE_SCREEN];
        const double sp[RCH_BENCH_N_SPLIT] = {sw[RCH_STAGE_READ], sw[RCH_STAGE_START], fits,
                                              sw[RCH_STAGE_JUMP_CHECK], sw[RCH_STAGE_UNCERTAINTY], tw};
        for (unsigned j = 0; j < RCH_BENCH_N_SPLIT; ++j)
            ts[j * cfg->runs + k] = sp[j];
        if (split) {
            split->calib_fits = cr->counts.fits;
            split->calib_jac_passes = cr->counts.jac_passes;
        }
    }
    for (unsigned j = 0; split && j < RCH_BENCH_N_SPLIT; ++j)
        med_range(&split->split_ms[j], NULL, NULL, ts + j * cfg->runs, cfg->runs);
    free(cr);
    free(ts);
    med_range(med, lo, hi, t, cfg->runs);
    return 0;
}

/* `rcal diagnose` with its defaults on one data file or one positions file,
 * diag_runs times (the whole workflow in one process, files included). */
static int bench_diagnose(double *med, double *lo, double *hi, size_t *rows, const rch_bench_cfg *cfg, int positions,
                          double *t, rch_diag *d)
{
    const char *path = positions ? cfg->positions_path : cfg->data_path;
    rch_diagnose_in in;
    memset(&in, 0, sizeof in);
    in.data_paths = positions ? NULL : &path;
    in.n_data = positions ? 0 : 1;
    in.positions_paths = positions ? &path : NULL;
    in.n_positions = positions ? 1 : 0;
    in.robot_path = cfg->robot_path;
    rch_diagnose_cfg dc;
    memset(&dc, 0, sizeof dc);
    rch_diagnose_result *dr = malloc(sizeof *dr);
    if (!dr) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    for (unsigned long k = 0; k < cfg->diag_runs; ++k) {
        const double t0 = now_ms();
        const int rc = rch_diagnose_inputs(dr, &in, &dc, d);
        t[k] = now_ms() - t0;
        if (rows)
            *rows = dr->n / 3;
        rch_diagnose_free(dr);
        if (rc != 0) {
            free(dr);
            return -1;
        }
    }
    free(dr);
    med_range(med, lo, hi, t, cfg->diag_runs);
    return 0;
}

int rch_bench_run(rch_bench_result *r, const rch_bench_cfg *cfg, rch_diag *d)
{
    rch_robot robot;
    rch_data data;
    memset(r, 0, sizeof *r);
    r->runs = cfg->runs;
    if (cfg->runs < 1) {
        rch_diag_set(d, "", 0, 0, "runs must be at least 1");
        return -2;
    }
    if (rch_load_model_and_data(&robot, cfg->robot_path, &data, cfg->data_path, d) != 0)
        return -1;
    r->n_samples = data.n;
    /* every run fits every row with every method (about 50 us per row fit):
     * 21 runs of the 1043 real rows is about 1e5 */
    const double work = (double)cfg->runs * (double)data.n * (double)RCH_BENCH_N_METHODS;
    if (work > RCH_BENCH_MAX_WORK) {
        rch_diag_set(d, "", 0, 0,
                     "%lu runs x %zu rows x %d methods = %.3g row fits, above the limit of %.0e (about 8 min): "
                     "lower --runs or use a smaller --data",
                     cfg->runs, data.n, RCH_BENCH_N_METHODS, work, RCH_BENCH_MAX_WORK);
        rch_data_free(&data);
        return -2;
    }
    rc_solve_work *w = malloc(sizeof *w);
    const unsigned long nt = cfg->runs > cfg->diag_runs ? cfg->runs : cfg->diag_runs;
    double *t_start = malloc(nt * sizeof *t_start), *t_solve = malloc(nt * sizeof *t_solve);
    int rc = (w && t_start && t_solve) ? 0 : -1;
    if (rc != 0)
        rch_diag_set(d, "", 0, 0, "out of memory");
    for (size_t k = 0; k < RCH_BENCH_N_METHODS && rc == 0; ++k)
        rc = bench_method(&r->rows[k], k_methods[k], cfg->runs, w, &robot, &data, t_start, t_solve, d);
    if (rc == 0)
        rc = bench_calibrate(&r->calib_ms, &r->calib_min_ms, &r->calib_max_ms, r, cfg, 0, t_solve, d);
    if (rc == 0)
        rc = bench_calibrate(&r->calib_ls_ms, &r->calib_ls_min_ms, &r->calib_ls_max_ms, NULL, cfg, 1, t_solve, d);
    if (rc == 0 && cfg->diag_runs)
        rc = bench_diagnose(&r->diag_ms, &r->diag_min_ms, &r->diag_max_ms, NULL, cfg, 0, t_solve, d);
    if (rc == 0 && cfg->diag_runs && cfg->positions_path)
        rc = bench_diagnose(&r->diag_pos_ms, &r->diag_pos_min_ms, &r->diag_pos_max_ms, &r->diag_pos_rows, cfg, 1,
                            t_solve, d);
    free(w);
    free(t_start);
    free(t_solve);
    rch_data_free(&data);
    return rc;
}
