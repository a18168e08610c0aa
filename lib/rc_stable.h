/* SPDX-License-Identifier: MIT */
/* rc_stable.h - the stability rule: display readings in, one sample out.
 *
 * What: a pose's cable length is the mean of `n` consecutive readings whose
 * max - min <= tol_mm. Readings are pushed one at a time, with the time they
 * arrived; each push says whether a sample is ready. A reading outside
 * [min_mm, max_mm] is rejected and restarts the window (a value the cable
 * cannot have says nothing about stability); a reading that disagrees with
 * the window drops the oldest readings until the rest agrees with it (the
 * longest agreeing tail is kept, so a drifting value settles as soon as it
 * stops). When the first reading of the pose is older than timeout_ms, the
 * rule gives up (RC_ERR_TIMEOUT): the arm is still moving or vibrating.
 *
 * No trend (issue 23): a display that filters its readings (a first-order
 * low-pass of time constant tau) creeps towards the true length; n readings
 * may agree within tol_mm while it is still far off (a step of 100 mm through a
 * 2 s filter, read at 20 Hz, passes the spread test 0.52 mm short, through a
 * 5 s one 1.48 mm: tests/lib/test_stable.c; with the trend test 0.03 mm). A full
 * window is accepted only when the change still to come, extrapolated from
 * the window's least-squares slope, is within tol_mm:
 *     |slope| * (tau + w/2) <= tol_mm      (w: the window's duration)
 * which for a first-order filter bounds the recorded error by tol_mm. tau is
 * the larger of cfg.tau_ms (set: the display's data sheet) and the one learnt
 * from the readings (cfg.learn_tau): the last RC_STABLE_MAX_N readings of the
 * pose are cut into four equal parts; an exponential approach shows as
 * changes d1, d2, d3 between their means of one sign with d1/d2 and d2/d3
 * alike (their logarithms within a factor of 2), both above 1.05, and
 * |d3| >= tol_mm/2 (well above the display's noise; a step or a ramp that
 * stops is not an exponential); then tau = dt / mean(ln(d1/d2), ln(d2/d3)),
 * capped at tau_max_ms. The learnt tau is a
 * property of the device: it is kept across poses (rc_stable_restart) and
 * only grows. A window that fails the trend test slides by one reading.
 *
 * This is the second step of the data path: serial byte -> reading
 * (drivers/rcd_proto, rcd_display) -> sample (this rule) -> acquisition file
 * (tools/host/files/rch_acqfile) -> fit.
 *
 * Depends on: rc_status.h only. No heap, no stdio, no clock: the caller
 * passes the time of each reading (any monotonic millisecond counter; a
 * 32-bit counter wraps after 49.7 days and differences are taken modulo
 * 2^32, so a pose may last up to 24.8 days).
 * Memory: rc_stable is caller-owned (RC_STABLE_MAX_N doubles inside).
 * Thread safety: one rc_stable per thread.
 * Errors: rc_stable_init RC_ERR_ARG for an invalid config (n outside
 * 1..RC_STABLE_MAX_N, tol_mm < 0 or not finite, min_mm >= max_mm,
 * learn_tau with tau_max_ms 0);
 * rc_stable_push see below.
 */
#ifndef RC_STABLE_H
#define RC_STABLE_H

#include <stdint.h>

#include "rc_status.h"

#ifndef RC_STABLE_MAX_N
#define RC_STABLE_MAX_N 64
#endif
#if RC_STABLE_MAX_N < 1
#error "RC_STABLE_MAX_N must be at least 1"
#endif

typedef struct rc_stable_config {
    unsigned n;          /* readings per sample, 1..RC_STABLE_MAX_N */
    double tol_mm;       /* max - min of the n readings, >= 0 */
    double min_mm;       /* physical range of a reading, min_mm < max_mm */
    double max_mm;
    uint32_t timeout_ms; /* give up this long after the pose's first reading; 0: never */
    uint32_t tau_ms;     /* the display's filter time constant, when known; 0: none known */
    int learn_tau;       /* 1: learn tau from the readings as well (the larger counts) */
    uint32_t tau_max_ms; /* cap of the learnt tau, >= 1 when learn_tau */
} rc_stable_config;

/* The rule as `rcal acquire` uses it by default: n 5, tol 0.05 mm, range
 * [1, 20000] mm, timeout 60 s, tau 0 and learnt (cap 30 s). */
void rc_stable_config_default(rc_stable_config *c);

typedef struct rc_stable_result {
    double mean_mm;   /* mean of the n readings */
    double spread_mm; /* max - min of the n readings */
    unsigned count;   /* n */
    double slope_mm_s; /* least-squares slope of the n readings, mm/s */
    double tau_ms;     /* the time constant the trend test used */
} rc_stable_result;

typedef struct rc_stable {
    rc_stable_config cfg;
    double win[RC_STABLE_MAX_N]; /* (nw) the current agreeing window, oldest first */
    uint32_t win_t[RC_STABLE_MAX_N]; /* (nw) their times */
    unsigned nw;
    double hist[RC_STABLE_MAX_N];    /* ring of the pose's last in-range readings (learning tau) */
    uint32_t hist_t[RC_STABLE_MAX_N];
    unsigned nh, h_next;             /* readings in the ring, next slot */
    double tau_learnt_ms;            /* kept across rc_stable_restart; 0: none learnt */
    int started;                 /* t_start is set */
    uint32_t t_start_ms;         /* time of the pose's first reading */
    /* counters since init/restart */
    unsigned long pushed;        /* readings pushed */
    unsigned long range_rejects; /* readings outside [min_mm, max_mm] */
    unsigned long restarts;      /* readings that disagreed with the window */
    unsigned long trend_rejects; /* full windows refused for their trend */
} rc_stable;

/* Start a pose with config c (copied). RC_OK or RC_ERR_ARG. */
rc_status rc_stable_init(rc_stable *s, const rc_stable_config *c);
/* Start over for a new pose (same config, counters cleared, learnt tau kept). */
void rc_stable_restart(rc_stable *s);
/* Forget the window but keep the pose's start time and counters (after a
 * reconnect: readings before and after are not consecutive). */
void rc_stable_clear_window(rc_stable *s);

/* Push one reading len_mm that arrived at t_ms. Returns
 *   RC_OK             a sample is ready in *out (the window restarts empty);
 *   RC_ERR_INCOMPLETE keep reading (also: a full window with a trend);
 *   RC_ERR_RANGE      the reading is outside [min_mm, max_mm] or not finite:
 *                     rejected, window cleared; keep reading;
 *   RC_ERR_TIMEOUT    timeout_ms passed since the pose's first reading
 *                     without a sample (checked before the reading is used);
 *   RC_ERR_ARG        s or out NULL.
 * out may be written only on RC_OK. */
rc_status rc_stable_push(rc_stable *s, rc_stable_result *out, double len_mm, uint32_t t_ms);

/* The time constant (ms) the trend test uses now: max(cfg.tau_ms, learnt). */
double rc_stable_tau_ms(const rc_stable *s);

#endif /* RC_STABLE_H */
