/* SPDX-License-Identifier: MIT */
/* cmd_compare.c - rcal compare: the LTLM paper's comparison of seven
 * identification methods (its Table 6, Fig. 6d, Figs. 7-8) on your data.
 * The protocol is rch_compare_run (tools/host/studies/rch_compare.h); this file
 * parses options, loads the robot and the data, and reports.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_compare.h"
#include "rch_cost.h"
#include "rch_calib_effects.h"
#include "rch_data.h"
#include "rch_dequant.h"
#include "rch_opt.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_plot.h"
#include "rch_resid.h"
#include "rch_robot.h"

/* the usage text: rch_opt_usage prints the option table between these */
static const char summary[] = "the LTLM paper's comparison of seven identification methods on your data";
static const char details[] =
    "In each case --samples rows are drawn at random, --test-fraction of them held out, every method\n"
    "fitted from the same start (nominal DH + encoder fitted alone) on the rest; the report gives the\n"
    "held-out errors (mean +- std over --cases cases) and times. The paper's other protocol:\n"
    "--samples 200 --test-fraction 0.2. --params both runs the paper's set-up and the common parameter set\n"
    "(plots and models then go to DIR/paper and DIR/common).";

/* The cost of the whole command before any work (both sets run the
 * protocol twice): refused above --max-minutes, said above 10 s. 0 or -1. */
static int check_cost(const rch_compare_config *cfg, size_t n, int both)
{
    /* the cost of the whole command before any work: both sets run the protocol twice */
    const double est_s = (both ? 2.0 : 1.0) * rch_compare_estimate_s(cfg, n);
    const double lim_min = cfg->max_minutes > 0.0 ? cfg->max_minutes : RCH_COMPARE_MAX_MINUTES;
    char b1[32];
    if (est_s > 60.0 * lim_min) {
        fprintf(stderr, "rcal compare: %lu cases of %zu rows%s would take about %s (measured cost per row on the "
                        "reference machine, docs/methods.md), above the limit of %.0f min: lower --cases or "
                        "--samples, or raise --max-minutes\n",
                cfg->cases, cfg->samples && cfg->samples < n ? cfg->samples : n,
                both ? ", both parameter sets," : "", rch_cost_human(b1, sizeof b1, est_s), lim_min);
        return -1;
    }
    if (est_s > 10.0)
        fprintf(stderr, "rcal compare: about %s (progress below)\n", rch_cost_human(b1, sizeof b1, est_s));
    return 0;
}

/* DIR, or DIR/paper and DIR/common when both sets run; NULL stays NULL. */
static const char *sub_dir(char *buf, size_t len, const char *dir, int both, rch_compare_params p)
{
    if (!dir || !both)
        return dir;
    snprintf(buf, len, "%s/%s", dir, rch_compare_params_name(p));
    return buf;
}

/* What the command writes besides the report. */
typedef struct compare_out {
    const char *plots, *models, *resid; /* directories / file, or NULL */
    const char *effects;                /* --effects LIST, or NULL */
    int json, both;                     /* --json; --params both */
    int dequantize;                     /* --dequantize-joints */
    int argc;                           /* the command line, for the JSON header */
    char **argv;
} compare_out;

