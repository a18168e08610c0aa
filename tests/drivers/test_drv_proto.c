/* SPDX-License-Identifier: MIT */
/* test_drv_proto.c - display protocol parsers: valid frames, every
 * truncation point, corruption of every byte, random garbage, encoders. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rc_rand.h"
#include "rcd_proto.h"

/* Parse from an exact-size heap copy, so that ASan catches any read past len. */
static rc_status parse_exact(rcd_reading *r, size_t *c, const rcd_proto_config *cfg, const uint8_t *b,
                             size_t len)
{
    uint8_t *copy = malloc(len ? len : 1);
    rc_status st;
    assert_non_null(copy);
    if (len)
        memcpy(copy, b, len);
    st = rcd_parse(r, c, cfg, copy, len);
    free(copy);
    return st;
}

static void expect_len(const rcd_proto_config *cfg, const char *frame, size_t len, double want_mm)
{
    rcd_reading r;
    size_t c = 0;
    rc_status st = parse_exact(&r, &c, cfg, (const uint8_t *)frame, len);
    assert_int_equal(st, RC_OK);
    assert_int_equal(c, len);
    assert_true(r.len_mm > want_mm - 1e-9 && r.len_mm < want_mm + 1e-9);
}

static void test_ascii_valid(void **state)
{
    rcd_proto_config cfg = {0};
    rcd_reading r;
    size_t c;
    (void)state;
    expect_len(&cfg, "+0509.19\r\n", 10, 509.19);
    expect_len(&cfg, "+ 509.190, MM\r\n", 15, 509.19);
    expect_len(&cfg, "-12.5 cm\n", 9, -125.0);
    expect_len(&cfg, " 1.5M\r", 6, 1500.0);
    expect_len(&cfg, "+0020.00 IN\r\n", 13, 508.0);
    expect_len(&cfg, "+0020.00,in\r\n", 13, 508.0);
    expect_len(&cfg, "0\n", 2, 0.0);
    /* decimals and unit are reported for the format lock */
    assert_int_equal(rcd_parse_ascii(&r, &c, (const uint8_t *)"+ 509.190, MM\r\n", 15), RC_OK);
    assert_int_equal(r.decimals, 3);
    assert_int_equal(r.unit, RCD_UNIT_MM);
    /* a CR LF split across reads: the lone LF is skipped as an empty line */
    assert_int_equal(rcd_parse_ascii(&r, &c, (const uint8_t *)"+1.0\r", 5), RC_OK);
    assert_int_equal(c, 5);
    assert_int_equal(rcd_parse_ascii(&r, &c, (const uint8_t *)"\n+2.0\r\n", 7), RC_OK);
    assert_int_equal(c, 7);
    assert_true(r.len_mm == 2.0);
}

static void test_ascii_malformed(void **state)
{
    static const char *const bad[] = {"+\r\n", ".5\r\n", "5.\r\n", "1.2.3\r\n", "12 34\r\n",
                                      "12.5 FT\r\n", "++12\r\n", "12.5 MM x\r\n", "\x01" "12\r\n",
                                      "1234567890123456\r\n", "7+0509.19\r\n", "+0509.19 MMM\r\n"};
    (void)state;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rcd_reading r;
        size_t c = 0, n = strlen(bad[i]);
        assert_int_equal(rcd_parse_ascii(&r, &c, (const uint8_t *)bad[i], n), RC_ERR_FORMAT);
        assert_int_equal(c, n); /* the whole bad line is dropped */
    }
    {
        /* a runaway line without terminator is dropped, not buffered forever */
        uint8_t big[200];
        size_t c = 0;
        memset(big, '1', sizeof big);
        assert_int_equal(rcd_parse_ascii(NULL, &c, big, sizeof big), RC_ERR_FORMAT);
        assert_true(c > 0 && c <= RCD_ASCII_MAX_LINE + 1);
    }
}

/* Every prefix of a valid frame: incomplete (or, for ASCII, the prefix that
 * ends at CR which is a complete line with the right value); never a wrong
 * value; consumed never beyond the prefix. */
