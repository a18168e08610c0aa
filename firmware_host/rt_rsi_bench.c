/* SPDX-License-Identifier: MIT */
/* rt_rsi_bench.c - rsi_bench: rcal-rt --rsi-port measured against a
 * simulated KUKA RSI controller, beside a trivial C responder on the same
 * schedule in the same run (docs/rsi.md, issue 49).
 *
 *   rsi_bench --rcal-rt RCAL_RT --rcal RCAL --model MODEL.json [--seconds 600] [--rate-hz 250] [--fifo]
 *             [--work DIR]
 *
 * It writes a smooth joint path of rate x seconds setpoints (DIR/targets.csv),
 * has `rcal compensate` correct it (DIR/compensated.csv), starts rcal-rt on
 * one port and a trivial responder (a forked process: finds <IPOC>, answers
 * a zero AK) on another, and runs two controller threads at the rate, the
 * responder's half a period after rcal-rt's. Each cycle a controller sends a
 * <Rob> with the next setpoint and waits for the answer until its next cycle:
 * no answer by then is a missed cycle, attributed to the responder when its
 * answer did not arrive (kernel stamp) within a period of the controller's
 * actual send, else to the machine (the controller thread itself sent or read
 * late). Reported: missed cycles and their attribution, the controller's send
 * lateness, round trip
 * (controller send to answer read) median/p99.99 for both, each responder's
 * own receive-to-send time (kernel receive stamp to sendto done) median/p99.99,
 * rcal-rt's CPU per answer, and the answers whose AK differs from compensate's
 * joints minus the setpoint by more than 1e-6 deg (after the first 100
 * cycles: the ramp). Exit 1 when an answer was wrong (its IPOC or its AK),
 * not for timing: this is a bench, not a timed test.
 * Linux, POSIX threads. */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "rt_sched.h"

#define NAX 6
#define HOLD 100 /* cycles at the start setpoint: the correction ramps in */

typedef struct {
    const char *rt, *rcal, *model, *work;
    double seconds, rate;
    int fifo;
} opts;

