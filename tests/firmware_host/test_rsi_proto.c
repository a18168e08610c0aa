/* SPDX-License-Identifier: MIT */
/* test_rsi_proto.c - the RSI datagrams and configuration file
 * (firmware_host/rt_rsi.c): a robot's <Rob> decoded to its setpoint, actual
 * axes, IPOC and Delay; what makes a datagram malformed and what only makes
 * its setpoint unusable; the <Sen> answer byte for byte; RSI's Ethernet
 * configuration file read into the names, and refused with file:line:col. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rt_rsi.h"

static const char rob[] =
    "<Rob Type=\"KUKA\"><RIst X=\"445.0\" Y=\"0.0\" Z=\"890.0\" A=\"0.0\" B=\"90.0\" C=\"0.0\"/>"
    "<AIPos A1=\"10.5\" A2=\"-40.25\" A3=\"60.0\" A4=\"5.0\" A5=\"30.0\" A6=\"20.0\"/>\n"
    "<ASPos A1=\"10.0\" A2=\"-40.0\" A3=\"60.125\" A4=\"5.0\" A5=\"30.0\" A6=\"-20.0\"/>"
    "<Delay D=\"3\"/><IPOC> 4208889 </IPOC></Rob>";

static rt_rsi_status dec(rt_rsi_rob *r, char *why, size_t why_len, const char *text)
{
    rt_rsi_names n;
    rt_rsi_names_default(&n);
    rt_rsi_dec *d = rt_rsi_dec_new(&n);
    assert_non_null(d);
    const rt_rsi_status st = rt_rsi_decode(r, why, why_len, d, text, strlen(text));
    rt_rsi_dec_free(d);
    return st;
}

static void test_decode(void **state)
{
    (void)state;
    rt_rsi_rob r;
    char why[192];
    assert_int_equal(dec(&r, why, sizeof why, rob), RT_RSI_OK);
    assert_true(r.ipoc == 4208889ull);
    assert_true(r.set_ok && r.has_act);
    const double set[6] = {10.0, -40.0, 60.125, 5.0, 30.0, -20.0};
    for (int i = 0; i < 6; ++i)
        assert_true(r.set_deg[i] == set[i]);
    assert_true(r.act_deg[0] == 10.5 && r.act_deg[1] == -40.25);
    assert_int_equal(r.delay, 3);
}

static void test_setpoint_unusable(void **state)
{
    (void)state;
    char buf[1024], why[192];
    rt_rsi_rob r;
    /* a non-number: still the robot's datagram (answered with the correction held) */
    snprintf(buf, sizeof buf, "%s", rob);
    char *p = strstr(buf, "A3=\"60.125\"");
    memcpy(p, "A3=\"6x.125\"", 11);
    assert_int_equal(dec(&r, why, sizeof why, buf), RT_RSI_OK);
    assert_false(r.set_ok);
    assert_non_null(strstr(r.set_why, "ASPos A3=\"6x.125\" is not a finite decimal number"));
    assert_non_null(strstr(r.set_why, "2:")); /* the line of <ASPos> */
    /* no ASPos; an axis missing; nan; hex */
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><IPOC>5</IPOC></Rob>"), RT_RSI_OK);
    assert_false(r.set_ok);
    assert_string_equal(r.set_why, "no <ASPos>");
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><ASPos A1=\"1\" A2=\"1\" A3=\"1\" A4=\"1\" A5=\"1\"/>"
                                              "<IPOC>5</IPOC></Rob>"), RT_RSI_OK);
    assert_non_null(strstr(r.set_why, "ASPos has no A6"));
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><ASPos A1=\"nan\" A2=\"1\" A3=\"1\" A4=\"1\" A5=\"1\" A6=\"1\"/>"
                                              "<IPOC>5</IPOC></Rob>"), RT_RSI_OK);
    assert_false(r.set_ok);
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><ASPos A1=\"0x1\" A2=\"1\" A3=\"1\" A4=\"1\" A5=\"1\" A6=\"1\"/>"
                                              "<IPOC>5</IPOC></Rob>"), RT_RSI_OK);
    assert_false(r.set_ok);
    /* two ASPos: which one is meant is unknown */
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><ASPos A1=\"1\" A2=\"1\" A3=\"1\" A4=\"1\" A5=\"1\" A6=\"1\"/>"
                                              "<ASPos A1=\"1\" A2=\"1\" A3=\"1\" A4=\"1\" A5=\"1\" A6=\"1\"/>"
                                              "<IPOC>5</IPOC></Rob>"), RT_RSI_OK);
    assert_false(r.set_ok);
    assert_non_null(strstr(r.set_why, "a second <ASPos>"));
}

