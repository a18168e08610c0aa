/* SPDX-License-Identifier: MIT */
/* cmd_poses_touch.c - rcal poses for the touch sensor (--plate ... or
 * --sensor touch; rcal_cmd_poses dispatches here): parses the plates, the
 * probe and the gauge block, runs rch_poses_touch_plan
 * (tools/host/studies/rch_poses_touch.h) and writes the touch file's
 * skeleton (pose,plane,q1..q6[,height_mm], the controller's joints) through a
 * temporary file renamed into place (rch_file.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_poses_touch.h"
#include "rch_robot.h"

static const char summary[] = "plan a touch run on flat plates for the best predicted 3-D accuracy at the probe";
static const char details[] =
    "Plans N touches of the probe (--tool, flange frame) on the plates given by --plate X,Y,Z,NX,NY,NZ[,SIZE]\n"
    "(repeatable: plates 0, 1, ...; a point on the face, the outward normal toward the probe, the usable face's\n"
    "diameter in mm, default 150): candidates are points on each face (less --edge-mm) with the probe's axis\n"
    "(the flange z) within --cone-deg of the inward normal, solved by the inverse kinematics of the nominal\n"
    "robot inside the joint limits less --margin-deg, the wrist --wrist-deg from its singularity, the flange\n"
    "outside every plate and, with a cell in the robot file, the links above the floor and out of the boxes.\n"
    "The plan minimises the predicted mean squared 3-D error of the probe's point over the workspace\n"
    "(I-optimal on the touch sensor's rows with the physical prior), every plate touched at least\n"
    "--min-per-plate times; --gauge-mm H: a gauge block of that height on --gauge-plate (at --gauge-at, default\n"
    "the plate's point; its top --gauge-size-mm across) gets at least --gauge-share of the touches (the length\n"
    "planes alone do not see). Writes pose,plane,q1..q6 (the controller's joints, degrees) and height_mm with a\n"
    "gauge: a touch file whose rows an acquisition confirms (docs/touches.md). Prints the predicted 95 %\n"
    "radius at the probe (trigger noise --noise-mm) beside random touches of the same count.";

/* --plate i: X,Y,Z,NX,NY,NZ[,SIZE]. 0 or -1 (reported). */
static int parse_plate(rch_touch_plate *p, const char *s, unsigned i)
{
    double v[7];
    int n = 0;
    const char *at = s;
    char *end;
    while (n < 7) {
        v[n] = strtod(at, &end);
        if (end == at || !isfinite(v[n]) || fabs(v[n]) > 1e5)
            break;
        ++n;
        if (*end != ',')
            break;
        at = end + 1;
    }
    if ((n != 6 && n != 7) || *end != '\0') {
        fprintf(stderr, "rcal poses: --plate %u '%s' (plate %u), at character %d: expected X,Y,Z,NX,NY,NZ[,SIZE] "
                        "(a point on the face and its outward normal in the base frame, the usable diameter, mm; "
                        "finite numbers within 1e5)\n", i + 1, s, i, (int)(end - s) + 1);
        return -1;
    }
    memcpy(p->point_mm, v, sizeof p->point_mm);
    memcpy(p->normal, v + 3, sizeof p->normal);
    p->size_mm = n == 7 ? v[6] : 150.0;
    if (!(sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5]) > 1e-9) || !(p->size_mm > 0.0)) {
        fprintf(stderr, "rcal poses: --plate %u '%s' (plate %u): %s\n", i + 1, s, i,
                p->size_mm > 0.0 ? "the normal NX,NY,NZ has no direction (all zero)" : "SIZE must be > 0 mm");
        return -1;
    }
    return 0;
}

typedef struct touch_args {
    const char *robot_path, *out_path, *order, *sensor;
    unsigned long n, seed, n_cand, passes, gauge_plate, min_per;
    double gauge_at[3];
    rch_opt_strs plates;
    int json;
    rch_poses_touch_config tc;
} touch_args;

