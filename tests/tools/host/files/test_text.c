/* SPDX-License-Identifier: MIT */
/* test_text.c - the one UTF-8 check and XML escaper (rch_text.h) against
 * the Unicode standard's table of well-formed byte sequences (Table 3-7)
 * and XML 1.0's character range, byte sequence by byte sequence. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_text.h"

/* Table 3-7 written as a predicate apart from the code under test. */
static size_t table37(const unsigned char *s)
{
    const unsigned b = s[0];
    struct {
        unsigned lo, hi, n, lo2, hi2;
    } rows[] = {{0x00, 0x7F, 1, 0, 0},       {0xC2, 0xDF, 2, 0x80, 0xBF}, {0xE0, 0xE0, 3, 0xA0, 0xBF},
                {0xE1, 0xEC, 3, 0x80, 0xBF}, {0xED, 0xED, 3, 0x80, 0x9F}, {0xEE, 0xEF, 3, 0x80, 0xBF},
                {0xF0, 0xF0, 4, 0x90, 0xBF}, {0xF1, 0xF3, 4, 0x80, 0xBF}, {0xF4, 0xF4, 4, 0x80, 0x8F}};
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; ++r) {
        if (b < rows[r].lo || b > rows[r].hi)
            continue;
        if (rows[r].n == 1)
            return 1;
        if (s[1] < rows[r].lo2 || s[1] > rows[r].hi2)
            return 0;
        for (unsigned k = 2; k < rows[r].n; ++k)
            if (s[k] < 0x80 || s[k] > 0xBF)
                return 0;
        return rows[r].n;
    }
    return 0;
}

/* Every first byte with every second byte, third and fourth bytes from a
 * set that covers each boundary. */
static void test_utf8_exhaustive(void **state)
{
    (void)state;
    static const unsigned char tails[] = {0x00, 0x41, 0x7F, 0x80, 0x8F, 0x90, 0x9F, 0xA0, 0xBF, 0xC0, 0xFF};
    size_t n = 0;
    for (unsigned a = 1; a < 256; ++a)
        for (unsigned b = 0; b < 256; ++b)
            for (size_t c = 0; c < sizeof tails; ++c)
                for (size_t d = 0; d < sizeof tails; ++d) {
                    const unsigned char s[5] = {(unsigned char)a, (unsigned char)b, tails[c], tails[d], 0};
                    if (b == 0 && (c || d))
                        continue;
                    assert_int_equal(rch_utf8_len(s), table37(s));
                    ++n;
                }
    print_message("%zu byte sequences agree with Table 3-7\n", n);
}

static void test_xml_escape(void **state)
{
    (void)state;
    char buf[128];
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "a<b>&\"c'", 0), "a&lt;b&gt;&amp;&quot;c&#39;");
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "t\tn\nr\r", 0), "t\tn\nr\r");
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "t\tn\nr\r", RCH_XML_WS_REFS), "t&#9;n&#10;r&#13;");
    /* what XML 1.0 cannot carry: controls, DEL, invalid UTF-8, U+FFFE, U+FFFF */
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "\x01\x7f\xff", 0), "&#xFFFD;&#xFFFD;&#xFFFD;");
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "\xEF\xBF\xBE\xEF\xBF\xBF", 0), "&#xFFFD;&#xFFFD;");
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "\xEF\xBF\xBD", 0), "\xEF\xBF\xBD"); /* U+FFFD itself */
    assert_string_equal(rch_xml_escape(buf, sizeof buf, "\xF0\x9F\x98\x80 \xC2\xB5m", 0), "\xF0\x9F\x98\x80 \xC2\xB5m");
    /* cut between whole references only */
    assert_string_equal(rch_xml_escape(buf, 7, "a&b", 0), "a&amp;");
    assert_string_equal(rch_xml_escape(buf, 6, "a&b", 0), "a");
    assert_string_equal(rch_xml_escape(buf, sizeof buf, NULL, 0), "");
    /* the stream form writes the same */
    char *mem = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&mem, &len);
    assert_non_null(f);
    rch_xml_put(f, "x<\x01\xC0\xAF", 0);
    fclose(f);
    assert_string_equal(mem, "x&lt;&#xFFFD;&#xFFFD;&#xFFFD;");
    free(mem);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_utf8_exhaustive),
        cmocka_unit_test(test_xml_escape),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
