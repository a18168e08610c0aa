/* SPDX-License-Identifier: MIT */
/* diag_sim_common.h - simulated data sets with one hidden effect, shared by
 * the diagnose tests and the detection-rate runs.
 *
 * Each case: the nominal IRB120 with random DH errors (rch_sim defaults:
 * 0.3 mm / 0.05 deg), an encoder outlet, grouped poses (wrist fixed for 20
 * consecutive poses, like the real acquisition), length noise 0.01 mm,
 * resolution 0.004 mm, joints recorded at 0.1 deg; plus ONE effect set in
 * the true model at a realistic size (a few tenths of a mm at the flange).
 * The workflow is given only the samples and the nominal model.
 */
#ifndef DIAG_SIM_COMMON_H
#define DIAG_SIM_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose.h"
#include "rch_robot.h"
#include "rch_sim.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct diag_case {
    const char *name;     /* expected verdict ("none" for a control) */
    rc_effect_kind kind;  /* RC_EFF_NONE for a control */
    unsigned joint0;      /* 0-based joint of a joint effect */
} diag_case;

static const diag_case diag_cases[] = {
    {"none", RC_EFF_NONE, 0},
    {"length_offset", RC_EFF_LENGTH_OFFSET, 0},
    {"time_drift", RC_EFF_TIME_DRIFT, 0},
    {"group_offset", RC_EFF_GROUP_OFFSET, 0},
    {"joint_compliance", RC_EFF_JOINT_COMPLIANCE, 1},
    {"joint_compliance", RC_EFF_JOINT_COMPLIANCE, 2},
    {"joint_periodic", RC_EFF_JOINT_PERIODIC, 0},
    {"joint_periodic", RC_EFF_JOINT_PERIODIC, 1},
    {"joint_periodic", RC_EFF_JOINT_PERIODIC, 2},
    {"cable_sag", RC_EFF_CABLE_SAG, 0},
    {"length_nonlinearity", RC_EFF_LENGTH_NONLIN, 0},
    {"length_periodic", RC_EFF_LENGTH_PERIODIC, 0},
};
#define DIAG_N_CASES (sizeof diag_cases / sizeof diag_cases[0])

#define DIAG_GROUP_SIZE 20u

/* Simulate n samples with the case's effect hidden in the truth. Returns 0
 * or -1. nominal: loaded robot model. */
static inline int diag_simulate(rc_sample *s, size_t n, const rc_model *nominal, const diag_case *c,
                         unsigned long long seed, double q_step_deg, double size)
{
    rch_sim_config sc;
    rc_rng g;
    rc_model truth;
    const double enc[3] = {350.0, -250.0, 50.0};
    memset(&sc, 0, sizeof sc);
    sc.group_size = DIAG_GROUP_SIZE;
    sc.q_step_deg = q_step_deg;
    rch_sim_defaults(&sc);
    rc_rng_seed(&g, seed);
    rch_sim_truth(&truth, nominal, enc, &sc, &g);
    if (c->kind != RC_EFF_NONE) {
        const unsigned groups = (unsigned)((n + DIAG_GROUP_SIZE - 1) / DIAG_GROUP_SIZE);
        if (rc_model_add_effect(&truth, c->kind, c->joint0, c->kind == RC_EFF_GROUP_OFFSET ? groups : 0) != RC_OK)
            return -1;
        double *x = &truth.x[truth.effects[truth.n_effects - 1].first];
        const double sgn = rc_rng_u01(&g) < 0.5 ? -1.0 : 1.0;
        switch (c->kind) {
        case RC_EFF_LENGTH_OFFSET: x[0] = sgn * size * 0.5; break;  /* mm */
        case RC_EFF_TIME_DRIFT:                                       /* warm-up: 0.5 mm over the run */
            x[0] = sgn * size * 0.8;
            x[1] = -sgn * size * 0.3;
            break;
        case RC_EFF_GROUP_OFFSET:                                     /* re-hooked cable: 0.3 mm sd */
            for (unsigned k = 0; k < groups; ++k)
                x[k] = size * 0.3 * rc_rng_normal(&g);
            break;
        case RC_EFF_JOINT_COMPLIANCE: x[0] = sgn * size * 1.5e-3; break;     /* rad per m of lever */
        case RC_EFF_JOINT_PERIODIC:                                   /* ~0.03 deg gear ripple */
            x[0] = sgn * size * 5e-4;
            x[1] = size * 2e-4 * rc_rng_normal(&g);
            x[2] = size * 3e-4 * rc_rng_normal(&g);
            x[3] = sgn * size * 3e-4;
            break;
        case RC_EFF_CABLE_SAG: x[0] = sgn * size * 3.0; break;  /* mm per m^3: ~0.1-0.4 mm */
        case RC_EFF_LENGTH_NONLIN:                                 /* ~0.1-0.2 mm over the range */
            x[0] = sgn * size * 2.0;
            x[1] = size * 3.0 * rc_rng_normal(&g);
            break;
        case RC_EFF_LENGTH_PERIODIC: /* an eccentric drum of 100-180 mm circumference, ~0.1 mm */
            x[0] = sgn * size * 0.08;
            x[1] = size * 0.04 * rc_rng_normal(&g);
            x[2] = 100.0 + 80.0 * rc_rng_u01(&g);
            break;
        default: return -1;
        }
    }
    return rch_sim_samples(s, NULL, n, &truth, &sc, &g);
}

