/* SPDX-License-Identifier: MIT */
/* rc_stable.c - the stability rule (see rc_stable.h). */
#include "rc_stable.h"

#include <math.h>
#include <string.h>

void rc_stable_config_default(rc_stable_config *c)
{
    c->n = 5u;
    c->tol_mm = 0.05;
    c->min_mm = 1.0;
    c->max_mm = 20000.0;
    c->timeout_ms = 60000u;
    c->tau_ms = 0u;
    c->learn_tau = 1;
    c->tau_max_ms = 30000u;
}

rc_status rc_stable_init(rc_stable *s, const rc_stable_config *c)
{
    if (!s || !c)
        return RC_ERR_ARG;
    if (c->n < 1u || c->n > (unsigned)RC_STABLE_MAX_N || !(c->tol_mm >= 0.0) || !isfinite(c->tol_mm) ||
        !(c->min_mm < c->max_mm) || !isfinite(c->min_mm) || !isfinite(c->max_mm) ||
        (c->learn_tau && c->tau_max_ms == 0u))
        return RC_ERR_ARG;
    memset(s, 0, sizeof *s);
    s->cfg = *c;
    return RC_OK;
}

void rc_stable_restart(rc_stable *s)
{
    rc_stable_config c = s->cfg;
    double tau = s->tau_learnt_ms;
    memset(s, 0, sizeof *s);
    s->cfg = c;
    s->tau_learnt_ms = tau;
}

void rc_stable_clear_window(rc_stable *s)
{
    s->nw = 0u;
    s->nh = 0u;
    s->h_next = 0u;
}

/* no libm on the reading path (it is cross-built for a microcontroller) */
static double absd(double x)
{
    return x < 0.0 ? -x : x;
}

/* natural logarithm of x > 0: x = 2^k y, y in [1, 2), ln y = 2 atanh((y - 1)/(y + 1)) */
static double ln_pos(double x)
{
    double k = 0.0, z, z2, term, sum = 0.0;
    while (x >= 2.0) {
        x *= 0.5;
        k += 1.0;
    }
    while (x < 1.0) {
        x *= 2.0;
        k -= 1.0;
    }
    z = (x - 1.0) / (x + 1.0); /* [0, 1/3) */
    z2 = z * z;
    term = z;
    for (int j = 1; j < 40; j += 2) {
        sum += term / (double)j;
        term *= z2;
    }
    return k * 0.69314718055994530942 + 2.0 * sum;
}

/* Learn tau from the ring (see rc_stable.h): quarters, d1/d2 = d2/d3 =
 * exp(dt/tau). */
static void learn(rc_stable *s)
{
    const unsigned k = s->nh / 4u, first = (s->h_next + RC_STABLE_MAX_N - s->nh) % RC_STABLE_MAX_N;
    const uint32_t t_ref = s->hist_t[first];
    double m[4] = {0, 0, 0, 0}, t[4] = {0, 0, 0, 0}, d[3], l1, l2, dt, tau;
    if (k < 3u)
        return;
    for (unsigned part = 0; part < 4u; ++part)
        for (unsigned j = 0; j < k; ++j) {
            /* the last 4k readings, oldest first */
            const unsigned idx = (first + (s->nh - 4u * k) + part * k + j) % RC_STABLE_MAX_N;
            m[part] += s->hist[idx] / (double)k;
            t[part] += (double)(uint32_t)(s->hist_t[idx] - t_ref) / (double)k;
        }
    for (int q = 0; q < 3; ++q)
        d[q] = m[q + 1] - m[q];
    dt = (t[3] - t[0]) / 3.0;
    if (!(d[0] * d[1] > 0.0) || !(d[1] * d[2] > 0.0) || !(absd(d[2]) >= 0.5 * s->cfg.tol_mm) || !(dt > 0.0))
        return;
    l1 = ln_pos(d[0] / d[1]);
    l2 = ln_pos(d[1] / d[2]);
    /* an exponential: both ratios above 1.05 and alike (a step or a ramp that stops is not) */
    if (!(l1 > 0.0488 && l2 > 0.0488) || l1 > 2.0 * l2 || l2 > 2.0 * l1)
        return;
    tau = 2.0 * dt / (l1 + l2);
    if (tau > (double)s->cfg.tau_max_ms)
        tau = (double)s->cfg.tau_max_ms;
    if (tau > s->tau_learnt_ms)
        s->tau_learnt_ms = tau;
}

/* least-squares slope (mm/ms) of the window and its duration (ms) */
static double window_slope(const rc_stable *s, double *dur_ms)
{
    double tm = 0.0, vm = 0.0, sxy = 0.0, sxx = 0.0;
    const uint32_t t0 = s->win_t[0];
    for (unsigned m = 0; m < s->nw; ++m) {
        tm += (double)(uint32_t)(s->win_t[m] - t0) / (double)s->nw;
        vm += s->win[m] / (double)s->nw;
    }
    for (unsigned m = 0; m < s->nw; ++m) {
        const double dx = (double)(uint32_t)(s->win_t[m] - t0) - tm;
        sxx += dx * dx;
        sxy += dx * (s->win[m] - vm);
    }
    *dur_ms = (double)(uint32_t)(s->win_t[s->nw - 1u] - t0);
    return sxx > 0.0 ? sxy / sxx : 0.0;
}

