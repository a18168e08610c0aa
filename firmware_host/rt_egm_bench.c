/* SPDX-License-Identifier: MIT */
/* rt_egm_bench.c - rcal-rt --egm-bench (docs/egm.md): a C controller sends
 * an EgmRobot every cycle (clock_nanosleep, absolute times) to two
 * responders at once, on loopback, each in its own process: rcal-rt's EGM
 * loop (rt_egm_run, a synthetic smooth path compensated with the model) and
 * a trivial C responder (receive, pack a fixed EgmSensor, send). Both see
 * the same schedule and the same machine in the same run (the order of the
 * two sends alternates every cycle). Reported per responder: the
 * controller's round trip and missed cycles (no reply before the next
 * cycle), the responder's own receive-to-send latency and CPU per cycle.
 * rcal-rt's replies are checked against the same targets compensated here
 * (to 1e-6 deg); exit status 1 when one differs or a reply is missing at
 * the end. Timing never decides the exit status. */
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "egm.pb-c.h"
#include "rt_egm.h"
#include "rt_sched.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)


/* the bench's path: each joint a slow sine of its own (radians), k at rate_hz */
typedef struct synth {
    unsigned long k;
    double rate_hz;
} synth;

static void synth_q(double q[RT_EGM_NJ], unsigned long k, double rate_hz)
{
    static const double c[RT_EGM_NJ] = {0.0, 0.35, -0.35, 0.0, 0.9, 0.0};
    static const double a[RT_EGM_NJ] = {1.2, 0.35, 0.35, 1.0, 0.5, 1.5};
    static const double f[RT_EGM_NJ] = {0.05, 0.07, 0.11, 0.13, 0.17, 0.19};
    const double t = (double)k / rate_hz;
    for (int i = 0; i < RT_EGM_NJ; ++i)
        q[i] = c[i] + a[i] * sin(2.0 * M_PI * f[i] * t + i);
}

static int synth_next(void *ctx, double q_rad[RT_EGM_NJ])
{
    synth *s = ctx;
    synth_q(q_rad, s->k++, s->rate_hz);
    return 1;
}

static int set_fifo(int prio)
{
    struct sched_param sp;
    memset(&sp, 0, sizeof sp);
    sp.sched_priority = prio;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
        return -1;
    mlockall(MCL_CURRENT | MCL_FUTURE);
    return 0;
}

static volatile sig_atomic_t triv_stop;
static void triv_signal(int sig)
{
    (void)sig;
    triv_stop = 1;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double pct(double *v, size_t n, double p)
{
    if (n == 0)
        return NAN;
    size_t k = (size_t)ceil(p / 100.0 * (double)n);
    if (k < 1)
        k = 1;
    if (k > n)
        k = n;
    return v[k - 1];
}

/* The trivial responder: receive, pack a fixed EgmSensor, send; its stats as
 * the JSON of rt_egm_run on stdout. */
static int trivial(unsigned port, size_t max)
{
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) != 0)
        return 2;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = triv_signal;
    sigaction(SIGTERM, &sa, NULL);
    double *lat = malloc(max * sizeof *lat), *cpu = malloc(max * sizeof *cpu);
    if (!lat || !cpu) {
        free(lat);
        free(cpu);
        close(fd);
        return 1;
    }
    size_t n = 0;
    uint32_t seq = 0;
    const double q[RT_EGM_NJ] = {0, 20, 30, 0, 40, 0};
    unsigned char buf[RT_EGM_MAX_DGRAM + 1];
    uint8_t out[256];
    const double t0 = rt_sched_now_ns();
    while (!triv_stop) {
        struct sockaddr_in peer;
        socklen_t pl = sizeof peer;
        const ssize_t r = recvfrom(fd, buf, sizeof buf, 0, (struct sockaddr *)&peer, &pl);
        const double t_rx = rt_sched_now_ns(), c_rx = rt_sched_cpu_ns();
        if (r < 0)
            continue;
        const size_t len = rt_egm_encode(out, sizeof out, ++seq, (uint32_t)((t_rx - t0) / 1e6), q);
        sendto(fd, out, len, 0, (struct sockaddr *)&peer, pl);
        const double t_tx = rt_sched_now_ns();
        if (n < max) {
            lat[n] = (t_tx - t_rx) / 1e3;
            cpu[n] = (rt_sched_cpu_ns() - c_rx) / 1e3;
            n++;
        }
    }
    qsort(lat, n, sizeof *lat, cmp_double);
    qsort(cpu, n, sizeof *cpu, cmp_double);
    double cm = 0;
    for (size_t i = 0; i < n; ++i)
        cm += cpu[i] / (double)n;
    printf("{\"label\": \"trivial\", \"replies\": %u, \"rx_tx_us\": {\"median\": %.3f, \"p99_99\": %.3f, \"max\": "
           "%.3f}, \"cpu_us\": {\"median\": %.3f, \"mean\": %.3f}}\n",
           seq, pct(lat, n, 50), pct(lat, n, 99.99), n ? lat[n - 1] : 0.0, pct(cpu, n, 50), cm);
    fflush(stdout);
    free(lat);
    free(cpu);
    close(fd);
    return 0;
}

