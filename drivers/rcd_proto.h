/* SPDX-License-Identifier: MIT */
/* rcd_proto.h - wire protocols of cable-encoder displays: parsers and encoders.
 *
 * What: pure functions over byte buffers. A parser looks at buf[0..len) only
 * (never past it), finds the first frame, and says how many leading bytes
 * the caller may drop (*consumed) whatever the outcome:
 *   RC_OK             a valid frame; *out filled; consumed = through its end.
 *   RC_ERR_INCOMPLETE no complete frame yet; consumed = garbage before the
 *                     earliest place a frame may start (drop it, read more).
 *   RC_ERR_FORMAT     a frame-shaped run was malformed; consumed = through it.
 *   RC_ERR_CHECKSUM   a frame failed its XOR/CRC check; consumed = through it
 *                     (STX) or its first byte (Modbus, which has no delimiter).
 *   RC_ERR_DEVICE     a Modbus exception response (out->exception holds the
 *                     code); consumed = through it.
 * Calling again on buf + consumed resynchronises after any garbage. consumed
 * is >= 1 for every result but RC_OK/RC_ERR_INCOMPLETE, so a loop always
 * progresses; for RC_OK it is the frame's end.
 *
 * Frame formats
 * 1. ASCII streaming (RCD_PROTO_ASCII): the display sends one reading per
 *    line, unprompted:
 *        [spaces] [sign: '+' | '-' | ' '] [spaces] digits ['.' digits]
 *        [spaces] [',' [spaces]] [unit] [spaces] terminator
 *    e.g. "+0509.19\r\n", "+ 509.190, MM\r\n", "-12.5 cm\n". At least one
 *    digit, at most one point, at most 15 significant digits. unit
 *    (case-insensitive): MM, CM, M, IN; none means mm. Terminator: CR, LF or
 *    CR LF (a CR alone ends the line; the LF after it is then an empty line,
 *    skipped silently). A line longer than RCD_ASCII_MAX_LINE bytes without a
 *    terminator is dropped as RC_ERR_FORMAT. ASCII has no integrity check: the
 *    reader (rcd_display.h) locks the number of decimals and the unit of the
 *    first good line, which rejects a dropped or inserted digit, point or
 *    unit letter; a changed digit is only caught by the stability rule of
 *    `rcal acquire` (N consecutive readings within a tolerance).
 * 2. ASCII polled (RCD_PROTO_ASCII_POLL): the host sends a command (default
 *    "R\r", configurable), the display answers one line as in 1.
 * 3. STX/ETX (RCD_PROTO_STX), polled with the same command as 2, or streamed:
 *        0x02  payload  0x03  BCC
 *    payload = an ASCII reading as in 1 without terminator (1..RCD_STX_MAX_PAYLOAD
 *    bytes, no control bytes); BCC = XOR of every payload byte and the ETX.
 *    An STX inside a payload restarts the frame there.
 * 4. Modbus RTU (RCD_PROTO_MODBUS), function 0x03, two holding registers:
 *        request : addr 0x03 reg_hi reg_lo 0x00 0x02 crc_lo crc_hi   (8 bytes)
 *        response: addr 0x03 0x04 b0 b1 b2 b3 crc_lo crc_hi           (9 bytes)
 *        exception: addr 0x83 code crc_lo crc_hi                       (5 bytes)
 *    CRC-16/MODBUS: init 0xFFFF, reflected poly 0xA001, over every byte before
 *    the CRC, sent low byte first. b0..b3 hold a 32-bit value whose big-endian
 *    bytes A B C D arrive in the configured word order: ABCD (b0..b3 = A B C D),
 *    CDAB (word swap), BADC (byte swap in each word), DCBA (reversed). The
 *    value is either a signed int32 scaled by 10^-decimals mm, or an IEEE-754
 *    float in mm. A response is recognised by addr, 0x03, 0x04 and a good
 *    CRC; a CRC failure drops one byte and searches again (RTU has no
 *    delimiter), so an incomplete false start never hides a complete frame
 *    behind it. A CRC-valid reply from another slave address, or from this
 *    one with another function code (0x04 response, 0x84 exception, ...), is
 *    consumed and named (RC_ERR_FORMAT, out->reject, mb_addr, mb_fn) rather
 *    than silently skipped: a wrong --mb-addr or register type then says so
 *    instead of "no reading".
 *
 * Depends on: rc_status.h only; no heap, no stdio, no libm.
 * Memory: caller-owned buffers; nothing is kept between calls.
 * Thread safety: reentrant.
 */
