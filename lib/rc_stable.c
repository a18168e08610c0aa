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
}

rc_status rc_stable_init(rc_stable *s, const rc_stable_config *c)
{
    if (!s || !c)
        return RC_ERR_ARG;
    if (c->n < 1u || c->n > (unsigned)RC_STABLE_MAX_N || !(c->tol_mm >= 0.0) || !isfinite(c->tol_mm) ||
        !(c->min_mm < c->max_mm) || !isfinite(c->min_mm) || !isfinite(c->max_mm))
        return RC_ERR_ARG;
    memset(s, 0, sizeof *s);
    s->cfg = *c;
    return RC_OK;
}

void rc_stable_restart(rc_stable *s)
{
    rc_stable_config c = s->cfg;
    memset(s, 0, sizeof *s);
    s->cfg = c;
}

void rc_stable_clear_window(rc_stable *s)
{
    s->nw = 0u;
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
    /* keep the longest tail of the window that agrees with the new reading */
    k = s->nw;
    while (k > 0u && span(s, k - 1u, len_mm) <= s->cfg.tol_mm)
        --k;
    if (k > 0u) {
        s->restarts++;
        memmove(s->win, s->win + k, (size_t)(s->nw - k) * sizeof s->win[0]);
        s->nw -= k;
    }
    if (s->nw == s->cfg.n) { /* full (n == 1 .. after a tail of n): drop the oldest */
        memmove(s->win, s->win + 1, (size_t)(s->nw - 1u) * sizeof s->win[0]);
        s->nw--;
    }
    s->win[s->nw++] = len_mm;
    if (s->nw < s->cfg.n)
        return RC_ERR_INCOMPLETE;
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
