/* SPDX-License-Identifier: MIT */
/* rcd_serialport.c - libserialport backend of the port interface.
 *
 * The only file of the project that includes libserialport.h. Every
 * sp_return is mapped by rcd_sp_status(); on SP_ERR_FAIL the OS message
 * (sp_last_error_message) is copied into ctx->err and the library's string
 * freed. Every libserialport object (port, config) is freed on every path.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include <libserialport.h>

#include "rcd_port.h"

static void set_err(rcd_serialport_ctx *c, const char *what, enum sp_return r)
{
    char *msg;
    switch (r) {
    case SP_ERR_FAIL:
        msg = sp_last_error_message();
        snprintf(c->err, sizeof c->err, "%s: %s", what, msg ? msg : "unknown OS error");
        if (msg)
            sp_free_error_message(msg);
        break;
    case SP_ERR_ARG:
        snprintf(c->err, sizeof c->err, "%s: invalid argument", what);
        break;
    case SP_ERR_MEM:
        snprintf(c->err, sizeof c->err, "%s: out of memory", what);
        break;
    case SP_ERR_SUPP:
        snprintf(c->err, sizeof c->err, "%s: not supported by this port or OS", what);
        break;
    default:
        snprintf(c->err, sizeof c->err, "%s: libserialport error %d", what, (int)r);
        break;
    }
}

/* sp_return -> rc_status. SP_ERR_FAIL from an I/O call whose errno says the
 * device vanished (unplugged USB adapter) is RC_ERR_CLOSED. */
static rc_status rcd_sp_status(enum sp_return r, int io_call)
{
    int code;
    if (r >= 0)
        return RC_OK;
    switch (r) {
    case SP_ERR_ARG:
        return RC_ERR_ARG;
    case SP_ERR_FAIL:
        if (io_call) {
            code = sp_last_error_code();
            if (code == EIO || code == ENXIO || code == ENODEV)
                return RC_ERR_CLOSED;
        }
        return RC_ERR_IO;
    case SP_ERR_MEM:
        return RC_ERR_IO;
    case SP_ERR_SUPP:
        return RC_ERR_UNSUPPORTED;
    default:
        return RC_ERR_IO;
    }
}

static rc_status fail(rcd_serialport_ctx *c, const char *what, enum sp_return r, int io_call)
{
    rc_status st = rcd_sp_status(r, io_call); /* before set_err: errno of the failing call */
    set_err(c, what, r);
    return st;
}

static enum sp_parity map_parity(rcd_parity p)
{
    switch (p) {
    case RCD_PARITY_ODD: return SP_PARITY_ODD;
    case RCD_PARITY_EVEN: return SP_PARITY_EVEN;
    case RCD_PARITY_MARK: return SP_PARITY_MARK;
    case RCD_PARITY_SPACE: return SP_PARITY_SPACE;
    case RCD_PARITY_NONE:
    default: return SP_PARITY_NONE;
    }
}

static enum sp_flowcontrol map_flow(rcd_flow f)
{
    switch (f) {
    case RCD_FLOW_XONXOFF: return SP_FLOWCONTROL_XONXOFF;
    case RCD_FLOW_RTSCTS: return SP_FLOWCONTROL_RTSCTS;
    case RCD_FLOW_DTRDSR: return SP_FLOWCONTROL_DTRDSR;
    case RCD_FLOW_NONE:
    default: return SP_FLOWCONTROL_NONE;
    }
}

static rc_status sp_open_(void *ctx, const char *path, const rcd_serial_config *cfg_in)
{
    rcd_serialport_ctx *c = ctx;
    rcd_serial_config cfg;
    struct sp_port *port = NULL;
    struct sp_port_config *conf = NULL;
    enum sp_return r;
    rc_status st;

    if (!c || !path)
        return RC_ERR_ARG;
    if (c->port) {
        snprintf(c->err, sizeof c->err, "port already open");
        return RC_ERR_ARG;
    }
    if (rcd_serial_config_resolve(&cfg, cfg_in) != RC_OK) {
        snprintf(c->err, sizeof c->err, "invalid line settings");
        return RC_ERR_ARG;
    }
    c->err[0] = '\0';
    r = sp_get_port_by_name(path, &port);
    if (r != SP_OK) {
        /* the library leaves port NULL on failure; free defensively */
        if (port)
            sp_free_port(port);
        /* libserialport says SP_ERR_ARG when it knows no port of that name */
        return fail(c, r == SP_ERR_ARG ? "find port (no such serial device, or not one libserialport handles)"
                                       : "find port", r, 0);
    }
    r = sp_open(port, SP_MODE_READ_WRITE);
    if (r != SP_OK) {
        st = fail(c, "open", r, 0);
        sp_free_port(port);
        return st;
    }
    r = sp_new_config(&conf);
    if (r != SP_OK) {
        st = fail(c, "new config", r, 0);
        goto fail_close;
    }
    if ((r = sp_set_config_baudrate(conf, (int)cfg.baud)) != SP_OK) {
        st = fail(c, "set baud rate", r, 0);
        goto fail_conf;
    }
    if ((r = sp_set_config_bits(conf, (int)cfg.data_bits)) != SP_OK) {
        st = fail(c, "set data bits", r, 0);
        goto fail_conf;
    }
    if ((r = sp_set_config_parity(conf, map_parity(cfg.parity))) != SP_OK) {
        st = fail(c, "set parity", r, 0);
        goto fail_conf;
    }
    if ((r = sp_set_config_stopbits(conf, (int)cfg.stop_bits)) != SP_OK) {
        st = fail(c, "set stop bits", r, 0);
        goto fail_conf;
    }
    if ((r = sp_set_config_flowcontrol(conf, map_flow(cfg.flow))) != SP_OK) {
        st = fail(c, "set flow control", r, 0);
        goto fail_conf;
    }
    if ((r = sp_set_config(port, conf)) != SP_OK) {
        st = fail(c, "apply line settings", r, 0);
        goto fail_conf;
    }
    sp_free_config(conf);
    c->port = port;
    return RC_OK;

fail_conf:
    sp_free_config(conf);
fail_close:
    sp_close(port); /* its own failure is secondary: the first error is kept */
    sp_free_port(port);
    return st;
}

