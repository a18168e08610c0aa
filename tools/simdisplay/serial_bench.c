/* SPDX-License-Identifier: MIT */
/* serial_bench.c - reading speed of the display path.
 *
 *  1. parser alone: readings/s of rcd_parse over a buffer of frames (ascii,
 *     stx, modbus), median of --runs;
 *  2. through the POSIX backend on a pty: a child process plays the display,
 *     pacing its bytes at --baud (10 bits per byte, 8N1) - ASCII streaming and
 *     Modbus polled (request 8 bytes, reply 9 bytes) - while the parent reads
 *     with rcd_display_read for --seconds; readings/s, median of --runs. Also
 *     once with no pacing (what the pty and the driver sustain).
 * usage: rcal_serial_bench [--baud B] [--seconds S] [--runs R]
 */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "rcd_display.h"
#include "rch_opt.h"
#include "rch_stdio.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static volatile double sink;

static double parser_rate(rcd_protocol proto)
{
    enum { NF = 200000 };
    static uint8_t buf[NF * 16];
    rcd_proto_config cfg = {0};
    size_t len = 0, off = 0, got = 0;
    double t0, sum = 0;
    cfg.protocol = proto;
    cfg.mb_decimals = 3;
    for (int i = 0; i < NF; ++i) {
        size_t n = 0;
        double v = 300.0 + (double)(i % 5000) * 0.1;
        if (proto == RCD_PROTO_ASCII)
            rcd_encode_ascii(buf + len, &n, sizeof buf - len, v, RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 3);
        else if (proto == RCD_PROTO_STX)
            rcd_encode_stx(buf + len, &n, sizeof buf - len, v, 3);
        else
            rcd_encode_modbus(buf + len, &n, sizeof buf - len, v, &cfg);
        len += n;
    }
    t0 = now_s();
    while (off < len) {
        rcd_reading r;
        size_t c = 0;
        if (rcd_parse(&r, &c, &cfg, buf + off, len - off) == RC_OK) {
            ++got;
            sum += r.len_mm;
        }
        if (c == 0)
            break;
        off += c;
    }
    sink = sum;
    return (double)got / (now_s() - t0);
}

/* The display side, in a child process on the pty master. */
static void child_display(int master, rcd_protocol proto, unsigned baud, double seconds)
{
    rcd_proto_config cfg = {0};
    uint8_t f[64], rq[256];
    size_t rq_len = 0;
    double t_end = now_s() + seconds + 1.0, line_free = now_s();
    cfg.protocol = proto;
    cfg.mb_decimals = 3;
    for (unsigned long i = 0; now_s() < t_end; ++i) {
        size_t n = 0, off = 0;
        double v = 300.0 + (double)(i % 5000) * 0.1;
        if (proto == RCD_PROTO_MODBUS) { /* wait for a request */
            size_t c = 0;
            uint16_t reg, cnt;
            ssize_t r = read(master, rq + rq_len, sizeof rq - rq_len);
            if (r > 0)
                rq_len += (size_t)r;
            if (rcd_parse_modbus_request(&reg, &cnt, &c, 1, rq, rq_len) != RC_OK) {
                memmove(rq, rq + c, rq_len - c);
                rq_len -= c;
                if (r <= 0) {
                    struct timespec ts = {0, 100000};
                    nanosleep(&ts, NULL);
                }
                --i;
                continue;
            }
            memmove(rq, rq + c, rq_len - c);
            rq_len -= c;
            if (baud) /* the request itself took 8 byte times on the wire */
                line_free += 8.0 * 10.0 / baud;
            rcd_encode_modbus(f, &n, sizeof f, v, &cfg);
        } else {
            rcd_encode_ascii(f, &n, sizeof f, v, RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 3);
        }
        if (baud) {
            double t = now_s();
            if (line_free > t) {
                struct timespec ts;
                double w = line_free - t;
                ts.tv_sec = (time_t)w;
                ts.tv_nsec = (long)((w - (double)ts.tv_sec) * 1e9);
                nanosleep(&ts, NULL);
            }
            t = now_s();
            line_free = (line_free > t ? line_free : t) + (double)n * 10.0 / baud;
        }
        while (off < n) {
            ssize_t w = write(master, f + off, n - off);
            if (w > 0)
                off += (size_t)w;
            else if (w < 0 && errno != EAGAIN && errno != EINTR)
                _exit(0);
        }
    }
    _exit(0);
}

