/* SPDX-License-Identifier: MIT */
/* rcd_display.c - display reader: port + protocol + format lock. */
#include <string.h>

#include "rcd_display.h"

/* Milliseconds left of timeout_ms since t0 on the port's clock (modulo 2^32). */
static long long left_ms(const rcd_display *d, uint32_t t0, unsigned timeout_ms)
{
    uint32_t elapsed = rcd_port_now_ms(d->port) - t0;
    return (long long)timeout_ms - (long long)elapsed;
}

static int is_polled(const rcd_display *d)
{
    return d->cfg.protocol != RCD_PROTO_ASCII;
}

rc_status rcd_display_init(rcd_display *d, rcd_port *port, const rcd_proto_config *cfg)
{
    if (!d || !port || !port->ops)
        return RC_ERR_ARG;
    memset(d, 0, sizeof *d);
    d->port = port;
    if (cfg)
        d->cfg = *cfg;
    if ((unsigned)d->cfg.protocol > RCD_PROTO_MODBUS || d->cfg.mb_decimals > 9 ||
        (unsigned)d->cfg.mb_order > RCD_WO_DCBA || (unsigned)d->cfg.mb_format > RCD_MB_FLOAT32)
        return RC_ERR_ARG;
    d->need_poll = 1;
    d->lock_decimals = -2;
    d->cand_decimals = -2;
    return RC_OK;
}

const char *rcd_display_why_silent(const rcd_display *d)
{
    if (!d)
        return "";
    if (d->last_reject == RCD_REJECT_MB_SLAVE)
        return "; replies from another Modbus slave address were ignored: check --mb-addr";
    if (d->last_reject == RCD_REJECT_MB_FUNCTION)
        return "; replies with another Modbus function code were ignored: the display does not answer "
               "holding-register reads (0x03) at this register";
    return "";
}

void rcd_display_reset(rcd_display *d)
{
    d->len = 0;
    d->need_poll = 1;
}

static void drop(rcd_display *d, size_t n)
{
    if (n >= d->len) {
        d->len = 0;
        return;
    }
    memmove(d->buf, d->buf + n, d->len - n);
    d->len -= n;
}

/* Shape check; RC_OK when the reading may be returned. */
static rc_status check_shape(rcd_display *d, const rcd_reading *r)
{
    if (d->cfg.protocol == RCD_PROTO_MODBUS)
        return RC_OK;
    if (d->lock_decimals != -2) {
        if (r->decimals == d->lock_decimals && r->unit == d->lock_unit)
            return RC_OK;
        d->stats.shape_rejects++;
        return RC_ERR_FORMAT;
    }
    if (r->decimals == d->cand_decimals && r->unit == d->cand_unit) {
        d->cand_count++;
    } else {
        d->cand_decimals = r->decimals;
        d->cand_unit = r->unit;
        d->cand_count = 1;
    }
    if (d->cand_count >= RCD_DISPLAY_LOCK_COUNT) {
        d->lock_decimals = d->cand_decimals;
        d->lock_unit = d->cand_unit;
        return RC_OK;
    }
    return RC_ERR_INCOMPLETE; /* still learning the format: keep reading */
}

/* Flush stale input and send one request, within what is left of the timeout. */
static rc_status send_poll(rcd_display *d, uint32_t t0, unsigned timeout_ms)
{
    uint8_t req[32];
    size_t rl = 0, wn = 0;
    long long left;
    rc_status st;
    d->len = 0;
    st = rcd_port_flush(d->port);
    if (st != RC_OK)
        return st;
    st = rcd_build_request(req, &rl, sizeof req, &d->cfg);
    if (st != RC_OK)
        return st;
    left = left_ms(d, t0, timeout_ms);
    st = rcd_port_write(d->port, &wn, req, rl, left > 0 ? (unsigned)left : 1u);
    if (st == RC_ERR_TIMEOUT)
        d->stats.timeouts++;
    if (st != RC_OK)
        return st;
    d->stats.polls++;
    d->need_poll = 0;
    return RC_OK;
}

/* A rejected frame: count it; a named Modbus reject goes to out. */
static rc_status reject(rcd_display *d, rc_status st, const rcd_reading *r, rcd_reading *out)
{
    d->stats.bad_frames++;
    d->last_reject = r->reject;
    if (st == RC_ERR_FORMAT && r->reject == RCD_REJECT_MB_SLAVE)
        d->stats.wrong_slave++;
    if (st == RC_ERR_FORMAT && r->reject == RCD_REJECT_MB_FUNCTION)
        d->stats.wrong_function++;
    if (st == RC_ERR_FORMAT && r->reject != RCD_REJECT_NONE) {
        d->last_mb_addr = r->mb_addr;
        d->last_mb_fn = r->mb_fn;
        if (out)
            *out = *r;
    }
    return st;
}

/* The next event from the buffered bytes, or RC_ERR_INCOMPLETE when more
 * bytes (or, polled, a new request) are needed. */
static rc_status parse_buffered(rcd_display *d, rcd_reading *out)
{
    while (d->len > 0) {
        rcd_reading r;
        size_t c = 0;
        rc_status st;
        memset(&r, 0, sizeof r);
        st = rcd_parse(&r, &c, &d->cfg, d->buf, d->len);
        drop(d, c);
        if (st == RC_ERR_INCOMPLETE)
            return st;
        d->need_poll = 1;
        if (st == RC_OK) {
            st = check_shape(d, &r);
            if (st == RC_ERR_INCOMPLETE) {
                if (is_polled(d))
                    return st; /* warm-up frame: poll again */
                continue;      /* warm-up frame: keep parsing */
            }
            if (st == RC_OK) {
                d->stats.readings++;
                if (out)
                    *out = r;
            }
            return st;
        }
        if (st == RC_ERR_DEVICE) {
            d->stats.device_errors++;
            if (out)
                *out = r;
            return st;
        }
        return reject(d, st, &r, out);
    }
    return RC_ERR_INCOMPLETE;
}

rc_status rcd_display_read(rcd_display *d, rcd_reading *out, unsigned timeout_ms)
{
    uint32_t t0;
    if (!d || !d->port)
        return RC_ERR_ARG;
    t0 = rcd_port_now_ms(d->port);
    for (;;) {
        rc_status st;
        size_t n = 0;
        long long left;
        if (is_polled(d) && d->need_poll) {
            st = send_poll(d, t0, timeout_ms);
            if (st != RC_OK)
                return st;
        }
        st = parse_buffered(d, out);
        if (st != RC_ERR_INCOMPLETE)
            return st;
        if (d->len == sizeof d->buf)
            drop(d, sizeof d->buf / 2); /* cannot happen with the parsers' limits */
        if (is_polled(d) && d->need_poll)
            continue;
        left = left_ms(d, t0, timeout_ms);
        if (left <= 0) {
            d->stats.timeouts++;
            d->need_poll = 1;
            return RC_ERR_TIMEOUT;
        }
        st = rcd_port_read(d->port, &n, d->buf + d->len, sizeof d->buf - d->len, (unsigned)left);
        if (st != RC_OK) {
            if (st == RC_ERR_TIMEOUT) {
                d->stats.timeouts++; /* the port waited for what was left */
                d->need_poll = 1;
            }
            return st;
        }
        d->len += n;
        d->stats.bytes += n;
    }
}
