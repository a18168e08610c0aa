/* SPDX-License-Identifier: MIT */
/* cmd_poses.c - rcal poses: plan a pose set.
 *
 * Parses the options, runs rch_poses_plan (tools/host/studies/rch_poses.h:
 * the 3-D position criterion for K outlets, or the D-optimal length plan)
 * or rch_poses_choose_outlets, and writes the plan (CSV with
 * rch_data_write_plan, or a RAPID module) through a temporary file renamed
 * into place (rch_file.h), refusing an --out that names the --robot file.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_calib_cfg.h"
#include "rch_data.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_poses.h"
#include "rch_poses_link.h"
#include "rch_robot.h"

static const char summary[] = "plan a pose set for the best predicted 3-D accuracy (one or several outlets)";
static const char details[] =
    "Plans N poses inside the joint limits of MODEL less --margin-deg whose cable length from the outlet(s) is\n"
    "within [--len-min-mm, --len-max-mm], chosen among M random candidates (default max(2000, 40 N)).\n"
    "--criterion position (default): the outlets at --outlet X,Y,Z (repeatable, mm in the base frame; none:\n"
    "the file's encoder_mm, else --encoder), every pose measured from every outlet (the plan repeats the poses\n"
    "per outlet) or with --split each from one; the plan minimises the predicted mean squared 3-D error of the\n"
    "flange (or --tool) over the workspace (I-optimal, the physical prior as prior information) and reports\n"
    "the predicted 95 % position radius over random workspace poses (median, 95th percentile) at --noise-mm,\n"
    "beside random poses. --criterion length: the earlier D-optimal plan on the lengths (one outlet; O1).\n"
    "--choose-outlets K --candidate X,Y,Z ...: which K of the candidate places give the best predicted\n"
    "accuracy (every combination up to 64, else greedily); the plan is then made for them.\n"
    "Writes pose,q1..q6 (degrees, 0.01 deg steps) and, with several outlets, outlet (0..K-1); --format rapid\n"
    "writes an ABB RAPID module that moves through the same plan (the same options and seed give the same\n"
    "plan). The design cost grows as N^2 (progress on stderr). The rows are then ordered for joint travel\n"
    "(--order travel): per outlet a tour from home (nearest neighbour, 2-opt), a joint with a range over 360 deg\n"
    "on the branch (q +- 360, within the limits less --margin-deg) that shortens it; the travel before and after\n"
    "is printed (the sum over moves of the largest joint move, deg).\n"
    "--plate X,Y,Z,NX,NY,NZ[,SIZE] or --sensor touch: plan a touch run instead (rcal poses --sensor touch --help).";

static int parse_places(double (*out)[3], unsigned *n, const rch_opt_strs *v, const char *name)
{
    *n = 0;
    for (size_t i = 0; i < v->n; ++i) {
        if (rch_parse_triple(v->v[i], out[i]) != 0 || fabs(out[i][0]) > 1e5 || fabs(out[i][1]) > 1e5 ||
            fabs(out[i][2]) > 1e5) {
            fprintf(stderr, "rcal poses: %s '%s': expected X,Y,Z in mm (three finite numbers within 1e5)\n", name,
                    v->v[i]);
            return -1;
        }
        ++*n;
    }
    return 0;
}

static void json_acc(rch_jw *w, const char *key, const rch_poses_accuracy *a)
{
    rch_jw_obj(w, key);
    rch_jw_num(w, "median_mm", a->median_mm);
    rch_jw_num(w, "p95_mm", a->p95_mm);
    rch_jw_num(w, "mean_sq_mm2", a->phi_mm2);
    rch_jw_end(w);
}

static void json_places(rch_jw *w, const double (*p)[3], const unsigned *idx, unsigned n)
{
    for (unsigned j = 0; j < n; ++j) {
        const double *x = p[idx ? idx[j] : j];
        rch_jw_arr(w, NULL);
        for (int c = 0; c < 3; ++c)
            rch_jw_numf(w, NULL, x[c], "%.6g");
        rch_jw_end(w);
    }
}

static void json_travel(rch_jw *w, const rch_poses_travel *t)
{
    rch_jw_obj(w, "joint_travel");
    rch_jw_str(w, "metric", "sum over moves of max over joints |dq|, from home, per outlet and plate point");
    rch_jw_numf(w, "before_deg", t->before_deg, "%.2f");
    rch_jw_numf(w, "after_deg", t->after_deg, "%.2f");
    rch_jw_num(w, "ratio", t->before_deg > 0 ? t->after_deg / t->before_deg : 1.0);
    rch_jw_arr(w, "q_min_deg");
    for (int j = 0; j < RC_NJ; ++j)
        rch_jw_numf(w, NULL, t->after_min_deg[j], "%.2f");
    rch_jw_end(w);
    rch_jw_arr(w, "q_max_deg");
    for (int j = 0; j < RC_NJ; ++j)
        rch_jw_numf(w, NULL, t->after_max_deg[j], "%.2f");
    rch_jw_end(w);
    rch_jw_end(w);
}

/* What was planned and written, as one JSON object on stdout (rcal-poses/2). */
static int report_json(const rch_poses_result *res, const rch_poses_config *pc, const rch_poses_choice *ch,
                       const double (*cand)[3], const char *out_path, const char *format, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-poses/2", argc, argv);
    rch_jw_str(&w, "out", out_path);
    rch_jw_str(&w, "out_format", format);
    rch_jw_str(&w, "criterion", pc->criterion == RCH_POSES_LENGTH ? "length" : "position");
    rch_jw_uint(&w, "poses", res->n_distinct);
    rch_jw_uint(&w, "rows", res->n);
    rch_jw_uint(&w, "outlets", res->n_outlets);
    rch_jw_bool(&w, "split", pc->split);
    rch_jw_arr(&w, "outlet_mm");
    json_places(&w, (const double(*)[3])pc->outlet_mm, NULL, pc->n_outlets);
    rch_jw_end(&w);
    rch_jw_arr(&w, "rows_per_outlet");
    for (unsigned k = 0; k < res->n_outlets; ++k)
        rch_jw_uint(&w, NULL, res->rows_per_outlet[k]);
    rch_jw_end(&w);
    if (pc->criterion != RCH_POSES_LENGTH)
        rch_jw_uint(&w, "rows_advised", res->rows_advised);
    rch_jw_uint(&w, "candidates", res->n_candidates);
    rch_jw_numf(&w, "clearance_mm", pc->clearance_mm, "%.6g");
    rch_jw_obj(&w, "dropped"); /* candidates dropped for the cable and the cell, by reason */
    rch_jw_uint(&w, "checked", res->n_checked);
    for (unsigned r = 1; r < RCH_CELL_N_REASONS; ++r)
        rch_jw_uint(&w, rch_cell_reason_key((rch_cell_reason)r), res->dropped[r]);
    rch_jw_end(&w);
    rch_jw_uint(&w, "seed", pc->seed);
    rch_jw_uint(&w, "identifiable_directions", res->n_ident);
    rch_jw_uint(&w, "params", res->n_params);
    if (pc->criterion != RCH_POSES_LENGTH) {
        rch_jw_numf(&w, "noise_mm", pc->noise_mm, "%.6g");
        if (pc->has_tool) {
            rch_jw_arr(&w, "tool_mm");
            for (int c = 0; c < 3; ++c)
                rch_jw_numf(&w, NULL, pc->tool_mm[c], "%.6g");
            rch_jw_end(&w);
        }
        rch_jw_obj(&w, "predicted_position95_mm");
        json_acc(&w, "plan", &res->plan);
        json_acc(&w, "random", &res->random);
        rch_jw_end(&w);
        if (res->n_points) {
            /* the tool plate: its points as told, and the same poses on the first j of them */
            rch_jw_arr(&w, "cable_points_mm");
            json_places(&w, (const double(*)[3])pc->points_mm, NULL, pc->n_points);
            rch_jw_end(&w);
            rch_jw_arr(&w, "predicted_by_points");
            for (unsigned j = 1; j <= res->n_points; ++j) {
                rch_jw_obj(&w, NULL);
                rch_jw_uint(&w, "points", j);
                rch_jw_uint(&w, "rows", res->by_points[j - 1].rows);
                rch_jw_num(&w, "median_mm", res->by_points[j - 1].ok ? res->by_points[j - 1].acc.median_mm : NAN);
                rch_jw_num(&w, "p95_mm", res->by_points[j - 1].ok ? res->by_points[j - 1].acc.p95_mm : NAN);
                rch_jw_end(&w);
            }
            rch_jw_end(&w);
        }
    }
    rch_jw_num(&w, "o1_plan", res->o1_plan);
    rch_jw_uint(&w, "rank_plan", res->rank_plan);
    rch_jw_num(&w, "o1_random", res->o1_random);
    rch_jw_uint(&w, "rank_random", res->rank_random);
    rch_jw_num(&w, "o1_ratio", res->o1_random > 0 ? res->o1_plan / res->o1_random : NAN);
    json_travel(&w, &res->travel);
    rch_jw_numf(&w, "len_min_mm", pc->len_min_mm, "%.6g");
    rch_jw_numf(&w, "len_max_mm", pc->len_max_mm, "%.6g");
    rch_jw_numf(&w, "margin_deg", pc->margin_deg, "%.6g");
    if (ch) {
        rch_jw_obj(&w, "choose_outlets");
        rch_jw_uint(&w, "k", ch->k);
        rch_jw_str(&w, "search", ch->exhaustive ? "every combination" : "greedy");
        rch_jw_arr(&w, "candidate_mm");
        json_places(&w, cand, NULL, ch->n_cand);
        rch_jw_end(&w);
        rch_jw_arr(&w, "combinations");
        for (size_t i = 0; i < ch->n_combos; ++i) {
            const rch_poses_combo *cb = &ch->combos[i];
            rch_jw_obj(&w, NULL);
            rch_jw_arr(&w, "candidates");
            for (unsigned j = 0; j < cb->k; ++j)
                rch_jw_uint(&w, NULL, cb->idx[j]);
            rch_jw_end(&w);
            rch_jw_num(&w, "median_mm", cb->acc.median_mm);
            rch_jw_num(&w, "p95_mm", cb->acc.p95_mm);
            rch_jw_str(&w, "span", cb->span == 1 ? "point" : cb->span == 2 ? "line" : "plane");
            rch_jw_bool(&w, "chosen", i == ch->best);
            rch_jw_end(&w);
        }
        rch_jw_end(&w);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

static void print_choice(const rch_poses_choice *ch, const double (*cand)[3])
{
    printf("rcal poses: which %u of %u candidate outlet places (%s; a greedy plan of the same count each):\n", ch->k,
           ch->n_cand, ch->exhaustive ? "every combination" : "greedily, one place at a time");
    for (size_t i = 0; i < ch->n_combos; ++i) {
        const rch_poses_combo *cb = &ch->combos[i];
        printf("  %s", i == ch->best ? "*" : " ");
        for (unsigned j = 0; j < cb->k; ++j)
            printf(" %u", cb->idx[j]);
        printf("  (");
        for (unsigned j = 0; j < cb->k; ++j)
            printf("%s%.0f,%.0f,%.0f", j ? "; " : "", cand[cb->idx[j]][0], cand[cb->idx[j]][1], cand[cb->idx[j]][2]);
        printf(")  predicted 95 %% radius median %.4f mm, p95 %.4f mm  [%s]\n", cb->acc.median_mm, cb->acc.p95_mm,
               cb->span == 1 ? "one point" : cb->span == 2 ? "on a line" : "a plane");
    }
}

/* What each further cable point gains (rch_poses_result.by_points). */
static void print_point_gains(const rch_poses_result *res)
{
    printf("  the same poses on the first j cable points of the plate (every pose on each; the plate's drawing "
           "to its prior sd):\n");
    for (unsigned j = 1; j <= res->n_points; ++j) {
        if (res->by_points[j - 1].ok)
            printf("    %u point(s), %zu rows: median %.4f mm, 95th percentile %.4f mm\n", j,
                   res->by_points[j - 1].rows, res->by_points[j - 1].acc.median_mm, res->by_points[j - 1].acc.p95_mm);
        else
            printf("    %u point(s): the prediction failed\n", j);
    }
}

/* The joint travel before and after ordering (rch_poses_order; issue 48). */
static void print_plan_figures(const rch_poses_result *res, const rch_poses_config *pc, const char *out_path);

static void print_travel(const rch_poses_travel *t)
{
    printf("  joint travel: %.0f deg before ordering, %.0f deg after (%.2f; the sum of the largest joint move per "
           "move, from home, per outlet and plate point)\n",
           t->before_deg, t->after_deg, t->before_deg > 0 ? t->after_deg / t->before_deg : 1.0);
    printf("    q4 in [%.0f, %.0f] deg, q6 in [%.0f, %.0f] deg (before: q4 [%.0f, %.0f], q6 [%.0f, %.0f])\n",
           t->after_min_deg[3], t->after_max_deg[3], t->after_min_deg[5], t->after_max_deg[5], t->before_min_deg[3],
           t->before_max_deg[3], t->before_min_deg[5], t->before_max_deg[5]);
}

/* The candidates the cable and the cell dropped (issue 48): one line. */
static void print_dropped(const rch_poses_result *res, const rch_poses_config *pc)
{
    char why[400];
    size_t n = 0;
    if (!rch_cell_any(pc->cell)) {
        printf("  the cable and the cell: not checked (the robot file has no \"links\" or \"cell\")\n");
        return;
    }
    for (unsigned r = 1; r < RCH_CELL_N_REASONS; ++r)
        n += res->dropped[r];
    rch_poses_dropped_str(why, sizeof why, res);
    printf("  the cable and the cell (%u links, %s, %u boxes; clearance %g mm): dropped %zu of %zu candidates: %s\n",
           pc->cell->n_links, pc->cell->has_floor ? "a floor" : "no floor", pc->cell->n_boxes, pc->clearance_mm, n,
           res->n_checked, why);
}

static void print_plan(const rch_poses_result *res, const rch_poses_config *pc, const char *out_path)
{
    print_plan_figures(res, pc, out_path);
    print_travel(&res->travel);
}

static void print_plan_figures(const rch_poses_result *res, const rch_poses_config *pc, const char *out_path)
{
    if (pc->criterion == RCH_POSES_LENGTH) {
        printf("rcal poses: %zu poses from %zu candidates, %u identifiable directions (rc_ident) of %u parameters\n",
               res->n, res->n_candidates, res->n_ident, res->n_params);
        printf("  observability O1 (rch_ident): planned %.5g (rank %u), random %.5g (rank %u), ratio %.2f\n",
               res->o1_plan, res->rank_plan, res->o1_random, res->rank_random,
               res->o1_random > 0 ? res->o1_plan / res->o1_random : 0.0);
        return;
    }
    printf("rcal poses: %zu poses from %zu candidates, %u outlet(s)%s: %zu rows; %u free parameters (the prior's "
           "information included; theta1, d1 held)\n",
           res->n_distinct, res->n_candidates, res->n_outlets,
           res->n_outlets < 2 ? "" : pc->split ? ", each pose from one outlet (--split)" : ", every pose from each",
           res->n, res->n_ident);
    char pts[400] = ""; /* on a plate: each point's run, with the points the follow check predicts from */
    size_t pp = 0;
    for (unsigned j = 0; j < pc->n_points && pp < sizeof pts; ++j)
        pp += (size_t)snprintf(pts + pp, sizeof pts - pp, " --cable-point %g,%g,%g", pc->points_mm[j][0],
                               pc->points_mm[j][1], pc->points_mm[j][2]);
    for (unsigned k = 0; k < res->n_outlets; ++k) {
        char opt[32] = "";
        if (res->n_outlets > 1)
            snprintf(opt, sizeof opt, " --outlet %u", k);
        printf("  outlet %u at (%.1f, %.1f, %.1f) mm: %zu rows; record them with: rcal acquire --poses %s%s "
               "--encoder %g,%g,%g%s%s ...\n",
               k, pc->outlet_mm[k][0], pc->outlet_mm[k][1], pc->outlet_mm[k][2], res->rows_per_outlet[k], out_path,
               opt, pc->outlet_mm[k][0], pc->outlet_mm[k][1], pc->outlet_mm[k][2], pc->n_points ? " --target P" : "",
               pts);
    }
    printf("  predicted 3-D accuracy of the %s after calibration (95 %% position radius over %s random workspace "
           "poses, length noise %g mm):\n",
           pc->has_tool ? "tool point" : "flange", "1000", pc->noise_mm > 0 ? pc->noise_mm : RCH_POSES_NOISE_MM);
    printf("    this plan:         median %.4f mm, 95th percentile %.4f mm\n", res->plan.median_mm,
           res->plan.p95_mm);
    printf("    random, same count: median %.4f mm, 95th percentile %.4f mm\n", res->random.median_mm,
           res->random.p95_mm);
    printf("  observability O1 of the lengths (rch_ident): planned %.5g, random %.5g, ratio %.2f\n", res->o1_plan,
           res->o1_random, res->o1_random > 0 ? res->o1_plan / res->o1_random : 0.0);
    if (pc->n_points > 0)
        print_point_gains(res);
    if (res->n < res->rows_advised)
        printf("  WARNING: %zu rows for about %zu parameters calibrate fits: it estimates the noise from the "
               "residuals and needs at least %zu rows, else the fit follows the noise and the predicted accuracy is "
               "not reached; next: raise --count%s\n",
               res->n, res->rows_advised - RCH_POSES_ROWS_SPARE, res->rows_advised,
               pc->split ? " (or measure every pose from each outlet: leave out --split)" : "");
}

/* --controller tcp:[HOST:]PORT of a link program: host (numeric, default 127.0.0.1) and port. 0 or -1. */
static int link_addr(char host[64], unsigned *port, const char *spec)
{
    const char *p = spec && strncmp(spec, "tcp:", 4) == 0 ? spec + 4 : NULL, *c = p ? strrchr(p, ':') : NULL;
    char *end;
    unsigned long v;
    if (!p)
        return -1;
    snprintf(host, 64, "127.0.0.1");
    if (c) {
        if (c == p || (size_t)(c - p) >= 64 || strspn(p, "0123456789.") != (size_t)(c - p))
            return -1;
        snprintf(host, 64, "%.*s", (int)(c - p), p);
        p = c + 1;
    }
    v = strtoul(p, &end, 10);
    if (*p < '0' || *p > '9' || *end || v < 1 || v > 65535)
        return -1;
    *port = (unsigned)v;
    return 0;
}

/* The plan into f: CSV (an outlet column with several outlets), RAPID, or a link program. 0 or -1. */
static int write_out_prog(FILE *f, const rch_poses_result *res, const rch_poses_config *pc, const char *format,
                          double settle_s, const char *link);

/* The plan as --format asks: the CSV in the model's joints (what `rcal acquire` reads), a robot program in
 * the controller's (the robot file's "controller" member, rch_ctrl.h). 0, or -1. */
static int write_out(FILE *f, const rch_poses_result *res, const rch_poses_config *pc, const char *format,
                     double settle_s, const char *link, const rch_ctrl *ctrl)
{
    if (strcmp(format, "csv") == 0 || ctrl->identity_joints)
        return write_out_prog(f, res, pc, format, settle_s, link);
    rch_poses_result r = *res;
    rc_sample *p = malloc((res->n ? res->n : 1) * sizeof *p);
    if (!p)
        return -1;
    for (size_t i = 0; i < res->n; ++i) {
        p[i] = res->poses[i];
        rch_ctrl_from_model(p[i].q_rad, ctrl, res->poses[i].q_rad);
    }
    r.poses = p;
    const int wr = write_out_prog(f, &r, pc, format, settle_s, link);
    free(p);
    return wr;
}

static int write_out_prog(FILE *f, const rch_poses_result *res, const rch_poses_config *pc, const char *format,
                          double settle_s, const char *link)
{
    if (strcmp(format, "rapid-link") == 0 || strcmp(format, "urscript-link") == 0) {
        char host[64], comment[200];
        unsigned port = 0;
        unsigned char *lab = malloc(2 * (res->n ? res->n : 1)), *pts = lab ? lab + (res->n ? res->n : 1) : NULL;
        if (!lab || link_addr(host, &port, link) != 0) {
            free(lab);
            return -1;
        }
        for (size_t i = 0; i < res->n; ++i) {
            lab[i] = res->poses[i].outlet;
            pts[i] = res->poses[i].target; /* the plan's target column: the plate point each AT reports */
        }
        if (pc->n_points == 0)
            pts = NULL;
        snprintf(comment, sizeof comment, "rcal poses --count %zu --seed %llu: %u outlet(s), %u plate point(s)",
                 res->n_distinct, pc->seed, res->n_outlets, pc->n_points);
        const int wr = format[0] == 'r'
                           ? rch_poses_write_rapid_link(f, res->poses, lab, pts, res->n, host, port, comment)
                           : rch_poses_write_urscript_link(f, res->poses, lab, pts, res->n, host, port, comment);
        free(lab);
        return wr;
    }
    if (strcmp(format, "rapid") != 0)
        return rch_data_write_plan_cols(f, res->poses, res->n, res->n_outlets > 1, pc->n_points > 0);
    unsigned char *lab = malloc(res->n ? res->n : 1);
    char comment[200];
    snprintf(comment, sizeof comment, "rcal poses --count %zu --seed %llu: %u outlet(s)%s", res->n_distinct,
             pc->seed, res->n_outlets, res->n_outlets > 1 ? (pc->split ? ", split" : ", every pose from each") : "");
    for (size_t i = 0; lab && i < res->n; ++i)
        lab[i] = res->poses[i].outlet;
    const int wr = lab ? rch_poses_write_rapid(f, res->poses, lab, res->n, settle_s, comment) : -1;
    free(lab);
    return wr;
}

/* --outlet, --candidate and --choose-outlets together. 0 or -1 (reported). */
static int check_places(unsigned long choose, unsigned n_places, unsigned n_c, int split)
{
    if (split && n_places < 2 && choose < 2) {
        fprintf(stderr, "rcal poses: --split needs at least two --outlet places (or --choose-outlets K >= 2)\n");
        return -1;
    }
    if (choose && (n_places || n_c < choose)) {
        fprintf(stderr, "rcal poses: --choose-outlets %lu needs at least %lu --candidate places and no --outlet\n",
                choose, choose);
        return -1;
    }
    if (!choose && n_c) {
        fprintf(stderr, "rcal poses: --candidate is for --choose-outlets K\n");
        return -1;
    }
    return 0;
}

/* --choose-outlets: the best K of the candidates into pc's outlets. 0 or -1 (reported). */
static int choose_places(rch_poses_choice *ch, rch_poses_config *pc, const rc_model *m, const double (*cand)[3],
                         unsigned n_c, unsigned k, int json)
{
    rch_diag dg;
    if (rch_poses_choose_outlets(ch, m, pc, cand, n_c, k, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", dg.msg);
        return -1;
    }
    pc->n_outlets = k;
    for (unsigned j = 0; j < k; ++j)
        memcpy(pc->outlet_mm[j], cand[ch->combos[ch->best].idx[j]], sizeof pc->outlet_mm[j]);
    if (!json)
        print_choice(ch, cand);
    return 0;
}

/* The options of rcal poses, and the planner's configuration made of them. */
typedef struct poses_args {
    const char *robot_path, *out_path, *criterion, *format, *order;
    unsigned long n, seed, n_cand, passes, choose;
    double max_minutes, settle_s;
    const char *link; /* --controller of a link program */
    const char *sensor; /* --sensor: cable here (touch: cmd_poses_touch.c) */
    double enc[3], tool[3];
    rch_poses_config pc;
    rch_opt_strs outlets, cands, cable_points;
    int json, split;
    double cand[RCH_OPT_MAX_STRS][3]; /* (n_c x 3) the --candidate places */
    unsigned n_places, n_c;
    const rc_model *model; /* the nominal robot (the predictions of fewer cable points) */
    const rch_ctrl *ctrl;  /* the controller's joint conventions (robot file): what a robot program states */
} poses_args;

/* The parsed options into a->pc (has_tool: --tool given). -1, or 2 (reported). */
static int to_config(poses_args *a, int has_tool)
{
    rch_poses_config *pc = &a->pc;
    if (parse_places(pc->outlet_mm, &a->n_places, &a->outlets, "--outlet") != 0 ||
        parse_places(a->cand, &a->n_c, &a->cands, "--candidate") != 0 ||
        check_places(a->choose, a->n_places, a->n_c, a->split) != 0)
        return 2;
    pc->count = a->n;
    pc->candidates = a->n_cand;
    pc->passes = a->passes;
    pc->max_minutes = a->max_minutes;
    pc->seed = a->seed;
    pc->n_outlets = a->n_places;
    pc->split = a->split;
    pc->criterion = strcmp(a->criterion, "length") == 0 ? RCH_POSES_LENGTH : RCH_POSES_POSITION;
    pc->has_tool = has_tool;
    pc->keep_order = strcmp(a->order, "selection") == 0;
    memcpy(pc->tool_mm, a->tool, sizeof a->tool);
    if (a->cable_points.n) { /* the calibrate option's one parser */
        char perr[160];
        if (rch_cable_points_parse(pc->points_mm, &pc->n_points, a->cable_points.v, a->cable_points.n, perr,
                                   sizeof perr) != 0) {
            fprintf(stderr, "rcal poses: %s\n", perr);
            return 2;
        }
        if (a->split || pc->criterion == RCH_POSES_LENGTH || a->choose) {
            fprintf(stderr, "rcal poses: --cable-point plans every pose on each point from every outlet: not with "
                            "--split, --choose-outlets or --criterion length\n");
            return 2;
        }
    }
    if (pc->criterion == RCH_POSES_LENGTH && (a->choose || pc->has_tool)) {
        fprintf(stderr, "rcal poses: --choose-outlets and --tool need --criterion position\n");
        return 2;
    }
    return -1;
}

/* The options into a: -1 when the command should run, else its exit status
 * (0 for --help, 2 for an error, reported). */
static int parse(poses_args *a, int argc, char **argv)
{
    rch_poses_config *pc = &a->pc;
    rch_cmdspec spec;
    unsigned long long seen = 0;
    memset(a, 0, sizeof *a);
    a->robot_path = RCAL_DEFAULT_ROBOT;
    a->criterion = "position";
    a->format = "csv";
    a->order = "travel";
    a->seed = 1;
    a->passes = 4;
    a->max_minutes = 60.0;
    a->enc[0] = 250.0;
    a->enc[1] = -460.0;
    a->enc[2] = 10.0;
    a->settle_s = 5.0;
    a->link = "tcp:127.0.0.1:5150";
    a->sensor = "cable";
    pc->len_min_mm = 250;
    pc->len_max_mm = 800;
    pc->margin_deg = 5;
    pc->noise_mm = RCH_POSES_NOISE_MM;
    pc->clearance_mm = RCH_CELL_CLEARANCE_MM;
    const rch_opt opts[] = {
        {"--count", RCH_OPT_UINT, &a->n, 1, RCH_POSES_MAX_COUNT, "N", "poses to plan", RCH_OPT_REQUIRED, NULL},
        {"--out", RCH_OPT_STR, &a->out_path, 0, 0, "FILE", "the plan (CSV, or RAPID with --format rapid)",
         RCH_OPT_REQUIRED, NULL},
        {"--robot", RCH_OPT_STR, &a->robot_path, 0, 0, "MODEL.json", "nominal model", 0, NULL},
        {"--seed", RCH_OPT_UINT, &a->seed, 0, 4294967295.0, "S", NULL, 0, NULL},
        {"--encoder", RCH_OPT_TRIPLE, a->enc, -1e5, 1e5, "X,Y,Z", "cable outlet (mm) if MODEL has none and no --outlet",
         0, NULL},
        {"--outlet", RCH_OPT_STRS, &a->outlets, 0, 0, "X,Y,Z",
         "an outlet's approximate place (mm, base frame); repeatable: outlets 0, 1, ...", 0, NULL},
        {"--split", RCH_OPT_FLAG, &a->split, 0, 0, NULL, "each pose from one outlet (default: every pose from each)", 0,
         NULL},
        {"--criterion", RCH_OPT_CHOICE, &a->criterion, 0, 0, NULL, "3-D position accuracy, or the lengths' D-optimum",
         0, "position|length"},
        {"--noise-mm", RCH_OPT_DOUBLE, &pc->noise_mm, 1e-6, 100, "MM", "length noise of the predicted accuracy", 0,
         NULL},
        {"--tool", RCH_OPT_TRIPLE, a->tool, -2000.0, 2000.0, "X,Y,Z", "plan for this tool point (flange frame, mm)", 0,
         NULL},
        {"--cable-point", RCH_OPT_STRS, &a->cable_points, 0, 0, "X,Y,Z",
         "a point of a tool plate the cable is hooked on in turn (nominal, flange frame, mm; repeatable, points 0, "
         "1, ...): every pose is planned on each (a target column), and the gain of each further point is printed",
         0, NULL},
        {"--choose-outlets", RCH_OPT_UINT, &a->choose, 1, RC_MAX_OUTLETS, "K",
         "choose the best K of the --candidate places", 0, NULL},
        {"--candidate", RCH_OPT_STRS, &a->cands, 0, 0, "X,Y,Z", "a candidate outlet place (repeatable)", 0, NULL},
        {"--order", RCH_OPT_CHOICE, &a->order, 0, 0, NULL,
         "the rows' order: a tour per outlet from home that shortens the joint travel (a joint over 360 deg on "
         "the branch that shortens it), "
         "or the selection's",
         0, "travel|selection"},
        {"--format", RCH_OPT_CHOICE, &a->format, 0, 0, NULL, "what --out holds (rapid-link, urscript-link: a program speaking docs/controller-link.md to rcal acquire "
         "--controller)", 0, "csv|rapid|rapid-link|urscript-link"},
        {"--controller", RCH_OPT_STR, &a->link, 0, 0, "tcp:[HOST:]PORT",
         "where a link program connects (the PC running rcal acquire --controller; numeric HOST)", 0, NULL},
        {"--settle-s", RCH_OPT_DOUBLE, &a->settle_s, 0, 600, "S", "RAPID: WaitTime at each pose (settle and read)", 0,
         NULL},
        {"--len-min-mm", RCH_OPT_DOUBLE, &pc->len_min_mm, 0, 20000, "A", "shortest cable length", 0, NULL},
        {"--len-max-mm", RCH_OPT_DOUBLE, &pc->len_max_mm, 0, 20000, "B", "longest cable length", 0, NULL},
        {"--candidates", RCH_OPT_UINT, &a->n_cand, 0, RCH_POSES_MAX_CANDIDATES, "M", "0: max(2000, 40 N)", 0, NULL},
        {"--margin-deg", RCH_OPT_DOUBLE, &pc->margin_deg, 0, 360, "D", "kept from every joint limit", 0, NULL},
        {"--clearance-mm", RCH_OPT_DOUBLE, &pc->clearance_mm, 0, 1000, "MM",
         "the cable's least distance from a link, a box or the floor of the robot file's \"links\" and \"cell\"", 0,
         NULL},
        {"--passes", RCH_OPT_UINT, &a->passes, 0, 100, "P", "exchange passes", 0, NULL},
        {"--max-minutes", RCH_OPT_DOUBLE, &a->max_minutes, 0.01, 1e7, "MIN",
         "refuse a plan estimated longer (the estimate is printed before the work when over 10 s)", 0, NULL},
        {"--json", RCH_OPT_FLAG, &a->json, 0, 0, NULL, "what was planned and written, as one JSON object on stdout", 0,
         NULL},
        {"--sensor", RCH_OPT_CHOICE, &a->sensor, 0, 0, NULL, "the sensor planned for (touch: plate touches, --plate)",
         0, "cable|touch"},
    };
    const int st = rch_opt_cmd(&spec, "poses", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, &seen);
    if (st >= 0)
        return st;
    return to_config(a, rch_opt_given(&spec, seen, "--tool"));
}

/* The plan written (to out, then committed) and reported. 0, or 1 (reported). */
static int finish(rch_out *out, const rch_poses_result *res, const poses_args *a, const rch_poses_choice *ch,
                  int argc, char **argv)
{
    rch_diag dg;
    char dbuf[900];
    if (!a->json) {
        print_plan(res, &a->pc, a->out_path);
        print_dropped(res, &a->pc);
    }
    char link_host[64] = "";
    unsigned link_port = 0;
    if ((strcmp(a->format, "rapid-link") == 0 || strcmp(a->format, "urscript-link") == 0) &&
        link_addr(link_host, &link_port, a->link) != 0) {
        rch_out_abort(out);
        fprintf(stderr, "rcal poses: --controller %s: expected tcp:[HOST:]PORT (HOST numeric, PORT 1..65535); nothing "
                        "was written\n", a->link);
        return 1;
    }
    if (write_out(out->f, res, &a->pc, a->format, a->settle_s, a->link, a->ctrl) != 0) {
        const int err = rch_out_errno(out);
        rch_out_abort(out);
        fprintf(stderr, "rcal poses: %s: cannot write --out: %s; nothing was replaced\n", a->out_path, strerror(err));
        return 1;
    }
    if (rch_out_commit(out, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
        return 1;
    }
    if (a->json)
        return report_json(res, &a->pc, ch, (const double(*)[3])a->cand, a->out_path, a->format, argc, argv) != 0;
    printf("  written to %s%s\n", a->out_path, strcmp(a->format, "rapid") == 0            ? " (RAPID module)"
                                                     : strcmp(a->format, "rapid-link") == 0 ? " (RAPID module, rcal-link/1)"
                                                     : strcmp(a->format, "urscript-link") == 0
                                                         ? " (URScript, rcal-link/1)"
                                                         : "");
    return 0;
}

/* The touch sensor's plan (cmd_poses_touch.c): --plate given, or --sensor touch (either spelling). */
static int wants_touch(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--plate") == 0 || strncmp(argv[i], "--plate=", 8) == 0 ||
            strcmp(argv[i], "--sensor=touch") == 0 ||
            (strcmp(argv[i], "--sensor") == 0 && i + 1 < argc && strcmp(argv[i + 1], "touch") == 0))
            return 1;
    return 0;
}

int rcal_cmd_poses(int argc, char **argv)
{
    poses_args a;
    if (wants_touch(argc, argv))
        return rcal_cmd_poses_touch(argc, argv);
    if (argc == 2 && strcmp(argv[1], "--help-bash") == 0) { /* the completion: the touch table once a plate is typed */
        printf("            if [[ \" ${COMP_WORDS[*]} \" == *\" --plate\"* || \" ${COMP_WORDS[*]} \" == *\" --sensor touch \"* ||\n"
               "                  \" ${COMP_WORDS[*]} \" == *\" --sensor=touch \"* ]]; then\n");
        fflush(stdout);
        if (rcal_cmd_poses_touch(argc, argv) != 0)
            return 1;
        printf("            else\n");
        fflush(stdout);
        const int st = parse(&a, argc, argv);
        printf("            fi\n");
        return st;
    }
    rch_poses_config *pc = &a.pc;
    rch_poses_result res;
    rch_poses_choice *ch = NULL;
    rch_robot *robot;
    rch_diag dg;
    rch_out out;
    char dbuf[900];
    const int st = parse(&a, argc, argv);
    if (st >= 0)
        return st;
    robot = calloc(1, sizeof *robot);
    if (!robot || rch_robot_load(robot, a.robot_path, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", robot ? rch_diag_str(&dg, dbuf, sizeof dbuf) : "out of memory");
        free(robot);
        return 1;
    }
    if (!robot->has_encoder)
        memcpy(&robot->model.x[RC_P_ENC], a.enc, sizeof a.enc);
    pc->prior = &robot->prior;
    pc->cell = &robot->cell;
    a.model = &robot->model;
    a.ctrl = &robot->ctrl;
    if (!a.n_places && !a.choose) { /* one outlet: the model's encoder */
        pc->n_outlets = 1;
        memcpy(pc->outlet_mm[0], &robot->model.x[RC_P_ENC], sizeof pc->outlet_mm[0]);
    }
    if (rch_out_open(&out, a.out_path, "--out", &a.robot_path, 1, &dg) != 0) { /* before the work */
        fprintf(stderr, "rcal poses: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
        free(robot);
        return 1;
    }
    int rc = 1;
    if (a.choose && (!(ch = malloc(sizeof *ch)) || choose_places(ch, pc, &robot->model, (const double(*)[3])a.cand,
                                                                 a.n_c, (unsigned)a.choose, a.json) != 0)) {
        if (!ch)
            fprintf(stderr, "rcal poses: out of memory\n");
        rch_out_abort(&out);
    } else if (rch_poses_plan(&res, &robot->model, pc, stderr, &dg) != 0) {
        rch_out_abort(&out);
        fprintf(stderr, "rcal poses: %s\n", dg.msg);
    } else {
        rc = finish(&out, &res, &a, ch, argc, argv);
        rch_poses_free(&res);
    }
    free(ch);
    free(robot);
    return rc;
}