static void check_truncations(const rcd_proto_config *cfg, const uint8_t *f, size_t len, double want)
{
    for (size_t k = 0; k < len; ++k) {
        rcd_reading r = {0};
        size_t c = 99999;
        rc_status st = parse_exact(&r, &c, cfg, f, k);
        assert_true(c <= k);
        if (st == RC_OK) {
            assert_true(cfg->protocol == RCD_PROTO_ASCII && k > 0 && f[k - 1] == '\r');
            assert_true(r.len_mm == want);
        } else {
            assert_int_equal(st, RC_ERR_INCOMPLETE);
            assert_int_equal(c, 0); /* the frame start is kept */
        }
    }
}

static void test_truncation_all_protocols(void **state)
{
    uint8_t f[RCD_MAX_FRAME];
    size_t n;
    rcd_proto_config cfg = {0};
    (void)state;
    cfg.protocol = RCD_PROTO_ASCII;
    assert_int_equal(rcd_encode_ascii(f, &n, sizeof f, 509.19, RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 2), RC_OK);
    assert_memory_equal(f, "+0509.19\r\n", 10);
    check_truncations(&cfg, f, n, 509.19);
    assert_int_equal(rcd_encode_ascii(f, &n, sizeof f, 509.19, RCD_STYLE_SPACE_UNIT, RCD_UNIT_MM, 3), RC_OK);
    assert_memory_equal(f, "+ 509.190, MM\r\n", 15);
    check_truncations(&cfg, f, n, 509.19);
    cfg.protocol = RCD_PROTO_STX;
    assert_int_equal(rcd_encode_stx(f, &n, sizeof f, 509.19, 2), RC_OK);
    check_truncations(&cfg, f, n, 509.19);
    cfg.protocol = RCD_PROTO_MODBUS;
    cfg.mb_decimals = 3;
    for (int wo = 0; wo < 4; ++wo)
        for (int fmt = 0; fmt < 2; ++fmt) {
            cfg.mb_order = (rcd_word_order)wo;
            cfg.mb_format = (rcd_mb_format)fmt;
            assert_int_equal(rcd_encode_modbus(f, &n, sizeof f, 509.19, &cfg), RC_OK);
            check_truncations(&cfg, f, n, fmt ? (double)509.19f : 509.19);
        }
    assert_int_equal(rcd_encode_modbus_exception(f, &n, sizeof f, 1, 2), RC_OK);
    check_truncations(&cfg, f, n, 0);
}

static void test_stx(void **state)
{
    static const uint8_t good[] = {0x02, '+', '1', '.', '5', 0x03, 0};
    uint8_t f[16];
    rcd_proto_config cfg = {0};
    rcd_reading r;
    size_t c;
    (void)state;
    cfg.protocol = RCD_PROTO_STX;
    memcpy(f, good, sizeof good);
    f[6] = (uint8_t)('+' ^ '1' ^ '.' ^ '5' ^ 0x03);
    assert_int_equal(parse_exact(&r, &c, &cfg, f, 7), RC_OK);
    assert_true(r.len_mm == 1.5);
    /* every single-byte corruption of the frame is detected */
    for (size_t i = 0; i < 7; ++i)
        for (unsigned bit = 0; bit < 8; ++bit) {
            uint8_t g[7];
            rc_status st;
            memcpy(g, f, 7);
            g[i] ^= (uint8_t)(1u << bit);
            st = parse_exact(&r, &c, &cfg, g, 7);
            assert_int_not_equal(st, RC_OK);
        }
    /* an STX inside a payload restarts the frame */
    {
        uint8_t h[20] = {0x02, '+', '9', 0x02};
        memcpy(h + 4, f + 1, 6);
        assert_int_equal(rcd_parse_stx(&r, &c, h, 10), RC_ERR_FORMAT);
        assert_int_equal(c, 3);
        assert_int_equal(rcd_parse_stx(&r, &c, h + 3, 7), RC_OK);
        assert_true(r.len_mm == 1.5);
    }
    /* empty payload, no ETX in time */
    {
        uint8_t e[3] = {0x02, 0x03, 0x03};
        uint8_t l[40];
        assert_int_equal(rcd_parse_stx(&r, &c, e, 3), RC_ERR_FORMAT);
        memset(l, '1', sizeof l);
        l[0] = 0x02;
        assert_int_equal(rcd_parse_stx(&r, &c, l, sizeof l), RC_ERR_FORMAT);
        assert_true(c > 0);
    }
}

