/* SPDX-License-Identifier: MIT */
/* rch_cost.c - cost estimates and progress (see rch_cost.h). */
#include "rch_cost.h"

#include <string.h>
#include <time.h>


double rch_cost_now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

double rch_cost_scale_s(double ref_us_per_unit, double units)
{
    return ref_us_per_unit * units * 1e-6;
}

void rch_progress_start(rch_progress *p, FILE *f, const char *what, double total, double estimate_s)
{
    p->f = f;
    p->what = what;
    p->total = total;
    p->t0_s = p->last_s = rch_cost_now_s();
    p->on = estimate_s > 10.0 && f != NULL;
}

void rch_progress_step(rch_progress *p, double done)
{
    const double t = rch_cost_now_s();
    char b1[32], b2[32];
    if (!p->on || t - p->last_s < 5.0 || done <= 0.0)
        return;
    p->last_s = t;
    fprintf(p->f, "%s %.0f of %.0f, %s elapsed, about %s left\n", p->what, done, p->total,
            rch_cost_human(b1, sizeof b1, t - p->t0_s),
            rch_cost_human(b2, sizeof b2, (t - p->t0_s) * (p->total - done) / done));
    fflush(p->f);
}

const char *rch_cost_human(char *buf, size_t len, double s)
{
    if (s < 120.0)
        snprintf(buf, len, "%.1f s", s);
    else if (s < 7200.0)
        snprintf(buf, len, "%.1f min", s / 60.0);
    else if (s < 172800.0)
        snprintf(buf, len, "%.1f h", s / 3600.0);
    else
        snprintf(buf, len, "%.1f days", s / 86400.0);
    return buf;
}
