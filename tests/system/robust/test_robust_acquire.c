/* SPDX-License-Identifier: MIT */
/* test_robust_acquire.c - resuming an acquisition never deletes samples
 * (issue 7 hardening; found as a data-loss bug, fixed in tools/cmd_acquire.c).
 *
 * `rcal acquire` reads an existing --out file before it resumes. It used to
 * read it with fgets(line, 1024) and to take the first line without '\n' for
 * an interrupted write: a NUL byte or a long line in the middle of the file
 * made it ftruncate() every later sample away. Now only the true last line
 * may be unfinished (it is copied to <out>.dropped before it is cut off);
 * any other damage is refused with line and column and the file is left as
 * it is. Each test runs rcal acquire against a port that does not exist, so
 * only the resume scan runs. Issue 12 adds outputs that name inputs and
 * devices as --out, refused before anything is written.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>


static const char *dir_ = RCAL_BINARY_DIR "/tests/system/robust/acq_resume";

static void write_file(const char *name, const char *bytes, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir_, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(bytes, 1, n, f), n);
    fclose(f);
}

static long long file_size(const char *name)
{
    char path[1024];
    struct stat sb;
    snprintf(path, sizeof path, "%s/%s", dir_, name);
    if (stat(path, &sb) != 0)
        return -1;
    return (long long)sb.st_size;
}

/* Runs rcal acquire on data.csv against a missing port; returns its exit
 * status and leaves its stderr in acquire.err. */
static int try_resume(void)
{
    char cmd[4096];
    static const char plan[] = "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n10,0,0,0,0,0\n20,0,0,0,0,0\n";
    (void)mkdir(dir_, 0755);
    write_file("plan.csv", plan, sizeof plan - 1);
    (void)remove(RCAL_BINARY_DIR "/tests/system/robust/acq_resume/data.csv.dropped");
    snprintf(cmd, sizeof cmd,
             "cd %s && timeout 30 %s/tools/rcal acquire --port %s/no-such-tty --backend posix --protocol ascii "
             "--poses plan.csv --out data.csv --reconnect-s 0 --quiet >/dev/null 2>acquire.err",
             dir_, RCAL_BINARY_DIR, dir_);
    return system(cmd);
}

static int err_contains(const char *needle)
{
    char path[1024], buf[4096];
    size_t n;
    snprintf(path, sizeof path, "%s/acquire.err", dir_);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    print_message("rcal acquire said: %s", buf);
    return strstr(buf, needle) != NULL;
}

#define HDR "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms\n"
#define S0 "0,0.0000,0.0000,0.0000,0.0000,0.0000,0.0000,500.1000,0.0100,5,1700000000000\n"
#define S2 "2,20.0000,0.0000,0.0000,0.0000,0.0000,0.0000,502.1000,0.0100,5,1700000000002\n"

/* a NUL byte in the middle line: refused at line 3, column 50; nothing cut */
static void test_nul_mid_file_refused(void **state)
{
    (void)state;
    static const char data[] = HDR S0 "1,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,501.\0000,0.0100,5,1700000000001\n" S2;
    (void)mkdir(dir_, 0755);
    write_file("data.csv", data, sizeof data - 1);
    assert_int_not_equal(try_resume(), 0);
    assert_int_equal(file_size("data.csv"), (long long)(sizeof data - 1));
    assert_true(err_contains("data.csv:3:50: NUL byte"));
    assert_int_equal(file_size("data.csv.dropped"), -1);
}

/* a 2000-byte line in the middle (more than the old 1023-byte buffer): it is
 * not a sample of the plan, so it is refused; nothing cut */
static void test_long_mid_line_refused(void **state)
{
    (void)state;
    static char data[4096];
    size_t n = 0;
    memcpy(data, HDR S0, strlen(HDR S0));
    n = strlen(HDR S0);
    memset(data + n, '7', 2000);
    n += 2000;
    data[n++] = '\n';
    memcpy(data + n, S2, strlen(S2));
    n += strlen(S2);
    (void)mkdir(dir_, 0755);
    write_file("data.csv", data, n);
    assert_int_not_equal(try_resume(), 0);
    assert_int_equal(file_size("data.csv"), (long long)n);
    assert_true(err_contains("data.csv:3:"));
}

/* an interrupted write at the very end: the fragment is cut off, but kept in
 * data.csv.dropped; the complete samples before it stay */
