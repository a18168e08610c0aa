/* SPDX-License-Identifier: MIT */
/* cmd_calibrate.c - rcal calibrate: identify the DH errors and the encoder
 * position from cable lengths, with a held-out before/after report. The work
 * is rch_calib_run (tools/host/fit/rch_calib.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_calib.h"
#include "rch_report.h"
#include "rch_calib_effects.h"
#include "rch_data.h"
#include "rch_file.h"
#include "rch_opt.h"
#include "rch_robot.h"

/* Write the calibrated model to out_path (never over an input), after the fit; text (may be NULL): its
 * text kept for --report (heap, *len bytes; NULL when not written). */
static int write_model(const rch_calib_result *r, const char *out_path, int quiet, char **text, size_t *len)
{
    rch_diag d;
    char msg[1024];
    if (!r->finite) {
        fprintf(stderr, "rcal calibrate: not writing %s: the model is not finite\n", out_path);
        return 0;
    }
    const int rc = text ? rch_calib_save_model_text(r, out_path, text, len, &d) : rch_calib_save_model(r, out_path, &d);
    if (rc != 0) {
        fprintf(stderr, "rcal calibrate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return -1;
    }
    if (!quiet)
        printf("calibrated model written to %s\n", out_path);
    return 0;
}

static const char summary[] = "identify the DH errors and the encoder position from cable lengths";
static const char details[] = "mean|e| is what the paper's Eq. 20 calls SD; SD is the true standard deviation.";

/* Options of rcal calibrate into cfg (and out_path, json, data). Returns -1
 * when the command should run, else its exit status (0 for --help, 2 for an
 * error). */
typedef struct {
    rch_calib_cfg cfg;
    const char *out_path, *method, *report_path;
    rch_opt_strs data, positions, cable_points;
    unsigned long seed, max_iter, cases, case_samples;
    int json;
    double tracker_pos[3], tracker_rot[3];
} calib_args;

/* The parsed options into a->cfg (spec, seen: what was given). -1, or 2
 * (reported). */
static int to_config(calib_args *a, const rch_cmdspec *spec, unsigned long long seen)
{
    rch_calib_cfg *cfg = &a->cfg;
    if (rch_method_parse(&cfg->method, a->method) != 0)
        return 2; /* unreachable: the choice list is the method list */
    cfg->seed = a->seed;
    cfg->max_iter = (unsigned)a->max_iter;
    char perr[160];
    if (rch_calib_cfg_cable_points(cfg, a->cable_points.v, a->cable_points.n, perr, sizeof perr) != 0) {
        fprintf(stderr, "rcal calibrate: %s\n", perr);
        return 2;
    }
    cfg->cases = a->cases;
    cfg->case_samples = a->case_samples;
    if (a->data.n == 0 && a->positions.n == 0) {
        fprintf(stderr, "rcal calibrate: --data or --positions is required (rcal calibrate --help)\n");
        return 2;
    }
    cfg->data_path = a->data.n ? a->data.v[0] : NULL;
    cfg->data_paths = a->data.n ? a->data.v : NULL;
    cfg->n_data_paths = a->data.n;
    cfg->positions_paths = a->positions.v;
    cfg->n_positions_paths = a->positions.n;
    cfg->joint_step_given = rch_opt_given(spec, seen, "--joint-step-deg");
    cfg->have_tracker_start = rch_opt_given(spec, seen, "--tracker-position") ||
                              rch_opt_given(spec, seen, "--tracker-rotation");
    for (int k = 0; k < 3; ++k) { /* the one not given: 0 */
        cfg->tracker_start[k] = a->tracker_pos[k];
        cfg->tracker_start[3 + k] = a->tracker_rot[k] * (3.14159265358979323846 / 180.0);
    }
    if (cfg->have_tracker_start && a->positions.n == 0) {
        fprintf(stderr, "rcal calibrate: --tracker-position and --tracker-rotation need --positions\n");
        return 2;
    }
    if (cfg->dequantize && cfg->no_dequantize) {
        fprintf(stderr, "rcal calibrate: --dequantize-joints and --no-dequantize-joints contradict each other\n");
        return 2;
    }
    return -1;
}

static int parse(calib_args *a, int argc, char **argv)
{
    rch_calib_cfg *cfg = &a->cfg;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--data", RCH_OPT_STRS, &a->data, 0, 0, "FILE",
         "measurements: CSV with q1..q6 (deg) and L (mm); several --data are merged (set-up groups never span two files)",
         0, NULL},
        {"--positions", RCH_OPT_STRS, &a->positions, 0, 0, "FILE",
         "laser-tracker positions: CSV with q1..q6 (deg), x, y, z (mm, tracker frame), optional target, pose, sigma_mm "
         "(docs/positions.md); repeatable, mixable with --data; the tracker frame and targets are estimated",
         0, NULL},
        {"--tracker-position", RCH_OPT_TRIPLE, a->tracker_pos, -1e5, 1e5, "X,Y,Z",
         "with --positions: start of the tracker frame's translation (the base origin in the tracker's frame, mm; "
         "default: a closed-form fit)", 0, NULL},
        {"--tracker-rotation", RCH_OPT_TRIPLE, a->tracker_rot, -360.0, 360.0, "RX,RY,RZ",
         "with --positions: start of its rotation (rotation vector, deg)", 0, NULL},
        {"--validate", RCH_OPT_STR, &cfg->validate_path, 0, 0, "FILE",
         "data the fit never sees: the model evaluated on it with no refit (RMSE, ISO 9283 from repeated poses)", 0,
         NULL},
        {"--plots", RCH_OPT_STR, &cfg->plots_dir, 0, 0, "DIR",
         "write the predicted-uncertainty plot (uncertainty_position.svg and .csv)", 0, NULL},
        {"--robot", RCH_OPT_STR, &cfg->robot_path, 0, 0, "MODEL.json", "nominal robot model", 0, NULL},
        {"--method", RCH_OPT_CHOICE, &a->method, 0, 0, NULL,
         "lm (robust), ltlm (robust + chaotic candidates), lm-paper / ltlm-paper (the paper's update, angles in "
         "rad), lm-paper-deg / ltlm-paper-deg (the same with angles in degrees)",
         0, RC_METHOD_CHOICES},
        {"--test-fraction", RCH_OPT_DOUBLE, &cfg->test_fraction, 0, 0.999, "F",
         "share of samples held out for the before/after report", 0, NULL},
        {"--seed", RCH_OPT_UINT, &a->seed, 0, 0, "S", "split (and LTLM) seed", 0, NULL},
        {"--max-iter", RCH_OPT_UINT, &a->max_iter, 1, 100000, "N", "iteration cap (not given: the method's default)", 0,
         NULL},
        {"--fix", RCH_OPT_STR, &cfg->fix, 0, 0, "LIST",
         "parameters held at nominal, e.g. a1,theta6 (a1..a6, d1..d6, alpha1..alpha6, theta1..theta6, ex, ey, ez)",
         0, NULL},
        {"--jumps", RCH_OPT_FLAG, &cfg->jumps, 0, 0, NULL,
         "fit length jumps at change points in acquisition order (a display re-zeroed, counts lost) with the "
         "geometry; they are not used at a new pose",
         0, NULL},
        {"--dequantize-joints", RCH_OPT_FLAG, &cfg->dequantize, 0, 0, NULL,
         "recover joint angles rounded for the file from its x, y, z columns (nominal FK); inconsistent rows refused "
         "(the default when the joints sit on a display step and x, y, z are the FK of finer angles; forced here)",
         0, NULL},
        {"--no-dequantize-joints", RCH_OPT_FLAG, &cfg->no_dequantize, 0, 0, NULL,
         "keep the joint angles as read, even when the file's x, y, z show they were rounded", 0, NULL},
        {"--holdout-groups", RCH_OPT_FLAG, &cfg->holdout_groups, 0, 0, NULL,
         "hold out whole set-up groups (the file's group column, else from the wrist joints) instead of random rows",
         0, NULL},
        {"--cases", RCH_OPT_UINT, &a->cases, 1, 1000, "N", "repeat on N random subsets (the paper's protocol)", 0,
         NULL},
        {"--max-minutes", RCH_OPT_DOUBLE, &a->cfg.max_minutes, 0.01, 1e7, "MIN",
         "refuse a run estimated longer than this (default 60; the estimate is printed above 10 s)", 0, NULL},
        {"--samples", RCH_OPT_UINT, &a->case_samples, 0, 10000000, "M", "rows per case (0: every row)", 0, NULL},
        {"--effects", RCH_OPT_STR, &cfg->effects, 0, 0, "LIST",
         "effects fitted with the geometry: length_offset, length_scale, time_drift, tool_offset, cable_sag, "
         "length_nonlinearity, length_periodic:P (start period, mm), joint_compliance:J, joint_periodic:J "
         "(e.g. what rcal diagnose named)",
         0, NULL},
        {"--cable-point", RCH_OPT_STRS, &a->cable_points, 0, 0, "X,Y,Z",
         "a point of a tool plate the cable is hooked on, nominal, in the flange frame (mm); once per point, in the "
         "order of the data's target column (0, 1, ...): points apart make the flange's orientation visible",
         0, NULL},
        {"--cable-point-sd", RCH_OPT_DOUBLE, &cfg->cable_point_sd_mm, 1e-6, 100.0, "MM",
         "the plate's tolerance: the prior sd of each point coordinate (default 0.05)", 0, NULL},
        {"--tool-offset", RCH_OPT_FLAG, &cfg->tool_offset, 0, 0, NULL,
         "identify where the cable is attached in the flange frame (tx, ty, tz); the default with the prior, "
         "needed with --no-prior", 0, NULL},
        {"--no-screen", RCH_OPT_FLAG, &cfg->no_screen, 0, 0, NULL,
         "fit every row: none left out as irreconcilable with the rest (by default a row beyond 8 robust standard "
         "deviations is named and left out, a file with more than 5 % of such rows refused)", 0, NULL},
        {"--timing", RCH_OPT_FLAG, &cfg->timing, 0, 0, NULL,
         "where the time went: each stage of the calibration's plan (read, start, map, jump_check, attachment, "
         "prior_scale, uncertainty, screen, ...) with its wall and CPU time, on stderr (with --json: its "
         "\"timing\" member)", 0, NULL},
        {"--no-jump-check", RCH_OPT_FLAG, &cfg->no_jump_check, 0, 0, NULL,
         "do not look for length jumps in the default run (a model fitted across jumps it found is not written: "
         "use --jumps)", 0, NULL},
        {"--no-length-offset", RCH_OPT_FLAG, &cfg->no_length_offset, 0, 0, NULL,
         "never weigh a length offset (a display's zero set off the outlet; each outlet's own) by default: by "
         "default it is fitted when its evidence beats its Occam penalty", 0, NULL},
        {"--no-drift", RCH_OPT_FLAG, &cfg->no_drift, 0, 0, NULL,
         "never weigh a drift of the lengths over the run (linear in acquisition order) by default", 0, NULL},
        {"--sensor-sd-mm", RCH_OPT_DOUBLE, &cfg->sensor_sd_mm, 1e-6, 100.0, "MM",
         "what the length sensor can repeat (the encoder's repeatability with the robot's; default 0.02): the fit's "
         "noise is judged against it with the display steps", 0, NULL},
        {"--display-step-mm", RCH_OPT_DOUBLE, &cfg->display_step_mm, 1e-9, 100.0, "MM",
         "the length display's step (default: from the data's digits)", 0, NULL},
        {"--joint-step-deg", RCH_OPT_DOUBLE, &cfg->joint_step_deg, 0.0, 10.0, "DEG",
         "the joint readings' step (default: from the data's digits; 0: exact)", 0, NULL},
        {"--force", RCH_OPT_FLAG, &cfg->force, 0, 0, NULL,
         "write the model even when its noise is far beyond what the sensor can produce or it predicts its own "
         "data worse than the nominal model (said, never silent)", 0, NULL},
        {"--prior-stated", RCH_OPT_FLAG, &cfg->prior_stated, 0, 0, NULL,
         "the prior's sd as stated (defaults or the robot file's), not widened to the spread this robot's "
         "determined parameters show (type-II maximum likelihood; a robot file's \"prior\" is always kept)", 0,
         NULL},
        {"--no-prior", RCH_OPT_FLAG, &cfg->no_prior, 0, 0, NULL,
         "plain least squares: no physical prior (the robot file's \"prior\", DESIGN.md), no attachment vector "
         "unless --tool-offset, base heading and height free (to reproduce earlier results)", 0, NULL},
        {"--out", RCH_OPT_STR, &a->out_path, 0, 0, "MODEL.json",
         "write the calibrated model (rcal-model/2) for compensation; never over an input", 0, NULL},
        {"--truth", RCH_OPT_STR, &cfg->truth_path, 0, 0, "TRUTH.json",
         "a simulated truth: flange errors over 2000 random poses, before and after", 0, NULL},
        {"--json", RCH_OPT_FLAG, &a->json, 0, 0, NULL, "one JSON object on stdout instead of the report", 0, NULL},
        {"--residuals", RCH_OPT_STR, &cfg->residuals_path, 0, 0, "FILE.csv",
         "each sample's residual with its row, file, group and set (train, test, validate); never over an input", 0,
         NULL},
        {"--report", RCH_OPT_STR, &a->report_path, 0, 0, "FILE.html",
         "also the HTML page of rcal report, from this run (its JSON kept beside it as FILE.calibration.json)", 0,
         NULL},
    };
    unsigned long long seen = 0;
    const int ps = rch_opt_cmd(&spec, "calibrate", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, &seen);
    if (ps >= 0)
        return ps;
    return to_config(a, &spec, seen);
}

