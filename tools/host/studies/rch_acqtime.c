/* SPDX-License-Identifier: MIT */
/* rch_acqtime.c - rcal's own time per pose over the controller link (see rch_acqtime.h). */
#include "rch_acqtime.h"

#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

int rch_acqtime_init(rch_acqtime *t, size_t cap, double settle_ms)
{
    memset(t, 0, sizeof *t);
    t->cap = cap ? cap : 1;
    t->settle_ms = settle_ms;
    t->own_ms = malloc(t->cap * sizeof *t->own_ms);
    t->display_ms = malloc(t->cap * sizeof *t->display_ms);
    t->move_ms = malloc(t->cap * sizeof *t->move_ms);
    t->cpu_ms = malloc(t->cap * sizeof *t->cpu_ms);
    if (!t->own_ms || !t->display_ms || !t->move_ms || !t->cpu_ms) {
        rch_acqtime_free(t);
        return -1;
    }
    return 0;
}

void rch_acqtime_free(rch_acqtime *t)
{
    free(t->own_ms);
    free(t->display_ms);
    free(t->move_ms);
    free(t->cpu_ms);
    memset(t, 0, sizeof *t);
}

void rch_acqtime_mark(rch_acqtime *t, rch_acqtime_ev ev, double now_ms, double cpu_ms)
{
    switch (ev) {
    case RCH_ACQTIME_CMD:
        if (t->kept && t->have_sample && t->n < t->cap) {
            const double disp = t->t_sample - t->t_settled;
            t->own_ms[t->n] = (now_ms - t->t_at) - t->settle_ms - disp;
            t->display_ms[t->n] = disp;
            t->move_ms[t->n] = t->t_at - t->t_cmd;
            t->cpu_ms[t->n] = cpu_ms - t->cpu_cmd;
            t->n++;
        }
        t->t_cmd = now_ms;
        t->cpu_cmd = cpu_ms;
        t->have_cmd = 1;
        t->have_sample = t->kept = 0;
        break;
    case RCH_ACQTIME_AT:
        t->t_at = now_ms;
        t->t_settled = now_ms + t->settle_ms; /* until SETTLED says when */
        break;
    case RCH_ACQTIME_SETTLED:
        t->t_settled = now_ms;
        break;
    case RCH_ACQTIME_SAMPLE:
        t->t_sample = now_ms;
        t->have_sample = 1;
        break;
    case RCH_ACQTIME_KEPT:
        t->kept = t->have_cmd;
        break;
    }
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* median, nearest-rank 95th percentile and max of v[0..n) (n >= 1) through tmp */
static void summarise(double *med, double *p95, double *max, const double *v, size_t n, double *tmp)
{
    size_t k95;
    memcpy(tmp, v, n * sizeof *tmp);
    qsort(tmp, n, sizeof *tmp, cmp_double);
    *med = n % 2 ? tmp[n / 2] : 0.5 * (tmp[n / 2 - 1] + tmp[n / 2]);
    k95 = (95u * n + 99u) / 100u; /* ceil(0.95 n), 1-based */
    if (p95)
        *p95 = tmp[(k95 ? k95 : 1) - 1];
    *max = tmp[n - 1];
}

int rch_acqtime_stats_of(rch_acqtime_stats *s, const rch_acqtime *t)
{
    double *tmp;
    memset(s, 0, sizeof *s);
    if (!t->n)
        return 0;
    tmp = malloc(t->n * sizeof *tmp);
    if (!tmp)
        return -1;
    s->n = t->n;
    summarise(&s->own_ms_median, &s->own_ms_p95, &s->own_ms_max, t->own_ms, t->n, tmp);
    summarise(&s->display_ms_median, NULL, &s->display_ms_max, t->display_ms, t->n, tmp);
    summarise(&s->move_ms_median, NULL, &s->move_ms_max, t->move_ms, t->n, tmp);
    summarise(&s->cpu_ms_median, NULL, &s->cpu_ms_max, t->cpu_ms, t->n, tmp);
    free(tmp);
    return 0;
}

double rch_acqtime_clock_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

double rch_acqtime_cpu_ms(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0.0;
    return (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) * 1e3 +
           (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-3;
}