static void test_unfinished_last_line_saved(void **state)
{
    (void)state;
    static const char frag[] = "2,20.0000,0.0000,0.00";
    static const char data[] = HDR S0 "2,20.0000,0.0000,0.00";
    (void)mkdir(dir_, 0755);
    write_file("data.csv", data, sizeof data - 1);
    (void)try_resume(); /* the port does not exist: fails after the scan */
    assert_int_equal(file_size("data.csv"), (long long)strlen(HDR S0));
    assert_int_equal(file_size("data.csv.dropped"), (long long)(sizeof frag - 1));
    assert_true(err_contains("unfinished last line"));
}

/* numbers out of range or not finite in a sample line (read with
 * strtoul/strtod, not sscanf, for which they are undefined behaviour): the
 * line is refused with its line number; nothing cut */
static void test_out_of_range_numbers_refused(void **state)
{
    static const char *const bad[] = {
        "1,1e999,0.0000,0.0000,0.0000,0.0000,0.0000,501.1000,0.0100,5,1700000000001\n",   /* q1 overflows */
        "1,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,-1e400,0.0100,5,1700000000001\n",   /* L overflows */
        "1,10.0000,0.0000,0.0000,0.0000,0.0000,nan,501.1000,0.0100,5,1700000000001\n",    /* q6 NaN */
        "1,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,inf,0.0100,5,1700000000001\n",      /* L infinite */
        "99999999999999999999999,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,501.1000\n", /* pose overflows */
        "-1,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,501.1000,0.0100,5,1700000000001\n", /* negative pose */
        "1,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,501.1x,0.0100,5,1700000000001\n",   /* text after L */
    };
    (void)state;
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        char data[1024];
        int n = snprintf(data, sizeof data, "%s%s%s%s", HDR, S0, bad[k], S2);
        assert_true(n > 0 && (size_t)n < sizeof data);
        (void)mkdir(dir_, 0755);
        write_file("data.csv", data, (size_t)n);
        assert_int_not_equal(try_resume(), 0);
        assert_int_equal(file_size("data.csv"), (long long)n);
        if (!err_contains("data.csv:3:"))
            fail_msg("case %zu (%s) not refused at line 3", k, bad[k]);
        assert_int_equal(file_size("data.csv.dropped"), -1);
    }
}

/* Issue 12: an output naming an input is refused before anything is
 * written (by inode: "./data.csv"), and so is a device as --out. */
static void test_outputs_refused(void **state)
{
    static const char data[] = HDR S0;
    char cmd[4096];
    (void)state;
    (void)mkdir(dir_, 0755);
    write_file("data.csv", data, sizeof data - 1);
    snprintf(cmd, sizeof cmd,
             "cd %s && timeout 30 %s/tools/rcal acquire --port %s/no-such-tty --backend posix --protocol ascii "
             "--poses plan.csv --out data.csv --announce ./data.csv --quiet >/dev/null 2>acquire.err",
             dir_, RCAL_BINARY_DIR, dir_);
    assert_int_equal(WEXITSTATUS(system(cmd)), 1);
    assert_true(err_contains("--announce"));
    assert_int_equal(file_size("data.csv"), (long long)(sizeof data - 1));
    snprintf(cmd, sizeof cmd,
             "cd %s && timeout 30 %s/tools/rcal acquire --port %s/no-such-tty --backend posix --protocol ascii "
             "--poses plan.csv --out plan.csv --quiet >/dev/null 2>acquire.err",
             dir_, RCAL_BINARY_DIR, dir_);
    assert_int_equal(WEXITSTATUS(system(cmd)), 1);
    assert_true(err_contains("--poses"));
    snprintf(cmd, sizeof cmd,
             "cd %s && timeout 10 %s/tools/rcal acquire --port %s/no-such-tty --backend posix --protocol ascii "
             "--poses plan.csv --out /dev/full --quiet >/dev/null 2>acquire.err",
             dir_, RCAL_BINARY_DIR, dir_);
    assert_int_equal(WEXITSTATUS(system(cmd)), 1);
    assert_true(err_contains("not a regular file"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nul_mid_file_refused),
        cmocka_unit_test(test_long_mid_line_refused),
        cmocka_unit_test(test_unfinished_last_line_saved),
        cmocka_unit_test(test_out_of_range_numbers_refused),
        cmocka_unit_test(test_outputs_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
