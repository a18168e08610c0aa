/* SPDX-License-Identifier: MIT */
/* test_drv_serialport.c - the libserialport backend with every sp_* call
 * substituted at link time (-Wl,--wrap): every failure point of open, every
 * sp_return of read/write/flush/drain/close, and no leaked port, config or
 * error message on any path. */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <libserialport.h>

#include "rcd_port.h"

/* ---- fakes ---------------------------------------------------------------- */

static int g_step, g_fail_at = -1, g_errno;
static enum sp_return g_fail_code = SP_ERR_FAIL;
static int g_ports, g_configs, g_msgs, g_open; /* live objects */
static int g_baud, g_bits, g_stop;
static enum sp_parity g_parity;
static enum sp_flowcontrol g_flow;
static int fake_port_storage, fake_conf_storage;

static enum sp_return step(void)
{
    return g_step++ == g_fail_at ? g_fail_code : SP_OK;
}

enum sp_return __wrap_sp_get_port_by_name(const char *portname, struct sp_port **port_ptr);
enum sp_return __wrap_sp_get_port_by_name(const char *portname, struct sp_port **port_ptr)
{
    enum sp_return r = step();
    (void)portname;
    *port_ptr = NULL;
    if (r != SP_OK)
        return r;
    *port_ptr = (struct sp_port *)(void *)&fake_port_storage;
    g_ports++;
    return SP_OK;
}
void __wrap_sp_free_port(struct sp_port *port);
void __wrap_sp_free_port(struct sp_port *port)
{
    assert_ptr_equal(port, &fake_port_storage);
    g_ports--;
}
enum sp_return __wrap_sp_open(struct sp_port *port, enum sp_mode flags);
enum sp_return __wrap_sp_open(struct sp_port *port, enum sp_mode flags)
{
    enum sp_return r = step();
    (void)port;
    assert_int_equal(flags, SP_MODE_READ_WRITE);
    if (r == SP_OK)
        g_open++;
    return r;
}
enum sp_return __wrap_sp_close(struct sp_port *port);
enum sp_return __wrap_sp_close(struct sp_port *port)
{
    (void)port;
    g_open--;
    return (enum sp_return)mock_type(int);
}
enum sp_return __wrap_sp_new_config(struct sp_port_config **config_ptr);
enum sp_return __wrap_sp_new_config(struct sp_port_config **config_ptr)
{
    enum sp_return r = step();
    *config_ptr = NULL;
    if (r != SP_OK)
        return r;
    *config_ptr = (struct sp_port_config *)(void *)&fake_conf_storage;
    g_configs++;
    return SP_OK;
}
void __wrap_sp_free_config(struct sp_port_config *config);
void __wrap_sp_free_config(struct sp_port_config *config)
{
    assert_ptr_equal(config, &fake_conf_storage);
    g_configs--;
}
enum sp_return __wrap_sp_set_config_baudrate(struct sp_port_config *c, int v);
enum sp_return __wrap_sp_set_config_baudrate(struct sp_port_config *c, int v)
{
    (void)c;
    g_baud = v;
    return step();
}
enum sp_return __wrap_sp_set_config_bits(struct sp_port_config *c, int v);
enum sp_return __wrap_sp_set_config_bits(struct sp_port_config *c, int v)
{
    (void)c;
    g_bits = v;
    return step();
}
enum sp_return __wrap_sp_set_config_parity(struct sp_port_config *c, enum sp_parity v);
enum sp_return __wrap_sp_set_config_parity(struct sp_port_config *c, enum sp_parity v)
{
    (void)c;
    g_parity = v;
    return step();
}
enum sp_return __wrap_sp_set_config_stopbits(struct sp_port_config *c, int v);
enum sp_return __wrap_sp_set_config_stopbits(struct sp_port_config *c, int v)
{
    (void)c;
    g_stop = v;
    return step();
}
enum sp_return __wrap_sp_set_config_flowcontrol(struct sp_port_config *c, enum sp_flowcontrol v);
enum sp_return __wrap_sp_set_config_flowcontrol(struct sp_port_config *c, enum sp_flowcontrol v)
{
    (void)c;
    g_flow = v;
    return step();
}
enum sp_return __wrap_sp_set_config(struct sp_port *port, const struct sp_port_config *config);
enum sp_return __wrap_sp_set_config(struct sp_port *port, const struct sp_port_config *config)
{
    (void)port;
    assert_ptr_equal(config, &fake_conf_storage);
    return step();
}
/* read/write/flush/drain: results queued with will_return */
enum sp_return __wrap_sp_blocking_read_next(struct sp_port *port, void *buf, size_t count,
                                            unsigned int timeout_ms);