static void test_modbus_vectors(void **state)
{
    /* reference vectors: the classic request 01 03 00 00 00 02 C4 0B and the
     * exception 01 83 02 C0 F1 */
    static const uint8_t req[] = {0x01, 0x03, 0x00, 0x00, 0x00, 0x02, 0xC4, 0x0B};
    static const uint8_t exc[] = {0x01, 0x83, 0x02, 0xC0, 0xF1};
    static const uint8_t i32[] = {0x01, 0x03, 0x04, 0x00, 0x07, 0xC5, 0x06, 0x98, 0xA0};
    static const uint8_t f32[] = {0x01, 0x03, 0x04, 0x43, 0xFE, 0x98, 0x52, 0x64, 0x7A};
    uint8_t b[16];
    size_t n, c;
    uint16_t reg, cnt;
    rcd_reading r;
    rcd_proto_config cfg = {0};
    (void)state;
    cfg.protocol = RCD_PROTO_MODBUS;
    assert_int_equal(rcd_build_request(b, &n, sizeof b, &cfg), RC_OK);
    assert_int_equal(n, 8);
    assert_memory_equal(b, req, 8);
    assert_int_equal(rcd_parse_modbus_request(&reg, &cnt, &c, 1, req, 8), RC_OK);
    assert_int_equal(reg, 0);
    assert_int_equal(cnt, 2);
    assert_int_equal(parse_exact(&r, &c, &cfg, exc, 5), RC_ERR_DEVICE);
    assert_int_equal(r.exception, 2);
    assert_int_equal(c, 5);
    cfg.mb_decimals = 3;
    assert_int_equal(parse_exact(&r, &c, &cfg, i32, 9), RC_OK);
    assert_true(r.len_mm > 509.19 - 1e-12 && r.len_mm < 509.19 + 1e-12);
    cfg.mb_format = RCD_MB_FLOAT32;
    assert_int_equal(parse_exact(&r, &c, &cfg, f32, 9), RC_OK);
    assert_true(r.len_mm == (double)509.19f);
    /* the encoder produces the same bytes */
    assert_int_equal(rcd_encode_modbus(b, &n, sizeof b, 509.19, &cfg), RC_OK);
    assert_memory_equal(b, f32, 9);
    cfg.mb_format = RCD_MB_INT32;
    assert_int_equal(rcd_encode_modbus(b, &n, sizeof b, 509.19, &cfg), RC_OK);
    assert_memory_equal(b, i32, 9);
    /* word orders: CDAB of 0x0007C506 is C5 06 00 07 */
    cfg.mb_order = RCD_WO_CDAB;
    assert_int_equal(rcd_encode_modbus(b, &n, sizeof b, 509.19, &cfg), RC_OK);
    assert_int_equal(b[3], 0xC5);
    assert_int_equal(b[4], 0x06);
    assert_int_equal(b[5], 0x00);
    assert_int_equal(b[6], 0x07);
    cfg.mb_order = RCD_WO_BADC;
    assert_int_equal(rcd_encode_modbus(b, &n, sizeof b, 509.19, &cfg), RC_OK);
    assert_int_equal(b[3], 0x07);
    assert_int_equal(b[6], 0xC5);
    cfg.mb_order = RCD_WO_DCBA;
    assert_int_equal(rcd_encode_modbus(b, &n, sizeof b, 509.19, &cfg), RC_OK);
    assert_int_equal(b[3], 0x06);
    assert_int_equal(b[6], 0x00);
    /* negative int32 round trip in every order */
    for (int wo = 0; wo < 4; ++wo) {
        cfg.mb_order = (rcd_word_order)wo;
        assert_int_equal(rcd_encode_modbus(b, &n, sizeof b, -1234.567, &cfg), RC_OK);
        assert_int_equal(parse_exact(&r, &c, &cfg, b, n), RC_OK);
        assert_true(r.len_mm > -1234.567 - 1e-9 && r.len_mm < -1234.567 + 1e-9);
    }
    /* a NaN float is refused, never returned */
    {
        rcd_proto_config fc = cfg;
        uint16_t crc;
        uint8_t nan_f[9] = {0x01, 0x03, 0x04, 0x7F, 0xC0, 0x00, 0x00};
        fc.mb_format = RCD_MB_FLOAT32;
        fc.mb_order = RCD_WO_ABCD;
        crc = rcd_crc16_modbus(nan_f, 7);
        nan_f[7] = (uint8_t)crc;
        nan_f[8] = (uint8_t)(crc >> 8);
        assert_int_equal(parse_exact(&r, &c, &fc, nan_f, 9), RC_ERR_FORMAT);
    }
    /* another slave's answer is consumed and named, not taken (issue 12) */
    {
        rcd_proto_config other = cfg;
        other.mb_addr = 7;
        assert_int_equal(parse_exact(&r, &c, &other, i32, 9), RC_ERR_FORMAT);
        assert_int_equal(c, 9);
        assert_int_equal(r.reject, RCD_REJECT_MB_SLAVE);
        assert_int_equal(r.mb_addr, 1);
        assert_int_equal(r.mb_fn, 0x03);
    }
    /* our slave answering another function (input registers 0x04, or an
     * exception of another function): named as such */
    {
        uint8_t f4[9], e4[5];
        uint16_t crc;
        memcpy(f4, i32, 9);
        f4[1] = 0x04;
        crc = rcd_crc16_modbus(f4, 7);
        f4[7] = (uint8_t)crc;
        f4[8] = (uint8_t)(crc >> 8);
        assert_int_equal(parse_exact(&r, &c, &cfg, f4, 9), RC_ERR_FORMAT);
        assert_int_equal(c, 9);
        assert_int_equal(r.reject, RCD_REJECT_MB_FUNCTION);
        assert_int_equal(r.mb_fn, 0x04);
        e4[0] = 0x01;
        e4[1] = 0x84;
        e4[2] = 0x01;
        crc = rcd_crc16_modbus(e4, 3);
        e4[3] = (uint8_t)crc;
        e4[4] = (uint8_t)(crc >> 8);
        assert_int_equal(parse_exact(&r, &c, &cfg, e4, 5), RC_ERR_FORMAT);
        assert_int_equal(r.reject, RCD_REJECT_MB_FUNCTION);
        assert_int_equal(r.mb_fn, 0x84);
    }
}