/* One responder's process, its stdout into a pipe; the pid, or -1. */
static pid_t spawn(int *rd, int which, unsigned port, const rc_kin *cal, const rc_kin *nom,
                   const rc_comp_config *cfg, double rate_hz, size_t cycles, int fifo)
{
    int p[2];
    if (pipe(p) != 0)
        return -1;
    fflush(stdout);
    fflush(stderr);
    const pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid > 0) {
        close(p[1]);
        *rd = p[0];
        return pid;
    }
    close(p[0]);
    dup2(p[1], 1);
    if (fifo)
        set_fifo(80);
    int rc;
    if (which == 0) {
        static synth sy;
        sy.k = 0;
        sy.rate_hz = rate_hz;
        rt_egm_opts o;
        rt_egm_opts_default(&o);
        o.port = port;
        o.next = synth_next;
        o.next_ctx = &sy;
        o.period_ms = 1e3 / rate_hz;
        o.timeout_s = 10.0;
        o.wait_s = 10.0;
        o.json = 1;
        o.quiet = 1;
        o.follow_deg = 1e9; /* the bench's controller does not move a robot */
        o.label = "rcal-rt";
        rc = rt_egm_run(&o, cal, nom, cfg);
    } else {
        rc = trivial(port, cycles + 16);
    }
    fflush(stdout);
    _exit(rc == 2 ? 2 : 0);
}

static size_t pack_robot(uint8_t *buf, size_t cap, uint32_t seq, uint32_t tm, const double q[RT_EGM_NJ])
{
    Abb__Egm__EgmHeader h = ABB__EGM__EGM_HEADER__INIT;
    Abb__Egm__EgmJoints jf = ABB__EGM__EGM_JOINTS__INIT, jp = ABB__EGM__EGM_JOINTS__INIT;
    Abb__Egm__EgmFeedBack fb = ABB__EGM__EGM_FEED_BACK__INIT;
    Abb__Egm__EgmPlanned pl = ABB__EGM__EGM_PLANNED__INIT;
    Abb__Egm__EgmMotorState ms = ABB__EGM__EGM_MOTOR_STATE__INIT;
    Abb__Egm__EgmMCIState mci = ABB__EGM__EGM_MCISTATE__INIT;
    Abb__Egm__EgmRapidCtrlExecState rx = ABB__EGM__EGM_RAPID_CTRL_EXEC_STATE__INIT;
    Abb__Egm__EgmRobot r = ABB__EGM__EGM_ROBOT__INIT;
    double a[RT_EGM_NJ], b[RT_EGM_NJ];
    memcpy(a, q, sizeof a);
    memcpy(b, q, sizeof b);
    h.has_seqno = h.has_tm = h.has_mtype = 1;
    h.seqno = seq;
    h.tm = tm;
    h.mtype = ABB__EGM__EGM_HEADER__MESSAGE_TYPE__MSGTYPE_DATA;
    jf.n_joints = jp.n_joints = RT_EGM_NJ;
    jf.joints = a;
    jp.joints = b;
    fb.joints = &jf;
    pl.joints = &jp;
    ms.state = ABB__EGM__EGM_MOTOR_STATE__MOTOR_STATE_TYPE__MOTORS_ON;
    mci.state = ABB__EGM__EGM_MCISTATE__MCISTATE_TYPE__MCI_RUNNING;
    rx.state = ABB__EGM__EGM_RAPID_CTRL_EXEC_STATE__RAPID_CTRL_EXEC_STATE_TYPE__RAPID_RUNNING;
    r.header = &h;
    r.feedback = &fb;
    r.planned = &pl;
    r.motorstate = &ms;
    r.mcistate = &mci;
    r.rapidexecstate = &rx;
    r.has_mciconvergencemet = 1;
    if (abb__egm__egm_robot__get_packed_size(&r) > cap)
        return 0;
    return abb__egm__egm_robot__pack(&r, buf);
}