/* Load, run the protocol (once per parameter set), report. */
static int compare_run(const rch_compare_config *cfg_in, const char *data_path, const char *robot_path,
                       const compare_out *o)
{
    rch_compare_config c = *cfg_in, *cfg = &c; /* gets the inputs and the set's directories */
    rch_robot robot;
    rch_data data;
    rch_compare_result res;
    rch_diag d;
    char msg[1024], pbuf[1100], mbuf[1100];
    const char *const inputs[2] = {data_path, robot_path};
    memset(&d, 0, sizeof d);
    if (o->plots && rch_plot_mkdir(o->plots) != 0) {
        fprintf(stderr, "rcal compare: cannot use %s as a plot directory: %s\n", o->plots, strerror(errno));
        return 1;
    }
    if (rch_robot_load(&robot, robot_path, &d) != 0 ||
        rch_data_load_limited(&data, data_path, 0, &robot.model, &d) != 0 ||
        (o->effects && rch_calib_effects(&robot.model, o->effects, &d) != 0)) {
        fprintf(stderr, "rcal compare: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (o->dequantize) { /* the joint angles from x, y, z (rch_dequant); inconsistent rows dropped */
        if (!data.xyz) {
            fprintf(stderr, "rcal compare: --dequantize-joints needs the x, y, z columns of %s\n", data_path);
            rch_data_free(&data);
            return 1;
        }
        uint8_t *bad = calloc(data.n + 1, 1);
        rch_dequant_result q;
        size_t k = 0;
        if (!bad) {
            rch_data_free(&data);
            return 1;
        }
        rch_dequant(&q, bad, data.s, data.n, (const double(*)[3])data.xyz, &robot.nominal, 0.0);
        for (size_t i = 0; i < data.n; ++i)
            if (!bad[i]) {
                data.s[k] = data.s[i];
                data.line[k] = data.line[i];
                memcpy(data.xyz[k], data.xyz[i], sizeof data.xyz[k]);
                ++k;
            }
        data.n = k;
        free(bad);
        if (!o->json)
            printf("joints dequantized from x, y, z: %zu rows corrected (RMS %.4f deg), %zu refused and dropped\n",
                   q.n_corrected, q.dq_rms_deg, q.n_refused);
    }
    if (cfg->samples > data.n) {
        fprintf(stderr, "rcal compare: --samples %zu but %s has %zu rows\n", cfg->samples, data_path, data.n);
        rch_data_free(&data);
        return 2;
    }
    cfg->inputs = inputs;
    cfg->n_inputs = 2;
    if (check_cost(cfg, data.n, o->both) != 0) {
        rch_data_free(&data);
        return 2;
    }
    int rc = 0;
    for (int k = 0; k < (o->both ? 2 : 1) && rc == 0; ++k) {
        if (o->both)
            cfg->params = k == 0 ? RCH_PARAMS_PAPER : RCH_PARAMS_COMMON;
        const char *plots = sub_dir(pbuf, sizeof pbuf, o->plots, o->both, cfg->params);
        cfg->models_dir = sub_dir(mbuf, sizeof mbuf, o->models, o->both, cfg->params);
        if (k > 0 && !o->json)
            printf("\n");
        /* progress and per-case failures on stderr, whatever the report format */
        rc = rch_compare_run(&res, cfg, &robot, data.s, data.n, stderr, &d) != 0 ? 1 : 0;
        if (rc == 0 && o->json)
            rc = rch_compare_json(stdout, &res, cfg, data_path, o->argc, o->argv) != 0;
        else if (rc == 0)
            rch_compare_report(stdout, &res, cfg, data_path);
        const rch_plot_dir pd = {plots, inputs, 2, o->json ? NULL : stdout};
        if (rc == 0 && plots && rch_compare_plots(&res, cfg, &pd, &d) != 0)
            rc = 1;
        if (rc == 0 && cfg->models_dir && !o->json)
            printf("  models of case 1: %s/BC.json, M1-LM.json .. M7-LTLM.json\n", cfg->models_dir);
        if (rc == 0 && o->resid) { /* case 1, every method */
            rch_resid_table t;
            rch_resid_init(&t, inputs, 1);
            if (rch_compare_resid(&t, &res, data.s, data.line) != 0) {
                rch_diag_set(&d, "", 0, 0, "out of memory");
                rc = 1;
            } else {
                rc = rch_resid_save(o->resid, inputs, 2, &t, &d) != 0;
            }
            rch_resid_free(&t);
        }
        if (rc == 0 && rch_compare_any_failed(&res))
            rc = 1; /* reported per case on stderr and in the table */
        if (rc != 0 && d.msg[0])
            fprintf(stderr, "rcal compare: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rch_compare_free(&res);
    }
    rch_data_free(&data);
    return rc;
}

int rcal_cmd_compare(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT, *plots = NULL, *methods = NULL, *models = NULL;
    const char *params = "paper", *resid = NULL, *effects = NULL;
    int literal = 0, jumps = 0, prior = 0, dequantize = 0, tool_offset = 0;
    unsigned long cases = 10, samples = 300, seed = 1;
    double test_fraction = 0.1, max_minutes = RCH_COMPARE_MAX_MINUTES;
    int json = 0;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--data", RCH_OPT_STR, &data_path, 0, 0, "FILE", "measurements (CSV with q1..q6 in deg and L in mm)",
         RCH_OPT_REQUIRED, NULL},
        {"--robot", RCH_OPT_STR, &robot_path, 0, 0, "MODEL.json", "nominal robot model", 0, NULL},
        {"--cases", RCH_OPT_UINT, &cases, 1, (double)RCH_COMPARE_MAX_CASES, NULL, "random cases", 0, NULL},
        {"--samples", RCH_OPT_UINT, &samples, 0, (double)RCH_DATA_MAX_ROWS, NULL, "rows drawn per case; 0 means every row",
         0, NULL},
        {"--test-fraction", RCH_OPT_DOUBLE, &test_fraction, 0.001, 0.999, "F", "share of each case held out", 0,
         NULL},
        {"--seed", RCH_OPT_UINT, &seed, 0, 4294967295.0, NULL, "case c draws with seed * 1000003 + c", 0, NULL},
        {"--methods", RCH_OPT_STR, &methods, 0, 0, "LIST",
         "comma list of LM,EKF,PF,SCA,QIBAS,SSLM,LTLM (or M1..M7), LM-paper, LM-paper-deg, LTLM-paper, "
         "LTLM-paper-deg; default the seven", 0, NULL},
        {"--plots", RCH_OPT_STR, &plots, 0, 0, "DIR", "SVG charts (each with its data as .csv): convergence, bars, times, per-sample errors", 0,
         NULL},
        {"--params", RCH_OPT_CHOICE, &params, 0, 0, "SET",
         "paper: the paper's set-up (LM/LTLM all parameters, the others a subset, a narrow box); common: every "
         "method on one identifiable set; both: one table each",
         0, "paper|common|both"},
        {"--models", RCH_OPT_STR, &models, 0, 0, "DIR",
         "write case 1's model of every row (BC.json, M1-LM.json .. M7-LTLM.json) for rcal grind --models", 0, NULL},
        {"--literal", RCH_OPT_FLAG, &literal, 0, 0, NULL,
         "also the paper's own M1 and M7: LM-paper (Eq. 10, mu = 5, no acceptance) and LTLM-paper (Algorithm I), "
         "angles in rad and in deg (-deg), beside the robust rows",
         0, NULL},
        {"--jumps", RCH_OPT_FLAG, &jumps, 0, 0, NULL,
         "fit length jumps at change points in acquisition order with every method (nuisance; rch_jumps)", 0, NULL},
        {"--dequantize-joints", RCH_OPT_FLAG, &dequantize, 0, 0, NULL,
         "recover the joint angles rounded in the file from its x, y, z (rows that cannot be are dropped)", 0, NULL},
        {"--effects", RCH_OPT_STR, &effects, 0, 0, "LIST",
         "model effects every method fits (rcal calibrate --effects names: tool_offset, length_offset, ...)", 0,
         NULL},
        {"--tool-offset", RCH_OPT_FLAG, &tool_offset, 0, 0, NULL, "the cable attachment off the flange centre "
         "(the tool_offset effect)", 0, NULL},
        {"--max-minutes", RCH_OPT_DOUBLE, &max_minutes, 0.01, 1e7, "MIN",
         "refuse a comparison estimated longer (both sets together); the estimate is printed above 10 s", 0, NULL},
        {"--prior", RCH_OPT_FLAG, &prior, 0, 0, NULL,
         "LM and LTLM maximum a posteriori with the robot's physical prior (as rcal calibrate; the others ignore it)",
         0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "one JSON object on stdout instead of the report", 0, NULL},
        {"--residuals", RCH_OPT_STR, &resid, 0, 0, "FILE.csv",
         "case 1's rows (test and train) with the BC residual and one column per method; never over an input", 0,
         NULL},
    };
    rch_compare_config cfg;
    rch_diag d;
    const int st = rch_opt_cmd(&spec, "compare", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st; /* usage printed, or the error named */
    rch_compare_defaults(&cfg);
    if (methods && rch_compare_methods(cfg.run, methods, &d) != 0) {
        fprintf(stderr, "rcal compare: %s\n", d.msg);
        return 2;
    }
    cfg.cases = cases;
    cfg.samples = samples;
    cfg.test_fraction = test_fraction;
    cfg.seed = seed;
    cfg.curves = plots != NULL;
    const int both = strcmp(params, "both") == 0;
    if (both && (json || resid)) {
        fprintf(stderr, "rcal compare: --%s takes one parameter set: --params paper or common\n",
                json ? "json" : "residuals");
        return 2;
    }
    cfg.params = strcmp(params, "common") == 0 ? RCH_PARAMS_COMMON : RCH_PARAMS_PAPER;
    if (literal)
        cfg.run[RCH_EST_LM_PAPER] = cfg.run[RCH_EST_LM_PAPER_DEG] = cfg.run[RCH_EST_LTLM_PAPER] =
            cfg.run[RCH_EST_LTLM_PAPER_DEG] = 1;
    cfg.jumps = jumps;
    cfg.prior = prior;
    cfg.max_minutes = max_minutes;
    char eff[512];
    if (tool_offset)
        snprintf(eff, sizeof eff, "%s%s%s", effects ? effects : "", effects ? "," : "", "tool_offset");
    const compare_out o = {plots, models, resid, tool_offset ? eff : effects, json, both, dequantize, argc, argv};
    return compare_run(&cfg, data_path, robot_path, &o);
}