static void test_modbus_corruption(void **state)
{
    uint8_t f[16];
    size_t n;
    rcd_proto_config cfg = {0};
    (void)state;
    cfg.protocol = RCD_PROTO_MODBUS;
    cfg.mb_decimals = 2;
    assert_int_equal(rcd_encode_modbus(f, &n, sizeof f, 777.77, &cfg), RC_OK);
    for (size_t i = 0; i < n; ++i)
        for (unsigned bit = 0; bit < 8; ++bit) {
            uint8_t g[16];
            size_t c, total = 0;
            rcd_reading r;
            rc_status st;
            memcpy(g, f, n);
            g[i] ^= (uint8_t)(1u << bit);
            /* drain the buffer as a reader would: no value may come out */
            do {
                st = parse_exact(&r, &c, &cfg, g + total, n - total);
                assert_int_not_equal(st, RC_OK);
                total += c;
            } while (st != RC_ERR_INCOMPLETE && total < n);
        }
    /* an incomplete false start does not hide a complete frame behind it */
    {
        uint8_t g[20] = {0x01, 0x03, 0x04, 0xAA};
        rcd_reading r;
        size_t c;
        memcpy(g + 4, f, n);
        assert_int_equal(parse_exact(&r, &c, &cfg, g, 4 + n), RC_OK);
        assert_true(r.len_mm > 777.77 - 1e-9 && r.len_mm < 777.77 + 1e-9);
        assert_int_equal(c, 4 + n);
    }
}

