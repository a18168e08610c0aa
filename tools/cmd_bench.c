/* SPDX-License-Identifier: MIT */
/* cmd_bench.c - rcal bench: calibration speed, medians of repeated runs in
 * one process (rch_bench_run, tools/host/studies/rch_bench.h). Times are wall-clock
 * on one core; these machines are shared, so quote the medians and the
 * ratios measured in the same run. The comparison with Ceres (whole
 * processes) is scripts/bench_ceres.sh. */
#include <stdio.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_bench.h"
#include "rch_jw.h"
#include "rch_opt.h"

static const char summary[] = "calibration speed: median/min/max wall time of full calibrations per method";
static const char details[] = "'start' = encoder guess + encoder-only fit; 'solve' = the identification itself;\n"
                              "'calibrate' = the whole calibrate path without printing (rch_calib_run).\n"
                              "Whole processes against Ceres: scripts/bench_ceres.sh.";

static void report_text(const rch_bench_result *r, const char *data_path)
{
    printf("rcal bench: %s, %zu samples, %lu runs each, one core\n", data_path, r->n_samples, r->runs);
    printf("  method      start median   solve median (min..max) ms   iterations  train RMS mm  vs lm\n");
    for (size_t k = 0; k < RCH_BENCH_N_METHODS; ++k) {
        const rch_bench_row *b = &r->rows[k];
        printf("  %-11s %10.2f   %10.2f (%.2f..%.2f)        %6u      %9.4f   %5.2fx\n", rc_method_name(b->method),
               b->start_ms, b->solve_ms, b->solve_min_ms, b->solve_max_ms, b->iterations, b->train_rms_mm,
               r->rows[0].solve_ms > 0 ? b->solve_ms / r->rows[0].solve_ms : 1.0);
    }
    printf("  calibrate (rcal calibrate --test-fraction 0 in one process: files, fit, identifiability, uncertainty "
           "and its map): median %.2f ms (%.2f..%.2f)\n",
           r->calib_ms, r->calib_min_ms, r->calib_max_ms);
    const double *sp = r->split_ms;
    printf("    split (medians, ms): read %.2f, start model %.2f, MAP fits %.2f, jump search %.2f, figures and "
           "uncertainty %.2f, writing the model file %.2f\n"
           "    work: %u fits, %u residual-and-Jacobian passes\n",
           sp[0], sp[1], sp[2], sp[3], sp[4], sp[5], r->calib_fits, r->calib_jac_passes);
    printf("  calibrate --no-prior --no-jump-check (least squares, no jump check: the work of the path before the\n"
           "    prior, the attachment test and the jump check): median %.2f ms (%.2f..%.2f); the default does %.1fx\n"
           "    its time (MAP noise passes, the attachment's evidence test, a jump search, a jump fit when found)\n",
           r->calib_ls_ms, r->calib_ls_min_ms, r->calib_ls_max_ms,
           r->calib_ls_ms > 0.0 ? r->calib_ms / r->calib_ls_ms : 0.0);
    if (r->diag_ms > 0.0)
        printf("  diagnose (rcal diagnose --data, defaults, in one process): median %.1f ms (%.1f..%.1f)\n", r->diag_ms,
               r->diag_min_ms, r->diag_max_ms);
    if (r->diag_pos_ms > 0.0)
        printf("  diagnose --positions (%zu position rows): median %.1f ms (%.1f..%.1f)\n", r->diag_pos_rows,
               r->diag_pos_ms, r->diag_pos_min_ms, r->diag_pos_max_ms);
}