static void test_malformed(void **state)
{
    (void)state;
    rt_rsi_rob r;
    char why[192];
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><IPOC>5</IPOC>"), RT_RSI_ERR_XML);
    assert_non_null(strstr(why, "1:")); /* expat's place */
    assert_false(r.set_ok);
    assert_int_equal(dec(&r, why, sizeof why, "<Sen><IPOC>5</IPOC></Sen>"), RT_RSI_ERR_ROOT);
    assert_int_equal(dec(&r, why, sizeof why, "<Rob></Rob>"), RT_RSI_ERR_IPOC);
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><IPOC>-5</IPOC></Rob>"), RT_RSI_ERR_IPOC);
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><IPOC>1234567890123456789</IPOC></Rob>"), RT_RSI_ERR_IPOC);
    assert_int_equal(dec(&r, why, sizeof why, "<Rob><IPOC>5</IPOC><IPOC>6</IPOC></Rob>"), RT_RSI_ERR_IPOC);
    assert_int_equal(dec(&r, why, sizeof why,
                         "<!DOCTYPE Rob [<!ENTITY a \"1\">]><Rob><IPOC>&a;</IPOC></Rob>"), RT_RSI_ERR_XML);
    assert_non_null(strstr(why, "DOCTYPE"));
    static char big[RT_RSI_MAX_DGRAM + 2];
    memset(big, ' ', sizeof big - 1);
    assert_int_equal(dec(&r, why, sizeof why, big), RT_RSI_ERR_TOO_LONG);
}

static void test_encode(void **state)
{
    (void)state;
    rt_rsi_names n;
    rt_rsi_names_default(&n);
    const double ak[6] = {-0.1401687226, 0.5, 0, 1e-10, -2.25, 0.0000000004};
    char out[RT_RSI_MAX_REPLY];
    const size_t len = rt_rsi_encode(out, sizeof out, &n, ak, 4208889ull);
    assert_string_equal(out, "<Sen Type=\"ImFree\"><AK A1=\"-0.1401687226\" A2=\"0.5000000000\" A3=\"0.0000000000\" "
                             "A4=\"0.0000000001\" A5=\"-2.2500000000\" A6=\"0.0000000004\"/><IPOC>4208889</IPOC></Sen>");
    assert_int_equal(len, strlen(out));
    const double bad[6] = {0, NAN, 0, 0, 0, 0};
    assert_int_equal(rt_rsi_encode(out, sizeof out, &n, bad, 1), 0);
    assert_int_equal(rt_rsi_encode(out, 40, &n, ak, 1), 0); /* does not fit: nothing */
}

static const char cfg[] =
    "<ROOT>\n"
    "  <CONFIG>\n"
    "    <IP_NUMBER>192.168.1.25</IP_NUMBER>\n"
    "    <PORT>59152</PORT>\n"
    "    <SENTYPE>rcal_rt</SENTYPE>\n"
    "    <ONLYSEND>FALSE</ONLYSEND>\n"
    "  </CONFIG>\n"
    "  <SEND><ELEMENTS>\n"
    "    <ELEMENT TAG=\"DEF_ASPos\" TYPE=\"DOUBLE\" INDX=\"INTERNAL\" />\n"
    "  </ELEMENTS></SEND>\n"
    "  <RECEIVE><ELEMENTS>\n"
    "    <ELEMENT TAG=\"Out.01\" TYPE=\"BOOL\" INDX=\"1\" HOLDON=\"1\" />\n"
    "    <ELEMENT TAG=\"Corr.X3\" TYPE=\"DOUBLE\" INDX=\"4\" HOLDON=\"1\" />\n"
    "    <ELEMENT TAG=\"Corr.X1\" TYPE=\"DOUBLE\" INDX=\"2\" HOLDON=\"1\" />\n"
    "    <ELEMENT TAG=\"Corr.X2\" TYPE=\"DOUBLE\" INDX=\"3\" HOLDON=\"1\" />\n"
    "    <ELEMENT TAG=\"Corr.X4\" TYPE=\"DOUBLE\" INDX=\"5\" HOLDON=\"1\" />\n"
    "    <ELEMENT TAG=\"Corr.X5\" TYPE=\"DOUBLE\" INDX=\"6\" HOLDON=\"1\" />\n"
    "    <ELEMENT TAG=\"Corr.X6\" TYPE=\"DOUBLE\" INDX=\"7\" HOLDON=\"1\" />\n"
    "  </ELEMENTS></RECEIVE>\n"
    "</ROOT>\n";

