/* SPDX-License-Identifier: MIT */
/* test_link.c - the controller link rcal-link/1 in-process (issue 48): the spec parser, a controller whose
 * lines are written ahead into a loopback socket (a wrong place, a wrong version, a malformed report, a
 * second controller) against rch_link_pose, and the acquisition file's plan columns (a controller's joints
 * off the plan's 4 decimals resume; a file of the other kind is refused). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "rch_acqfile.h"
#include "rch_link.h"

static void test_parse(void **state)
{
    char host[64];
    unsigned port = 7;
    (void)state;
    assert_int_equal(rch_link_parse(host, &port, "tcp:5000"), 0);
    assert_string_equal(host, "127.0.0.1");
    assert_int_equal(port, 5000);
    assert_int_equal(rch_link_parse(host, &port, "tcp:127.0.0.2:0"), 0);
    assert_string_equal(host, "127.0.0.2");
    assert_int_equal(port, 0);
    assert_int_equal(rch_link_parse(host, &port, "tcp:65536"), -1);
    assert_int_equal(rch_link_parse(host, &port, "udp:5000"), -1);
    assert_int_equal(rch_link_parse(host, &port, "tcp:localhost:5000"), -1); /* numeric only: no resolver */
    assert_int_equal(rch_link_parse(host, &port, "tcp:"), -1);
    assert_int_equal(rch_link_parse(host, &port, "tcp:12x"), -1);
}

/* A client of port with `text` already sent (the controller's lines, ahead of rcal's answers). */
static int client(unsigned port, const char *text)
{
    struct sockaddr_in sa;
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    assert_true(fd >= 0);
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons((unsigned short)port);
    inet_pton(AF_INET, "127.0.0.1", &sa.sin_addr);
    assert_int_equal(connect(fd, (struct sockaddr *)&sa, sizeof sa), 0);
    assert_int_equal(send(fd, text, strlen(text), 0), (ssize_t)strlen(text));
    return fd;
}

