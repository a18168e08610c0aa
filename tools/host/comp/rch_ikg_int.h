/* SPDX-License-Identifier: MIT */
/* rch_ikg_int.h - inside the general IK: its closed-form starts
 * (rch_ikg_seed.c). */
#ifndef RCH_IKG_INT_H
#define RCH_IKG_INT_H

#include "rch_ikg.h"

/* Idealisation of a table for the starts (rch_ikg_seed.c). */
#define RCH_IKG_IDEAL_DEG 3.0
#define RCH_IKG_IDEAL_MM 2.0

/* ik->cls, ik->ideal, ik->ideal_model from m. */
void rch_ikg_seed_init(rch_ikg *ik, const rc_model *m);

/* The idealised arm's closed-form solutions of the TCP pose (pt, Rt):
 * out (8 x 6); returns how many (0: no class, or no solution). */
int rch_ikg_seeds(double out[8][RC_NJ], const rch_ikg *ik, const double pt[3], const double Rt[9]);

#endif
