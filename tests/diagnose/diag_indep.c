/* SPDX-License-Identifier: MIT */
/* diag_indep.c - detection and false-alarm rates of `rcal diagnose` on data
 * made apart from its own simulator and effect code (issue 14): this file's
 * forward kinematics and random numbers (tests/common/rct_indep.h), two
 * robots (data/irb120.json and data/kr6.json), effects parameterised
 * differently from the library's (an exponential warm-up instead of t, t^2; a
 * gravity lever from this file's own chain to the wrist centre; a sinusoid
 * with a random phase;
 * jumps inside set-ups; a sag of the cable; a cable attached off the flange
 * centre), noise levels drawn at random in [0.002, 0.05] mm and never passed
 * to the workflow, set-ups of 10 poses (wrist fixed), contiguous.
 *
 * usage: diag_indep [SEEDS=10] [SIZE=8]   (SIZE: the effect's RMS length
 * change in units of the noise). Prints the table by effect, robot and noise
 * band. With --check it runs a short version and exits non-zero when the
 * controls give more than 1 false alarm in 10 per robot or length jumps are
 * named in fewer than 4 of 5 seeds (the ctest diag_indep). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose.h"
#include "rch_robot.h"
#include "rct_indep.h"

#define DEGR (3.14159265358979323846 / 180.0)
#define N 300

typedef enum { E_NONE, E_JUMP, E_DRIFT, E_GROUP, E_COMPL2, E_PERIOD3, E_SAG, E_ATTACH, E_COUNT } eff;
static const char *const eff_name[E_COUNT] = {"none",         "length jump",       "warm-up drift (exp)",
                                              "set-up offsets", "compliance j2",   "periodic j3 (phase)",
                                              "cable sag",    "attachment offset"};
/* what a correct diagnosis names */
static const char *const expect[E_COUNT] = {"none",        "length_jump",      "time_drift",  "group_offset",
                                            "joint_compliance", "joint_periodic", "unexplained", "none"};
static const unsigned expect_joint[E_COUNT] = {0, 0, 0, 0, 2, 3, 0, 0};

/* One data set: robot nominal (as its model file), truth = nominal + small
 * DH errors, the effect scaled to an RMS length change of size * noise. */
static double make(rc_sample *s, const rc_model *nom, eff e, rct_rng *g, double noise, double size)
{
    double dh[6][4], q[N][6], extra[N], e0[3];
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            dh[i][k] = nom->x[4 * i + k] + (k < 2 ? 0.2 * rct_gauss(g) : 0.03 * DEGR * rct_gauss(g));
    const double reach = fabs(nom->x[4]) + fabs(nom->x[13]) + 200.0;
    e0[0] = 0.6 * reach + 50 * rct_gauss(g);
    e0[1] = -0.7 * reach + 50 * rct_gauss(g);
    e0[2] = 50 * rct_gauss(g);
    const double phase = 6.283185307179586 * rct_u01(g), tau = 0.15 + 0.3 * rct_u01(g);
    size_t jump_at = 0;
    double wrist[3] = {0, 0, 0}, setup_off = 0.0;
    do { /* a jump inside a set-up, away from the ends */
        jump_at = 30 + (size_t)(rct_u01(g) * (N - 60));
    } while (jump_at % 10 < 3 || jump_at % 10 > 7);
    double tool[3] = {25 * rct_gauss(g), 25 * rct_gauss(g), 10 * rct_gauss(g)};
    double sum2 = 0.0;
    for (size_t i = 0; i < N; ++i) {
        for (int j = 0; j < 6; ++j) {
            double lo = nom->q_min_rad[j] * 0.75, hi = nom->q_max_rad[j] * 0.75;
            if (j >= 3 && i % 10 != 0)
                q[i][j] = wrist[j - 3];
            else
                q[i][j] = lo + (hi - lo) * rct_u01(g);
            if (j >= 3)
                wrist[j - 3] = q[i][j];
        }
        if (i % 10 == 0)
            setup_off = rct_gauss(g);
        const double t = (double)i / (N - 1);
        double qe[6];
        memcpy(qe, q[i], sizeof qe);
        if (e == E_COMPL2) /* the arm sags under its weight: joint 2 turns with the gravity moment */
            qe[1] += 1e-3 * rct_lever2_m(dh, q[i]); /* scaled below through the length change */
        if (e == E_PERIOD3)
            qe[2] += 1e-3 * sin(q[i][2] + phase);
        double p[3], R[9], base[3];
        rct_pose(p, R, dh, qe);
        if (e == E_ATTACH)
            for (int r = 0; r < 3; ++r)
                p[r] += R[r * 3] * tool[0] + R[r * 3 + 1] * tool[1] + R[r * 3 + 2] * tool[2];
        rct_flange(base, dh, q[i]);
        const double l = rct_dist(p, e0), l0 = rct_dist(base, e0);
        double x = 0.0;
        switch (e) {
        case E_NONE: x = 0.0; break;
        case E_JUMP: x = i >= jump_at ? 1.0 : 0.0; break;
        case E_DRIFT: x = 1.0 - exp(-t / tau); break;
        case E_GROUP: x = setup_off; break;
        case E_COMPL2:
        case E_PERIOD3:
        case E_ATTACH: x = l - l0; break;
        case E_SAG: {
            const double h2 = (p[0] - e0[0]) * (p[0] - e0[0]) + (p[1] - e0[1]) * (p[1] - e0[1]);
            x = 1e-6 * h2;
            break;
        }
        case E_COUNT: break;
        }
        extra[i] = x;
        s[i].len_mm = l0;
        memcpy(s[i].q_rad, q[i], sizeof q[i]);
        for (int j = 0; j < 6; ++j) /* recorded at 0.001 deg, a controller readout */
            s[i].q_rad[j] = 0.001 * DEGR * round(s[i].q_rad[j] / (0.001 * DEGR));
        s[i].t = t;
        s[i].group = 0;
    }
    double mean = 0.0;
    for (size_t i = 0; i < N; ++i)
        mean += extra[i] / N;
    for (size_t i = 0; i < N; ++i)
        sum2 += (extra[i] - (e == E_JUMP || e == E_DRIFT || e == E_SAG ? mean : 0.0)) *
                (extra[i] - (e == E_JUMP || e == E_DRIFT || e == E_SAG ? mean : 0.0));
    const double rms = sqrt(sum2 / N), k = rms > 0 ? size * noise / rms : 0.0;
    for (size_t i = 0; i < N; ++i)
        s[i].len_mm += k * extra[i] + noise * rct_gauss(g);
    return k;
}

