/* SPDX-License-Identifier: MIT */
/* test_opt.c - the shared option parser: strict numbers, ranges, --opt=value,
 * -h, repeated and required options, no exit(). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "rch_opt.h"

static const char *s_out;
static unsigned long s_n;
static long s_i;
static double s_x, s_t[3];
static int s_flag;
static const char *s_method;
static rch_opt_strs s_data;

static const rch_opt opts[] = {
    {"--out", RCH_OPT_STR, &s_out, 0, 0, "FILE", "output", RCH_OPT_REQUIRED, NULL},
    {"--samples", RCH_OPT_UINT, &s_n, 1, 1e6, NULL, "count", 0, NULL},
    {"--shift", RCH_OPT_INT, &s_i, -10, 10, NULL, "signed", 0, NULL},
    {"--noise-mm", RCH_OPT_DOUBLE, &s_x, 0, 5, NULL, "noise", 0, NULL},
    {"--encoder", RCH_OPT_TRIPLE, s_t, 0, 0, NULL, "outlet", 0, NULL},
    {"--json", RCH_OPT_FLAG, &s_flag, 0, 0, NULL, "JSON", 0, NULL},
    {"--method", RCH_OPT_CHOICE, &s_method, 0, 0, NULL, "solver", 0, "lm|ltlm|lm-paper"},
    {"--data", RCH_OPT_STRS, &s_data, 0, 0, "FILE", "data", 0, NULL},
};
static const rch_cmdspec spec = {"demo", "a test command", "Details.", opts, sizeof opts / sizeof opts[0]};

static rch_opt_status run(const char *line, char *err, size_t errlen)
{
    static char buf[512];
    char *argv[32];
    int argc = 0;
    snprintf(buf, sizeof buf, "%s", line);
    for (char *t = strtok(buf, " "); t && argc < 32; t = strtok(NULL, " "))
        argv[argc++] = t;
    s_out = NULL;
    s_n = 7;
    s_i = 0;
    s_x = 0.5;
    s_flag = 0;
    s_method = "lm";
    memset(&s_data, 0, sizeof s_data);
    memset(s_t, 0, sizeof s_t);
    FILE *e = fmemopen(err, errlen, "w");
    FILE *o = fopen("/dev/null", "w");
    assert_non_null(e);
    assert_non_null(o);
    rch_opt_status st = rch_opt_parse(&spec, argc, argv, NULL, o, e);
    fclose(e);
    fclose(o);
    return st;
}

static void test_values(void **state)
{
    (void)state;
    char err[512] = "";
    assert_int_equal(run("demo --out a.csv --samples=42 --shift -3 --noise-mm 1.5e-1 --encoder=1,-2,3.5 --json "
                         "--method ltlm --data x.csv --data=y.csv",
                         err, sizeof err),
                     RCH_OPT_OK);
    assert_string_equal(s_out, "a.csv");
    assert_int_equal(s_n, 42);
    assert_int_equal(s_i, -3);
    assert_true(s_x == 0.15);
    assert_true(s_t[0] == 1.0 && s_t[1] == -2.0 && s_t[2] == 3.5);
    assert_int_equal(s_flag, 1);
    assert_string_equal(s_method, "ltlm");
    assert_int_equal(s_data.n, 2);
    assert_string_equal(s_data.v[1], "y.csv");
}

/* Every one of these is refused with status 2 and a message naming the option. */
static void test_refusals(void **state)
{
    (void)state;
    static const struct {
        const char *line, *name;
    } bad[] = {
        {"demo --samples 5", "--out"},                       /* required missing */
        {"demo --out a --samples 4294967297", "--samples"},  /* no wrap, out of range */
        {"demo --out a --samples 18446744073709551617", "--samples"},
        {"demo --out a --samples 0", "--samples"},           /* 0 is not a silent default */
        {"demo --out a --samples -1", "--samples"},
        {"demo --out a --samples 1e3", "--samples"},
        {"demo --out a --samples 0x10", "--samples"},
        {"demo --out a --shift 11", "--shift"},
        {"demo --out a --noise-mm 0x1.8p+1", "--noise-mm"},  /* hex float */
        {"demo --out a --noise-mm inf", "--noise-mm"},
        {"demo --out a --noise-mm nan", "--noise-mm"},
        {"demo --out a --noise-mm 1e300", "--noise-mm"},
        {"demo --out a --noise-mm 1.", "--noise-mm"},         /* accepted? see below */
        {"demo --out a --encoder 1,2", "--encoder"},
        {"demo --out a --encoder 1,2,3,4", "--encoder"},
        {"demo --out a --method fast", "--method"},
        {"demo --out a --method=", "--method"},
        {"demo --out a --json=1", "--json"},
        {"demo --out a --samples", "--samples"},
        {"demo --out a --bogus 1", "--bogus"},
        {"demo --out a --out b", "--out"},
        {"demo --out=", "--out"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        char err[512] = "";
        rch_opt_status st = run(bad[k].line, err, sizeof err);
        if (strcmp(bad[k].line, "demo --out a --noise-mm 1.") == 0) {
            assert_int_equal(st, RCH_OPT_OK); /* "1." is a decimal number */
            continue;
        }
        if (st != RCH_OPT_ERROR || !strstr(err, bad[k].name))
            fail_msg("'%s' gave %d: %s", bad[k].line, (int)st, err);
    }
}

static void test_seed_with_blank(void **state)
{
    (void)state;
    unsigned long v = 5;
    assert_int_equal(rch_parse_ulong(" -1", &v), -1);
    assert_int_equal(rch_parse_ulong(" 1", &v), -1);
    assert_int_equal(rch_parse_ulong("+1", &v), -1);
    assert_int_equal(rch_parse_ulong("", &v), -1);
    assert_int_equal(v, 5);
    assert_int_equal(rch_parse_ulong("18446744073709551615", &v), 0);
    double d = 1;
    assert_int_equal(rch_parse_double(" 1", &d), -1);
    assert_int_equal(rch_parse_double("1 ", &d), -1);
    assert_int_equal(rch_parse_double(".", &d), -1);
    assert_int_equal(rch_parse_double("-.5e-3", &d), 0);
    assert_true(d == -0.0005);
    assert_int_equal(rch_parse_double("1e-320", &d), 0); /* subnormal is a number */
}

static void test_help(void **state)
{
    (void)state;
    char text[4096] = "";
    FILE *o = fmemopen(text, sizeof text, "w");
    char a0[] = "demo", a1[] = "--samples", a2[] = "3", a3[] = "-h";
    char *argv[] = {a0, a1, a2, a3};
    assert_int_equal(rch_opt_parse(&spec, 4, argv, NULL, o, stderr), RCH_OPT_HELP);
    fclose(o);
    assert_non_null(strstr(text, "usage: rcal demo"));
    assert_non_null(strstr(text, "--samples N"));
    assert_non_null(strstr(text, "(1 to 1000000)"));
    assert_non_null(strstr(text, "--method lm|ltlm|lm-paper"));
    assert_non_null(strstr(text, "(required)"));
    assert_non_null(strstr(text, "Details."));
}

static void test_given(void **state)
{
    (void)state;
    unsigned long long seen = 0;
    char a0[] = "demo", a1[] = "--out", a2[] = "x", a3[] = "--shift=2";
    char *argv[] = {a0, a1, a2, a3};
    s_i = 0;
    assert_int_equal(rch_opt_parse(&spec, 4, argv, &seen, stdout, stderr), RCH_OPT_OK);
    assert_true(rch_opt_given(&spec, seen, "--shift"));
    assert_false(rch_opt_given(&spec, seen, "--samples"));
    assert_false(rch_opt_given(&spec, seen, "--nope"));
    assert_int_equal(s_i, 2);
}

/* rch_opt_cmd: the spec filled, -1 to run, 0 after --help, 2 after a usage
 * error; nothing exits. */
static void test_cmd(void **state)
{
    (void)state;
    rch_cmdspec cs;
    char a0[] = "demo", a1[] = "--out=x", a2[] = "--help", a3[] = "--samples", a4[] = "0";
    char *run[] = {a0, a1}, *help[] = {a0, a2}, *bad[] = {a0, a1, a3, a4};
    assert_int_equal(rch_opt_cmd(&cs, "demo", "one line", "details", opts, RCH_OPT_COUNT(opts), 2, run, NULL), -1);
    assert_string_equal(cs.cmd, "demo");
    assert_int_equal(cs.n, RCH_OPT_COUNT(opts));
    assert_string_equal(s_out, "x");
    /* prints the usage text on stdout */
    assert_int_equal(rch_opt_cmd(&cs, "demo", "one line", NULL, opts, RCH_OPT_COUNT(opts), 2, help, NULL), 0);
    /* --samples 0 is outside 1..1e6: a usage error on stderr */
    assert_int_equal(rch_opt_cmd(&cs, "demo", "one line", NULL, opts, RCH_OPT_COUNT(opts), 4, bad, NULL), 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values), cmocka_unit_test(test_refusals), cmocka_unit_test(test_seed_with_blank),
        cmocka_unit_test(test_help), cmocka_unit_test(test_given),
        cmocka_unit_test(test_cmd),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
