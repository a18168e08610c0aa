/* SPDX-License-Identifier: MIT */
/* rch_chaos.c - the logistic-tent map uniformity study; see rch_chaos.h. */
#include "rch_chaos.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_est.h"
#include "rch_jw.h"
#include "rch_plot.h"

void rch_chaos_defaults(rch_chaos_config *cfg)
{
    const rch_chaos_config def = {.points = 1000, .bins = 50, .starts = 100, .seed = 1, .step = 0.01, .r_hist = NAN};
    *cfg = def;
}

static size_t n_r(double step) { return (size_t)floor(4.0 / step + 1e-9) + 1; }

double rch_chaos_cost(const rch_chaos_config *cfg)
{
    if (!(cfg->step >= 1e-4 && cfg->step <= 4.0))
        return HUGE_VAL;
    return ((double)n_r(cfg->step) + 1.0) * (double)cfg->starts * (double)cfg->points;
}

int rch_chaos_check(const rch_chaos_config *cfg, rch_diag *d)
{
    if (cfg->points < 1 || cfg->bins < 2 || cfg->bins > 1024 || cfg->starts < 1 || cfg->points > 0xffffffffu ||
        cfg->starts > 0xffffffffu || !(cfg->step >= 1e-4 && cfg->step <= 4.0) ||
        (!isnan(cfg->r_hist) && !(cfg->r_hist >= 0.0 && cfg->r_hist <= 4.0))) {
        rch_diag_set(d, "", 0, 0, "need points >= 1, 2 <= bins <= 1024, starts >= 1, 1e-4 <= step <= 4, "
                                  "0 <= r <= 4");
        return -1;
    }
    const double cost = rch_chaos_cost(cfg);
    if (cost > RCH_CHAOS_MAX_ITERATES) {
        rch_diag_set(d, "", 0, 0,
                     "%lu points x %lu starts x %zu r values = %.3g map iterations, above the limit of %.0e "
                     "(about 8 s); lower --points, --starts or raise --step",
                     cfg->points, cfg->starts, n_r(cfg->step) + 1, cost, RCH_CHAOS_MAX_ITERATES);
        return -1;
    }
    return 0;
}

void rch_chaos_free(rch_chaos_result *res)
{
    free(res->r);
    free(res->sd);
    free(res->se);
    free(res->hist);
    res->r = res->sd = res->se = NULL;
    res->hist = NULL;
}

/* The histogram at r_hist, summed over the same initial values as the curve. */
static int histogram(rch_chaos_result *res, const rch_chaos_config *cfg)
{
    unsigned *one = malloc(cfg->bins * sizeof *one);
    rc_rng g;
    if (!one)
        return -1;
    memset(res->hist, 0, cfg->bins * sizeof *res->hist);
    rc_rng_seed(&g, cfg->seed);
    for (unsigned long s = 0; s < cfg->starts; ++s) {
        rch_chaos_sd(one, res->r_hist, 0.01 + 0.98 * rc_rng_u01(&g), (unsigned)cfg->points, (unsigned)cfg->bins);
        for (unsigned long b = 0; b < cfg->bins; ++b)
            res->hist[b] += one[b];
    }
    free(one);
    return 0;
}

/* r values statistically indistinguishable from independent uniform draws. */
static void band(rch_chaos_result *res)
{
    res->band_lo = res->band_hi = res->sd_at_05 = res->se_at_05 = NAN;
    res->n_band = 0;
    for (size_t k = 0; k < res->nr; ++k) {
        if (fabs(res->sd[k] - res->sd_iid) <= 2.0 * res->se[k] + 1e-12 || res->sd[k] <= res->sd_iid) {
            if (res->n_band == 0)
                res->band_lo = res->r[k];
            res->band_hi = res->r[k];
            ++res->n_band;
        }
        if (fabs(res->r[k] - 0.5) < 1e-9) {
            res->sd_at_05 = res->sd[k];
            res->se_at_05 = res->se[k];
        }
    }
}

