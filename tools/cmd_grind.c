/* cmd_grind.c - rcal grind: the grinding-path experiment (the paper's
 * Table 8). The experiment (surface, path, nominal IK, base alignment,
 * compensation, deviations, SVG) is rch_grind_run and rch_grind_plots
 * (tools/host/rch_grind.h); this file parses options, loads the models and
 * reports.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_grind.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal grind --model MODEL.json --truth TRUTH.json [--surface SPEC] [--plots DIR]\n"
            "                  [--nominal ROBOT.json] [--position-only] [--max-dev-deg D] [--no-align] [--json]\n"
            "  --model    calibrated model used for compensation (rcal calibrate --out)\n"
            "  --truth    the simulated true robot (rcal simulate --truth-out, or any model file)\n"
            "  --nominal  nominal model the path is programmed with (default: the model's \"nominal\")\n"
            "  --surface  NAME[:key=value,...] (lengths mm, angles deg); NAME one of\n"
            "               plane              z = z0\n"
            "               tilted             z = z0 + tan(ax) (x - cx) + tan(ay) (y - cy)    ax=15 ay=0\n"
            "               cylinder           z = z0 + sqrt(r^2 - (y - cy)^2) - r, axis along x   r=150\n"
            "               saddle             z = z0 + k (x - cx)(y - cy) / (w/2 h/2)             k=20\n"
            "               sine               z = z0 + amp sin(2 pi (x - cx)/wl) cos(2 pi (y - cy)/wl)  amp=10 wl=100\n"
            "             common keys: cx=400 cy=0 z0=300 (patch centre), w=200 h=120 (patch size along\n"
            "             x and y), step=10 (raster line spacing), ds=5 (point spacing). Default: tilted\n"
            "  --plots    directory for grind_path.svg, grind_deviation.svg, grind_points.csv\n"
            "  --position-only  compensate the flange position only (default: full pose)\n"
            "  --max-dev-deg    largest joint correction (default 30: an offline experiment, not a\n"
            "                   controller; rcal compensate's default is 5.73 = 0.1 rad)\n"
            "  --no-align keep the calibrated model's base heading and height as identified\n"
            "  --json     one JSON object on stdout instead of the table\n");
}

/* Load the three models, run, report. */
static int grind_run(const rch_grind_config *cfg, const char *model_path, const char *truth_path,
                     const char *nominal_path, const char *plots, int json)
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
    if (json)
        rch_grind_json(stdout, &res, cfg);
    else
        rch_grind_report(stdout, &res, cfg, model_path, truth_path);
    int rc = 0;
    if (plots && rch_grind_plots(&res, cfg, plots, &d) != 0) {
        fprintf(stderr, "rcal grind: %s\n", d.msg);
        rc = 1;
    }
    if (plots && !json && rc == 0)
        printf("  plots: %s/grind_path.svg, %s/grind_deviation.svg; points: %s/grind_points.csv\n", plots, plots,
               plots);
    rch_grind_free(&res);
    return rc;
}

int rcal_cmd_grind(int argc, char **argv)
{
    const char *model_path = NULL, *truth_path = NULL, *nominal_path = NULL, *spec = NULL, *plots = NULL;
    int json = 0;
    double max_dev_deg = 30.0;
    rch_grind_config cfg;
    rch_diag d;
    rch_grind_defaults(&cfg);
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_double(argc, argv, &i, "--max-dev-deg", &max_dev_deg))
            continue;
        if (rcal_opt_str(argc, argv, &i, "--model", &model_path) ||
            rcal_opt_str(argc, argv, &i, "--truth", &truth_path) ||
            rcal_opt_str(argc, argv, &i, "--nominal", &nominal_path) ||
            rcal_opt_str(argc, argv, &i, "--surface", &spec) || rcal_opt_str(argc, argv, &i, "--plots", &plots))
            continue;
        if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (strcmp(argv[i], "--position-only") == 0)
            cfg.position_only = 1;
        else if (strcmp(argv[i], "--no-align") == 0)
            cfg.align = 0;
        else if (strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        } else
            return rcal_opt_unknown("grind", argv[i]);
    }
    if (!model_path)
        return rcal_opt_missing("grind", "--model");
    if (!truth_path)
        return rcal_opt_missing("grind", "--truth");
    if (rch_surface_parse(&cfg.surface, spec, &d) != 0) {
        fprintf(stderr, "rcal grind: %s\n", d.msg);
        return 2;
    }
    if (!(max_dev_deg > 0.0 && max_dev_deg <= 180.0)) {
        fprintf(stderr, "rcal grind: --max-dev-deg must be within (0, 180]\n");
        return 2;
    }
    cfg.max_dev_rad = max_dev_deg * (M_PI / 180.0);
    return grind_run(&cfg, model_path, truth_path, nominal_path, plots, json);
}
