/* SPDX-License-Identifier: MIT */
/* rch_link.c - the controller link rcal-link/1 (see rch_link.h, docs/controller-link.md). */
#include "rch_link.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static const char *const fault_names[RCH_LINK_NFAULTS] = {"OFFSET",  "DUPLICATE", "ORDER",   "PLACE", "UNKNOWN",
                                                          "VERSION", "BUSY",      "STALLED", "LOST"};

const char *rch_link_fault_name(int fault)
{
    return fault >= 0 && fault < RCH_LINK_NFAULTS ? fault_names[fault] : "?";
}

static long long mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

int rch_link_parse(char host[64], unsigned *port, const char *spec)
{
    const char *p, *colon;
    char *end;
    unsigned long v;
    struct in_addr a;
    if (!spec || strncmp(spec, "tcp:", 4) != 0)
        return -1;
    p = spec + 4;
    colon = strrchr(p, ':');
    if (colon) {
        size_t n = (size_t)(colon - p);
        if (n == 0 || n >= 64)
            return -1;
        memcpy(host, p, n);
        host[n] = '\0';
        if (inet_pton(AF_INET, host, &a) != 1)
            return -1;
        p = colon + 1;
    } else {
        memcpy(host, "127.0.0.1", sizeof "127.0.0.1");
    }
    if (*p < '0' || *p > '9')
        return -1;
    errno = 0;
    v = strtoul(p, &end, 10);
    if (errno || *end || v > 65535ul)
        return -1;
    *port = (unsigned)v;
    return 0;
}

static void say(const rch_link *l, const char *fmt, ...)
{
    va_list ap;
    if (!l->err)
        return;
    va_start(ap, fmt);
    fprintf(l->err, "rcal acquire: controller link: ");
    vfprintf(l->err, fmt, ap);
    va_end(ap);
}

static int nonblock(int fd)
{
    int fl = fcntl(fd, F_GETFL);
    return fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0 ? -1 : 0;
}

/* One line to fd, whole or not at all (bounded wait on a full buffer). 0, or -1. */
static int send_line_fd(int fd, const char *line)
{
    const size_t n = strlen(line);
    size_t off = 0;
    const long long t0 = mono_ms();
    while (off < n) {
        ssize_t w = send(fd, line + off, n - off, MSG_NOSIGNAL);
        if (w > 0) {
            off += (size_t)w;
            continue;
        }
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) && mono_ms() - t0 < 2000) {
            struct pollfd p = {fd, POLLOUT, 0};
            (void)poll(&p, 1, 50);
            continue;
        }
        return -1;
    }
    return 0;
}

static void drop(rch_link *l, int count_lost, const char *why)
{
    if (l->cfd < 0)
        return;
    close(l->cfd);
    l->cfd = -1;
    l->hello = 0;
    l->len = 0;
    l->skipping = 0;
    if (count_lost) {
        l->faults[RCH_LINK_LOST]++;
        say(l, "LOST: %s; waiting up to %lu s for the controller to connect again (%s is voided and asked again)\n",
            why, l->c.wait_ms / 1000ul, l->cmd[0] ? l->cmd : "nothing");
    }
}

static void send_line(rch_link *l, const char *fmt, ...)
{
    char line[RCH_LINK_MAX_LINE + 2];
    va_list ap;
    int n;
    if (l->cfd < 0)
        return;
    va_start(ap, fmt);
    n = vsnprintf(line, sizeof line - 1, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof line - 1)
        n = (int)sizeof line - 2;
    line[n] = '\n';
    line[n + 1] = '\0';
    if (send_line_fd(l->cfd, line) != 0) {
        drop(l, 1, "sending failed");
        return;
    }
    l->last_tx_ms = mono_ms();
}