static int parse(touch_args *a, int argc, char **argv)
{
    rch_poses_touch_config *tc = &a->tc;
    rch_cmdspec spec;
    unsigned long long seen = 0;
    memset(a, 0, sizeof *a);
    a->robot_path = RCAL_DEFAULT_ROBOT;
    a->order = "travel";
    a->sensor = "touch";
    a->seed = 1;
    a->passes = 4;
    a->min_per = 3;
    tc->margin_deg = 5.0;
    tc->cone_deg = 30.0;
    tc->edge_mm = 10.0;
    tc->wrist_deg = 10.0;
    tc->gauge_size_mm = 40.0;
    tc->gauge_share = 0.2;
    tc->noise_mm = RCH_TOUCH_NOISE_MM;
    const rch_opt opts[] = {
        {"--count", RCH_OPT_UINT, &a->n, 1, RCH_POSES_MAX_COUNT, "N", "touches to plan", RCH_OPT_REQUIRED, NULL},
        {"--out", RCH_OPT_STR, &a->out_path, 0, 0, "FILE", "the plan: a touch file's skeleton (CSV)", RCH_OPT_REQUIRED,
         NULL},
        {"--sensor", RCH_OPT_CHOICE, &a->sensor, 0, 0, NULL, "the sensor planned for (--plate implies touch)", 0,
         "cable|touch"},
        {"--robot", RCH_OPT_STR, &a->robot_path, 0, 0, "MODEL.json", "nominal model", 0, NULL},
        {"--seed", RCH_OPT_UINT, &a->seed, 0, 4294967295.0, "S", NULL, 0, NULL},
        {"--plate", RCH_OPT_STRS, &a->plates, 0, 0, "X,Y,Z,NX,NY,NZ[,SIZE]",
         "a plate: a point on its face, the outward normal, the usable diameter (mm, base frame; repeatable)",
         RCH_OPT_REQUIRED, NULL},
        {"--tool", RCH_OPT_TRIPLE, tc->tool_mm, -2000.0, 2000.0, "X,Y,Z", "the probe's point (flange frame, mm)",
         RCH_OPT_REQUIRED, NULL},
        {"--cone-deg", RCH_OPT_DOUBLE, &tc->cone_deg, 0.1, 80, "DEG", "the probe's axis within this of the normal", 0,
         NULL},
        {"--edge-mm", RCH_OPT_DOUBLE, &tc->edge_mm, 0, 1000, "MM", "kept from a face's edge", 0, NULL},
        {"--wrist-deg", RCH_OPT_DOUBLE, &tc->wrist_deg, 0, 44, "DEG", "q5 kept this far from the wrist singularity",
         0, NULL},
        {"--margin-deg", RCH_OPT_DOUBLE, &tc->margin_deg, 0, 360, "D", "kept from every joint limit", 0, NULL},
        {"--gauge-mm", RCH_OPT_DOUBLE, &tc->gauge_mm, 0, 1000, "H", "a gauge block of this height (0: none)", 0, NULL},
        {"--gauge-plate", RCH_OPT_UINT, &a->gauge_plate, 0, RCH_TOUCH_MAX_PLATES - 1, "K", "the plate it stands on",
         0, NULL},
        {"--gauge-at", RCH_OPT_TRIPLE, a->gauge_at, -1e5, 1e5, "X,Y,Z",
         "where it stands on that plate's face (default the plate's point)", 0, NULL},
        {"--gauge-size-mm", RCH_OPT_DOUBLE, &tc->gauge_size_mm, 1, 1000, "MM", "its top's usable diameter", 0, NULL},
        {"--gauge-share", RCH_OPT_DOUBLE, &tc->gauge_share, 0.01, 0.9, "F",
         "the share of candidates on its top, and the least share of the plan", 0, NULL},
        {"--min-per-plate", RCH_OPT_UINT, &a->min_per, 3, 1000, "K", "touches per plate at least", 0, NULL},
        {"--noise-mm", RCH_OPT_DOUBLE, &tc->noise_mm, 1e-6, 100, "MM", "the trigger's noise of the prediction", 0,
         NULL},
        {"--candidates", RCH_OPT_UINT, &a->n_cand, 0, RCH_POSES_MAX_CANDIDATES, "M", "0: max(2000, 40 N)", 0, NULL},
        {"--passes", RCH_OPT_UINT, &a->passes, 0, 100, "P", "exchange passes", 0, NULL},
        {"--order", RCH_OPT_CHOICE, &a->order, 0, 0, NULL, "one tour from home that shortens the joint travel, or "
         "the selection's order", 0, "travel|selection"},
        {"--json", RCH_OPT_FLAG, &a->json, 0, 0, NULL, "what was planned and written, as one JSON object on stdout", 0,
         NULL},
    };
    const int st = rch_opt_cmd(&spec, "poses", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, &seen);
    if (st >= 0)
        return st;
    if (strcmp(a->sensor, "touch") != 0) {
        fprintf(stderr, "rcal poses: --sensor cable takes no --plate (a plate is the touch sensor's)\n");
        return 2;
    }
    for (size_t i = 0; i < a->plates.n; ++i)
        if (parse_plate(&tc->plates[i], a->plates.v[i], (unsigned)i) != 0)
            return 2;
    tc->n_plates = (unsigned)a->plates.n;
    if (rch_opt_given(&spec, seen, "--gauge-at")) {
        tc->has_gauge_at = 1;
        memcpy(tc->gauge_at_mm, a->gauge_at, sizeof a->gauge_at);
    }
    if (tc->gauge_mm == 0.0 && (rch_opt_given(&spec, seen, "--gauge-at") || rch_opt_given(&spec, seen, "--gauge-plate"))) {
        fprintf(stderr, "rcal poses: --gauge-at and --gauge-plate describe a gauge block: give its --gauge-mm\n");
        return 2;
    }
    if (a->gauge_plate >= tc->n_plates) {
        fprintf(stderr, "rcal poses: --gauge-plate %lu: only %u --plate given (plates 0..%u)\n", a->gauge_plate,
                tc->n_plates, tc->n_plates - 1);
        return 2;
    }
    tc->gauge_plate = (unsigned)a->gauge_plate;
    tc->count = a->n;
    tc->candidates = a->n_cand;
    tc->passes = a->passes;
    tc->seed = a->seed;
    tc->min_per_plate = (unsigned)a->min_per;
    tc->keep_order = strcmp(a->order, "selection") == 0;
    return -1;
}