static double now_ns(clockid_t c)
{
    struct timespec t;
    clock_gettime(c, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double pct(double *v, size_t n, double p)
{
    if (n == 0)
        return NAN;
    size_t k = (size_t)ceil(p / 100.0 * (double)n);
    k = k < 1 ? 1 : k > n ? n : k;
    return v[k - 1];
}

/* ---- the path and its reference ---- */

static void path_at(double q[NAX], size_t k, size_t n)
{
    static const double c[NAX] = {10, -40, 60, 5, 30, 20}, a[NAX] = {25, 12, 15, 40, 20, 60};
    const double t = k < HOLD ? 0.0 : (double)(k - HOLD) / (double)(n > HOLD ? n - HOLD : 1);
    for (int i = 0; i < NAX; ++i) /* six decimals: the same numbers in the CSV and in the datagram */
        q[i] = round((c[i] + a[i] * sin(2 * M_PI * 3.0 * t + i)) * 1e6) / 1e6;
}

static int run_cmd(char *const argv[])
{
    const pid_t p = fork();
    if (p == 0) {
        execv(argv[0], argv);
        _exit(127);
    }
    int st = 0;
    if (p < 0 || waitpid(p, &st, 0) < 0)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int make_reference(double (**q)[NAX], double (**ref)[NAX], size_t n, const opts *o)
{
    char tin[1024], tout[1024];
    snprintf(tin, sizeof tin, "%s/targets.csv", o->work);
    snprintf(tout, sizeof tout, "%s/compensated.csv", o->work);
    *q = malloc(n * sizeof **q);
    *ref = malloc(n * sizeof **ref);
    FILE *f = fopen(tin, "w");
    if (!*q || !*ref || !f) {
        fprintf(stderr, "rsi_bench: %s: %s\n", tin, strerror(errno));
        if (f)
            fclose(f);
        return -1;
    }
    fprintf(f, "q1,q2,q3,q4,q5,q6\n");
    for (size_t k = 0; k < n; ++k) {
        path_at((*q)[k], k, n);
        for (int i = 0; i < NAX; ++i)
            fprintf(f, "%.6f%c", (*q)[k][i], i + 1 < NAX ? ',' : '\n');
    }
    if (fclose(f) != 0)
        return -1;
    char a1[] = "compensate", a2[] = "--model", a3[] = "--in", a4[] = "--out";
    char *const argv[] = {(char *)o->rcal, a1, a2, (char *)o->model, a3, tin, a4, tout, NULL};
    const int rc = run_cmd(argv);
    if (rc != 0) {
        fprintf(stderr, "rsi_bench: rcal compensate exit %d\n", rc);
        return -1;
    }
    f = fopen(tout, "r");
    char line[512];
    size_t k = 0;
    if (!f || !fgets(line, sizeof line, f)) {
        if (f)
            fclose(f);
        return -1;
    }
    while (k < n && fgets(line, sizeof line, f)) {
        double *r = (*ref)[k];
        const char *p = line;
        int j = 0;
        for (; j < 6; ++j) { /* six numbers separated by commas, each checked (strtod) */
            char *end;
            r[j] = strtod(p, &end);
            if (end == p || !isfinite(r[j]) || (j < 5 && *end != ','))
                break;
            p = end + 1;
        }
        if (j != 6)
            break;
        ++k;
    }
    fclose(f);
    if (k != n) {
        fprintf(stderr, "rsi_bench: %s: %zu rows, not %zu\n", tout, k, n);
        return -1;
    }
    return 0;
}

/* ---- the trivial responder (a forked process) ---- */

static volatile sig_atomic_t g_stop;
static void on_term(int s)
{
    (void)s;
    g_stop = 1;
}

static void set_fifo(int prio, const char *who)
{
    struct sched_param sp;
    memset(&sp, 0, sizeof sp);
    sp.sched_priority = prio;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
        fprintf(stderr, "rsi_bench: note: %s: SCHED_FIFO refused (%s)\n", who, strerror(errno));
}

static void responder(int fd, int out_fd, int fifo, size_t cap, double period_us)
{
    signal(SIGTERM, on_term);
    if (fifo) {
        set_fifo(80, "responder");
        mlockall(MCL_CURRENT | MCL_FUTURE);
    }
    double *lat = malloc(cap * sizeof *lat);
    size_t n = 0, over = 0;
    struct timespec c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    while (!g_stop) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, 100) <= 0)
            continue;
        char buf[8192], out[512];
        struct sockaddr_in from;
        struct timespec rx;
        const ssize_t r = rt_sched_recv_stamped(fd, buf, sizeof buf - 1, MSG_DONTWAIT, &from, &rx, NULL, NULL);
        if (r <= 0)
            continue;
        buf[r] = '\0';
        const char *i = strstr(buf, "<IPOC>");
        const unsigned long long ipoc = i ? strtoull(i + 6, NULL, 10) : 0;
        const int m = snprintf(out, sizeof out,
                               "<Sen Type=\"ImFree\"><AK A1=\"0.0\" A2=\"0.0\" A3=\"0.0\" A4=\"0.0\" A5=\"0.0\" "
                               "A6=\"0.0\"/><IPOC>%llu</IPOC></Sen>", ipoc);
        sendto(fd, out, (size_t)m, 0, (struct sockaddr *)&from, sizeof from);
        const double tx = now_ns(CLOCK_REALTIME);
        if (lat && n < cap) {
            lat[n] = (tx - rt_sched_ts_ns(&rx)) / 1e3;
            over += lat[n++] > period_us;
        }
    }
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    if (lat)
        qsort(lat, n, sizeof *lat, cmp_d);
    char line[256];
    const double cpu = ((double)(c1.tv_sec - c0.tv_sec) * 1e9 + (double)(c1.tv_nsec - c0.tv_nsec)) / 1e3;
    const int len = snprintf(line, sizeof line, "%zu %.1f %.1f %.1f %.2f %zu %.1f\n", n, pct(lat, n, 50),
                             pct(lat, n, 99.99), n ? lat[n - 1] : NAN, n ? cpu / (double)n : NAN, over,
                             pct(lat, n, 99));
    free(lat);
    if (write(out_fd, line, (size_t)len) != len)
        _exit(1);
    _exit(0);
}

