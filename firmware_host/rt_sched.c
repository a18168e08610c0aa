/* SPDX-License-Identifier: MIT */
/* rt_sched.c - rcal-rt's real-time set-up (rt_sched.h). */
#include "rt_sched.h"

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <netinet/in.h>
#include <sys/mman.h>
#include <sys/socket.h>
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

double rt_sched_ts_ns(const struct timespec *t)
{
    return (double)t->tv_sec * 1e9 + (double)t->tv_nsec;
}

ssize_t rt_sched_recv_stamped(int fd, void *buf, size_t cap, int flags, struct sockaddr_in *from, struct timespec *rx,
                              struct timespec *read_at, int *trunc)
{
    struct iovec iov = {buf, cap};
    char ctl[256];
    struct msghdr mh;
    memset(&mh, 0, sizeof mh);
    if (from) {
        mh.msg_name = from;
        mh.msg_namelen = sizeof *from;
    }
    mh.msg_iov = &iov;
    mh.msg_iovlen = 1;
    mh.msg_control = ctl;
    mh.msg_controllen = sizeof ctl;
    const ssize_t n = recvmsg(fd, &mh, flags);
    clock_gettime(CLOCK_REALTIME, rx);
    if (read_at)
        *read_at = *rx;
    for (struct cmsghdr *c = CMSG_FIRSTHDR(&mh); n > 0 && c; c = CMSG_NXTHDR(&mh, c))
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS)
            memcpy(rx, CMSG_DATA(c), sizeof *rx);
    if (trunc)
        *trunc = n >= 0 && (mh.msg_flags & MSG_TRUNC) != 0;
    return n;
}
