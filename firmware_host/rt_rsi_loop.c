/* SPDX-License-Identifier: MIT */
/* rt_rsi_loop.c - rcal-rt as a KUKA RSI partner (correction mode): each <Rob>
 * datagram's setpoint axes (ASPos) compensated with the model, answered with
 * <Sen><AK ../><IPOC/></Sen>, AK = compensated setpoint - setpoint (degrees).
 * The model set up as rcal compensate sets it up (rch_comp_run: the
 * determined model at the flange, the orientation decided the same way), so
 * AK equals compensate's joints minus the setpoint. Faults (docs/rsi.md):
 * the correction sent never changes by more than --rsi-max-step-deg per
 * answer; every fault counted, the first of each kind and every 1000th
 * logged on stderr; only the controller's address answered. */
#include "rt_rsi_loop.h"
#include "rt_sched.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <sys/time.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rc_comp.h"
#include "rch_comp.h"
#include "rch_diag.h"
#include "rch_file.h"
#include "rch_opt.h"
#include "rch_robot.h"
#include "rt_rsi.h"
#include "rt_rsi_model.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
/* a setpoint axis that moves more than this per cycle is not a robot's path
 * (400 deg/s, the fastest axes of small robots, is 1.6 deg at 4 ms) */
#define RT_RSI_MAX_SET_STEP_DEG 5.0
#define RT_RSI_PENDING 8
#define RT_RSI_LOG_LINE 320
/* the model file looked at this often (by the watcher thread) */
#define RT_RSI_WATCH_EVERY_S 0.25

void rt_rsi_usage(FILE *f)
{
    fprintf(f,
            "       rcal-rt --model MODEL.json --rsi-port PORT [--rsi-addr IP] [--rsi-config RSI_ETHERNET.xml]\n"
            "               [--rsi-mode absolute|relative] [--rsi-max-step-deg D] [--rsi-controller IP]\n"
            "               [--rsi-cycle-ms MS] [--rsi-timeout-ms MS] [--nominal ROBOT.json]\n"
            "               [--position-only|--full-pose] [--seconds S] [--fifo] [--cpu N] [--json]\n"
            "  RSI:     a KUKA RSI partner (correction mode, docs/rsi.md): each <Rob> datagram's setpoint axes\n"
            "           (ASPos, degrees, the controller's axes: the model file's \"controller\" member maps them to the\n"
            "           model's joints and back) compensated as rcal compensate does, answered\n"
            "           with <Sen><AK A1..A6/><IPOC/></Sen>, AK = compensated - setpoint; the correction changes by\n"
            "           at most --rsi-max-step-deg per answer (default 0.01); only the first sender (or\n"
            "           --rsi-controller) answered; a replaced model file is taken (the correction moving to it within\n"
            "           the step limit); runs until --seconds or SIGINT/SIGTERM, then reports\n");
}

typedef struct rsi_opts {
    const char *model, *nominal, *config, *addr, *controller;
    long port;
    int relative, fifo, pin, json, position_only, full_pose;
    unsigned long cpu;
    double max_step_deg, cycle_ms, timeout_ms, seconds;
} rsi_opts;

static int num_opt(const char *name, const char *v, double *out, double lo, double hi)
{
    if (rch_parse_double(v, out) != 0 || !(*out >= lo && *out <= hi)) {
        fprintf(stderr, "rcal-rt: option %s: '%s' is not a number in [%g, %g]\n", name, v, lo, hi);
        return -1;
    }
    return 0;
}

