/* SPDX-License-Identifier: MIT */
/* rch_groups.h - set-up groups of an acquisition when the file does not
 * name them: consecutive samples whose wrist joints (q4..q6) stay the same
 * were taken in one set-up (the wrist is re-oriented between set-ups). A
 * wrist reading that flickers by one display step (an angle on a rounding
 * boundary) does not start a new group. Used by the cluster-robust
 * covariance of `rcal calibrate` and by `rcal diagnose`.
 * Host side (prefix rch_). */
#ifndef RCH_GROUPS_H
#define RCH_GROUPS_H

#include <stddef.h>

#include "rc_model.h"

/* Label s[i].group (s: n samples in acquisition order); q_step_deg is the
 * joints' display step (0 or less: exact equality). *flicker (may be NULL)
 * counts samples whose wrist moved by no more than 1.5 steps. Returns the
 * number of groups. */
unsigned rch_groups_by_wrist(rc_sample *s, size_t n, double q_step_deg, unsigned *flicker);

#endif