#ifndef RCD_PROTO_H
#define RCD_PROTO_H

#include <stddef.h>
#include <stdint.h>

#include "rc_status.h"

#define RCD_ASCII_MAX_LINE 64
#define RCD_STX_MAX_PAYLOAD 32
#define RCD_STX 0x02u
#define RCD_ETX 0x03u
#define RCD_MODBUS_RESP_LEN 9u
#define RCD_MODBUS_REQ_LEN 8u
#define RCD_MODBUS_EXC_LEN 5u
#define RCD_MAX_FRAME 64 /* longest frame any encoder below writes */

typedef enum rcd_protocol {
    RCD_PROTO_ASCII = 0,      /* streaming lines */
    RCD_PROTO_ASCII_POLL = 1, /* command, one reply line */
    RCD_PROTO_STX = 2,        /* STX payload ETX BCC, polled */
    RCD_PROTO_MODBUS = 3      /* Modbus RTU fn 0x03 */
} rcd_protocol;

typedef enum rcd_unit {
    RCD_UNIT_NONE = 0, /* no unit given: mm */
    RCD_UNIT_MM = 1,
    RCD_UNIT_CM = 2,
    RCD_UNIT_M = 3,
    RCD_UNIT_IN = 4
} rcd_unit;

typedef enum rcd_word_order {
    RCD_WO_ABCD = 0,
    RCD_WO_CDAB = 1,
    RCD_WO_BADC = 2,
    RCD_WO_DCBA = 3
} rcd_word_order;

typedef enum rcd_mb_format {
    RCD_MB_INT32 = 0,  /* signed, value_mm = raw * 10^-decimals */
    RCD_MB_FLOAT32 = 1 /* IEEE-754 single, mm */
} rcd_mb_format;

/* Protocol settings. All-zero: ASCII streaming; poll command "R\r"; Modbus
 * slave 1, register 0, int32 ABCD with 0 decimals (set what your display
 * documents). */
typedef struct rcd_proto_config {
    rcd_protocol protocol;
    char poll_cmd[16];          /* NUL-terminated; "" means "R\r" */
    uint8_t mb_addr;            /* slave address 1..247, 0: 1 */
    uint16_t mb_reg;            /* first holding register */
    rcd_mb_format mb_format;
    rcd_word_order mb_order;
    uint8_t mb_decimals;        /* int32: digits after the point, 0..9 */
} rcd_proto_config;

/* Why a well-formed frame was not taken (RC_ERR_FORMAT). */
typedef enum rcd_reject {
    RCD_REJECT_NONE = 0,
    RCD_REJECT_MB_SLAVE = 1,   /* a valid Modbus reply from another slave address (mb_addr) */
    RCD_REJECT_MB_FUNCTION = 2 /* a valid Modbus reply with another function code (mb_fn) */
} rcd_reject;

/* One parsed reading. */
typedef struct rcd_reading {
    double len_mm;     /* converted to mm */
    int8_t decimals;   /* ASCII/STX: digits after the point; Modbus: -1 */
    uint8_t unit;      /* rcd_unit as written */
    uint8_t exception; /* Modbus exception code when RC_ERR_DEVICE */
    uint8_t reject;    /* rcd_reject, with RC_ERR_FORMAT */
    uint8_t mb_addr;   /* RCD_REJECT_MB_*: the frame's slave address */
    uint8_t mb_fn;     /* RCD_REJECT_MB_*: the frame's function code */
} rcd_reading;

