/* cmd_bench.c - rcal bench: calibration speed, median of repeated runs.
 * Times are wall-clock on one core; these machines are shared, so quote the
 * median and the ratios measured in the same run. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_calib.h"
#include "rch_data.h"
#include "rch_robot.h"

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

int rcal_cmd_bench(int argc, char **argv)
{
    const char *data_path = "../shared/data/robotcali.csv", *robot_path = RCAL_DEFAULT_ROBOT;
    unsigned long runs = 21;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--data", &data_path) || rcal_opt_str(argc, argv, &i, "--robot", &robot_path) ||
            rcal_opt_uint(argc, argv, &i, "--runs", &runs))
            continue;
        if (strcmp(argv[i], "--help") == 0) {
            printf("usage: rcal bench [--data FILE (default ../shared/data/robotcali.csv)] [--robot MODEL] "
                   "[--runs N (21)]\n"
                   "Full calibration on all samples of FILE, per method: median/min/max wall time over N runs.\n"
                   "'start' = encoder guess + encoder-only fit; 'solve' = the identification itself.\n");
            return 0;
        }
        return rcal_opt_unknown("bench", argv[i]);
    }
    if (runs < 1 || runs > 10000)
        runs = 21;
    rch_robot robot;
    rch_data data;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, robot_path, &d) != 0 || rch_data_load(&data, data_path, 0, &d) != 0) {
        fprintf(stderr, "rcal bench: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    rc_solve_work *w = malloc(sizeof *w);
    double *t_start = malloc(runs * sizeof *t_start), *t_solve = malloc(runs * sizeof *t_solve);
    int rc = 0;
    if (!w || !t_start || !t_solve) {
        fprintf(stderr, "rcal bench: out of memory\n");
        rc = 1;
        goto done;
    }
    static const rc_method methods[] = {RC_METHOD_LM, RC_METHOD_LTLM, RC_METHOD_LM_PAPER, RC_METHOD_LTLM_PAPER};
    double lm_median = 0.0;
    printf("rcal bench: %s, %zu samples, %lu runs per method, one core\n", data_path, data.n, runs);
    printf("  method      start median   solve median (min..max) ms   iterations  train RMS mm  vs lm\n");
    for (size_t k = 0; k < sizeof methods / sizeof methods[0]; ++k) {
        rc_solve_result res;
        memset(&res, 0, sizeof res);
        for (unsigned long r = 0; r < runs; ++r) {
            rc_model m;
            const double t0 = now_ms();
            if (rch_calib_start(&m, w, &robot, data.s, data.n, &d) != 0) {
                fprintf(stderr, "rcal bench: %s\n", rch_diag_str(&d, msg, sizeof msg));
                rc = 1;
                goto done;
            }
            const double t1 = now_ms();
            rc_solve_config cfg;
            memset(&cfg, 0, sizeof cfg);
            cfg.method = methods[k];
            cfg.seed = 1;
            rc_solve(&m, &res, w, &cfg, data.s, data.n);
            const double t2 = now_ms();
            t_start[r] = t1 - t0;
            t_solve[r] = t2 - t1;
        }
        qsort(t_start, runs, sizeof *t_start, cmp_double);
        qsort(t_solve, runs, sizeof *t_solve, cmp_double);
        const double med = t_solve[runs / 2];
        if (k == 0)
            lm_median = med;
        printf("  %-11s %10.2f   %10.2f (%.2f..%.2f)        %6u      %9.4f   %5.2fx\n", rc_method_name(methods[k]),
               t_start[runs / 2], med, t_solve[0], t_solve[runs - 1], res.iterations, res.rms_final_mm,
               lm_median > 0 ? med / lm_median : 1.0);
    }
done:
    free(w);
    free(t_start);
    free(t_solve);
    rch_data_free(&data);
    return rc;
}
