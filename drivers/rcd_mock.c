/* SPDX-License-Identifier: MIT */
/* rcd_mock.c - scripted port with fault injection, for tests. */
#include <string.h>

#include "rcd_port.h"

static rc_status fail_st(const rcd_mock_ctx *m)
{
    return m->fail_status ? m->fail_status : RC_ERR_IO;
}

static rc_status mk_open(void *ctx, const char *path, const rcd_serial_config *cfg)
{
    rcd_mock_ctx *m = ctx;
    rcd_serial_config r;
    (void)path;
    if (rcd_serial_config_resolve(&r, cfg) != RC_OK)
        return RC_ERR_ARG;
    if (m->fail_open)
        return fail_st(m);
    m->is_open = 1;
    return RC_OK;
}

static rc_status mk_close(void *ctx)
{
    rcd_mock_ctx *m = ctx;
    m->is_open = 0;
    return RC_OK;
}

static rc_status mk_read_(rcd_mock_ctx *m, size_t *n_read, uint8_t *buf, size_t cap)
{
    size_t n, left;
    m->n_reads++;
    if (!m->is_open)
        return RC_ERR_CLOSED;
    if (m->fail_rx_after != RCD_MOCK_NEVER && m->rx_pos >= m->fail_rx_after)
        return fail_st(m);
    if (m->timeout_every && m->n_reads % m->timeout_every == 0)
        return RC_ERR_TIMEOUT;
    left = m->rx_len - m->rx_pos;
    if (m->n_segments) {
        size_t lim = m->released < m->rx_len ? m->released : m->rx_len;
        left = lim > m->rx_pos ? lim - m->rx_pos : 0;
        if (left == 0 && m->rx_pos < m->rx_len)
            return RC_ERR_TIMEOUT; /* the device waits for a request */
    }
    if (left == 0)
        return m->closed_at_end ? RC_ERR_CLOSED : RC_ERR_TIMEOUT;
    n = cap < left ? cap : left;
    if (m->max_chunk && n > m->max_chunk)
        n = m->max_chunk;
    if (m->fail_rx_after != RCD_MOCK_NEVER && m->rx_pos + n > m->fail_rx_after)
        n = m->fail_rx_after - m->rx_pos; /* deliver up to byte N, fail on the next read */
    memcpy(buf, m->rx + m->rx_pos, n);
    m->rx_pos += n;
    *n_read = n;
    return RC_OK;
}

static rc_status mk_read(void *ctx, size_t *n_read, uint8_t *buf, size_t cap, unsigned timeout_ms)
{
    rcd_mock_ctx *m = ctx;
    rc_status st;
    *n_read = 0;
    st = mk_read_(m, n_read, buf, cap);
    if (st == RC_ERR_TIMEOUT)
        m->clock_ms += (uint32_t)timeout_ms; /* the wait a real port would have done */
    else if (st == RC_OK && *n_read > 0)
        m->clock_ms += m->ms_per_read;
    return st;
}

static uint32_t mk_now_ms(void *ctx)
{
    const rcd_mock_ctx *m = ctx;
    return m->clock_ms;
}

static rc_status mk_write(void *ctx, size_t *n_written, const uint8_t *buf, size_t len,
                          unsigned timeout_ms)
{
    rcd_mock_ctx *m = ctx;
    size_t n = len;
    (void)timeout_ms;
    *n_written = 0;
    m->n_writes++;
    if (!m->is_open)
        return RC_ERR_CLOSED;
    if (m->fail_tx_after != RCD_MOCK_NEVER) {
        if (m->tx_total >= m->fail_tx_after)
            return fail_st(m);
        if (m->tx_total + n > m->fail_tx_after)
            n = m->fail_tx_after - m->tx_total;
    }
    for (size_t i = 0; i < n; ++i)
        if (m->tx && m->tx_len < m->tx_cap)
            m->tx[m->tx_len++] = buf[i];
    m->tx_total += n;
    *n_written = n;
    if (m->n_segments && m->seg_next < m->n_segments)
        m->released += m->segments[m->seg_next++];
    return n == len ? RC_OK : fail_st(m);
}

static rc_status mk_flush(void *ctx)
{
    rcd_mock_ctx *m = ctx;
    m->n_flush++;
    return m->is_open ? RC_OK : RC_ERR_CLOSED;
}

static rc_status mk_drain(void *ctx)
{
    rcd_mock_ctx *m = ctx;
    m->n_drain++;
    return m->is_open ? RC_OK : RC_ERR_CLOSED;
}

static const char *mk_last_error(void *ctx)
{
    (void)ctx;
    return "mock fault";
}

const rcd_port_ops rcd_mock_ops = {
    .name = "mock",
    .open = mk_open,
    .close = mk_close,
    .read = mk_read,
    .write = mk_write,
    .flush = mk_flush,
    .drain = mk_drain,
    .last_error = mk_last_error,
    .now_ms = mk_now_ms,
};

void rcd_mock_init(rcd_port *p, rcd_mock_ctx *ctx)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->fail_rx_after = RCD_MOCK_NEVER;
    ctx->fail_tx_after = RCD_MOCK_NEVER;
    p->ops = &rcd_mock_ops;
    p->ctx = ctx;
}