/* Parsers: see the file comment for the contract. out may be NULL. */
rc_status rcd_parse_ascii(rcd_reading *out, size_t *consumed, const uint8_t *buf, size_t len);
rc_status rcd_parse_stx(rcd_reading *out, size_t *consumed, const uint8_t *buf, size_t len);
rc_status rcd_parse_modbus(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                           const uint8_t *buf, size_t len);
/* Dispatch on cfg->protocol (ASCII and ASCII_POLL share the line parser). */
rc_status rcd_parse(rcd_reading *out, size_t *consumed, const rcd_proto_config *cfg,
                    const uint8_t *buf, size_t len);

/* Parse the text of one reading (no terminator): the grammar of format 1.
 * text: (len). RC_ERR_FORMAT when it is not exactly one reading. */
rc_status rcd_parse_value(rcd_reading *out, const uint8_t *text, size_t len);

/* CRC-16/MODBUS of data (len). */
uint16_t rcd_crc16_modbus(const uint8_t *data, size_t len);
/* XOR of data (len). */
uint8_t rcd_xor8(const uint8_t *data, size_t len);

/* The request the host sends for one reading (ASCII_POLL, STX: poll command;
 * Modbus: the 8-byte fn 0x03 request; ASCII streaming: nothing, *n = 0).
 * buf: (cap). RC_ERR_CAPACITY when cap is too small. */
rc_status rcd_build_request(uint8_t *buf, size_t *n, size_t cap, const rcd_proto_config *cfg);

/* ---- Encoders: what a display sends (simulated display, tests). -------- */

/* ASCII text styles of a reading. */
typedef enum rcd_ascii_style {
    RCD_STYLE_ZERO_PAD = 0, /* "+0509.19"    sign, 4 integer digits zero padded */
    RCD_STYLE_SPACE_UNIT = 1 /* "+ 509.190, MM" sign, space padded, unit */
} rcd_ascii_style;

/* Text of a reading in unit (len_mm converted), decimals 0..6, no
 * terminator. buf: (cap). RC_ERR_RANGE when it does not fit the style. */
rc_status rcd_format_value(uint8_t *buf, size_t *n, size_t cap, double len_mm, rcd_ascii_style style,
                           rcd_unit unit, unsigned decimals);
/* Complete frames for a value: ASCII line with CR LF, STX frame, Modbus
 * response (cfg: address, format, word order, decimals). buf: (cap). */
rc_status rcd_encode_ascii(uint8_t *buf, size_t *n, size_t cap, double len_mm, rcd_ascii_style style,
                           rcd_unit unit, unsigned decimals);
rc_status rcd_encode_stx(uint8_t *buf, size_t *n, size_t cap, double len_mm, unsigned decimals);
rc_status rcd_encode_modbus(uint8_t *buf, size_t *n, size_t cap, double len_mm,
                            const rcd_proto_config *cfg);
/* Modbus exception response with code. buf: (cap >= 5). */
rc_status rcd_encode_modbus_exception(uint8_t *buf, size_t *n, size_t cap, uint8_t addr, uint8_t code);
/* Device side: find a fn 0x03 request for addr in buf (len), with the same
 * consumed contract as the parsers; *reg and *count receive its fields. */
rc_status rcd_parse_modbus_request(uint16_t *reg, uint16_t *count, size_t *consumed, uint8_t addr,
                                   const uint8_t *buf, size_t len);

/* Names for command lines: "ascii", "ascii-poll", "stx", "modbus";
 * "mm"...; "abcd"... Parse returns RC_ERR_ARG for an unknown name. */
const char *rcd_protocol_name(rcd_protocol p);
rc_status rcd_protocol_from_name(rcd_protocol *p, const char *name);
rc_status rcd_word_order_from_name(rcd_word_order *wo, const char *name);
rc_status rcd_unit_from_name(rcd_unit *u, const char *name);
/* mm per unit (none and MM: 1). */
double rcd_unit_mm(rcd_unit u);

#endif /* RCD_PROTO_H */