/* What rcal sent to fd (read until `until` appears or 2 s). */
static void received(int fd, char *buf, size_t cap, const char *until)
{
    size_t n = 0;
    struct timeval tv = {0, 100000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    for (int k = 0; k < 20 && !strstr(buf, until); ++k) {
        ssize_t r = recv(fd, buf + n, cap - 1 - n, 0);
        if (r > 0)
            n += (size_t)r;
        buf[n] = '\0';
    }
}

static void config(rch_link_config *c)
{
    memset(c, 0, sizeof *c);
    c->spec = "tcp:0";
    c->tol_deg = 0.05;
    c->wait_ms = 3000;
    c->link_timeout_ms = 3000;
    c->move_timeout_ms = 3000;
    c->hb_ms = 1000;
    c->retries = 2;
    c->n_poses = 5;
    c->outlet = 1;
    c->point = -1;
}

static void test_faults(void **state)
{
    static const double plan[RC_NJ] = {10, -20, 30, 0, 45, 90};
    rch_link l;
    rch_link_config c;
    double q[RC_NJ], xyz[3];
    int has_xyz = 0;
    char buf[4096] = "";
    (void)state;
    config(&c);
    assert_int_equal(rch_link_open(&l, &c, NULL), RC_OK);
    assert_true(l.port > 0);
    /* a controller of another version: refused and closed */
    int bad = client(l.port, "HELLO rcal-link/9 old\n");
    /* the controller: a wrong place, a malformed report, garbage, then pose 3 at its precision with a TCP */
    int good = client(l.port, "HELLO rcal-link/1 t\n"
                              "AT 3 0 -1 10 -20 30 0 45 90\n"
                              "AT 3 1 -1 10 -20 30 zero 45 90\n"
                              "MOVE 3\n"
                              "AT 3 1 -1 10.00123 -20.00456 30.00001 -0.00002 45.0 89.99999 1.5 2.5 3.5\n");
    assert_int_equal(rch_link_pose(&l, "NEXT", 3, plan, q, xyz, &has_xyz), RC_OK);
    assert_true(fabs((q[0]) - (10.00123)) < 1e-12);
    assert_true(fabs((q[5]) - (89.99999)) < 1e-12);
    assert_int_equal(has_xyz, 1);
    assert_true(fabs((xyz[2]) - (3.5)) < 1e-12);
    assert_int_equal(l.faults[RCH_LINK_VERSION_F], 1);
    assert_int_equal(l.faults[RCH_LINK_PLACE], 1);
    assert_int_equal(l.faults[RCH_LINK_UNKNOWN], 2);
    assert_int_equal(l.faults[RCH_LINK_OFFSET], 0);
    received(bad, buf, sizeof buf, "FAULT VERSION");
    assert_non_null(strstr(buf, "FAULT VERSION -1"));
    buf[0] = '\0';
    received(good, buf, sizeof buf, "FAULT UNKNOWN -1 unknown");
    assert_non_null(strstr(buf, "WELCOME rcal-link/1 5\nNEXT 3\n"));
    assert_non_null(strstr(buf, "FAULT PLACE 3"));
    assert_non_null(strstr(buf, "FAULT UNKNOWN 3 q4 'zero' is not a number"));
    assert_non_null(strstr(buf, "FAULT UNKNOWN -1 unknown message 'MOVE'"));
    /* a second controller while the first is connected: BUSY, the first goes on; two offsets stop the run */
    int second = client(l.port, "HELLO rcal-link/1 other\n");
    const char *off = "AT 4 1 -1 10 -20 30.2 0 45 90\n";
    assert_int_equal(send(good, off, strlen(off), 0), (ssize_t)strlen(off));
    assert_int_equal(send(good, off, strlen(off), 0), (ssize_t)strlen(off));
    assert_int_equal(rch_link_pose(&l, "NEXT", 4, plan, q, xyz, &has_xyz), RC_ERR_RANGE);
    assert_int_equal(l.faults[RCH_LINK_OFFSET], 2);
    buf[0] = '\0';
    received(second, buf, sizeof buf, "FAULT BUSY");
    assert_non_null(strstr(buf, "FAULT BUSY -1"));
    assert_int_equal(l.faults[RCH_LINK_BUSY], 1);
    rch_link_stop(&l, "stopped");
    buf[0] = '\0';
    received(good, buf, sizeof buf, "STOP stopped");
    assert_non_null(strstr(buf, "STOP stopped"));
    close(bad);
    close(good);
    close(second);
    rch_link_close(&l);
}

/* No controller within wait_ms: RC_ERR_TIMEOUT, bounded. */
static void test_no_controller(void **state)
{
    static const double plan[RC_NJ] = {0};
    rch_link l;
    rch_link_config c;
    double q[RC_NJ], xyz[3];
    int has_xyz;
    (void)state;
    config(&c);
    c.wait_ms = 200;
    assert_int_equal(rch_link_open(&l, &c, NULL), RC_OK);
    assert_int_equal(rch_link_pose(&l, "NEXT", 0, plan, q, xyz, &has_xyz), RC_ERR_TIMEOUT);
    rch_link_close(&l);
}

static void test_plan_columns(void **state)
{
    static const double plan[2][RC_NJ] = {{10, -20, 30, 0, 45, 90}, {11, -21, 31, 1, 46, 91}};
    const double q0[RC_NJ] = {10.00123, -20.00456, 30.00001, -0.00002, 45.0, 89.99999};
    const char *path = "link_plan_cols.csv";
    rch_acqfile f;
    rch_acqfile_state st;
    rc_stable_result r;
    unsigned char done[2];
    rch_diag d;
    char line[512];
    (void)state;
    memset(&r, 0, sizeof r);
    r.mean_mm = 500.25;
    r.count = 8;
    unlink(path);
    assert_int_equal(rch_acqfile_open_plan(&f, &st, done, path, plan, 2, 0, 0, 1, &d), 0);
    assert_int_equal(rch_acqfile_append_plan(&f, 0, q0, plan[0], &r, 1000, &d), 0);
    assert_int_equal(rch_acqfile_append_plan(&f, 1, q0, NULL, &r, 1000, &d), -1); /* the plan's are needed */
    assert_int_equal(rch_acqfile_close(&f, &d), 0);
    FILE *fp = fopen(path, "r");
    assert_non_null(fp);
    assert_non_null(fgets(line, sizeof line, fp));
    assert_string_equal(line, RCH_ACQ_HEADER RCH_ACQ_PLAN_COLS "\n");
    assert_non_null(fgets(line, sizeof line, fp));
    fclose(fp);
    /* the controller's joints at 6 decimals, the plan's beside */
    assert_non_null(strstr(line, "0,10.001230,-20.004560,30.000010,-0.000020,45.000000,89.999990,500.2500,"));
    assert_non_null(strstr(line, ",10.0000,-20.0000,30.0000,0.0000,45.0000,90.0000\n"));
    /* resumed: the plan columns decide (the joints are 0.005 deg off the plan's) */
    assert_int_equal(rch_acqfile_open_plan(&f, &st, done, path, plan, 2, 0, 0, 1, &d), 0);
    assert_int_equal(st.n_done, 1);
    assert_int_equal(done[0], 1);
    assert_int_equal(rch_acqfile_close(&f, &d), 0);
    /* a run without the controller on this file, and a controller run on a plain file: refused */
    assert_int_equal(rch_acqfile_open_at(&f, &st, done, path, plan, 2, 0, 0, &d), -1);
    assert_non_null(strstr(d.msg, "resume it with --controller"));
    /* another plan (pose 0's plan columns differ): refused */
    static const double other[2][RC_NJ] = {{10, -20, 30, 0, 45, 90.5}, {11, -21, 31, 1, 46, 91}};
    assert_int_equal(rch_acqfile_open_plan(&f, &st, done, path, other, 2, 0, 0, 1, &d), -1);
    assert_non_null(strstr(d.msg, "another plan"));
    unlink(path);
    assert_int_equal(rch_acqfile_open_at(&f, &st, done, path, plan, 2, 0, 0, &d), 0);
    assert_int_equal(rch_acqfile_append(&f, 0, plan[0], &r, 1000, &d), 0);
    assert_int_equal(rch_acqfile_close(&f, &d), 0);
    assert_int_equal(rch_acqfile_open_plan(&f, &st, done, path, plan, 2, 0, 0, 1, &d), -1);
    assert_non_null(strstr(d.msg, "needs a file of its own"));
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_faults),
        cmocka_unit_test(test_no_controller),
        cmocka_unit_test(test_plan_columns),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
