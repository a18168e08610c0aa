/* SPDX-License-Identifier: MIT */
/* rt_sched.h - rcal-rt's real-time set-up (--cpu, --fifo) and clocks, one
 * definition for the file loop, the KUKA RSI partner and the ABB EGM sensor. */
#ifndef RT_SCHED_H
#define RT_SCHED_H

/* Pin to CPU cpu (pin nonzero) and, with fifo, run as SCHED_FIFO priority 80
 * with memory locked. Each refusal is a note on stderr, never fatal. 1 when
 * SCHED_FIFO was granted, else 0. */
int rt_sched_realtime(int pin, unsigned long cpu, int fifo);
/* CLOCK_MONOTONIC, in ns. */
double rt_sched_now_ns(void);
/* The calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID), in ns. */
double rt_sched_cpu_ns(void);

#endif /* RT_SCHED_H */
