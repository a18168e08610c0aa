/* SPDX-License-Identifier: MIT */
/* cmd_poses.c - rcal poses: plan an identifiable pose set.
 *
 * Parses the options, runs rch_poses_plan (tools/host/studies/rch_poses.h: the
 * D-optimal design) and writes the plan with rch_data_write_plan through a
 * temporary file renamed into place (rch_file.h), refusing an --out that
 * names the --robot file.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_data.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_poses.h"
#include "rch_robot.h"

static const char summary[] = "plan an identifiable pose set (D-optimal)";
static const char details[] =
    "Plans N poses inside the joint limits of MODEL less --margin-deg whose cable length (encoder at the\n"
    "file's encoder_mm, else --encoder) is within [--len-min-mm, --len-max-mm], chosen among M random candidates\n"
    "(default max(2000, 40 N)) to maximise det(J^T J) over the identifiable directions (rc_ident; greedy +\n"
    "exchange).\n"
    "Writes pose,q1..q6 (degrees, 0.01 deg steps); prints the observability index O1 beside that of a random\n"
    "plan of the same size. The design cost grows as N^2 (1000 poses: about 25 s; progress on stderr).";

/* What was planned and written, as one JSON object on stdout (rcal-poses/1). */
static int report_json(const rch_poses_result *res, const rch_poses_config *pc, const char *out_path, int argc,
                       char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-poses/1", argc, argv);
    rch_jw_str(&w, "out", out_path);
    rch_jw_uint(&w, "poses", res->n);
    rch_jw_uint(&w, "candidates", res->n_candidates);
    rch_jw_uint(&w, "seed", pc->seed);
    rch_jw_uint(&w, "identifiable_directions", res->n_ident);
    rch_jw_uint(&w, "params", res->n_params);
    rch_jw_num(&w, "o1_plan", res->o1_plan);
    rch_jw_uint(&w, "rank_plan", res->rank_plan);
    rch_jw_num(&w, "o1_random", res->o1_random);
    rch_jw_uint(&w, "rank_random", res->rank_random);
    rch_jw_num(&w, "o1_ratio", res->o1_random > 0 ? res->o1_plan / res->o1_random : NAN);
    rch_jw_numf(&w, "len_min_mm", pc->len_min_mm, "%.6g");
    rch_jw_numf(&w, "len_max_mm", pc->len_max_mm, "%.6g");
    rch_jw_numf(&w, "margin_deg", pc->margin_deg, "%.6g");
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

int rcal_cmd_poses(int argc, char **argv)
{
    const char *robot_path = RCAL_DEFAULT_ROBOT, *out_path = NULL;
    unsigned long n = 0, seed = 1, n_cand = 0, passes = 4;
    double enc[3] = {250.0, -460.0, 10.0};
    rch_poses_config pc = {0, 0, 4, 1, 250, 800, 5};
    int json = 0;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--count", RCH_OPT_UINT, &n, 1, RCH_POSES_MAX_COUNT, "N", "poses to plan", RCH_OPT_REQUIRED, NULL},
        {"--out", RCH_OPT_STR, &out_path, 0, 0, "POSES.csv", "the plan", RCH_OPT_REQUIRED, NULL},
        {"--robot", RCH_OPT_STR, &robot_path, 0, 0, "MODEL.json", "nominal model", 0, NULL},
        {"--seed", RCH_OPT_UINT, &seed, 0, 4294967295.0, "S", NULL, 0, NULL},
        {"--encoder", RCH_OPT_TRIPLE, enc, -1e5, 1e5, "X,Y,Z", "cable outlet (mm) if MODEL has none", 0, NULL},
        {"--len-min-mm", RCH_OPT_DOUBLE, &pc.len_min_mm, 0, 20000, "A", "shortest cable length", 0, NULL},
        {"--len-max-mm", RCH_OPT_DOUBLE, &pc.len_max_mm, 0, 20000, "B", "longest cable length", 0, NULL},
        {"--candidates", RCH_OPT_UINT, &n_cand, 0, RCH_POSES_MAX_CANDIDATES, "M", "0: max(2000, 40 N)", 0, NULL},
        {"--margin-deg", RCH_OPT_DOUBLE, &pc.margin_deg, 0, 360, "D", "kept from every joint limit", 0, NULL},
        {"--passes", RCH_OPT_UINT, &passes, 0, 100, "P", "exchange passes", 0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL, "what was planned and written, as one JSON object on stdout", 0,
         NULL},
    };
    rch_poses_result res;
    rch_robot *robot;
    rch_diag dg;
    rch_out out;
    char dbuf[900];
    int rc = 1;
    const int st = rch_opt_cmd(&spec, "poses", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, NULL);
    if (st >= 0)
        return st;
    pc.count = n;
    pc.candidates = n_cand;
    pc.passes = passes;
    pc.seed = seed;
    robot = calloc(1, sizeof *robot);
    if (!robot || rch_robot_load(robot, robot_path, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", robot ? rch_diag_str(&dg, dbuf, sizeof dbuf) : "out of memory");
        free(robot);
        return 1;
    }
    if (!robot->has_encoder)
        memcpy(&robot->model.x[RC_P_ENC], enc, sizeof enc);
    if (rch_out_open(&out, out_path, "--out", &robot_path, 1, &dg) != 0) { /* before the work */
        fprintf(stderr, "rcal poses: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
        free(robot);
        return 1;
    }
    if (rch_poses_plan(&res, &robot->model, &pc, stderr, &dg) != 0) {
        rch_out_abort(&out);
        fprintf(stderr, "rcal poses: %s\n", dg.msg);
        free(robot);
        return 1;
    }
    if (!json) {
        printf("rcal poses: %zu poses from %zu candidates, %u identifiable directions (rc_ident) of %u parameters\n",
               res.n, res.n_candidates, res.n_ident, res.n_params);
        printf("  observability O1 (rch_ident): planned %.5g (rank %u), random %.5g (rank %u), ratio %.2f\n",
               res.o1_plan, res.rank_plan, res.o1_random, res.rank_random,
               res.o1_random > 0 ? res.o1_plan / res.o1_random : 0.0);
    }
    if (rch_data_write_plan(out.f, res.poses, res.n) != 0) {
        rch_out_abort(&out);
        fprintf(stderr, "rcal poses: writing %s failed; nothing was replaced\n", out_path);
    } else if (rch_out_commit(&out, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
    } else if (json) {
        rc = report_json(&res, &pc, out_path, argc, argv) != 0;
    } else {
        printf("  written to %s\n", out_path);
        rc = 0;
    }
    rch_poses_free(&res);
    free(robot);
    return rc;
}
