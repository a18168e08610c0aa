/* SPDX-License-Identifier: MIT */
/* cmd_report.c - rcal report: one self-contained HTML page of a calibration
 * (with its diagnosis and model file when given) and the data of its plots as
 * CSV beside it. The work is in tools/host/outputs/rch_report.h; see docs/report.md. */
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_calib.h"
#include "rch_diagnose.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_report.h"
#include "rch_save.h"
#include "rch_text.h"

static const char summary[] = "an HTML report of a calibration: one self-contained file to hand on";
static const char details[] =
    "The page has its CSS inline and every plot as inline SVG: no script, no font, image or link that\n"
    "leaves the file. First the verdict: the predicted 95 % accuracy after compensation over the data's\n"
    "poses and the workspace (pass or fail with --tolerance-mm), the held-out figures and what they rest on.\n"
    "Sections: data (with every nuisance fitted), split, before/after metrics, the identified parameters with\n"
    "their standard errors, 95 % intervals and identifiability, the diagnosis, the predicted accuracy\n"
    "over the workspace, warnings, provenance. Members a run does not carry say \"not in this run\".\n"
    "The data of every plot is written beside the page, named from it (x.html: x_metrics.csv, x_params.csv,\n"
    "...); the page and its CSVs are written whole or not at all. See docs/report.md.";

int rcal_outputs_check(const char *cmd, const char *const *outs, const char *const *whats, size_t n,
                       const char *html, const char *const *inputs, size_t n_inputs)
{
    enum { MAX_OUTS = 16 };
    char bundle[RCH_REPORT_BUNDLE][RCH_REPORT_NAME], msg[1024];
    const char *all[MAX_OUTS + RCH_REPORT_BUNDLE], *all_what[MAX_OUTS + RCH_REPORT_BUNDLE];
    size_t m = 0;
    for (size_t k = 0; k < n && m < MAX_OUTS; ++k) {
        all[m] = outs[k];
        all_what[m++] = whats[k];
    }
    const size_t nb = rch_report_bundle(bundle, html);
    for (size_t k = 0; k < nb; ++k) {
        all[m] = bundle[k];
        all_what[m++] = "--report (a file beside the page)";
    }
    rch_diag d;
    if (rch_outs_distinct(all, all_what, m, &d) != 0) {
        fprintf(stderr, "rcal %s: %s\n", cmd, rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    for (size_t k = 0; k < m; ++k)
        for (size_t i = 0; all[k] && strcmp(all[k], "-") != 0 && i < n_inputs; ++i)
            if (inputs[i] && rch_path_same(all[k], inputs[i])) {
                fprintf(stderr, "rcal %s: %s %s is also the input %s: refused, nothing written\n", cmd, all_what[k],
                        all[k], inputs[i]);
                return 1;
            }
    return 0;
}

/* What the page lacks, one line per way of getting it: "  not in this
 * run: noise floor, the diagnosis; needs a diagnosis: rcal diagnose ...". */
static void print_missing(const rch_report_result *res)
{
    for (unsigned k = 0; k < res->n_missing_items; ++k) {
        unsigned seen = 0;
        for (unsigned i = 0; i < k; ++i)
            seen |= strcmp(res->missing[i].how, res->missing[k].how) == 0;
        if (seen)
            continue;
        fputs("  not in this run: ", stderr);
        for (unsigned i = k, n = 0; i < res->n_missing_items; ++i)
            if (strcmp(res->missing[i].how, res->missing[k].how) == 0)
                fprintf(stderr, "%s%s", n++ ? ", " : "", res->missing[i].what);
        if (res->missing[k].how[0])
            fprintf(stderr, "; needs %s\n", res->missing[k].how);
        else
            fputs("; the calibration output has none\n", stderr);
    }
}

/* What was written, as one JSON object on stdout (rcal-report/1). */
static int report_json(const rch_report_result *res, const rch_report_cfg *cfg, int argc, char **argv)
{
    const char *const files[] = {"calibration", cfg->cal_path, "diagnosis", cfg->diag_path, "model", cfg->model_path,
                                 "out", cfg->out_path, NULL};
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-report/1", argc, argv);
    rch_jw_strs(&w, files);
    rch_jw_arr(&w, "plot_data");
    for (unsigned k = 0; k < res->n_csv; ++k)
        rch_jw_str(&w, NULL, res->csv[k]);
    rch_jw_end(&w);
    rch_jw_uint(&w, "plots", res->n_plots);
    rch_jw_uint(&w, "warnings", res->n_warnings);
    rch_jw_uint(&w, "not_in_this_run", res->n_missing);
    rch_jw_arr(&w, "not_in_this_run_items"); /* each distinct one and how a run gets it ("": it cannot) */
    for (unsigned k = 0; k < res->n_missing_items; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "what", res->missing[k].what);
        rch_jw_str(&w, "how", res->missing[k].how);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

int rcal_cmd_report(int argc, char **argv)
{
    rch_report_cfg cfg = {NULL, NULL, NULL, NULL, NULL, NULL, 0.0, NULL, NULL, 0, 0};
    int json = 0;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--calibration", RCH_OPT_STR, &cfg.cal_path, 0, 0, "CAL.json", "the output of rcal calibrate --json",
         RCH_OPT_REQUIRED, NULL},
        {"--diagnosis", RCH_OPT_STR, &cfg.diag_path, 0, 0, "DIAG.json", "the output of rcal diagnose --json", 0,
         NULL},
        {"--model", RCH_OPT_STR, &cfg.model_path, 0, 0, "MODEL.json",
         "the model file of the run (rcal calibrate --out): robot name, and its uncertainty and provenance "
         "when the calibration output has none",
         0, NULL},
        {"--out", RCH_OPT_STR, &cfg.out_path, 0, 0, "report.html",
         "the HTML page (written whole or not at all, never over an input)", RCH_OPT_REQUIRED, NULL},
        {"--tolerance-mm", RCH_OPT_DOUBLE, &cfg.tolerance_mm, 0.001, 1000.0, "MM",
         "the verdict: pass when the compensated robot's 95 % position radius stays within MM over the data's poses "
         "(the largest), fail otherwise",
         0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "what was written, as one JSON object on stdout", 0, NULL},
    };
    const int st = rch_opt_cmd(&spec, "report", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st;
    char args[4000], cmdline[4096];
    snprintf(cmdline, sizeof cmdline, "rcal %s", rch_shell_join(args, sizeof args, argc, (const char *const *)argv));
    cfg.command_line = cmdline;
    rch_report_result res;
    rch_diag d;
    if (rch_report_write(&res, &cfg, &d) != 0)
        return rch_opt_fail(&spec, &d);
    if (json)
        return report_json(&res, &cfg, argc, argv) != 0;
    fprintf(stderr, "rcal report: %s written (%u plots, %u warnings, %u place%s saying \"not in this run\"%s)\n",
            cfg.out_path, res.n_plots, res.n_warnings, res.n_missing, res.n_missing == 1 ? "" : "s",
            res.n_missing ? ", below" : "");
    print_missing(&res);
    for (unsigned k = 0; k < res.n_csv; ++k)
        fprintf(stderr, "  plot data: %s\n", res.csv[k]);
    return 0;
}
