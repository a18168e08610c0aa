/* SPDX-License-Identifier: MIT */
/* fuzz_proto_common.h - checks shared by the display protocol fuzz targets.
 *
 * Every parser of rcd_proto.h has the same contract (see its header):
 * it looks at buf[0..len) only, *consumed <= len, and consumed >= 1 for every
 * result but RC_OK/RC_ERR_INCOMPLETE, so a loop "parse, drop consumed"
 * always progresses. The targets check that contract on every call, and for
 * the line and STX protocols that a stream cut into arbitrary chunks gives
 * the same readings as the whole stream (what a serial port does to it).
 */
#ifndef FUZZ_PROTO_COMMON_H
#define FUZZ_PROTO_COMMON_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rcd_proto.h"

typedef rc_status (*fz_parser)(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                               const uint8_t *buf, size_t len);

#define FZ_MAX_READINGS 4096

typedef struct fz_readings {
    size_t n;
    rcd_reading r[FZ_MAX_READINGS];
} fz_readings;

/* One call with the contract checks; the parser sees a private copy of
 * exactly len bytes so that ASan catches any read past the end. */
static rc_status fz_parse_once(fz_parser parse, rcd_reading *r, size_t *consumed,
                               const rcd_proto_config *cfg, const uint8_t *buf, size_t len)
{
    rc_status st;
    *consumed = (size_t)-1;
    memset(r, 0xA5, sizeof *r);
    st = parse(r, consumed, cfg, buf, len);
    FZ_CHECK(*consumed <= len);
    switch (st) {
    case RC_OK:
        FZ_CHECK(*consumed >= 1);
        FZ_CHECK(isfinite(r->len_mm));
        break;
    case RC_ERR_INCOMPLETE:
        break;
    case RC_ERR_FORMAT:
    case RC_ERR_CHECKSUM:
    case RC_ERR_DEVICE:
        FZ_CHECK(*consumed >= 1);
        break;
    default:
        FZ_CHECK(0 && "unexpected status from a parser");
    }
    if (st == RC_ERR_DEVICE)
        FZ_CHECK(cfg->protocol == RCD_PROTO_MODBUS);
    /* the same bytes give the same answer (no hidden state) */
    {
        rcd_reading r2;
        size_t c2 = 0;
        memset(&r2, 0, sizeof r2);
        FZ_CHECK(parse(&r2, &c2, cfg, buf, len) == st && c2 == *consumed);
        if (st == RC_OK)
            FZ_CHECK(r2.len_mm == r->len_mm && r2.decimals == r->decimals && r2.unit == r->unit);
        /* out may be NULL */
        FZ_CHECK(parse(NULL, &c2, cfg, buf, len) == st && c2 == *consumed);
    }
    return st;
}

/* Parse the whole stream as one buffer: "parse, drop consumed" until the
 * parser needs more input. Collects the readings. */
static void fz_parse_stream(fz_readings *out, fz_parser parse, const rcd_proto_config *cfg,
                            const uint8_t *data, size_t size)
{
    size_t pos = 0, calls = 0;
    out->n = 0;
    for (;;) {
        rcd_reading r;
        size_t c;
        rc_status st = fz_parse_once(parse, &r, &c, cfg, data + pos, size - pos);
        FZ_CHECK(++calls <= size + 2); /* progress: at most one call per byte */
        pos += c;
        if (st == RC_ERR_INCOMPLETE)
            break;
        if (st == RC_OK && out->n < FZ_MAX_READINGS)
            out->r[out->n++] = r;
    }
}

/* The same stream delivered in chunks into a bounded receive buffer, as
 * rcd_display does: append a chunk, parse until more input is needed. */
static void fz_parse_chunked(fz_readings *out, fz_parser parse, const rcd_proto_config *cfg,
                             const uint8_t *data, size_t size, size_t chunk)
{
    uint8_t buf[512];
    size_t len = 0, pos = 0;
    out->n = 0;
    while (pos < size) {
        size_t n = size - pos < chunk ? size - pos : chunk;
        FZ_CHECK(len + n <= sizeof buf); /* parsers must bound what they keep */
        memcpy(buf + len, data + pos, n);
        len += n;
        pos += n;
        for (;;) {
            rcd_reading r;
            size_t c;
            rc_status st = fz_parse_once(parse, &r, &c, cfg, buf, len);
            memmove(buf, buf + c, len - c);
            len -= c;
            if (st == RC_ERR_INCOMPLETE)
                break;
            if (st == RC_OK && out->n < FZ_MAX_READINGS)
                out->r[out->n++] = r;
        }
    }
}

static inline int fz_same_readings(const fz_readings *a, const fz_readings *b)
{
    if (a->n != b->n)
        return 0;
    for (size_t i = 0; i < a->n; ++i)
        if (a->r[i].len_mm != b->r[i].len_mm || a->r[i].decimals != b->r[i].decimals ||
            a->r[i].unit != b->r[i].unit)
            return 0;
    return 1;
}

#endif
