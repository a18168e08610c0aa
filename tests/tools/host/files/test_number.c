/* SPDX-License-Identifier: MIT */
/* test_number.c - rch_median_max against a sort; rch_parse_double, the one
 * number reader: its fast path
 * (Clinger: <= 15 significant digits and |10^e| <= 22, one rounding) must give
 * the very double strtod gives. Random decimals of every shape the data files
 * and options hold (integers, fixed point, leading and trailing zeros, signs,
 * exponents, 1..20 digits) are read both ways and compared bit by bit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rch_opt.h"
#include "rch_stats.h"

/* splitmix64: the test's own generator */
static uint64_t next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15u);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
}

static unsigned below(uint64_t *s, unsigned n)
{
    return (unsigned)(next(s) % n);
}

static void digits(char **p, uint64_t *s, unsigned n, int leading_zeros)
{
    for (unsigned i = 0; i < n; ++i)
        *(*p)++ = (char)('0' + (i == 0 && !leading_zeros ? 1 + below(s, 9) : below(s, 10)));
}

/* One random decimal into buf (at least 64 chars). */
static void random_decimal(char *buf, uint64_t *s)
{
    char *p = buf;
    const unsigned shape = below(s, 6);
    if (below(s, 3) == 0)
        *p++ = below(s, 2) ? '-' : '+';
    if (shape == 0) { /* integer */
        digits(&p, s, 1 + below(s, 18), 0);
    } else if (shape == 1) { /* 0.000ddd */
        *p++ = '0';
        *p++ = '.';
        for (unsigned z = below(s, 8); z > 0; --z)
            *p++ = '0';
        digits(&p, s, 1 + below(s, 18), 1);
    } else { /* ddd.ddd, sometimes with trailing zeros or an exponent */
        digits(&p, s, 1 + below(s, 8), below(s, 4) == 0);
        *p++ = '.';
        digits(&p, s, below(s, 14), 1);
        if (shape == 3)
            for (unsigned z = 1 + below(s, 6); z > 0; --z)
                *p++ = '0';
        if (shape >= 4) {
            *p++ = below(s, 2) ? 'e' : 'E';
            if (below(s, 2))
                *p++ = below(s, 2) ? '-' : '+';
            p += sprintf(p, "%u", below(s, shape == 4 ? 30 : 330));
        }
    }
    *p = '\0';
}

static void test_fast_path_equals_strtod(void **state)
{
    (void)state;
    uint64_t seed = 20261129u;
    char buf[96];
    unsigned read = 0;
    for (int i = 0; i < 300000; ++i) {
        random_decimal(buf, &seed);
        double a, b = strtod(buf, NULL);
        if (rch_parse_double(buf, &a) != 0) { /* refused: only out of range */
            assert_true(b == 0.0 || b > 1.7e308 || b < -1.7e308 || (b != 0.0 && fabs(b) < 2.3e-308));
            continue;
        }
        if (memcmp(&a, &b, sizeof a) != 0)
            fail_msg("%s: rch_parse_double %.17g, strtod %.17g", buf, a, b);
        ++read;
    }
    assert_true(read > 250000u);
}

/* Values a CSV of the project holds, and the edges of the fast path. */
static void test_edges(void **state)
{
    (void)state;
    static const char *const v[] = {"0",   "-0",  "+0.0", "0.1", "-123.456789", "769.432329", "1e22", "1e23",
                                    "123456789012345", "1234567890123456", "9007199254740993", "0.000000000000001e-7",
                                    "4.9406564584124654e-324", "1.7976931348623157e308", "2.2250738585072014e-308",
                                    "1.5", "00000000000000000000000001.25", "1.000000000000000000001", "5e-1"};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i) {
        double a, b = strtod(v[i], NULL);
        assert_int_equal(rch_parse_double(v[i], &a), 0);
        if (memcmp(&a, &b, sizeof a) != 0)
            fail_msg("%s: rch_parse_double %.17g, strtod %.17g", v[i], a, b);
    }
    double x;
    assert_int_equal(rch_parse_double("1e999", &x), -1);
    assert_int_equal(rch_parse_double(" 1", &x), -1);
    assert_int_equal(rch_parse_double("1.2.3", &x), -1);
    assert_int_equal(rch_parse_double("0x10", &x), -1);
    assert_int_equal(rch_parse_double(".", &x), -1);
}

static int cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The O(n) selection gives what sorting gives: random sizes 1..300 and
 * 2000, values with many ties, sorted, reversed and constant inputs. */
static void test_median_max(void **state)
{
    (void)state;
    uint64_t seed = 7u;
    static double v[2000], w[2000];
    for (int trial = 0; trial < 3000; ++trial) {
        const size_t n = trial == 0 ? 2000 : 1 + below(&seed, 300);
        const unsigned kind = below(&seed, 5), levels = 1 + below(&seed, 20);
        for (size_t i = 0; i < n; ++i) {
            double x = (double)(next(&seed) >> 11) * 0x1p-53 * 10.0 - 3.0;
            if (kind == 1)
                x = (double)below(&seed, levels); /* ties */
            else if (kind == 2)
                x = (double)i; /* sorted */
            else if (kind == 3)
                x = -(double)i; /* reversed */
            else if (kind == 4)
                x = 1.25; /* constant */
            v[i] = w[i] = x;
        }
        qsort(w, n, sizeof w[0], cmp);
        const double med = n % 2 ? w[n / 2] : 0.5 * (w[n / 2 - 1] + w[n / 2]);
        double m, mx;
        rch_median_max(&m, &mx, v, n);
        assert_true(m == med);
        assert_true(mx == w[n - 1]);
    }
    double m, mx;
    rch_median_max(&m, &mx, v, 0);
    assert_true(isnan(m) && isnan(mx));
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fast_path_equals_strtod), cmocka_unit_test(test_edges),
                                       cmocka_unit_test(test_median_max)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