/* 1 (with the message) when --out, --residuals, --report (or a file beside
 * the page) or a plot name each other or one of the inputs; --data given
 * twice (the same file by inode, whatever the spelling) or --validate equal
 * to a --data file. */
static int out_is_input(const calib_args *a)
{
    const char *inputs[2 * RCH_OPT_MAX_STRS + 3] = {a->cfg.robot_path, a->cfg.truth_path, a->cfg.validate_path};
    for (size_t i = 0; i < a->data.n; ++i)
        inputs[3 + i] = a->data.v[i];
    for (size_t i = 0; i < a->positions.n; ++i)
        inputs[3 + a->data.n + i] = a->positions.v[i];
    for (size_t i = 0; i < a->positions.n; ++i)
        for (size_t j = 0; j < 3 + a->data.n + i; ++j)
            if (inputs[j] && (rch_same_file(a->positions.v[i], inputs[j]) || strcmp(a->positions.v[i], inputs[j]) == 0)) {
                fprintf(stderr, "rcal calibrate: --positions %s is given twice or is another input: refused\n",
                        a->positions.v[i]);
                return 1;
            }
    for (size_t i = 0; i < a->data.n; ++i)
        for (size_t j = 0; j < i; ++j)
            if (rch_same_file(a->data.v[i], a->data.v[j]) || strcmp(a->data.v[i], a->data.v[j]) == 0) {
                fprintf(stderr, "rcal calibrate: --data %s is the same file as --data %s: refused (each file once; "
                                "merging a file with itself counts every sample twice)\n",
                        a->data.v[i], a->data.v[j]);
                return 1;
            }
    for (size_t i = 0; a->cfg.validate_path && i < a->data.n; ++i)
        if (rch_same_file(a->cfg.validate_path, a->data.v[i]) || strcmp(a->cfg.validate_path, a->data.v[i]) == 0) {
            fprintf(stderr, "rcal calibrate: --validate %s is the same file as --data %s: refused (validation data "
                            "must be samples the fit never saw; give a file of other measurements)\n",
                    a->cfg.validate_path, a->data.v[i]);
            return 1;
        }
    char svg[1100], csv[1100];
    const char *plot_svg = NULL, *plot_csv = NULL;
    if (a->cfg.plots_dir) {
        if ((size_t)snprintf(svg, sizeof svg, "%s/uncertainty_position.svg", a->cfg.plots_dir) >= sizeof svg ||
            (size_t)snprintf(csv, sizeof csv, "%s/uncertainty_position.csv", a->cfg.plots_dir) >= sizeof csv) {
            fprintf(stderr, "rcal calibrate: --plots %s: path too long: refused\n", a->cfg.plots_dir);
            return 1;
        }
        plot_svg = svg;
        plot_csv = csv;
    }
    const char *outs[5] = {a->out_path, a->cfg.residuals_path, a->report_path, plot_svg, plot_csv};
    static const char *const what[5] = {"--out", "--residuals", "--report", "--plots", "--plots"};
    if (rcal_outputs_check("calibrate", outs, what, 5, a->report_path, inputs, 3 + a->data.n + a->positions.n) != 0)
        return 1;
    if (a->cfg.residuals_path && (a->cases > 1 || a->cfg.jumps)) {
        fprintf(stderr, "rcal calibrate: --residuals is for one calibration without --jumps (not with --cases or "
                        "--jumps)\n");
        return 1;
    }
    struct stat st;
    if (a->out_path && strcmp(a->out_path, "-") != 0 && stat(a->out_path, &st) == 0 && !S_ISREG(st.st_mode)) {
        fprintf(stderr, "rcal calibrate: --out %s is not a regular file: refused before the fit\n", a->out_path);
        return 1;
    }
    return 0;
}

