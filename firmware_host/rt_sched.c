/* SPDX-License-Identifier: MIT */
/* rt_sched.c - rcal-rt's real-time set-up (rt_sched.h). */
#include "rt_sched.h"

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

int rt_sched_realtime(int pin, unsigned long cpu, int fifo)
{
    int fifo_on = 0;
    if (pin) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET((size_t)cpu, &set);
        if (sched_setaffinity(0, sizeof set, &set) != 0)
            fprintf(stderr, "rcal-rt: note: cannot pin to CPU %lu: %s\n", cpu, strerror(errno));
    }
    if (fifo) {
        struct sched_param sp;
        memset(&sp, 0, sizeof sp);
        sp.sched_priority = 80;
        if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
            fprintf(stderr, "rcal-rt: note: SCHED_FIFO refused (%s); running as a normal process\n", strerror(errno));
        else
            fifo_on = 1;
        if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
            fprintf(stderr, "rcal-rt: note: mlockall refused (%s)\n", strerror(errno));
    }
    return fifo_on;
}

double rt_sched_now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

double rt_sched_cpu_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}