/* a reply's seqno and joints; 0, or -1 when it is not an EgmSensor with six joints */
static int unpack_sensor(uint32_t *seq, double q[RT_EGM_NJ], const uint8_t *buf, size_t len)
{
    Abb__Egm__EgmSensor *s = abb__egm__egm_sensor__unpack(NULL, len, buf);
    int rc = -1;
    if (s && s->header && s->header->has_seqno && s->planned && s->planned->joints &&
        s->planned->joints->n_joints == RT_EGM_NJ) {
        *seq = s->header->seqno;
        memcpy(q, s->planned->joints->joints, sizeof(double) * RT_EGM_NJ);
        rc = 0;
    }
    if (s)
        abb__egm__egm_sensor__free_unpacked(s, NULL);
    return rc;
}

typedef struct side {
    int fd, rd;
    pid_t pid;
    struct sockaddr_in to;
    double *rtt_us;
    size_t n_rtt;
    unsigned long missed, replies;
    /* per cycle, for the attribution of a miss (attribute()): the send (CLOCK_REALTIME, as the kernel stamps),
     * the reply's kernel arrival stamp (0: none came), the send's lateness behind the schedule (us), in time */
    double *send_rt, *arr_rt, *send_late_us;
    unsigned char *in_time;
    unsigned long miss_resp, miss_ctrl, late_sends;
    int got;          /* this cycle's reply came */
    double t_send;
    double q[RT_EGM_NJ];
    char json[2048];
} side;

static void read_json(side *s)
{
    size_t k = 0;
    ssize_t r;
    while (k + 1 < sizeof s->json && (r = read(s->rd, s->json + k, sizeof s->json - 1 - k)) > 0)
        k += (size_t)r;
    s->json[k] = '\0';
    while (k > 0 && s->json[k - 1] == '\n')
        s->json[--k] = '\0';
    close(s->rd);
}

/* recv with the kernel's arrival stamp (CLOCK_REALTIME ns; the read's time when there is none) */
static ssize_t recv_stamped(int fd, uint8_t *buf, size_t cap, double *arr_ns)
{
    struct timespec t;
    const ssize_t n = rt_sched_recv_stamped(fd, buf, cap, 0, NULL, &t, NULL, NULL);
    *arr_ns = rt_sched_ts_ns(&t);
    return n;
}

/* Each missed cycle (no reply read by the next cycle's scheduled start)
 * attributed: the responder's when its reply did not arrive (kernel stamp)
 * within a period of the controller's actual send, else the machine's (the
 * controller itself sent late, or read late, the reply having come in
 * time). late_sends: sends more than half a period behind the schedule. */
static void attribute(side *x, size_t cycles, double period_ns)
{
    for (size_t k = 0; k < cycles; ++k) {
        x->late_sends += x->send_late_us[k] > 0.5 * period_ns / 1e3;
        if (x->in_time[k])
            continue;
        if (x->arr_rt[k] > 0 && x->arr_rt[k] - x->send_rt[k] <= period_ns)
            x->miss_ctrl++;
        else
            x->miss_resp++;
    }
}

typedef struct bench_check {
    unsigned long wrong, checked; /* rcal-rt's replies off the expected joints by more than 1e-6 deg, and all */
    double worst_deg;
} bench_check;

/* The replies of this cycle (seq) until both came or the deadline passed;
 * rcal-rt's (side 0) checked against expect (cycles + 2 rows). */
