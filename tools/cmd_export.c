/* SPDX-License-Identifier: MIT */
/* cmd_export.c - rcal export: a model as a URDF or as a DH table in CSV
 * (tools/host/outputs/rch_export.h, docs/export.md). */
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_export.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_opt.h"

static const char summary[] = "export a model as a URDF or as a DH table in CSV";
static const char details[] =
    "URDF: joint origins from the model's DH table (lengths in m, angles in rad, %.17g), the joint-zero\n"
    "offsets folded into the origins' yaw; the robot, joint and link names of --nominal-urdf when given,\n"
    "else joint_1..joint_6, link_0..link_6, flange. DH CSV: one row per parameter with the nominal,\n"
    "calibrated and correction values (mm, deg) and the standard error when the model has one.\n"
    "See docs/export.md.";

/* What was written, as one JSON object on stdout (rcal-export/1). */
static int report_json(const rch_export_result *res, const char *model, const char *format, const char *out_path,
                       const char *nominal, int drop, int argc, char **argv)
{
    const int urdf = strcmp(format, "urdf") == 0;
    const char *const files[] = {"model", model, "export_format", format, "out", out_path, "nominal_urdf", nominal,
                                 NULL};
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-export/1", argc, argv);
    rch_jw_strs(&w, files);
    if (urdf)
        rch_jw_uint(&w, "joints", res->n_joints);
    else
        rch_jw_uint(&w, "rows", res->n_rows);
    rch_jw_bool(&w, "standard_errors", res->has_se);
    rch_jw_uint(&w, "effects_not_carried", res->n_effects_left);
    rch_jw_bool(&w, "joint_effects_dropped", drop);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

int rcal_cmd_export(int argc, char **argv)
{
    const char *model = NULL, *format = NULL, *out_path = "-", *nominal = NULL;
    int drop = 0, json = 0;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--model", RCH_OPT_STR, &model, 0, 0, "M.json", "the model to export (rcal calibrate --out, or a robot file)",
         RCH_OPT_REQUIRED, NULL},
        {"--format", RCH_OPT_CHOICE, &format, 0, 0, "F", "urdf: the robot as a URDF; dh-csv: the DH table as CSV",
         RCH_OPT_REQUIRED, "urdf|dh-csv"},
        {"--out", RCH_OPT_STR, &out_path, 0, 0, "FILE", "write here (written whole or not at all); - is stdout", 0,
         NULL},
        {"--nominal-urdf", RCH_OPT_STR, &nominal, 0, 0, "NOMINAL.urdf",
         "urdf: take the robot, joint and link names from this URDF", 0, NULL},
        {"--drop-joint-effects", RCH_OPT_FLAG, &drop, 0, 0, NULL,
         "urdf: write the geometry of a model with joint-side effects (its FK then differs)", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "what was written, as one JSON object on stdout (needs --out FILE)",
         0, NULL},
    };
    const int st = rch_opt_cmd(&spec, "export", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st;
    const rch_export_format fmt = strcmp(format, "urdf") == 0 ? RCH_EXPORT_URDF : RCH_EXPORT_DH_CSV;
    if (nominal && fmt != RCH_EXPORT_URDF) {
        fprintf(stderr, "rcal export: --nominal-urdf applies to --format urdf only\n");
        return 2;
    }
    if (json && strcmp(out_path, "-") == 0) {
        fprintf(stderr, "rcal export: --json needs --out FILE (the export would share stdout)\n");
        return 2;
    }
    const char *inputs[2] = {model, nominal};
    rch_out out;
    rch_export_result res;
    rch_diag d;
    char msg[1024];
    if (rch_out_open(&out, out_path, "--out", inputs, 2, &d) != 0) {
        fprintf(stderr, "rcal export: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (rch_export_file(&res, out.f, fmt, model, nominal, drop, &d) != 0) {
        if (!d.file[0]) /* a write error: the file it was writing */
            snprintf(d.file, sizeof d.file, "%.255s", out.path);
        rch_out_abort(&out);
        fprintf(stderr, "rcal export: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (rch_out_commit(&out, &d) != 0) {
        fprintf(stderr, "rcal export: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (nominal && res.overlay)
        fprintf(stderr, "rcal export: %s with its joint origins calibrated (everything else kept)%s\n", nominal,
                res.flange_moved ? "; no fixed joint after joint 6: the flange's change is not carried" : "");
    else if (nominal && res.overlay_why[0])
        fprintf(stderr, "rcal export: not an overlay of %s (%s): a URDF of DH frames with its names written\n",
                nominal, res.overlay_why);
    if (res.n_effects_left)
        fprintf(stderr, "rcal export: %u model effect(s) not carried by the URDF (listed in its comments)\n",
                res.n_effects_left);
    if (json)
        return report_json(&res, model, format, out_path, nominal, drop, argc, argv) != 0;
    if (strcmp(out_path, "-") != 0) {
        if (fmt == RCH_EXPORT_URDF)
            fprintf(stderr, "rcal export: URDF with %u joints written to %s\n", res.n_joints, out_path);
        else
            fprintf(stderr, "rcal export: %u DH CSV rows%s written to %s\n", res.n_rows,
                    res.has_se ? " with standard errors" : "", out_path);
    }
    return 0;
}
