/* SPDX-License-Identifier: MIT */
/* test_drv_display.c - mock port and display reader: short reads, timeouts,
 * failure after every byte N, polled protocols, format lock. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "rcd_display.h"

enum { NV = 12 };

static size_t build_ascii(uint8_t *s, size_t cap, const double *v, size_t n)
{
    size_t len = 0;
    for (size_t i = 0; i < n; ++i) {
        size_t k;
        assert_int_equal(rcd_encode_ascii(s + len, &k, cap - len, v[i], RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 2), RC_OK);
        len += k;
    }
    return len;
}

static void values(double *v)
{
    for (int i = 0; i < NV; ++i)
        v[i] = 500.0 + i * 1.25;
}

/* Streaming ASCII in chunks of 1..9 bytes: the first LOCK_COUNT-1 frames
 * teach the format, every later frame comes out exactly. */
static void test_stream_chunks(void **state)
{
    uint8_t s[1024];
    double v[NV];
    (void)state;
    values(v);
    size_t len = build_ascii(s, sizeof s, v, NV);
    for (size_t chunk = 1; chunk < 10; ++chunk) {
        rcd_port p;
        rcd_mock_ctx m;
        rcd_display d;
        rcd_reading r;
        rcd_mock_init(&p, &m);
        m.rx = s;
        m.rx_len = len;
        m.max_chunk = chunk;
        assert_int_equal(rcd_port_open(&p, "mock", NULL), RC_OK);
        assert_int_equal(rcd_display_init(&d, &p, NULL), RC_OK);
        for (int i = RCD_DISPLAY_LOCK_COUNT - 1; i < NV; ++i) {
            assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
            assert_true(r.len_mm == v[i]);
        }
        assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_TIMEOUT);
        assert_int_equal(d.stats.readings, NV - RCD_DISPLAY_LOCK_COUNT + 1);
        assert_int_equal(m.n_writes, 0); /* streaming never sends */
    }
}

/* The port fails after byte N, for every N: the readings before it are right,
 * then the failure is reported; never a wrong or partial value. */
static void test_fail_after_every_byte(void **state)
{
    uint8_t s[1024];
    double v[NV];
    (void)state;
    values(v);
    size_t len = build_ascii(s, sizeof s, v, NV), flen = len / NV;
    for (size_t n = 0; n <= len; ++n) {
        rcd_port p;
        rcd_mock_ctx m;
        rcd_display d;
        rcd_reading r;
        rc_status st;
        int got = 0;
        size_t complete = n / flen; /* frames wholly before byte n (CR ends a line) */
        if (n % flen == flen - 1)
            complete++;
        rcd_mock_init(&p, &m);
        m.rx = s;
        m.rx_len = len;
        m.max_chunk = 5;
        m.fail_rx_after = n;
        m.fail_status = RC_ERR_CLOSED;
        rcd_port_open(&p, "mock", NULL);
        rcd_display_init(&d, &p, NULL);
        while ((st = rcd_display_read(&d, &r, 100)) == RC_OK) {
            assert_true(r.len_mm == v[RCD_DISPLAY_LOCK_COUNT - 1 + got]);
            ++got;
        }
        assert_int_equal(st, RC_ERR_CLOSED); /* the mock fails at n == len too */
        assert_int_equal(got, complete >= RCD_DISPLAY_LOCK_COUNT ? complete - RCD_DISPLAY_LOCK_COUNT + 1 : 0);
    }
}

/* Every third read times out: the reader reports it and then carries on. */
static void test_timeouts_and_close(void **state)
{
    uint8_t s[1024];
    double v[NV];
    rcd_port p;
    rcd_mock_ctx m;
    rcd_display d;
    rcd_reading r;
    int got = 0, timeouts = 0;
    rc_status st;
    (void)state;
    values(v);
    rcd_mock_init(&p, &m);
    m.rx = s;
    m.rx_len = build_ascii(s, sizeof s, v, NV);
    m.max_chunk = 4;
    m.timeout_every = 3;
    m.closed_at_end = 1;
    rcd_port_open(&p, "mock", NULL);
    rcd_display_init(&d, &p, NULL);
    while ((st = rcd_display_read(&d, &r, 100)) != RC_ERR_CLOSED) {
        if (st == RC_ERR_TIMEOUT) {
            ++timeouts;
            continue;
        }
        assert_int_equal(st, RC_OK);
        assert_true(r.len_mm == v[RCD_DISPLAY_LOCK_COUNT - 1 + got]);
        ++got;
    }
    assert_int_equal(got, NV - RCD_DISPLAY_LOCK_COUNT + 1);
    assert_true(timeouts > 0);
    assert_int_equal(d.stats.timeouts, (unsigned long)timeouts);
    /* a closed port answers every call with RC_ERR_CLOSED */
    rcd_port_close(&p);
    assert_int_equal(rcd_display_read(&d, &r, 10), RC_ERR_CLOSED);
}

