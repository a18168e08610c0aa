/* SPDX-License-Identifier: MIT */
/* rch_start.c - the BC start model: the outlets guessed, the encoder fitted
 * alone (see rch_start.h). */
#include "rch_start.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_positions.h"
#include "rch_sensors.h"

/* The first guess of outlet k's position (k = 0: e) from its samples. */
static int guess_outlet(double e[3], const rc_model *m, unsigned k, const rc_sample *s, size_t n, rch_diag *d)
{
    rc_sample *sub = malloc((n ? n : 1) * sizeof *sub);
    size_t ns = 0;
    if (!sub) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    for (size_t i = 0; i < n; ++i)
        if (s[i].outlet == k && s[i].sensor == RC_SENSOR_LENGTH) /* a tracker's samples have no outlet */
            sub[ns++] = s[i];
    rc_status st = rc_encoder_guess(e, m, sub, ns);
    free(sub);
    char which[48] = "";
    if (k > 0)
        snprintf(which, sizeof which, " of outlet %u", k);
    if (st == RC_ERR_RANGE) {
        rch_diag_set(d, "", 0, 0,
                     "cannot place the encoder%s: the lengths fit no sphere around the nominal flange positions "
                     "(misfit above 15 %% of the lengths): the length column is not the cable, or the robot "
                     "is over 100 mm from its nominal model; give the outlet in the robot file (\"encoder_mm\")",
                     which);
        return -1;
    }
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot place the encoder%s: %s (the poses must spread in all three directions)",
                     which, rc_strerror(st));
        return -1;
    }
    return 0;
}

int rch_calib_bc(rc_model *start, rc_solve_work *w, const rc_model *nominal, int has_encoder, const rc_sample *s,
                 size_t n, rch_diag *d)
{
    *start = *nominal;
    const size_t n_len = rch_pos_count_lengths(s, n);
    if (n_len < n && rch_pos_effect_at(start, RC_EFF_TRACKER_ROTATION, NULL) >= 0 &&
        rch_pos_start(start, s, n, rch_pos_frame_given(start)) != 0) { /* closed form, then with e below */
        rch_diag_set(d, "", 0, 0, "cannot place the tracker: the positions do not spread in three directions");
        return -1;
    }
    if (rch_sensors_start(start, s, n, d) != 0) /* the other sensors' closed forms (rch_sensors.h) */
        return -1;
    if (!has_encoder && (n_len > 0 || n == 0)) { /* no lengths at all: e is held (rch_pos_fix_unseen) */
        double e[3];
        if (guess_outlet(e, start, 0, s, n, d) != 0)
            return -1;
        memcpy(&start->x[RC_P_ENC], e, sizeof e);
    }
    for (unsigned i = 0; i < start->n_effects; ++i) {
        const rc_effect *ef = &start->effects[i];
        if (ef->kind != RC_EFF_OUTLET)
            continue;
        double e[3];
        if (guess_outlet(e, start, ef->joint, s, n, d) != 0)
            return -1;
        memcpy(&start->x[ef->first], e, sizeof e);
    }
    uint8_t fixed[RC_MAX_PARAMS];
    memset(fixed, 1, sizeof fixed);
    fixed[RC_P_ENC] = fixed[RC_P_ENC + 1] = fixed[RC_P_ENC + 2] = 0;
    /* the sensors' placements (outlets, the tracker's frame and targets) are fitted to the nominal robot; the
     * tracker's scale is physical (its prior is centred on this start): fitted here it would take up the
     * robot's size error (405 ppm on a tracker file of sens_rates, 4 x its prior sd, a model rcal compensate
     * then refused as implausible) */
    for (unsigned i = 0; i < start->n_effects; ++i) {
        const rc_effect_desc *ds = rc_effect_describe(start->effects[i].kind);
        if (start->effects[i].kind == RC_EFF_OUTLET ||
            (ds && ds->side == RC_SIDE_SENSOR && start->effects[i].kind != RC_EFF_TRACKER_SCALE))
            memset(&fixed[start->effects[i].first], 0, start->effects[i].count);
    }
    rch_pos_fix_unseen(fixed, start, s, n);
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_METHOD_LM;
    cfg.max_iter = RCH_CALIB_BC_MAX_ITER;
    cfg.fixed = fixed;
    rc_solve_result res;
    rc_status st = rc_solve(start, &res, w, &cfg, s, n);
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "fitting the encoder position failed: %s", rc_strerror(st));
        return -1;
    }
    return 0;
}

int rch_calib_start(rc_model *start, rc_solve_work *w, const rch_robot *robot, const rc_sample *train, size_t n,
                    rch_diag *d)
{
    return rch_calib_bc(start, w, &robot->model, robot->has_encoder, train, n, d);
}
