/* SPDX-License-Identifier: MIT */
/* cmd_grind.c - rcal grind: the grinding-path experiment (the paper's
 * Table 8). The experiment (surface, path, nominal IK, base alignment,
 * compensation, deviations, SVG) is rch_grind_run and rch_grind_plots
 * (tools/host/studies/rch_grind.h); this file parses options, loads the models and
 * reports.
 */
#include <math.h>
#include <stdio.h>

#include "rcal_cmds.h"
#include "rch_opt.h"
#include "rch_grind.h"
#include "rch_robot.h"
#include "rch_compare.h" /* rch_compare_model_file: the names rcal compare --models writes */

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* the usage text: rch_opt_usage prints the option table between these */
static const char summary[] = "the grinding-path experiment (the paper's Table 8) on a simulated true robot";
static const char details[] =
    "--surface NAME[:key=value,...] (lengths mm, angles deg); NAME one of\n"
    "  plane     z = z0\n"
    "  tilted    z = z0 + tan(ax) (x - cx) + tan(ay) (y - cy)                    ax=15 ay=0\n"
    "  cylinder  z = z0 + sqrt(r^2 - (y - cy)^2) - r, axis along x               r=150\n"
    "  saddle    z = z0 + k (x - cx)(y - cy) / (w/2 h/2)                         k=20\n"
    "  sine      z = z0 + amp sin(2 pi (x - cx)/wl) cos(2 pi (y - cy)/wl)        amp=10 wl=100\n"
    "common keys: cx=400 cy=0 z0=300 (patch centre), w=200 h=120 (patch size along x and y),\n"
    "step=10 (raster line spacing), ds=5 (point spacing).\n"
    "Cable lengths cannot see the base heading and height: by default they are taken from the truth\n"
    "(--no-align compares raw frames).";

