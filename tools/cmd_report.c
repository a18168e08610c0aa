/* SPDX-License-Identifier: MIT */
/* cmd_report.c - rcal report: one self-contained HTML page of a calibration
 * (with its diagnosis and model file when given) and the data of its plots as
 * CSV beside it. The work is in tools/host/rch_report.h; see docs/report.md. */
#include <stdio.h>

#include "rcal_cmds.h"
#include "rch_opt.h"
#include "rch_report.h"

int rcal_cmd_report(int argc, char **argv)
{
    rch_report_cfg cfg = {NULL, NULL, NULL, NULL, NULL, NULL};
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
    };
    const rch_cmdspec spec = {
        "report", "an HTML report of a calibration: one self-contained file to hand on",
        "The page has its CSS inline and every plot as inline SVG: no script, no font, image or link that\n"
        "leaves the file. Sections: data, split, before/after metrics, the identified parameters with\n"
        "their standard errors, 95 % intervals and identifiability, the diagnosis, the predicted accuracy\n"
        "over the workspace, warnings, provenance. Members a run does not carry say \"not in this run\".\n"
        "The data of every plot is written beside the page as report_<plot>.csv. See docs/report.md.",
        opts, sizeof opts / sizeof opts[0]};
    const int st = rch_opt_main(&spec, argc, argv, NULL);
    if (st >= 0)
        return st;
    char args[4000], cmdline[4096];
    snprintf(cmdline, sizeof cmdline, "rcal %s", rch_report_cmdline(args, sizeof args, argc, argv));
    cfg.command_line = cmdline;
    rch_report_result res;
    rch_diag d;
    if (rch_report_write(&res, &cfg, &d) != 0)
        return rch_opt_fail(&spec, &d);
    fprintf(stderr, "rcal report: %s written (%u plots, %u warnings, %u places not in this run)\n", cfg.out_path,
            res.n_plots, res.n_warnings, res.n_missing);
    for (unsigned k = 0; k < res.n_csv; ++k)
        fprintf(stderr, "  plot data: %s\n", res.csv[k]);
    return 0;
}