/* -1 when read, else the exit status (2 usage, 0 help). */
static int parse(rsi_opts *o, int argc, char **argv)
{
    memset(o, 0, sizeof *o);
    o->port = -1;
    o->max_step_deg = 0.01;
    o->cycle_ms = 4.0;
    o->timeout_ms = 1000.0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        double x;
        int used = 1;
        if (strcmp(a, "--fifo") == 0)
            o->fifo = 1;
        else if (strcmp(a, "--json") == 0)
            o->json = 1;
        else if (strcmp(a, "--position-only") == 0)
            o->position_only = 1;
        else if (strcmp(a, "--full-pose") == 0)
            o->full_pose = 1;
        else if (strcmp(a, "--help") == 0) {
            rt_rsi_usage(stdout);
            return 0;
        } else
            used = 0;
        if (used)
            continue;
        if (!v) {
            fprintf(stderr, "rcal-rt: option %s %s\n", a, a[0] == '-' ? "needs a value or is unknown" : "is unknown");
            return 2;
        }
        ++i;
        if (strcmp(a, "--model") == 0)
            o->model = v;
        else if (strcmp(a, "--nominal") == 0)
            o->nominal = v;
        else if (strcmp(a, "--rsi-config") == 0)
            o->config = v;
        else if (strcmp(a, "--rsi-addr") == 0)
            o->addr = v;
        else if (strcmp(a, "--rsi-controller") == 0)
            o->controller = v;
        else if (strcmp(a, "--rsi-mode") == 0) {
            if (strcmp(v, "absolute") != 0 && strcmp(v, "relative") != 0) {
                fprintf(stderr, "rcal-rt: --rsi-mode '%s': absolute or relative\n", v);
                return 2;
            }
            o->relative = strcmp(v, "relative") == 0;
        } else if (strcmp(a, "--rsi-port") == 0) {
            if (num_opt(a, v, &x, 0, 65535) != 0 || x != floor(x))
                return 2;
            o->port = (long)x;
        } else if (strcmp(a, "--rsi-max-step-deg") == 0) {
            if (num_opt(a, v, &o->max_step_deg, 1e-9, 1.0) != 0)
                return 2;
        } else if (strcmp(a, "--rsi-cycle-ms") == 0) {
            if (num_opt(a, v, &o->cycle_ms, 1.0, 100.0) != 0 || o->cycle_ms != floor(o->cycle_ms))
                return 2;
        } else if (strcmp(a, "--rsi-timeout-ms") == 0) {
            if (num_opt(a, v, &o->timeout_ms, 10.0, 600000.0) != 0)
                return 2;
        } else if (strcmp(a, "--seconds") == 0) {
            if (num_opt(a, v, &o->seconds, 0.001, 1e7) != 0)
                return 2;
        } else if (strcmp(a, "--cpu") == 0) {
            if (num_opt(a, v, &x, 0, CPU_SETSIZE - 1) != 0 || x != floor(x))
                return 2;
            o->cpu = (unsigned long)x;
            o->pin = 1;
        } else {
            fprintf(stderr, "rcal-rt: option %s is not one of the RSI mode's\n", a);
            rt_rsi_usage(stderr);
            return 2;
        }
    }
    if (!o->model) {
        fprintf(stderr, "rcal-rt: the RSI mode needs --model MODEL.json (the calibrated model)\n");
        return 2;
    }
    if (o->position_only && o->full_pose) {
        fprintf(stderr, "rcal-rt: --position-only and --full-pose exclude each other\n");
        return 2;
    }
    return -1;
}

/* ---- the model in use and the one a replaced file brought (rt_rsi_model.h) ---- */

typedef struct rsi_comp {
    rt_rsi_model mod[2];
    rc_comp_stream cs[2];
    int cur; /* mod[cur], cs[cur] in use */
} rsi_comp;

/* ---- the loop ---- */

static volatile sig_atomic_t g_stop;
static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

enum { F_FOREIGN, F_MALFORMED, F_DUP, F_REORDER, F_DROP, F_LATE, F_BAD_TARGET, F_NOCONV, F_LIMITED, F_MODEL,
       F_SEND, F_ROBOT_LATE, F_RELOAD_REFUSED, F_N };
static const char *const f_name[F_N] = {"foreign_sender", "malformed", "duplicate", "reordered",
                                        "dropped",        "late",      "bad_target", "not_converged",
                                        "step_limited",   "model_file_changed", "send_failed", "robot_late",
                                        "model_reload_refused"};