enum sp_return __wrap_sp_blocking_read_next(struct sp_port *port, void *buf, size_t count,
                                            unsigned int timeout_ms)
{
    int r = mock_type(int);
    (void)port;
    check_expected(timeout_ms);
    if (r > 0)
        memset(buf, 'x', (size_t)r < count ? (size_t)r : count);
    return (enum sp_return)r;
}
enum sp_return __wrap_sp_nonblocking_read(struct sp_port *port, void *buf, size_t count);
enum sp_return __wrap_sp_nonblocking_read(struct sp_port *port, void *buf, size_t count)
{
    int r = mock_type(int);
    (void)port;
    if (r > 0)
        memset(buf, 'y', (size_t)r < count ? (size_t)r : count);
    return (enum sp_return)r;
}
enum sp_return __wrap_sp_blocking_write(struct sp_port *port, const void *buf, size_t count,
                                        unsigned int timeout_ms);
enum sp_return __wrap_sp_blocking_write(struct sp_port *port, const void *buf, size_t count,
                                        unsigned int timeout_ms)
{
    (void)port;
    (void)buf;
    (void)count;
    (void)timeout_ms;
    return (enum sp_return)mock_type(int);
}
enum sp_return __wrap_sp_flush(struct sp_port *port, enum sp_buffer buffers);
enum sp_return __wrap_sp_flush(struct sp_port *port, enum sp_buffer buffers)
{
    (void)port;
    assert_int_equal(buffers, SP_BUF_BOTH);
    return (enum sp_return)mock_type(int);
}
enum sp_return __wrap_sp_drain(struct sp_port *port);
enum sp_return __wrap_sp_drain(struct sp_port *port)
{
    (void)port;
    return (enum sp_return)mock_type(int);
}
char *__wrap_sp_last_error_message(void);
char *__wrap_sp_last_error_message(void)
{
    char *m = malloc(32);
    assert_non_null(m);
    strcpy(m, "Fake OS error");
    g_msgs++;
    return m;
}
void __wrap_sp_free_error_message(char *message);
void __wrap_sp_free_error_message(char *message)
{
    free(message);
    g_msgs--;
}
int __wrap_sp_last_error_code(void);
int __wrap_sp_last_error_code(void)
{
    return g_errno;
}

static int reset(void **state)
{
    (void)state;
    g_step = 0;
    g_fail_at = -1;
    g_fail_code = SP_ERR_FAIL;
    g_errno = 0;
    g_ports = g_configs = g_msgs = g_open = 0;
    return 0;
}

static void open_ok(rcd_port *p, rcd_serialport_ctx *c)
{
    rcd_serialport_init(p, c);
    g_step = 0;
    g_fail_at = -1;
    assert_int_equal(rcd_port_open(p, "/dev/ttyUSB0", NULL), RC_OK);
}

static void close_ok(rcd_port *p)
{
    will_return(__wrap_sp_close, SP_OK);
    assert_int_equal(rcd_port_close(p), RC_OK);
    assert_int_equal(g_ports, 0);
    assert_int_equal(g_open, 0);
}

/* ---- tests ---------------------------------------------------------------- */

/* Open fails at each of its 9 libserialport calls with each sp_return:
 * the right status, the step named in the message, nothing leaked. */
