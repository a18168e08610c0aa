/* SPDX-License-Identifier: MIT */
/* rcd_port.h - byte-stream port interface for the cable-encoder display.
 *
 * What: a small `const` table of function pointers (open, close, read with a
 * timeout, write, flush, drain, last error text) plus a `void *ctx`, so that
 * the display reader (rcd_display.h) and `rcal acquire` run unchanged over
 *   - libserialport (real RS-232/RS-485 adapters):   rcd_serialport_*
 *   - a POSIX file descriptor with termios (ptys):    rcd_posix_*
 *   - a scripted mock with fault injection (tests):   rcd_mock_*
 * Only rcd_serialport.c includes libserialport.h.
 *
 * Depends on: rc_status.h; libserialport (serialport backend only); POSIX
 * (posix backend only).
 * Memory: every context is a caller-owned struct; no backend allocates except
 * libserialport itself, whose objects the serialport backend frees on every
 * path (failed open included). The mock never copies its script: the caller
 * keeps rx/tx buffers alive while the port is used.
 * Thread safety: one port per thread; backends keep no global state.
 * Errors: rc_status. RC_ERR_ARG contract misuse, RC_ERR_IO OS/device failure
 * (the OS message is kept: rcd_port_last_error), RC_ERR_TIMEOUT nothing within
 * timeout_ms, RC_ERR_CLOSED the peer hung up / device vanished,
 * RC_ERR_UNSUPPORTED a setting the backend cannot do. Byte counts are returned
 * through out-parameters (n_read, n_written), never inside the status.
 */
#ifndef RCD_PORT_H
#define RCD_PORT_H

#include <stddef.h>
#include <stdint.h>

#include "rc_status.h"

typedef enum rcd_parity {
    RCD_PARITY_NONE = 0, /* default */
    RCD_PARITY_ODD = 1,
    RCD_PARITY_EVEN = 2,
    RCD_PARITY_MARK = 3,
    RCD_PARITY_SPACE = 4
} rcd_parity;

typedef enum rcd_flow {
    RCD_FLOW_NONE = 0, /* default */
    RCD_FLOW_XONXOFF = 1,
    RCD_FLOW_RTSCTS = 2,
    RCD_FLOW_DTRDSR = 3
} rcd_flow;

/* Line settings. All-zero means the default 9600 baud 8N1, no flow control. */
typedef struct rcd_serial_config {
    unsigned baud;      /* bits per second, 0: 9600 */
    unsigned data_bits; /* 5..8, 0: 8 */
    rcd_parity parity;
    unsigned stop_bits; /* 1 or 2, 0: 1 */
    rcd_flow flow;
} rcd_serial_config;

/* The config with defaults filled in; RC_ERR_ARG for out-of-range fields. */
rc_status rcd_serial_config_resolve(rcd_serial_config *out, const rcd_serial_config *in);

/* Backend operations. Every function receives the backend's ctx.
 *  open:  path is the device ("/dev/ttyUSB0", "/dev/pts/3"); cfg may be NULL
 *         (defaults).
 *  read:  waits until at least one byte is available or timeout_ms elapsed
 *         (0: do not wait), then returns what is there, at most cap bytes.
 *         RC_OK with *n_read >= 1, RC_ERR_TIMEOUT with *n_read == 0,
 *         RC_ERR_CLOSED when the peer hung up.
 *  write: writes all len bytes unless timeout_ms elapses (RC_ERR_TIMEOUT,
 *         *n_written tells how many went out).
 *  flush: discards pending input and output.
 *  drain: waits until pending output has been transmitted.
 *  last_error: static or ctx-owned text of the last OS/device error ("" if
 *         none); never NULL.
 *  now_ms: a monotonic millisecond clock (any origin). The display reader
 *         and the acquisition take their time from here and nowhere else, so
 *         the reading path runs wherever a backend can supply a clock (a
 *         microcontroller's tick counter). 32 bits: it wraps after 49.7 days;
 *         callers take differences modulo 2^32. */
typedef struct rcd_port_ops {
    const char *name;
    rc_status (*open)(void *ctx, const char *path, const rcd_serial_config *cfg);
    rc_status (*close)(void *ctx);
    rc_status (*read)(void *ctx, size_t *n_read, uint8_t *buf, size_t cap, unsigned timeout_ms);
    rc_status (*write)(void *ctx, size_t *n_written, const uint8_t *buf, size_t len,
                       unsigned timeout_ms);
    rc_status (*flush)(void *ctx);
    rc_status (*drain)(void *ctx);
    const char *(*last_error)(void *ctx);
    uint32_t (*now_ms)(void *ctx);
} rcd_port_ops;

typedef struct rcd_port {
    const rcd_port_ops *ops;
    void *ctx;
} rcd_port;

/* Thin dispatchers (check arguments, zero the out-counts, call the backend). */
rc_status rcd_port_open(rcd_port *p, const char *path, const rcd_serial_config *cfg);
rc_status rcd_port_close(rcd_port *p);
rc_status rcd_port_read(rcd_port *p, size_t *n_read, uint8_t *buf, size_t cap, unsigned timeout_ms);
rc_status rcd_port_write(rcd_port *p, size_t *n_written, const uint8_t *buf, size_t len,
                         unsigned timeout_ms);