/* ---- the controllers ---- */

typedef struct {
    int fd;
    double t0_ns, period_ns, offset_ns;
    size_t n;
    const double (*q)[NAX];
    const double (*ref)[NAX]; /* NULL: the trivial responder, AK not checked */
    int fifo;
    /* results */
    double *rtt_us;     /* answers in time */
    double *t_send;     /* per cycle: when its Rob was sent (late answers' round trip) */
    double *rtt_all_us; /* every answer, in time or late */
    /* per cycle, for the attribution of a miss: the send (CLOCK_REALTIME, as the kernel stamps), the answer's
     * kernel arrival stamp (0: none came), the send's lateness behind the schedule (us), answered in time */
    double *send_rt, *arr_rt, *send_late_us;
    unsigned char *in_time;
    size_t answered, n_all, missed, late, wrong_ipoc, wrong_ak, compared;
    size_t miss_resp, miss_ctrl, late_sends; /* after the run: see attribute() */
    double worst_ak;
} ctrl;

static double ak_of(const char *s, int i)
{
    char key[16]; /* " A1=\"" .. " A6=\"" (i is 0..5) */
    snprintf(key, sizeof key, " A%d=\"", i + 1);
    const char *p = strstr(s, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

/* recv with the kernel's arrival stamp (CLOCK_REALTIME ns; the read's time when there is none) */
static ssize_t recv_stamped(int fd, char *buf, size_t cap, double *arr_ns)
{
    struct timespec t;
    const ssize_t n = rt_sched_recv_stamped(fd, buf, cap, MSG_DONTWAIT, NULL, &t, NULL, NULL);
    *arr_ns = rt_sched_ts_ns(&t);
    return n;
}

/* Each missed cycle (no answer read by the next cycle's scheduled start)
 * attributed: the responder's when its answer did not arrive (kernel stamp)
 * within a period of the controller's actual send, else the machine's (the
 * controller itself sent late, or read late, its answer having come in
 * time). late_sends: sends more than half a period behind the schedule. */
static void attribute(ctrl *c)
{
    for (size_t k = 0; k < c->n; ++k) {
        c->late_sends += c->send_late_us[k] > 0.5 * c->period_ns / 1e3;
        if (c->in_time[k])
            continue;
        if (c->arr_rt[k] > 0 && c->arr_rt[k] - c->send_rt[k] <= c->period_ns)
            ++c->miss_ctrl;
        else
            ++c->miss_resp;
    }
}

static void *ctrl_run(void *arg)
{
    ctrl *c = arg;
    if (c->fifo)
        set_fifo(70, "controller");
    const unsigned long long base = 1000000;
    for (size_t k = 0; k < c->n; ++k) {
        const double tk = c->t0_ns + c->offset_ns + (double)k * c->period_ns;
        struct timespec ts = {(time_t)(tk / 1e9), (long)fmod(tk, 1e9)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
        }
        char m[1024];
        const double *q = c->q[k];
        const unsigned long long ipoc = base + 4ull * k;
        const int len = snprintf(
            m, sizeof m,
            "<Rob Type=\"KUKA\"><RIst X=\"445.0\" Y=\"0.0\" Z=\"890.0\" A=\"0.0\" B=\"90.0\" C=\"0.0\"/>"
            "<AIPos A1=\"%.6f\" A2=\"%.6f\" A3=\"%.6f\" A4=\"%.6f\" A5=\"%.6f\" A6=\"%.6f\"/>"
            "<ASPos A1=\"%.6f\" A2=\"%.6f\" A3=\"%.6f\" A4=\"%.6f\" A5=\"%.6f\" A6=\"%.6f\"/>"
            "<Delay D=\"0\"/><IPOC>%llu</IPOC></Rob>",
            q[0], q[1], q[2], q[3], q[4], q[5], q[0], q[1], q[2], q[3], q[4], q[5], ipoc);
        c->send_rt[k] = now_ns(CLOCK_REALTIME);
        const double ts_send = now_ns(CLOCK_MONOTONIC);
        c->t_send[k] = ts_send;
        c->send_late_us[k] = (ts_send - tk) / 1e3;
        send(c->fd, m, (size_t)len, 0);
        const double deadline = tk + c->period_ns;
        int got = 0;
        while (!got) {
            const double left_ms = (deadline - now_ns(CLOCK_MONOTONIC)) / 1e6;
            if (left_ms <= 0)
                break;
            struct pollfd p = {c->fd, POLLIN, 0};
            if (poll(&p, 1, (int)ceil(left_ms)) <= 0)
                continue;
            char r[1024];
            double arr;
            const ssize_t n = recv_stamped(c->fd, r, sizeof r - 1, &arr);
            if (n <= 0)
                continue;
            const double t_rx = now_ns(CLOCK_MONOTONIC);
            r[n] = '\0';
            const char *i = strstr(r, "<IPOC>");
            const unsigned long long e = i ? strtoull(i + 6, NULL, 10) : 0;
            if (e < ipoc && e >= base && (e - base) % 4u == 0) {
                ++c->late; /* an answer to an earlier cycle, after its deadline */
                c->rtt_all_us[c->n_all++] = (t_rx - c->t_send[(e - base) / 4u]) / 1e3;
                c->arr_rt[(e - base) / 4u] = arr;
                continue;
            }
            if (e != ipoc) {
                ++c->wrong_ipoc;
                continue;
            }
            c->rtt_all_us[c->n_all++] = (t_rx - ts_send) / 1e3;
            c->arr_rt[k] = arr;
            if (t_rx > deadline) {
                ++c->late;
                break;
            }
            got = 1;
            c->in_time[k] = 1;
            c->rtt_us[c->answered++] = (t_rx - ts_send) / 1e3;
            if (c->ref && k >= HOLD) {
                ++c->compared;
                for (int a = 0; a < NAX; ++a) {
                    const double d = fabs(ak_of(r, a) - (c->ref[k][a] - q[a]));
                    if (!(d <= c->worst_ak))
                        c->worst_ak = isnan(d) ? INFINITY : d;
                    if (!(d <= 1e-6)) {
                        ++c->wrong_ak;
                        break;
                    }
                }
            }
        }
        if (!got)
            ++c->missed;
    }
    return NULL;
}

static int udp_to(int port)
{
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in sa;
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons((unsigned short)port);
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const int on = 1;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0 ||
        connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0)
        return -1;
    return fd;
}

static int udp_bound(int *port)
{
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in sa;
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t sl = sizeof sa;
    const int on = 1;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0 ||
        bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 || getsockname(fd, (struct sockaddr *)&sa, &sl) != 0)
        return -1;
    *port = ntohs(sa.sin_port);
    return fd;
}