static void json_acc(rch_jw *w, const char *key, const rch_poses_accuracy *p)
{
    rch_jw_obj(w, key);
    rch_jw_num(w, "median_mm", p->median_mm);
    rch_jw_num(w, "p95_mm", p->p95_mm);
    rch_jw_num(w, "mean_sq_mm2", p->phi_mm2);
    rch_jw_end(w);
}

static int report_json(const rch_poses_touch_result *res, const touch_args *a, int argc, char **argv)
{
    const rch_poses_touch_config *tc = &a->tc;
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-poses/2", argc, argv);
    rch_jw_str(&w, "out", a->out_path);
    rch_jw_str(&w, "out_format", "csv");
    rch_jw_str(&w, "sensor", "touch");
    rch_jw_str(&w, "criterion", "position");
    rch_jw_uint(&w, "poses", res->n);
    rch_jw_uint(&w, "rows", res->n);
    rch_jw_uint(&w, "candidates", res->n_candidates);
    rch_jw_uint(&w, "points_tried", res->n_tried);
    rch_jw_obj(&w, "dropped");
    rch_jw_uint(&w, "out_of_reach", res->no_ik);
    rch_jw_uint(&w, "limits_or_wrist", res->rejected_limits);
    rch_jw_uint(&w, "flange_inside_plate", res->rejected_plate);
    rch_jw_uint(&w, "cell", res->rejected_cell);
    rch_jw_end(&w);
    rch_jw_uint(&w, "seed", tc->seed);
    rch_jw_uint(&w, "params", res->n_params);
    rch_jw_uint(&w, "free_params", res->nf);
    rch_jw_numf(&w, "noise_mm", tc->noise_mm, "%.6g");
    rch_jw_arr(&w, "tool_mm");
    for (int c = 0; c < 3; ++c)
        rch_jw_numf(&w, NULL, tc->tool_mm[c], "%.6g");
    rch_jw_end(&w);
    rch_jw_arr(&w, "plates");
    for (unsigned k = 0; k < tc->n_plates; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_arr(&w, "point_mm");
        for (int c = 0; c < 3; ++c)
            rch_jw_numf(&w, NULL, tc->plates[k].point_mm[c], "%.6g");
        rch_jw_end(&w);
        rch_jw_arr(&w, "normal");
        for (int c = 0; c < 3; ++c)
            rch_jw_numf(&w, NULL, tc->plates[k].normal[c], "%.6g");
        rch_jw_end(&w);
        rch_jw_numf(&w, "size_mm", tc->plates[k].size_mm, "%.6g");
        rch_jw_uint(&w, "touches", res->per_plate[k]);
        rch_jw_numf(&w, "spread_mm", res->spread_mm[k], "%.3f");
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    if (tc->gauge_mm > 0.0) {
        rch_jw_obj(&w, "gauge");
        rch_jw_numf(&w, "height_mm", tc->gauge_mm, "%.6g");
        rch_jw_uint(&w, "plate", tc->gauge_plate);
        rch_jw_uint(&w, "touches", res->gauge_rows);
        rch_jw_end(&w);
    }
    rch_jw_obj(&w, "predicted_position95_mm");
    json_acc(&w, "plan", &res->plan);
    json_acc(&w, "random", &res->random);
    rch_jw_end(&w);
    rch_jw_obj(&w, "joint_travel");
    rch_jw_numf(&w, "before_deg", res->travel.before_deg, "%.2f");
    rch_jw_numf(&w, "after_deg", res->travel.after_deg, "%.2f");
    rch_jw_end(&w);
    rch_jw_numf(&w, "cone_deg", tc->cone_deg, "%.6g");
    rch_jw_numf(&w, "margin_deg", tc->margin_deg, "%.6g");
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

static void print_plan(const rch_poses_touch_result *res, const touch_args *a, int cell)
{
    const rch_poses_touch_config *tc = &a->tc;
    printf("rcal poses: %zu touches on %u plate(s) from %zu candidates (%zu face points tried: %zu out of reach, %zu "
           "against the limits or the wrist, %zu with the flange inside a plate, %zu against the cell%s); %u free "
           "parameters (the prior's information included; theta1, d1 held)\n",
           res->n, tc->n_plates, res->n_candidates, res->n_tried, res->no_ik, res->rejected_limits,
           res->rejected_plate, res->rejected_cell, cell ? "" : ": none in the robot file", res->nf);
    for (unsigned k = 0; k < tc->n_plates; ++k)
        printf("  plate %u at (%.1f, %.1f, %.1f) mm: %zu touches, spread %.1f mm%s\n", k, tc->plates[k].point_mm[0],
               tc->plates[k].point_mm[1], tc->plates[k].point_mm[2], res->per_plate[k], res->spread_mm[k],
               tc->gauge_mm > 0.0 && k == tc->gauge_plate ? " (and the gauge block's top)" : "");
    if (tc->gauge_mm > 0.0)
        printf("  the gauge block (%g mm) on plate %u: %zu touches of its top (height_mm %g)\n", tc->gauge_mm,
               tc->gauge_plate, res->gauge_rows, tc->gauge_mm);
    printf("  predicted 3-D accuracy of the probe's point after calibration (95 %% position radius over 1000 random "
           "workspace poses, trigger noise %g mm):\n", tc->noise_mm);
    printf("    this plan:         median %.4f mm, 95th percentile %.4f mm\n", res->plan.median_mm, res->plan.p95_mm);
    printf("    random, same count: median %.4f mm, 95th percentile %.4f mm (fewest on a plate: %zu)\n",
           res->random.median_mm, res->random.p95_mm, res->random_per_plate_min);
    printf("  joint travel: %.0f deg before ordering, %.0f deg after\n", res->travel.before_deg, res->travel.after_deg);
    if (res->n < res->nf + RCH_POSES_ROWS_SPARE)
        printf("  WARNING: %zu touches for about %u parameters calibrate fits: it estimates the noise from the "
               "residuals and needs at least %u, else the fit follows the noise (measured: 60 touches on 3 plates "
               "and a gauge no better than random ones, 100 better; docs/touches.md); next: raise --count\n",
               res->n, res->nf, res->nf + RCH_POSES_ROWS_SPARE);
    printf("  record them: drive each row's joints, approach along the plate's normal until the probe triggers, and "
           "write the triggered joints in the row (docs/touches.md)\n");
}

int rcal_cmd_poses_touch(int argc, char **argv)
{
    touch_args a;
    rch_poses_touch_result res;
    rch_diag dg;
    rch_out out;
    char dbuf[900];
    const int st = parse(&a, argc, argv);
    if (st >= 0)
        return st;
    rch_robot *robot = calloc(1, sizeof *robot);
    if (!robot || rch_robot_load(robot, a.robot_path, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", robot ? rch_diag_str(&dg, dbuf, sizeof dbuf) : "out of memory");
        free(robot);
        return 1;
    }
    a.tc.prior = &robot->prior;
    a.tc.cell = &robot->cell;
    if (rch_poses_touch_check(&robot->model, &a.tc, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", dg.msg);
        free(robot);
        return 2;
    }
    if (rch_out_open(&out, a.out_path, "--out", &a.robot_path, 1, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
        free(robot);
        return 1;
    }
    if (rch_poses_touch_plan(&res, &robot->model, &a.tc, stderr, &dg) != 0) {
        rch_out_abort(&out);
        fprintf(stderr, "rcal poses: %s\n", dg.msg);
        free(robot);
        return 1;
    }
    int rc = 1;
    rc_sample *rows = malloc((res.n ? res.n : 1) * sizeof *rows);
    if (rows) {
        for (size_t i = 0; i < res.n; ++i) { /* a data file states the controller's joints */
            rows[i] = res.rows[i];
            rch_ctrl_from_model(rows[i].q_rad, &robot->ctrl, res.rows[i].q_rad);
        }
        if (!a.json)
            print_plan(&res, &a, rch_cell_any(&robot->cell));
        if (rch_poses_touch_write_csv(out.f, rows, res.n, a.tc.gauge_mm > 0.0) != 0) {
            const int err = rch_out_errno(&out);
            rch_out_abort(&out);
            fprintf(stderr, "rcal poses: %s: cannot write --out: %s; nothing was replaced\n", a.out_path,
                    strerror(err));
        } else if (rch_out_commit(&out, &dg) != 0) {
            fprintf(stderr, "rcal poses: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
        } else {
            rc = a.json ? report_json(&res, &a, argc, argv) != 0 : 0;
            if (!a.json)
                printf("  written to %s\n", a.out_path);
        }
    } else {
        rch_out_abort(&out);
        fprintf(stderr, "rcal poses: out of memory\n");
    }
    free(rows);
    rch_poses_touch_free(&res);
    free(robot);
    return rc;
}