typedef struct rsi_state {
    unsigned long count[F_N];
    unsigned long datagrams, answered, sessions;
    unsigned long over_cycle; /* answers sent more than a cycle after their datagram arrived */
    unsigned long reloads;    /* replaced model files taken */
    /* the longest time of each stage (us): the measurement of where a late answer's time went */
    double max_decode_us, max_comp_us, max_send_us, max_after_us;
    double max_wake_us;          /* the kernel's receive stamp to the read returning */
    unsigned long wake_over_ms;  /* reads returning more than 1 ms after the kernel's receive */
    int in_session;
    unsigned long long last_ipoc;
    double last_rx_s;          /* monotonic seconds of the last controller datagram */
    double ak_abs[RT_RSI_NAX]; /* the correction in effect (absolute), degrees */
    double want[RT_RSI_NAX];   /* the last correction computed (held on a fault) */
    double max_step_seen;      /* largest change of ak_abs between answers in a session */
    long robot_delay;
    double last_set[RT_RSI_NAX]; /* the last setpoint compensated */
    int have_set;
    struct sockaddr_in ctrl;
    int have_ctrl;
    char pending[RT_RSI_PENDING][RT_RSI_LOG_LINE]; /* this datagram's log lines, written after its answer */
    int n_pending;
} rsi_state;

static double mono_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

#ifdef __GNUC__
static void fault(rsi_state *s, int kind, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
#endif
static void fault(rsi_state *s, int kind, const char *fmt, ...)
{
    const unsigned long k = ++s->count[kind];
    if (k > 5 && k % 1000 != 0)
        return;
    /* formatted now, written after the answer is sent (flush_log): stderr is not on the answer's path */
    if (s->n_pending >= RT_RSI_PENDING)
        return;
    char *b = s->pending[s->n_pending++];
    int w = snprintf(b, RT_RSI_LOG_LINE, "rcal-rt: rsi: %s #%lu: ", f_name[kind], k);
    if (w < 0 || w >= RT_RSI_LOG_LINE)
        w = 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(b + w, RT_RSI_LOG_LINE - (size_t)w, fmt, ap);
    va_end(ap);
    if (k == 5)
        snprintf(b + strlen(b), RT_RSI_LOG_LINE - strlen(b), " (further ones: every 1000th)");
}

static void flush_log(rsi_state *s)
{
    for (int i = 0; i < s->n_pending; ++i)
        fprintf(stderr, "%s\n", s->pending[i]);
    s->n_pending = 0;
}

static int open_socket(int *fd_out, const rsi_opts *o, const char *addr, long port)
{
    struct sockaddr_in sa;
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons((unsigned short)port);
    if (inet_pton(AF_INET, addr, &sa.sin_addr) != 1) {
        fprintf(stderr, "rcal-rt: --rsi-addr '%s' is not an IPv4 address\n", addr);
        return -1;
    }
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) {
        fprintf(stderr, "rcal-rt: rsi: socket: %s\n", strerror(errno));
        return -1;
    }
    const int on = 1;
    if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0)
        fprintf(stderr, "rcal-rt: note: no kernel receive time stamps (%s): latency from the read\n",
                strerror(errno));
    if (bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        fprintf(stderr, "rcal-rt: rsi: cannot listen on %s:%ld: %s\n", addr, port, strerror(errno));
        close(fd);
        return -1;
    }
    socklen_t sl = sizeof sa;
    getsockname(fd, (struct sockaddr *)&sa, &sl);
    fprintf(stderr, "rcal-rt: rsi: listening on %s:%u (%s corrections, at most %.6g deg per answer)\n", addr,
            (unsigned)ntohs(sa.sin_port), o->relative ? "relative" : "absolute", o->max_step_deg);
    *fd_out = fd;
    return 0;
}

/* The correction wanted for this datagram's setpoint into s->want (held
 * on a fault). The setpoint is the controller's (its axes as it means them:
 * the model file's "controller" member maps them to the model's joints),
 * compensated in the model's joints and mapped back: AK is in the
 * controller's axes, as rcal compensate writes the controller's joints. */
