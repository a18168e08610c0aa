/* SPDX-License-Identifier: MIT */
/* rcd_display.h - reading lengths from a cable-encoder display over a port.
 *
 * What: joins a port (rcd_port.h) and a protocol (rcd_proto.h). Each
 * rcd_display_read returns the next event of the display: a reading, a
 * rejected frame, a device error, a timeout or a hang-up. Polled protocols
 * (ASCII_POLL, STX, MODBUS) send a request first (stale input is flushed
 * before, so a late answer to an earlier request is not taken for this one)
 * and again after every frame event; ASCII streaming only listens.
 *
 * Format lock (ASCII, ASCII_POLL, STX): a reading is returned only once
 * RCD_DISPLAY_LOCK_COUNT consecutive frames showed the same number of
 * decimals and unit, and only while it keeps that shape; others are
 * rejected (RC_ERR_FORMAT, stats.shape_rejects). A byte dropped from or added
 * to a line changes its shape, so it is never returned as a value.
 *
 * Depends on: rcd_port.h, rcd_proto.h. Time comes from the port's clock
 * (rcd_port_now_ms): no OS call here, so it builds for a microcontroller.
 * Memory: rcd_display is caller-owned (a 512-byte receive buffer inside);
 * the port is borrowed and must outlive it.
 * Thread safety: one display per thread.
 * Errors (rcd_display_read):
 *   RC_OK              *out holds a reading (mm).
 *   RC_ERR_FORMAT      a malformed or wrong-shape frame was dropped.
 *   RC_ERR_CHECKSUM    a frame failed its BCC/CRC and was dropped.
 *   RC_ERR_DEVICE      Modbus exception (out->exception has the code).
 *   RC_ERR_TIMEOUT     no complete frame within timeout_ms.
 *   RC_ERR_CLOSED, RC_ERR_IO from the port (rcd_port_last_error tells more).
 * Every error but CLOSED/IO leaves the display usable: call again.
 */
#ifndef RCD_DISPLAY_H
#define RCD_DISPLAY_H

#include "rcd_port.h"
#include "rcd_proto.h"

#define RCD_DISPLAY_BUF 512
#define RCD_DISPLAY_LOCK_COUNT 3

typedef struct rcd_display_stats {
    unsigned long readings;       /* returned with RC_OK */
    unsigned long bad_frames;     /* format or checksum failures */
    unsigned long shape_rejects;  /* well-formed but another decimals/unit */
    unsigned long device_errors;  /* Modbus exceptions */
    unsigned long timeouts;
    unsigned long polls;          /* requests sent */
    unsigned long bytes;          /* bytes received */
    unsigned long wrong_slave;    /* Modbus replies from another slave address */
    unsigned long wrong_function; /* Modbus replies with another function code */
} rcd_display_stats;

typedef struct rcd_display {
    rcd_port *port;                 /* borrowed */
    rcd_proto_config cfg;
    uint8_t buf[RCD_DISPLAY_BUF];   /* (len) received, not yet parsed */
    size_t len;
    int need_poll;
    int8_t lock_decimals;           /* -2: not locked */
    uint8_t lock_unit;
    int8_t cand_decimals;           /* candidate shape while locking */
    uint8_t cand_unit;
    unsigned cand_count;
    rcd_display_stats stats;
    uint8_t last_reject;            /* rcd_reject of the last rejected frame */
    uint8_t last_mb_addr, last_mb_fn;
} rcd_display;

/* Bind a display to an open port. cfg NULL: ASCII streaming. */
rc_status rcd_display_init(rcd_display *d, rcd_port *port, const rcd_proto_config *cfg);
/* Next event within timeout_ms (see the file comment). out may be NULL. */
rc_status rcd_display_read(rcd_display *d, rcd_reading *out, unsigned timeout_ms);
/* Why nothing usable arrived, as a static text to append to a timeout
 * message ("" when there is no known reason): replies from another Modbus
 * slave or with another function code were seen and ignored. */
const char *rcd_display_why_silent(const rcd_display *d);
/* Drop buffered bytes and pending poll state (after a reconnect). The format
 * lock is kept: the display's format does not change with the cable. */
void rcd_display_reset(rcd_display *d);

#endif /* RCD_DISPLAY_H */
