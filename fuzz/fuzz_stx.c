/* SPDX-License-Identifier: MIT */
/* fuzz_stx.c - STX payload ETX BCC frames (rcd_parse_stx).
 * Input: byte 0 chooses the chunk size of the chunked pass, the rest is
 * the byte stream from the display. */
#include "fuzz_proto_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rc_status p_stx(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                       const uint8_t *buf, size_t len)
{
    (void)cfg;
    return rcd_parse_stx(out, consumed, buf, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static fz_readings whole, chunked, viad;
    rcd_proto_config cfg;
    if (size < 1)
        return 0;
    memset(&cfg, 0, sizeof cfg);
    cfg.protocol = RCD_PROTO_STX;
    const size_t chunk = (size_t)(data[0] % 16u) + 1u;
    data++, size--;

    fz_parse_stream(&whole, p_stx, &cfg, data, size);
    fz_parse_chunked(&chunked, p_stx, &cfg, data, size, chunk);
    FZ_CHECK(fz_same_readings(&whole, &chunked));
    fz_parse_stream(&viad, rcd_parse, &cfg, data, size);
    FZ_CHECK(fz_same_readings(&whole, &viad));
    return 0;
}
