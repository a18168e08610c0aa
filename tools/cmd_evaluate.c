/* SPDX-License-Identifier: MIT */
/* cmd_evaluate.c - rcal evaluate: a calibrated model on data the fit never
 * saw (no refit of the robot). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_data.h"
#include "rch_evaluate.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_positions.h"
#include "rch_resid.h"
#include "rch_robot.h"

static const char summary[] = "a calibrated model on new data, without refitting the robot";
static const char details[] =
    "RMSE, mean |e|, SD and MAX of the cable-length residuals, and the ISO 9283 distance\n"
    "accuracy and repeatability where poses were read more than once. With --positions (laser-tracker\n"
    "positions, docs/positions.md): the 3-D error |p_model - p_measured| (RMS, mean, MAX) and ISO 9283 AP and\n"
    "RP where a pose was measured more than once; nothing of the robot is refitted: the model's tracker frame\n"
    "is kept when it has one (calibrated from that tracker) and only the targets it lacks are fitted, else\n"
    "the tracker frame and every target are fitted (--refit-tracker: always).";

static int positions_report(const rch_pos_eval *r, const rch_pos *p, const char *model, const char *data, int json,
                            int argc, char **argv)
{
    const char *how = r->frame_fitted ? "fitted" : "kept";
    if (json) {
        rch_jw w;
        rch_jw_begin(&w, stdout, 1, "rcal-evaluate/1", argc, argv);
        rch_jw_str(&w, "model", model);
        rch_jw_str(&w, "positions", data);
        rch_jw_uint(&w, "n", p->n);
        rch_jw_uint(&w, "rows", p->rows);
        rch_jw_str(&w, "tracker_frame", how);
        rch_jw_nums(&w, "tracker_frame_params", r->frame, 6);
        rch_jw_uint(&w, "targets_known", r->targets_known);
        rch_jw_uint(&w, "targets_fitted", r->targets_fitted);
        rch_jw_numf(&w, "component_rms_mm", r->rms_component_mm, "%.6f");
        rch_pos_err_json(&w, "position_error_mm", &r->err);
        rch_jw_end(&w);
        return rch_jw_finish(&w);
    }
    printf("model %s on the tracker positions %s: %zu positions (%zu poses), no refit of the robot\n", model, data,
           r->err.points, p->poses);
    if (r->frame_fitted)
        printf("  tracker frame fitted here (the model has none from this tracker, or --refit-tracker), and %u "
               "target(s)\n", r->targets_fitted);
    else
        printf("  tracker frame kept from the model (calibrated from this tracker); %u target(s) known, %u fitted "
               "here\n", r->targets_known, r->targets_fitted);
    printf("  3-D position error |p_model - p_measured|: RMS %.4f mm, mean %.4f mm, MAX %.4f mm\n", r->err.rms_mm,
           r->err.mean_mm, r->err.max_mm);
    if (r->err.repeated)
        printf("  ISO 9283 over %zu repeated pose-targets: positioning accuracy AP max %.4f mm, repeatability RP max "
               "%.4f mm\n", r->err.repeated, r->err.ap_max_mm, r->err.rp_max_mm);
    else
        printf("  ISO 9283 AP and RP: no pose was measured twice\n");
    return 0;
}

static int evaluate_positions(const char *model_path, const char *pos_path, int refit, int json, int argc,
                              char **argv)
{
    rch_robot robot;
    rch_pos p;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, model_path, &d) != 0 || rch_pos_load(&p, &pos_path, 1, 0.0, &robot.nominal, &d) != 0) {
        fprintf(stderr, "rcal evaluate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    rch_pos_eval *r = malloc(sizeof *r);
    rc_solve_work *w = malloc(sizeof *w);
    int rc = r && w ? rch_pos_evaluate(r, &robot.model, &p, refit, w, msg, sizeof msg) : -1;
    if (rc != 0)
        fprintf(stderr, "rcal evaluate: %s: %s\n", pos_path, r && w ? msg : "out of memory");
    else
        rc = positions_report(r, &p, model_path, pos_path, json, argc, argv) != 0;
    free(r);
    free(w);
    rch_pos_free(&p);
    return rc != 0;
}

static int report_json(const rch_evaluate_result *r, const rch_robot *robot, const char *model, const char *data,
                       int argc, char **argv)
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
    /* the text's jumps note: fitted as nuisance of the calibration's
     * acquisition, never applied here */
    rch_jw_obj(&w, "calibration_jumps");
    rch_jw_uint(&w, "n", robot->n_cal_jumps);
    if (robot->n_cal_jumps)
        rch_jw_num(&w, "max_mm", robot->cal_jump_max_mm);
    else
        rch_jw_null(&w, "max_mm");
    rch_jw_bool(&w, "applied", 0);
    rch_jw_bool(&w, "data_is_calibration_file", robot->cal_data[0] && rch_path_same(data, robot->cal_data));
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* The length jumps the calibration fitted are a nuisance of that
 * acquisition: never applied to new data, so the figures above hold them
 * when data is the calibration file. */
static void jumps_note(const rch_robot *robot, const char *data)
{
    if (robot->n_cal_jumps == 0)
        return;
    const int same = robot->cal_data[0] && rch_path_same(data, robot->cal_data);
    printf("  note: the model was calibrated with %u length jump%s fitted as nuisance of that acquisition (largest "
           "%.3f mm), not applied to new data: %s\n",
           robot->n_cal_jumps, robot->n_cal_jumps == 1 ? "" : "s", robot->cal_jump_max_mm,
           same ? "this is the calibration file, so the RMSE above includes its jumps (rcal calibrate's figures "
                  "take them out)"
                : "on another file the RMSE holds that file's own jumps, if it has any");
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
    const char *model_path = NULL, *data_path = NULL, *resid_path = NULL, *pos_path = NULL;
    int refit = 0, json = 0, refit_tracker = 0;
    double same_deg = 1e-6;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--model", RCH_OPT_STR, &model_path, 0, 0, "MODEL.json", "calibrated model", RCH_OPT_REQUIRED, NULL},
        {"--data", RCH_OPT_STR, &data_path, 0, 0, "FILE.csv", "measurements the fit never saw (or --positions)", 0,
         NULL},
        {"--positions", RCH_OPT_STR, &pos_path, 0, 0, "FILE.csv",
         "laser-tracker positions (docs/positions.md): the 3-D error of the model", 0, NULL},
        {"--refit-tracker", RCH_OPT_FLAG, &refit_tracker, 0, 0, NULL,
         "with --positions: fit the tracker frame even when the model has one", 0, NULL},
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
    if ((data_path != NULL) == (pos_path != NULL)) {
        fprintf(stderr, "rcal evaluate: give one of --data and --positions (rcal evaluate --help)\n");
        return 2;
    }
    if (pos_path) {
        if (refit || resid_path) {
            fprintf(stderr, "rcal evaluate: --refit-encoder and --residuals are for --data\n");
            return 2;
        }
        return evaluate_positions(model_path, pos_path, refit_tracker, json, argc, argv);
    }
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
        rc = report_json(&r, &robot, model_path, data_path, argc, argv) != 0;
    else {
        report_text(&r, model_path, data_path);
        jumps_note(&robot, data_path);
    }
    return rc;
}
