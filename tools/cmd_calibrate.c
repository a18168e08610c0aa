/* cmd_calibrate.c - rcal calibrate: identify the DH errors and the encoder
 * position from cable lengths, with a held-out before/after report. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_calib.h"
#include "rch_data.h"
#include "rch_ident.h"
#include "rch_robot.h"
#include "rch_sim.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal calibrate --data FILE [--robot MODEL.json] [--method lm|ltlm|lm-paper|ltlm-paper]\n"
            "                      [--test-fraction F] [--seed S] [--max-iter N] [--fix LIST] [--tool-offset]\n"
            "                      [--out MODEL.json]\n"
            "                      [--truth TRUTH.json] [--json]\n"
            "  --data           measurements: CSV with q1..q6 (deg) and L (mm) columns\n"
            "  --robot          nominal robot model (default %s)\n"
            "  --method         lm (default, robust), ltlm (robust + chaotic candidates),\n"
            "                   lm-paper / ltlm-paper (the paper's fixed-damping update, for reproduction)\n"
            "  --test-fraction  share of samples held out for the before/after report (default 0.1)\n"
            "  --seed           split (and LTLM) seed (default 1)\n"
            "  --out            write the calibrated model (rcal-model/1 JSON) for compensation\n"
            "  --tool-offset    also identify where the cable is attached in the flange frame (tx, ty, tz)\n"
            "  --fix            comma-separated parameters held at their nominal values, e.g. a1,theta6\n"
            "                   (names: a1..a6, d1..d6, alpha1..alpha6, theta1..theta6, ex, ey, ez)\n"
            "  --truth          a simulated truth model: report flange-position errors against it over\n"
            "                   2000 random poses in the joint limits, before and after\n"
            "  --json           one JSON object on stdout instead of the report\n",
            RCAL_DEFAULT_ROBOT);
}

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static void json_metrics(FILE *f, const char *name, const rc_metrics *m)
{
    fprintf(f, "\"%s\": {\"n\": %zu, \"rmse_mm\": %.6f, \"mean_abs_mm\": %.6f, \"sd_mm\": %.6f, \"mean_mm\": %.6f, "
               "\"max_mm\": %.6f}",
            name, m->n, m->rmse_mm, m->mean_abs_mm, m->sd_mm, m->mean_mm, m->max_mm);
}

static void print_metrics_row(const char *label, const rc_metrics *m)
{
    printf("  %-38s %8.4f %8.4f %8.4f %8.4f\n", label, m->rmse_mm, m->mean_abs_mm, m->sd_mm, m->max_mm);
}

int rcal_cmd_calibrate(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT, *out_path = NULL, *method_name = "lm";
    const char *truth_path = NULL, *fix_list = NULL;
    double test_fraction = 0.1;
    unsigned long seed = 1, max_iter = 0;
    int json = 0, tool_offset = 0;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--data", &data_path) || rcal_opt_str(argc, argv, &i, "--robot", &robot_path) ||
            rcal_opt_str(argc, argv, &i, "--out", &out_path) || rcal_opt_str(argc, argv, &i, "--truth", &truth_path) ||
            rcal_opt_str(argc, argv, &i, "--fix", &fix_list) || rcal_opt_str(argc, argv, &i, "--method", &method_name) ||
            rcal_opt_double(argc, argv, &i, "--test-fraction", &test_fraction) ||
            rcal_opt_uint(argc, argv, &i, "--seed", &seed) || rcal_opt_uint(argc, argv, &i, "--max-iter", &max_iter))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--tool-offset") == 0) {
            tool_offset = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("calibrate", argv[i]);
    }
    if (!data_path)
        return rcal_opt_missing("calibrate", "--data");
    rc_method method;
    if (rch_method_parse(&method, method_name) != 0) {
        fprintf(stderr, "rcal calibrate: unknown method '%s' (lm, ltlm, lm-paper, ltlm-paper)\n", method_name);
        return 2;
    }
    if (!(test_fraction >= 0.0 && test_fraction < 1.0)) {
        fprintf(stderr, "rcal calibrate: --test-fraction must be in [0, 1)\n");
        return 2;
    }

    rch_robot robot;
    rch_data data;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, robot_path, &d) != 0 || rch_data_load(&data, data_path, 0, &d) != 0) {
        fprintf(stderr, "rcal calibrate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (tool_offset && rc_model_add_effect(&robot.model, RC_EFF_TOOL_OFFSET, 0, 0) != RC_OK) {
        fprintf(stderr, "rcal calibrate: cannot add the tool offset (RC_MAX_PARAMS or RC_MAX_EFFECTS)\n");
        rch_data_free(&data);
        return 1;
    }
    int rc = 1;
    size_t *idx = malloc(data.n * sizeof *idx);
    rc_solve_work *w = malloc(sizeof *w);
    rc_sample *train = NULL, *test = NULL;
    if (!idx || !w)
        goto done;
    rch_split(idx, data.n, seed);
    size_t n_test = (size_t)floor(test_fraction * (double)data.n + 0.5);
    size_t n_train = data.n - n_test;
    if (n_train < RC_N_BASE) {
        fprintf(stderr, "rcal calibrate: %zu training samples; at least %d are needed for 27 parameters\n", n_train,
                RC_N_BASE);
        goto done;
    }
    test = rch_data_pick(data.s, idx, n_test);
    train = rch_data_pick(data.s, idx + n_test, n_train);
    if (!test || !train)
        goto done;

    rc_model before, model;
    if (rch_calib_start(&before, w, &robot, train, n_train, &d) != 0) {
        fprintf(stderr, "rcal calibrate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        goto done;
    }
    model = before;
    uint8_t fixed[RC_MAX_PARAMS];
    memset(fixed, 0, sizeof fixed);
    if (fix_list) {
        char list[1024];
        snprintf(list, sizeof list, "%s", fix_list);
        for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
            unsigned k;
            char name[64];
            for (k = 0; k < model.n_params; ++k)
                if (strcmp(rc_param_name(name, sizeof name, &model, k), tok) == 0)
                    break;
            if (k == model.n_params) {
                fprintf(stderr, "rcal calibrate: --fix: unknown parameter '%s'\n", tok);
                rc = 2;
                goto done;
            }
            fixed[k] = 1;
        }
    }
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = method;
    cfg.fixed = fixed;
    cfg.max_iter = (unsigned)max_iter;
    cfg.seed = seed;
    rc_solve_result res;
    const double t0 = now_ms();
    rc_status st = rc_solve(&model, &res, w, &cfg, train, n_train);
    const double time_ms = now_ms() - t0;
    if (st != RC_OK) {
        fprintf(stderr, "rcal calibrate: solver failed: %s\n", rc_strerror(st));
        goto done;
    }
    int finite = 1;
    for (unsigned k = 0; k < model.n_params; ++k)
        finite &= isfinite(model.x[k]) != 0;

    rc_metrics tb, ta, trb, tra;
    memset(&tb, 0, sizeof tb);
    memset(&ta, 0, sizeof ta);
    const rc_sample *eval_set = n_test ? test : train;
    const size_t n_eval = n_test ? n_test : n_train;
    rc_eval(&tb, &before, eval_set, n_eval);
    int after_ok = finite && rc_eval(&ta, &model, eval_set, n_eval) == RC_OK;
    rc_eval(&trb, &before, train, n_train);
    if (!after_ok || rc_eval(&tra, &model, train, n_train) != RC_OK)
        memset(&tra, 0, sizeof tra);
    /* Against a known truth: flange positions over the workspace, with the
     * base heading and height aligned (cable lengths cannot see them). */
    double tr_before = 0.0, tr_after = 0.0, tr_before_max = 0.0, tr_after_max = 0.0;
    if (truth_path && finite) {
        rch_robot truth;
        if (rch_robot_load(&truth, truth_path, &d) != 0) {
            fprintf(stderr, "rcal calibrate: %s\n", rch_diag_str(&d, msg, sizeof msg));
            goto done;
        }
        rc_sample *ws = malloc(2000 * sizeof *ws);
        rc_rng g;
        rc_rng_seed(&g, 12345);
        if (!ws)
            goto done;
        for (size_t i = 0; i < 2000; ++i) {
            memset(&ws[i], 0, sizeof ws[i]);
            for (unsigned j = 0; j < RC_NJ; ++j)
                ws[i].q_rad[j] = truth.model.q_min_rad[j] +
                                 (truth.model.q_max_rad[j] - truth.model.q_min_rad[j]) * rc_rng_u01(&g);
        }
        rch_sim_flange_diff(&tr_before, &tr_before_max, &before, &truth.model, ws, 2000, 1);
        rch_sim_flange_diff(&tr_after, &tr_after_max, &model, &truth.model, ws, 2000, 1);
        free(ws);
    }
    rch_ident id;
    int have_id = finite && rch_ident_compute(&id, &model, train, n_train) == 0;

    if (json) {
        printf("{\"method\": \"%s\", \"data\": \"%s\", \"n_train\": %zu, \"n_test\": %zu, \"seed\": %lu, ",
               rc_method_name(method), data_path, n_train, n_test, seed);
        json_metrics(stdout, "before", &tb);
        printf(", ");
        json_metrics(stdout, "after", &ta);
        printf(", ");
        json_metrics(stdout, "train_before", &trb);
        printf(", ");
        json_metrics(stdout, "train_after", &tra);
        printf(", \"held_out\": %s, \"converged\": %s, \"exit\": \"%s\", \"iterations\": %u, \"cost_evals\": %u, "
               "\"time_ms\": %.3f, ",
               n_test ? "true" : "false", after_ok ? "true" : "false", rc_exit_str(res.exit), res.iterations,
               res.cost_evals, time_ms);
        printf("\"params\": [");
        for (unsigned k = 0; k < model.n_params; ++k) {
            char name[64];
            const int unit = rc_param_unit(&model, k);
            const double scale = unit == 1 ? 1.0 / DEG : 1.0;
            const double nominal = k < RC_N_DH ? robot.model.x[k] : (k < RC_N_BASE ? before.x[k] : 0.0);
            printf("%s{\"name\": \"%s\", \"unit\": \"%s\", \"value\": %.9g, \"delta\": %.9g}", k ? ", " : "",
                   rc_param_name(name, sizeof name, &model, k), unit == 0 ? "mm" : unit == 1 ? "deg" : "-",
                   finite ? model.x[k] * scale : 0.0, finite ? (model.x[k] - nominal) * scale : 0.0);
        }
        printf("], \"encoder_mm\": [%.6f, %.6f, %.6f]", model.x[RC_P_ENC], model.x[RC_P_ENC + 1],
               model.x[RC_P_ENC + 2]);
        if (truth_path)
            printf(", \"truth_flange\": {\"before_rms_mm\": %.6f, \"before_max_mm\": %.6f, \"after_rms_mm\": %.6f, "
                   "\"after_max_mm\": %.6f}",
                   tr_before, tr_before_max, tr_after, tr_after_max);
        if (have_id) {
            printf(", \"identifiability\": {\"params\": %u, \"rank\": %u, \"weak\": %u, \"cond\": %.6g, "
                   "\"observability\": %.6g, \"directions\": [",
                   id.n_params, id.rank, id.n_weak, id.cond, id.observability);
            for (unsigned k = 0; k < id.n_dirs; ++k)
                printf("%s{\"sv_rel\": %.3g, \"identifiable\": \"%s\", \"combo\": \"%s\"}", k ? ", " : "",
                       id.dirs[k].sv_rel, id.dirs[k].weak ? "weakly" : "no", id.dirs[k].combo);
            printf("]}");
        }
        printf("}\n");
    } else {
        printf("rcal calibrate: %s (%zu samples), robot \"%s\", method %s\n", data_path, data.n, robot.name,
               rc_method_name(method));
        printf("split: %zu train / %zu held out (test fraction %.2f, seed %lu)\n\n", n_train, n_test, test_fraction,
               seed);
        printf("%s error (%zu samples, mm)          RMSE  mean|e|       SD      MAX\n",
               n_test ? "held-out" : "training", n_eval);
        print_metrics_row("before (nominal DH, fitted encoder)", &tb);
        if (after_ok)
            print_metrics_row("after", &ta);
        else
            printf("  after: the solver diverged (non-finite model or cable length): no figures\n");
        printf("  (mean|e| is what the paper's Eq. 20 calls SD; SD here is the true standard deviation)\n");
        printf("training RMSE: before %.4f mm, after %.4f mm\n\n", trb.rmse_mm, tra.rmse_mm);
        if (truth_path)
            printf("flange position against the truth (2000 random poses, base heading/height aligned):\n"
                   "  before RMS %.4f mm, max %.4f mm;  after RMS %.4f mm, max %.4f mm\n\n",
                   tr_before, tr_before_max, tr_after, tr_after_max);
        printf("identified model (the paper's Table 7 form; deltas against nominal):\n");
        printf("  joint     a (mm)     d (mm)   alpha (deg)  theta (deg) |   da (mm)    dd (mm)  dalpha(deg)  "
               "dtheta(deg)\n");
        for (unsigned j = 0; j < RC_NJ; ++j) {
            const double *x = &model.x[4 * j], *x0 = &robot.model.x[4 * j];
            printf("  %5u %10.4f %10.4f %12.5f %12.5f | %9.4f %10.4f %12.5f %12.5f\n", j + 1, x[0], x[1], x[2] / DEG,
                   x[3] / DEG, x[0] - x0[0], x[1] - x0[1], (x[2] - x0[2]) / DEG, (x[3] - x0[3]) / DEG);
        }
        printf("  encoder e = (%.4f, %.4f, %.4f) mm  (before calibration: %.4f, %.4f, %.4f)\n\n", model.x[RC_P_ENC],
               model.x[RC_P_ENC + 1], model.x[RC_P_ENC + 2], before.x[RC_P_ENC], before.x[RC_P_ENC + 1],
               before.x[RC_P_ENC + 2]);
        if (have_id) {
            printf("identifiability (%u parameters, at the solution): rank %u, %u not identifiable, %u weakly "
                   "identifiable;\n  condition number %.3g over the identifiable part, observability index O1 %.4g\n",
                   id.n_params, id.rank, id.n_params - id.rank, id.n_weak, id.cond, id.observability);
            for (unsigned k = 0; k < id.n_dirs; ++k) {
                printf("  - %s (relative singular value %.1e): %s\n", id.dirs[k].weak ? "weak" : "NOT identifiable",
                       id.dirs[k].sv_rel, id.dirs[k].combo);
                if (id.dirs[k].why[0])
                    printf("      %s\n", id.dirs[k].why);
            }
            printf("  The solver leaves directions it cannot identify where they started (nominal).\n\n");
        }
        printf("solver: %s, %u iterations, %u passes over the data, exit: %s, %.2f ms\n", rc_method_name(method),
               res.iterations, res.cost_evals, rc_exit_str(res.exit), time_ms);
    }
    if (out_path) {
        FILE *f = fopen(out_path, "w");
        char cal[512];
        snprintf(cal, sizeof cal,
                 "{\"method\": \"%s\", \"data\": \"%s\", \"n_train\": %zu, \"n_test\": %zu, \"seed\": %lu, "
                 "\"rmse_before_mm\": %.6f, \"rmse_after_mm\": %.6f}",
                 rc_method_name(method), data_path, n_train, n_test, seed, tb.rmse_mm, ta.rmse_mm);
        if (!finite) {
            fprintf(stderr, "rcal calibrate: not writing %s: the model is not finite\n", out_path);
        } else if (!f || rch_robot_write(f, robot.name, &model, &robot.nominal, cal) != 0) {
            fprintf(stderr, "rcal calibrate: cannot write %s\n", out_path);
            if (f)
                fclose(f);
            goto done;
        } else {
            fclose(f);
            if (!json)
                printf("calibrated model written to %s\n", out_path);
        }
    }
    rc = after_ok ? 0 : 1;
done:
    free(idx);
    free(w);
    free(train);
    free(test);
    rch_data_free(&data);
    return rc;
}