static void compensate(rsi_state *s, rsi_comp *c, const rt_rsi_rob *r, double cycles)
{
    const rt_rsi_model *m = &c->mod[c->cur];
    if (!r->set_ok) {
        fault(s, F_BAD_TARGET, "ipoc %llu: %s; the correction held", r->ipoc, r->set_why);
        return;
    }
    /* a setpoint no robot reaches in the time: not a path (the stream's warm start is kept for the path) */
    for (int i = 0; s->have_set && i < RC_NJ; ++i)
        if (fabs(r->set_deg[i] - s->last_set[i]) > RT_RSI_MAX_SET_STEP_DEG * cycles) {
            fault(s, F_BAD_TARGET, "ipoc %llu: A%d jumped %.4f deg in %.0f cycle(s) (more than %g deg per cycle); "
                  "the correction held", r->ipoc, i + 1, r->set_deg[i] - s->last_set[i], cycles,
                  RT_RSI_MAX_SET_STEP_DEG);
            return;
        }
    double q[RC_NJ], qc[RC_NJ], cc[RC_NJ];
    rt_rsi_model_to_model(q, m, r->set_deg);
    for (int i = 0; i < RC_NJ; ++i)
        if (q[i] < m->det.q_min_rad[i] || q[i] > m->det.q_max_rad[i]) {
            fault(s, F_BAD_TARGET, "ipoc %llu: A%d = %.6f deg is joint %d = %.6f deg of the model, outside its "
                  "limits [%g, %g] deg; the correction held", r->ipoc, i + 1, r->set_deg[i], i + 1, q[i] / DEG,
                  m->det.q_min_rad[i] / DEG, m->det.q_max_rad[i] / DEG);
            return;
        }
    memcpy(s->last_set, r->set_deg, sizeof s->last_set);
    s->have_set = 1;
    rc_comp_result res;
    const rc_status st = rc_comp_stream_step(&c->cs[c->cur], qc, &res, q);
    if (st != RC_OK) {
        fault(s, F_NOCONV, "ipoc %llu: the compensation did not converge (%s, %.4f mm); the correction held",
              r->ipoc, st == RC_ERR_NOCONV ? rc_comp_exit_str(res.exit) : rc_strerror(st), (double)res.pos_err_mm);
        return;
    }
    rt_rsi_model_to_ctrl(cc, m, qc);
    for (int i = 0; i < RC_NJ; ++i)
        s->want[i] = cc[i] - r->set_deg[i];
}

/* The correction to send: ak_abs moved toward want by at most max_step per
 * axis; out: absolute, or the increment in relative mode. */
static void step_toward(rsi_state *s, double out[RT_RSI_NAX], const rsi_opts *o, unsigned long long ipoc)
{
    int limited = 0;
    double big = 0.0;
    for (int i = 0; i < RT_RSI_NAX; ++i) {
        double d = s->want[i] - s->ak_abs[i];
        if (d > o->max_step_deg || d < -o->max_step_deg) {
            limited = 1;
            big = fmax(big, fabs(d));
            d = d > 0 ? o->max_step_deg : -o->max_step_deg;
        }
        s->ak_abs[i] += d;
        s->max_step_seen = fmax(s->max_step_seen, fabs(d));
        out[i] = o->relative ? d : s->ak_abs[i];
    }
    if (limited)
        fault(s, F_LIMITED, "ipoc %llu: the correction wanted is %.6f deg away; moved by %.6g deg", ipoc, big,
              o->max_step_deg);
}

typedef struct rsi_io {
    int fd;
    rt_rsi_dec *dec;
    rt_rsi_names names;
    rt_rsi_hist hist;
    rt_rsi_watch watch;
    struct in_addr only; /* --rsi-controller */
    int have_only;
} rsi_io;