int rch_chaos_run(rch_chaos_result *res, const rch_chaos_config *cfg, FILE *progress, rch_diag *d)
{
    memset(res, 0, sizeof *res);
    if (rch_chaos_check(cfg, d) != 0)
        return -1;
    const size_t nr = n_r(cfg->step);
    const int show = progress && rch_chaos_cost(cfg) > 2e8;
    res->nr = nr;
    res->r = malloc(nr * sizeof *res->r);
    res->sd = malloc(nr * sizeof *res->sd);
    res->se = malloc(nr * sizeof *res->se);
    res->hist = malloc(cfg->bins * sizeof *res->hist);
    if (!res->r || !res->sd || !res->se || !res->hist) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < nr; ++k) {
        res->r[k] = k + 1 == nr ? 4.0 : (double)k * cfg->step;
        if (res->r[k] > 4.0)
            res->r[k] = 4.0;
        res->sd[k] = rch_chaos_sd_avg(&res->se[k], res->r[k], (unsigned)cfg->points, (unsigned)cfg->bins,
                                      (unsigned)cfg->starts, cfg->seed);
        if (res->sd[k] < res->sd[res->best])
            res->best = k;
        if (show && (k + 1) % ((nr + 9) / 10) == 0)
            fprintf(progress, "chaos: %zu of %zu r values done\n", k + 1, nr);
    }
    res->sd_iid = rch_chaos_sd_iid((unsigned)cfg->points, (unsigned)cfg->bins);
    res->r_hist = isnan(cfg->r_hist) ? res->r[res->best] : cfg->r_hist;
    if (histogram(res, cfg) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    band(res);
    return 0;
}

void rch_chaos_report(FILE *f, const rch_chaos_result *res, const rch_chaos_config *cfg)
{
    const size_t best = res->best;
    fprintf(f, "rcal chaos: logistic-tent map, %lu points, %lu bins, averaged over %lu initial values "
               "(seed %llu), r step %g\n",
            cfg->points, cfg->bins, cfg->starts, cfg->seed, cfg->step);
    fprintf(f, "  sd of bin counts (Eq. 12), mean +- standard error over the initial values:\n");
    for (size_t k = 0; k < res->nr; ++k) {
        const double r = res->r[k];
        const int half = fabs(r * 2.0 - floor(r * 2.0 + 0.5)) < 1e-6; /* 0, 0.5, 1, ... */
        if (k == best || half || r <= 0.05 + 1e-9)
            fprintf(f, "    r = %.2f: %8.3f +- %.3f%s\n", r, res->sd[k], res->se[k], k == best ? "  <- minimum" : "");
    }
    fprintf(f, "  minimum at r = %.2f: sd %.3f +- %.3f; the paper's r = 0.5 gives %.3f +- %.3f\n", res->r[best],
            res->sd[best], res->se[best], res->sd_at_05, res->se_at_05);
    fprintf(f, "  independent uniform draws give sd %.3f; %zu of %zu r values are within two standard errors\n"
               "  of that (or below it); the lowest is r = %.2f, the highest r = %.2f\n",
            res->sd_iid, res->n_band, res->nr, res->band_lo, res->band_hi);
    if (res->sd[0] > 5.0 * res->sd_iid)
        fprintf(f, "  r = 0 is the tent map x -> 2x (mod 1): in binary floating point it reaches 0 after\n"
                   "  about 53 steps and stays there, hence its huge sd; it is an artefact of doubles.\n");
    fprintf(f, "  histogram at r = %.2f (counts summed over the %lu initial values):\n   ", res->r_hist, cfg->starts);
    for (unsigned long b = 0; b < cfg->bins; ++b)
        fprintf(f, " %u%s", res->hist[b], (b + 1) % 16 == 0 && b + 1 < cfg->bins ? "\n   " : "");
    fprintf(f, "\n");
}