/* A dropped digit, point or unit letter changes the shape: rejected. */
static void test_format_lock(void **state)
{
    static const char script[] = "+0509.19\r\n+0509.20\r\n+0509.21\r\n"
                                 "+0509.2\r\n"   /* dropped decimal digit */
                                 "+050922\r\n"   /* dropped point */
                                 "+0509.22\r\n"
                                 "+0509.23 CM\r\n" /* unit appeared */
                                 "+0509.24\r\n";
    rcd_port p;
    rcd_mock_ctx m;
    rcd_display d;
    rcd_reading r;
    (void)state;
    rcd_mock_init(&p, &m);
    m.rx = (const uint8_t *)script;
    m.rx_len = sizeof script - 1;
    rcd_port_open(&p, "mock", NULL);
    rcd_display_init(&d, &p, NULL);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm == 509.21);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_FORMAT);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_FORMAT);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm == 509.22);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_FORMAT);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm == 509.24);
    assert_int_equal(d.stats.shape_rejects, 3);
    /* a corrupted first frame does not lock the wrong shape */
    {
        static const char s2[] = "+0509.1\r\n+0509.19\r\n+0509.19\r\n+0509.19\r\n";
        rcd_mock_init(&p, &m);
        m.rx = (const uint8_t *)s2;
        m.rx_len = sizeof s2 - 1;
        rcd_port_open(&p, "mock", NULL);
        rcd_display_init(&d, &p, NULL);
        assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
        assert_true(r.len_mm == 509.19);
        assert_int_equal(d.lock_decimals, 2);
    }
}

/* Modbus: the request goes out (flushed first), the answer comes back; an
 * exception is a device error; a corrupted answer a checksum error. */
static void test_modbus_polled(void **state)
{
    rcd_proto_config cfg = {0};
    uint8_t s[128], tx[128];
    size_t len = 0, k;
    static const size_t segs[] = {9, 5, 9};
    rcd_port p;
    rcd_mock_ctx m;
    rcd_display d;
    rcd_reading r;
    (void)state;
    cfg.protocol = RCD_PROTO_MODBUS;
    cfg.mb_addr = 5;
    cfg.mb_reg = 0x1000;
    cfg.mb_format = RCD_MB_FLOAT32;
    cfg.mb_order = RCD_WO_CDAB;
    assert_int_equal(rcd_encode_modbus(s, &k, sizeof s, 1234.5, &cfg), RC_OK);
    len += k;
    assert_int_equal(rcd_encode_modbus_exception(s + len, &k, sizeof s - len, 5, 4), RC_OK);
    len += k;
    assert_int_equal(rcd_encode_modbus(s + len, &k, sizeof s - len, 99.0, &cfg), RC_OK);
    s[len + 4] ^= 0x10; /* corrupt */
    len += k;
    rcd_mock_init(&p, &m);
    m.segments = segs;
    m.n_segments = 3;
    m.rx = s;
    m.rx_len = len;
    m.tx = tx;
    m.tx_cap = sizeof tx;
    m.max_chunk = 3;
    rcd_port_open(&p, "mock", NULL);
    rcd_display_init(&d, &p, &cfg);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm == 1234.5);
    assert_int_equal(m.tx_len, 8);
    assert_int_equal(tx[0], 5);
    assert_int_equal(tx[1], 3);
    assert_int_equal(tx[2], 0x10);
    assert_int_equal(tx[3], 0x00);
    assert_int_equal(tx[5], 2);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_DEVICE);
    assert_int_equal(r.exception, 4);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_CHECKSUM);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_TIMEOUT);
    assert_int_equal(m.tx_len, 32); /* one request per read */
    assert_int_equal(m.n_flush, 4);
    assert_int_equal(d.stats.polls, 4);
    /* a failing write is reported, not retried silently */
    rcd_mock_init(&p, &m);
    m.fail_tx_after = 3;
    rcd_port_open(&p, "mock", NULL);
    rcd_display_init(&d, &p, &cfg);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_ERR_IO);
    assert_int_equal(m.tx_total, 3);
}

