/* cmd_chaos.c - rcal chaos: the LTLM paper's uniformity study of its
 * logistic-tent map (its Figs. 2-3 and Eq. 12).
 *
 * For r = 0, step, ..., 4: the standard deviation of the histogram bin counts
 * of `points` iterates of rc_lt_map (lower = more uniform), averaged over
 * `starts` initial values drawn from a fixed seed (one initial value makes
 * the curve as noisy as the differences it is meant to show). Reports the
 * minimising r, the yardstick of independent uniform draws, which r lie within
 * two standard errors of that yardstick, and the histogram at the chosen r
 * (--r, else the minimiser).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rc_rand.h"
#include "rch_est.h"
#include "rch_plot.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: rcal chaos [--r R] [--points 1000] [--bins 50] [--starts 100] [--step 0.01]\n"
               "                  [--seed 1] [--plots DIR] [--json]\n"
               "  Uniformity of the logistic-tent map (paper Eq. 11) for r in [0, 4]: the standard\n"
               "  deviation of the bin counts of --points iterates in --bins bins (Eq. 12), averaged\n"
               "  over --starts initial values; the histogram at --r (default: the minimiser).\n");
}

int rcal_cmd_chaos(int argc, char **argv)
{
    const char *plots = NULL;
    double r_user = NAN, step = 0.01;
    unsigned long points = 1000, bins = 50, starts = 100, seed = 1;
    int json = 0;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--plots", &plots) || rcal_opt_double(argc, argv, &i, "--r", &r_user) ||
            rcal_opt_double(argc, argv, &i, "--step", &step) ||
            rcal_opt_uint(argc, argv, &i, "--points", &points) || rcal_opt_uint(argc, argv, &i, "--bins", &bins) ||
            rcal_opt_uint(argc, argv, &i, "--starts", &starts) || rcal_opt_uint(argc, argv, &i, "--seed", &seed))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("chaos", argv[i]);
    }
    if (!isnan(r_user) && !(r_user >= 0.0 && r_user <= 4.0)) {
        fprintf(stderr, "rcal chaos: --r must be within [0, 4]\n");
        return 2;
    }
    if (points < 1 || points > 100000000ul || bins < 2 || bins > 1024 || starts < 1 || starts > 100000 ||
        !(step >= 1e-4 && step <= 4.0)) {
        fprintf(stderr, "rcal chaos: need 1 <= --points <= 1e8, 2 <= --bins <= 1024, 1 <= --starts <= 1e5, "
                        "1e-4 <= --step <= 4\n");
        return 2;
    }
    const size_t nr = (size_t)floor(4.0 / step + 1e-9) + 1;
    double *rs = malloc(nr * sizeof *rs), *sd = malloc(nr * sizeof *sd), *se = malloc(nr * sizeof *se);
    unsigned *counts = malloc(bins * sizeof *counts);
    int rc = 1;
    if (!rs || !sd || !se || !counts) {
        fprintf(stderr, "rcal chaos: out of memory\n");
        goto done;
    }
    size_t best = 0;
    for (size_t k = 0; k < nr; ++k) {
        rs[k] = k + 1 == nr ? 4.0 : (double)k * step;
        if (rs[k] > 4.0)
            rs[k] = 4.0;
        sd[k] = rch_chaos_sd_avg(&se[k], rs[k], (unsigned)points, (unsigned)bins, (unsigned)starts, seed);
        if (sd[k] < sd[best])
            best = k;
    }
    const double iid = rch_chaos_sd_iid((unsigned)points, (unsigned)bins);
    const double r_hist = isnan(r_user) ? rs[best] : r_user;
    /* histogram: summed over the same initial values as the curve */
    {
        unsigned *one = malloc(bins * sizeof *one);
        rc_rng g;
        if (!one)
            goto done;
        memset(counts, 0, bins * sizeof *counts);
        rc_rng_seed(&g, seed);
        for (unsigned long s = 0; s < starts; ++s) {
            rch_chaos_sd(one, r_hist, 0.01 + 0.98 * rc_rng_u01(&g), (unsigned)points, (unsigned)bins);
            for (unsigned long b = 0; b < bins; ++b)
                counts[b] += one[b];
        }
        free(one);
    }
    /* r values statistically indistinguishable from independent uniform draws */
    double band_lo = NAN, band_hi = NAN, sd_at_05 = NAN, se_at_05 = NAN;
    size_t n_band = 0;
    for (size_t k = 0; k < nr; ++k) {
        if (fabs(sd[k] - iid) <= 2.0 * se[k] + 1e-12 || sd[k] <= iid) {
            if (n_band == 0)
                band_lo = rs[k];
            band_hi = rs[k];
            ++n_band;
        }
        if (fabs(rs[k] - 0.5) < 1e-9) {
            sd_at_05 = sd[k];
            se_at_05 = se[k];
        }
    }
    if (json) {
        printf("{\"command\": \"chaos\", \"points\": %lu, \"bins\": %lu, \"starts\": %lu, \"seed\": %lu, "
               "\"step\": %.6g,\n \"r_best\": %.6g, \"sd_best\": %.6f, \"se_best\": %.6f, \"sd_iid\": %.6f, "
               "\"sd_at_0_5\": %.6f, \"r_hist\": %.6g,\n \"curve\": [",
               points, bins, starts, seed, step, rs[best], sd[best], se[best], iid, sd_at_05, r_hist);
        for (size_t k = 0; k < nr; ++k)
            printf("%s[%.6g, %.6f, %.6f]", k ? ", " : "", rs[k], sd[k], se[k]);
        printf("],\n \"histogram\": [");
        for (unsigned long b = 0; b < bins; ++b)
            printf("%s%u", b ? ", " : "", counts[b]);
        printf("]}\n");
    } else {
        printf("rcal chaos: logistic-tent map, %lu points, %lu bins, averaged over %lu initial values "
               "(seed %lu), r step %g\n",
               points, bins, starts, seed, step);
        printf("  sd of bin counts (Eq. 12), mean +- standard error over the initial values:\n");
        for (size_t k = 0; k < nr; ++k) {
            const double r = rs[k];
            const int half = fabs(r * 2.0 - floor(r * 2.0 + 0.5)) < 1e-6; /* 0, 0.5, 1, ... */
            if (k == best || half || r <= 0.05 + 1e-9)
                printf("    r = %.2f: %8.3f +- %.3f%s\n", r, sd[k], se[k], k == best ? "  <- minimum" : "");
        }
        printf("  minimum at r = %.2f: sd %.3f +- %.3f; the paper's r = 0.5 gives %.3f +- %.3f\n", rs[best],
               sd[best], se[best], sd_at_05, se_at_05);
        printf("  independent uniform draws give sd %.3f; %zu of %zu r values are within two standard errors\n"
               "  of that (or below it); the lowest is r = %.2f, the highest r = %.2f\n",
               iid, n_band, nr, band_lo, band_hi);
        if (sd[0] > 5.0 * iid)
            printf("  r = 0 is the tent map x -> 2x (mod 1): in binary floating point it reaches 0 after\n"
                   "  about 53 steps and stays there, hence its huge sd; it is an artefact of doubles.\n");
        printf("  histogram at r = %.2f (counts summed over the %lu initial values):\n   ", r_hist, starts);
        for (unsigned long b = 0; b < bins; ++b)
            printf(" %u%s", counts[b], (b + 1) % 16 == 0 && b + 1 < bins ? "\n   " : "");
        printf("\n");
    }
    if (plots) {
        struct stat sb;
        char path[4096];
        char mk[4096];
        snprintf(mk, sizeof mk, "%s", plots);
        for (char *q = mk + 1; *q; ++q) /* mkdir -p for the parents */
            if (*q == '/') {
                *q = '\0';
                if (stat(mk, &sb) != 0)
                    (void)mkdir(mk, 0777);
                *q = '/';
            }
        if (!(stat(plots, &sb) == 0 && S_ISDIR(sb.st_mode)) && mkdir(plots, 0777) != 0) {
            fprintf(stderr, "rcal chaos: cannot create %s: %s\n", plots, strerror(errno));
            goto done;
        }
        {
            char title[160];
            double xl[2] = {0.0, 4.0}, yl[2] = {iid, iid};
            snprintf(title, sizeof title, "Uniformity of the logistic-tent map (%lu points, %lu bins, %lu starts)",
                     points, bins, starts);
            rch_plot *p = rch_plot_new(title, "r", "sd of bin counts (Eq. 12)");
            rch_plot_line(p, "logistic-tent map", rs, sd, nr);
            rch_plot_line(p, "independent uniform draws", xl, yl, 2);
            rch_plot_scatter(p, "minimum", &rs[best], &sd[best], 1);
            rch_plot_logy(p, 1);
            snprintf(path, sizeof path, "%s/chaos_sd.svg", plots);
            if (rch_plot_write_svg(p, path) != 0) {
                fprintf(stderr, "rcal chaos: cannot write %s: %s\n", path, strerror(errno));
                rch_plot_free(p);
                goto done;
            }
            rch_plot_free(p);
            if (!json)
                printf("  wrote %s\n", path);
        }
        {
            char title[160];
            double *x = malloc(bins * sizeof *x), *y = malloc(bins * sizeof *y);
            if (!x || !y) {
                free(x);
                free(y);
                goto done;
            }
            for (unsigned long b = 0; b < bins; ++b) {
                x[b] = ((double)b + 0.5) / (double)bins;
                y[b] = (double)counts[b];
            }
            snprintf(title, sizeof title, "Histogram of the map at r = %.2f (%lu x %lu iterates)", r_hist, starts,
                     points);
            rch_plot *p = rch_plot_new(title, "value (bin centre)", "count");
            rch_plot_line(p, "counts", x, y, bins);
            rch_plot_scatter(p, "", x, y, bins);
            rch_plot_yrange(p, 0.0, 0.0);
            snprintf(path, sizeof path, "%s/chaos_hist.svg", plots);
            int w = rch_plot_write_svg(p, path);
            rch_plot_free(p);
            free(x);
            free(y);
            if (w != 0) {
                fprintf(stderr, "rcal chaos: cannot write %s: %s\n", path, strerror(errno));
                goto done;
            }
            if (!json)
                printf("  wrote %s\n", path);
        }
    }
    rc = 0;
done:
    free(rs);
    free(sd);
    free(se);
    free(counts);
    return rc;
}