/* One datagram: checked, compensated, answered. */
static void one_dgram(rsi_state *s, rsi_io *io, rsi_comp *c, const rsi_opts *o,
                const char *buf, size_t len, const struct sockaddr_in *from, const struct timespec *rx)
{
    char who[64];
    snprintf(who, sizeof who, "%s:%u", inet_ntoa(from->sin_addr), (unsigned)ntohs(from->sin_port));
    s->datagrams++;
    const double now = mono_s();
    /* the controller: its IP (the first sender's, or --rsi-controller) and, within a session, its port */
    const int live = s->in_session && now - s->last_rx_s <= o->timeout_ms / 1e3;
    const int ip_ok = io->have_only ? from->sin_addr.s_addr == io->only.s_addr
                                    : !s->have_ctrl || from->sin_addr.s_addr == s->ctrl.sin_addr.s_addr;
    if (!ip_ok || (live && from->sin_port != s->ctrl.sin_port)) {
        fault(s, F_FOREIGN, "a datagram from %s, not the controller: not read, not answered", who);
        return;
    }
    rt_rsi_rob r;
    char why[192];
    const double t_dec = mono_s();
    const rt_rsi_status st = rt_rsi_decode(&r, why, sizeof why, io->dec, buf, len);
    s->max_decode_us = fmax(s->max_decode_us, (mono_s() - t_dec) * 1e6);
    if (st != RT_RSI_OK) {
        fault(s, F_MALFORMED, "from %s: %s: %s; not answered", who, rt_rsi_strerror(st), why);
        return;
    }
    /* a session: the first datagram, or one after --rsi-timeout-ms of silence (also in IPOC ms) */
    const int fresh = !s->in_session || now - s->last_rx_s > o->timeout_ms / 1e3 ||
                      (r.ipoc > s->last_ipoc && (double)(r.ipoc - s->last_ipoc) > o->timeout_ms);
    if (!fresh && r.ipoc == s->last_ipoc) {
        fault(s, F_DUP, "ipoc %llu from %s again: not answered twice", r.ipoc, who);
        return;
    }
    if (!fresh && r.ipoc < s->last_ipoc) {
        fault(s, F_REORDER, "ipoc %llu from %s after %llu: stale, not answered", r.ipoc, who, s->last_ipoc);
        return;
    }
    double steps = 1.0;
    if (fresh) {
        if (s->n_pending < RT_RSI_PENDING)
            snprintf(s->pending[s->n_pending++], RT_RSI_LOG_LINE,
                     "rcal-rt: rsi: session %lu: the controller %s, ipoc %llu%s", s->sessions + 1, who, r.ipoc,
                     s->in_session ? " (the last one ended: silence or an IPOC jump over --rsi-timeout-ms); from a "
                                     "zero correction"
                                   : "");
        s->sessions++;
        s->in_session = 1;
        memset(s->ak_abs, 0, sizeof s->ak_abs);
        memset(s->want, 0, sizeof s->want);
        s->have_set = 0;
        /* a new program run: compensated from a cold start, as rcal compensate starts a file */
        rc_comp_stream_init(&c->cs[c->cur], &c->mod[c->cur].det, &c->mod[c->cur].nom_pt, &c->mod[c->cur].cfg);
    } else {
        steps = (double)(r.ipoc - s->last_ipoc) / o->cycle_ms;
        if (steps > 1.5)
            fault(s, F_DROP, "ipoc %llu after %llu: %.0f datagram(s) missing", r.ipoc, s->last_ipoc, steps - 1.0);
        else if (now - s->last_rx_s > 1.5 * o->cycle_ms / 1e3)
            fault(s, F_LATE, "ipoc %llu arrived %.3f ms after the previous one", r.ipoc, (now - s->last_rx_s) * 1e3);
    }
    if (!s->have_ctrl) {
        s->have_ctrl = 1;
        s->ctrl = *from;
    }
    s->ctrl.sin_port = from->sin_port; /* the controller's port of this datagram */
    s->last_ipoc = r.ipoc;
    s->last_rx_s = now;
    const double t_comp = mono_s();
    compensate(s, c, &r, steps < 1.0 ? 1.0 : steps);
    double ak[RT_RSI_NAX];
    step_toward(s, ak, o, r.ipoc);
    const double t_send = mono_s();
    s->max_comp_us = fmax(s->max_comp_us, (t_send - t_comp) * 1e6);
    char out[RT_RSI_MAX_REPLY];
    const size_t n = rt_rsi_encode(out, sizeof out, &io->names, ak, r.ipoc);
    if (n == 0 || sendto(io->fd, out, n, 0, (const struct sockaddr *)from, sizeof *from) != (ssize_t)n) {
        fault(s, F_SEND, "ipoc %llu to %s: %s", r.ipoc, who, n == 0 ? "the answer did not fit" : strerror(errno));
        return;
    }
    s->max_send_us = fmax(s->max_send_us, (mono_s() - t_send) * 1e6);
    struct timespec tx;
    clock_gettime(CLOCK_REALTIME, &tx);
    const double took_us = ((double)(tx.tv_sec - rx->tv_sec) * 1e9 + (double)(tx.tv_nsec - rx->tv_nsec)) / 1e3;
    rt_rsi_hist_add(&io->hist, took_us);
    s->over_cycle += took_us > o->cycle_ms * 1e3;
    s->answered++;
    if (r.delay > s->robot_delay && s->robot_delay >= 0)
        fault(s, F_ROBOT_LATE, "ipoc %llu: the robot counts %ld late answers (DEF_Delay)", r.ipoc, r.delay);
    s->robot_delay = r.delay;
}

