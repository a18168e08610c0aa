/* SPDX-License-Identifier: MIT */
/* cmd_evaluate.c - rcal evaluate: a calibrated model on data the fit never
 * saw (no refit of the robot). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_data.h"
#include "rch_evaluate.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_resid.h"
#include "rch_robot.h"

static const char summary[] = "a calibrated model on new data, without refitting the robot";
static const char details[] =
    "RMSE, mean |e|, SD and MAX of the cable-length residuals, and the ISO 9283 distance\n"
    "accuracy and repeatability where poses were read more than once.";

static int report_json(const rch_evaluate_result *r, const char *model, const char *data, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, stdout, 1, "rcal-evaluate/1", argc, argv);
    rch_jw_str(&w, "model", model);
    rch_jw_str(&w, "data", data);
    rch_jw_uint(&w, "n", r->m.n);
    rch_jw_bool(&w, "encoder_refitted", r->encoder_refitted);
    rch_jw_nums(&w, "encoder_mm", r->encoder_mm, 3);
    rch_jw_num(&w, "encoder_shift_mm", r->encoder_refitted ? r->encoder_shift_mm : 0.0);
    rch_jw_obj(&w, "residual");
    rch_jw_num(&w, "rmse_mm", r->m.rmse_mm);
    rch_jw_num(&w, "mean_abs_mm", r->m.mean_abs_mm);
    rch_jw_num(&w, "sd_mm", r->m.sd_mm);
    rch_jw_num(&w, "mean_mm", r->m.mean_mm);
    rch_jw_num(&w, "max_mm", r->m.max_mm);
    rch_jw_end(&w);
    rch_jw_obj(&w, "iso9283");
    rch_jw_uint(&w, "poses", r->n_poses);
    rch_jw_uint(&w, "repeated_poses", r->n_repeated);
    rch_jw_num(&w, "ad_mean_mm", r->ad_mean_mm); /* null without repeated poses */
    rch_jw_num(&w, "ad_max_mm", r->ad_max_mm);
    rch_jw_num(&w, "rd_mean_mm", r->rd_mean_mm);
    rch_jw_num(&w, "rd_max_mm", r->rd_max_mm);
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

static void report_text(const rch_evaluate_result *r, const char *model, const char *data)
{
    printf("model %s on %s: %zu samples, no refit of the robot%s\n", model, data, r->m.n,
           r->encoder_refitted ? "; encoder outlet refitted alone" : "");
    if (r->encoder_refitted)
        printf("  encoder outlet %.3f %.3f %.3f mm (moved %.3f mm from the model's)\n", r->encoder_mm[0],
               r->encoder_mm[1], r->encoder_mm[2], r->encoder_shift_mm);
    printf("  RMSE %.4f mm, mean |e| %.4f mm, SD %.4f mm, mean %.4f mm, MAX %.4f mm\n", r->m.rmse_mm, r->m.mean_abs_mm,
           r->m.sd_mm, r->m.mean_mm, r->m.max_mm);
    if (r->n_repeated)
        printf("  ISO 9283 (cable length as the distance, %zu repeated of %zu poses): distance accuracy AD mean "
               "%.4f / max %.4f mm, distance repeatability RD mean %.4f / max %.4f mm\n",
               r->n_repeated, r->n_poses, r->ad_mean_mm, r->ad_max_mm, r->rd_mean_mm, r->rd_max_mm);
    else
        printf("  ISO 9283 distance accuracy and repeatability: no pose was read twice (%zu poses)\n", r->n_poses);
}

int rcal_cmd_evaluate(int argc, char **argv)
{
    const char *model_path = NULL, *data_path = NULL, *resid_path = NULL;
    int refit = 0, json = 0;
    double same_deg = 1e-6;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--model", RCH_OPT_STR, &model_path, 0, 0, "MODEL.json", "calibrated model", RCH_OPT_REQUIRED, NULL},
        {"--data", RCH_OPT_STR, &data_path, 0, 0, "FILE.csv", "measurements the fit never saw", RCH_OPT_REQUIRED, NULL},
        {"--refit-encoder", RCH_OPT_FLAG, &refit, 0, 0, NULL, "refit the encoder outlet alone first", 0, NULL},
        {"--same-pose-deg", RCH_OPT_DOUBLE, &same_deg, 1e-9, 1.0, "DEG", "rows this close in every joint are one pose",
         0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "JSON on stdout", 0, NULL},
        {"--residuals", RCH_OPT_STR, &resid_path, 0, 0, "FILE.csv",
         "each sample's residual (set validate; with the refitted outlet when --refit-encoder); never over an input",
         0, NULL},
    };
    const int st = rch_opt_cmd(&spec, "evaluate", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st;
    rch_robot robot;
    rch_data data;
    rch_diag d;
    char msg[1024];
    if (rch_load_model_and_data(&robot, model_path, &data, data_path, &d) != 0)
        return rch_opt_fail(&spec, &d);
    rch_evaluate_config cfg = {refit, same_deg};
    rch_evaluate_result r;
    rc_solve_work *w = malloc(sizeof *w);
    int rc = w ? rch_evaluate(&r, &robot.model, data.s, data.n, &cfg, w, msg, sizeof msg) : -1;
    free(w);
    if (rc != 0) {
        rch_data_free(&data);
        fprintf(stderr, "rcal evaluate: %s\n", w ? msg : "out of memory");
        return 1;
    }
    if (resid_path) { /* the model as evaluated: the outlet refitted when asked */
        const char *inputs[2] = {model_path, data_path};
        rch_resid_table t;
        rc_model m = robot.model;
        for (unsigned k = 0; k < 3; ++k)
            m.x[RC_P_ENC + k] = r.encoder_mm[k];
        rch_resid_init(&t, inputs + 1, 1);
        rc = rch_resid_add_model(&t, &m, data.s, data.line, NULL, data.n, RCH_RESID_VALIDATE, 0);
        if (rc != 0)
            fprintf(stderr, "rcal evaluate: out of memory\n");
        else if ((rc = rch_resid_save(resid_path, inputs, 2, &t, &d)) != 0)
            fprintf(stderr, "rcal evaluate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rch_resid_free(&t);
    }
    rch_data_free(&data);
    if (rc != 0)
        return 1;
    if (json)
        rc = report_json(&r, model_path, data_path, argc, argv) != 0;
    else
        report_text(&r, model_path, data_path);
    return rc;
}
