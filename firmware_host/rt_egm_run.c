/* SPDX-License-Identifier: MIT */
/* rt_egm_run.c - rcal-rt's EGM loop (rt_egm.h, docs/egm.md): a UDP socket,
 * one EgmSensor answer per EgmRobot from the controller, the targets from a
 * stream read without blocking, every fault counted and the reference kept
 * from jumping by the guard.
 *
 * The cycle: a datagram arrives -> the sender is checked (the controller's
 * address and port only), decoded, its seqno checked (duplicate, older,
 * gap), its planned and feedback joints checked against the recent
 * references -> the reply prepared after the previous answer (the next
 * target compensated, guarded) is encoded and sent -> then, off the
 * critical path, the next target is read and compensated, the model file
 * looked at, the log written. A target not there when the datagram arrives
 * (the stream stalls) is looked for once more, else the last reference is
 * sent again. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rch_ctrl.h"
#include "rch_data.h"
#include "rch_diag.h"
#include "rch_file.h"
#include "rt_egm.h"
#include "rt_sched.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
/* latency samples kept (beyond: the statistics of the first ones) */
#define EGM_MAX_SAMPLES ((size_t)1 << 22)
/* recent references the robot's planned and feedback joints are compared with (64 ms at 4 ms) */
#define EGM_HIST 16
/* a log line per fault kind: the first ones, then every EGM_LOG_EVERY-th */
#define EGM_LOG_FIRST 10
#define EGM_LOG_EVERY 1000
/* the model file looked at every this many replies (1 s at 250 Hz) */
#define EGM_WATCH_EVERY 250
/* this many older seqnos in a row from the controller: its numbering restarted (100 ms at 4 ms) */
#define EGM_RESTART_RUN 25u
/* a line of --in longer than this is refused */
#define EGM_MAX_LINE 4096

static volatile sig_atomic_t egm_stop;
static void on_signal(int sig)
{
    (void)sig;
    egm_stop = 1;
}


void rt_egm_opts_default(rt_egm_opts *o)
{
    memset(o, 0, sizeof *o);
    o->bind_addr = "127.0.0.1";
    o->period_ms = 4.0;
    o->step_deg = 0.01;
    o->follow_deg = 1.0;
    o->timeout_s = 1.0;
    o->wait_s = 60.0;
    o->label = "rcal-rt egm";
}

/* ---- the target stream: --in read line by line without blocking ---- */

typedef struct egm_src {
    int fd;
    const char *name;
    char line[EGM_MAX_LINE + 2];
    size_t have;            /* bytes of the line being assembled */
    int too_long;           /* the current line passed EGM_MAX_LINE */
    unsigned lineno;        /* lines completed */
    char header[EGM_MAX_LINE + 2];
    int has_header, first_done, eof;
    int fifo, seen_data;    /* a FIFO: its end is a read of 0 after data came (before: no writer yet) */
    char buf[8192];
    size_t off, len;        /* read but not yet consumed */
    const rc_model *lim;
} egm_src;

/* One complete line (NUL-terminated, no newline): 1 a target, 0 nothing (a
 * header, a blank line), -2 refused (message on stderr). */
