/* SPDX-License-Identifier: MIT */
/* rch_acqtime.h - rcal's own time per pose over the controller link (issue 48).
 *
 * A pose recorded over the link passes, on rcal's side, from the controller's
 * accepted `AT J` to rcal's next command (NEXT / BACK / AGAIN / STOP):
 *
 *   t_at ── WAIT, --settle-ms ── t_settled ── display frames until the
 *   stability rule gives the sample ── t_sample ── follow check, append
 *   (fsync), progress ── t_cmd (the next command sent)
 *
 * rcal's own time of the pose is (t_cmd - t_at) - settle_ms - (t_sample -
 * t_settled): everything but the settle it was told to wait and the time
 * the display's frames took to satisfy the stability rule (--samples-per-pose
 * readings within --stable-mm, at the display's rate). A sleep past settle_ms
 * counts as rcal's. The display's part and the controller's move (command to
 * AT) are kept beside it, and rcal's CPU time (getrusage: user + system)
 * from one command to the next. Only poses whose sample was accepted count.
 *
 * The clocks are passed in (rch_acqtime_clock_ms, rch_acqtime_cpu_ms in the
 * run; a test's own numbers in the tests). Host side (prefix rch_): heap.
 */
#ifndef RCH_ACQTIME_H
#define RCH_ACQTIME_H

#include <stddef.h>

typedef enum rch_acqtime_ev {
    RCH_ACQTIME_CMD,     /* a command sent to the controller (closes a pending pose) */
    RCH_ACQTIME_AT,      /* its AT accepted */
    RCH_ACQTIME_SETTLED, /* --settle-ms waited */
    RCH_ACQTIME_SAMPLE,  /* the stability rule gave the sample */
    RCH_ACQTIME_KEPT     /* the sample accepted (recorded or held): the pose counts at the next command */
} rch_acqtime_ev;

typedef struct rch_acqtime_stats {
    size_t n;                                  /* poses timed */
    double own_ms_median, own_ms_p95, own_ms_max;
    double display_ms_median, display_ms_max;  /* t_sample - t_settled */
    double move_ms_median, move_ms_max;        /* command to AT (the controller's move) */
    double cpu_ms_median, cpu_ms_max;          /* rcal's CPU time, command to command */
} rch_acqtime_stats;

typedef struct rch_acqtime {
    double *own_ms, *display_ms, *move_ms, *cpu_ms; /* (cap) */
    size_t n, cap;
    double settle_ms;
    double t_cmd, t_at, t_settled, t_sample, cpu_cmd; /* this pose's marks; cpu at its command */
    int have_cmd, have_sample, kept;
} rch_acqtime;

/* Room for cap poses, settle_ms the run's --settle-ms. 0, or -1 (out of memory). */
int rch_acqtime_init(rch_acqtime *t, size_t cap, double settle_ms);
void rch_acqtime_free(rch_acqtime *t);

/* The event at monotonic time now_ms, rcal's CPU time cpu_ms so far. */
void rch_acqtime_mark(rch_acqtime *t, rch_acqtime_ev ev, double now_ms, double cpu_ms);

/* Median, 95th percentile (nearest rank) and largest of the poses timed; all 0 when none. 0, or -1. */
int rch_acqtime_stats_of(rch_acqtime_stats *s, const rch_acqtime *t);

double rch_acqtime_clock_ms(void); /* CLOCK_MONOTONIC */
double rch_acqtime_cpu_ms(void);   /* getrusage(RUSAGE_SELF): user + system */

#endif
