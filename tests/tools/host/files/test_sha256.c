/* SPDX-License-Identifier: MIT */
/* test_sha256.c - FIPS 180-4 test vectors, and a file digest equal to
 * sha256sum's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "rch_sha256.h"

static void digest(const char *msg, size_t reps, char hex[65])
{
    rch_sha256 c;
    rch_sha256_init(&c);
    for (size_t i = 0; i < reps; ++i)
        rch_sha256_update(&c, msg, strlen(msg));
    rch_sha256_final(&c, hex);
}

static void test_vectors(void **state)
{
    (void)state;
    char h[65];
    digest("", 1, h);
    assert_string_equal(h, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    digest("abc", 1, h);
    assert_string_equal(h, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    digest("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq", 1, h);
    assert_string_equal(h, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    digest("a", 1000000, h);
    assert_string_equal(h, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

static void test_file(void **state)
{
    (void)state;
    char h[65], cmd[512], want[80] = "";
    const char *path = RCAL_SOURCE_DIR "/data/irb120.json";
    assert_int_equal(rch_sha256_file(h, path), 0);
    snprintf(cmd, sizeof cmd, "sha256sum '%s'", path);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    assert_non_null(fgets(want, sizeof want, p));
    pclose(p);
    want[64] = '\0';
    assert_string_equal(h, want);
    assert_int_equal(rch_sha256_file(h, "/nonexistent/file"), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_vectors), cmocka_unit_test(test_file)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
