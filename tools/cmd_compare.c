/* cmd_compare.c - rcal compare: the LTLM paper's comparison of seven
 * identification methods (its Table 6, Fig. 6d, Figs. 7-8) on your data.
 *
 * Protocol, per case c = 0..cases-1: draw `samples` rows at random (seed
 * derived from --seed and c), hold out round(test_fraction * samples) of
 * them, build the start (BC) model from the training part only
 * (rch_calib_start: nominal DH + encoder fitted alone), run every method from
 * that same start on the same training samples, evaluate on the held-out
 * samples. Nothing is tuned on held-out samples: every hyperparameter is a
 * fixed default documented in rc_est.h / rc_solve.h.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_calib.h"
#include "rch_data.h"
#include "rch_est.h"
#include "rch_plot.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal compare --data FILE [--robot MODEL.json] [--cases 10] [--samples 300]\n"
            "                    [--test-fraction 0.1] [--seed S] [--methods LIST] [--plots DIR] [--json]\n"
            "  The LTLM paper's protocol: in each case draw --samples rows at random, hold out\n"
            "  --test-fraction of them, fit every method from the same start on the rest, and\n"
            "  report held-out errors (mean +- std over --cases cases) and times.\n"
            "  --samples 0 uses every row. The paper's other protocol: --samples 200 --test-fraction 0.2.\n"
            "  --methods  comma list of LM,EKF,PF,SCA,QIBAS,SSLM,LTLM (or M1..M7); default all\n"
            "  --plots    directory for SVG charts: convergence, bars, times, per-sample errors\n"
            "  --json     one JSON object on stdout instead of the report\n"
            "  --robot    nominal robot model (default %s)\n",
            RCAL_DEFAULT_ROBOT);
}

/* Running mean / variance (Welford). */
typedef struct stat1 {
    double n, mean, m2;
} stat1;

static void st_add(stat1 *s, double v)
{
    double d;
    s->n += 1.0;
    d = v - s->mean;
    s->mean += d / s->n;
    s->m2 += d * (v - s->mean);
}

static double st_sd(const stat1 *s) { return s->n > 1.0 ? sqrt(s->m2 / (s->n - 1.0)) : 0.0; }

/* Row 0 = BC, rows 1..7 = methods M1..M7 (rch_est_id + 1). */
enum { NROW = RCH_EST_COUNT + 1 };

typedef struct row_stats {
    stat1 rmse, mean_abs, max, time, train, iters, evals;
    int used;
    int failed; /* a case where the method failed or diverged */
} row_stats;

static const char *row_name(int r) { return r == 0 ? "BC" : rch_est_name((rch_est_id)(r - 1)); }

static int parse_methods(int *sel, const char *list)
{
    char buf[256];
    char *tok, *save = NULL;
    if (strlen(list) >= sizeof buf)
        return -1;
    strcpy(buf, list);
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        sel[i] = 0;
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int id = rch_est_parse(tok);
        if (id < 0) {
            fprintf(stderr, "rcal compare: unknown method '%s' (LM, EKF, PF, SCA, QIBAS, SSLM, LTLM)\n", tok);
            return -1;
        }
        sel[id] = 1;
    }
    return 0;
}

/* mkdir -p */
static int ensure_dir(const char *dir)
{
    char buf[4096];
    struct stat sb;
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof buf) {
        errno = ENAMETOOLONG;
        return -1;
    }
    memcpy(buf, dir, n + 1);
    for (size_t i = 1; i <= n; ++i) {
        if (buf[i] != '/' && buf[i] != '\0')
            continue;
        const char c = buf[i];
        buf[i] = '\0';
        if (stat(buf, &sb) != 0) {
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
        } else if (!S_ISDIR(sb.st_mode)) {
            errno = ENOTDIR;
            return -1;
        }
        buf[i] = c;
    }
    return 0;
}

static void path_join(char *out, size_t len, const char *dir, const char *name)
{
    snprintf(out, len, "%s/%s", dir, name);
}