/* Frames separated by random garbage, streamed through a reader loop in
 * random chunk sizes: every frame is recovered, in order, and nothing else. */
static void run_garbage(rcd_protocol proto, uint64_t seed)
{
    enum { NF = 300 };
    static uint8_t stream[NF * 64];
    double sent[NF];
    size_t len = 0, got = 0, buf_len = 0, pos = 0;
    uint8_t buf[256];
    rcd_proto_config cfg = {0};
    rc_rng g;
    rc_rng_seed(&g, seed);
    cfg.protocol = proto;
    cfg.mb_decimals = 2;
    for (int i = 0; i < NF; ++i) {
        size_t n = 0, ng = 1 + rc_rng_below(&g, 20);
        sent[i] = (double)(10000 + rc_rng_below(&g, 90000)) / 100.0;
        for (size_t k = 0; k < ng; ++k) {
            uint8_t b = (uint8_t)rc_rng_below(&g, 256);
            if (proto == RCD_PROTO_ASCII && (b == '\r' || b == '\n'))
                b = 'x';
            if (proto == RCD_PROTO_STX && b == RCD_STX)
                b = 'x'; /* an STX in garbage costs the frame after it: tested elsewhere */
            stream[len++] = b;
        }
        if (proto == RCD_PROTO_ASCII) { /* the garbage ends its own line */
            stream[len++] = '\r';
            stream[len++] = '\n';
            assert_int_equal(rcd_encode_ascii(stream + len, &n, 64, sent[i], RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 2), RC_OK);
        } else if (proto == RCD_PROTO_STX) {
            assert_int_equal(rcd_encode_stx(stream + len, &n, 64, sent[i], 2), RC_OK);
        } else {
            assert_int_equal(rcd_encode_modbus(stream + len, &n, 64, sent[i], &cfg), RC_OK);
        }
        len += n;
    }
    while (pos < len || buf_len) {
        size_t chunk = 1 + rc_rng_below(&g, 16), c;
        rcd_reading r;
        rc_status st;
        if (chunk > len - pos)
            chunk = len - pos;
        if (chunk > sizeof buf - buf_len)
            chunk = sizeof buf - buf_len;
        memcpy(buf + buf_len, stream + pos, chunk);
        buf_len += chunk;
        pos += chunk;
        do {
            st = rcd_parse(&r, &c, &cfg, buf, buf_len);
            assert_true(c <= buf_len);
            memmove(buf, buf + c, buf_len - c);
            buf_len -= c;
            if (st == RC_OK) {
                assert_true(got < NF);
                assert_true(r.len_mm > sent[got] - 1e-9 && r.len_mm < sent[got] + 1e-9);
                ++got;
            }
        } while (st != RC_ERR_INCOMPLETE);
        if (pos == len)
            break;
    }
    assert_int_equal(got, NF);
}

static void test_garbage_ascii(void **state)
{
    (void)state;
    run_garbage(RCD_PROTO_ASCII, 11);
}

static void test_garbage_stx(void **state)
{
    (void)state;
    run_garbage(RCD_PROTO_STX, 12);
}

static void test_garbage_modbus(void **state)
{
    (void)state;
    run_garbage(RCD_PROTO_MODBUS, 13);
}

