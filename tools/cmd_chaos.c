/* cmd_chaos.c - rcal chaos: the LTLM paper's uniformity study of its
 * logistic-tent map (its Figs. 2-3 and Eq. 12). The study is rch_chaos_run
 * (tools/host/rch_chaos.h); this file parses options and reports.
 */
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_chaos.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: rcal chaos [--r R] [--points 1000] [--bins 50] [--starts 100] [--step 0.01]\n"
               "                  [--seed 1] [--plots DIR] [--json]\n"
               "  Uniformity of the logistic-tent map (paper Eq. 11) for r in [0, 4]: the standard\n"
               "  deviation of the bin counts of --points iterates in --bins bins (Eq. 12), averaged\n"
               "  over --starts initial values; the histogram at --r (default: the minimiser).\n");
}

int rcal_cmd_chaos(int argc, char **argv)
{
    const char *plots = NULL;
    rch_chaos_config cfg;
    rch_chaos_result res;
    rch_diag d;
    unsigned long seed = 1;
    int json = 0;
    rch_chaos_defaults(&cfg);
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--plots", &plots) || rcal_opt_double(argc, argv, &i, "--r", &cfg.r_hist) ||
            rcal_opt_double(argc, argv, &i, "--step", &cfg.step) ||
            rcal_opt_uint(argc, argv, &i, "--points", &cfg.points) || rcal_opt_uint(argc, argv, &i, "--bins", &cfg.bins) ||
            rcal_opt_uint(argc, argv, &i, "--starts", &cfg.starts) || rcal_opt_uint(argc, argv, &i, "--seed", &seed))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("chaos", argv[i]);
    }
    cfg.seed = seed;
    if (rch_chaos_check(&cfg, &d) != 0) {
        fprintf(stderr, "rcal chaos: %s\n", d.msg);
        return 2;
    }
    int rc = rch_chaos_run(&res, &cfg, stderr, &d) == 0 ? 0 : 1;
    if (rc == 0) {
        if (json)
            rch_chaos_json(stdout, &res, &cfg);
        else
            rch_chaos_report(stdout, &res, &cfg);
        if (plots && rch_chaos_plots(&res, &cfg, plots, json ? NULL : stdout, &d) != 0)
            rc = 1;
    }
    if (rc != 0)
        fprintf(stderr, "rcal chaos: %s\n", d.msg);
    rch_chaos_free(&res);
    return rc;
}
