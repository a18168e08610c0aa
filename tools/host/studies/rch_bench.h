/* SPDX-License-Identifier: MIT */
/* rch_bench.h - calibration speed in one process (prefix rch_bench_), what
 * `rcal bench` reports.
 *
 * Two measurements, each the median (and range) of repeated runs, wall
 * clock (CLOCK_MONOTONIC) on one core:
 *  - per method (lm, ltlm, lm-paper, ltlm-paper): the start (encoder guess +
 *    encoder-only fit, rch_calib_start) and the identification (rc_solve) on
 *    every sample;
 *  - the whole calibrate path: rch_calib_run with every sample in training
 *    (what `rcal calibrate --test-fraction 0` computes before it prints:
 *    reading the robot and data files, the fit, identifiability, the
 *    uncertainty and its workspace map), the figure to set beside the
 *    whole-process times of scripts/bench_ceres.sh (which adds process
 *    start-up and printing); and the same with --no-prior --no-jump-check
 *    (least squares without the jump check: the work the calibrate path did
 *    before the prior, the attachment test and the jump check existed, so
 *    that a version comparison compares the same work).
 * These machines are shared: quote medians and ratios measured in one run.
 * Memory: heap (the solver workspace, the timings); errors: 0 or -1 with
 * the diagnostic in d.
 */
#ifndef RCH_BENCH_H
#define RCH_BENCH_H

#include <stddef.h>

#include "rc_solve.h"
#include "rch_diag.h"

#define RCH_BENCH_N_METHODS 4
/* runs x samples x methods at most (about 8 minutes) */
#define RCH_BENCH_MAX_WORK 1e7

#define RCH_BENCH_N_SPLIT 6 /* read, start, fits, jumps, uncertainty, write */

typedef struct rch_bench_cfg {
    const char *data_path;  /* measurements (every sample is fitted) */
    const char *robot_path; /* nominal robot model */
    unsigned long runs;     /* repetitions of each measurement, >= 1 */
    unsigned long diag_runs; /* repetitions of `rcal diagnose` (0: not timed) */
    const char *positions_path; /* a tracker positions file `rcal diagnose --positions` is timed on, or NULL */
} rch_bench_cfg;

typedef struct rch_bench_row {
    rc_method method;
    double start_ms;                             /* median: encoder guess + encoder-only fit */
    double solve_ms, solve_min_ms, solve_max_ms; /* the identification itself */
    unsigned iterations;
    double train_rms_mm;
} rch_bench_row;

typedef struct rch_bench_result {
    size_t n_samples;
    unsigned long runs;
    rch_bench_row rows[RCH_BENCH_N_METHODS];     /* lm first: the reference of the ratios */
    double calib_ms, calib_min_ms, calib_max_ms; /* rch_calib_run, --test-fraction 0, default method */
    double calib_ls_ms, calib_ls_min_ms, calib_ls_max_ms; /* the same with --no-prior --no-jump-check */
    /* The default run's split (medians, ms): reading the files, the start
     * model, the MAP fits, the jump search, figures and uncertainty, writing
     * the model file (to a temporary file); and its work (the last run). */
    double split_ms[RCH_BENCH_N_SPLIT];
    unsigned calib_fits, calib_jac_passes;
    double diag_ms, diag_min_ms, diag_max_ms;    /* rch_diagnose_inputs on the data, defaults (diag_runs) */
    double diag_pos_ms, diag_pos_min_ms, diag_pos_max_ms; /* on positions_path (diag_runs; 0: not given) */
    size_t diag_pos_rows;                        /* its position rows */
} rch_bench_result;

/* Run the benchmark. -2 (d set) when the work (runs x samples x methods)
 * exceeds RCH_BENCH_MAX_WORK or runs is 0; -1 (d set) when the files cannot
 * be read, memory runs out or a calibration fails. */
int rch_bench_run(rch_bench_result *r, const rch_bench_cfg *cfg, rch_diag *d);

#endif /* RCH_BENCH_H */
