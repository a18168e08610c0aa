/* SPDX-License-Identifier: MIT */
/* cmd_simulate.c - rcal simulate: a data set from a simulated robot with
 * known DH errors and encoder position, in the same CSV format as real data.
 * The work is rch_sim_make (tools/host/fit/rch_sim.h). */
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_data.h" /* RCH_DATA_MAX_ROWS */
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_sim.h"

static const char summary[] = "a data set from a simulated robot with known errors";
static const char details[] =
    "The true robot is --truth if given, else the nominal --robot plus random DH errors\n"
    "and the encoder at --encoder. Lengths get Gaussian noise and the encoder\n"
    "resolution; joint angles are recorded at the display step.";

static int report_json(int argc, char **argv, unsigned long n, const char *out_path, const char *truth_out,
                       const rch_sim_job *job)
{
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-simulate/1", argc, argv);
    rch_jw_uint(&w, "samples", n);
    rch_jw_str(&w, "data", out_path);
    rch_jw_str(&w, "truth", truth_out);
    rch_jw_uint(&w, "seed", job->seed);
    rch_jw_num(&w, "noise_mm", job->sim.noise_mm > 0 ? job->sim.noise_mm : 0.0);
    rch_jw_num(&w, "q_step_deg", job->sim.q_step_deg > 0 ? job->sim.q_step_deg : 0.0);
    rch_jw_uint(&w, "repeats", job->sim.repeats > 1 ? job->sim.repeats : 1u);
    rch_jw_end(&w);
    return rch_jw_finish(&w) == 0 ? 0 : 1;
}

int rcal_cmd_simulate(int argc, char **argv)
{
    rch_sim_job job;
    memset(&job, 0, sizeof job);
    job.robot_path = RCAL_DEFAULT_ROBOT;
    job.enc_mm[0] = 250.0;
    job.enc_mm[1] = -460.0;
    job.enc_mm[2] = 10.0;
    const char *out_path = NULL, *truth_out = NULL;
    unsigned long repeats = 1, n = 500, seed = 1, group = 0;
    int json = 0;
    rch_sim_config *c = &job.sim;
    rch_sim_defaults(c); /* the defaults shown; 0 given on the command line means none, never the default */
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--out", RCH_OPT_STR, &out_path, 0, 0, "DATA.csv", "the simulated measurements", RCH_OPT_REQUIRED, NULL},
        {"--truth-out", RCH_OPT_STR, &truth_out, 0, 0, "TRUTH.json", "the true model", 0, NULL},
        {"--robot", RCH_OPT_STR, &job.robot_path, 0, 0, "MODEL.json", "nominal robot model", 0, NULL},
        {"--truth", RCH_OPT_STR, &job.truth_path, 0, 0, "TRUTH.json", "a given true model (no random errors)", 0,
         NULL},
        {"--samples", RCH_OPT_UINT, &n, 1, (double)RCH_DATA_MAX_ROWS, NULL, "number of samples (what rcal reads)", 0,
         NULL},
        {"--seed", RCH_OPT_UINT, &seed, 0, 0, "S", "random seed", 0, NULL},
        {"--noise-mm", RCH_OPT_DOUBLE, &c->noise_mm, -1, 100, "S", "length noise sigma (0 or negative: none)", 0,
         NULL},
        {"--resolution-mm", RCH_OPT_DOUBLE, &c->resolution_mm, -1, 100, "R",
         "encoder resolution (0 or negative: none)", 0, NULL},
        {"--q-step-deg", RCH_OPT_DOUBLE, &c->q_step_deg, -1, 10, "D",
         "joint display step (0 or negative: none)", 0, NULL},
        {"--err-len-mm", RCH_OPT_DOUBLE, &c->err_len_mm, -100, 100, "S", "sigma of the a, d errors (0: none)", 0,
         NULL},
        {"--err-ang-deg", RCH_OPT_DOUBLE, &c->err_ang_deg, -10, 10, "S",
         "sigma of the alpha, theta errors (0: none)", 0, NULL},
        {"--encoder", RCH_OPT_TRIPLE, job.enc_mm, -10000, 10000, NULL, "encoder outlet (mm)", 0, NULL},
        {"--group-size", RCH_OPT_UINT, &group, 0, 1000000, "G",
         "keep the wrist joints fixed for G consecutive poses (0: independent poses)", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "what was written, as one JSON object on stdout", 0, NULL},
        {"--repeats", RCH_OPT_UINT, &repeats, 1, 1000, "R",
         "read every pose R times in a row (fresh length noise): repeatability, ISO 9283", 0, NULL},
    };
    const int ps = rch_opt_cmd(&spec, "simulate", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (ps >= 0)
        return ps;
    job.n = n;
    job.seed = seed;
    c->group_size = (unsigned)group;
    c->repeats = (unsigned)repeats;
    double *zero_means_none[] = {&c->noise_mm, &c->resolution_mm, &c->q_step_deg, &c->err_len_mm, &c->err_ang_deg};
    for (size_t k = 0; k < sizeof zero_means_none / sizeof zero_means_none[0]; ++k)
        if (*zero_means_none[k] == 0.0)
            *zero_means_none[k] = -1.0; /* rch_sim_defaults fills only zeros */

    rch_sim_set set;
    rch_diag d;
    char msg[1024];
    if (rch_sim_make(&set, &job, &d) != 0)
        return rch_opt_fail(&spec, &d);
    const int rc = rch_sim_save(&set, &job, out_path, truth_out, &d);
    rch_sim_set_free(&set);
    if (rc != 0) {
        fprintf(stderr, "rcal simulate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (json)
        return report_json(argc, argv, n, out_path, truth_out, &job);
    printf("rcal simulate: %lu samples written to %s%s%s\n", n, out_path, truth_out ? ", truth to " : "",
           truth_out ? truth_out : "");
    return 0;
}
