/* SPDX-License-Identifier: MIT */
/* rcd_posix.c - POSIX file-descriptor backend (termios, poll).
 *
 * For devices libserialport refuses, chiefly pseudo-terminals of the
 * simulated display. Non-blocking fd, poll(2) for timeouts; EOF, POLLHUP
 * without data, EIO/ENXIO are a hang-up (RC_ERR_CLOSED).
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "rcd_port.h"

static rc_status set_errno(rcd_posix_ctx *c, const char *what, int e)
{
    snprintf(c->err, sizeof c->err, "%s: %s", what, strerror(e));
    if (e == EIO || e == ENXIO || e == ENODEV || e == EPIPE)
        return RC_ERR_CLOSED;
    return RC_ERR_IO;
}

static long long now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

uint32_t rcd_posix_now_ms(void *ctx)
{
    (void)ctx;
    return (uint32_t)((unsigned long long)now_ms() & 0xFFFFFFFFull);
}

static int baud_const(unsigned baud, speed_t *out)
{
    static const struct {
        unsigned b;
        speed_t s;
    } t[] = {{1200, B1200},     {2400, B2400},     {4800, B4800},   {9600, B9600},
             {19200, B19200},   {38400, B38400},   {57600, B57600}, {115200, B115200},
             {230400, B230400}, {460800, B460800}, {921600, B921600}};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; ++i)
        if (t[i].b == baud) {
            *out = t[i].s;
            return 1;
        }
    return 0;
}

static rc_status configure(rcd_posix_ctx *c, const rcd_serial_config *in)
{
    rcd_serial_config cfg;
    struct termios tio;
    speed_t sp;
    if (rcd_serial_config_resolve(&cfg, in) != RC_OK) {
        snprintf(c->err, sizeof c->err, "invalid line settings");
        return RC_ERR_ARG;
    }
    if (!baud_const(cfg.baud, &sp)) {
        snprintf(c->err, sizeof c->err, "baud rate %u not supported by the POSIX backend", cfg.baud);
        return RC_ERR_UNSUPPORTED;
    }
    if (cfg.parity == RCD_PARITY_MARK || cfg.parity == RCD_PARITY_SPACE ||
        cfg.flow == RCD_FLOW_DTRDSR) {
        snprintf(c->err, sizeof c->err, "mark/space parity and DTR/DSR flow need the serialport backend");
        return RC_ERR_UNSUPPORTED;
    }
    if (tcgetattr(c->fd, &tio) != 0)
        return set_errno(c, "tcgetattr", errno);
    cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= (tcflag_t)~(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
    tio.c_cflag |= cfg.data_bits == 5 ? CS5 : cfg.data_bits == 6 ? CS6 : cfg.data_bits == 7 ? CS7 : CS8;
    if (cfg.parity != RCD_PARITY_NONE)
        tio.c_cflag |= PARENB | (cfg.parity == RCD_PARITY_ODD ? PARODD : 0);
    if (cfg.stop_bits == 2)
        tio.c_cflag |= CSTOPB;
    if (cfg.flow == RCD_FLOW_RTSCTS)
        tio.c_cflag |= CRTSCTS;
    tio.c_iflag &= (tcflag_t)~(IXON | IXOFF | IXANY);
    if (cfg.flow == RCD_FLOW_XONXOFF)
        tio.c_iflag |= IXON | IXOFF;
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    cfsetispeed(&tio, sp);
    cfsetospeed(&tio, sp);
    if (tcsetattr(c->fd, TCSANOW, &tio) != 0)
        return set_errno(c, "tcsetattr", errno);
    return RC_OK;
}

static rc_status px_open(void *ctx, const char *path, const rcd_serial_config *cfg)
{
    rcd_posix_ctx *c = ctx;
    rc_status st;
    if (c->fd >= 0) {
        snprintf(c->err, sizeof c->err, "port already open");
        return RC_ERR_ARG;
    }
    c->err[0] = '\0';
    c->fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (c->fd < 0) {
        int e = errno;
        snprintf(c->err, sizeof c->err, "open %s: %s", path, strerror(e));
        return e == ENOENT || e == ENXIO ? RC_ERR_CLOSED : RC_ERR_IO;
    }
    c->owned = 1;
    c->is_tty = isatty(c->fd);
    if (c->is_tty) {
        st = configure(c, cfg);
        if (st != RC_OK) {
            close(c->fd);
            c->fd = -1;
            return st;
        }
    }
    return RC_OK;
}

static rc_status px_close(void *ctx)
{
    rcd_posix_ctx *c = ctx;
    int r = 0;
    if (c->fd < 0)
        return RC_OK;
    if (c->owned)
        r = close(c->fd);
    c->fd = -1;
    return r == 0 ? RC_OK : set_errno(c, "close", errno);
}

static rc_status px_read(void *ctx, size_t *n_read, uint8_t *buf, size_t cap, unsigned timeout_ms)
{
    rcd_posix_ctx *c = ctx;
    long long deadline = now_ms() + timeout_ms;
    *n_read = 0;
    if (c->fd < 0) {
        snprintf(c->err, sizeof c->err, "read: port not open");
        return RC_ERR_CLOSED;
    }
    for (;;) {
        ssize_t n = read(c->fd, buf, cap);
        struct pollfd pfd;
        long long left;
        int pr;
        if (n > 0) {
            *n_read = (size_t)n;
            return RC_OK;
        }
        if (n == 0 && !c->is_tty) {
            snprintf(c->err, sizeof c->err, "read: end of file (peer closed)");
            return RC_ERR_CLOSED;
        }
        if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
            return set_errno(c, "read", errno);
        left = deadline - now_ms();
        if (left <= 0)
            return RC_ERR_TIMEOUT;
        pfd.fd = c->fd;
        pfd.events = POLLIN;
        pfd.revents = 0;
        pr = poll(&pfd, 1, (int)left);
        if (pr < 0 && errno != EINTR)
            return set_errno(c, "poll", errno);
        if (pr > 0 && (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) && !(pfd.revents & POLLIN)) {
            snprintf(c->err, sizeof c->err, "read: device hung up");
            return RC_ERR_CLOSED;
        }
    }
}

static rc_status px_write(void *ctx, size_t *n_written, const uint8_t *buf, size_t len,
                          unsigned timeout_ms)
{
    rcd_posix_ctx *c = ctx;
    long long deadline = now_ms() + timeout_ms;
    size_t done = 0;
    *n_written = 0;
    if (c->fd < 0) {
        snprintf(c->err, sizeof c->err, "write: port not open");
        return RC_ERR_CLOSED;
    }
    while (done < len) {
        ssize_t n = write(c->fd, buf + done, len - done);
        struct pollfd pfd;
        long long left;
        if (n > 0) {
            done += (size_t)n;
            *n_written = done;
            continue;
        }
        if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
            return set_errno(c, "write", errno);
        left = deadline - now_ms();
        if (left <= 0) {
            snprintf(c->err, sizeof c->err, "write: %zu of %zu bytes within %u ms", done, len,
                     timeout_ms);
            return RC_ERR_TIMEOUT;
        }
        pfd.fd = c->fd;
        pfd.events = POLLOUT;
        pfd.revents = 0;
        if (poll(&pfd, 1, (int)left) < 0 && errno != EINTR)
            return set_errno(c, "poll", errno);
        if (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) {
            snprintf(c->err, sizeof c->err, "write: device hung up");
            return RC_ERR_CLOSED;
        }
    }
    return RC_OK;
}

static rc_status px_flush(void *ctx)
{
    rcd_posix_ctx *c = ctx;
    uint8_t junk[256];
    if (c->fd < 0)
        return RC_ERR_CLOSED;
    if (isatty(c->fd)) {
        if (tcflush(c->fd, TCIOFLUSH) != 0)
            return set_errno(c, "tcflush", errno);
        return RC_OK;
    }
    while (read(c->fd, junk, sizeof junk) > 0) /* pipes and files: drop what is there */
        ;
    return RC_OK;
}

