/* SPDX-License-Identifier: MIT */
/* rch_seen.c - the one vocabulary of what the data see (see rch_seen.h). */
#include "rch_seen.h"

#include <string.h>

const rch_seen_desc rch_seen_table[RCH_SEEN_COUNT] = {
    {RCH_SEEN_HELD, "held", "held", "fixed by the set-up (the gauge or the user): not estimated"},
    {RCH_SEEN_DATA, "data", "determined by the data",
     "posterior sd below 0.5 x the prior's (the data carry at least 3 x the prior's information); with no prior "
     "on it: identifiable"},
    {RCH_SEEN_PARTLY, "partly", "partly determined",
     "posterior sd 0.5 to 0.9 x the prior's: data and prior share in it; with no prior on it: weakly identifiable"},
    {RCH_SEEN_PRIOR, "prior_only", "prior only",
     "the data do not see it: posterior sd at least 0.9 x the prior's; it stays where the drawing puts it, with "
     "the prior's uncertainty"},
    {RCH_SEEN_UNSEEN, "unseen", "not seen by the data",
     "no prior on it and not identifiable: it stays where it started, its value means nothing alone"},
};

rch_seen rch_seen_of(rch_param_class cls, rch_prior_class pcls, int has_prior)
{
    if (cls == RCH_PARAM_FIXED)
        return RCH_SEEN_HELD;
    if (has_prior && pcls != RCH_PRIOR_CLASS_NONE)
        return pcls == RCH_PRIOR_CLASS_DETERMINED ? RCH_SEEN_DATA
                                                  : pcls == RCH_PRIOR_CLASS_PARTLY ? RCH_SEEN_PARTLY : RCH_SEEN_PRIOR;
    return cls == RCH_PARAM_IDENTIFIABLE ? RCH_SEEN_DATA : cls == RCH_PARAM_WEAK ? RCH_SEEN_PARTLY : RCH_SEEN_UNSEEN;
}

rch_seen rch_seen_of_unc(const rch_model_unc *u, unsigned k)
{
    const int prior = u->has_prior && u->prior_sd[k] > 0.0;
    return rch_seen_of((rch_param_class)u->cls[k], (rch_prior_class)u->prior_cls[k], prior);
}

const char *rch_seen_words(rch_seen c)
{
    return (unsigned)c < RCH_SEEN_COUNT ? rch_seen_table[c].words : "?";
}

const char *rch_seen_key(rch_seen c)
{
    return (unsigned)c < RCH_SEEN_COUNT ? rch_seen_table[c].key : "?";
}

int rch_seen_parse(const char *s)
{
    for (unsigned k = 0; s && k < RCH_SEEN_COUNT; ++k)
        if (strcmp(s, rch_seen_table[k].key) == 0 || strcmp(s, rch_seen_table[k].words) == 0)
            return (int)k;
    return -1;
}

const char *rch_seen_why(rch_seen c, rch_param_class cls)
{
    switch (cls) {
    case RCH_PARAM_NOT_IDENTIFIABLE:
        return c == RCH_SEEN_DATA || c == RCH_SEEN_PARTLY
                   ? "alone in a direction the data cannot see; its combination with others is seen"
                   : "in a direction the data cannot see";
    case RCH_PARAM_WEAK: return "in a direction the data see only weakly";
    case RCH_PARAM_IDENTIFIABLE:
        return c == RCH_SEEN_PRIOR ? "the data see it, but no sharper than the prior already knows it"
               : c == RCH_SEEN_PARTLY ? "the data see it, about as sharply as the prior knows it"
                                      : "";
    case RCH_PARAM_FIXED: break;
    }
    return "";
}
