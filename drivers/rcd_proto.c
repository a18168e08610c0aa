/* SPDX-License-Identifier: MIT */
/* rcd_proto.c - display protocol parsers and encoders (pure, no heap/stdio). */
#include <string.h>

#include "rcd_proto.h"

#define NONE_POS ((size_t)-1)

static double pow10_u(unsigned k)
{
    double p = 1.0;
    while (k--)
        p *= 10.0;
    return p;
}

double rcd_unit_mm(rcd_unit u)
{
    switch (u) {
    case RCD_UNIT_CM: return 10.0;
    case RCD_UNIT_M: return 1000.0;
    case RCD_UNIT_IN: return 25.4;
    case RCD_UNIT_MM:
    case RCD_UNIT_NONE:
    default: return 1.0;
    }
}

static int upc(uint8_t c)
{
    return (c >= 'a' && c <= 'z') ? c - 'a' + 'A' : c;
}

static int is_alpha(uint8_t c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

rc_status rcd_parse_value(rcd_reading *out, const uint8_t *t, size_t len)
{
    size_t i = 0, ndig = 0, nsig = 0, u0;
    uint64_t mant = 0;
    int neg = 0, dec = -1;
    rcd_unit unit = RCD_UNIT_NONE;
    if (!t)
        return RC_ERR_ARG;
    while (i < len && t[i] == ' ')
        ++i;
    if (i < len && (t[i] == '+' || t[i] == '-')) {
        neg = t[i] == '-';
        ++i;
    }
    while (i < len && t[i] == ' ')
        ++i;
    for (; i < len; ++i) {
        if (t[i] >= '0' && t[i] <= '9') {
            if (mant != 0 || t[i] != '0')
                ++nsig;
            if (nsig > 15)
                return RC_ERR_FORMAT;
            mant = mant * 10u + (uint64_t)(t[i] - '0');
            ++ndig;
            if (dec >= 0)
                ++dec;
        } else if (t[i] == '.') {
            if (dec >= 0 || ndig == 0)
                return RC_ERR_FORMAT; /* second point, or no integer digit */
            dec = 0;
        } else {
            break;
        }
        if (ndig > 18)
            return RC_ERR_FORMAT;
    }
    if (ndig == 0 || dec == 0)
        return RC_ERR_FORMAT; /* no digit, or a point without decimals */
    while (i < len && t[i] == ' ')
        ++i;
    if (i < len && t[i] == ',') {
        ++i;
        while (i < len && t[i] == ' ')
            ++i;
    }
    u0 = i;
    while (i < len && is_alpha(t[i]))
        ++i;
    if (i > u0) {
        size_t n = i - u0;
        if (n == 2 && upc(t[u0]) == 'M' && upc(t[u0 + 1]) == 'M')
            unit = RCD_UNIT_MM;
        else if (n == 2 && upc(t[u0]) == 'C' && upc(t[u0 + 1]) == 'M')
            unit = RCD_UNIT_CM;
        else if (n == 1 && upc(t[u0]) == 'M')
            unit = RCD_UNIT_M;
        else if (n == 2 && upc(t[u0]) == 'I' && upc(t[u0 + 1]) == 'N')
            unit = RCD_UNIT_IN;
        else
            return RC_ERR_FORMAT;
    }
    while (i < len && t[i] == ' ')
        ++i;
    if (i != len)
        return RC_ERR_FORMAT;
    if (out) {
        double v = (double)mant / pow10_u(dec < 0 ? 0u : (unsigned)dec);
        out->len_mm = (neg ? -v : v) * rcd_unit_mm(unit);
        out->decimals = (int8_t)(dec < 0 ? 0 : dec);
        out->unit = (uint8_t)unit;
        out->exception = 0;
        out->reject = RCD_REJECT_NONE;
        out->mb_addr = 0;
        out->mb_fn = 0;
    }
    return RC_OK;
}

rc_status rcd_parse_ascii(rcd_reading *out, size_t *consumed, const uint8_t *buf, size_t len)
{
    size_t i = 0, start, j;
    rc_status st;
    if (!consumed || (!buf && len))
        return RC_ERR_ARG;
    *consumed = 0;
    while (i < len && (buf[i] == '\r' || buf[i] == '\n'))
        ++i; /* empty lines (the LF of a CR LF split across reads) */
    start = i;
    for (j = start; j < len && buf[j] != '\r' && buf[j] != '\n'; ++j)
        if (j - start >= RCD_ASCII_MAX_LINE) {
            *consumed = j; /* runaway line: drop it, keep looking */
            return RC_ERR_FORMAT;
        }
    if (j == len) {
        *consumed = start;
        return RC_ERR_INCOMPLETE;
    }
    *consumed = (buf[j] == '\r' && j + 1 < len && buf[j + 1] == '\n') ? j + 2 : j + 1;
    st = rcd_parse_value(out, buf + start, j - start);
    if (st == RC_OK && start == j)
        st = RC_ERR_FORMAT;
    return st;
}

uint8_t rcd_xor8(const uint8_t *data, size_t len)
{
    uint8_t x = 0;
    for (size_t i = 0; i < len; ++i)
        x ^= data[i];
    return x;
}

rc_status rcd_parse_stx(rcd_reading *out, size_t *consumed, const uint8_t *buf, size_t len)
{
    size_t i = 0, k;
    if (!consumed || (!buf && len))
        return RC_ERR_ARG;
    *consumed = 0;
    while (i < len && buf[i] != RCD_STX)
        ++i;
    if (i == len) {
        *consumed = len; /* all garbage */
        return RC_ERR_INCOMPLETE;
    }
    for (k = i + 1; k < len; ++k) {
        if (buf[k] == RCD_STX) {
            *consumed = k; /* a new frame starts inside this one: drop the broken head */
            return RC_ERR_FORMAT;
        }
        if (buf[k] == RCD_ETX) {
            rc_status st;
            if (k + 1 >= len) {
                *consumed = i;
                return RC_ERR_INCOMPLETE; /* BCC not here yet */
            }
            *consumed = k + 2;
            if ((uint8_t)(rcd_xor8(buf + i + 1, k - i - 1) ^ RCD_ETX) != buf[k + 1])
                return RC_ERR_CHECKSUM;
            if (k == i + 1)
                return RC_ERR_FORMAT;
            st = rcd_parse_value(out, buf + i + 1, k - i - 1);
            return st == RC_OK ? RC_OK : RC_ERR_FORMAT;
        }
        if (k - i > RCD_STX_MAX_PAYLOAD) {
            *consumed = k; /* no ETX in time */
            return RC_ERR_FORMAT;
        }
    }
    *consumed = i;
    return RC_ERR_INCOMPLETE;
}

uint16_t rcd_crc16_modbus(const uint8_t *data, size_t len)
{
    uint16_t crc = 0xFFFFu;
    for (size_t i = 0; i < len; ++i) {
        crc ^= data[i];
        for (int b = 0; b < 8; ++b)
            crc = (crc & 1u) ? (uint16_t)((crc >> 1) ^ 0xA001u) : (uint16_t)(crc >> 1);
    }
    return crc;
}

static int crc_ok(const uint8_t *f, size_t n_before_crc)
{
    uint16_t c = rcd_crc16_modbus(f, n_before_crc);
    return f[n_before_crc] == (uint8_t)(c & 0xFFu) && f[n_before_crc + 1] == (uint8_t)(c >> 8);
}

static void order_bytes(uint8_t abcd[4], const uint8_t r[4], rcd_word_order wo)
{
    static const uint8_t map[4][4] = {{0, 1, 2, 3}, {2, 3, 0, 1}, {1, 0, 3, 2}, {3, 2, 1, 0}};
    unsigned o = (unsigned)wo < 4 ? (unsigned)wo : 0;
    for (int i = 0; i < 4; ++i)
        abcd[i] = r[map[o][i]]; /* map is its own inverse for all four orders */
}

static rc_status decode_value(rcd_reading *out, const uint8_t r[4], const rcd_proto_config *cfg)
{
    uint8_t b[4];
    uint32_t u;
    double v;
    order_bytes(b, r, cfg->mb_order);
    u = (uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | (uint32_t)b[3];
    if (cfg->mb_format == RCD_MB_FLOAT32) {
        float f;
        if (((u >> 23) & 0xFFu) == 0xFFu)
            return RC_ERR_FORMAT; /* NaN or infinity: never a value */
        memcpy(&f, &u, sizeof f);
        v = (double)f;
    } else {
        v = u >= 0x80000000u ? (double)u - 4294967296.0 : (double)u;
        v /= pow10_u(cfg->mb_decimals);
    }
    if (out) {
        out->len_mm = v;
        out->decimals = -1;
        out->unit = RCD_UNIT_MM;
        out->exception = 0;
        out->reject = RCD_REJECT_NONE;
        out->mb_addr = 0;
        out->mb_fn = 0;
    }
    return RC_OK;
}

/* Length of a complete, CRC-valid Modbus reply at f that is not for us:
 * another slave address (fn 0x03 response or any exception), or our address
 * with another function (a 4-byte response of fn 0x04, or an exception
 * other than 0x83); 0 otherwise. */
static size_t foreign_frame(const uint8_t *f, size_t left, uint8_t addr)
{
    if (left < RCD_MODBUS_EXC_LEN || f[0] == 0 || f[0] > 247)
        return 0;
    if (f[0] != addr) {
        if (f[1] == 0x03 && left >= RCD_MODBUS_RESP_LEN && f[2] == 4 && crc_ok(f, 7))
            return RCD_MODBUS_RESP_LEN;
        if ((f[1] & 0x80u) && crc_ok(f, 3))
            return RCD_MODBUS_EXC_LEN;
        return 0;
    }
    if (f[1] == 0x04 && left >= RCD_MODBUS_RESP_LEN && f[2] == 4 && crc_ok(f, 7))
        return RCD_MODBUS_RESP_LEN;
    if ((f[1] & 0x80u) && f[1] != 0x83 && crc_ok(f, 3))
        return RCD_MODBUS_EXC_LEN;
    return 0;
}

rc_status rcd_parse_modbus(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                           const uint8_t *buf, size_t len)
{
    size_t first_inc = NONE_POS, first_bad = NONE_POS;
    uint8_t addr;
    if (!consumed || !cfg || (!buf && len))
        return RC_ERR_ARG;
    *consumed = 0;
    addr = cfg->mb_addr ? cfg->mb_addr : 1;
    for (size_t p = 0; p < len; ++p) {
        size_t left = len - p;
        size_t flen = foreign_frame(buf + p, left, addr);
        if (flen) {
            if (out) {
                out->len_mm = 0.0;
                out->decimals = -1;
                out->unit = RCD_UNIT_NONE;
                out->exception = 0;
                out->reject = (uint8_t)(buf[p] != addr ? RCD_REJECT_MB_SLAVE : RCD_REJECT_MB_FUNCTION);
                out->mb_addr = buf[p];
                out->mb_fn = buf[p + 1];
            }
            *consumed = p + flen;
            return RC_ERR_FORMAT;
        }
        if (buf[p] != addr)
            continue;
        if (left < 2) {
            if (first_inc == NONE_POS)
                first_inc = p;
            continue;
        }
        if (buf[p + 1] == 0x03) {
            if (left < 3) {
                if (first_inc == NONE_POS)
                    first_inc = p;
                continue;
            }
            if (buf[p + 2] != 4)
                continue;
            if (left < RCD_MODBUS_RESP_LEN) {
                if (first_inc == NONE_POS)
                    first_inc = p;
                continue;
            }
            if (crc_ok(buf + p, 7)) {
                rc_status st = decode_value(out, buf + p + 3, cfg);
                *consumed = p + RCD_MODBUS_RESP_LEN;
                return st;
            }
            if (first_bad == NONE_POS)
                first_bad = p;
        } else if (buf[p + 1] == 0x83) {
            if (left < RCD_MODBUS_EXC_LEN) {
                if (first_inc == NONE_POS)
                    first_inc = p;
                continue;
            }
            if (crc_ok(buf + p, 3)) {
                if (out) {
                    out->len_mm = 0.0;
                    out->decimals = -1;
                    out->unit = RCD_UNIT_NONE;
                    out->exception = buf[p + 2];
                    out->reject = RCD_REJECT_NONE;
                    out->mb_addr = 0;
                    out->mb_fn = 0;
                }
                *consumed = p + RCD_MODBUS_EXC_LEN;
                return RC_ERR_DEVICE;
            }
            if (first_bad == NONE_POS)
                first_bad = p;
        }
    }
    if (first_bad != NONE_POS && (first_inc == NONE_POS || first_bad < first_inc)) {
        *consumed = first_bad + 1;
        return RC_ERR_CHECKSUM;
    }
    *consumed = first_inc != NONE_POS ? first_inc : len;
    return RC_ERR_INCOMPLETE;
}

rc_status rcd_parse(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                    const uint8_t *buf, size_t len)
{
    if (!cfg)
        return RC_ERR_ARG;
    switch (cfg->protocol) {
    case RCD_PROTO_ASCII:
    case RCD_PROTO_ASCII_POLL:
        return rcd_parse_ascii(out, consumed, buf, len);
    case RCD_PROTO_STX:
        return rcd_parse_stx(out, consumed, buf, len);
    case RCD_PROTO_MODBUS:
        return rcd_parse_modbus(out, consumed, cfg, buf, len);
    default:
        return RC_ERR_ARG;
    }
}

rc_status rcd_build_request(uint8_t *buf, size_t *n, size_t cap, const rcd_proto_config *cfg)
{
    if (!buf || !n || !cfg)
        return RC_ERR_ARG;
    *n = 0;
    switch (cfg->protocol) {
    case RCD_PROTO_ASCII:
        return RC_OK;
    case RCD_PROTO_ASCII_POLL:
    case RCD_PROTO_STX: {
        const char *cmd = cfg->poll_cmd[0] ? cfg->poll_cmd : "R\r";
        size_t l = 0; /* strnlen is POSIX, not C99 */
        while (l < sizeof cfg->poll_cmd && cmd[l] != '\0')
            ++l;
        if (l > cap)
            return RC_ERR_CAPACITY;
        memcpy(buf, cmd, l);
        *n = l;
        return RC_OK;
    }
    case RCD_PROTO_MODBUS: {
        uint16_t c;
        if (cap < RCD_MODBUS_REQ_LEN)
            return RC_ERR_CAPACITY;
        buf[0] = cfg->mb_addr ? cfg->mb_addr : 1;
        buf[1] = 0x03;
        buf[2] = (uint8_t)(cfg->mb_reg >> 8);
        buf[3] = (uint8_t)(cfg->mb_reg & 0xFFu);
        buf[4] = 0;
        buf[5] = 2;
        c = rcd_crc16_modbus(buf, 6);
        buf[6] = (uint8_t)(c & 0xFFu);
        buf[7] = (uint8_t)(c >> 8);
        *n = RCD_MODBUS_REQ_LEN;
        return RC_OK;
    }
    default:
        return RC_ERR_ARG;
    }
}

/* ---- encoders ----------------------------------------------------------- */

static const char *unit_text(rcd_unit u)
{
    switch (u) {
    case RCD_UNIT_MM: return "MM";
    case RCD_UNIT_CM: return "CM";
    case RCD_UNIT_M: return "M";
    case RCD_UNIT_IN: return "IN";
    case RCD_UNIT_NONE:
    default: return "";
    }
}

rc_status rcd_format_value(uint8_t *buf, size_t *n, size_t cap, double len_mm, rcd_ascii_style style,
                           rcd_unit unit, unsigned decimals)
{
    uint8_t tmp[40];
    size_t k = 0, nint;
    double v, scaled;
    uint64_t r, ip, fp, div;
    int neg;
    char digits[24];
    size_t nd = 0;
    if (!buf || !n || decimals > 6)
        return RC_ERR_ARG;
    *n = 0;
    v = len_mm / rcd_unit_mm(unit);
    if (!(v == v) || v > 1e12 || v < -1e12)
        return RC_ERR_RANGE;
    neg = v < 0;
    scaled = (neg ? -v : v) * pow10_u(decimals) + 0.5;
    r = (uint64_t)scaled;
    div = (uint64_t)pow10_u(decimals);
    ip = r / div;
    fp = r % div;
    if (r == 0)
        neg = 0;
    do {
        digits[nd++] = (char)('0' + ip % 10u);
        ip /= 10u;
    } while (ip && nd < sizeof digits);
    tmp[k++] = neg ? '-' : '+';
    nint = nd < 4 ? 4 : nd;
    for (size_t i = nint; i > nd; --i)
        tmp[k++] = style == RCD_STYLE_SPACE_UNIT ? ' ' : '0';
    while (nd)
        tmp[k++] = (uint8_t)digits[--nd];
    if (decimals) {
        tmp[k++] = '.';
        for (unsigned d = decimals; d > 0; --d) {
            uint64_t p = (uint64_t)pow10_u(d - 1);
            tmp[k++] = (uint8_t)('0' + (fp / p) % 10u);
        }
    }
    if (style == RCD_STYLE_SPACE_UNIT && unit != RCD_UNIT_NONE) {
        const char *u = unit_text(unit);
        tmp[k++] = ',';
        tmp[k++] = ' ';
        while (*u)
            tmp[k++] = (uint8_t)*u++;
    }
    if (k > cap)
        return RC_ERR_CAPACITY;
    memcpy(buf, tmp, k);
    *n = k;
    return RC_OK;
}

rc_status rcd_encode_ascii(uint8_t *buf, size_t *n, size_t cap, double len_mm, rcd_ascii_style style,
                           rcd_unit unit, unsigned decimals)
{
    rc_status st;
    if (!buf || !n)
        return RC_ERR_ARG;
    st = rcd_format_value(buf, n, cap, len_mm, style, unit, decimals);
    if (st != RC_OK)
        return st;
    if (*n + 2 > cap)
        return RC_ERR_CAPACITY;
    buf[(*n)++] = '\r';
    buf[(*n)++] = '\n';
    return RC_OK;
}

rc_status rcd_encode_stx(uint8_t *buf, size_t *n, size_t cap, double len_mm, unsigned decimals)
{
    size_t m;
    rc_status st;
    if (!buf || !n || cap < 4)
        return RC_ERR_ARG;
    *n = 0;
    buf[0] = RCD_STX;
    st = rcd_format_value(buf + 1, &m, cap - 3, len_mm, RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, decimals);
    if (st != RC_OK)
        return st;
    buf[1 + m] = RCD_ETX;
    buf[2 + m] = (uint8_t)(rcd_xor8(buf + 1, m) ^ RCD_ETX);
    *n = m + 3;
    return RC_OK;
}

rc_status rcd_encode_modbus(uint8_t *buf, size_t *n, size_t cap, double len_mm,
                            const rcd_proto_config *cfg)
{
    uint8_t b[4];
    uint32_t u;
    uint16_t c;
    if (!buf || !n || !cfg)
        return RC_ERR_ARG;
    *n = 0;
    if (cap < RCD_MODBUS_RESP_LEN)
        return RC_ERR_CAPACITY;
    if (cfg->mb_format == RCD_MB_FLOAT32) {
        float f = (float)len_mm;
        memcpy(&u, &f, sizeof u);
    } else {
        double s = len_mm * pow10_u(cfg->mb_decimals);
        double rr = s < 0 ? s - 0.5 : s + 0.5;
        int64_t i64;
        if (!(rr > -2147483648.5 && rr < 2147483647.5))
            return RC_ERR_RANGE;
        i64 = (int64_t)rr;
        u = (uint32_t)(i64 & 0xFFFFFFFF);
    }
    b[0] = (uint8_t)(u >> 24);
    b[1] = (uint8_t)(u >> 16);
    b[2] = (uint8_t)(u >> 8);
    b[3] = (uint8_t)u;
    buf[0] = cfg->mb_addr ? cfg->mb_addr : 1;
    buf[1] = 0x03;
    buf[2] = 4;
    order_bytes(buf + 3, b, cfg->mb_order);
    c = rcd_crc16_modbus(buf, 7);
    buf[7] = (uint8_t)(c & 0xFFu);
    buf[8] = (uint8_t)(c >> 8);
    *n = RCD_MODBUS_RESP_LEN;
    return RC_OK;
}

rc_status rcd_encode_modbus_exception(uint8_t *buf, size_t *n, size_t cap, uint8_t addr, uint8_t code)
{
    uint16_t c;
    if (!buf || !n)
        return RC_ERR_ARG;
    *n = 0;
    if (cap < RCD_MODBUS_EXC_LEN)
        return RC_ERR_CAPACITY;
    buf[0] = addr;
    buf[1] = 0x83;
    buf[2] = code;
    c = rcd_crc16_modbus(buf, 3);
    buf[3] = (uint8_t)(c & 0xFFu);
    buf[4] = (uint8_t)(c >> 8);
    *n = RCD_MODBUS_EXC_LEN;
    return RC_OK;
}

rc_status rcd_parse_modbus_request(uint16_t *reg, uint16_t *count, size_t *consumed, uint8_t addr,
                                   const uint8_t *buf, size_t len)
{
    size_t first_inc = NONE_POS, first_bad = NONE_POS;
    if (!consumed || (!buf && len))
        return RC_ERR_ARG;
    *consumed = 0;
    for (size_t p = 0; p < len; ++p) {
        size_t left = len - p;
        if (buf[p] != addr)
            continue;
        if (left < 2 || (buf[p + 1] == 0x03 && left < RCD_MODBUS_REQ_LEN)) {
            if (first_inc == NONE_POS)
                first_inc = p;
            continue;
        }
        if (buf[p + 1] != 0x03)
            continue;
        if (crc_ok(buf + p, 6)) {
            if (reg)
                *reg = (uint16_t)(buf[p + 2] << 8 | buf[p + 3]);
            if (count)
                *count = (uint16_t)(buf[p + 4] << 8 | buf[p + 5]);
            *consumed = p + RCD_MODBUS_REQ_LEN;
            return RC_OK;
        }
        if (first_bad == NONE_POS)
            first_bad = p;
    }
    if (first_bad != NONE_POS && (first_inc == NONE_POS || first_bad < first_inc)) {
        *consumed = first_bad + 1;
        return RC_ERR_CHECKSUM;
    }
    *consumed = first_inc != NONE_POS ? first_inc : len;
    return RC_ERR_INCOMPLETE;
}

/* ---- names ---------------------------------------------------------------- */

static int streq_ci(const char *a, const char *b)
{
    while (*a && *b && upc((uint8_t)*a) == upc((uint8_t)*b))
        ++a, ++b;
    return *a == '\0' && *b == '\0';
}

static const char *const proto_names[] = {"ascii", "ascii-poll", "stx", "modbus"};

const char *rcd_protocol_name(rcd_protocol p)
{
    return (unsigned)p < 4 ? proto_names[p] : "?";
}

rc_status rcd_protocol_from_name(rcd_protocol *p, const char *name)
{
    if (!p || !name)
        return RC_ERR_ARG;
    for (unsigned i = 0; i < 4; ++i)
        if (streq_ci(name, proto_names[i])) {
            *p = (rcd_protocol)i;
            return RC_OK;
        }
    return RC_ERR_ARG;
}

rc_status rcd_word_order_from_name(rcd_word_order *wo, const char *name)
{
    static const char *const n[] = {"abcd", "cdab", "badc", "dcba"};
    if (!wo || !name)
        return RC_ERR_ARG;
    for (unsigned i = 0; i < 4; ++i)
        if (streq_ci(name, n[i])) {
            *wo = (rcd_word_order)i;
            return RC_OK;
        }
    return RC_ERR_ARG;
}

rc_status rcd_unit_from_name(rcd_unit *u, const char *name)
{
    static const char *const n[] = {"none", "mm", "cm", "m", "in"};
    if (!u || !name)
        return RC_ERR_ARG;
    for (unsigned i = 0; i < 5; ++i)
        if (streq_ci(name, n[i])) {
            *u = (rcd_unit)i;
            return RC_OK;
        }
    return RC_ERR_ARG;
}