static void fault(rch_link *l, rch_link_fault f, long pose, const char *fmt, ...)
{
    char text[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    l->faults[f]++;
    say(l, "%s at pose %ld: %s; nothing recorded from it\n", fault_names[f], pose, text);
    send_line(l, "FAULT %s %ld %s", fault_names[f], pose, text);
}

rc_status rch_link_open(rch_link *l, const rch_link_config *c, FILE *err)
{
    struct sockaddr_in sa;
    socklen_t sl = sizeof sa;
    int one = 1;
    memset(l, 0, sizeof *l);
    l->c = *c;
    l->lfd = l->cfd = -1;
    l->reading = -1;
    l->err = err;
    if (!(c->tol_deg > 0.0) || c->retries < 1 || c->wait_ms < 1 || c->link_timeout_ms < 1 ||
        c->move_timeout_ms < 1 || rch_link_parse(l->host, &l->port, c->spec) != 0) {
        say(l, "--controller %s: expected tcp:[HOST:]PORT (HOST a numeric IPv4 address, 127.0.0.1 by default; "
               "PORT 0..65535)\n", c->spec ? c->spec : "(none)");
        return RC_ERR_ARG;
    }
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons((unsigned short)l->port);
    inet_pton(AF_INET, l->host, &sa.sin_addr);
    l->lfd = socket(AF_INET, SOCK_STREAM, 0);
    if (l->lfd < 0 || setsockopt(l->lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
        bind(l->lfd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(l->lfd, 4) != 0 || nonblock(l->lfd) != 0 ||
        getsockname(l->lfd, (struct sockaddr *)&sa, &sl) != 0) {
        say(l, "cannot listen on %s:%u (--controller %s): %s\n", l->host, l->port, c->spec, strerror(errno));
        if (l->lfd >= 0)
            close(l->lfd);
        l->lfd = -1;
        return RC_ERR_IO;
    }
    l->port = ntohs(sa.sin_port);
    say(l, "listening on %s:%u for the controller (%s)\n", l->host, l->port, RCH_LINK_VERSION);
    return RC_OK;
}

/* A connection waiting: the controller, or a second one refused (BUSY). */
static void accept_one(rch_link *l)
{
    int fd = accept(l->lfd, NULL, NULL);
    if (fd < 0)
        return;
    if (l->cfd >= 0) {
        l->faults[RCH_LINK_BUSY]++;
        say(l, "BUSY: a second controller connected; refused (the first goes on)\n");
        (void)send_line_fd(fd, "FAULT BUSY -1 a controller is already connected\n");
        close(fd);
        return;
    }
    if (nonblock(fd) != 0) {
        close(fd);
        return;
    }
    l->cfd = fd;
    l->hello = 0;
    l->len = 0;
    l->skipping = 0;
    l->last_rx_ms = mono_ms();
    l->connects++;
}

/* Fields of a line (modified in place), at most max. */
static int split(char *s, char **f, int max)
{
    int n = 0;
    for (char *p = strtok(s, " \t"); p; p = strtok(NULL, " \t")) {
        if (n == max)
            return max + 1;
        f[n++] = p;
    }
    return n;
}

static int num(double *v, const char *s)
{
    char *end;
    *v = strtod(s, &end);
    return end != s && *end == '\0' && isfinite(*v) ? 0 : -1;
}

static int integer(long *v, const char *s)
{
    char *end;
    errno = 0;
    *v = strtol(s, &end, 10);
    return end != s && *end == '\0' && errno == 0 ? 0 : -1;
}

typedef struct waitfor {
    size_t pose;
    const double *plan_deg;
    double *q_deg, *xyz_mm;
    int *has_xyz;
    long long t_cmd;
    unsigned long offsets, stalls;
    int got;
    rc_status stop;
} waitfor;

static void command(rch_link *l, waitfor *w)
{
    send_line(l, "%s", l->cmd);
    w->t_cmd = mono_ms();
}

static void on_at(rch_link *l, waitfor *w, char **f, int n)
{
    long pose, outlet, point;
    double q[RC_NJ], x[3];
    if ((n != 10 && n != 13) || integer(&pose, f[1]) != 0 || integer(&outlet, f[2]) != 0 ||
        integer(&point, f[3]) != 0) {
        fault(l, RCH_LINK_UNKNOWN, -1, "AT needs POSE OUTLET POINT Q1..Q6 [X Y Z] (%d fields)", n - 1);
        return;
    }
    for (int j = 0; j < RC_NJ; ++j)
        if (num(&q[j], f[4 + j]) != 0) {
            fault(l, RCH_LINK_UNKNOWN, pose, "q%d '%.20s' is not a number", j + 1, f[4 + j]);
            return;
        }
    for (int j = 0; n == 13 && j < 3; ++j)
        if (num(&x[j], f[10 + j]) != 0) {
            fault(l, RCH_LINK_UNKNOWN, pose, "%c '%.20s' is not a number", "xyz"[j], f[10 + j]);
            return;
        }
    if (pose != (long)w->pose) {
        const int recorded = pose >= 0 && (size_t)pose < l->c.n_poses && l->done && l->done[pose];
        if (recorded || pose == l->reading) {
            fault(l, RCH_LINK_DUPLICATE, pose, "pose %ld was %s; waiting for pose %zu", pose,
                  recorded ? "recorded already" : "reported already", w->pose);
        } else {
            fault(l, RCH_LINK_ORDER, pose, "pose %zu was asked for (%s)", w->pose, l->cmd);
            command(l, w);
        }
        return;
    }
    if (outlet != l->c.outlet || point != l->c.point) {
        fault(l, RCH_LINK_PLACE, pose, "outlet %ld point %ld, this run measures outlet %d point %d", outlet, point,
              l->c.outlet, l->c.point);
        command(l, w);
        return;
    }
    for (int j = 0; j < RC_NJ; ++j)
        if (fabs(q[j] - w->plan_deg[j]) > l->c.tol_deg) {
            fault(l, RCH_LINK_OFFSET, pose, "q%d = %.6f deg, the plan %.4f deg (off %.4f, tolerance %g deg)", j + 1,
                  q[j], w->plan_deg[j], q[j] - w->plan_deg[j], l->c.tol_deg);
            if (++w->offsets >= l->c.retries) {
                say(l, "pose %zu reached elsewhere than planned %lu times in a row; stopping\n", w->pose, w->offsets);
                w->stop = RC_ERR_RANGE;
                return;
            }
            command(l, w);
            return;
        }
    memcpy(w->q_deg, q, sizeof q);
    *w->has_xyz = n == 13;
    if (n == 13)
        memcpy(w->xyz_mm, x, sizeof x);
    l->reading = pose;
    w->got = 1;
}

static void on_line(rch_link *l, waitfor *w, char *line)
{
    char *f[16];
    int n = split(line, f, 14);
    if (n == 0) {
        fault(l, RCH_LINK_UNKNOWN, -1, "empty line");
        return;
    }
    if (!l->hello) {
        if (n == 3 && strcmp(f[0], "HELLO") == 0 && strcmp(f[1], RCH_LINK_VERSION) == 0) {
            l->hello = 1;
            say(l, "controller '%.40s' connected\n", f[2]);
            send_line(l, "WELCOME %s %zu", RCH_LINK_VERSION, l->c.n_poses);
            command(l, w);
            return;
        }
        fault(l, RCH_LINK_VERSION_F, -1, "expected HELLO %s NAME first", RCH_LINK_VERSION);
        drop(l, 0, "");
        return;
    }
    if (strcmp(f[0], "HB") == 0 && n == 1)
        return;
    if (strcmp(f[0], "BYE") == 0 && n == 1) {
        drop(l, 1, "the controller said BYE");
        return;
    }
    if (strcmp(f[0], "AT") == 0) {
        on_at(l, w, f, n);
        return;
    }
    fault(l, RCH_LINK_UNKNOWN, -1, "unknown message '%.20s'", f[0]);
}

/* Hand over the complete lines buffered, until a report is accepted or the run must stop. */
static void process(rch_link *l, waitfor *w)
{
    while (!w->got && !w->stop && l->cfd >= 0) {
        char *nl = memchr(l->buf, '\n', l->len);
        if (!nl) {
            if (l->len > RCH_LINK_MAX_LINE) { /* too long: refuse it, skip to its end */
                if (!l->skipping)
                    fault(l, RCH_LINK_UNKNOWN, -1, "line longer than %u bytes", RCH_LINK_MAX_LINE);
                l->skipping = 1;
                l->len = 0;
            }
            return;
        }
        size_t n = (size_t)(nl - l->buf);
        *nl = '\0';
        if (n > 0 && l->buf[n - 1] == '\r')
            l->buf[--n] = '\0';
        if (l->skipping) {
            l->skipping = 0;
        } else if (n > RCH_LINK_MAX_LINE) {
            fault(l, RCH_LINK_UNKNOWN, -1, "line longer than %u bytes", RCH_LINK_MAX_LINE);
        } else {
            int bad = 0;
            for (size_t i = 0; i < n; ++i)
                bad |= (unsigned char)l->buf[i] < 0x20 || (unsigned char)l->buf[i] > 0x7e;
            if (bad)
                fault(l, RCH_LINK_UNKNOWN, -1, "not printable ASCII");
            else
                on_line(l, w, l->buf);
        }
        if (l->cfd < 0)
            return; /* dropped: the rest is void */
        l->len -= (size_t)(nl + 1 - l->buf);
        memmove(l->buf, nl + 1, l->len);
    }
}

/* Read what is there, then hand over complete lines. */
static void on_readable(rch_link *l, waitfor *w)
{
    ssize_t r = recv(l->cfd, l->buf + l->len, sizeof l->buf - 1 - l->len, 0);
    if (r == 0 || (r < 0 && errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK)) {
        drop(l, 1, r == 0 ? "the controller closed the connection" : strerror(errno));
        return;
    }
    if (r < 0)
        return;
    l->last_rx_ms = mono_ms();
    l->len += (size_t)r;
    process(l, w);
}

rc_status rch_link_pose(rch_link *l, const char *cmd, size_t pose, const double plan_deg[RC_NJ], double q_deg[RC_NJ],
                        double xyz_mm[3], int *has_xyz)
{
    waitfor w;
    long long lost_at = mono_ms();
    memset(&w, 0, sizeof w);
    w.pose = pose;
    w.plan_deg = plan_deg;
    w.q_deg = q_deg;
    w.xyz_mm = xyz_mm;
    w.has_xyz = has_xyz;
    *has_xyz = 0;
    snprintf(l->cmd, sizeof l->cmd, "%s %zu", cmd, pose);
    l->last_rx_ms = mono_ms(); /* a pose's reading is no silence of the controller's */
    if (l->cfd >= 0 && l->hello)
        command(l, &w);
    if (l->cfd >= 0 && l->hello)
        process(l, &w); /* lines that came while the display was read */
    while (!w.got && !w.stop) {
        struct pollfd p[2];
        const long long now = mono_ms();
        int np = 1, rc;
        if (l->cfd < 0) {
            if (now - lost_at > (long long)l->c.wait_ms) {
                say(l, "no controller connected within %lu s (--controller-wait-s); stopping\n", l->c.wait_ms / 1000ul);
                return RC_ERR_TIMEOUT;
            }
        } else {
            lost_at = now;
            if (l->hello && now - l->last_tx_ms >= (long long)l->c.hb_ms)
                send_line(l, "HB");
            if (now - l->last_rx_ms > (long long)l->c.link_timeout_ms) {
                drop(l, 1, "nothing received within the link timeout");
                continue;
            }
            if (l->hello && now - w.t_cmd > (long long)l->c.move_timeout_ms) {
                l->faults[RCH_LINK_STALLED]++;
                say(l, "STALLED at pose %zu: no AT within %lu ms of '%s' (%lu/%lu)\n", pose, l->c.move_timeout_ms,
                    l->cmd, w.stalls + 1, l->c.retries);
                if (++w.stalls >= l->c.retries)
                    return RC_ERR_TIMEOUT;
                send_line(l, "FAULT STALLED %zu no AT within %lu ms", pose, l->c.move_timeout_ms);
                command(l, &w);
                continue;
            }
        }
        p[0].fd = l->lfd;
        p[0].events = POLLIN;
        p[0].revents = 0;
        if (l->cfd >= 0) {
            p[1].fd = l->cfd;
            p[1].events = POLLIN;
            p[1].revents = 0;
            np = 2;
        }
        rc = poll(p, (nfds_t)np, 50);
        if (rc < 0 && errno != EINTR) {
            say(l, "poll: %s\n", strerror(errno));
            return RC_ERR_IO;
        }
        if (rc <= 0)
            continue;
        if (np == 2 && (p[1].revents & (POLLIN | POLLHUP | POLLERR)))
            on_readable(l, &w);
        if (p[0].revents & POLLIN) {
            const int had = l->cfd >= 0;
            accept_one(l);
            if (!had && l->cfd >= 0)
                lost_at = mono_ms();
        }
    }
    return w.stop ? w.stop : RC_OK;
}

void rch_link_wait(rch_link *l, unsigned long ms)
{
    send_line(l, "WAIT %lu", ms);
}

void rch_link_stop(rch_link *l, const char *reason)
{
    if (l->hello)
        send_line(l, "STOP %s", reason);
}

void rch_link_close(rch_link *l)
{
    if (l->cfd >= 0)
        close(l->cfd);
    if (l->lfd >= 0)
        close(l->lfd);
    l->cfd = l->lfd = -1;
}
