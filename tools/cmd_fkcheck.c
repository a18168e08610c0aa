/* SPDX-License-Identifier: MIT */
/* cmd_fkcheck.c - rcal fkcheck: does our forward kinematics reproduce the
 * controller's nominal x, y, z columns? Reports every row that does not. The
 * work is rch_fkcheck_run (tools/host/fit/rch_fkcheck.h). */
#include <stdio.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_fkcheck.h"
#include "rch_jw.h"
#include "rch_opt.h"

static const char summary[] = "compare the nominal FK at each row's joint angles with its x, y, z";
static const char details[] = "A row further than T mm is a fault unless a joint change within the 0.1 deg\n"
                              "display rounding explains it. Exit status: 0 no fault, 3 faults found (listed),\n"
                              "1 the check could not run, 2 usage.";

static int report_json(const rch_fkcheck_result *r, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-fkcheck/1", argc, argv);
    rch_jw_uint(&w, "rows", r->rows);
    rch_jw_uint(&w, "faults", r->faults);
    rch_jw_uint(&w, "explained_by_rounding", r->rounding);
    rch_jw_numf(&w, "rms_mm", r->rms_mm, "%.6f");
    rch_jw_numf(&w, "max_mm", r->max_mm, "%.6f");
    rch_jw_numf(&w, "max_consistent_mm", r->max_consistent_mm, "%.6f");
    rch_jw_arr(&w, "fault_lines");
    for (size_t i = 0; i < r->faults; ++i) {
        rch_jw_obj(&w, NULL);
        rch_jw_uint(&w, "line", r->fault[i].line);
        rch_jw_numf(&w, "dist_mm", r->fault[i].dist_mm, "%.6f");
        rch_jw_numf(&w, "dq_deg", r->fault[i].dq_deg, "%.6f");
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

static void report_text(const rch_fkcheck_result *r, const char *data_path, double tol_mm)
{
    printf("FK check of %s against %s (tolerance %.3f mm)\n", data_path, r->robot_name, tol_mm);
    for (size_t i = 0; i < r->faults; ++i) {
        const rch_fk_fault *f = &r->fault[i];
        printf("  FAULT line %u: |FK - xyz| = %.3f mm, needs a joint change of %.3f deg (FK %.2f %.2f %.2f, "
               "file %.2f %.2f %.2f)\n",
               f->line, f->dist_mm, f->dq_deg, f->fk_mm[0], f->fk_mm[1], f->fk_mm[2], f->file_mm[0], f->file_mm[1],
               f->file_mm[2]);
    }
    printf("rows %zu: %zu within %.2f mm, %zu further but explained by the 0.1 deg angle rounding "
           "(|dq| <= %.2f deg), %zu FAULTS.\nlargest consistent difference %.3f mm; RMS of all %.4f mm\n",
           r->rows, r->rows - r->faults - r->rounding, tol_mm, r->rounding, RCH_FK_ROUNDING_DEG, r->faults,
           r->max_consistent_mm, r->rms_mm);
}

int rcal_cmd_fkcheck(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT;
    double tol_mm = 0.5;
    int json = 0;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--data", RCH_OPT_STR, &data_path, 0, 0, "FILE", "measurements with x, y, z columns", RCH_OPT_REQUIRED,
         NULL},
        {"--robot", RCH_OPT_STR, &robot_path, 0, 0, "MODEL.json", "nominal robot model", 0, NULL},
        {"--tol-mm", RCH_OPT_DOUBLE, &tol_mm, 0, 1e6, "T", "rows further than T mm are listed", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "one JSON object on stdout", 0, NULL},
    };
    const int ps = rch_opt_cmd(&spec, "fkcheck", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (ps >= 0)
        return ps;
    rch_fkcheck_result r;
    rch_diag d;
    char msg[1024];
    if (rch_fkcheck_run(&r, data_path, robot_path, tol_mm, &d) != 0) {
        fprintf(stderr, "rcal fkcheck: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rch_fkcheck_free(&r);
        return 1;
    }
    int rc = 0;
    if (json)
        rc = report_json(&r, argc, argv) != 0;
    else
        report_text(&r, data_path, tol_mm);
    if (rc == 0 && r.faults > 0)
        rc = 3; /* the file holds rows the nominal model cannot have produced */
    rch_fkcheck_free(&r);
    return rc;
}
