/* cmd_diagnose.c - rcal diagnose: where model and measurement disagree,
 * which missing physical effect explains it, and how much the held-out gap
 * shrinks when it is added (issue 6). The work is in rch_diagnose. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_data.h"
#include "rch_diagnose.h"
#include "rch_robot.h"

static int usage(FILE *f)
{
    fprintf(f,
            "usage: rcal diagnose --data FILE [--robot MODEL] [--seed S] [--folds K] [--steps N]\n"
            "                     [--plots DIR] [--json] [--q-step-deg D] [--len-step-mm D]\n"
            "                     [--len-noise-mm S] [--alpha A] [--max-iter N] [--verbose]\n"
            "Fits the geometric model with K-fold cross-validation (folds random within set-up\n"
            "groups), compares the held-out residuals with the noise floor (length step and the\n"
            "joint display step through the Jacobian), tests the residuals for structure, and\n"
            "tries each candidate effect (length_offset, length_scale, time_drift, group_offset,\n"
            "joint_compliance j2/j3, joint_periodic j1..j6) jointly with the geometry. An effect\n"
            "is chosen only on a significant held-out gain; the verdict is the effect, 'none'\n"
            "or 'unexplained'. Up to N effects (default 3) are added one after the other.\n"
            "Steps are detected from the data unless given (a negative value: no quantization).\n"
            "--len-noise-mm adds the encoder's stated noise to the floor; --max-iter caps the LM\n"
            "iterations of each warm-started fold fit (default 100).\n");
    return f == stdout ? 0 : 2;
}

int rcal_cmd_diagnose(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT, *plots = NULL;
    unsigned long seed = 1, folds = 5, steps = 3, max_iter = 0;
    int json = 0;
    rch_diagnose_cfg cfg;
    memset(&cfg, 0, sizeof cfg);
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--data", &data_path) ||
            rcal_opt_str(argc, argv, &i, "--robot", &robot_path) ||
            rcal_opt_str(argc, argv, &i, "--plots", &plots) || rcal_opt_uint(argc, argv, &i, "--seed", &seed) ||
            rcal_opt_uint(argc, argv, &i, "--folds", &folds) || rcal_opt_uint(argc, argv, &i, "--steps", &steps) ||
            rcal_opt_uint(argc, argv, &i, "--max-iter", &max_iter) ||
            rcal_opt_double(argc, argv, &i, "--q-step-deg", &cfg.q_step_deg) ||
            rcal_opt_double(argc, argv, &i, "--len-step-mm", &cfg.len_step_mm) ||
            rcal_opt_double(argc, argv, &i, "--len-noise-mm", &cfg.len_noise_mm) ||
            rcal_opt_double(argc, argv, &i, "--alpha", &cfg.alpha))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--verbose") == 0) {
            cfg.verbose++;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0)
            return usage(stdout);
        return rcal_opt_unknown("diagnose", argv[i]);
    }
    if (!data_path)
        return rcal_opt_missing("diagnose", "--data");
    if (folds < 2 || folds > RCH_DIAGNOSE_MAX_FOLDS || steps < 1 || steps > RCH_DIAGNOSE_MAX_STEPS ||
        cfg.alpha < 0.0 || cfg.alpha >= 1.0) {
        fprintf(stderr, "rcal diagnose: --folds must be 2..%d, --steps 1..%d, --alpha in (0, 1)\n",
                RCH_DIAGNOSE_MAX_FOLDS, RCH_DIAGNOSE_MAX_STEPS);
        return 2;
    }
    cfg.folds = (unsigned)folds;
    cfg.max_steps = (unsigned)steps;
    cfg.seed = seed;
    cfg.max_iter = (unsigned)max_iter;

    rch_robot robot;
    rch_data data;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, robot_path, &d) != 0 || rch_data_load(&data, data_path, 0, &d) != 0) {
        fprintf(stderr, "rcal diagnose: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    cfg.groups_given = data.has_group;
    cfg.have_encoder = robot.has_encoder;
    rch_diagnose_result r;
    int rc = rch_diagnose_run(&r, data.s, data.n, &robot.nominal, &cfg, &d);
    rch_data_free(&data);
    if (rc != 0) {
        fprintf(stderr, "rcal diagnose: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rch_diagnose_free(&r);
        return 1;
    }
    char paths[4096] = "";
    if (plots && rch_diagnose_plots(&r, plots, paths, sizeof paths, &d) != 0) {
        fprintf(stderr, "rcal diagnose: plots: %s\n", rch_diag_str(&d, msg, sizeof msg));
        rch_diagnose_free(&r);
        return 1;
    }
    if (json) {
        rc = rch_diagnose_json(stdout, &r);
    } else {
        rc = rch_diagnose_print(stdout, &r);
        if (plots)
            printf("\nPlots:\n%s", paths);
    }
    rch_diagnose_free(&r);
    return rc == 0 ? 0 : 1;
}