static rc_status px_drain(void *ctx)
{
    rcd_posix_ctx *c = ctx;
    if (c->fd < 0)
        return RC_ERR_CLOSED;
    if (isatty(c->fd) && tcdrain(c->fd) != 0)
        return set_errno(c, "tcdrain", errno);
    return RC_OK;
}

static const char *px_last_error(void *ctx)
{
    rcd_posix_ctx *c = ctx;
    return c->err;
}

const rcd_port_ops rcd_posix_ops = {
    .name = "posix",
    .open = px_open,
    .close = px_close,
    .read = px_read,
    .write = px_write,
    .flush = px_flush,
    .drain = px_drain,
    .last_error = px_last_error,
    .now_ms = rcd_posix_now_ms,
};

void rcd_posix_init(rcd_port *p, rcd_posix_ctx *ctx)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->fd = -1;
    p->ops = &rcd_posix_ops;
    p->ctx = ctx;
}

rc_status rcd_posix_attach(rcd_port *p, rcd_posix_ctx *ctx, int fd, int owned)
{
    int fl;
    if (!p || !ctx || fd < 0)
        return RC_ERR_ARG;
    rcd_posix_init(p, ctx);
    fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) < 0)
        return set_errno(ctx, "fcntl", errno);
    ctx->fd = fd;
    ctx->owned = owned;
    ctx->is_tty = isatty(fd);
    return RC_OK;
}