static void one(rsi_state *s, rsi_io *io, rsi_comp *c, const rsi_opts *o, const char *buf, size_t len,
                const struct sockaddr_in *from, const struct timespec *rx)
{
    one_dgram(s, io, c, o, buf, len, from, rx);
    flush_log(s);
}

/* The model file replaced while running (the watcher thread read it, off
 * the answer path): the new model taken between two datagrams, its stream
 * started cold (as rcal compensate starts), the correction moving to the
 * new model's by at most --rsi-max-step-deg per answer (step_toward); a
 * file that cannot be used is counted and the model in use kept. */
static void take_model(rsi_state *s, rsi_io *io, rsi_comp *c, const rsi_opts *o)
{
    static rt_rsi_model next;
    char msg[700];
    const int what = rt_rsi_watch_take(&io->watch, &next, msg, sizeof msg);
    if (what == RT_RSI_WATCH_NONE)
        return;
    s->count[F_MODEL]++;
    if (what == RT_RSI_WATCH_REMOVED) {
        fault(s, F_RELOAD_REFUSED, "%s was removed (%s): the model in use kept", o->model, msg);
        return;
    }
    if (what == RT_RSI_WATCH_REFUSED) {
        fault(s, F_RELOAD_REFUSED, "%s changed but cannot be used, the model in use kept: %s", o->model, msg);
        return;
    }
    const int k = 1 - c->cur;
    c->mod[k] = next;
    if (rc_comp_stream_init(&c->cs[k], &c->mod[k].det, &c->mod[k].nom_pt, &c->mod[k].cfg) != RC_OK) {
        fault(s, F_RELOAD_REFUSED, "%s changed but cannot be used for compensation: the model in use kept", o->model);
        return;
    }
    /* a cold start, as rcal compensate starts a file: from here the answers are compensate's on the rest of the
     * path with the new model (position only, a warm start from the old model's correction could settle on
     * another of the joint solutions); step_toward moves the correction there */
    c->cur = k;
    s->reloads++;
    if (s->n_pending < RT_RSI_PENDING)
        snprintf(s->pending[s->n_pending++], RT_RSI_LOG_LINE, "rcal-rt: rsi: model_file_changed #%lu: %.180s; the "
                 "correction moves to it at most %g deg per answer", s->count[F_MODEL], msg, o->max_step_deg);
}

static void report(const rsi_state *s, const rsi_io *io, const rsi_opts *o, double cpu_s, int fifo_on)
{
    const rt_rsi_hist *h = &io->hist;
    const double cpu_us = s->answered ? cpu_s / (double)s->answered * 1e6 : 0.0;
    if (o->json) {
        printf("{\"mode\": \"%s\", \"max_step_deg\": %.9g, \"sched_fifo\": %s, \"datagrams\": %lu, \"answered\": %lu, "
               "\"sessions\": %lu, \"faults\": {", o->relative ? "relative" : "absolute", o->max_step_deg,
               fifo_on ? "true" : "false", s->datagrams, s->answered, s->sessions);
        for (int k = 0; k < F_N; ++k)
            printf("%s\"%s\": %lu", k ? ", " : "", f_name[k], s->count[k]);
        printf("}, \"largest_step_deg\": %.10f, \"latency_us\": {\"median\": %.1f, \"p99\": %.1f, \"p99_99\": %.1f, "
               "\"max\": %.1f, \"mean\": %.2f}, \"answers_over_a_cycle\": %lu, \"cpu_us_per_answer\": %.2f, "
               "\"reloads\": %lu, \"stage_max_us\": {\"wake\": %.1f, \"decode\": %.1f, \"compensate\": %.1f, "
               "\"send\": %.1f, \"after\": %.1f}, \"wakes_over_1ms\": %lu}\n",
               s->max_step_seen, rt_rsi_hist_pct(h, 50), rt_rsi_hist_pct(h, 99), rt_rsi_hist_pct(h, 99.99),
               h->max_us, h->n ? h->sum_us / (double)h->n : 0.0, s->over_cycle, cpu_us, s->reloads,
               s->max_wake_us, s->max_decode_us, s->max_comp_us, s->max_send_us, s->max_after_us, s->wake_over_ms);
        return;
    }
    printf("rcal-rt rsi: %lu datagrams, %lu answered, %lu session(s), %s corrections, %s\n", s->datagrams,
           s->answered, s->sessions, o->relative ? "relative" : "absolute",
           fifo_on ? "SCHED_FIFO" : "not SCHED_FIFO (a normal process)");
    printf("  faults:");
    for (int k = 0; k < F_N; ++k)
        printf(" %s %lu%s", f_name[k], s->count[k], k + 1 < F_N ? "," : "\n");
    printf("  largest change of the correction between answers: %.10f deg (limit %.10f)\n", s->max_step_seen,
           o->max_step_deg);
    printf("  receive-to-send latency (kernel receive to sendto done): median %.1f us, p99 %.1f, p99.99 %.1f, max "
           "%.1f; %lu answers over a cycle; CPU %.2f us per answer\n",
           rt_rsi_hist_pct(h, 50), rt_rsi_hist_pct(h, 99), rt_rsi_hist_pct(h, 99.99), h->max_us, s->over_cycle,
           cpu_us);
    printf("  model files taken while running: %lu; the longest stage: wake-up (kernel receive to the read) %.1f us "
           "(%lu over 1 ms), decode %.1f us, compensate %.1f us, send %.1f us, after the answer (the model taken, the "
           "log) %.1f us\n", s->reloads, s->max_wake_us, s->wake_over_ms, s->max_decode_us, s->max_comp_us,
           s->max_send_us, s->max_after_us);
}