static void report(const char *name, ctrl *c)
{
    attribute(c);
    double *sl = malloc(c->n * sizeof *sl);
    if (sl) {
        memcpy(sl, c->send_late_us, c->n * sizeof *sl);
        qsort(sl, c->n, sizeof *sl, cmp_d);
    }
    qsort(c->rtt_us, c->answered, sizeof *c->rtt_us, cmp_d);
    qsort(c->rtt_all_us, c->n_all, sizeof *c->rtt_all_us, cmp_d);
    printf("  %-9s answered in time %zu of %zu, missed %zu (late answers %zu, wrong IPOC %zu); round trip of every "
           "answer median %.1f us, p99 %.1f us, p99.99 %.1f us, max %.1f us\n",
           name, c->answered, c->n, c->missed, c->late, c->wrong_ipoc, pct(c->rtt_all_us, c->n_all, 50),
           pct(c->rtt_all_us, c->n_all, 99), pct(c->rtt_all_us, c->n_all, 99.99),
           c->n_all ? c->rtt_all_us[c->n_all - 1] : NAN);
    printf("  %-9s missed cycles attributed: %zu the responder's (its answer not in within a period of the actual "
           "send), %zu the machine's (the simulated controller sent or read late; the answer came in time); the "
           "controller's sends behind schedule: median %.1f us, p99.99 %.1f us, max %.1f us, %zu over half a period\n",
           name, c->miss_resp, c->miss_ctrl, sl ? pct(sl, c->n, 50) : NAN, sl ? pct(sl, c->n, 99.99) : NAN,
           sl && c->n ? sl[c->n - 1] : NAN, c->late_sends);
    free(sl);
}

