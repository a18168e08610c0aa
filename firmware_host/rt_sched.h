/* SPDX-License-Identifier: MIT */
/* rt_sched.h - rcal-rt's real-time set-up (--cpu, --fifo) and clocks, one
 * definition for the file loop, the KUKA RSI partner and the ABB EGM sensor. */
#ifndef RT_SCHED_H
#define RT_SCHED_H

#include <stddef.h>
#include <sys/types.h>

struct sockaddr_in;
struct timespec;

/* Pin to CPU cpu (pin nonzero) and, with fifo, run as SCHED_FIFO priority 80
 * with memory locked. Each refusal is a note on stderr, never fatal. 1 when
 * SCHED_FIFO was granted, else 0. */
int rt_sched_realtime(int pin, unsigned long cpu, int fifo);
/* CLOCK_MONOTONIC, in ns. */
double rt_sched_now_ns(void);
/* The calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID), in ns. */
double rt_sched_cpu_ns(void);

/* One datagram from fd (SO_TIMESTAMPNS set on it) with the kernel's arrival
 * time: recvmsg with flags (0 or MSG_DONTWAIT). rx: the kernel's stamp
 * (CLOCK_REALTIME), the read's time when there is none; read_at (NULL: not
 * wanted) the read's time; from (NULL: not wanted) the sender; trunc (NULL:
 * not wanted) nonzero when the datagram was longer than cap. recvmsg's
 * return. The one definition for the RSI loop and both benches. */
ssize_t rt_sched_recv_stamped(int fd, void *buf, size_t cap, int flags, struct sockaddr_in *from, struct timespec *rx,
                              struct timespec *read_at, int *trunc);
/* t in ns. */
double rt_sched_ts_ns(const struct timespec *t);

#endif /* RT_SCHED_H */
