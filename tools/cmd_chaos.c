/* SPDX-License-Identifier: MIT */
/* cmd_chaos.c - rcal chaos: the LTLM paper's uniformity study of its
 * logistic-tent map (its Figs. 2-3 and Eq. 12). The study is rch_chaos_run
 * (tools/host/studies/rch_chaos.h); this file parses options and reports.
 */
#include <stdio.h>

#include "rcal_cmds.h"
#include "rch_chaos.h"
#include "rch_opt.h"

/* the usage text: rch_opt_usage prints the option table between these */
static const char summary[] = "uniformity of the logistic-tent map (paper Eq. 11) for r in [0, 4]";
static const char details[] =
    "The standard deviation of the bin counts of --points iterates in --bins bins (Eq. 12), averaged\n"
    "over --starts initial values; the histogram at --r. The study may take at most 1e9 map iterations\n"
    "((4 / --step + 2) x --starts x --points, about 8 s); larger requests are refused.";

int rcal_cmd_chaos(int argc, char **argv)
{
    const char *plots = NULL;
    rch_chaos_config cfg;
    rch_chaos_result res;
    rch_diag d;
    char msg[1024];
    unsigned long seed = 1;
    int json = 0;
    rch_chaos_defaults(&cfg);
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--r", RCH_OPT_DOUBLE, &cfg.r_hist, 0, 4, "R", "r of the histogram (not given: the minimiser)", 0, NULL},
        {"--points", RCH_OPT_UINT, &cfg.points, 1, 1e7, NULL, "iterates per initial value", 0, NULL},
        {"--bins", RCH_OPT_UINT, &cfg.bins, 2, 1024, NULL, "histogram bins on [0, 1)", 0, NULL},
        {"--starts", RCH_OPT_UINT, &cfg.starts, 1, 1e5, NULL, "initial values averaged over", 0, NULL},
        {"--step", RCH_OPT_DOUBLE, &cfg.step, 1e-4, 4, NULL, "r step over [0, 4]", 0, NULL},
        {"--seed", RCH_OPT_UINT, &seed, 0, 4294967295.0, NULL, "seed of the initial values", 0, NULL},
        {"--plots", RCH_OPT_STR, &plots, 0, 0, "DIR", "chaos_sd.svg and chaos_hist.svg, each with its data as .csv", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "one JSON object on stdout instead of the report", 0, NULL},
    };
    const int st = rch_opt_cmd(&spec, "chaos", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st; /* usage printed, or the error named */
    cfg.seed = seed;
    if (rch_chaos_check(&cfg, &d) != 0) {
        fprintf(stderr, "rcal chaos: %s\n", d.msg);
        return 2;
    }
    int rc = rch_chaos_run(&res, &cfg, stderr, &d) == 0 ? 0 : 1;
    if (rc == 0 && json)
        rc = rch_chaos_json(stdout, &res, &cfg, argc, argv) != 0;
    else if (rc == 0)
        rch_chaos_report(stdout, &res, &cfg);
    const rch_plot_dir pd = {plots, NULL, 0, json ? NULL : stdout};
    if (rc == 0 && plots && rch_chaos_plots(&res, &cfg, &pd, &d) != 0)
        rc = 1;
    if (rc != 0)
        fprintf(stderr, "rcal chaos: %s\n", rch_diag_str(&d, msg, sizeof msg));
    rch_chaos_free(&res);
    return rc;
}
