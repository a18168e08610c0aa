/* SPDX-License-Identifier: MIT */
/* rch_report_inline.c - the page of `rcal report` from a run in this
 * process (calibrate --report, diagnose --report; rch_report.h,
 * rch_report_inline): the run's JSON made in memory, kept beside the page
 * and handed to rch_report_write as text, not written and read back.
 *
 * The model file the run wrote (its text kept by rch_calib_save_model_text)
 * and the data files as the run read them (their digests and poses:
 * rch_calib_result.read_q) go to the page in memory too (rch_report_mem):
 * with them no input and no output of the run is opened again.
 *
 * Depends on: rch_calib (its JSON), rch_diagnose (its JSON), rch_save,
 * rch_report. Memory: the JSON texts freed before returning. Errors: 1 with
 * the message on stderr.
 */
#include "rch_report.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_calib.h"
#include "rch_diagnose.h"
#include "rch_save.h"

#define RCH_REPORT_MAX_INPUTS 64 /* input files a run may name (several --data, robot, validate) */

/* path's name without a .html or .htm ending, followed by suffix. */
static void beside(char *buf, size_t len, const char *path, const char *suffix)
{
    size_t n = strlen(path);
    if (n > 5 && strcmp(path + n - 5, ".html") == 0)
        n -= 5;
    else if (n > 4 && strcmp(path + n - 4, ".htm") == 0)
        n -= 4;
    snprintf(buf, len, "%.*s%s", (int)n, path, suffix);
}

size_t rch_report_bundle(char names[RCH_REPORT_BUNDLE][RCH_REPORT_NAME], const char *html)
{
    static const char *const csv[4] = {"metrics", "params", "accuracy", "candidates"};
    size_t n = 0;
    if (!html || strlen(html) >= 1024)
        return 0;
    beside(names[n++], RCH_REPORT_NAME, html, ".calibration.json");
    beside(names[n++], RCH_REPORT_NAME, html, ".diagnosis.json");
    for (size_t k = 0; k < 4; ++k)
        if (rch_report_csv_path(names[n], RCH_REPORT_NAME, html, csv[k]) == 0)
            ++n;
    return n;
}


/* The run's JSON (as its --json prints it) in memory: *text (heap, *len), 0; -1 when memory runs out. */
static int json_text(char **text, size_t *len, const struct rch_calib_result *cal,
                     const struct rch_diagnose_result *diag, int argc, char **argv)
{
    *text = NULL;
    *len = 0;
    FILE *f = open_memstream(text, len);
    if (!f)
        return -1;
    const int rc = cal ? rch_calib_json(f, cal, argc, argv) : rch_diagnose_json(f, diag, argc, argv);
    if (fclose(f) != 0 || rc != 0) {
        free(*text);
        *text = NULL;
        return -1;
    }
    return 0;
}

/* rch_save's writer of a text in memory. */
typedef struct {
    const char *text;
    size_t len;
} mem_text;
static int text_cb(FILE *f, const void *ctx)
{
    const mem_text *t = ctx;
    return fwrite(t->text, 1, t->len, f) == t->len ? 0 : -1;
}

int rch_report_inline(const char *html, const struct rch_calib_result *cal, const struct rch_diagnose_result *diag,
                      int argc, char **argv, const char *model, const char *const *inputs, size_t n_inputs,
                      int quiet)
{
    return rch_report_inline_model(html, cal, diag, argc, argv, model, NULL, 0, inputs, n_inputs, quiet);
}

/* The run's data files as it read them (cal->read_q, cfg.keep_poses) into data (one per provenance file);
 * the count, 0 when the run kept none (the report then reads the files). */
static size_t run_data(rch_report_data data[RCH_PROV_MAX_FILES], const rch_calib_result *cal)
{
    if (!cal->read_q)
        return 0;
    size_t at = 0;
    const unsigned n = cal->prov.n_files < RCH_PROV_MAX_FILES ? cal->prov.n_files : RCH_PROV_MAX_FILES;
    for (unsigned f = 0; f < n; ++f) {
        const char *sha = cal->prov.sha256[f];
        data[f].file = cal->prov.file[f];
        data[f].sha256 = strlen(sha) == 64 ? sha : NULL; /* "unknown": the file read as it is now */
        data[f].q_rad = (const double(*)[6])(cal->read_q + at);
        data[f].n = cal->read_n[f];
        at += cal->read_n[f];
    }
    return n;
}

int rch_report_inline_model(const char *html, const struct rch_calib_result *cal,
                            const struct rch_diagnose_result *diag, int argc, char **argv, const char *model,
                            const char *model_text, size_t model_len, const char *const *inputs, size_t n_inputs,
                            int quiet)
{
    char cal_path[1100], diag_path[1100], msg[1024];
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (strlen(html) >= 1024 || strcmp(html, "-") == 0) {
        fprintf(stderr, "rcal: --report %s: a file name (under 1024 bytes) is needed, the plot data go beside it\n",
                html);
        return 1;
    }
    beside(cal_path, sizeof cal_path, html, ".calibration.json");
    beside(diag_path, sizeof diag_path, html, ".diagnosis.json");
    const char *ins[RCH_REPORT_MAX_INPUTS + 1];
    size_t n_ins = 0;
    ins[n_ins++] = model;
    for (size_t i = 0; i < n_inputs && n_ins < RCH_REPORT_MAX_INPUTS + 1; ++i)
        ins[n_ins++] = inputs[i];
    char *ct = NULL, *dt = NULL; /* both made by this command line, in memory: written, never read back */
    size_t cl = 0, dl = 0;
    if (json_text(&ct, &cl, cal, NULL, argc, argv) != 0 || (diag && json_text(&dt, &dl, NULL, diag, argc, argv) != 0)) {
        free(ct);
        fprintf(stderr, "rcal: --report: out of memory\n");
        return 1;
    }
    const mem_text cal_t = {ct, cl}, diag_t = {dt, dl};
    rch_report_cfg cfg = {cal_path, diag ? diag_path : NULL, model, html, NULL, NULL, 0.0, ct, dt, cl, dl};
    rch_report_data data[RCH_PROV_MAX_FILES];
    const rch_report_mem mem = {model_text, model_len, data, run_data(data, cal)};
    rch_report_result res;
    int rc = 0;
    if (rch_save(cal_path, "--report (its calibration JSON)", ins, n_ins, text_cb, &cal_t, &d) != 0 ||
        (diag && rch_save(diag_path, "--report (its diagnosis JSON)", ins, n_ins, text_cb, &diag_t, &d) != 0) ||
        rch_report_write_mem(&res, &cfg, &mem, &d) != 0) {
        fprintf(stderr, "rcal: --report: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rc = 1;
    }
    free(ct);
    free(dt);
    if (rc != 0)
        return 1;
    if (!quiet)
        fprintf(stderr, "rcal: report %s written (%u plots, %u warnings; its JSON: %s%s%s)\n", html, res.n_plots,
                res.n_warnings, cal_path, diag ? ", " : "", diag ? diag_path : "");
    return 0;
}