/* The machine's CPU time (user+nice+system, idle, steal) in ticks, /proc/stat. */
static void cpu_ticks(double t[3])
{
    t[0] = t[1] = t[2] = 0;
    FILE *f = fopen("/proc/stat", "r");
    unsigned long long v[8] = {0};
    char line[512];
    int got = 0;
    if (f && fgets(line, sizeof line, f) && strncmp(line, "cpu ", 4) == 0) { /* each count checked (strtoull) */
        const char *p = line + 4;
        for (; got < 8; ++got) {
            char *end;
            errno = 0;
            v[got] = strtoull(p, &end, 10);
            if (end == p || errno != 0)
                break;
            p = end;
        }
    }
    if (got == 8) {
        t[0] = (double)(v[0] + v[1] + v[2] + v[5] + v[6]);
        t[1] = (double)(v[3] + v[4]);
        t[2] = (double)v[7];
    }
    if (f)
        fclose(f);
}

static int parse(opts *o, int argc, char **argv)
{
    memset(o, 0, sizeof *o);
    o->seconds = 600;
    o->rate = 250;
    o->work = ".";
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--fifo") == 0) {
            o->fifo = 1;
            continue;
        }
        if (!v) {
            fprintf(stderr, "rsi_bench: %s needs a value (or is unknown)\n", a);
            return -1;
        }
        ++i;
        if (strcmp(a, "--rcal-rt") == 0)
            o->rt = v;
        else if (strcmp(a, "--rcal") == 0)
            o->rcal = v;
        else if (strcmp(a, "--model") == 0)
            o->model = v;
        else if (strcmp(a, "--work") == 0)
            o->work = v;
        else if (strcmp(a, "--seconds") == 0 || strcmp(a, "--rate-hz") == 0) {
            char *end;
            const double x = strtod(v, &end);
            if (end == v || *end || !isfinite(x)) {
                fprintf(stderr, "rsi_bench: %s %s: not a number\n", a, v);
                return -1;
            }
            *(a[2] == 's' ? &o->seconds : &o->rate) = x;
        }
        else {
            fprintf(stderr, "rsi_bench: unknown option %s\n", a);
            return -1;
        }
    }
    if (!o->rt || !o->rcal || !o->model || !(o->seconds >= 0.5 && o->seconds <= 7200) ||
        !(o->rate >= 10 && o->rate <= 2000)) {
        fprintf(stderr, "usage: rsi_bench --rcal-rt RCAL_RT --rcal RCAL --model MODEL.json [--seconds 0.5..7200] "
                        "[--rate-hz 10..2000] [--fifo] [--work DIR]\n");
        return -1;
    }
    return 0;
}

/* rcal-rt on a free port (*port), its stdout and stderr on pipes; returns its
 * pid once it says it listens, or -1. */