static rt_rsi_status cfg_read(rt_rsi_names *n, rt_rsi_net *net, char *msg, size_t len, const char *text)
{
    return rt_rsi_config_read(n, net, msg, len, text, strlen(text), "eth.xml");
}

static void test_config(void **state)
{
    (void)state;
    rt_rsi_names n;
    rt_rsi_net net;
    char msg[512];
    assert_int_equal(cfg_read(&n, &net, msg, sizeof msg, cfg), RT_RSI_OK);
    assert_string_equal(n.sentype, "rcal_rt");
    assert_string_equal(net.ip, "192.168.1.25");
    assert_int_equal(net.port, 59152);
    assert_string_equal(n.corr_tag, "Corr");
    const char *const want[6] = {"X1", "X2", "X3", "X4", "X5", "X6"}; /* by INDX, not by place */
    for (int i = 0; i < 6; ++i)
        assert_string_equal(n.corr_attr[i], want[i]);
    double ak[6] = {0};
    char out[RT_RSI_MAX_REPLY];
    assert_true(rt_rsi_encode(out, sizeof out, &n, ak, 9) > 0);
    assert_non_null(strstr(out, "<Sen Type=\"rcal_rt\"><Corr X1=\"0.0000000000\" X2="));
}

static void refused(const char *text, const char *what)
{
    rt_rsi_names n;
    rt_rsi_net net;
    char msg[512];
    assert_int_equal(cfg_read(&n, &net, msg, sizeof msg, text), RT_RSI_ERR_CONFIG);
    if (!strstr(msg, what))
        fail_msg("'%s' does not say '%s'", msg, what);
}

static void replace(char *out, size_t cap, const char *from, const char *to)
{
    const char *p = strstr(cfg, from);
    assert_non_null(p);
    snprintf(out, cap, "%.*s%s%s", (int)(p - cfg), cfg, to, p + strlen(from));
}

static void test_config_refused(void **state)
{
    (void)state;
    static char buf[4096];
    replace(buf, sizeof buf, "<ONLYSEND>FALSE", "<ONLYSEND>TRUE");
    refused(buf, "eth.xml:6:");
    refused(buf, "ONLYSEND is TRUE");
    replace(buf, sizeof buf, "DEF_ASPos", "DEF_AIPos");
    refused(buf, "SEND has no DEF_ASPos");
    replace(buf, sizeof buf, "Corr.X6", "Other.X6");
    refused(buf, "no group of six DOUBLE elements");
    replace(buf, sizeof buf, "Corr.X6", "Corr.X5");
    refused(buf, "names Corr.X5 twice");
    replace(buf, sizeof buf, "<PORT>59152", "<PORT>70000");
    refused(buf, "eth.xml:4:");
    replace(buf, sizeof buf, "<SENTYPE>rcal_rt", "<SENTYPE>a\"b");
    refused(buf, "SENTYPE");
    replace(buf, sizeof buf, "Corr.X1", "Co\"rr.X1");
    refused(buf, "eth.xml:"); /* not XML */
    replace(buf, sizeof buf, "Corr.X1", "C<r.X1");
    refused(buf, "eth.xml:14:");
    refused("<CONFIG/>", "not <ROOT>");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_decode),         cmocka_unit_test(test_setpoint_unusable),
        cmocka_unit_test(test_malformed),      cmocka_unit_test(test_encode),
        cmocka_unit_test(test_config),         cmocka_unit_test(test_config_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