static int src_line(egm_src *s, double q_rad[RT_EGM_NJ])
{
    char text[2 * EGM_MAX_LINE + 8];
    int n = snprintf(text, sizeof text, "%s%s%s\n", s->has_header ? s->header : "", s->has_header ? "\n" : "",
                     s->line);
    if (n < 0 || (size_t)n >= sizeof text)
        return -2;
    rch_data data;
    rch_diag d;
    memset(&d, 0, sizeof d);
    const int rc = rch_data_parse_limited(&data, text, (size_t)n, s->name,
                                          RCH_DATA_TARGETS | RCH_DATA_NO_LEN | RCH_DATA_ALLOW_EMPTY, s->lim, &d);
    const int first = !s->first_done;
    s->first_done = 1;
    if (rc != 0) {
        /* the message's line is the line in the stream, not in the text parsed */
        d.line = s->lineno;
        char msg[1024];
        fprintf(stderr, "rcal-rt: egm: target refused, the reference held: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return -2;
    }
    int got = 0;
    if (data.n == 1) {
        memcpy(q_rad, data.s[0].q_rad, sizeof(double) * RT_EGM_NJ);
        got = 1;
    } else if (first && s->line[strspn(s->line, " \t\r")] != '\0') {
        memcpy(s->header, s->line, strlen(s->line) + 1); /* the header, prepended to every row after */
        s->has_header = 1;
    }
    rch_data_free(&data);
    return got;
}

/* The next target: 1, 0 none yet, -1 the end, -2 a row refused. */
static int src_next(egm_src *s, double q_rad[RT_EGM_NJ])
{
    for (;;) {
        while (s->off < s->len) {
            const char c = s->buf[s->off++];
            if (c == '\n') {
                s->line[s->have] = '\0';
                s->lineno++;
                const int was_long = s->too_long;
                s->have = 0;
                s->too_long = 0;
                if (was_long) {
                    fprintf(stderr, "rcal-rt: egm: %s:%u: target refused, the reference held: a line longer than "
                                    "%d bytes\n", s->name, s->lineno, EGM_MAX_LINE);
                    return -2;
                }
                const int r = src_line(s, q_rad);
                if (r != 0)
                    return r;
            } else if (s->have < EGM_MAX_LINE) {
                s->line[s->have++] = c;
            } else {
                s->too_long = 1;
            }
        }
        if (s->eof) {
            if (s->have > 0 || s->too_long) { /* a last line without its newline */
                s->buf[0] = '\n';
                s->off = 0;
                s->len = 1;
                continue;
            }
            return -1;
        }
        const ssize_t n = read(s->fd, s->buf, sizeof s->buf);
        if (n > 0) {
            s->off = 0;
            s->len = (size_t)n;
            s->seen_data = 1;
        } else if (n == 0 && s->fifo && !s->seen_data) {
            return 0; /* no writer has opened the FIFO yet: a stall, not the end */
        } else if (n == 0) {
            s->eof = 1; /* a FIFO: every writer closed it; a file: its end */
        } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
            return 0;
        } else if (errno != EINTR) {
            fprintf(stderr, "rcal-rt: egm: reading %s: %s\n", s->name, strerror(errno));
            s->eof = 1;
        }
    }
}

/* A regular file is checked whole first the way rcal-rt --in checks it
 * (every field, the limits, the radians rule); a FIFO, a pipe or standard
 * input (whatever it is) row by row. */
static int src_open(egm_src *s, const char *path, const rc_model *lim)
{
    memset(s, 0, sizeof *s);
    s->name = strcmp(path, "-") == 0 ? "<stdin>" : path;
    s->lim = lim;
    s->fd = strcmp(path, "-") == 0 ? 0 : open(path, O_RDONLY | O_NONBLOCK);
    if (s->fd < 0) {
        fprintf(stderr, "rcal-rt: egm: --in %s: %s\n", path, strerror(errno));
        return -1;
    }
    struct stat st;
    if (s->fd != 0 && fstat(s->fd, &st) == 0 && S_ISREG(st.st_mode)) {
        char *text = NULL, msg[1024];
        size_t len = 0;
        rch_diag d;
        rch_data data;
        memset(&d, 0, sizeof d);
        if (rch_read_file(&text, &len, path, (size_t)64 << 20, &d) != 0 ||
            rch_data_parse_limited(&data, text, len, path, RCH_DATA_TARGETS | RCH_DATA_NO_LEN, lim, &d) != 0) {
            free(text);
            fprintf(stderr, "rcal-rt: egm: %s\n", rch_diag_str(&d, msg, sizeof msg));
            close(s->fd);
            return -1;
        }
        free(text);
        double mx[RT_EGM_NJ] = {0};
        for (size_t k = 0; k < data.n; ++k)
            for (int i = 0; i < RT_EGM_NJ; ++i)
                mx[i] = fmax(mx[i], fabs(data.s[k].q_rad[i] / DEG));
        char why[256];
        const int rad = rch_data_q_look_rad(why, sizeof why, mx, data.n);
        rch_data_free(&data);
        if (rad) {
            fprintf(stderr, "rcal-rt: egm: %s: %s\n", path, why);
            close(s->fd);
            return -1;
        }
    } else if (s->fd != 0) {
        s->fifo = 1; /* opened without blocking (with no writer yet); reads stay non-blocking */
    } else {
        fcntl(0, F_SETFL, fcntl(0, F_GETFL) | O_NONBLOCK);
    }
    return 0;
}

/* ---- counts, statistics, the log ---- */

