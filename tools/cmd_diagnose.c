/* SPDX-License-Identifier: MIT */
/* cmd_diagnose.c - rcal diagnose: where model and measurement disagree,
 * which missing physical effect explains it, and how much the held-out gap
 * shrinks when it is added (issue 6). The work is rch_diagnose_file
 * (tools/host/studies/rch_diagnose.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_diagnose.h"
#include "rch_calib.h"
#include "rch_report.h"
#include "rch_data.h"
#include "rch_opt.h"
#include "rch_resid.h"

static const char summary[] = "which missing physical effect explains the residuals";
static const char details[] =
    "Takes every input rcal calibrate takes: cable lengths from one or several outlets\n"
    "(--data), tracker positions (--positions), both, and the effects already known\n"
    "(--effects). Fits the geometric model with K-fold cross-validation (folds random\n"
    "within set-up groups, every pose whole), compares the held-out residuals of each\n"
    "sensor with its noise floor, tests them for structure, and tries each candidate\n"
    "effect of the sensors in the data (joint side: compliance j2/j3, periodic j1..j6;\n"
    "cable: offset, scale, drift, groups, sag, nonlinearity, drum period, per-outlet\n"
    "offset and scale; tracker: scale) jointly with the geometry. An effect is chosen\n"
    "only on a significant held-out gain; the verdict is the effect, 'none' or\n"
    "'unexplained'. Up to N effects are added one after the other.\n"
    "Steps are detected from the data unless given (a negative value: no quantization).";

/* --residuals: the data lines as the diagnosis read them (it keeps the
 * samples in file order, less rows --dequantize-joints refused). */
