/* rch_calib.h - the calibration pipeline shared by rcal's commands.
 *
 * Start: nominal geometry; the encoder outlet from the robot file when it
 * has one, else from rc_encoder_guess; then the encoder alone is refined by
 * LM with the geometry held fixed. That start is also the "before
 * calibration" (BC) model: nominal robot, best encoder position. Then every
 * parameter is identified with the chosen method.
 */
#ifndef RCH_CALIB_H
#define RCH_CALIB_H

#include <stddef.h>

#include "rc_solve.h"
#include "rch_diag.h"
#include "rch_robot.h"

/* BC model from the training samples. Returns 0 or -1 with d set. */
int rch_calib_start(rc_model *start, rc_solve_work *w, const rch_robot *robot, const rc_sample *train,
                    size_t n, rch_diag *d);

/* Parse a method name (lm, ltlm, lm-paper, ltlm-paper). Returns 0 or -1. */
int rch_method_parse(rc_method *out, const char *name);

#endif