rc_status rcd_port_flush(rcd_port *p);
rc_status rcd_port_drain(rcd_port *p);
const char *rcd_port_last_error(const rcd_port *p);
/* The backend's clock (0 when the port has none: a contract violation). */
uint32_t rcd_port_now_ms(const rcd_port *p);

/* ---- libserialport backend (rcd_serialport.c) ---------------------------
 * Opens by name through sp_get_port_by_name, configures baud/bits/parity/
 * stop/flow, reads with sp_blocking_read_next, writes with sp_blocking_write.
 * Linux ptys are refused by libserialport itself: use the POSIX backend. */
typedef struct rcd_serialport_ctx {
    void *port;     /* struct sp_port *, owned; NULL when closed */
    char err[256];  /* last error: "what: OS message" */
} rcd_serialport_ctx;

extern const rcd_port_ops rcd_serialport_ops;
/* Bind p to the backend with ctx (zeroed here). */
void rcd_serialport_init(rcd_port *p, rcd_serialport_ctx *ctx);

/* ---- POSIX fd backend (rcd_posix.c) --------------------------------------
 * open(2) O_RDWR|O_NOCTTY|O_NONBLOCK, termios raw mode with the line settings
 * (on a pty the baud rate is recorded but has no effect), poll(2) timeouts.
 * rcd_posix_attach wraps an already open fd (not closed by close unless
 * owned). */
typedef struct rcd_posix_ctx {
    int fd;         /* -1 when closed */
    int owned;      /* close(2) the fd on rcd_port_close */
    int is_tty;     /* read() == 0 means "no data yet" on a raw tty, EOF elsewhere */
    char err[256];
} rcd_posix_ctx;

extern const rcd_port_ops rcd_posix_ops;
void rcd_posix_init(rcd_port *p, rcd_posix_ctx *ctx);
/* Use an open fd (set non-blocking here); owned: close it on port close. */
rc_status rcd_posix_attach(rcd_port *p, rcd_posix_ctx *ctx, int fd, int owned);
/* CLOCK_MONOTONIC in milliseconds, modulo 2^32: the clock of the POSIX and
 * libserialport backends (ctx unused). */
uint32_t rcd_posix_now_ms(void *ctx);

/* ---- mock backend (rcd_mock.c) -------------------------------------------
 * Reads deliver the scripted rx bytes; writes append to tx. Faults:
 *  - fail_rx_after / fail_tx_after: once that many bytes have passed, every
 *    further read / write returns fail_status (default RC_ERR_IO);
 *  - max_chunk: a read returns at most this many bytes (short reads);
 *  - timeout_every: every k-th read returns RC_ERR_TIMEOUT with no byte;
 *  - at the end of the script (or of the released segments) a read returns
 *    RC_ERR_TIMEOUT, or RC_ERR_CLOSED when closed_at_end is set.
 * flush only counts (scripted bytes are the device's future output).
 * Simulated time: the clock (now_ms) starts at clock_ms and advances only
 * when a read times out (by that read's timeout_ms), by ms_per_read at each
 * read that delivers bytes (a display's update period), or when a test moves
 * it; a timeout is reported at once. */
#define RCD_MOCK_NEVER ((size_t)-1)

typedef struct rcd_mock_ctx {
    /* script, set by the caller after rcd_mock_init */
    const uint8_t *rx; /* (rx_len) bytes the device "sends" */
    size_t rx_len;
    uint8_t *tx;       /* (tx_cap) capture of what the host sent; may be NULL */
    size_t tx_cap;
    /* faults */
    size_t fail_rx_after;  /* RCD_MOCK_NEVER: no failure */
    size_t fail_tx_after;  /* RCD_MOCK_NEVER: no failure */
    rc_status fail_status; /* 0 means RC_ERR_IO */
    size_t max_chunk;      /* 0: unlimited */
    unsigned timeout_every; /* 0: never */
    int closed_at_end;
    int fail_open;          /* open returns fail_status */
    uint32_t clock_ms;      /* the simulated clock (state; tests may set it) */
    uint32_t ms_per_read;   /* a read that delivers bytes advances the clock this much (0: not at all) */
    /* polled device: when n_segments > 0, the script is cut into segments
     * (segments: (n_segments) byte counts) and each write releases the next
     * one: a reply only after a request. */
    const size_t *segments;
    size_t n_segments;
    size_t released;        /* bytes released so far (state) */
    size_t seg_next;        /* next segment to release (state) */
    /* state, read by tests */
    size_t rx_pos;
    size_t tx_len;     /* bytes captured (<= tx_cap) */
    size_t tx_total;   /* bytes written, captured or not */
    unsigned n_reads, n_writes, n_flush, n_drain;
    int is_open;
} rcd_mock_ctx;

extern const rcd_port_ops rcd_mock_ops;
/* Zero ctx, set "no fault" defaults and bind p. */
void rcd_mock_init(rcd_port *p, rcd_mock_ctx *ctx);

#endif /* RCD_PORT_H */