/* The noise bands of the rate tables (mm): drawn at random in a band and
 * never told to the workflow. */
#define DIAG_N_BANDS 3
static const double diag_band_lo[DIAG_N_BANDS] = {0.002, 0.005, 0.02};
static const double diag_band_hi[DIAG_N_BANDS] = {0.005, 0.02, 0.05};

/* diag_simulate with the noise drawn in [noise_lo, noise_hi] (returned in
 * *noise_mm), joints recorded at 0.001 deg and lengths at 0.001 mm (so that
 * the noise, not the display, sets the floor), and the hidden effect scaled
 * so that its RMS length change over the data set is size_x_noise times the
 * noise (mean removed for drift, sag and nonlinearity, whose constant part
 * the geometry absorbs). With visible != 0 the size is instead the part of
 * the effect that no geometry explains (the RMS residual of a geometric fit
 * to the noise-free lengths): what a diagnosis can see at all; a length
 * offset, for one, is mostly absorbed by the geometry. The effect's parameters are first drawn as in
 * diag_simulate, then scaled (every library effect is linear in its
 * parameters, the joint-side ones to first order). */
static inline int diag_simulate_band(rc_sample *s, size_t n, const rc_model *nominal, const diag_case *c,
                                     unsigned long long seed, double noise_lo, double noise_hi,
                                     double size_x_noise, int visible, double *noise_mm)
{
    rch_sim_config sc;
    rc_rng g, g0;
    rc_model truth, geo;
    const double enc[3] = {350.0, -250.0, 50.0};
    memset(&sc, 0, sizeof sc);
    sc.group_size = DIAG_GROUP_SIZE;
    sc.q_step_deg = 0.001;
    sc.resolution_mm = 0.001;
    rch_sim_defaults(&sc);
    sc.noise_mm = -1.0;
    rc_rng_seed(&g, seed);
    *noise_mm = noise_lo + (noise_hi - noise_lo) * rc_rng_u01(&g);
    rch_sim_truth(&truth, nominal, enc, &sc, &g);
    geo = truth;
    if (c->kind != RC_EFF_NONE) {
        const unsigned groups = (unsigned)((n + DIAG_GROUP_SIZE - 1) / DIAG_GROUP_SIZE);
        if (rc_model_add_effect(&truth, c->kind, c->joint0, c->kind == RC_EFF_GROUP_OFFSET ? groups : 0) != RC_OK)
            return -1;
        const rc_effect *ef = &truth.effects[truth.n_effects - 1];
        double *x = &truth.x[ef->first];
        for (unsigned k = 0; k < ef->count; ++k)
            x[k] = (k % 2 ? 0.5 : 1.0) * (rc_rng_u01(&g) < 0.5 ? -1.0 : 1.0) * (0.5 + rc_rng_u01(&g));
        const unsigned n_lin = c->kind == RC_EFF_LENGTH_PERIODIC ? 2u : ef->count; /* the period is not scaled */
        if (c->kind == RC_EFF_LENGTH_PERIODIC)
            x[2] = 100.0 + 80.0 * rc_rng_u01(&g);
        if (c->kind == RC_EFF_JOINT_COMPLIANCE || c->kind == RC_EFF_JOINT_PERIODIC)
            for (unsigned k = 0; k < ef->count; ++k)
                x[k] *= 1e-3; /* stay in the linear range */
        /* the poses: drawn without noise, the RMS of the effect over them */
        g0 = g;
        if (rch_sim_samples(s, NULL, n, &truth, &sc, &g0) != 0)
            return -1;
        double mean = 0.0, s2 = 0.0;
        const int center = c->kind == RC_EFF_TIME_DRIFT || c->kind == RC_EFF_CABLE_SAG ||
                           c->kind == RC_EFF_LENGTH_NONLIN || c->kind == RC_EFF_LENGTH_PERIODIC;
        double *dl = malloc(n * sizeof *dl);
        if (!dl)
            return -1;
        for (size_t i = 0; i < n; ++i) {
            double l0;
            if (rc_meas(&l0, NULL, &geo, &s[i]) != RC_OK) {
                free(dl);
                return -1;
            }
            double l1;
            (void)rc_meas(&l1, NULL, &truth, &s[i]);
            dl[i] = l1 - l0;
            mean += dl[i] / (double)n;
        }
        for (size_t i = 0; i < n; ++i)
            s2 += (dl[i] - (center ? mean : 0.0)) * (dl[i] - (center ? mean : 0.0));
        free(dl);
        double rms = sqrt(s2 / (double)n);
        if (visible) { /* the part no geometry explains: the RMS residual of a geometric fit to the noise-free lengths */
            rc_solve_work *w = malloc(sizeof *w);
            rc_solve_config scfg;
            rc_solve_result res;
            rc_model fit = geo;
            memset(&scfg, 0, sizeof scfg);
            scfg.method = RC_METHOD_LM;
            scfg.max_iter = 200;
            if (!w || rc_solve(&fit, &res, w, &scfg, s, n) != RC_OK) {
                free(w);
                return -1;
            }
            free(w);
            rms = res.rms_final_mm;
        }
        if (!(rms > 0.0))
            return -1;
        for (unsigned k = 0; k < n_lin; ++k)
            x[k] *= size_x_noise * *noise_mm / rms;
    }
    /* the same poses (the same generator state, no noise draws between
     * them), then the noise, recorded at 0.001 mm */
    sc.noise_mm = -1.0;
    if (rch_sim_samples(s, NULL, n, &truth, &sc, &g) != 0)
        return -1;
    for (size_t i = 0; i < n; ++i)
        s[i].value = 0.001 * round((s[i].value + *noise_mm * rc_rng_normal(&g)) / 0.001);
    return 0;
}

