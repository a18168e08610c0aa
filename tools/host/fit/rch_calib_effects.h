/* SPDX-License-Identifier: MIT */
/* rch_calib_effects.h - what a fit carries, as the command line names it:
 * the method (--method), the effects added to the geometry (--effects), the
 * parameters held at nominal (--fix), and the nuisance a fitted model sheds
 * before it predicts a new pose.
 *
 * Depends on: the core (rc_model's effect table, rc_method_from_name),
 * rch_opt (numbers), rch_comp (rch_model_rebuild). Memory: none on the heap.
 * Errors: 0, or -1 with d naming the entry (rch_method_parse: -1 alone).
 */
#ifndef RCH_CALIB_EFFECTS_H
#define RCH_CALIB_EFFECTS_H

#include <stdint.h>

#include "rc_model.h"
#include "rc_solve.h"
#include "rch_diag.h"

/* Parse a method name (lm, ltlm, lm-paper, ltlm-paper). Returns 0 or -1. */
int rch_method_parse(rc_method *out, const char *name);

/* Add the effects of list to m: comma-separated, "length_offset",
 * "length_scale", "time_drift", "tool_offset", "cable_sag",
 * "length_nonlinearity", "length_periodic:P" (P the period's start value
 * in mm, 1..1000), "joint_compliance:J" (J = 2
 * or 3), "joint_periodic:J" (J = 1..6). 0, or -1 with d naming the entry. */
int rch_calib_effects(rc_model *m, const char *list, rch_diag *d);

/* A copy of m without its nuisance effects (group offsets, time drift):
 * they describe one acquisition, not the robot, and predict nothing at a new
 * pose. */
void rch_model_strip_nuisance(rc_model *out, const rc_model *m);

/* Mark the comma-separated parameter names of list (e.g. "a1,theta6") in
 * fixed (m->n_params). 0, or -1 with d naming the unknown parameter. */
int rch_calib_fix(uint8_t *fixed, const rc_model *m, const char *list, rch_diag *d);

#endif