static int match(const rch_diagnose_result *r, eff e)
{
    return strcmp(r->effect, expect[e]) == 0 && (expect_joint[e] == 0 || r->joint == expect_joint[e]);
}

int main(int argc, char **argv)
{
    int check = argc > 1 && strcmp(argv[1], "--check") == 0;
    unsigned seeds = check ? 5 : (argc > 1 ? (unsigned)atoi(argv[1]) : 10u);
    double size = (!check && argc > 2) ? atof(argv[2]) : 8.0;
    const char *robots[2] = {RCAL_SOURCE_DIR "/data/irb120.json", RCAL_SOURCE_DIR "/data/kr6.json"};
    rc_sample *s = malloc(N * sizeof *s);
    int fail = 0;
    if (!s || seeds == 0 || seeds > 1000)
        return 2;
    printf("rcal diagnose on independent data: %u seeds per cell, %d samples in set-ups of 10, effect RMS = %g x noise,\n"
           "noise drawn in [0.002, 0.05] mm and not told; hits / runs per noise band (low < 0.01 <= mid < 0.03 <= high)\n",
           seeds, N, size);
    printf("%-22s %-8s %-14s %6s %6s %6s   %s\n", "effect", "robot", "expected", "low", "mid", "high", "other verdicts");
    for (unsigned ri = 0; ri < 2; ++ri) {
        rch_robot robot;
        rch_diag d;
        if (rch_robot_load(&robot, robots[ri], &d) != 0)
            return 2;
        for (unsigned e = 0; e < E_COUNT; ++e) {
            if (check && e != E_NONE && e != E_JUMP)
                continue;
            unsigned hit[3] = {0, 0, 0}, runs[3] = {0, 0, 0};
            char other[400] = "";
            size_t op = 0;
            rct_rng g = {1000003ull * (ri + 1) + 7919ull * e};
            unsigned n_seeds = check && e == E_NONE ? 10 : seeds;
            for (unsigned k = 0; k < n_seeds; ++k) {
                double noise = 0.002 + 0.048 * rct_u01(&g);
                make(s, &robot.model, (eff)e, &g, noise, size);
                rch_diagnose_cfg cfg;
                rch_diagnose_result r;
                memset(&cfg, 0, sizeof cfg);
                cfg.folds = 4;
                cfg.max_steps = 1;
                cfg.seed = 100u + k;
                const unsigned band = noise < 0.01 ? 0 : noise < 0.03 ? 1 : 2;
                runs[band]++;
                if (rch_diagnose_run(&r, s, N, &robot.nominal, &cfg, &d) != 0) {
                    if (op < sizeof other - 40)
                        op += (size_t)snprintf(other + op, sizeof other - op, " (failed: %s)", d.msg);
                    rch_diagnose_free(&r);
                    continue;
                }
                if (match(&r, (eff)e))
                    hit[band]++;
                else if (op < sizeof other - 40)
                    op += (size_t)snprintf(other + op, sizeof other - op, " %s%s%u", r.effect, r.joint ? " j" : "",
                                           r.joint ? r.joint : 0u);
                rch_diagnose_free(&r);
            }
            char cell[3][16];
            for (int b = 0; b < 3; ++b)
                snprintf(cell[b], sizeof cell[b], "%u/%u", hit[b], runs[b]);
            printf("%-22s %-8s %-14s %6s %6s %6s  %s\n", eff_name[e], ri ? "kr6" : "irb120", expect[e], cell[0],
                   cell[1], cell[2], other);
            fflush(stdout);
            const unsigned h = hit[0] + hit[1] + hit[2], n = runs[0] + runs[1] + runs[2];
            if (check && e == E_NONE && n - h > 1)
                fail = 1;
            if (check && e == E_JUMP && h + 1 < n)
                fail = 1;
        }
    }
    free(s);
    if (check)
        printf("%s\n", fail ? "FAIL: false alarms above 1 in 10, or jumps missed" : "ok");
    return fail;
}