static void test_open_every_failure(void **state)
{
    static const char *const what[] = {"find port", "open", "new config", "set baud rate",
                                       "set data bits", "set parity", "set stop bits",
                                       "set flow control", "apply line settings"};
    static const struct {
        enum sp_return sp;
        rc_status rc;
    } codes[] = {{SP_ERR_FAIL, RC_ERR_IO}, {SP_ERR_ARG, RC_ERR_ARG}, {SP_ERR_MEM, RC_ERR_IO},
                 {SP_ERR_SUPP, RC_ERR_UNSUPPORTED}};
    (void)state;
    for (int at = 0; at < 9; ++at)
        for (size_t k = 0; k < 4; ++k) {
            rcd_port p;
            rcd_serialport_ctx c;
            reset(NULL);
            g_fail_at = at;
            g_fail_code = codes[k].sp;
            if (at >= 2)
                will_return(__wrap_sp_close, SP_OK); /* the opened port is closed again */
            rcd_serialport_init(&p, &c);
            assert_int_equal(rcd_port_open(&p, "/dev/ttyUSB0", NULL), codes[k].rc);
            assert_null(c.port);
            assert_int_equal(g_ports, 0);
            assert_int_equal(g_configs, 0);
            assert_int_equal(g_open, 0);
            assert_int_equal(g_msgs, 0);
            assert_non_null(strstr(rcd_port_last_error(&p), what[at]));
            if (codes[k].sp == SP_ERR_FAIL)
                assert_non_null(strstr(rcd_port_last_error(&p), "Fake OS error"));
        }
}

static void test_open_settings(void **state)
{
    rcd_port p;
    rcd_serialport_ctx c;
    rcd_serial_config cfg = {0};
    (void)state;
    reset(NULL);
    open_ok(&p, &c);
    assert_int_equal(g_baud, 9600);
    assert_int_equal(g_bits, 8);
    assert_int_equal(g_parity, SP_PARITY_NONE);
    assert_int_equal(g_stop, 1);
    assert_int_equal(g_flow, SP_FLOWCONTROL_NONE);
    assert_int_equal(g_configs, 0); /* freed after use */
    assert_int_equal(rcd_port_open(&p, "/dev/ttyUSB0", NULL), RC_ERR_ARG); /* already open */
    close_ok(&p);
    cfg.baud = 115200;
    cfg.data_bits = 7;
    cfg.parity = RCD_PARITY_EVEN;
    cfg.stop_bits = 2;
    cfg.flow = RCD_FLOW_RTSCTS;
    rcd_serialport_init(&p, &c);
    g_step = 0;
    assert_int_equal(rcd_port_open(&p, "/dev/ttyUSB0", &cfg), RC_OK);
    assert_int_equal(g_baud, 115200);
    assert_int_equal(g_bits, 7);
    assert_int_equal(g_parity, SP_PARITY_EVEN);
    assert_int_equal(g_stop, 2);
    assert_int_equal(g_flow, SP_FLOWCONTROL_RTSCTS);
    close_ok(&p);
    /* invalid settings are refused before any libserialport call */
    cfg.data_bits = 9;
    rcd_serialport_init(&p, &c);
    g_step = 0;
    assert_int_equal(rcd_port_open(&p, "/dev/ttyUSB0", &cfg), RC_ERR_ARG);
    assert_int_equal(g_step, 0);
}

static void test_read_paths(void **state)
{
    rcd_port p;
    rcd_serialport_ctx c;
    uint8_t b[8];
    size_t n = 99;
    (void)state;
    reset(NULL);
    open_ok(&p, &c);
    will_return(__wrap_sp_blocking_read_next, 5);
    expect_value(__wrap_sp_blocking_read_next, timeout_ms, 250);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 250), RC_OK);
    assert_int_equal(n, 5);
    assert_int_equal(b[0], 'x');
    will_return(__wrap_sp_blocking_read_next, 0); /* nothing within the timeout */
    expect_value(__wrap_sp_blocking_read_next, timeout_ms, 10);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_TIMEOUT);
    assert_int_equal(n, 0);
    will_return(__wrap_sp_nonblocking_read, 2); /* timeout 0: no wait */
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 0), RC_OK);
    assert_int_equal(n, 2);
    assert_int_equal(b[0], 'y');
    /* an unplugged adapter: SP_ERR_FAIL with EIO is a hang-up */
    g_errno = EIO;
    will_return(__wrap_sp_blocking_read_next, SP_ERR_FAIL);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_CLOSED);
    assert_non_null(strstr(rcd_port_last_error(&p), "read: Fake OS error"));
    g_errno = ENODEV;
    will_return(__wrap_sp_blocking_read_next, SP_ERR_FAIL);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_CLOSED);
    g_errno = EINVAL;
    will_return(__wrap_sp_blocking_read_next, SP_ERR_FAIL);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_IO);
    will_return(__wrap_sp_blocking_read_next, SP_ERR_ARG);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_ARG);
    will_return(__wrap_sp_blocking_read_next, SP_ERR_MEM);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_IO);
    assert_non_null(strstr(rcd_port_last_error(&p), "out of memory"));
    will_return(__wrap_sp_blocking_read_next, SP_ERR_SUPP);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_UNSUPPORTED);
    will_return(__wrap_sp_nonblocking_read, SP_ERR_FAIL);
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 0), RC_ERR_IO);
    /* a library that claims more bytes than the buffer holds is refused */
    will_return(__wrap_sp_blocking_read_next, 100);
    expect_any(__wrap_sp_blocking_read_next, timeout_ms);
    assert_int_equal(rcd_port_read(&p, &n, b, 4, 10), RC_ERR_IO);
    assert_int_equal(n, 0);
    assert_int_equal(g_msgs, 0);
    close_ok(&p);
    /* reading a closed port */
    assert_int_equal(rcd_port_read(&p, &n, b, sizeof b, 10), RC_ERR_CLOSED);
}