static int write_plot(rch_plot *p, const char *dir, const char *name, int json)
{
    char path[4096];
    path_join(path, sizeof path, dir, name);
    if (!p || rch_plot_write_svg(p, path) != 0) {
        fprintf(stderr, "rcal compare: cannot write %s: %s\n", path, strerror(errno));
        rch_plot_free(p);
        return -1;
    }
    if (!json)
        printf("  wrote %s\n", path);
    rch_plot_free(p);
    return 0;
}

int rcal_cmd_compare(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT, *plots = NULL;
    const char *methods = NULL;
    double test_fraction = 0.1;
    unsigned long cases = 10, samples = 300, seed = 1;
    int json = 0, sel[RCH_EST_COUNT];
    for (int i = 0; i < RCH_EST_COUNT; ++i)
        sel[i] = 1;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--data", &data_path) ||
            rcal_opt_str(argc, argv, &i, "--robot", &robot_path) ||
            rcal_opt_str(argc, argv, &i, "--plots", &plots) ||
            rcal_opt_str(argc, argv, &i, "--methods", &methods) ||
            rcal_opt_double(argc, argv, &i, "--test-fraction", &test_fraction) ||
            rcal_opt_uint(argc, argv, &i, "--cases", &cases) ||
            rcal_opt_uint(argc, argv, &i, "--samples", &samples) ||
            rcal_opt_uint(argc, argv, &i, "--seed", &seed))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("compare", argv[i]);
    }
    if (!data_path)
        return rcal_opt_missing("compare", "--data");
    if (methods && parse_methods(sel, methods) != 0)
        return 2;
    if (!(test_fraction > 0.0 && test_fraction < 1.0)) {
        fprintf(stderr, "rcal compare: --test-fraction must be in (0, 1)\n");
        return 2;
    }
    if (cases < 1 || cases > 10000) {
        fprintf(stderr, "rcal compare: --cases must be within 1..10000\n");
        return 2;
    }
    if (plots && ensure_dir(plots) != 0) {
        fprintf(stderr, "rcal compare: cannot use %s as a plot directory: %s\n", plots, strerror(errno));
        return 1;
    }

    rch_robot robot;
    rch_data data;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, robot_path, &d) != 0 || rch_data_load(&data, data_path, 0, &d) != 0) {
        fprintf(stderr, "rcal compare: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (samples == 0)
        samples = data.n;
    if (samples > data.n) {
        fprintf(stderr, "rcal compare: --samples %lu but %s has %zu rows\n", samples, data_path, data.n);
        rch_data_free(&data);
        return 2;
    }
    const size_t n_draw = (size_t)samples;
    size_t n_test = (size_t)floor(test_fraction * (double)n_draw + 0.5);
    if (n_test < 1)
        n_test = 1;
    const size_t n_train = n_draw - n_test;
    if (n_train < RC_N_BASE) {
        fprintf(stderr, "rcal compare: %zu training samples per case; at least %d are needed\n", n_train,
                RC_N_BASE);
        rch_data_free(&data);
        return 2;
    }

    int rc = 1;
    size_t *idx = malloc(data.n * sizeof *idx);
    rch_est_ws *ws = rch_est_ws_new();
    row_stats *rows = calloc(NROW, sizeof *rows);
    double *case_rmse = calloc((size_t)cases * NROW, sizeof(double)); /* (cases x NROW) */
    double(*ltlm_x)[RC_MAX_PARAMS] = calloc((size_t)cases, sizeof *ltlm_x);
    rch_curve curves[RCH_EST_COUNT];
    double *err_case0 = NULL; /* (NROW x n_test) per-sample held-out errors of case 0 */
    rc_model start0;
    memset(curves, 0, sizeof curves);
    memset(&start0, 0, sizeof start0);
    if (!idx || !ws || !rows || !case_rmse || !ltlm_x ||
        !(err_case0 = calloc(NROW * n_test, sizeof(double)))) {
        fprintf(stderr, "rcal compare: out of memory\n");
        goto done;
    }
    unsigned n_ltlm = 0;
    for (unsigned long c = 0; c < cases; ++c) {
        const unsigned long long cseed = (unsigned long long)seed * 1000003ull + c;
        rc_sample *train = NULL, *test = NULL;
        rc_model start;
        rc_metrics mt;
        rch_split(idx, data.n, cseed);
        /* the case's draw is idx[0 .. n_draw-1]: its first n_test are held out */
        test = rch_data_pick(data.s, idx, n_test);
        train = rch_data_pick(data.s, idx + n_test, n_train);
        if (!test || !train) {
            free(test);
            free(train);
            fprintf(stderr, "rcal compare: out of memory\n");
            goto done;
        }
        if (rch_calib_start(&start, &ws->solve, &robot, train, n_train, &d) != 0 ||
            rc_eval(&mt, &start, test, n_test) != RC_OK) {
            fprintf(stderr, "rcal compare: case %lu: %s\n", c + 1, rch_diag_str(&d, msg, sizeof msg));
            free(test);
            free(train);
            goto done;
        }
        if (c == 0)
            start0 = start;
        rows[0].used = 1;
        st_add(&rows[0].rmse, mt.rmse_mm);
        st_add(&rows[0].mean_abs, mt.mean_abs_mm);
        st_add(&rows[0].max, mt.max_mm);
        {
            rc_metrics trm;
            if (rc_eval(&trm, &start, train, n_train) == RC_OK)
                st_add(&rows[0].train, trm.rmse_mm);
        }
        case_rmse[c * NROW] = mt.rmse_mm;
        if (c == 0)
            for (size_t k = 0; k < n_test; ++k) {
                double l;
                err_case0[k] = rc_meas(&l, NULL, &start, &test[k]) == RC_OK ? l - test[k].len_mm : NAN;
            }
        for (int id = 0; id < RCH_EST_COUNT; ++id) {
            row_stats *r = &rows[id + 1];
            rc_model m = start;
            rch_est_out out;
            rc_metrics me;
            if (!sel[id])
                continue;
            r->used = 1;
            rc_status st = rch_est_run(&m, &out, c == 0 && plots ? &curves[id] : NULL, ws,
                                       (rch_est_id)id, cseed, NULL, train, n_train);
            if (st != RC_OK || rc_eval(&me, &m, test, n_test) != RC_OK) {
                if (!json)
                    fprintf(stderr, "rcal compare: case %lu: %s failed: %s\n", c + 1,
                            rch_est_name((rch_est_id)id), rc_strerror(st));
                r->failed++;
                case_rmse[c * NROW + (size_t)id + 1] = NAN;
                continue;
            }
            st_add(&r->rmse, me.rmse_mm);
            st_add(&r->mean_abs, me.mean_abs_mm);
            st_add(&r->max, me.max_mm);
            st_add(&r->time, out.time_ms);
            st_add(&r->train, out.rms_final_mm);
            st_add(&r->iters, (double)out.iterations);
            st_add(&r->evals, (double)out.cost_evals);
            case_rmse[c * NROW + (size_t)id + 1] = me.rmse_mm;
            if (id == RCH_EST_LTLM)
                memcpy(ltlm_x[n_ltlm++], m.x, sizeof m.x);
            if (c == 0)
                for (size_t k = 0; k < n_test; ++k) {
                    double l;
                    err_case0[(size_t)(id + 1) * n_test + k] =
                        rc_meas(&l, NULL, &m, &test[k]) == RC_OK ? l - test[k].len_mm : NAN;
                }
        }
        free(test);
        free(train);
        if (!json)
            fprintf(stderr, "case %lu/%lu done\n", c + 1, cases);
    }

    const double lm_time = rows[RCH_EST_LM + 1].used && rows[RCH_EST_LM + 1].time.n > 0
                               ? rows[RCH_EST_LM + 1].time.mean
                               : NAN;
    if (json) {
        printf("{\"command\": \"compare\", \"data\": \"");
        for (const char *s = data_path; *s; ++s)
            printf(*s == '"' || *s == '\\' ? "\\%c" : "%c", *s);
        printf("\", \"rows_in_file\": %zu, \"cases\": %lu, \"samples\": %zu, \"n_train\": %zu, \"n_test\": %zu, "
               "\"test_fraction\": %.6g, \"seed\": %lu,\n \"methods\": [",
               data.n, cases, n_draw, n_train, n_test, test_fraction, seed);
        int first = 1;
        for (int r = 0; r < NROW; ++r) {
            const row_stats *s = &rows[r];
            if (!s->used)
                continue;
            printf("%s\n  {\"name\": \"%s\", \"cases_ok\": %.0f, \"rmse_mm\": %.6f, \"rmse_std_mm\": %.6f, "
                   "\"mean_abs_mm\": %.6f, \"mean_abs_std_mm\": %.6f, \"max_mm\": %.6f, \"max_std_mm\": %.6f, "
                   "\"train_rmse_mm\": %.6f",
                   first ? "" : ",", row_name(r), s->rmse.n, s->rmse.mean, st_sd(&s->rmse), s->mean_abs.mean,
                   st_sd(&s->mean_abs), s->max.mean, st_sd(&s->max), s->train.mean);
            if (r == 0)
                printf(", \"time_ms\": 0}");
            else
                printf(", \"time_ms\": %.4f, \"time_std_ms\": %.4f, \"time_ratio_lm\": %.4g, \"iterations\": %.1f, "
                       "\"cost_evals\": %.0f}",
                       s->time.mean, st_sd(&s->time), isfinite(lm_time) && lm_time > 0 ? s->time.mean / lm_time : 0.0,
                       s->iters.mean, s->evals.mean);
            first = 0;
        }
        printf("\n ],\n \"cases_rmse_mm\": [");
        for (unsigned long c = 0; c < cases; ++c) {
            printf("%s[", c ? ", " : "");
            int f2 = 1;
            for (int r = 0; r < NROW; ++r)
                if (rows[r].used) {
                    const double v = case_rmse[c * NROW + (size_t)r];
                    if (isfinite(v))
                        printf("%s%.6f", f2 ? "" : ", ", v);
                    else
                        printf("%snull", f2 ? "" : ", ");
                    f2 = 0;
                }
            printf("]");
        }
        printf("]");
        if (n_ltlm > 0) {
            printf(",\n \"ltlm_parameters\": {\"cases\": %u, \"joints\": [", n_ltlm);
            for (unsigned j = 0; j < RC_NJ; ++j) {
                stat1 s[4];
                memset(s, 0, sizeof s);
                for (unsigned c = 0; c < n_ltlm; ++c)
                    for (unsigned k = 0; k < 4; ++k)
                        st_add(&s[k], ltlm_x[c][4 * j + k] / (k >= 2 ? DEG : 1.0));
                printf("%s{\"joint\": %u, \"a_mm\": %.5f, \"d_mm\": %.5f, \"alpha_deg\": %.6f, \"theta_deg\": %.6f, "
                       "\"a_std_mm\": %.5f, \"d_std_mm\": %.5f, \"alpha_std_deg\": %.6f, \"theta_std_deg\": %.6f}",
                       j ? ", " : "", j + 1, s[0].mean, s[1].mean, s[2].mean, s[3].mean, st_sd(&s[0]), st_sd(&s[1]),
                       st_sd(&s[2]), st_sd(&s[3]));
            }
            {
                stat1 e[3];
                memset(e, 0, sizeof e);
                for (unsigned c = 0; c < n_ltlm; ++c)
                    for (unsigned k = 0; k < 3; ++k)
                        st_add(&e[k], ltlm_x[c][RC_P_ENC + k]);
                printf("], \"encoder_mm\": [%.4f, %.4f, %.4f]}", e[0].mean, e[1].mean, e[2].mean);
            }
        }
        printf("\n}\n");
    } else {
        printf("rcal compare: %s, %zu rows; %lu cases of %zu random rows (%zu train / %zu held out), seed %lu\n",
               data_path, data.n, cases, n_draw, n_train, n_test, seed);
        printf("Held-out errors, mean +- std over cases (mm); time of the identification alone (ms, one core)\n");
        printf("  %-6s %-17s %-17s %-17s %-19s %8s %10s %9s\n", "method", "RMSE", "mean|e| (\"SD\")", "MAX",
               "time (ms)", "x LM", "train RMS", "iters");
        for (int r = 0; r < NROW; ++r) {
            const row_stats *s = &rows[r];
            char tbuf[64], rbuf[32];
            if (!s->used)
                continue;
            if (r == 0) {
                snprintf(tbuf, sizeof tbuf, "%s", "-");
                snprintf(rbuf, sizeof rbuf, "%s", "-");
            } else {
                snprintf(tbuf, sizeof tbuf, "%8.2f +- %-7.2f", s->time.mean, st_sd(&s->time));
                if (isfinite(lm_time) && lm_time > 0)
                    snprintf(rbuf, sizeof rbuf, "%.2f", s->time.mean / lm_time);
                else
                    snprintf(rbuf, sizeof rbuf, "-");
            }
            printf("  %-6s %6.4f +- %-7.4f %6.4f +- %-7.4f %6.4f +- %-7.4f %-19s %8s %10.4f %9.0f%s\n",
                   r == 0 ? "BC" : row_name(r), s->rmse.mean, st_sd(&s->rmse), s->mean_abs.mean,
                   st_sd(&s->mean_abs), s->max.mean, st_sd(&s->max), tbuf, rbuf, s->train.mean,
                   r == 0 ? 0.0 : s->iters.mean, s->failed ? "  (failed in some cases)" : "");
        }
        printf("  (BC: nominal DH with the encoder fitted alone; mean|e| is what the paper's Eq. 20 calls SD)\n");
        if (n_ltlm > 0) {
            printf("\nLTLM identified parameters, the paper's Table 7 form (mean +- std over %u cases):\n", n_ltlm);
            printf("  joint           a (mm)               d (mm)            alpha (deg)            theta (deg)\n");
            for (unsigned j = 0; j < RC_NJ; ++j) {
                stat1 s[4];
                memset(s, 0, sizeof s);
                for (unsigned c = 0; c < n_ltlm; ++c)
                    for (unsigned k = 0; k < 4; ++k)
                        st_add(&s[k], ltlm_x[c][4 * j + k] / (k >= 2 ? DEG : 1.0));
                printf("  %5u %9.4f +- %-7.4f %9.4f +- %-7.4f %10.5f +- %-8.5f %10.5f +- %-8.5f\n", j + 1, s[0].mean,
                       st_sd(&s[0]), s[1].mean, st_sd(&s[1]), s[2].mean, st_sd(&s[2]), s[3].mean, st_sd(&s[3]));
            }
            stat1 e[3];
            memset(e, 0, sizeof e);
            for (unsigned c = 0; c < n_ltlm; ++c)
                for (unsigned k = 0; k < 3; ++k)
                    st_add(&e[k], ltlm_x[c][RC_P_ENC + k]);
            printf("  encoder e = (%.3f, %.3f, %.3f) mm  (+- %.3f, %.3f, %.3f)\n", e[0].mean, e[1].mean, e[2].mean,
                   st_sd(&e[0]), st_sd(&e[1]), st_sd(&e[2]));
            printf("  Parameters the data cannot separate (e.g. d1 against e_z, theta1 against a rotation of e)\n"
                   "  stay at their start values; their spread over cases shows how weakly the rest is determined.\n");
        }
    }

    if (plots) {
        static const char *const labels_all[NROW] = {"BC", "LM", "EKF", "PF", "SCA", "QIBAS", "SSLM", "LTLM"};
        const char *labels[NROW];
        double vals[NROW], errs[NROW], tv[NROW], te[NROW];
        size_t nb = 0, nt = 0;
        const char *tlabels[NROW];
        int ok = 0;
        if (!json)
            printf("\nplots:\n");
        /* convergence: every method, case 1 */
        for (int zoom = 0; zoom < 2; ++zoom) {
            rch_plot *p = rch_plot_new(zoom ? "Convergence, first 60 iterations (case 1)"
                                            : "Convergence: training RMS per iteration (case 1)",
                                       "iteration", "training RMS (mm)");
            for (int id = 0; id < RCH_EST_COUNT; ++id) {
                double *x;
                if (!sel[id] || curves[id].n == 0)
                    continue;
                x = malloc(curves[id].n * sizeof *x);
                if (!x)
                    continue;
                for (size_t k = 0; k < curves[id].n; ++k)
                    x[k] = (double)k;
                rch_plot_line(p, rch_est_name((rch_est_id)id), x, curves[id].rms_mm, curves[id].n);
                free(x);
            }
            rch_plot_logy(p, 1);
            if (zoom)
                rch_plot_xrange(p, 0.0, 60.0);
            ok |= write_plot(p, plots, zoom ? "convergence_zoom.svg" : "convergence.svg", json);
        }
        for (int r = 0; r < NROW; ++r) {
            if (!rows[r].used || rows[r].rmse.n == 0)
                continue;
            labels[nb] = labels_all[r];
            vals[nb] = rows[r].rmse.mean;
            errs[nb] = st_sd(&rows[r].rmse);
            ++nb;
            if (r > 0) {
                tlabels[nt] = labels_all[r];
                tv[nt] = rows[r].time.mean;
                te[nt] = st_sd(&rows[r].time);
                ++nt;
            }
        }
        {
            char title[160];
            snprintf(title, sizeof title, "Held-out RMSE, mean +- std over %lu cases (%zu train / %zu test)",
                     cases, n_train, n_test);
            rch_plot *p = rch_plot_new(title, "method", "RMSE (mm)");
            rch_plot_bars(p, labels, vals, errs, nb);
            ok |= write_plot(p, plots, "rmse_bars.svg", json);
        }
        {
            rch_plot *p = rch_plot_new("Identification time per case, mean +- std", "method", "time (ms)");
            rch_plot_bars(p, tlabels, tv, te, nt);
            rch_plot_logy(p, 1);
            ok |= write_plot(p, plots, "time_bars.svg", json);
        }
        {
            rch_plot *p = rch_plot_new("Held-out error of each sample, case 1 (Fig. 7 kind)",
                                       "held-out sample", "model - measured length (mm)");
            double *x = malloc(n_test * sizeof *x);
            if (x) {
                for (size_t k = 0; k < n_test; ++k)
                    x[k] = (double)(k + 1);
                rch_plot_line(p, "before (BC)", x, err_case0, n_test);
                if (sel[RCH_EST_LM])
                    rch_plot_line(p, "after LM", x, err_case0 + (size_t)(RCH_EST_LM + 1) * n_test, n_test);
                if (sel[RCH_EST_LTLM])
                    rch_plot_line(p, "after LTLM", x, err_case0 + (size_t)(RCH_EST_LTLM + 1) * n_test, n_test);
                free(x);
            }
            ok |= write_plot(p, plots, "per_sample.svg", json);
        }
        if (ok != 0)
            goto done;
    }
    rc = 0;
    for (int r = 1; r < NROW; ++r)
        if (rows[r].used && rows[r].failed)
            rc = 1;
done:
    for (int id = 0; id < RCH_EST_COUNT; ++id)
        rch_curve_free(&curves[id]);
    free(err_case0);
    free(ltlm_x);
    free(case_rmse);
    free(rows);
    rch_est_ws_free(ws);
    free(idx);
    rch_data_free(&data);
    (void)start0;
    return rc;
}
