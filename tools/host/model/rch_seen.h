/* SPDX-License-Identifier: MIT */
/* rch_seen.h - what the data see of a parameter: the one vocabulary of
 * identifiability and data-vs-prior (prefix rch_seen_).
 *
 * Two facts describe a parameter after a calibration: its identifiability
 * (rch_param_class, from the singular values of the data's Jacobian:
 * lib/rc_ident.h) and, for a maximum a posteriori fit, how far the data
 * narrowed its prior (rch_prior_class: posterior sd / prior sd against
 * RCH_PRIOR_DETERMINED 0.5 and RCH_PRIOR_ONLY 0.9). Printed side by side
 * they contradict each other ("not identifiable" alone while its
 * combination with others is determined; "identifiable" with a posterior
 * as wide as the prior). Every output (the calibrate text and JSON, the
 * model file, the HTML report) prints instead ONE class made from both,
 * and the SVD fact as the why:
 *
 *   determined by the data   prior: posterior sd < 0.5 prior sd (the data
 *                            carry >= 3 x the prior's information); no
 *                            prior on it: identifiable
 *   partly determined        prior: 0.5 <= ratio < 0.9; no prior: weak
 *   prior only               prior: ratio >= 0.9: the data do not see it;
 *                            it stays where the drawing puts it, with the
 *                            prior's uncertainty
 *   not seen by the data     no prior on it and not identifiable: it stays
 *                            where it started (its value means nothing alone)
 *   held                     fixed by the set-up (the gauge, the user)
 *
 * With a prior the ratio decides (it is what every u95 carries); the SVD
 * class only explains. Depends on: rch_prior, rch_uncert (the enums only).
 * Memory: none. Thread safety: reentrant (static strings). */
#ifndef RCH_SEEN_H
#define RCH_SEEN_H

#include <stddef.h>

#include "rch_prior.h"
#include "rch_uncert.h"

typedef enum {
    RCH_SEEN_HELD = 0,
    RCH_SEEN_DATA = 1,
    RCH_SEEN_PARTLY = 2,
    RCH_SEEN_PRIOR = 3,
    RCH_SEEN_UNSEEN = 4
} rch_seen;

typedef struct rch_seen_desc {
    rch_seen c;
    const char *key;        /* JSON value ("data", "partly", "prior_only", "unseen", "held") */
    const char *words;      /* the class as every report prints it */
    const char *definition; /* one sentence with the threshold */
} rch_seen_desc;

/* The table, indexed by rch_seen (RCH_SEEN_COUNT entries). */
#define RCH_SEEN_COUNT 5
extern const rch_seen_desc rch_seen_table[RCH_SEEN_COUNT];

/* The one class of a parameter: cls its identifiability, pcls what the
 * data did to its prior (has_prior: the parameter has a prior sd > 0). */
rch_seen rch_seen_of(rch_param_class cls, rch_prior_class pcls, int has_prior);
/* Of parameter k of a model file's or a calibration's uncertainty. */
rch_seen rch_seen_of_unc(const rch_model_unc *u, unsigned k);
const char *rch_seen_words(rch_seen c);
const char *rch_seen_key(rch_seen c);
/* The class from its words or its key (report readers); -1: neither. */
int rch_seen_parse(const char *s);
/* Why (the SVD fact that explains the class), "" when nothing to add. */
const char *rch_seen_why(rch_seen c, rch_param_class cls);

#endif
