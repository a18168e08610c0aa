/* SPDX-License-Identifier: MIT */
/* test_pkg.c - the generated version header, rc_version() and the run-time
 * location of the data files (rch_paths). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "rc_model.h"
#include "rch_paths.h"

static void test_version_header_matches_library(void **state)
{
    (void)state;
    char want[32];
    snprintf(want, sizeof want, "%d.%d.%d", RC_VERSION_MAJOR, RC_VERSION_MINOR, RC_VERSION_PATCH);
    assert_string_equal(RC_VERSION_STRING, want);
    assert_string_equal(rc_version(), RC_VERSION_STRING);
    assert_int_equal(RC_VERSION_NUMBER, RC_VERSION_MAJOR * 10000 + RC_VERSION_MINOR * 100 + RC_VERSION_PATCH);
    /* the link-time token is defined by the library, with this header's limits */
    assert_int_equal(RC_ABI_SYMBOL, 1);
}

static void test_limits_size_the_structs(void **state)
{
    (void)state;
    rc_model m;
    assert_int_equal(sizeof m.x / sizeof m.x[0], RC_MAX_PARAMS);
    assert_int_equal(sizeof m.effects / sizeof m.effects[0], RC_MAX_EFFECTS);
    assert_true(RC_MAX_PARAMS >= RC_N_BASE);
}

/* A temporary directory holding one file "name". */
static void make_dir_with(char dir[64], const char *name)
{
    snprintf(dir, 64, "/tmp/rcal_pkg_XXXXXX");
    assert_non_null(mkdtemp(dir));
    char p[128];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fputs("{}\n", f);
    fclose(f);
}

static void remove_dir_with(const char *dir, const char *name)
{
    char p[128];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    unlink(p);
    rmdir(dir);
}

static void test_env_dir_comes_first(void **state)
{
    (void)state;
    char dir[64], want[128], got[4096];
    make_dir_with(dir, "irb120.json");
    snprintf(want, sizeof want, "%s/irb120.json", dir);
    setenv("RCAL_DATA_DIR", dir, 1);
    assert_int_equal(rch_data_path(got, sizeof got, "irb120.json"), 0);
    assert_string_equal(got, want);
    unsetenv("RCAL_DATA_DIR");
    remove_dir_with(dir, "irb120.json");
}

static void test_build_tree_falls_back_to_source_data(void **state)
{
    (void)state;
    char dir[64], got[4096];
    struct stat a, b;
    make_dir_with(dir, "other.txt"); /* RCAL_DATA_DIR without the file: skipped */
    setenv("RCAL_DATA_DIR", dir, 1);
    assert_int_equal(rch_data_path(got, sizeof got, "irb120.json"), 0);
    /* the very file of the source tree (paths may differ by symbolic links) */
    assert_int_equal(stat(got, &a), 0);
    assert_int_equal(stat(RCAL_SOURCE_DIR "/data/irb120.json", &b), 0);
    assert_true(a.st_dev == b.st_dev && a.st_ino == b.st_ino);
    assert_string_equal(rch_default_robot(), got);
    unsetenv("RCAL_DATA_DIR");
    remove_dir_with(dir, "other.txt");
}

static void test_missing_file_and_short_buffer(void **state)
{
    (void)state;
    char got[4096], tiny[8];
    unsetenv("RCAL_DATA_DIR");
    assert_int_equal(rch_data_path(got, sizeof got, "no_such_file.json"), -1);
    /* the message path names the file where an installed program looks */
    assert_non_null(strstr(got, "no_such_file.json"));
    assert_int_equal(rch_data_path(tiny, sizeof tiny, "irb120.json"), -1);
    assert_true(strlen(tiny) < sizeof tiny);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version_header_matches_library),
        cmocka_unit_test(test_limits_size_the_structs),
        cmocka_unit_test(test_env_dir_comes_first),
        cmocka_unit_test(test_build_tree_falls_back_to_source_data),
        cmocka_unit_test(test_missing_file_and_short_buffer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