static int rx_one(rsi_io *io, char *buf, size_t cap, size_t *len, struct sockaddr_in *from, struct timespec *rx,
                  double *wake_us)
{
    struct timespec read_at;
    int trunc;
    /* blocks up to SO_RCVTIMEO (100 ms): one call per datagram */
    const ssize_t n = rt_sched_recv_stamped(io->fd, buf, cap, 0, from, rx, &read_at, &trunc);
    if (n < 0)
        return -1;
    /* from the kernel's receive to the read returning: the thread's wake-up (the scheduler's, not the loop's) */
    *wake_us = (rt_sched_ts_ns(&read_at) - rt_sched_ts_ns(rx)) / 1e3;
    *len = trunc ? cap + 1 : (size_t)n; /* over the limit: refused by the decoder */
    return 0;
}

/* --rsi-config, the port and --rsi-controller into io, net and o: -1 when
 * read, else the exit status (1 a file refused, 2 a usage error). */
static int setup(rsi_io *io, rt_rsi_net *net, rsi_opts *o)
{
    rt_rsi_names_default(&io->names);
    if (o->config) {
        char *text = NULL, msg[1024];
        size_t len = 0;
        rch_diag d;
        if (rch_read_file(&text, &len, o->config, (size_t)1 << 20, &d) != 0) {
            fprintf(stderr, "rcal-rt: %s\n", rch_diag_str(&d, msg, sizeof msg));
            return 1;
        }
        const rt_rsi_status st = rt_rsi_config_read(&io->names, net, msg, sizeof msg, text, len, o->config);
        free(text);
        if (st != RT_RSI_OK) {
            fprintf(stderr, "rcal-rt: %s\n", st == RT_RSI_ERR_CONFIG ? msg : rt_rsi_strerror(st));
            return 1;
        }
    }
    if (o->port < 0)
        o->port = net->port;
    if (o->port < 0) {
        fprintf(stderr, "rcal-rt: the RSI mode needs --rsi-port PORT (or a PORT in --rsi-config)\n");
        return 2;
    }
    if (o->controller) {
        if (inet_pton(AF_INET, o->controller, &io->only) != 1) {
            fprintf(stderr, "rcal-rt: --rsi-controller '%s' is not an IPv4 address\n", o->controller);
            return 2;
        }
        io->have_only = 1;
    }
    return -1;
}

/* The loop: one datagram, its answer, then the log and (once a second) the
 * model file; until --seconds or a signal. Then the report. */