static int save_residuals(const rch_diagnose_result *r, const char *data_path, const char *robot_path,
                          const char *path)
{
    rch_diag d;
    char msg[1024];
    const char *inputs[2] = {data_path, robot_path};
    if (r->n_read != r->n || !r->line) {
        fprintf(stderr, "rcal diagnose: --residuals: %zu of %zu rows were refused (--dequantize-joints); their lines "
                        "cannot be named: not written\n", r->n_read - r->n, r->n_read);
        return 1;
    }
    int rc = 0;
    rch_resid_table t;
    rch_resid_init(&t, inputs, 1);
    if (rch_diagnose_resid(&t, r, r->line) != 0) {
        fprintf(stderr, "rcal diagnose: out of memory\n");
        rc = 1;
    } else if (rch_resid_save(path, inputs, 2, &t, &d) != 0) {
        fprintf(stderr, "rcal diagnose: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rc = 1;
    }
    rch_resid_free(&t);
    return rc;
}

/* --report: the page needs a calibration; it is the one `rcal calibrate
 * --data D --robot R --seed S` makes (with --dequantize-joints when given). */
static int diagnose_report(const rch_diagnose_result *r, const char *data_path, const char *robot_path,
                           unsigned long seed, int dequantize, const char *html, int quiet, int argc, char **argv)
{
    rch_calib_cfg cc;
    rch_calib_cfg_init(&cc);
    cc.data_path = data_path;
    cc.robot_path = robot_path;
    cc.seed = seed;
    cc.dequantize = dequantize;
    cc.inputs = r->raw; /* the files as the diagnosis read them: not read again */
    cc.keep_poses = 1;  /* the page's poses from memory */
    rch_calib_result *c = malloc(sizeof *c);
    rch_diag d;
    char msg[1024];
    if (!c || rch_calib_run(c, &cc, &d) != 0) {
        if (c)
            rch_calib_result_free(c);
        fprintf(stderr, "rcal diagnose: --report: the calibration: %s\n", c ? rch_diag_str(&d, msg, sizeof msg) : "out of memory");
        free(c);
        return 1;
    }
    const char *const inputs[2] = {data_path, robot_path};
    const int rc = rch_report_inline(html, c, r, argc, argv, NULL, inputs, 2, quiet);
    rch_calib_result_free(c);
    free(c);
    return rc;
}

/* inputs: the data and the robot file; robot_given: --robot was on the
 * command line (then the next step names it) */
static int report(rch_diagnose_result *r, const char *plots, const char *const inputs[2], int robot_given, int json,
                  int argc, char **argv)
{
    rch_diag d;
    char msg[1024], paths[4096] = "";
    if (plots && rch_diagnose_plots(r, plots, inputs, 2, paths, sizeof paths, &d) != 0) {
        fprintf(stderr, "rcal diagnose: plots: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (json)
        return rch_diagnose_json(stdout, r, argc, argv) == 0 ? 0 : 1;
    if (rch_diagnose_print(stdout, r) != 0)
        return 1;
    char next[1200];
    if (rch_diagnose_next(next, sizeof next, r, inputs[0], robot_given ? inputs[1] : NULL) == 0)
        printf("\nNext: %s\n", next);
    if (plots)
        printf("\nPlots:\n%s", paths);
    return 0;
}

/* The options of rcal diagnose. */
typedef struct {
    const char *robot_path, *plots, *out_path, *resid, *report_path, *effects;
    rch_opt_strs data, positions, cable_points;
    unsigned long seed, folds, steps, max_iter, verbosity;
    int json, verbose;
    rch_diagnose_cfg cfg;
    const char *ins[2 * RCH_OPT_MAX_STRS + 1]; /* every input file, for the outputs' check */
    size_t n_ins;
} diag_args;

/* Options into a; -1 when the command should run, else its exit status. */
static int parse(diag_args *a, int argc, char **argv)
{
    rch_diagnose_cfg *cfg = &a->cfg;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--data", RCH_OPT_STRS, &a->data, 0, 0, "FILE",
         "cable lengths: CSV with q1..q6 (deg) and L (mm), optional outlet; several --data are merged", 0, NULL},
        {"--positions", RCH_OPT_STRS, &a->positions, 0, 0, "FILE",
         "laser-tracker positions: CSV with q1..q6 (deg), x, y, z (mm, tracker frame), optional target, pose; "
         "several are merged, mixable with --data",
         0, NULL},
        {"--effects", RCH_OPT_STR, &a->effects, 0, 0, "LIST",
         "effects already known (as rcal calibrate --effects names them): fitted from the start, never offered again",
         0, NULL},
        {"--cable-point", RCH_OPT_STRS, &a->cable_points, 0, 0, "X,Y,Z",
         "a point of a tool plate the cable is hooked on (nominal, flange frame, mm), once per point in the data's "
         "target order, as rcal calibrate --cable-point",
         0, NULL},
        {"--jumps", RCH_OPT_FLAG, &cfg->jumps, 0, 0, NULL,
         "length jumps found are removed as nuisance even at a set-up change (rcal calibrate --jumps)", 0, NULL},
        {"--robot", RCH_OPT_STR, &a->robot_path, 0, 0, "MODEL", "nominal robot model", 0, NULL},
        {"--seed", RCH_OPT_UINT, &a->seed, 0, 0, "S", "fold assignment seed", 0, NULL},
        {"--folds", RCH_OPT_UINT, &a->folds, 2, RCH_DIAGNOSE_MAX_FOLDS, "K", "cross-validation folds", 0, NULL},
        {"--steps", RCH_OPT_UINT, &a->steps, 1, RCH_DIAGNOSE_MAX_STEPS, "N", "effects added at most", 0, NULL},
        {"--plots", RCH_OPT_STR, &a->plots, 0, 0, "DIR", "write residual plots (SVG, each with its data as .csv) into DIR",
         0, NULL},
        {"--out", RCH_OPT_STR, &a->out_path, 0, 0, "MODEL.json",
         "write the calibrated model with the effects found (nuisances left out); never over an input", 0, NULL},
        {"--json", RCH_OPT_FLAG, &a->json, 0, 0, NULL, "one JSON object on stdout", 0, NULL},
        {"--residuals", RCH_OPT_STR, &a->resid, 0, 0, "FILE.csv",
         "each sample's residual under the final model and its cross-validated residual before and after the "
         "chosen effects; never over an input",
         0, NULL},
        {"--report", RCH_OPT_STR, &a->report_path, 0, 0, "FILE.html",
         "also the HTML page of rcal report: this diagnosis with a calibration of the same data (rcal calibrate "
         "--seed S defaults); both JSON kept beside it",
         0, NULL},
        {"--q-step-deg", RCH_OPT_DOUBLE, &cfg->q_step_deg, -1, 10, "D", "joint display step (0: detected)", 0, NULL},
        {"--len-step-mm", RCH_OPT_DOUBLE, &cfg->len_step_mm, -1, 10, "D", "length display step (0: detected)", 0,
         NULL},
        {"--len-noise-mm", RCH_OPT_DOUBLE, &cfg->len_noise_mm, 0, 100, "S", "the encoder's stated noise, added", 0,
         NULL},
        {"--alpha", RCH_OPT_DOUBLE, &cfg->alpha, 0, 0.5, "A", "family-wise level of each decision (0: 0.01)", 0,
         NULL},
        {"--max-iter", RCH_OPT_UINT, &a->max_iter, 0, 100000, "N",
         "LM iterations of each warm-started fold fit (0: 100)", 0, NULL},
        {"--jump-max-mm", RCH_OPT_DOUBLE, &cfg->jump_max_mm, 0, 10000, "MM",
         "the largest length jump a display event explains (re-zeroed, counts lost); a larger one is named as "
         "implausible (0: 10)",
         0, NULL},
        {"--no-jumps", RCH_OPT_FLAG, &cfg->no_jumps, 0, 0, NULL, "do not look for length jumps in acquisition order",
         0, NULL},
        {"--dequantize-joints", RCH_OPT_FLAG, &cfg->dequantize, 0, 0, NULL,
         "recover joint angles rounded for the file from its x, y, z columns (nominal FK); inconsistent rows refused",
         0, NULL},
        {"--verbose", RCH_OPT_FLAG, &a->verbose, 0, 0, NULL, "progress to stderr", 0, NULL},
        {"--verbosity", RCH_OPT_UINT, &a->verbosity, 0, 3, "V", "progress level (3: also singular values)", 0, NULL},
    };
    const int ps = rch_opt_cmd(&spec, "diagnose", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (ps >= 0)
        return ps;
    cfg->folds = (unsigned)a->folds;
    cfg->max_steps = (unsigned)a->steps;
    cfg->seed = a->seed;
    cfg->max_iter = (unsigned)a->max_iter;
    cfg->verbose = a->verbosity > 0 ? (int)a->verbosity : a->verbose;
    for (size_t k = 0; k < a->data.n; ++k)
        a->ins[a->n_ins++] = a->data.v[k];
    for (size_t k = 0; k < a->positions.n; ++k)
        a->ins[a->n_ins++] = a->positions.v[k];
    a->ins[a->n_ins++] = a->robot_path;
    if (a->data.n + a->positions.n == 0) {
        fprintf(stderr, "rcal diagnose: give --data FILE (cable lengths) or --positions FILE (tracker), or both\n");
        return 2;
    }
    if (!(a->data.n == 1 && a->positions.n == 0) && (a->resid || a->report_path)) { /* one file: its lines, calibrate --report's one data file */
        fprintf(stderr, "rcal diagnose: --residuals and --report take one --data file (no --positions) for now; "
                        "the diagnosis itself takes them all\n");
        return 2;
    }
    /* outputs that name each other or an input: refused before the work */
    const char *const outs[3] = {a->out_path, a->resid, a->report_path};
    static const char *const what[3] = {"--out", "--residuals", "--report"};
    return rcal_outputs_check("diagnose", outs, what, 3, a->report_path, a->ins, a->n_ins) != 0 ? 2 : -1;
}

int rcal_cmd_diagnose(int argc, char **argv)
{
    const char *const default_robot = RCAL_DEFAULT_ROBOT;
    static diag_args a;
    memset(&a, 0, sizeof a);
    a.robot_path = default_robot;
    a.seed = 1;
    a.folds = 5;
    a.steps = 3;
    const int ps = parse(&a, argc, argv);
    if (ps >= 0)
        return ps;
    rch_diagnose_in in;
    memset(&in, 0, sizeof in);
    in.data_paths = a.data.v;
    in.n_data = a.data.n;
    in.positions_paths = a.positions.v;
    in.n_positions = a.positions.n;
    in.robot_path = a.robot_path;
    in.robot_given = a.robot_path != default_robot;
    in.effects = a.effects;
    in.cable_points = a.cable_points.v;
    in.n_cable_points = a.cable_points.n;
    rch_diagnose_result r;
    rch_diag d;
    char msg[1024];
    if (rch_diagnose_inputs(&r, &in, &a.cfg, &d) != 0) {
        fprintf(stderr, "rcal diagnose: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rch_diagnose_free(&r);
        return 1;
    }
    const char *data_path = a.data.n ? a.data.v[0] : NULL;
    const char *inputs[2] = {data_path ? data_path : a.positions.v[0], a.robot_path};
    int rc = report(&r, a.plots, inputs, in.robot_given, a.json, argc, argv);
    if (rc == 0 && a.out_path) {
        if (rch_diagnose_save_model(&r, data_path, a.robot_path, a.out_path, a.ins, a.n_ins, &d) != 0) {
            fprintf(stderr, "rcal diagnose: %s\n", rch_diag_str(&d, msg, sizeof msg));
            rc = 1;
        } else if (!a.json) {
            printf("model with the effects found written to %s\n", a.out_path);
        }
    }
    if (rc == 0 && a.resid)
        rc = save_residuals(&r, data_path, a.robot_path, a.resid);
    if (rc == 0 && a.report_path)
        rc = diagnose_report(&r, data_path, a.robot_path, a.seed, a.cfg.dequantize, a.report_path, a.json, argc, argv);
    rch_diagnose_free(&r);
    return rc;
}
