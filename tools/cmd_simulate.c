/* cmd_simulate.c - rcal simulate: a data set from a simulated robot with
 * known DH errors and encoder position, in the same CSV format as real data. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_data.h"
#include "rch_robot.h"
#include "rch_sim.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal simulate --out DATA.csv [--truth-out TRUTH.json] [--robot MODEL.json] [--truth TRUTH.json]\n"
            "                     [--samples N] [--seed S] [--noise-mm S] [--resolution-mm R] [--q-step-deg D]\n"
            "                     [--err-len-mm S] [--err-ang-deg S] [--encoder X,Y,Z] [--group-size G]\n"
            "  The true robot is --truth if given, else the nominal --robot (default %s) plus random DH\n"
            "  errors (sigma --err-len-mm 0.3 mm for a, d; --err-ang-deg 0.05 deg for alpha, theta) and the\n"
            "  encoder at --encoder (default 250,-460,10 mm). Lengths get Gaussian noise (--noise-mm 0.01,\n"
            "  negative for none) and the encoder resolution (--resolution-mm 0.004); joint angles are\n"
            "  recorded at the display step (--q-step-deg 0.1). --group-size G keeps the wrist joints fixed\n"
            "  for G consecutive poses, like a real acquisition (default 0: independent poses).\n",
            RCAL_DEFAULT_ROBOT);
}

int rcal_cmd_simulate(int argc, char **argv)
{
    const char *out_path = NULL, *truth_out = NULL, *robot_path = RCAL_DEFAULT_ROBOT, *truth_path = NULL;
    unsigned long n = 500, seed = 1, group = 0;
    double enc[3] = {250.0, -460.0, 10.0};
    rch_sim_config c;
    memset(&c, 0, sizeof c);
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--out", &out_path) || rcal_opt_str(argc, argv, &i, "--truth-out", &truth_out) ||
            rcal_opt_str(argc, argv, &i, "--robot", &robot_path) || rcal_opt_str(argc, argv, &i, "--truth", &truth_path) ||
            rcal_opt_triple(argc, argv, &i, "--encoder", enc) || rcal_opt_uint(argc, argv, &i, "--samples", &n) ||
            rcal_opt_uint(argc, argv, &i, "--seed", &seed) || rcal_opt_uint(argc, argv, &i, "--group-size", &group) ||
            rcal_opt_double(argc, argv, &i, "--noise-mm", &c.noise_mm) ||
            rcal_opt_double(argc, argv, &i, "--resolution-mm", &c.resolution_mm) ||
            rcal_opt_double(argc, argv, &i, "--q-step-deg", &c.q_step_deg) ||
            rcal_opt_double(argc, argv, &i, "--err-len-mm", &c.err_len_mm) ||
            rcal_opt_double(argc, argv, &i, "--err-ang-deg", &c.err_ang_deg))
            continue;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("simulate", argv[i]);
    }
    if (!out_path)
        return rcal_opt_missing("simulate", "--out");
    if (n < 1 || n > 10000000) {
        fprintf(stderr, "rcal simulate: --samples must be 1..10000000\n");
        return 2;
    }
    c.group_size = (unsigned)group;
    rch_sim_defaults(&c);
    rch_robot robot;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, truth_path ? truth_path : robot_path, &d) != 0) {
        fprintf(stderr, "rcal simulate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    rc_rng g;
    rc_rng_seed(&g, seed);
    rc_model truth;
    if (truth_path) {
        truth = robot.model;
        if (!robot.has_encoder)
            memcpy(&truth.x[RC_P_ENC], enc, sizeof enc);
    } else {
        rch_sim_truth(&truth, &robot.model, enc, &c, &g);
    }
    rc_sample *s = malloc(n * sizeof *s);
    if (!s)
        return 1;
    if (rch_sim_samples(s, NULL, n, &truth, &c, &g) != 0) {
        fprintf(stderr, "rcal simulate: no pose puts the cable within %.0f..%.0f mm; check --encoder\n",
                c.len_min_mm, c.len_max_mm);
        free(s);
        return 1;
    }
    FILE *f = fopen(out_path, "w");
    if (!f || rch_data_write(f, s, n, &robot.nominal) != 0) {
        fprintf(stderr, "rcal simulate: cannot write %s\n", out_path);
        if (f)
            fclose(f);
        free(s);
        return 1;
    }
    fclose(f);
    free(s);
    if (truth_out) {
        char info[256];
        snprintf(info, sizeof info,
                 "{\"simulated\": true, \"seed\": %lu, \"noise_mm\": %g, \"resolution_mm\": %g, \"q_step_deg\": %g}",
                 seed, c.noise_mm, c.resolution_mm, c.q_step_deg);
        f = fopen(truth_out, "w");
        if (!f || rch_robot_write(f, "simulated truth", &truth, &robot.nominal, info) != 0) {
            fprintf(stderr, "rcal simulate: cannot write %s\n", truth_out);
            if (f)
                fclose(f);
            return 1;
        }
        fclose(f);
    }
    printf("rcal simulate: %lu samples written to %s%s%s\n", n, out_path, truth_out ? ", truth to " : "",
           truth_out ? truth_out : "");
    return 0;
}