static void collect(side sd[2], uint32_t seq_now, double deadline, const double (*expect)[RT_EGM_NJ], size_t cycles,
                    bench_check *chk)
{
    uint8_t in[RT_EGM_MAX_DGRAM];
    while (!(sd[0].got && sd[1].got)) {
        const double left_ms = (deadline - rt_sched_now_ns()) / 1e6;
        if (left_ms <= 0)
            break;
        struct pollfd p[2] = {{sd[0].fd, POLLIN, 0}, {sd[1].fd, POLLIN, 0}};
        if (poll(p, 2, (int)ceil(left_ms)) <= 0)
            continue;
        for (int j = 0; j < 2; ++j) {
            if (!(p[j].revents & POLLIN))
                continue;
            double arr;
            const ssize_t r = recv_stamped(sd[j].fd, in, sizeof in, &arr);
            const double t = rt_sched_now_ns();
            uint32_t seq;
            double q[RT_EGM_NJ];
            if (r <= 0 || unpack_sensor(&seq, q, in, (size_t)r) != 0)
                continue;
            sd[j].replies++;
            if (seq >= 1 && seq <= cycles && sd[j].arr_rt[seq - 1] == 0.0)
                sd[j].arr_rt[seq - 1] = arr;
            if (seq == seq_now && !sd[j].got) {
                sd[j].got = 1;
                sd[j].in_time[seq - 1] = 1;
                sd[j].rtt_us[sd[j].n_rtt++] = (t - sd[j].t_send) / 1e3;
            }
            if (j == 0 && seq >= 1 && seq <= cycles + 1) {
                memcpy(sd[0].q, q, sizeof q); /* the robot follows */
                double m = 0;
                for (int i = 0; i < RT_EGM_NJ; ++i)
                    m = fmax(m, fabs(q[i] - expect[seq - 1][i]));
                chk->worst_deg = fmax(chk->worst_deg, m);
                chk->wrong += m > 1e-6;
                chk->checked++;
            }
        }
    }
}

static void report(side sd[2], const bench_check *chk, double rate_hz, double seconds, size_t cycles, int fifo,
                   int fifo_ok, double load0, double load1, int json)
{
    const char *names[2] = {"rcal-rt", "trivial"};
    if (json) {
        printf("{\"rate_hz\": %.1f, \"seconds\": %.1f, \"cycles\": %zu, \"sched_fifo\": %s, \"load_before\": %.2f, "
               "\"load_after\": %.2f, \"checked\": %lu, \"wrong\": %lu, \"worst_deg\": %.3g",
               rate_hz, seconds, cycles, fifo_ok ? "true" : "false", load0, load1, chk->checked, chk->wrong,
               chk->worst_deg);
        for (int j = 0; j < 2; ++j)
            printf(", \"%s\": {\"missed\": %lu, \"missed_responder\": %lu, \"missed_machine\": %lu, "
                   "\"late_sends\": %lu, \"rtt_us\": {\"median\": %.3f, \"p99_99\": %.3f, \"max\": %.3f}, "
                   "\"responder\": %s}", names[j], sd[j].missed, sd[j].miss_resp, sd[j].miss_ctrl, sd[j].late_sends, pct(sd[j].rtt_us, sd[j].n_rtt, 50),
                   pct(sd[j].rtt_us, sd[j].n_rtt, 99.99), sd[j].n_rtt ? sd[j].rtt_us[sd[j].n_rtt - 1] : 0.0,
                   sd[j].json[0] ? sd[j].json : "null");
        printf("}\n");
    } else {
        printf("rcal-rt --egm-bench: %zu cycles at %.0f Hz (%.0f s), loopback, %s; load average %.2f before, %.2f "
               "after\n", cycles, rate_hz, seconds,
               fifo_ok ? "SCHED_FIFO (controller 81, responders 80)"
                       : fifo ? "SCHED_FIFO refused: normal scheduling" : "normal scheduling (no --fifo)",
               load0, load1);
        for (int j = 0; j < 2; ++j) {
            printf("  %-8s missed cycles %lu; round trip median %.1f us, p99.99 %.1f us, max %.1f us\n", names[j],
                   sd[j].missed, pct(sd[j].rtt_us, sd[j].n_rtt, 50), pct(sd[j].rtt_us, sd[j].n_rtt, 99.99),
                   sd[j].n_rtt ? sd[j].rtt_us[sd[j].n_rtt - 1] : 0.0);
            printf("           missed cycles attributed: %lu the responder's (its reply not in within a period of the "
                   "actual send), %lu the machine's (the controller sent or read late; the reply came in time); "
                   "sends over half a period behind schedule: %lu\n", sd[j].miss_resp, sd[j].miss_ctrl,
                   sd[j].late_sends);
            printf("           responder: %s\n", sd[j].json[0] ? sd[j].json : "(no summary)");
        }
        printf("  rcal-rt's replies: %lu checked against the path compensated here, %lu differ by more than 1e-6 "
               "deg (largest %.3g deg)\n", chk->checked, chk->wrong, chk->worst_deg);
    }
}