static double port_rate(rcd_protocol proto, unsigned baud, double seconds)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY);
    rcd_port p;
    rcd_posix_ctx px;
    rcd_display d;
    rcd_proto_config cfg = {0};
    rcd_serial_config sc = {0};
    unsigned long got = 0;
    double t0, t;
    pid_t pid;
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0)
        return -1;
    rcd_posix_init(&p, &px);
    sc.baud = baud ? baud : 115200;
    if (rcd_port_open(&p, ptsname(master), &sc) != RC_OK) {
        fprintf(stderr, "open %s: %s\n", ptsname(master), rcd_port_last_error(&p));
        return -1;
    }
    cfg.protocol = proto;
    cfg.mb_decimals = 3;
    rcd_display_init(&d, &p, &cfg);
    pid = fork();
    if (pid == 0)
        child_display(master, proto, baud, seconds);
    t0 = now_s();
    do {
        rcd_reading r;
        if (rcd_display_read(&d, &r, 500) == RC_OK)
            ++got;
        t = now_s();
    } while (t - t0 < seconds);
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
    rcd_port_close(&p);
    close(master);
    return (double)got / (t - t0);
}

static int run(int argc, char **argv)
{
    unsigned baud = 115200;
    double seconds = 1.0, v[32] = {0};
    int runs = 5;
    static const rcd_protocol protos[] = {RCD_PROTO_ASCII, RCD_PROTO_STX, RCD_PROTO_MODBUS};
    unsigned long baud_ul = baud, runs_ul = (unsigned long)runs;
    const rch_opt opts[] = {
        {"--baud", RCH_OPT_UINT, &baud_ul, 1, 4000000, "B", "pty line rate to pace at", 0, NULL},
        {"--seconds", RCH_OPT_DOUBLE, &seconds, 0.001, 3600, "T", "duration of the pty measurement", 0, NULL},
        {"--runs", RCH_OPT_UINT, &runs_ul, 1, 32, "N", "runs (median reported)", 0, NULL},
    };
    const rch_cmdspec spec = {"serial_bench", "serial reading benchmark: parsers alone and the POSIX backend on a pty",
                              NULL, opts, sizeof opts / sizeof opts[0]};
    rch_opt_status ost = rch_opt_parse(&spec, argc, argv, NULL, stdout, stderr);
    if (ost != RCH_OPT_OK)
        return ost == RCH_OPT_HELP ? 0 : 2;
    baud = (unsigned)baud_ul;
    runs = (int)runs_ul;
    printf("parser alone (median of %d runs over 200000 frames):\n", runs);
    for (int k = 0; k < 3; ++k) {
        for (int r = 0; r < runs; ++r)
            v[r] = parser_rate(protos[k]);
        printf("  %-7s %12.0f readings/s\n", rcd_protocol_name(protos[k]), median(v, runs));
    }
    printf("POSIX backend on a pty, display paced at %u baud 8N1 (median of %d runs of %.1f s):\n", baud, runs,
           seconds);
    for (int r = 0; r < runs; ++r)
        v[r] = port_rate(RCD_PROTO_ASCII, baud, seconds);
    printf("  ascii stream  %8.1f readings/s (wire limit %.1f for 11-byte lines)\n", median(v, runs),
           baud / 10.0 / 11.0);
    for (int r = 0; r < runs; ++r)
        v[r] = port_rate(RCD_PROTO_MODBUS, baud, seconds);
    printf("  modbus polled %8.1f readings/s (wire limit %.1f for 8 + 9 bytes)\n", median(v, runs),
           baud / 10.0 / 17.0);
    printf("POSIX backend on a pty, no pacing (median of %d runs of %.1f s):\n", runs, seconds);
    for (int r = 0; r < runs; ++r)
        v[r] = port_rate(RCD_PROTO_ASCII, 0, seconds);
    printf("  ascii stream  %8.0f readings/s\n", median(v, runs));
    for (int r = 0; r < runs; ++r)
        v[r] = port_rate(RCD_PROTO_MODBUS, 0, seconds);
    printf("  modbus polled %8.0f readings/s\n", median(v, runs));
    return 0;
}

/* Closed standard descriptors opened on /dev/null first; standard output and
 * standard error checked at the end (tools/host/files/rch_stdio.h). */
int main(int argc, char **argv)
{
    rch_stdio_begin("serial_bench");
    return rch_stdio_end(run(argc, argv));
}
