/* cmd_compare.c - rcal compare: the LTLM paper's comparison of seven
 * identification methods (its Table 6, Fig. 6d, Figs. 7-8) on your data.
 *
 * Protocol, per case c = 0..cases-1: draw `samples` rows at random (seed
 * derived from --seed and c), hold out round(test_fraction * samples) of
 * them, build the start (BC) model from the training part only
 * (rch_calib_start: nominal DH + encoder fitted alone), run every method from
 * that same start on the same training samples, evaluate on the held-out
 * samples. Nothing is tuned on held-out samples: every hyperparameter is a
 * fixed default documented in rc_est.h / rc_solve.h.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_compare.h"
#include "rch_data.h"
#include "rch_plot.h"
#include "rch_robot.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal compare --data FILE [--robot MODEL.json] [--cases 10] [--samples 300]\n"
            "                    [--test-fraction 0.1] [--seed S] [--methods LIST] [--plots DIR] [--json]\n"
            "  The LTLM paper's protocol: in each case draw --samples rows at random, hold out\n"
            "  --test-fraction of them, fit every method from the same start on the rest, and\n"
            "  report held-out errors (mean +- std over --cases cases) and times.\n"
            "  --samples 0 uses every row. The paper's other protocol: --samples 200 --test-fraction 0.2.\n"
            "  --methods  comma list of LM,EKF,PF,SCA,QIBAS,SSLM,LTLM (or M1..M7); default all\n"
            "  --plots    directory for SVG charts: convergence, bars, times, per-sample errors\n"
            "  --json     one JSON object on stdout instead of the report\n"
            "  --robot    nominal robot model (default %s)\n",
            RCAL_DEFAULT_ROBOT);
}

/* Load, run the protocol, report. */
static int compare_run(const rch_compare_config *cfg, const char *data_path, const char *robot_path,
                       const char *plots, int json)
{
    rch_robot robot;
    rch_data data;
    rch_compare_result res;
    rch_diag d;
    char msg[1024];
    memset(&d, 0, sizeof d);
    if (plots && rch_plot_mkdir(plots) != 0) {
        fprintf(stderr, "rcal compare: cannot use %s as a plot directory: %s\n", plots, strerror(errno));
        return 1;
    }
    if (rch_robot_load(&robot, robot_path, &d) != 0 || rch_data_load(&data, data_path, 0, &d) != 0) {
        fprintf(stderr, "rcal compare: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (cfg->samples > data.n) {
        fprintf(stderr, "rcal compare: --samples %zu but %s has %zu rows\n", cfg->samples, data_path, data.n);
        rch_data_free(&data);
        return 2;
    }
    int rc = rch_compare_run(&res, cfg, &robot, data.s, data.n, json ? NULL : stderr, &d) != 0 ? 1 : 0;
    if (rc == 0) {
        if (json)
            rch_compare_json(stdout, &res, cfg, data_path);
        else
            rch_compare_report(stdout, &res, cfg, data_path);
        if (plots && rch_compare_plots(&res, cfg, plots, json ? NULL : stdout, &d) != 0)
            rc = 1;
        else if (rch_compare_any_failed(&res))
            rc = 1;
    }
    if (rc != 0 && d.msg[0])
        fprintf(stderr, "rcal compare: %s\n", rch_diag_str(&d, msg, sizeof msg));
    rch_compare_free(&res);
    rch_data_free(&data);
    return rc;
}

int rcal_cmd_compare(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT, *plots = NULL;
    const char *methods = NULL;
    rch_compare_config cfg;
    unsigned long cases = 10, samples = 300, seed = 1;
    int json = 0;
    rch_diag d;
    rch_compare_defaults(&cfg);
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--data", &data_path) ||
            rcal_opt_str(argc, argv, &i, "--robot", &robot_path) ||
            rcal_opt_str(argc, argv, &i, "--plots", &plots) ||
            rcal_opt_str(argc, argv, &i, "--methods", &methods) ||
            rcal_opt_double(argc, argv, &i, "--test-fraction", &cfg.test_fraction) ||
            rcal_opt_uint(argc, argv, &i, "--cases", &cases) ||
            rcal_opt_uint(argc, argv, &i, "--samples", &samples) ||
            rcal_opt_uint(argc, argv, &i, "--seed", &seed))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("compare", argv[i]);
    }
    if (!data_path)
        return rcal_opt_missing("compare", "--data");
    if (methods && rch_compare_methods(cfg.run, methods, &d) != 0) {
        fprintf(stderr, "rcal compare: %s\n", d.msg);
        return 2;
    }
    if (!(cfg.test_fraction > 0.0 && cfg.test_fraction < 1.0)) {
        fprintf(stderr, "rcal compare: --test-fraction must be in (0, 1)\n");
        return 2;
    }
    if (cases < 1 || cases > 10000) {
        fprintf(stderr, "rcal compare: --cases must be within 1..10000\n");
        return 2;
    }
    cfg.cases = cases;
    cfg.samples = samples;
    cfg.seed = seed;
    cfg.curves = plots != NULL;
    return compare_run(&cfg, data_path, robot_path, plots, json);
}