static void test_write_flush_drain_close(void **state)
{
    rcd_port p;
    rcd_serialport_ctx c;
    size_t n;
    (void)state;
    reset(NULL);
    open_ok(&p, &c);
    will_return(__wrap_sp_blocking_write, 8);
    assert_int_equal(rcd_port_write(&p, &n, (const uint8_t *)"12345678", 8, 100), RC_OK);
    assert_int_equal(n, 8);
    will_return(__wrap_sp_blocking_write, 3); /* timed out part way */
    assert_int_equal(rcd_port_write(&p, &n, (const uint8_t *)"12345678", 8, 100), RC_ERR_TIMEOUT);
    assert_int_equal(n, 3);
    g_errno = ENXIO;
    will_return(__wrap_sp_blocking_write, SP_ERR_FAIL);
    assert_int_equal(rcd_port_write(&p, &n, (const uint8_t *)"1", 1, 100), RC_ERR_CLOSED);
    assert_int_equal(n, 0);
    g_errno = 0;
    will_return(__wrap_sp_blocking_write, SP_ERR_SUPP);
    assert_int_equal(rcd_port_write(&p, &n, (const uint8_t *)"1", 1, 100), RC_ERR_UNSUPPORTED);
    will_return(__wrap_sp_flush, SP_OK);
    assert_int_equal(rcd_port_flush(&p), RC_OK);
    will_return(__wrap_sp_flush, SP_ERR_FAIL);
    assert_int_equal(rcd_port_flush(&p), RC_ERR_IO);
    assert_non_null(strstr(rcd_port_last_error(&p), "flush: Fake OS error"));
    will_return(__wrap_sp_drain, SP_OK);
    assert_int_equal(rcd_port_drain(&p), RC_OK);
    will_return(__wrap_sp_drain, SP_ERR_ARG);
    assert_int_equal(rcd_port_drain(&p), RC_ERR_ARG);
    /* close fails: reported, and the port is freed all the same */
    will_return(__wrap_sp_close, SP_ERR_FAIL);
    assert_int_equal(rcd_port_close(&p), RC_ERR_IO);
    assert_null(c.port);
    assert_int_equal(g_ports, 0);
    assert_int_equal(g_msgs, 0);
    assert_int_equal(rcd_port_close(&p), RC_OK); /* closing twice is harmless */
    assert_int_equal(rcd_port_flush(&p), RC_ERR_CLOSED);
    assert_int_equal(rcd_port_drain(&p), RC_ERR_CLOSED);
    assert_int_equal(rcd_port_write(&p, &n, (const uint8_t *)"1", 1, 100), RC_ERR_CLOSED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_open_every_failure, reset),
        cmocka_unit_test_setup(test_open_settings, reset),
        cmocka_unit_test_setup(test_read_paths, reset),
        cmocka_unit_test_setup(test_write_flush_drain_close, reset),
    };
    return cmocka_run_group_tests_name("drv_serialport", tests, NULL, NULL);
}
