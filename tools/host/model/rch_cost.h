/* SPDX-License-Identifier: MIT */
/* rch_cost.h - what a long command will cost, before it starts, and how far
 * it is while it runs (issue 23: "costs that are not what they say").
 *
 * An estimate is a count of work units (what the command will do: rows x
 * iterations x cases, or row fits per method) times the measured cost of a
 * unit on the reference machine (the development machine, one core of a
 * shared 2-core VM; the figures and how they were measured are in
 * docs/methods.md, "Cost estimates"). A timed probe at start was tried and
 * dropped: on a shared machine it varied by a factor of 3 from run to run,
 * more than the estimate may be off. The work counts are exact; a faster
 * machine finishes sooner than said.
 *
 * Progress (rch_progress): "DONE of TOTAL UNIT, ELAPSED s, about LEFT s
 * left" on a stream at most every 5 s, only when the estimate is above 10 s.
 *
 * Host side (prefix rch_): a clock, no heap.
 */
#ifndef RCH_COST_H
#define RCH_COST_H

#include <stdio.h>

/* Seconds of `units` units of ref_us_per_unit microseconds each. */
double rch_cost_scale_s(double ref_us_per_unit, double units);

/* Monotonic wall clock, seconds. */
double rch_cost_now_s(void);

typedef struct rch_progress {
    FILE *f;           /* NULL: silent */
    const char *what;  /* "rcal calibrate: case" */
    double total;      /* units */
    double t0_s, last_s;
    int on;            /* the estimate was above 10 s */
} rch_progress;

void rch_progress_start(rch_progress *p, FILE *f, const char *what, double total, double estimate_s);
/* done units so far; prints at most every 5 s */
void rch_progress_step(rch_progress *p, double done);

/* "1.2 s", "3.4 min", "5.6 h", "7.8 days" */
const char *rch_cost_human(char *buf, size_t len, double s);

#endif