/* Pure random bytes: parsers terminate, always progress, never overrun. */
static void test_random_bytes(void **state)
{
    rc_rng g;
    (void)state;
    rc_rng_seed(&g, 99);
    for (int proto = 0; proto < 4; ++proto) {
        rcd_proto_config cfg = {0};
        cfg.protocol = (rcd_protocol)proto;
        for (int trial = 0; trial < 200; ++trial) {
            uint8_t b[100];
            size_t len = rc_rng_below(&g, sizeof b), off = 0;
            for (size_t i = 0; i < len; ++i)
                b[i] = (uint8_t)rc_rng_below(&g, 256);
            for (int guard = 0; guard < 200 && off < len; ++guard) {
                size_t c = 0;
                rc_status st = parse_exact(NULL, &c, &cfg, b + off, len - off);
                assert_true(c <= len - off);
                off += c;
                if (st == RC_ERR_INCOMPLETE)
                    break;
                assert_true(c > 0); /* progress on every non-incomplete result */
            }
        }
    }
}

static void test_encoders_and_names(void **state)
{
    uint8_t b[64];
    size_t n;
    rcd_protocol p;
    rcd_word_order wo;
    rcd_unit u;
    (void)state;
    assert_int_equal(rcd_format_value(b, &n, sizeof b, -3.14159, RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 3), RC_OK);
    assert_memory_equal(b, "-0003.142", 9);
    assert_int_equal(rcd_format_value(b, &n, sizeof b, 12345.6, RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 1), RC_OK);
    assert_memory_equal(b, "+12345.6", 8);
    assert_int_equal(rcd_format_value(b, &n, sizeof b, 508.0, RCD_STYLE_SPACE_UNIT, RCD_UNIT_IN, 2), RC_OK);
    assert_memory_equal(b, "+  20.00, IN", 12);
    assert_int_equal(rcd_format_value(b, &n, 4, 508.0, RCD_STYLE_SPACE_UNIT, RCD_UNIT_IN, 2), RC_ERR_CAPACITY);
    assert_int_equal(rcd_protocol_from_name(&p, "Modbus"), RC_OK);
    assert_int_equal(p, RCD_PROTO_MODBUS);
    assert_int_equal(rcd_protocol_from_name(&p, "ascii-poll"), RC_OK);
    assert_int_equal(p, RCD_PROTO_ASCII_POLL);
    assert_int_equal(rcd_protocol_from_name(&p, "nope"), RC_ERR_ARG);
    assert_int_equal(rcd_word_order_from_name(&wo, "dcba"), RC_OK);
    assert_int_equal(wo, RCD_WO_DCBA);
    assert_int_equal(rcd_unit_from_name(&u, "cm"), RC_OK);
    assert_int_equal(u, RCD_UNIT_CM);
    {
        rcd_proto_config cfg = {0};
        cfg.protocol = RCD_PROTO_ASCII_POLL;
        assert_int_equal(rcd_build_request(b, &n, sizeof b, &cfg), RC_OK);
        assert_int_equal(n, 2);
        assert_memory_equal(b, "R\r", 2);
        memcpy(cfg.poll_cmd, "MEAS?\r\n", 8);
        assert_int_equal(rcd_build_request(b, &n, sizeof b, &cfg), RC_OK);
        assert_int_equal(n, 7);
        assert_int_equal(rcd_build_request(b, &n, 3, &cfg), RC_ERR_CAPACITY);
        cfg.protocol = RCD_PROTO_ASCII;
        assert_int_equal(rcd_build_request(b, &n, sizeof b, &cfg), RC_OK);
        assert_int_equal(n, 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ascii_valid),       cmocka_unit_test(test_ascii_malformed),
        cmocka_unit_test(test_truncation_all_protocols), cmocka_unit_test(test_stx),
        cmocka_unit_test(test_modbus_vectors),    cmocka_unit_test(test_modbus_corruption),
        cmocka_unit_test(test_garbage_ascii),     cmocka_unit_test(test_garbage_stx),
        cmocka_unit_test(test_garbage_modbus),    cmocka_unit_test(test_random_bytes),
        cmocka_unit_test(test_encoders_and_names),
    };
    return cmocka_run_group_tests_name("drv_proto", tests, NULL, NULL);
}