/* least-squares slope (mm/ms) of the ring's readings of the last span_ms
 * (a display that rounds to 0.01 mm hides a slow creep in n readings) */
static double ring_slope(const rc_stable *s, double span_ms)
{
    const unsigned newest = (s->h_next + RC_STABLE_MAX_N - 1u) % RC_STABLE_MAX_N;
    double tm = 0.0, vm = 0.0, sxy = 0.0, sxx = 0.0;
    unsigned m = 0;
    while (m < s->nh) {
        const unsigned idx = (newest + RC_STABLE_MAX_N - m) % RC_STABLE_MAX_N;
        if ((double)(uint32_t)(s->hist_t[newest] - s->hist_t[idx]) > span_ms)
            break;
        ++m;
    }
    for (unsigned j = 0; j < m; ++j) {
        const unsigned idx = (newest + RC_STABLE_MAX_N - j) % RC_STABLE_MAX_N;
        tm -= (double)(uint32_t)(s->hist_t[newest] - s->hist_t[idx]) / (double)m;
        vm += s->hist[idx] / (double)m;
    }
    for (unsigned j = 0; j < m; ++j) {
        const unsigned idx = (newest + RC_STABLE_MAX_N - j) % RC_STABLE_MAX_N;
        const double dx = -(double)(uint32_t)(s->hist_t[newest] - s->hist_t[idx]) - tm;
        sxx += dx * dx;
        sxy += dx * (s->hist[idx] - vm);
    }
    return sxx > 0.0 ? sxy / sxx : 0.0;
}

double rc_stable_tau_ms(const rc_stable *s)
{
    const double set = (double)s->cfg.tau_ms;
    return s->cfg.learn_tau && s->tau_learnt_ms > set ? s->tau_learnt_ms : set;
}

/* max - min of win[from..nw-1] together with v */
static double span(const rc_stable *s, unsigned from, double v)
{
    double lo = v, hi = v;
    for (unsigned m = from; m < s->nw; ++m) {
        lo = s->win[m] < lo ? s->win[m] : lo;
        hi = s->win[m] > hi ? s->win[m] : hi;
    }
    return hi - lo;
}

rc_status rc_stable_push(rc_stable *s, rc_stable_result *out, double len_mm, uint32_t t_ms)
{
    unsigned k;
    if (!s || !out)
        return RC_ERR_ARG;
    if (!s->started) {
        s->started = 1;
        s->t_start_ms = t_ms;
    } else if (s->cfg.timeout_ms != 0u && (uint32_t)(t_ms - s->t_start_ms) > s->cfg.timeout_ms) {
        return RC_ERR_TIMEOUT;
    }
    s->pushed++;
    if (!(len_mm >= s->cfg.min_mm && len_mm <= s->cfg.max_mm)) {
        s->range_rejects++;
        s->nw = 0u;
        return RC_ERR_RANGE;
    }
    s->hist[s->h_next] = len_mm;
    s->hist_t[s->h_next] = t_ms;
    s->h_next = (s->h_next + 1u) % RC_STABLE_MAX_N;
    if (s->nh < RC_STABLE_MAX_N)
        s->nh++;
    if (s->cfg.learn_tau)
        learn(s);
    /* keep the longest tail of the window that agrees with the new reading */
    k = s->nw;
    while (k > 0u && span(s, k - 1u, len_mm) <= s->cfg.tol_mm)
        --k;
    if (k > 0u) {
        s->restarts++;
        memmove(s->win, s->win + k, (size_t)(s->nw - k) * sizeof s->win[0]);
        memmove(s->win_t, s->win_t + k, (size_t)(s->nw - k) * sizeof s->win_t[0]);
        s->nw -= k;
    }
    if (s->nw == s->cfg.n) { /* full (n == 1 .. after a tail of n): drop the oldest */
        memmove(s->win, s->win + 1, (size_t)(s->nw - 1u) * sizeof s->win[0]);
        memmove(s->win_t, s->win_t + 1, (size_t)(s->nw - 1u) * sizeof s->win_t[0]);
        s->nw--;
    }
    s->win[s->nw] = len_mm;
    s->win_t[s->nw++] = t_ms;
    if (s->nw < s->cfg.n)
        return RC_ERR_INCOMPLETE;
    {
        double dur_ms, tau = rc_stable_tau_ms(s), slope = window_slope(s, &dur_ms); /* mm/ms */
        if (tau > 0.0) { /* the slope over the last tau as well: the larger counts */
            const double ring = ring_slope(s, tau > dur_ms ? tau : dur_ms);
            slope = absd(ring) > absd(slope) ? ring : slope;
        }
        if (absd(slope) * (tau + 0.5 * dur_ms) > s->cfg.tol_mm) {
            s->trend_rejects++; /* still creeping: the next reading slides the window */
            return RC_ERR_INCOMPLETE;
        }
        out->slope_mm_s = slope * 1000.0;
        out->tau_ms = tau;
    }
    {
        double sum = 0.0, lo = s->win[0], hi = s->win[0];
        for (unsigned m = 0; m < s->nw; ++m) {
            sum += s->win[m];
            lo = s->win[m] < lo ? s->win[m] : lo;
            hi = s->win[m] > hi ? s->win[m] : hi;
        }
        out->mean_mm = sum / (double)s->nw;
        out->spread_mm = hi - lo;
        out->count = s->nw;
    }
    s->nw = 0u;
    return RC_OK;
}
