/* SPDX-License-Identifier: MIT */
/* rch_start.h - the start model of every fit: "before calibration" (BC).
 *
 * The one definition of the start model. Nominal geometry; the encoder
 * outlet from the robot file when it has one, else from rc_encoder_guess
 * (each further outlet, RC_EFF_OUTLET, from its own samples); with tracker
 * positions the tracker frame in closed form (rch_pos_start); then the
 * encoder (and the sensor-side effects) alone refined by LM with everything
 * else held. `rcal calibrate` (rch_calib_run), `rcal evaluate`
 * (rch_evaluate's outlet refit), `rcal compare`, `rcal bench` and
 * `rcal diagnose` all start from it.
 *
 * Depends on: the core (rc_model, rc_solve), rch_robot, rch_positions; never
 * on the pipeline (rch_calib.h) nor rch_evaluate.h, which both use it.
 * Memory: the caller's model and solver scratch; a temporary copy of the
 * samples while an outlet is guessed. Errors: 0, or -1 with d set.
 */
#ifndef RCH_START_H
#define RCH_START_H

#include <stddef.h>

#include "rc_solve.h"
#include "rch_diag.h"
#include "rch_robot.h"

/* Iteration cap of the encoder-only fit of the BC model. */
#define RCH_CALIB_BC_MAX_ITER 200

/* BC model from the samples (n): start = nominal as given (the caller chooses
 * which effects it carries; they stay at their values), encoder from nominal
 * when has_encoder, else from rc_encoder_guess; then the encoder alone fitted
 * (LM, at most RCH_CALIB_BC_MAX_ITER iterations). w: solver scratch. Returns 0
 * or -1 with d set. */
int rch_calib_bc(rc_model *start, rc_solve_work *w, const rc_model *nominal, int has_encoder, const rc_sample *s,
                 size_t n, rch_diag *d);

/* rch_calib_bc with the robot file's model and encoder. */
int rch_calib_start(rc_model *start, rc_solve_work *w, const rch_robot *robot, const rc_sample *train, size_t n,
                    rch_diag *d);

#endif