static int report_json(const rch_bench_result *r, const char *data_path, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-bench/1", argc, argv);
    rch_jw_str(&w, "data", data_path);
    rch_jw_uint(&w, "samples", r->n_samples);
    rch_jw_uint(&w, "runs", r->runs);
    rch_jw_arr(&w, "methods");
    for (size_t k = 0; k < RCH_BENCH_N_METHODS; ++k) {
        const rch_bench_row *b = &r->rows[k];
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "method", rc_method_name(b->method));
        rch_jw_numf(&w, "start_median_ms", b->start_ms, "%.4f");
        rch_jw_numf(&w, "solve_median_ms", b->solve_ms, "%.4f");
        rch_jw_numf(&w, "solve_min_ms", b->solve_min_ms, "%.4f");
        rch_jw_numf(&w, "solve_max_ms", b->solve_max_ms, "%.4f");
        rch_jw_uint(&w, "iterations", b->iterations);
        rch_jw_numf(&w, "train_rms_mm", b->train_rms_mm, "%.6f");
        rch_jw_numf(&w, "vs_lm", r->rows[0].solve_ms > 0 ? b->solve_ms / r->rows[0].solve_ms : 1.0, "%.4f");
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_obj(&w, "calibrate");
    rch_jw_numf(&w, "median_ms", r->calib_ms, "%.4f");
    rch_jw_numf(&w, "min_ms", r->calib_min_ms, "%.4f");
    rch_jw_numf(&w, "max_ms", r->calib_max_ms, "%.4f");
    static const char *const names[RCH_BENCH_N_SPLIT] = {"read_ms", "start_ms", "fits_ms", "jump_search_ms",
                                                         "uncertainty_ms", "write_ms"};
    rch_jw_obj(&w, "split_median");
    for (unsigned j = 0; j < RCH_BENCH_N_SPLIT; ++j)
        rch_jw_numf(&w, names[j], r->split_ms[j], "%.4f");
    rch_jw_end(&w);
    rch_jw_uint(&w, "fits", r->calib_fits);
    rch_jw_uint(&w, "jacobian_passes", r->calib_jac_passes);
    rch_jw_end(&w);
    rch_jw_obj(&w, "diagnose");
    rch_jw_numf(&w, "median_ms", r->diag_ms, "%.4f");
    rch_jw_numf(&w, "min_ms", r->diag_min_ms, "%.4f");
    rch_jw_numf(&w, "max_ms", r->diag_max_ms, "%.4f");
    rch_jw_end(&w);
    rch_jw_obj(&w, "diagnose_positions");
    rch_jw_uint(&w, "rows", r->diag_pos_rows);
    rch_jw_numf(&w, "median_ms", r->diag_pos_ms, "%.4f");
    rch_jw_numf(&w, "min_ms", r->diag_pos_min_ms, "%.4f");
    rch_jw_numf(&w, "max_ms", r->diag_pos_max_ms, "%.4f");
    rch_jw_end(&w);
    rch_jw_obj(&w, "calibrate_least_squares");
    rch_jw_numf(&w, "median_ms", r->calib_ls_ms, "%.4f");
    rch_jw_numf(&w, "min_ms", r->calib_ls_min_ms, "%.4f");
    rch_jw_numf(&w, "max_ms", r->calib_ls_max_ms, "%.4f");
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

int rcal_cmd_bench(int argc, char **argv)
{
    rch_bench_cfg cfg = {"../shared/data/robotcali.csv", RCAL_DEFAULT_ROBOT, 21, 0, NULL};
    int json = 0;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--data", RCH_OPT_STR, &cfg.data_path, 0, 0, "FILE", "measurements (all samples are fitted)", 0, NULL},
        {"--robot", RCH_OPT_STR, &cfg.robot_path, 0, 0, "MODEL.json", "nominal robot model", 0, NULL},
        {"--runs", RCH_OPT_UINT, &cfg.runs, 1, 10000, "N", "repetitions of each measurement", 0, NULL},
        {"--diagnose-runs", RCH_OPT_UINT, &cfg.diag_runs, 0, 1000, "N",
         "repetitions of rcal diagnose on --data (and --positions) with its defaults (0: not timed)", 0, NULL},
        {"--positions", RCH_OPT_STR, &cfg.positions_path, 0, 0, "FILE",
         "a tracker positions file rcal diagnose --positions is also timed on", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "one JSON object on stdout", 0, NULL},
    };
    const int ps = rch_opt_cmd(&spec, "bench", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (ps >= 0)
        return ps;
    static rch_bench_result r;
    rch_diag d;
    const int rc = rch_bench_run(&r, &cfg, &d);
    if (rc != 0)
        return rch_opt_fail(&spec, &d) + (rc == -2); /* 2: the arguments ask too much */
    if (json)
        return report_json(&r, cfg.data_path, argc, argv) == 0 ? 0 : 1;
    report_text(&r, cfg.data_path);
    return 0;
}
