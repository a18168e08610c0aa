/* SPDX-License-Identifier: MIT */
/* fuzz_modbus.c - Modbus RTU responses (rcd_parse_modbus) with every
 * register format and word order.
 * Input: byte 0 slave address (0: default 1), byte 1 format/word order/
 * decimals, byte 2 chunk size, the rest the byte stream from the display. */
#include "fuzz_proto_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rc_status p_mb(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                      const uint8_t *buf, size_t len)
{
    return rcd_parse_modbus(out, consumed, cfg, buf, len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static fz_readings whole, chunked;
    rcd_proto_config cfg;
    if (size < 3)
        return 0;
    memset(&cfg, 0, sizeof cfg);
    cfg.protocol = RCD_PROTO_MODBUS;
    cfg.mb_addr = data[0];
    cfg.mb_format = (rcd_mb_format)(data[1] & 1u);
    cfg.mb_order = (rcd_word_order)((data[1] >> 1) & 3u);
    cfg.mb_decimals = (uint8_t)((data[1] >> 3) % 10u);
    const size_t chunk = (size_t)(data[2] % 16u) + 1u;
    data += 3, size -= 3;

    fz_parse_stream(&whole, p_mb, &cfg, data, size);
    for (size_t i = 0; i < whole.n; ++i) {
        FZ_CHECK(whole.r[i].decimals == -1 && whole.r[i].unit == RCD_UNIT_MM);
        if (cfg.mb_format == RCD_MB_INT32)
            FZ_CHECK(fabs(whole.r[i].len_mm) <= 2147483648.0);
    }
    /* Chunked delivery: RTU has no delimiter, so overlapping frames may be
     * resolved differently; only the contract checks apply. */
    fz_parse_chunked(&chunked, p_mb, &cfg, data, size, chunk);
    /* A frame the encoder writes is read back exactly (round trip). */
    {
        uint8_t fr[RCD_MAX_FRAME];
        size_t n = 0, c = 0;
        rcd_reading r;
        double v = 0.0;
        if (size >= 4) {
            int32_t raw;
            memcpy(&raw, data, sizeof raw);
            v = (double)raw / 1000.0;
        }
        if (rcd_encode_modbus(fr, &n, sizeof fr, v, &cfg) == RC_OK) {
            FZ_CHECK(n == RCD_MODBUS_RESP_LEN);
            FZ_CHECK(rcd_parse_modbus(&r, &c, &cfg, fr, n) == RC_OK && c == n);
            FZ_CHECK(isfinite(r.len_mm));
        }
    }
    return 0;
}