int rch_chaos_json(FILE *f, const rch_chaos_result *res, const rch_chaos_config *cfg, int argc, char **argv)
{
    const size_t b = res->best;
    rch_jw w;
    rch_jw_begin(&w, f, 1, "rcal-chaos/1", argc, argv);
    rch_jw_uint(&w, "points", cfg->points);
    rch_jw_uint(&w, "bins", cfg->bins);
    rch_jw_uint(&w, "starts", cfg->starts);
    rch_jw_uint(&w, "seed", cfg->seed);
    rch_jw_numf(&w, "step", cfg->step, "%.6g");
    rch_jw_numf(&w, "r_best", res->r[b], "%.6g");
    rch_jw_numf(&w, "sd_best", res->sd[b], "%.6f");
    rch_jw_numf(&w, "se_best", res->se[b], "%.6f");
    rch_jw_numf(&w, "sd_iid", res->sd_iid, "%.6f");
    rch_jw_numf(&w, "sd_at_0_5", res->sd_at_05, "%.6f"); /* null when r = 0.5 is not on the grid */
    rch_jw_numf(&w, "r_hist", res->r_hist, "%.6g");
    rch_jw_arr(&w, "curve"); /* [r, sd, se] */
    for (size_t k = 0; k < res->nr; ++k) {
        rch_jw_arr(&w, NULL);
        rch_jw_numf(&w, NULL, res->r[k], "%.6g");
        rch_jw_numf(&w, NULL, res->sd[k], "%.6f");
        rch_jw_numf(&w, NULL, res->se[k], "%.6f");
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_arr(&w, "histogram");
    for (unsigned long k = 0; k < cfg->bins; ++k)
        rch_jw_uint(&w, NULL, res->hist[k]);
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

static rch_plot *plot_curve(const rch_chaos_result *res, const rch_chaos_config *cfg)
{
    char title[160];
    double xl[2] = {0.0, 4.0}, yl[2] = {res->sd_iid, res->sd_iid};
    snprintf(title, sizeof title, "How evenly the logistic-tent map fills [0, 1] against its parameter r");
    rch_plot *p = rch_plot_new(title, "map parameter r (dimensionless)", "standard deviation of the bin counts (count)");
    snprintf(title, sizeof title,
             "%lu points from each of %lu starts in %lu bins; lower is more uniform (the paper's Eq. 12)", cfg->points,
             cfg->starts, cfg->bins);
    rch_plot_subtitle(p, title);
    rch_plot_line(p, "logistic-tent map (mean over the starts)", res->r, res->sd, res->nr);
    rch_plot_line(p, "independent uniform draws (expected)", xl, yl, 2);
    rch_plot_scatter(p, "most uniform r", &res->r[res->best], &res->sd[res->best], 1);
    rch_plot_logy(p, 1);
    return p;
}

static rch_plot *plot_hist(const rch_chaos_result *res, const rch_chaos_config *cfg)
{
    char title[160];
    double *x = malloc(cfg->bins * sizeof *x), *y = malloc(cfg->bins * sizeof *y);
    rch_plot *p = NULL;
    if (x && y) {
        double ymax = 0.0, total = 0.0;
        for (unsigned long b = 0; b < cfg->bins; ++b) {
            x[b] = ((double)b + 0.5) / (double)cfg->bins;
            y[b] = (double)res->hist[b];
            ymax = y[b] > ymax ? y[b] : ymax;
            total += y[b];
        }
        snprintf(title, sizeof title, "Histogram of the logistic-tent map's values at r = %.2f", res->r_hist);
        p = rch_plot_new(title, "value of the map (bin centre, dimensionless)", "values in the bin (count)");
        snprintf(title, sizeof title, "%lu starts x %lu iterates in %lu bins; a flat histogram is uniform", cfg->starts,
                 cfg->points, cfg->bins);
        rch_plot_subtitle(p, title);
        rch_plot_scatter(p, "count per bin", x, y, cfg->bins);
        const double ex[2] = {0.0, 1.0}, ey[2] = {total / (double)cfg->bins, total / (double)cfg->bins};
        rch_plot_line(p, "count expected of a uniform draw", ex, ey, 2);
        rch_plot_yrange(p, 0.0, 1.15 * ymax); /* from zero: the bars' spread against their height */
    }
    free(x);
    free(y);
    return p;
}

int rch_chaos_plots(const rch_chaos_result *res, const rch_chaos_config *cfg, const rch_plot_dir *pd, rch_diag *d)
{
    if (rch_plot_mkdir(pd->dir) != 0) {
        rch_diag_set(d, "", 0, 0, "cannot create %s: %s", pd->dir, strerror(errno));
        return -1;
    }
    if (rch_plot_save(plot_curve(res, cfg), pd, "chaos_sd.svg", d) != 0 ||
        rch_plot_save(plot_hist(res, cfg), pd, "chaos_hist.svg", d) != 0)
        return -1;
    return 0;
}