static inline int diag_load_nominal(rc_model *m)
{
    rch_robot robot;
    rch_diag d;
    if (rch_robot_load(&robot, RCAL_SOURCE_DIR "/data/irb120.json", &d) != 0) {
        char buf[1024];
        fprintf(stderr, "%s\n", rch_diag_str(&d, buf, sizeof buf));
        return -1;
    }
    *m = robot.nominal;
    return 0;
}

/* Verdict matches the case (joint too for joint effects). */
static inline int diag_match(const rch_diagnose_result *r, const diag_case *c)
{
    if (strcmp(r->effect, c->name) != 0)
        return 0;
    if (c->kind == RC_EFF_JOINT_COMPLIANCE || c->kind == RC_EFF_JOINT_PERIODIC)
        return r->joint == c->joint0 + 1;
    return 1;
}

/* Named: the verdict, or the effect the diagnosis adds at a later step
 * (printed under "Effects added"); "none" only when nothing is added. */
static inline int diag_named(const rch_diagnose_result *r, const diag_case *c)
{
    if (diag_match(r, c))
        return 1;
    if (strcmp(c->name, "none") == 0)
        return 0;
    const size_t len = strlen(c->name);
    const int joint_eff = c->kind == RC_EFF_JOINT_COMPLIANCE || c->kind == RC_EFF_JOINT_PERIODIC;
    for (unsigned k = 0; k < r->n_steps; ++k) {
        const rch_diagnose_step *st = &r->steps[k];
        if (st->chosen < 0)
            continue;
        const rch_diagnose_cand *cd = &st->cand[st->chosen];
        if (strncmp(cd->name, c->name, len) == 0 && (cd->name[len] == '\0' || cd->name[len] == ' ') &&
            (!joint_eff || cd->joint == c->joint0 + 1))
            return 1;
    }
    return 0;
}

static inline void diag_case_label(char *buf, size_t len, const diag_case *c)
{
    if (c->kind == RC_EFF_JOINT_COMPLIANCE || c->kind == RC_EFF_JOINT_PERIODIC)
        snprintf(buf, len, "%s j%u", c->name, c->joint0 + 1);
    else
        snprintf(buf, len, "%s", c->name);
}

#endif
