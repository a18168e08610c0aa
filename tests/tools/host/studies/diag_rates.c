/* SPDX-License-Identifier: MIT */
/* diag_rates.c - detection rate of `rcal diagnose` on simulated data with
 * each effect hidden (not a test: a measurement). For every case of
 * diag_sim_common.h and seeds 1..S: simulate, diagnose, compare the verdict.
 * usage: diag_rates [SEEDS=10] [N=320] [FOLDS=4] [Q_STEP_DEG=0.01] [SIZE=1] [CASE]
 *        diag_rates --bands [SEEDS=10] [SIZE_X_NOISE=3]   (rates by noise band, issue 14)
 *        diag_rates --bands-visible [SEEDS] [SIZE]        (size = the part no geometry absorbs)
 * SIZE multiplies every hidden effect; Q_STEP_DEG is the joint display step
 * (0.1 as in the real file, 0.01 for a controller readout).
 * Prints one line per case: hits/seeds, held-out RMSE before/after and the
 * floor (medians), and the wrong verdicts seen. */
#include <time.h>

#include "diag_sim_common.h"

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, unsigned n)
{
    qsort(v, n, sizeof *v, cmp_d);
    return n ? (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2])) : 0.0;
}

/* Rates by effect and noise band (issue 14): the noise drawn in each band
 * and not told, the effect at size_x times the noise, joints at 0.001 deg
 * (diag_simulate_band). One line per case: hits / runs per band. */
