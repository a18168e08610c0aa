/* SPDX-License-Identifier: MIT */
/* rch_ffi_report.c - export and the HTML report through the flat C API (see
 * rch_ffi.h): rch_export_file into a temporary committed on success, and
 * rch_report_write on the handles' JSON saved beside the page. Depends on:
 * rch_export, rch_report, rch_save, rch_file. Memory: none kept. Errors: a
 * status, the message into err; outputs are never written over an input. */
#include <stdio.h>
#include <string.h>

#include "rch_export.h"
#include "rch_ffi_int.h"
#include "rch_file.h"
#include "rch_report.h"
#include "rch_save.h"

/* ---- export and report ---- */

int rch_ffi_export(const char *model_path, const char *out_path, int format, const char *nominal_urdf,
                   int drop_joint_effects, unsigned *written, unsigned *effects_left, char *err, size_t err_len)
{
    if (!model_path || !out_path || (format != RCH_EXPORT_URDF && format != RCH_EXPORT_DH_CSV))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "export: model, output and format 0 (URDF) or 1 (DH CSV)");
    if (nominal_urdf && format != RCH_EXPORT_URDF)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "export: nominal_urdf applies to the URDF format only");
    const char *inputs[2] = {model_path, nominal_urdf};
    rch_out out;
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_out_open(&out, out_path, "--out", inputs, 2, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    rch_export_result res;
    memset(&res, 0, sizeof res);
    if (rch_export_file(&res, out.f, (rch_export_format)format, model_path, nominal_urdf, drop_joint_effects != 0,
                        &d) != 0) {
        rch_out_abort(&out);
        return fail_diag(d.file[0] ? RCH_FFI_ERR_INPUT : RCH_FFI_ERR_ARG, err, err_len, &d);
    }
    if (rch_out_commit(&out, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    if (written)
        *written = format == RCH_EXPORT_URDF ? res.n_joints : res.n_rows;
    if (effects_left)
        *effects_left = res.n_effects_left;
    return RCH_FFI_OK;
}

/* page without .html/.htm, then suffix, into buf (PATH_LEN + 32). */
static void beside(char *buf, size_t len, const char *page, const char *suffix)
{
    size_t n = strlen(page);
    if (n >= 5 && strcmp(page + n - 5, ".html") == 0)
        n -= 5;
    else if (n >= 4 && strcmp(page + n - 4, ".htm") == 0)
        n -= 4;
    snprintf(buf, len, "%.*s%s", (int)n, page, suffix);
}

static void add_path(char *paths, size_t len, const char *p)
{
    const size_t k = strlen(paths);
    if (k < len)
        snprintf(paths + k, len - k, "%s\n", p);
}

int rch_ffi_report(const rch_ffi_calib *c, const rch_ffi_diag *g, const char *html_path, const char *model_path,
                   double tolerance_mm, char *paths, size_t paths_len, char *err, size_t err_len)
{
    if (!c || !html_path || strcmp(html_path, "-") == 0 || strlen(html_path) >= PATH_LEN)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "report: a calibration and a page name (under 1024 bytes; the plot data go beside it)");
    char cal_path[PATH_LEN + 32], diag_path[PATH_LEN + 32];
    beside(cal_path, sizeof cal_path, html_path, ".calibration.json");
    beside(diag_path, sizeof diag_path, html_path, ".diagnosis.json");
    const rch_calib_cfg *cfg = &c->r.cfg;
    const char *ins[RCH_CALIB_MAX_FILES + 6];
    size_t n_ins = 0;
    ins[n_ins++] = model_path;
    ins[n_ins++] = cfg->robot_path;
    ins[n_ins++] = cfg->truth_path;
    ins[n_ins++] = cfg->validate_path;
    for (size_t i = 0; i < cfg->n_data_paths && cfg->data_paths; ++i)
        ins[n_ins++] = cfg->data_paths[i];
    if (g)
        ins[n_ins++] = g->data_path;
    rch_diag d;
    memset(&d, 0, sizeof d);
    const char *const outs[3] = {html_path, cal_path, g ? diag_path : NULL};
    static const char *const what[3] = {"report", "report (its calibration JSON)", "report (its diagnosis JSON)"};
    if (rch_outs_distinct(outs, what, 3, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    if (rch_save(cal_path, what[1], ins, n_ins, rch_ffip_cal_json, &c->r, &d) != 0 ||
        (g && rch_save(diag_path, what[2], ins, n_ins, rch_ffip_diag_json, &g->r, &d) != 0))
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    rch_report_cfg rc = {.cal_path = cal_path, .diag_path = g ? diag_path : NULL, .model_path = model_path,
                         .out_path = html_path, .tolerance_mm = tolerance_mm > 0.0 ? tolerance_mm : 0.0};
    rch_report_result res;
    memset(&res, 0, sizeof res);
    if (rch_report_write(&res, &rc, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    if (paths && paths_len > 0) {
        paths[0] = '\0';
        add_path(paths, paths_len, html_path);
        for (unsigned k = 0; k < res.n_csv && k < RCH_REPORT_MAX_CSV; ++k)
            add_path(paths, paths_len, res.csv[k]);
        add_path(paths, paths_len, cal_path);
        if (g)
            add_path(paths, paths_len, diag_path);
    }
    return RCH_FFI_OK;
}