static void serve(rsi_io *io, rsi_comp *c, const rsi_opts *o, int fifo_on)
{
    static rsi_state s;
    memset(&s, 0, sizeof s);
    s.robot_delay = -1;
    const double t_end = o->seconds > 0 ? mono_s() + o->seconds : INFINITY;
    double cpu0 = -1.0;
    static char buf[RT_RSI_MAX_DGRAM + 1];
    const struct timeval rcv_to = {0, 100000}; /* the stop flag and --seconds looked at 10 times a second */
    if (setsockopt(io->fd, SOL_SOCKET, SO_RCVTIMEO, &rcv_to, sizeof rcv_to) != 0)
        fprintf(stderr, "rcal-rt: rsi: SO_RCVTIMEO: %s\n", strerror(errno));
    for (double t = mono_s(); !g_stop && t < t_end;) {
        size_t len;
        struct sockaddr_in from;
        struct timespec rx;
        double wake_us = 0.0;
        if (rx_one(io, buf, sizeof buf - 1, &len, &from, &rx, &wake_us) == 0) {
            s.max_wake_us = fmax(s.max_wake_us, wake_us);
            s.wake_over_ms += wake_us > 1e3;
            if (cpu0 < 0) {
                struct timespec ct;
                clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ct);
                cpu0 = (double)ct.tv_sec + (double)ct.tv_nsec * 1e-9;
            }
            one(&s, io, c, o, buf, len, &from, &rx);
        } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
            fprintf(stderr, "rcal-rt: rsi: receive: %s\n", strerror(errno));
            break;
        }
        /* after the answer: a model the watcher posted (a try, never a wait), its log line */
        const double t_after = mono_s();
        take_model(&s, io, c, o);
        flush_log(&s);
        t = mono_s();
        s.max_after_us = fmax(s.max_after_us, (t - t_after) * 1e6);
    }
    struct timespec ct;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ct);
    const double cpu_s = cpu0 < 0 ? 0.0 : (double)ct.tv_sec + (double)ct.tv_nsec * 1e-9 - cpu0;
    report(&s, io, o, cpu_s, fifo_on);
}

int rt_rsi_main(int argc, char **argv)
{
    rsi_opts o;
    int rc = parse(&o, argc, argv);
    if (rc >= 0)
        return rc;
    static rsi_io io;
    memset(&io, 0, sizeof io);
    rt_rsi_net net = {"", -1};
    if ((rc = setup(&io, &net, &o)) >= 0)
        return rc;
    static rsi_comp comp;
    memset(&comp, 0, sizeof comp);
    const rt_rsi_model_src src = {o.model, o.nominal, o.position_only, o.full_pose};
    struct stat st0;
    const int have_st0 = stat(o.model, &st0) == 0; /* before the read: a replacement meanwhile is seen */
    char note[1024], err[1200];
    if (rt_rsi_model_load(&comp.mod[0], note, sizeof note, err, sizeof err, &src) != 0) {
        fprintf(stderr, "rcal-rt: %s\n", err);
        return 1;
    }
    fprintf(stderr, "rcal-rt: rsi: %s\n", note);
    if (rc_comp_stream_init(&comp.cs[0], &comp.mod[0].det, &comp.mod[0].nom_pt, &comp.mod[0].cfg) != RC_OK) {
        fprintf(stderr, "rcal-rt: %s: the model cannot be used for compensation\n", o.model);
        return 1;
    }
    io.dec = rt_rsi_dec_new(&io.names);
    if (!io.dec || rt_rsi_hist_init(&io.hist) != 0) {
        fprintf(stderr, "rcal-rt: out of memory\n");
        rt_rsi_dec_free(io.dec);
        return 1;
    }
    if (open_socket(&io.fd, &o, o.addr ? o.addr : net.ip[0] ? net.ip : "127.0.0.1", o.port) != 0) {
        rt_rsi_dec_free(io.dec);
        rt_rsi_hist_free(&io.hist);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal; /* no SA_RESTART: a signal ends the blocking read */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    rt_rsi_watch_start(&io.watch, &src, have_st0 ? &st0 : NULL, RT_RSI_WATCH_EVERY_S);
    const int fifo_on = rt_sched_realtime(o.pin, o.cpu, o.fifo);
    serve(&io, &comp, &o, fifo_on);
    rt_rsi_watch_stop(&io.watch);
    close(io.fd);
    rt_rsi_dec_free(io.dec);
    rt_rsi_hist_free(&io.hist);
    return 0;
}
