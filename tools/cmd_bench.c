/* SPDX-License-Identifier: MIT */
/* cmd_bench.c - rcal bench: calibration speed, median of repeated runs.
 * Times are wall-clock on one core; these machines are shared, so quote the
 * median and the ratios measured in the same run. The comparison with Ceres
 * (whole processes) is scripts/bench_ceres.sh. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_calib.h"
#include "rch_data.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_robot.h"

typedef struct {
    rc_method method;
    double start_ms;                   /* median: encoder guess + encoder-only fit */
    double solve_ms, solve_min_ms, solve_max_ms; /* the identification itself */
    unsigned iterations;
    double train_rms_mm;
} bench_row;

static const rc_method k_methods[] = {RC_METHOD_LM, RC_METHOD_LTLM, RC_METHOD_LM_PAPER, RC_METHOD_LTLM_PAPER};
#define N_METHODS (sizeof k_methods / sizeof k_methods[0])

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

/* Full calibrations of data with one method, runs times; t_start, t_solve
 * (runs) scratch. 0 or -1 with d set. */
static int bench_method(bench_row *row, rc_method method, unsigned long runs, rc_solve_work *w,
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
    qsort(t_start, runs, sizeof *t_start, cmp_double);
    qsort(t_solve, runs, sizeof *t_solve, cmp_double);
    row->method = method;
    row->start_ms = t_start[runs / 2];
    row->solve_ms = t_solve[runs / 2];
    row->solve_min_ms = t_solve[0];
    row->solve_max_ms = t_solve[runs - 1];
    row->iterations = res.iterations;
    row->train_rms_mm = res.rms_final_mm;
    return 0;
}

static void report_text(const bench_row *rows, const char *data_path, size_t n, unsigned long runs)
{
    printf("rcal bench: %s, %zu samples, %lu runs per method, one core\n", data_path, n, runs);
    printf("  method      start median   solve median (min..max) ms   iterations  train RMS mm  vs lm\n");
    for (size_t k = 0; k < N_METHODS; ++k) {
        const bench_row *b = &rows[k];
        printf("  %-11s %10.2f   %10.2f (%.2f..%.2f)        %6u      %9.4f   %5.2fx\n", rc_method_name(b->method),
               b->start_ms, b->solve_ms, b->solve_min_ms, b->solve_max_ms, b->iterations, b->train_rms_mm,
               rows[0].solve_ms > 0 ? b->solve_ms / rows[0].solve_ms : 1.0);
    }
}

static int report_json(const bench_row *rows, const char *data_path, size_t n, unsigned long runs, int argc,
                       char **argv)
{
    rch_jw w;
    rch_jw_init(&w, stdout, 0);
    rch_jw_obj(&w, NULL);
    rch_jw_header(&w, "rcal-bench/1", argc, argv);
    rch_jw_str(&w, "data", data_path);
    rch_jw_uint(&w, "samples", n);
    rch_jw_uint(&w, "runs", runs);
    rch_jw_arr(&w, "methods");
    for (size_t k = 0; k < N_METHODS; ++k) {
        const bench_row *b = &rows[k];
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "method", rc_method_name(b->method));
        rch_jw_numf(&w, "start_median_ms", b->start_ms, "%.4f");
        rch_jw_numf(&w, "solve_median_ms", b->solve_ms, "%.4f");
        rch_jw_numf(&w, "solve_min_ms", b->solve_min_ms, "%.4f");
        rch_jw_numf(&w, "solve_max_ms", b->solve_max_ms, "%.4f");
        rch_jw_uint(&w, "iterations", b->iterations);
        rch_jw_numf(&w, "train_rms_mm", b->train_rms_mm, "%.6f");
        rch_jw_numf(&w, "vs_lm", rows[0].solve_ms > 0 ? b->solve_ms / rows[0].solve_ms : 1.0, "%.4f");
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* runs x rows x methods at most */
#define RCAL_BENCH_MAX_WORK 1e7

int rcal_cmd_bench(int argc, char **argv)
{
    const char *data_path = "../shared/data/robotcali.csv", *robot_path = RCAL_DEFAULT_ROBOT;
    unsigned long runs = 21;
    int json = 0;
    const rch_opt opts[] = {
        {"--data", RCH_OPT_STR, &data_path, 0, 0, "FILE", "measurements (all samples are fitted)", 0, NULL},
        {"--robot", RCH_OPT_STR, &robot_path, 0, 0, "MODEL.json", "nominal robot model", 0, NULL},
        {"--runs", RCH_OPT_UINT, &runs, 1, 10000, "N", "calibrations per method", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "one JSON object on stdout", 0, NULL},
    };
    const rch_cmdspec spec = {"bench", "calibration speed: median/min/max wall time of full calibrations per method",
                              "'start' = encoder guess + encoder-only fit; 'solve' = the identification itself.\n"
                              "Whole processes against Ceres: scripts/bench_ceres.sh.",
                              opts, sizeof opts / sizeof opts[0]};
    const int ps = rch_opt_main(&spec, argc, argv, NULL);
    if (ps >= 0)
        return ps;
    rch_robot robot;
    rch_data data;
    rch_diag d;
    if (rch_load_model_and_data(&robot, robot_path, &data, data_path, &d) != 0)
        return rch_opt_fail(&spec, &d);
    /* the cost: every run fits every row with every method (about 50 us per
     * row fit): 21 runs of the 1043 real rows is about 1e5 */
    const double work = (double)runs * (double)data.n * (double)(unsigned)N_METHODS;
    if (work > RCAL_BENCH_MAX_WORK) {
        fprintf(stderr,
                "rcal bench: %lu runs x %zu rows x %d methods = %.3g row fits, above the limit of %.0e (about 8 min): "
                "lower --runs or use a smaller --data\n",
                runs, data.n, (int)N_METHODS, work, RCAL_BENCH_MAX_WORK);
        rch_data_free(&data);
        return 2;
    }
    rc_solve_work *w = malloc(sizeof *w);
    double *t_start = malloc(runs * sizeof *t_start), *t_solve = malloc(runs * sizeof *t_solve);
    bench_row rows[N_METHODS];
    int rc = (w && t_start && t_solve) ? 0 : 1;
    if (rc != 0)
        fprintf(stderr, "rcal bench: out of memory\n");
    for (size_t k = 0; k < N_METHODS && rc == 0; ++k)
        if (bench_method(&rows[k], k_methods[k], runs, w, &robot, &data, t_start, t_solve, &d) != 0)
            rc = rch_opt_fail(&spec, &d);
    if (rc == 0 && json)
        rc = report_json(rows, data_path, data.n, runs, argc, argv) == 0 ? 0 : 1;
    else if (rc == 0)
        report_text(rows, data_path, data.n, runs);
    free(w);
    free(t_start);
    free(t_solve);
    rch_data_free(&data);
    return rc;
}