/* The two responders started, each on a free loopback port, and the controller's socket to each. 0 or -1. */
static int start_sides(side sd[2], const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg, double rate_hz,
                       size_t cycles, int fifo)
{
    unsigned port0 = 0;
    /* two free ports: bound by the kernel, released, handed to the children */
    for (int i = 0; i < 2; ++i) {
        const int t = socket(AF_INET, SOCK_DGRAM, 0);
        struct sockaddr_in a;
        socklen_t al = sizeof a;
        memset(&a, 0, sizeof a);
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (t < 0 || bind(t, (struct sockaddr *)&a, sizeof a) != 0 || getsockname(t, (struct sockaddr *)&a, &al) != 0) {
            fprintf(stderr, "rcal-rt: --egm-bench: no loopback UDP port: %s\n", strerror(errno));
            return -1;
        }
        sd[i].to = a;
        port0 = ntohs(a.sin_port);
        close(t);
        sd[i].pid = spawn(&sd[i].rd, i, port0, cal, nom, cfg, rate_hz, cycles, fifo);
        if (sd[i].pid < 0) {
            fprintf(stderr, "rcal-rt: --egm-bench: fork: %s\n", strerror(errno));
            if (i == 1)
                kill(sd[0].pid, SIGTERM);
            return -1;
        }
        sd[i].fd = socket(AF_INET, SOCK_DGRAM, 0);
        struct sockaddr_in me;
        memset(&me, 0, sizeof me);
        me.sin_family = AF_INET;
        me.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        const int on = 1;
        if (sd[i].fd < 0 || setsockopt(sd[i].fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0 ||
            bind(sd[i].fd, (struct sockaddr *)&me, sizeof me) != 0) {
            fprintf(stderr, "rcal-rt: --egm-bench: the controller's socket: %s\n", strerror(errno));
            for (int j = 0; j <= i; ++j) /* the responders started: stopped, not left behind */
                kill(sd[j].pid, SIGTERM);
            return -1;
        }
        synth_q(sd[i].q, 0, rate_hz);
        for (int j = 0; j < RT_EGM_NJ; ++j)
            sd[i].q[j] /= DEG;
    }
    return 0;
}

static void sides_free(side sd[2])
{
    for (int j = 0; j < 2; ++j) {
        free(sd[j].rtt_us);
        free(sd[j].send_rt);
        free(sd[j].arr_rt);
        free(sd[j].send_late_us);
        free(sd[j].in_time);
    }
}

int rt_egm_bench(const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg, double rate_hz, double seconds,
                 int fifo, int json)
{
    const size_t cycles = (size_t)(rate_hz * seconds + 0.5);
    const long period_ns = (long)(1e9 / rate_hz + 0.5);
    /* the expected replies: the same path compensated here, in the same order */
    double (*expect)[RT_EGM_NJ] = malloc((cycles + 2) * sizeof *expect);
    side sd[2];
    memset(sd, 0, sizeof sd);
    int mem_ok = 1;
    for (int j = 0; j < 2; ++j) {
        sd[j].rtt_us = malloc(cycles * sizeof(double));
        sd[j].send_rt = calloc(cycles, sizeof(double));
        sd[j].arr_rt = calloc(cycles, sizeof(double));
        sd[j].send_late_us = calloc(cycles, sizeof(double));
        sd[j].in_time = calloc(cycles, 1);
        mem_ok &= sd[j].rtt_us && sd[j].send_rt && sd[j].arr_rt && sd[j].send_late_us && sd[j].in_time;
    }
    if (!expect || !mem_ok) {
        fprintf(stderr, "rcal-rt: --egm-bench: out of memory for %zu cycles\n", cycles);
        free(expect);
        sides_free(sd);
        return 1;
    }
    static rc_comp_stream s;
    rc_comp_stream_init_kin(&s, cal, nom, cfg);
    for (size_t k = 0; k < cycles + 2; ++k) {
        double q[RT_EGM_NJ];
        rc_real qr[RC_NJ], qc[RC_NJ];
        synth_q(q, k, rate_hz);
        for (int i = 0; i < RC_NJ; ++i)
            qr[i] = (rc_real)q[i];
        rc_comp_stream_step(&s, qc, NULL, qr);
        for (int i = 0; i < RC_NJ; ++i)
            expect[k][i] = (double)qc[i] / DEG;
    }
    double la0[3] = {0, 0, 0}, la1[3] = {0, 0, 0};
    getloadavg(la0, 3);
    if (start_sides(sd, cal, nom, cfg, rate_hz, cycles, fifo) != 0) {
        free(expect);
        sides_free(sd);
        return 1;
    }
    const int fifo_ok = fifo ? set_fifo(81) == 0 : 0;
    if (fifo && !fifo_ok)
        fprintf(stderr, "rcal-rt: --egm-bench: note: SCHED_FIFO refused (%s): every process runs as a normal one\n",
                strerror(errno));
    struct timespec z = {0, 200000000L}; /* the responders bind */
    nanosleep(&z, NULL);
    bench_check chk = {0, 0, 0.0};
    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    const double t0 = rt_sched_now_ns();
    uint8_t out[512];
    for (size_t k = 0; k < cycles; ++k) {
        next.tv_nsec += period_ns;
        while (next.tv_nsec >= 1000000000L) {
            next.tv_nsec -= 1000000000L;
            next.tv_sec++;
        }
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR) {
        }
        const double deadline = (double)next.tv_sec * 1e9 + (double)next.tv_nsec + (double)period_ns;
        for (int j = 0; j < 2; ++j) {
            side *x = &sd[(k & 1u) ? 1 - j : j];
            const size_t len = pack_robot(out, sizeof out, (uint32_t)k + 1, (uint32_t)((rt_sched_now_ns() - t0) / 1e6), x->q);
            x->got = 0;
            struct timespec rt;
            clock_gettime(CLOCK_REALTIME, &rt);
            x->send_rt[k] = (double)rt.tv_sec * 1e9 + (double)rt.tv_nsec;
            x->t_send = rt_sched_now_ns();
            x->send_late_us[k] = (x->t_send - (deadline - (double)period_ns)) / 1e3;
            sendto(x->fd, out, len, 0, (struct sockaddr *)&x->to, sizeof x->to);
        }
        collect(sd, (uint32_t)k + 1, deadline, (const double(*)[RT_EGM_NJ])expect, cycles, &chk);
        for (int j = 0; j < 2; ++j)
            sd[j].missed += !sd[j].got;
    }
    getloadavg(la1, 3);
    for (int j = 0; j < 2; ++j) {
        kill(sd[j].pid, SIGTERM);
        read_json(&sd[j]);
        int stw = 0;
        waitpid(sd[j].pid, &stw, 0);
        close(sd[j].fd);
        qsort(sd[j].rtt_us, sd[j].n_rtt, sizeof(double), cmp_double);
        attribute(&sd[j], cycles, (double)period_ns);
    }
    report(sd, &chk, rate_hz, seconds, cycles, fifo, fifo_ok, la0[0], la1[0], json);
    free(expect);
    sides_free(sd);
    if (chk.wrong || chk.checked == 0) {
        fprintf(stderr, "rcal-rt: --egm-bench: %lu of %lu replies differ from the compensation: exit status 1\n",
                chk.wrong, chk.checked);
        return 1;
    }
    return 0;
}