static int bands(unsigned seeds, double size_x, int visible, size_t n, unsigned folds)
{
    rc_model nominal;
    rc_sample *s = calloc(n, sizeof *s);
    if (!s || diag_load_nominal(&nominal) != 0)
        return 1;
    printf("own simulator (rch_sim, IRB120), %u seeds per noise band and case, n %zu in set-ups of %u, %u folds,\n"
           "effect RMS%s = %g x noise, noise drawn in each band and not told; hits / runs per band (mm)\n",
           seeds, n, DIAG_GROUP_SIZE, folds, visible ? " left after a geometric fit" : "", size_x);
    printf("%-22s %11s %11s %11s   %s\n", "hidden effect", "0.002-0.005", "0.005-0.02", "0.02-0.05",
           "other verdicts");
    for (unsigned ci = 0; ci < DIAG_N_CASES; ++ci) {
        const diag_case *c = &diag_cases[ci];
        char other[600] = "", label[64], cell[DIAG_N_BANDS][16];
        if (getenv("DIAG_CASE") && (unsigned)atoi(getenv("DIAG_CASE")) != ci)
            continue; /* one case only (its index in diag_cases), e.g. with DIAG_VERBOSE=1 */
        size_t op = 0;
        for (unsigned b = 0; b < DIAG_N_BANDS; ++b) {
            unsigned hits = 0;
            for (unsigned k = 0; k < seeds; ++k) {
                rch_diagnose_cfg cfg;
                rch_diagnose_result r;
                rch_diag d;
                double noise;
                memset(&cfg, 0, sizeof cfg);
                cfg.folds = folds;
                cfg.max_steps = 2; /* named: the verdict or the effect added next (diag_named) */
                cfg.seed = 1000u + k;
                cfg.verbose = getenv("DIAG_VERBOSE") ? atoi(getenv("DIAG_VERBOSE")) : 0;
                if (diag_simulate_band(s, n, &nominal, c, 104729ull * (k + 1) + 7919ull * ci + 31ull * b,
                                       diag_band_lo[b], diag_band_hi[b], size_x, visible, &noise) != 0 ||
                    rch_diagnose_run(&r, s, n, &nominal, &cfg, &d) != 0) {
                    fprintf(stderr, "case %u band %u seed %u failed\n", ci, b, k + 1);
                    free(s);
                    return 1;
                }
                const int ok = diag_named(&r, c);
                hits += (unsigned)ok;
                if (!ok && op < sizeof other - 40)
                    op += (size_t)snprintf(other + op, sizeof other - op, "%s%s", op ? ", " : "", r.effect);
                if (!ok && r.joint && op < sizeof other - 8)
                    op += (size_t)snprintf(other + op, sizeof other - op, " j%u", r.joint);
                rch_diagnose_free(&r);
            }
            snprintf(cell[b], sizeof cell[b], "%u/%u", hits, seeds);
        }
        diag_case_label(label, sizeof label, c);
        printf("%-22s %11s %11s %11s   %s\n", label, cell[0], cell[1], cell[2], other);
        fflush(stdout);
    }
    free(s);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && (strcmp(argv[1], "--bands") == 0 || strcmp(argv[1], "--bands-visible") == 0)) {
        const unsigned sd = argc > 2 ? (unsigned)atoi(argv[2]) : 10u;
        const int vis = strcmp(argv[1], "--bands-visible") == 0;
        return sd == 0 || sd > 1000 ? 1 : bands(sd, argc > 3 ? atof(argv[3]) : 3.0, vis, 300, 4);
    }
    const unsigned seeds = argc > 1 ? (unsigned)atoi(argv[1]) : 10u;
    const size_t n = argc > 2 ? (size_t)atoi(argv[2]) : 320u;
    const unsigned folds = argc > 3 ? (unsigned)atoi(argv[3]) : 4u;
    const double q_step = argc > 4 ? atof(argv[4]) : 0.01;
    const double size = argc > 5 ? atof(argv[5]) : 1.0;
    const unsigned only = argc > 6 ? (unsigned)atoi(argv[6]) : 999u;
    rc_model nominal;
    if (diag_load_nominal(&nominal) != 0 || seeds == 0 || seeds > 1000)
        return 1;
    rc_sample *s = calloc(n, sizeof *s);
    double *before = malloc(seeds * sizeof *before), *after = malloc(seeds * sizeof *after),
           *floor_ = malloc(seeds * sizeof *floor_);
    if (!s || !before || !after || !floor_)
        return 1;
    printf("n %zu, %u folds, joint step %g deg, effect size x%g, %u seeds\n", n, folds, q_step, size, seeds);
    printf("%-22s %7s %10s %10s %10s  %s\n", "hidden effect", "hits", "before mm", "after mm", "floor mm",
           "other verdicts");
    for (unsigned ci = 0; ci < DIAG_N_CASES; ++ci) {
        if (only != 999u && ci != only)
            continue;
        const diag_case *c = &diag_cases[ci];
        unsigned hits = 0;
        char other[512] = "", label[64];
        size_t op = 0;
        for (unsigned k = 0; k < seeds; ++k) {
            rch_diagnose_cfg cfg;
            rch_diagnose_result r;
            rch_diag d;
            memset(&cfg, 0, sizeof cfg);
            cfg.folds = folds;
            cfg.max_steps = 1;
            cfg.seed = 1000u + k;
            cfg.len_noise_mm = 0.01; /* the simulated encoder noise, as its data sheet would state */
            cfg.max_iter = getenv("DIAG_MAX_ITER") ? (unsigned)atoi(getenv("DIAG_MAX_ITER")) : 40u;
            if (diag_simulate(s, n, &nominal, c, 7919ull * (k + 1) + ci, q_step, size) != 0 ||
                rch_diagnose_run(&r, s, n, &nominal, &cfg, &d) != 0) {
                fprintf(stderr, "case %u seed %u failed\n", ci, k + 1);
                return 1;
            }
            const int ok = diag_match(&r, c);
            hits += (unsigned)ok;
            before[k] = r.rmse_before_mm;
            after[k] = r.rmse_after_mm;
            floor_[k] = r.noise_floor_mm;
            if (!ok && op < sizeof other - 40)
                op += (size_t)snprintf(other + op, sizeof other - op, "%s%s%s%u", op ? ", " : "", r.effect,
                                       r.joint ? " j" : "", r.joint);
            if (!ok && r.joint == 0 && op >= 1 && other[op - 1] == '0')
                other[--op] = '\0';
            rch_diagnose_free(&r);
        }
        diag_case_label(label, sizeof label, c);
    printf("%-22s %3u/%-3u %10.4f %10.4f %10.4f  %s\n", label, hits, seeds, median(before, seeds),
               median(after, seeds), median(floor_, seeds), other);
        fflush(stdout);
    }
    free(s);
    free(before);
    free(after);
    free(floor_);
    return 0;
}