/* Load the three models, run, report. */
static int grind_run(const rch_grind_config *cfg, const char *model_path, const char *truth_path,
                     const char *nominal_path, const char *plots, int json, int argc, char **argv)
{
    static rch_robot mrob, trob, nrob;
    rch_grind_result res;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&mrob, model_path, &d) != 0 || rch_robot_load(&trob, truth_path, &d) != 0 ||
        (nominal_path && rch_robot_load(&nrob, nominal_path, &d) != 0)) {
        fprintf(stderr, "rcal grind: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    const rc_model *nom = nominal_path ? &nrob.model : &mrob.nominal;
    if (rch_grind_run(&res, cfg, &mrob.model, &trob.model, nom, &d) != 0) {
        fprintf(stderr, "rcal grind: %s\n", d.msg);
        rch_grind_free(&res);
        return 1;
    }
    int rc = 0;
    if (json)
        rc = rch_grind_json(stdout, &res, cfg, argc, argv) != 0;
    else
        rch_grind_report(stdout, &res, cfg, model_path, truth_path);
    const char *const inputs[3] = {model_path, truth_path, nominal_path};
    const rch_plot_dir pd = {plots, inputs, 3, NULL};
    if (plots && rch_grind_plots(&res, cfg, &pd, &d) != 0) {
        fprintf(stderr, "rcal grind: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rc = 1;
    }
    if (plots && !json && rc == 0)
        printf("  plots: %s/grind_path.svg, %s/grind_deviation.svg (data beside each as .csv); points: %s/grind_points.csv\n", plots, plots,
               plots);
    rch_grind_free(&res);
    return rc;
}

/* The Table 8 form: every model on one path, a row each. */
static int grind_table(const rch_grind_config *cfg, const char *const *paths, const char *const *names, size_t n,
                       const char *truth_path, const char *nominal_path, int json, int argc, char **argv)
{
    static rch_grind_table t;
    rch_diag d;
    char msg[1024];
    if (rch_grind_table8_files(&t, cfg, paths, names, n, truth_path, nominal_path, &d) != 0) {
        fprintf(stderr, "rcal grind: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (json)
        return rch_grind_table8_json(stdout, &t, cfg, argc, argv) != 0;
    rch_grind_table8_report(stdout, &t, cfg, truth_path);
    return 0;
}

int rcal_cmd_grind(int argc, char **argv)
{
    rch_opt_strs model_paths = {{NULL}, 0};
    const char *models_dir = NULL, *truth_path = NULL, *nominal_path = NULL, *spec_s = NULL, *plots = NULL;
    int json = 0, no_align = 0;
    double max_dev_deg = 30.0;
    rch_grind_config cfg;
    rch_diag d;
    rch_grind_defaults(&cfg);
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--model", RCH_OPT_STRS, &model_paths, 0, 0, "MODEL.json",
         "calibrated model used for compensation (rcal calibrate --out); repeat it for the Table 8 form, a row each",
         0, NULL},
        {"--models", RCH_OPT_STR, &models_dir, 0, 0, "DIR",
         "the Table 8 form with the models rcal compare --models wrote (M1-LM.json .. M7-LTLM.json)", 0, NULL},
        {"--truth", RCH_OPT_STR, &truth_path, 0, 0, "TRUTH.json",
         "the simulated true robot (rcal simulate --truth-out, or any model file)", RCH_OPT_REQUIRED, NULL},
        {"--nominal", RCH_OPT_STR, &nominal_path, 0, 0, "ROBOT.json",
         "nominal model the path is programmed with (default: the model's \"nominal\")", 0, NULL},
        {"--surface", RCH_OPT_STR, &spec_s, 0, 0, "SPEC", "NAME[:key=value,...], see below (default tilted)", 0, NULL},
        {"--plots", RCH_OPT_STR, &plots, 0, 0, "DIR", "grind_path.svg, grind_deviation.svg (each with its data as .csv), grind_points.csv", 0,
         NULL},
        {"--position-only", RCH_OPT_FLAG, &cfg.position_only, 0, 0, NULL,
         "compensate the flange position only (default: full pose)", 0, NULL},
        {"--max-dev-deg", RCH_OPT_DOUBLE, &max_dev_deg, 0.001, 180, "D",
         "largest joint correction (an offline experiment; rcal compensate's default is 5.73)", 0, NULL},
        {"--no-align", RCH_OPT_FLAG, &no_align, 0, 0, NULL,
         "keep the calibrated model's base heading and height as identified", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "one JSON object on stdout instead of the table", 0, NULL},
    };
    const int st = rch_opt_cmd(&spec, "grind", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st; /* usage printed, or the error named */
    if (rch_surface_parse(&cfg.surface, spec_s, &d) != 0) {
        fprintf(stderr, "rcal grind: --surface: %s\n", d.msg);
        return 2;
    }
    cfg.align = !no_align;
    cfg.max_dev_rad = max_dev_deg * (M_PI / 180.0);
    if (model_paths.n == 1 && !models_dir)
        return grind_run(&cfg, model_paths.v[0], truth_path, nominal_path, plots, json, argc, argv);
    if (model_paths.n == 0 && !models_dir) {
        fprintf(stderr, "rcal grind: --model or --models is required\n");
        return 2;
    }
    if (plots) {
        fprintf(stderr, "rcal grind: --plots takes one --model\n");
        return 2;
    }
    /* the Table 8 form: the --model files, then DIR's M1..M7 in method order */
    static char dir_paths[RCH_COMPARE_ROWS][RCH_COMPARE_PATH_MAX], dir_names[RCH_COMPARE_ROWS][32];
    const size_t nd = models_dir ? rch_compare_model_list(dir_paths, dir_names, models_dir) : 0;
    const char *paths[RCH_OPT_MAX_STRS + RCH_COMPARE_ROWS], *names[RCH_OPT_MAX_STRS + RCH_COMPARE_ROWS];
    size_t n = 0;
    for (size_t k = 0; k < model_paths.n; ++k, ++n)
        paths[n] = names[n] = model_paths.v[k];
    for (size_t k = 0; k < nd; ++k, ++n) {
        paths[n] = dir_paths[k];
        names[n] = dir_names[k];
    }
    if (models_dir && nd == 0) {
        fprintf(stderr, "rcal grind: no model file (M1-LM.json .. M7-LTLM.json) in %s\n", models_dir);
        return 1;
    }
    return grind_table(&cfg, paths, names, n, truth_path, nominal_path, json, argc, argv);
}