enum {
    F_FOREIGN, F_MALFORMED, F_DUPLICATE, F_REORDERED, F_DROPPED, F_LATE, F_STALL, F_BAD_ROW, F_NOCONV, F_CLAMPED,
    F_NOFOLLOW, F_RELOAD_REFUSED, F_SEND, F_NKIND
};
static const char *const fault_name[F_NKIND] = {
    "foreign", "malformed", "duplicate", "reordered", "dropped", "late", "stall", "bad_row", "not_compensated",
    "limited", "not_following", "reload_refused", "send_failed"};

typedef struct egm_state {
    const rt_egm_opts *o;
    unsigned long n[F_NKIND];
    unsigned long replies, targets, rows_refused, reloads, datagrams;
    double *lat_us, *cpu_us;
    size_t ns;
    rt_egm_guard g;
    double hist[EGM_HIST][RT_EGM_NJ];
    unsigned nhist, hpos;
    unsigned back_run;           /* older seqnos in a row */
    unsigned long restarts;      /* numbering restarts taken */
    rc_model lim_model;          /* the model's joint limits (a target mapped from the controller's checked) */
} egm_state;

/* 1 when this occurrence of fault k is to be logged */
static int count_fault(egm_state *st, int k, unsigned long by)
{
    const unsigned long before = st->n[k];
    st->n[k] += by;
    return !st->o->quiet && (before < EGM_LOG_FIRST || before / EGM_LOG_EVERY != st->n[k] / EGM_LOG_EVERY);
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double pct(const double *v, size_t n, double p)
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

static int addr_eq(const struct sockaddr_in *a, const struct sockaddr_in *b)
{
    return a->sin_addr.s_addr == b->sin_addr.s_addr && a->sin_port == b->sin_port;
}

static const char *addr_str(char *buf, size_t n, const struct sockaddr_in *a)
{
    char ip[INET_ADDRSTRLEN] = "?";
    inet_ntop(AF_INET, &a->sin_addr, ip, sizeof ip);
    snprintf(buf, n, "%s:%u", ip, (unsigned)ntohs(a->sin_port));
    return buf;
}

/* largest joint difference of q to the nearest recent reference, and the joint */
static double nearest_ref(const egm_state *st, const double q[RT_EGM_NJ], int *joint)
{
    double best = INFINITY;
    *joint = 0;
    for (unsigned h = 0; h < st->nhist; ++h) {
        double m = 0.0;
        int jm = 0;
        for (int i = 0; i < RT_EGM_NJ; ++i)
            if (fabs(q[i] - st->hist[h][i]) > m) {
                m = fabs(q[i] - st->hist[h][i]);
                jm = i;
            }
        if (m < best) {
            best = m;
            *joint = jm;
        }
    }
    return best;
}

/* ---- the model file watched ---- */

typedef struct egm_watch {
    struct stat st;
    int ok;
    rc_kin kin[2][2];  /* two sets (calibrated, nominal): the one in use and the one loaded into */
    int cur;           /* -1: the tables given to rt_egm_run are in use */
} egm_watch;

static int same_file(const struct stat *a, const struct stat *b)
{
    return a->st_ino == b->st_ino && a->st_dev == b->st_dev && a->st_size == b->st_size &&
           a->st_mtim.tv_sec == b->st_mtim.tv_sec && a->st_mtim.tv_nsec == b->st_mtim.tv_nsec;
}

/* The model file replaced: read again and, when it loads, the stream moved
 * to it (the guard limits the change of the correction). */
static void watch_model(egm_state *st, egm_watch *w, rc_comp_stream *s, rc_comp_config *cfg)
{
    const rt_egm_opts *o = st->o;
    struct stat now;
    if (!o->model_path || !o->reload || stat(o->model_path, &now) != 0 || (w->ok && same_file(&now, &w->st)))
        return;
    const int was_ok = w->ok;
    w->st = now;
    w->ok = 1;
    if (!was_ok)
        return;
    const int next = w->cur == 0 ? 1 : 0;
    unsigned flags = 0;
    char err[1024] = "";
    if (o->reload(o->reload_ctx, &w->kin[next][0], &w->kin[next][1], &flags, err, sizeof err) != 0) {
        if (count_fault(st, F_RELOAD_REFUSED, 1))
            fprintf(stderr, "rcal-rt: egm: the model file %s changed but cannot be used, the model in use kept: %s\n",
                    o->model_path, err);
        return;
    }
    rc_comp_config c = *cfg;
    c.flags = flags;
    const int had = s->have_dq;
    rc_real dq[RC_NJ], qp[RC_NJ];
    memcpy(dq, s->dq_rad, sizeof dq);
    memcpy(qp, s->q_prev_rad, sizeof qp);
    rc_comp_stream_init_kin(s, &w->kin[next][0], &w->kin[next][1], &c);
    /* warm start from the old correction: the new model's is close */
    s->have_dq = had;
    memcpy(s->dq_rad, dq, sizeof dq);
    memcpy(s->q_prev_rad, qp, sizeof qp);
    *cfg = c;
    w->cur = next;
    st->reloads++;
    if (!o->quiet)
        fprintf(stderr, "rcal-rt: egm: the model file %s changed: compensating with it from reply %lu (the "
                        "correction moves to it at most %g deg per cycle)\n", o->model_path, st->replies + 1,
                o->step_deg);
}

/* ---- the next reference ---- */

typedef struct egm_next {
    int ready;      /* a new target was compensated into sent */
    double sent[RT_EGM_NJ];
    int ended;      /* the stream ended */
} egm_next;

/* Prepare the next reference from the next target, if one is there. */
static void prepare(egm_state *st, egm_next *nx, egm_src *src, rc_comp_stream *s)
{
    const rt_egm_opts *o = st->o;
    if (nx->ready || nx->ended)
        return;
    double q[RT_EGM_NJ];
    int r;
    for (;;) {
        r = src ? src_next(src, q) : o->next(o->next_ctx, q);
        if (r != -2)
            break;
        st->rows_refused++;
        count_fault(st, F_BAD_ROW, 1);
    }
    if (r == -1) {
        nx->ended = 1;
        return;
    }
    if (r == 0)
        return;
    rc_real qr[RC_NJ], qc[RC_NJ];
    double t_deg[RT_EGM_NJ], c_deg[RT_EGM_NJ], qm[RT_EGM_NJ];
    /* the controller's joints (its signs, zeros, J2/J3 coupling) to the model's */
    memcpy(qm, q, sizeof qm);
    if (o->ctrl)
        rch_ctrl_to_model(qm, o->ctrl, qm);
    for (int i = 0; i < RT_EGM_NJ; ++i)
        if (!(qm[i] >= st->lim_model.q_min_rad[i] && qm[i] <= st->lim_model.q_max_rad[i])) {
            st->rows_refused++;
            if (count_fault(st, F_BAD_ROW, 1))
                fprintf(stderr, "rcal-rt: egm: target %lu refused, the reference held: joint %d = %.6f deg is "
                                "%.6f deg of the model, outside its limits [%g, %g] deg\n", st->targets + 1, i + 1,
                        q[i] / DEG, qm[i] / DEG, st->lim_model.q_min_rad[i] / DEG,
                        st->lim_model.q_max_rad[i] / DEG);
            return;
        }
    for (int i = 0; i < RT_EGM_NJ; ++i) {
        qr[i] = (rc_real)qm[i];
        t_deg[i] = q[i] / DEG;
    }
    rc_comp_result res;
    const rc_status cs = rc_comp_stream_step(s, qc, &res, qr);
    double cq[RT_EGM_NJ];
    for (int i = 0; i < RT_EGM_NJ; ++i)
        cq[i] = (double)qc[i];
    if (o->ctrl) /* back to the controller's joints */
        rch_ctrl_from_model(cq, o->ctrl, cq);
    for (int i = 0; i < RT_EGM_NJ; ++i)
        c_deg[i] = cq[i] / DEG;
    if (cs != RC_OK && count_fault(st, F_NOCONV, 1))
        fprintf(stderr, "rcal-rt: egm: target %lu not compensated (%s): its reference keeps the last good "
                        "correction\n", st->targets + 1,
                cs == RC_ERR_NOCONV ? rc_comp_exit_str(res.exit) : rc_strerror(cs));
    if (rt_egm_guard_step(&st->g, nx->sent, t_deg, cs == RC_OK ? c_deg : NULL) && count_fault(st, F_CLAMPED, 0))
        fprintf(stderr, "rcal-rt: egm: target %lu: the correction changed by more than %g deg in one cycle: "
                        "limited\n", st->targets + 1, o->step_deg);
    st->n[F_CLAMPED] = st->g.n_clamped;
    st->targets++;
    nx->ready = 1;
}

static int open_socket(const rt_egm_opts *o, struct sockaddr_in *ctl, int *has_ctl)
{
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)o->port);
    if (inet_pton(AF_INET, o->bind_addr, &a.sin_addr) != 1) {
        fprintf(stderr, "rcal-rt: egm: --egm-bind '%s' is not an IPv4 address\n", o->bind_addr);
        return -1;
    }
    *has_ctl = 0;
    memset(ctl, 0, sizeof *ctl);
    if (o->controller) {
        ctl->sin_family = AF_INET;
        if (inet_pton(AF_INET, o->controller, &ctl->sin_addr) != 1) {
            fprintf(stderr, "rcal-rt: egm: --egm-controller '%s' is not an IPv4 address\n", o->controller);
            return -1;
        }
        *has_ctl = 1;
    }
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) {
        fprintf(stderr, "rcal-rt: egm: socket: %s\n", strerror(errno));
        return -1;
    }
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        fprintf(stderr, "rcal-rt: egm: cannot listen on %s:%u/udp: %s\n", o->bind_addr, o->port, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

static void summary(egm_state *st, const char *why_end, int ended_input, int rc)
{
    const rt_egm_opts *o = st->o;
    qsort(st->lat_us, st->ns, sizeof(double), cmp_double);
    qsort(st->cpu_us, st->ns, sizeof(double), cmp_double);
    double cpu_mean = 0.0;
    for (size_t i = 0; i < st->ns; ++i)
        cpu_mean += st->cpu_us[i] / (double)st->ns;
    fprintf(stderr, "%s: %s; %lu datagrams, %lu replies, %lu targets taken%s, %lu rows refused\n", o->label, why_end,
            st->datagrams, st->replies, st->targets, ended_input ? " (the input ended)" : " (the input had not ended)",
            st->rows_refused);
    fprintf(stderr, "%s: faults:", o->label);
    for (int k = 0; k < F_NKIND; ++k)
        fprintf(stderr, " %s %lu", fault_name[k], st->n[k]);
    fprintf(stderr, "; model reloads %lu, seqno restarts %lu\n", st->reloads, st->restarts);
    if (st->ns)
        fprintf(stderr, "%s: receive-to-send median %.1f us, p99.99 %.1f us, max %.1f us; CPU per cycle median "
                        "%.1f us, mean %.1f us; exit status %d\n", o->label, pct(st->lat_us, st->ns, 50),
                pct(st->lat_us, st->ns, 99.99), st->lat_us[st->ns - 1], pct(st->cpu_us, st->ns, 50), cpu_mean, rc);
    else
        fprintf(stderr, "%s: no reply sent; exit status %d\n", o->label, rc);
    if (o->json) {
        printf("{\"label\": \"%s\", \"end\": \"%s\", \"datagrams\": %lu, \"replies\": %lu, \"targets\": %lu, "
               "\"input_ended\": %d, \"rows_refused\": %lu, \"reloads\": %lu, \"restarts\": %lu, \"faults\": {",
               o->label, why_end, st->datagrams, st->replies, st->targets, ended_input, st->rows_refused, st->reloads,
               st->restarts);
        for (int k = 0; k < F_NKIND; ++k)
            printf("%s\"%s\": %lu", k ? ", " : "", fault_name[k], st->n[k]);
        printf("}, \"rx_tx_us\": {\"median\": %.3f, \"p99_99\": %.3f, \"max\": %.3f}, \"cpu_us\": {\"median\": "
               "%.3f, \"mean\": %.3f}, \"samples\": %zu, \"exit\": %d}\n",
               st->ns ? pct(st->lat_us, st->ns, 50) : 0.0, st->ns ? pct(st->lat_us, st->ns, 99.99) : 0.0,
               st->ns ? st->lat_us[st->ns - 1] : 0.0, st->ns ? pct(st->cpu_us, st->ns, 50) : 0.0, cpu_mean, st->ns,
               rc);
        fflush(stdout);
    }
}

/* The checks of one datagram from the controller (seqno, timing, the robot
 * following): 1 to answer it, 0 to drop it. */
static int check_datagram(egm_state *st, const rt_egm_robot *r, int *have_seq, uint32_t *last_seq, double t_rx,
                          double *t_last, const char *from)
{
    const rt_egm_opts *o = st->o;
    if (*have_seq) {
        const int32_t d = (int32_t)(r->seqno - *last_seq);
        if (d == 0) {
            if (count_fault(st, F_DUPLICATE, 1))
                fprintf(stderr, "rcal-rt: egm: seqno %u from %s again: a duplicate, not answered\n", r->seqno, from);
            return 0;
        }
        if (d < 0) {
            if (count_fault(st, F_REORDERED, 1))
                fprintf(stderr, "rcal-rt: egm: seqno %u from %s after %u: out of order, not answered\n", r->seqno,
                        from, *last_seq);
            /* a controller that restarted its numbering (a new EGM session): EGM_RESTART_RUN older seqnos in a
             * row are taken as the new numbering, not as reordering */
            if (++st->back_run < EGM_RESTART_RUN)
                return 0;
            fprintf(stderr, "rcal-rt: egm: %u datagrams in a row from %s numbered before %u: its numbering restarted "
                            "(at %u); answered again\n", st->back_run, from, *last_seq, r->seqno);
            st->restarts++;
        }
        st->back_run = 0;
        if (d > 1 && count_fault(st, F_DROPPED, (unsigned long)(d - 1)))
            fprintf(stderr, "rcal-rt: egm: seqno %u from %s after %u: %d datagrams lost\n", r->seqno, from,
                    *last_seq, d - 1);
        const double gap_ms = (t_rx - *t_last) / 1e6;
        if (gap_ms > 1.5 * o->period_ms && count_fault(st, F_LATE, 1))
            fprintf(stderr, "rcal-rt: egm: seqno %u from %s came %.2f ms after the last (the cycle is %g ms)\n",
                    r->seqno, from, gap_ms, o->period_ms);
    }
    *have_seq = 1;
    *last_seq = r->seqno;
    *t_last = t_rx;
    /* the robot follows: its planned and its feedback joints near a recent reference */
    if (st->nhist >= 2) {
        int jp = 0, jf = 0;
        const double dp = r->has_planned ? nearest_ref(st, r->planned_deg, &jp) : 0.0;
        const double df = nearest_ref(st, r->fb_deg, &jf);
        if ((dp > o->follow_deg || df > o->follow_deg) && count_fault(st, F_NOFOLLOW, 1)) {
            if (dp > o->follow_deg)
                fprintf(stderr, "rcal-rt: egm: the robot at %s does not follow: its planned q%d is %.3f deg from "
                                "the nearest of the last %u references (seqno %u; limit %g deg)\n", from, jp + 1, dp,
                        st->nhist, r->seqno, o->follow_deg);
            else
                fprintf(stderr, "rcal-rt: egm: the robot at %s does not follow: its feedback q%d is %.3f deg from "
                                "the nearest of the last %u references (seqno %u; limit %g deg)\n", from, jf + 1, df,
                        st->nhist, r->seqno, o->follow_deg);
        }
    }
    return 1;
}

/* The loop's state (one run at a time: static storage in rt_egm_run). */
typedef struct egm_loop {
    egm_state st;
    egm_watch w;
    rc_comp_stream s;
    rc_comp_config cfg;
    rt_egm_arena arena;
    egm_src src, *sp;        /* sp: &src with --in, else NULL (o->next) */
    rc_model lim;            /* the joint limits the reader checks */
    egm_next nx;
    int fd, has_ctl, locked, have_seq, have_ref;
    struct sockaddr_in ctl;
    char ctl_s[64];
    double t0, t_last;
    uint32_t last_seq, own_seq;
    double ref[RT_EGM_NJ];   /* the last reference sent */
} egm_loop;

/* A datagram from peer (n bytes in buf) checked: 1 to answer it (r decoded), 0 to drop it. */
static int accept_datagram(egm_loop *L, rt_egm_robot *r, const unsigned char *buf, size_t n,
                           const struct sockaddr_in *peer, double t_rx)
{
    egm_state *st = &L->st;
    char from[64], why[256];
    /* only the controller: the address given, else the first valid sender (address and port); the sender's
     * address made into text only for a log line (the controller's once, at the lock) */
    const int from_ctl = L->locked ? addr_eq(peer, &L->ctl)
                         : L->has_ctl ? peer->sin_addr.s_addr == L->ctl.sin_addr.s_addr : 1;
    if (!from_ctl) {
        if (count_fault(st, F_FOREIGN, 1))
            fprintf(stderr, "rcal-rt: egm: a datagram from %s, not the controller: not answered\n",
                    addr_str(from, sizeof from, peer));
        return 0;
    }
    if (rt_egm_decode(r, why, sizeof why, &L->arena, buf, n) != 0) {
        if (count_fault(st, F_MALFORMED, 1))
            fprintf(stderr, "rcal-rt: egm: from %s: %s: not answered\n", addr_str(from, sizeof from, peer), why);
        return 0;
    }
    if (!L->locked) {
        L->ctl = *peer;
        L->locked = 1;
        addr_str(L->ctl_s, sizeof L->ctl_s, &L->ctl);
        if (!st->o->quiet)
            fprintf(stderr, "rcal-rt: egm: the controller is %s (only it is answered)\n", L->ctl_s);
    }
    st->datagrams++;
    return check_datagram(st, r, &L->have_seq, &L->last_seq, t_rx, &L->t_last, L->ctl_s);
}

/* The answer to r: the reference sent, then (off the critical path) the next one prepared and the model
 * file looked at; the cycle's times recorded. */
static void answer(egm_loop *L, const rt_egm_robot *r, double t_rx, double c_rx)
{
    egm_state *st = &L->st;
    uint8_t out[256];
    /* the reference: the prepared one, else (the stream stalled) one more look, else the last again */
    if (!L->nx.ready)
        prepare(st, &L->nx, L->sp, &L->s);
    if (L->nx.ready) {
        memcpy(L->ref, L->nx.sent, sizeof L->ref);
        L->have_ref = 1;
        L->nx.ready = 0;
    } else if (!L->nx.ended && count_fault(st, F_STALL, 1)) {
        fprintf(stderr, "rcal-rt: egm: no target from %s for seqno %u: the last reference held\n",
                L->sp ? L->sp->name : "the source", r->seqno);
    }
    if (!L->have_ref) { /* nothing to send yet: the robot holds where it is */
        memcpy(L->ref, r->fb_deg, sizeof L->ref);
        L->have_ref = 1;
    }
    const uint32_t tm = (uint32_t)((t_rx - L->t0) / 1e6);
    const size_t len = rt_egm_encode(out, sizeof out, ++L->own_seq, tm, L->ref);
    const ssize_t sent = sendto(L->fd, out, len, 0, (const struct sockaddr *)&L->ctl, sizeof L->ctl);
    const double t_tx = rt_sched_now_ns();
    if (sent != (ssize_t)len && count_fault(st, F_SEND, 1))
        fprintf(stderr, "rcal-rt: egm: sending to %s: %s\n", L->ctl_s, sent < 0 ? strerror(errno) : "short write");
    st->replies++;
    memcpy(st->hist[st->hpos], L->ref, sizeof L->ref);
    st->hpos = (st->hpos + 1) % EGM_HIST;
    if (st->nhist < EGM_HIST)
        st->nhist++;
    if (st->replies % EGM_WATCH_EVERY == 0)
        watch_model(st, &L->w, &L->s, &L->cfg);
    prepare(st, &L->nx, L->sp, &L->s);
    if (st->ns < EGM_MAX_SAMPLES) {
        st->lat_us[st->ns] = (t_tx - t_rx) / 1e3;
        st->cpu_us[st->ns] = (rt_sched_cpu_ns() - c_rx) / 1e3;
        st->ns++;
    }
}

/* The model's joint limits m as the controller's (out): its signs and
 * zeros exactly, its J2/J3 coupling by the interval of c3 over the box (the
 * reader and the guard check these; each target is checked again in the
 * model's joints, exactly). */
static void ctrl_limits(rc_model *out, const struct rch_ctrl *c, const rc_model *m)
{
    for (int i = 0; i < RC_NJ; ++i) {
        out->q_min_rad[i] = m->q_min_rad[i];
        out->q_max_rad[i] = m->q_max_rad[i];
    }
    if (!c)
        return;
    for (int i = 0; i < RC_NJ; ++i) {
        double lo = m->q_min_rad[i], hi = m->q_max_rad[i];
        if (i == 2 && c->q3_coupling != 0.0) { /* c3 = s3 (q3 - k q2) + z3 */
            const double a = -c->q3_coupling * m->q_min_rad[1], b = -c->q3_coupling * m->q_max_rad[1];
            lo += fmin(a, b);
            hi += fmax(a, b);
        }
        const double x = c->sign[i] * lo + c->zero_rad[i], y = c->sign[i] * hi + c->zero_rad[i];
        out->q_min_rad[i] = fmin(x, y);
        out->q_max_rad[i] = fmax(x, y);
    }
}

/* Everything before the first datagram: the compensation, the guard, the
 * input, the socket, the sample arrays, the signals. 0, or the exit status. */
static int setup(egm_loop *L, const rt_egm_opts *o, const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg0)
{
    memset(L, 0, sizeof *L);
    L->st.o = o;
    L->w.cur = -1;
    L->cfg = *cfg0;
    rc_comp_stream_init_kin(&L->s, cal, nom, &L->cfg);
    double qmin[RT_EGM_NJ], qmax[RT_EGM_NJ];
    for (int i = 0; i < RC_NJ; ++i) {
        L->st.lim_model.q_min_rad[i] = (double)cal->q_min_rad[i];
        L->st.lim_model.q_max_rad[i] = (double)cal->q_max_rad[i];
    }
    ctrl_limits(&L->lim, o->ctrl, &L->st.lim_model);
    for (int i = 0; i < RC_NJ; ++i) {
        qmin[i] = L->lim.q_min_rad[i] / DEG;
        qmax[i] = L->lim.q_max_rad[i] / DEG;
    }
    rt_egm_guard_init(&L->st.g, o->step_deg, qmin, qmax);
    if (o->in_path && src_open(&L->src, o->in_path, &L->lim) != 0)
        return 1;
    L->sp = o->in_path ? &L->src : NULL;
    if ((L->fd = open_socket(o, &L->ctl, &L->has_ctl)) < 0)
        return 2;
    L->st.lat_us = malloc(EGM_MAX_SAMPLES * sizeof(double));
    L->st.cpu_us = malloc(EGM_MAX_SAMPLES * sizeof(double));
    if (!L->st.lat_us || !L->st.cpu_us) {
        fprintf(stderr, "rcal-rt: egm: out of memory\n");
        free(L->st.lat_us);
        free(L->st.cpu_us);
        close(L->fd);
        return 1;
    }
    egm_stop = 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    watch_model(&L->st, &L->w, &L->s, &L->cfg); /* its first look: what is there now */
    prepare(&L->st, &L->nx, L->sp, &L->s);
    L->t0 = L->t_last = rt_sched_now_ns();
    return 0;
}

int rt_egm_run(const rt_egm_opts *o, const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg0)
{
    static egm_loop L;
    int rc = setup(&L, o, cal, nom, cfg0);
    if (rc != 0)
        return rc;
    const char *why_end = "stopped by a signal";
    unsigned char buf[RT_EGM_MAX_DGRAM + 1];
    while (!egm_stop) {
        const double wait_ms = L.st.datagrams ? o->timeout_s * 1e3 - (rt_sched_now_ns() - L.t_last) / 1e6
                                              : o->wait_s * 1e3 - (rt_sched_now_ns() - L.t0) / 1e6;
        if (wait_ms <= 0) {
            why_end = L.st.datagrams ? "the controller fell silent" : "no datagram from a controller";
            break;
        }
        struct pollfd pfd = {L.fd, POLLIN, 0};
        if (poll(&pfd, 1, (int)ceil(wait_ms)) <= 0)
            continue; /* a timeout or a signal: looked at above */
        struct sockaddr_in peer;
        memset(&peer, 0, sizeof peer);
        socklen_t pl = sizeof peer;
        const ssize_t n = recvfrom(L.fd, buf, sizeof buf, MSG_TRUNC, (struct sockaddr *)&peer, &pl);
        const double t_rx = rt_sched_now_ns(), c_rx = rt_sched_cpu_ns();
        rt_egm_robot r;
        if (n >= 0 && accept_datagram(&L, &r, buf, (size_t)n, &peer, t_rx))
            answer(&L, &r, t_rx, c_rx);
    }
    const egm_state *st = &L.st;
    const int bad = st->rows_refused || st->n[F_NOCONV] || st->n[F_NOFOLLOW] || st->n[F_SEND] || !L.nx.ended ||
                    !st->datagrams;
    rc = bad ? 1 : 0;
    summary(&L.st, why_end, L.nx.ended, rc);
    free(L.st.lat_us);
    free(L.st.cpu_us);
    close(L.fd);
    if (L.sp && L.sp->fd != 0)
        close(L.sp->fd);
    return rc;
}
