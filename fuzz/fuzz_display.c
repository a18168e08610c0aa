/* SPDX-License-Identifier: MIT */
/* fuzz_display.c - the display reader (rcd_display_read) over the mock port:
 * fuzzed bytes arrive in short reads with injected timeouts, for every
 * protocol, until the mock hangs up. Checks that every call returns a
 * documented status, readings are finite and keep the locked shape, the
 * statistics add up, and the reader always reaches the hang-up (no livelock).
 * Input: byte 0 protocol and word order, byte 1 format/decimals, byte 2
 * short-read size and timeout period, the rest the bytes from the display. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rcd_display.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static rcd_display d; /* 512-byte buffer inside */
    rcd_port port;
    rcd_mock_ctx mock;
    rcd_proto_config cfg;
    uint8_t tx[256];
    if (size < 3)
        return 0;
    memset(&cfg, 0, sizeof cfg);
    cfg.protocol = (rcd_protocol)(data[0] & 3u);
    cfg.mb_order = (rcd_word_order)((data[0] >> 2) & 3u);
    cfg.mb_addr = (uint8_t)(data[0] >> 4); /* 0: default 1 */
    cfg.mb_format = (rcd_mb_format)(data[1] & 1u);
    cfg.mb_decimals = (uint8_t)((data[1] >> 1) % 10u);

    rcd_mock_init(&port, &mock);
    mock.rx = data + 3;
    mock.rx_len = size - 3;
    mock.tx = tx;
    mock.tx_cap = sizeof tx;
    mock.max_chunk = (size_t)(data[2] & 15u);      /* 0: whole reads */
    mock.timeout_every = (unsigned)(data[2] >> 4) % 5u; /* 0: never */
    if (mock.timeout_every == 1)
        mock.timeout_every = 2; /* every read timing out would never deliver a byte */
    mock.closed_at_end = 1;
    FZ_CHECK(rcd_port_open(&port, "mock", NULL) == RC_OK);
    FZ_CHECK(rcd_display_init(&d, &port, &cfg) == RC_OK);

    unsigned long ok = 0;
    const size_t max_calls = 4 * (size + 8);
    size_t calls = 0;
    for (;;) {
        rcd_reading r;
        memset(&r, 0, sizeof r);
        rc_status st = rcd_display_read(&d, &r, 1000);
        FZ_CHECK(++calls <= max_calls); /* must reach the hang-up: no livelock */
        FZ_CHECK(d.len <= sizeof d.buf);
        if (st == RC_ERR_CLOSED)
            break;
        switch (st) {
        case RC_OK:
            ++ok;
            FZ_CHECK(isfinite(r.len_mm));
            if (cfg.protocol != RCD_PROTO_MODBUS)
                FZ_CHECK(d.lock_decimals != -2 && r.decimals == d.lock_decimals &&
                         r.unit == d.lock_unit);
            break;
        case RC_ERR_FORMAT:
        case RC_ERR_CHECKSUM:
        case RC_ERR_TIMEOUT:
            break;
        case RC_ERR_DEVICE:
            FZ_CHECK(cfg.protocol == RCD_PROTO_MODBUS);
            break;
        default:
            FZ_CHECK(0 && "undocumented status from rcd_display_read");
        }
    }
    FZ_CHECK(d.stats.readings == ok);
    FZ_CHECK(d.stats.bytes <= mock.rx_len);
    FZ_CHECK(mock.rx_pos == mock.rx_len);
    rcd_port_close(&port);
    return 0;
}