/* ASCII polled and STX: command out, line/frame back, lock applies. */
static void test_ascii_poll_and_stx(void **state)
{
    uint8_t s[256], tx[64];
    size_t len = 0, k, segs[4];
    rcd_proto_config cfg = {0};
    rcd_port p;
    rcd_mock_ctx m;
    rcd_display d;
    rcd_reading r;
    (void)state;
    for (int i = 0; i < 4; ++i) {
        assert_int_equal(rcd_encode_stx(s + len, &k, sizeof s - len, 100.0 + i, 3), RC_OK);
        segs[i] = k;
        len += k;
    }
    cfg.protocol = RCD_PROTO_STX;
    memcpy(cfg.poll_cmd, "?\r", 3);
    rcd_mock_init(&p, &m);
    m.segments = segs;
    m.n_segments = 4;
    m.rx = s;
    m.rx_len = len;
    m.tx = tx;
    m.tx_cap = sizeof tx;
    rcd_port_open(&p, "mock", NULL);
    rcd_display_init(&d, &p, &cfg);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm == 102.0);
    assert_int_equal(m.tx_len, 6); /* three polls: two warm-up frames, one reading */
    assert_memory_equal(tx, "?\r?\r?\r", 6);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm == 103.0);
    /* ASCII polled */
    len = 0;
    for (int i = 0; i < 4; ++i) {
        assert_int_equal(rcd_encode_ascii(s + len, &k, sizeof s - len, 7.0 + i, RCD_STYLE_SPACE_UNIT, RCD_UNIT_CM, 1), RC_OK);
        segs[i] = k;
        len += k;
    }
    cfg.protocol = RCD_PROTO_ASCII_POLL;
    cfg.poll_cmd[0] = '\0';
    rcd_mock_init(&p, &m);
    m.rx = s;
    m.rx_len = len;
    m.tx = tx;
    m.tx_cap = sizeof tx;
    m.max_chunk = 2;
    m.segments = segs;
    m.n_segments = 4;
    rcd_port_open(&p, "mock", NULL);
    rcd_display_init(&d, &p, &cfg);
    assert_int_equal(rcd_display_read(&d, &r, 100), RC_OK);
    assert_true(r.len_mm > 9.0 - 1e-9 && r.len_mm < 9.0 + 1e-9); /* sent as "+   0.9, CM" */
    assert_memory_equal(tx, "R\r", 2);
}

static void test_port_contract(void **state)
{
    rcd_port p;
    rcd_mock_ctx m;
    uint8_t b[4];
    size_t n = 7;
    rcd_serial_config c = {0}, out;
    (void)state;
    rcd_mock_init(&p, &m);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 0), RC_ERR_CLOSED); /* not open */
    assert_int_equal(n, 0);
    assert_int_equal(rcd_port_read(&p, NULL, b, sizeof b, 0), RC_ERR_ARG);
    assert_int_equal(rcd_port_read(&p, &n, b, 0, 0), RC_ERR_ARG);
    assert_int_equal(rcd_port_write(&p, &n, NULL, 3, 0), RC_ERR_ARG);
    assert_int_equal(rcd_port_open(&p, NULL, NULL), RC_ERR_ARG);
    m.fail_open = 1;
    assert_int_equal(rcd_port_open(&p, "x", NULL), RC_ERR_IO);
    assert_int_equal(rcd_serial_config_resolve(&out, &c), RC_OK);
    assert_int_equal(out.baud, 9600);
    assert_int_equal(out.data_bits, 8);
    assert_int_equal(out.stop_bits, 1);
    assert_int_equal(out.parity, RCD_PARITY_NONE);
    c.data_bits = 9;
    assert_int_equal(rcd_serial_config_resolve(&out, &c), RC_ERR_ARG);
    c.data_bits = 7;
    c.stop_bits = 3;
    assert_int_equal(rcd_serial_config_resolve(&out, &c), RC_ERR_ARG);
    assert_string_equal(rcd_port_last_error(&p), "mock fault");
}

/* Time comes from the port: the mock's clock advances by the timeout of each
 * read that times out, and the display's deadline follows that clock (also
 * across a wrap of the 32-bit counter). */
static void test_port_clock(void **state)
{
    rcd_port p;
    rcd_mock_ctx m;
    rcd_display d;
    rcd_reading r;
    (void)state;
    rcd_mock_init(&p, &m);
    m.clock_ms = UINT32_MAX - 100u;
    assert_int_equal(rcd_port_open(&p, "mock", NULL), RC_OK);
    assert_int_equal(rcd_port_now_ms(&p), UINT32_MAX - 100u);
    assert_int_equal(rcd_display_init(&d, &p, NULL), RC_OK);
    assert_int_equal(rcd_display_read(&d, &r, 300), RC_ERR_TIMEOUT);
    assert_int_equal(rcd_port_now_ms(&p), (uint32_t)(UINT32_MAX - 100u + 300u));
    assert_int_equal(m.n_reads, 1);
    {
        rcd_port none = {NULL, NULL};
        assert_int_equal(rcd_port_now_ms(&none), 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stream_chunks),      cmocka_unit_test(test_fail_after_every_byte),
        cmocka_unit_test(test_timeouts_and_close), cmocka_unit_test(test_format_lock),
        cmocka_unit_test(test_modbus_polled),      cmocka_unit_test(test_ascii_poll_and_stx),
        cmocka_unit_test(test_port_contract),      cmocka_unit_test(test_port_clock),
    };
    return cmocka_run_group_tests_name("drv_display", tests, NULL, NULL);
}
