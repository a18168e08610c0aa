/* SPDX-License-Identifier: MIT */
/* fuzz_ascii.c - ASCII line protocol (streaming and polled share
 * rcd_parse_ascii) and the reading grammar rcd_parse_value.
 * Input: byte 0 chooses the chunk size of the chunked pass, the rest is
 * the byte stream from the display. */
#include "fuzz_proto_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rc_status p_ascii(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                         const uint8_t *buf, size_t len)
{
    (void)cfg;
    return rcd_parse_ascii(out, consumed, buf, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static fz_readings whole, chunked;
    rcd_proto_config cfg;
    if (size < 1)
        return 0;
    memset(&cfg, 0, sizeof cfg);
    cfg.protocol = RCD_PROTO_ASCII;
    const size_t chunk = (size_t)(data[0] % 16u) + 1u;
    data++, size--;

    fz_parse_stream(&whole, p_ascii, &cfg, data, size);
    fz_parse_chunked(&chunked, p_ascii, &cfg, data, size, chunk);
    FZ_CHECK(fz_same_readings(&whole, &chunked));
    for (size_t i = 0; i < whole.n; ++i) {
        FZ_CHECK(whole.r[i].decimals >= 0 && whole.r[i].decimals <= 18);
        FZ_CHECK(whole.r[i].unit <= RCD_UNIT_IN);
    }
    /* the dispatcher gives the same for both line protocols */
    {
        static fz_readings viad;
        cfg.protocol = RCD_PROTO_ASCII_POLL;
        fz_parse_stream(&viad, rcd_parse, &cfg, data, size);
        FZ_CHECK(fz_same_readings(&whole, &viad));
    }
    /* the whole input as the text of one reading */
    {
        rcd_reading r;
        if (rcd_parse_value(&r, data, size) == RC_OK) {
            FZ_CHECK(isfinite(r.len_mm));
            FZ_CHECK(memchr(data, '\n', size) == NULL && memchr(data, '\r', size) == NULL);
        }
    }
    return 0;
}