static pid_t start_rt(int *port, FILE **fout, FILE **ferr, const opts *o)
{
    const int probe = udp_bound(port);
    close(probe);
    char port_s[16];
    snprintf(port_s, sizeof port_s, "%d", *port);
    int out[2], err[2];
    if (pipe(out) != 0 || pipe(err) != 0)
        return -1;
    const pid_t rt = fork();
    if (rt == 0) {
        dup2(out[1], 1);
        dup2(err[1], 2);
        close(out[0]);
        close(err[0]);
        char a1[] = "--model", a2[] = "--rsi-port", a3[] = "--json", a4[] = "--fifo";
        char *args[16] = {(char *)o->rt, a1, (char *)o->model, a2, port_s, a3, o->fifo ? a4 : NULL, NULL};
        execv(o->rt, args);
        _exit(127);
    }
    close(out[1]);
    close(err[1]);
    *fout = fdopen(out[0], "r");
    *ferr = fdopen(err[0], "r");
    char line[1024];
    int ready = 0;
    while (!ready && *ferr && fgets(line, sizeof line, *ferr)) {
        fputs(line, stderr);
        ready = strstr(line, "listening on") != NULL;
    }
    if (rt < 0 || !ready || !*fout) {
        fprintf(stderr, "rsi_bench: rcal-rt did not start\n");
        return -1;
    }
    return rt;
}

/* A controller's buffers and schedule; 0, or -1 out of memory. */
static int ctrl_init(ctrl *c, int fd, size_t n, const opts *o, double t0_ns, double offset_ns)
{
    memset(c, 0, sizeof *c);
    c->fd = fd;
    c->n = n;
    c->period_ns = 1e9 / o->rate;
    c->t0_ns = t0_ns;
    c->offset_ns = offset_ns;
    c->fifo = o->fifo;
    c->rtt_us = malloc(n * sizeof(double));
    c->t_send = malloc(n * sizeof(double));
    c->rtt_all_us = malloc(n * sizeof(double));
    c->send_rt = calloc(n, sizeof(double));
    c->arr_rt = calloc(n, sizeof(double));
    c->send_late_us = calloc(n, sizeof(double));
    c->in_time = calloc(n, 1);
    return fd >= 0 && c->rtt_us && c->t_send && c->rtt_all_us && c->send_rt && c->arr_rt && c->send_late_us &&
                   c->in_time
               ? 0
               : -1;
}

static void ctrl_free(ctrl *c)
{
    free(c->rtt_us);
    free(c->t_send);
    free(c->rtt_all_us);
    free(c->send_rt);
    free(c->arr_rt);
    free(c->send_late_us);
    free(c->in_time);
}

static void summary(ctrl *a, ctrl *b, const opts *o, const double ticks0[3], const double ticks1[3], const char *rep,
                    const char *rline)
{
    size_t rcount = 0, rover = 0;
    double rmed = NAN, rp4 = NAN, rmax = NAN, rcpu = NAN, rp2 = NAN;
    { /* the responder's line: count median p99.99 max cpu over p99, each number checked */
        double v[7];
        const char *p = rline;
        int k = 0;
        for (; k < 7; ++k) {
            char *end;
            v[k] = strtod(p, &end);
            if (end == p)
                break;
            p = end;
        }
        if (k == 7) {
            rcount = (size_t)v[0];
            rmed = v[1];
            rp4 = v[2];
            rmax = v[3];
            rcpu = v[4];
            rover = (size_t)v[5];
            rp2 = v[6];
        }
    }
    printf("rsi_bench: %zu cycles at %.0f Hz (%.0f s), %s; the responder half a period after rcal-rt\n", a->n,
           o->rate, o->seconds, o->fifo ? "--fifo asked (notes above say when refused)" : "normal scheduling (no --fifo)");
    const double busy = ticks1[0] - ticks0[0], idle = ticks1[1] - ticks0[1], steal = ticks1[2] - ticks0[2];
    const double all = busy + idle + steal + 1e-9;
    printf("  the machine meanwhile (/proc/stat, all CPUs): %.1f %% busy, %.1f %% idle, %.1f %% stolen by the "
           "hypervisor\n", 100 * busy / all, 100 * idle / all, 100 * steal / all);
    report("rcal-rt", a);
    report("trivial", b);
    printf("  rcal-rt's own report: %s", rep[0] ? rep : "(none)\n");
    printf("  trivial responder receive-to-send: median %.1f us, p99 %.1f us, p99.99 %.1f us, max %.1f us; %zu answers "
           "over a cycle; CPU %.2f us per answer (%zu answers)\n", rmed, rp2, rp4, rmax, rover, rcpu, rcount);
    printf("  AK against rcal compensate (after the %d-cycle ramp): %zu compared, %zu differ by more than 1e-6 deg "
           "(worst %.3g deg)\n", HOLD, a->compared, a->wrong_ak, a->worst_ak);
}