static rc_status sp_close_(void *ctx)
{
    rcd_serialport_ctx *c = ctx;
    enum sp_return r;
    rc_status st = RC_OK;
    if (!c)
        return RC_ERR_ARG;
    if (!c->port)
        return RC_OK;
    r = sp_close(c->port);
    if (r != SP_OK)
        st = fail(c, "close", r, 0);
    sp_free_port(c->port); /* freed even when close failed */
    c->port = NULL;
    return st;
}

static rc_status sp_read_(void *ctx, size_t *n_read, uint8_t *buf, size_t cap, unsigned timeout_ms)
{
    rcd_serialport_ctx *c = ctx;
    enum sp_return r;
    *n_read = 0;
    if (!c->port) {
        snprintf(c->err, sizeof c->err, "read: port not open");
        return RC_ERR_CLOSED;
    }
    if (timeout_ms == 0)
        r = sp_nonblocking_read(c->port, buf, cap);
    else
        r = sp_blocking_read_next(c->port, buf, cap, timeout_ms);
    if (r < 0)
        return fail(c, "read", r, 1);
    if (r == 0)
        return RC_ERR_TIMEOUT;
    if ((size_t)r > cap) { /* a broken library would overrun: refuse the count */
        snprintf(c->err, sizeof c->err, "read: library returned %d > %zu bytes", (int)r, cap);
        return RC_ERR_IO;
    }
    *n_read = (size_t)r;
    return RC_OK;
}

static rc_status sp_write_(void *ctx, size_t *n_written, const uint8_t *buf, size_t len,
                           unsigned timeout_ms)
{
    rcd_serialport_ctx *c = ctx;
    enum sp_return r;
    *n_written = 0;
    if (!c->port) {
        snprintf(c->err, sizeof c->err, "write: port not open");
        return RC_ERR_CLOSED;
    }
    r = sp_blocking_write(c->port, buf, len, timeout_ms);
    if (r < 0)
        return fail(c, "write", r, 1);
    *n_written = (size_t)r > len ? len : (size_t)r;
    if ((size_t)r < len) {
        snprintf(c->err, sizeof c->err, "write: %d of %zu bytes within %u ms", (int)r, len,
                 timeout_ms);
        return RC_ERR_TIMEOUT;
    }
    return RC_OK;
}

static rc_status sp_flush_(void *ctx)
{
    rcd_serialport_ctx *c = ctx;
    enum sp_return r;
    if (!c->port)
        return RC_ERR_CLOSED;
    r = sp_flush(c->port, SP_BUF_BOTH);
    return r == SP_OK ? RC_OK : fail(c, "flush", r, 1);
}

static rc_status sp_drain_(void *ctx)
{
    rcd_serialport_ctx *c = ctx;
    enum sp_return r;
    if (!c->port)
        return RC_ERR_CLOSED;
    r = sp_drain(c->port);
    return r == SP_OK ? RC_OK : fail(c, "drain", r, 1);
}

static const char *sp_last_error_(void *ctx)
{
    rcd_serialport_ctx *c = ctx;
    return c ? c->err : "";
}

const rcd_port_ops rcd_serialport_ops = {
    .name = "serialport",
    .open = sp_open_,
    .close = sp_close_,
    .read = sp_read_,
    .write = sp_write_,
    .flush = sp_flush_,
    .drain = sp_drain_,
    .last_error = sp_last_error_,
    .now_ms = rcd_posix_now_ms,
};

void rcd_serialport_init(rcd_port *p, rcd_serialport_ctx *ctx)
{
    memset(ctx, 0, sizeof *ctx);
    p->ops = &rcd_serialport_ops;
    p->ctx = ctx;
}
