/* SPDX-License-Identifier: MIT */
/* rcd_port.c - dispatchers of the port interface and line-setting checks. */
#include "rcd_port.h"

rc_status rcd_serial_config_resolve(rcd_serial_config *out, const rcd_serial_config *in)
{
    rcd_serial_config c = {0};
    if (!out)
        return RC_ERR_ARG;
    if (in)
        c = *in;
    if (c.baud == 0)
        c.baud = 9600;
    if (c.data_bits == 0)
        c.data_bits = 8;
    if (c.stop_bits == 0)
        c.stop_bits = 1;
    if (c.data_bits < 5 || c.data_bits > 8 || c.stop_bits > 2 || c.baud > 4000000u ||
        (unsigned)c.parity > RCD_PARITY_SPACE || (unsigned)c.flow > RCD_FLOW_DTRDSR)
        return RC_ERR_ARG;
    *out = c;
    return RC_OK;
}

rc_status rcd_port_open(rcd_port *p, const char *path, const rcd_serial_config *cfg)
{
    if (!p || !p->ops || !path)
        return RC_ERR_ARG;
    return p->ops->open(p->ctx, path, cfg);
}

rc_status rcd_port_close(rcd_port *p)
{
    if (!p || !p->ops)
        return RC_ERR_ARG;
    return p->ops->close(p->ctx);
}

rc_status rcd_port_read(rcd_port *p, size_t *n_read, uint8_t *buf, size_t cap, unsigned timeout_ms)
{
    if (n_read)
        *n_read = 0;
    if (!p || !p->ops || !n_read || !buf || cap == 0)
        return RC_ERR_ARG;
    return p->ops->read(p->ctx, n_read, buf, cap, timeout_ms);
}

rc_status rcd_port_write(rcd_port *p, size_t *n_written, const uint8_t *buf, size_t len,
                         unsigned timeout_ms)
{
    if (n_written)
        *n_written = 0;
    if (!p || !p->ops || !n_written || (!buf && len))
        return RC_ERR_ARG;
    if (len == 0)
        return RC_OK;
    return p->ops->write(p->ctx, n_written, buf, len, timeout_ms);
}

rc_status rcd_port_flush(rcd_port *p)
{
    if (!p || !p->ops)
        return RC_ERR_ARG;
    return p->ops->flush(p->ctx);
}

rc_status rcd_port_drain(rcd_port *p)
{
    if (!p || !p->ops)
        return RC_ERR_ARG;
    return p->ops->drain(p->ctx);
}

const char *rcd_port_last_error(const rcd_port *p)
{
    const char *s;
    if (!p || !p->ops || !p->ops->last_error)
        return "";
    s = p->ops->last_error(p->ctx);
    return s ? s : "";
}

uint32_t rcd_port_now_ms(const rcd_port *p)
{
    if (!p || !p->ops || !p->ops->now_ms)
        return 0u;
    return p->ops->now_ms(p->ctx);
}