int main(int argc, char **argv)
{
    opts o;
    if (parse(&o, argc, argv) != 0)
        return 2;
    const size_t n = (size_t)(o.seconds * o.rate + 0.5);
    double(*q)[NAX] = NULL, (*ref)[NAX] = NULL;
    if (make_reference(&q, &ref, n, &o) != 0) {
        free(q); /* make_reference leaves what it allocated to the caller */
        free(ref);
        return 1;
    }
    /* the trivial responder: a forked process, its figures on a pipe */
    int rport = 0, pfd[2];
    const int rfd = udp_bound(&rport);
    if (rfd < 0 || pipe(pfd) != 0) {
        fprintf(stderr, "rsi_bench: socket: %s\n", strerror(errno));
        free(q);
        free(ref);
        return 1;
    }
    const pid_t resp = fork();
    if (resp == 0) {
        close(pfd[0]);
        free(q); /* the responder needs neither: freed in the forked copy too (memcheck traces it) */
        q = NULL;
        free(ref);
        ref = NULL;
        responder(rfd, pfd[1], o.fifo, n + 16, 1e6 / o.rate);
    }
    close(pfd[1]);
    close(rfd);
    int tport = 0;
    FILE *fout = NULL, *ferr = NULL;
    const pid_t rt = start_rt(&tport, &fout, &ferr, &o);
    ctrl a, b;
    const double t0 = now_ns(CLOCK_MONOTONIC) + 20e6;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    if (rt < 0 || ctrl_init(&a, udp_to(tport), n, &o, t0, 0.0) != 0 ||
        ctrl_init(&b, udp_to(rport), n, &o, t0, 0.5e9 / o.rate) != 0) {
        ctrl_free(&a);
        ctrl_free(&b);
        free(q);
        free(ref);
        return 1;
    }
    a.q = b.q = (const double(*)[NAX])q;
    a.ref = (const double(*)[NAX])ref;
    if (o.fifo)
        mlockall(MCL_CURRENT | MCL_FUTURE);
    double ticks0[3], ticks1[3];
    cpu_ticks(ticks0);
    pthread_t ta, tb;
    pthread_create(&ta, NULL, ctrl_run, &a);
    pthread_create(&tb, NULL, ctrl_run, &b);
    pthread_join(ta, NULL);
    pthread_join(tb, NULL);
    cpu_ticks(ticks1);
    kill(rt, SIGTERM);
    kill(resp, SIGTERM);
    char rep[4096] = "", line[1024], rline[256] = "";
    if (!fgets(rep, sizeof rep, fout))
        rep[0] = '\0';
    while (fgets(line, sizeof line, ferr))
        fputs(line, stderr);
    const ssize_t rn = read(pfd[0], rline, sizeof rline - 1);
    rline[rn > 0 ? rn : 0] = '\0';
    int st = 0;
    waitpid(rt, &st, 0);
    waitpid(resp, NULL, 0);
    summary(&a, &b, &o, ticks0, ticks1, rep, rline);
    const int bad = a.wrong_ak || a.wrong_ipoc || b.wrong_ipoc || a.compared == 0 || !WIFEXITED(st) ||
                    WEXITSTATUS(st) != 0;
    free(q);
    free(ref);
    ctrl_free(&a);
    ctrl_free(&b);
    return bad ? 1 : 0;
}
