/* test_robust_known.c - KNOWN BUGS found by the hardening work (issue 7).
 *
 * Each test here FAILS on the current code and documents a defect in a file
 * this suite does not own, with the fix proposed in its comment and in the
 * hardening report. The ctest entry is DISABLED so CI stays green;
 * run it by hand to check a fix:
 *     ctest -R robust_known_issues   (shows "Disabled")
 *     ./tests/robust/robust_known_issues
 * When a fix lands, move the test into test_robust_solve.c.
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


/* Fixed since (tests moved to test_robust_solve.c):
 *  - rc_encoder_guess took coplanar flange points in an oblique plane for a
 *    valid pose set (RC_OK, outlet 1.9 m off): coplanarity is now judged by
 *    the smallest scatter eigenvalue;
 *  - one wild length gave RC_OK and an outlet 2.9e13 mm away: now refused
 *    by the sphere-consistency check (RC_ERR_RANGE). */

/* BUG (tools/cmd_acquire.c, scan_existing): resuming an acquisition
 * reads the existing output with fgets(line, 1024) and takes the first line
 * that does not end in '\n' for "an unfinished last line (interrupted
 * write)": it stops there and ftruncate()s the file. A NUL byte inside a line
 * (strlen stops at it) or a line longer than 1023 bytes anywhere in the
 * middle of the file is taken for that, and every sample after it is
 * deleted - acquired data lost, before the port is even opened.
 * Fix: drop a line without '\n' only when it is the end of the file (the
 * next fgetc is EOF); anywhere else refuse ("line N is damaged") and leave
 * the file alone; read lines with getline() so that a NUL is seen
 * (returned length != strlen). */
static void test_acquire_resume_keeps_samples(void **state)
{
    (void)state;
    const char *dir = RCAL_BINARY_DIR "/tests/robust/known_acq";
    char path[1024], cmd[4096];
    (void)mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/plan.csv", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n10,0,0,0,0,0\n20,0,0,0,0,0\n", f);
    fclose(f);
    static const char data[] =
        "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms\n"
        "0,0.0000,0.0000,0.0000,0.0000,0.0000,0.0000,500.1000,0.0100,5,1700000000000\n"
        "1,10.0000,0.0000,0.0000,0.0000,0.0000,0.0000,501.\0000,0.0100,5,1700000000001\n" /* NUL */
        "2,20.0000,0.0000,0.0000,0.0000,0.0000,0.0000,502.1000,0.0100,5,1700000000002\n";
    snprintf(path, sizeof path, "%s/data.csv", dir);
    f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, sizeof data - 1, f), sizeof data - 1);
    fclose(f);
    snprintf(cmd, sizeof cmd,
             "cd %s && timeout 30 %s/tools/rcal acquire --port %s/no-such-tty --backend posix --protocol ascii "
             "--poses plan.csv --out data.csv --reconnect-s 0 --quiet >/dev/null 2>&1",
             dir, RCAL_BINARY_DIR, dir);
    int st = system(cmd);
    (void)st;
    struct stat sb;
    assert_int_equal(stat(path, &sb), 0);
    print_message("data.csv: %lld bytes before, %lld after rcal acquire tried to resume\n",
                  (long long)(sizeof data - 1), (long long)sb.st_size);
    assert_int_equal((long long)sb.st_size, (long long)(sizeof data - 1)); /* nothing deleted */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_acquire_resume_keeps_samples),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