/* Every --data and --validate file against the robot's joint limits, before
 * the fit (rch_calib_run loads them again; its loader is not this file's):
 * 1 with the message (file:line:column) when a reading is beyond them. */
int rcal_cmd_calibrate(int argc, char **argv)
{
    calib_args a;
    memset(&a, 0, sizeof a);
    rch_calib_cfg_init(&a.cfg);
    a.cfg.robot_path = RCAL_DEFAULT_ROBOT;
    a.method = "lm";
    a.seed = 1;
    a.cases = 1;
    const int ps = parse(&a, argc, argv);
    if (ps >= 0)
        return ps;
    if (out_is_input(&a))
        return 2;
    a.cfg.keep_poses = a.report_path != NULL; /* the report's poses from the run's reading, not the files again */
    rch_calib_result *r = malloc(sizeof *r); /* large: two models, the identifiability report */
    rch_diag d;
    char msg[1024];
    const int rc = r ? rch_calib_run(r, &a.cfg, &d) : -1;
    if (rc != 0) {
        fprintf(stderr, "rcal calibrate: %s\n", r ? rch_diag_str(&d, msg, sizeof msg) : "out of memory");
        if (r)
            rch_calib_result_free(r);
        free(r);
        return rc == -2 ? 2 : 1;
    }
    int status = r->after_ok ? 0 : 1;
    char *model_text = NULL; /* the model file's text as written, for --report (never read back) */
    size_t model_len = 0;
    if (a.cfg.timing)
        rch_calib_timing_print(stderr, &r->timing, "rcal calibrate: ");
    if (r->screen.out) /* named on stderr too, whatever the output's form */
        rch_calib_print_screened(stderr, r, "rcal calibrate: ");
    if (a.json ? rch_calib_json(stdout, r, argc, argv) != 0 : (rch_calib_print(stdout, r), 0))
        status = 1;
    else if (a.out_path && write_model(r, a.out_path, a.json, a.report_path ? &model_text : NULL, &model_len) != 0)
        status = 1;
    else if (a.report_path && r->finite) {
        const char *inputs[2 * RCH_OPT_MAX_STRS + 3] = {a.cfg.robot_path, a.cfg.truth_path, a.cfg.validate_path};
        for (size_t i = 0; i < a.data.n; ++i)
            inputs[3 + i] = a.data.v[i];
        for (size_t i = 0; i < a.positions.n; ++i)
            inputs[3 + a.data.n + i] = a.positions.v[i];
        if (rch_report_inline_model(a.report_path, r, NULL, argc, argv, r->finite ? a.out_path : NULL, model_text,
                                    model_len, inputs, 3 + a.data.n + a.positions.n, a.json) != 0)
            status = 1;
    }
    if (a.cfg.residuals_path && !r->finite)
        fprintf(stderr, "rcal calibrate: not writing %s: the model is not finite\n", a.cfg.residuals_path);
    else if (!a.json && status == 0 && a.cfg.residuals_path)
        printf("per-sample residuals written to %s\n", a.cfg.residuals_path);
    free(model_text);
    rch_calib_result_free(r);
    free(r);
    return status;
}
