/* SPDX-License-Identifier: MIT */
/* test_jw.c - the JSON writer: whatever the strings and numbers, the output
 * parses back (with the project's strict reader) to the same values. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "rch_json.h"
#include "rch_jw.h"

static rch_json *write_and_parse(const char *key_str, double num, int pretty, char *buf, size_t len)
{
    FILE *f = fmemopen(buf, len, "w");
    assert_non_null(f);
    rch_jw w;
    rch_jw_init(&w, f, pretty);
    rch_jw_obj(&w, NULL);
    rch_jw_str(&w, "format", "test/1");
    rch_jw_str(&w, "path", key_str);
    rch_jw_num(&w, "x", num);
    rch_jw_int(&w, "n", -42);
    rch_jw_bool(&w, "ok", 1);
    rch_jw_null(&w, "none");
    double v[3] = {1.5, NAN, -INFINITY};
    rch_jw_nums(&w, "v", v, 3);
    rch_jw_arr(&w, "list");
    rch_jw_obj(&w, NULL);
    rch_jw_str(&w, key_str, "value");
    rch_jw_end(&w);
    rch_jw_end(&w);
    rch_jw_end(&w);
    assert_int_equal(rch_jw_finish(&w), 0);
    fclose(f);
    rch_diag d;
    rch_json *j = rch_json_parse(buf, strlen(buf), "mem", &d);
    if (!j)
        fail_msg("invalid JSON (%s at %u:%u):\n%s", d.msg, d.line, d.col, buf);
    return j;
}

static void test_roundtrip_hostile_strings(void **state)
{
    (void)state;
    static const char *hostile[] = {"plain", "a\"b", "back\\slash", "new\nline", "tab\there", "ctl\x01\x1f",
                                    "*/ int x; /*", "caf\xc3\xa9", "M\xc3\xbcller \xe2\x82\xac \xf0\x9f\x98\x80", "\xff\xfe bytes", ""};
    char buf[4096];
    for (int pretty = 0; pretty <= 1; ++pretty)
        for (size_t k = 0; k < sizeof hostile / sizeof hostile[0]; ++k) {
            rch_json *j = write_and_parse(hostile[k], 0.1, pretty, buf, sizeof buf);
            const rch_json *p = rch_json_get(j, "path");
            assert_non_null(p);
            assert_int_equal(p->type, RCH_JSTR);
            /* every string comes back byte for byte, except invalid UTF-8 (U+FFFD) */
            if (strncmp(hostile[k], "\xff", 1) != 0)
                assert_string_equal(p->str, hostile[k]);
            else
                assert_string_equal(p->str, "\xef\xbf\xbd\xef\xbf\xbd bytes");
            const rch_json *list = rch_json_get(j, "list");
            assert_non_null(list);
            assert_int_equal(list->n, 1);
            assert_int_equal(list->items[0]->n, 1);
            rch_json_free(j);
        }
}

static void test_numbers(void **state)
{
    (void)state;
    char buf[4096];
    static const double vals[] = {0.1, -1e-300, 1e300, 123456.789012345678};
    for (size_t k = 0; k < sizeof vals / sizeof vals[0]; ++k) {
        rch_json *j = write_and_parse("p", vals[k], 1, buf, sizeof buf);
        assert_true(rch_json_get(j, "x")->num == vals[k]); /* %.17g round-trips */
        rch_json_free(j);
    }
    rch_json *j = write_and_parse("p", NAN, 0, buf, sizeof buf);
    assert_int_equal(rch_json_get(j, "x")->type, RCH_JNULL);
    const rch_json *v = rch_json_get(j, "v");
    assert_int_equal(v->n, 3);
    assert_int_equal(v->items[1]->type, RCH_JNULL);
    assert_int_equal(v->items[2]->type, RCH_JNULL);
    assert_null(strstr(buf, "nan"));
    assert_null(strstr(buf, "inf"));
    rch_json_free(j);
}

/* rch_jw_strs: every pair a member, NULL values null, hostile text escaped. */
static void test_strs(void **state)
{
    (void)state;
    char buf[1024];
    FILE *f = fmemopen(buf, sizeof buf, "w");
    assert_non_null(f);
    rch_jw w;
    rch_jw_init(&w, f, 0);
    rch_jw_obj(&w, NULL);
    static const char *const kv[] = {"a", "x\"y\\z\n", "b", NULL, "c", "", NULL};
    rch_jw_strs(&w, kv);
    rch_jw_end(&w);
    assert_int_equal(rch_jw_finish(&w), 0);
    fclose(f);
    rch_diag d;
    rch_json *j = rch_json_parse(buf, strlen(buf), "mem", &d);
    if (!j)
        fail_msg("invalid JSON (%s at %u:%u):\n%s", d.msg, d.line, d.col, buf);
    assert_string_equal(rch_json_get(j, "a")->str, "x\"y\\z\n");
    assert_int_equal(rch_json_get(j, "b")->type, RCH_JNULL);
    assert_string_equal(rch_json_get(j, "c")->str, "");
    rch_json_free(j);
}

static void test_misuse_reported(void **state)
{
    (void)state;
    char buf[256];
    FILE *f = fmemopen(buf, sizeof buf, "w");
    rch_jw w;
    rch_jw_init(&w, f, 0);
    rch_jw_obj(&w, NULL);
    rch_jw_num(&w, NULL, 1.0); /* value without key inside an object */
    rch_jw_end(&w);
    assert_int_equal(rch_jw_finish(&w), -1);
    fclose(f);
    f = fmemopen(buf, sizeof buf, "w");
    rch_jw_init(&w, f, 0);
    rch_jw_arr(&w, NULL); /* never closed */
    assert_int_equal(rch_jw_finish(&w), -1);
    fclose(f);
    /* Write error: a 16-byte buffer cannot hold the document. */
    char small[16];
    f = fmemopen(small, sizeof small, "w");
    setvbuf(f, NULL, _IONBF, 0);
    rch_jw_init(&w, f, 0);
    rch_jw_obj(&w, NULL);
    rch_jw_str(&w, "a-long-key", "a long value that does not fit");
    rch_jw_end(&w);
    assert_int_equal(rch_jw_finish(&w), -1);
    fclose(f);
}

static void test_escape_buffer(void **state)
{
    (void)state;
    char b[16];
    assert_string_equal(rch_jw_escape("a\"b\\c", b, sizeof b), "a\\\"b\\\\c");
    assert_string_equal(rch_jw_escape("\n", b, sizeof b), "\\u000a");
    assert_string_equal(rch_jw_escape("0123456789abcdefXYZ", b, 8), "0123456");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip_hostile_strings),
        cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_strs),
        cmocka_unit_test(test_misuse_reported),
        cmocka_unit_test(test_escape_buffer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
