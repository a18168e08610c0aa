/* SPDX-License-Identifier: MIT */
/* test_robust_parsers.c - parser regressions found by fuzzing (issue 7), and
 * a replay of the checked-in fuzz seed corpora through the host parsers in
 * the ordinary build (so the sanitizer and valgrind runs of ctest cover them
 * without clang/libFuzzer).
 *
 * Regressions:
 *  - fuzz_csv: a t column holding 1e308 and -1e308 made t_max - t_min
 *    overflow to infinity and every scaled t NaN (rch_data.c now refuses
 *    |t| > 1e300).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_data.h"
#include "rch_json.h"
#include "rch_robot.h"

static void test_csv_t_overflow(void **state)
{
    static const char text[] = "t,q1,q2,q3,q4,q5,q6,L\n"
                               "1e308,0,0,0,0,0,0,500\n"
                               "-1e308,0,0,0,0,0,0,500\n";
    rch_data d;
    rch_diag diag;
    (void)state;
    memset(&diag, 0, sizeof diag);
    int rc = rch_data_parse(&d, text, sizeof text - 1, "t.csv", 0, &diag);
    if (rc == 0) {
        for (size_t i = 0; i < d.n; ++i)
            assert_true(isfinite(d.s[i].t) && d.s[i].t >= 0.0 && d.s[i].t <= 1.0);
        rch_data_free(&d);
    } else {
        assert_int_equal(diag.line, 2);
        assert_int_equal(diag.col, 1);
        print_message("refused as expected: %s\n", diag.msg);
    }
    /* a wide but sane t range still scales to [0, 1] */
    static const char ok[] = "t,q1,q2,q3,q4,q5,q6,L\n"
                             "1e300,0,0,0,0,0,0,500\n"
                             "-1e300,0,0,0,0,0,0,500\n"
                             "0,0,0,0,0,0,0,500\n";
    assert_int_equal(rch_data_parse(&d, ok, sizeof ok - 1, "ok.csv", 0, &diag), 0);
    assert_true(d.s[0].t == 1.0 && d.s[1].t == 0.0 && fabs(d.s[2].t - 0.5) < 1e-12);
    rch_data_free(&d);
}

/* Read a whole file into an exact-size heap buffer (no NUL after it). */
static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        buf = malloc(n ? (size_t)n : 1u);
        if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
            free(buf);
            buf = NULL;
        }
        *len = (size_t)n;
    }
    fclose(f);
    return buf;
}

typedef void (*replay_fn)(const char *text, size_t len, const char *name);

static void replay_csv(const char *text, size_t len, const char *name)
{
    rch_data d;
    rch_diag diag;
    for (unsigned flags = 0; flags <= RCH_DATA_NO_LEN; flags += RCH_DATA_NO_LEN) {
        if (rch_data_parse(&d, text, len, name, flags, &diag) == 0) {
            for (size_t i = 0; i < d.n; ++i)
                assert_true(isfinite(d.s[i].t) && isfinite(d.s[i].value));
            rch_data_free(&d);
        } else {
            assert_true(diag.msg[0] != '\0');
        }
    }
}

static void replay_json(const char *text, size_t len, const char *name)
{
    rch_diag diag;
    rch_json *j = rch_json_parse(text, len, name, &diag);
    if (j)
        rch_json_free(j);
    else
        assert_true(diag.msg[0] != '\0');
}

static void replay_robot(const char *text, size_t len, const char *name)
{
    static rch_robot r;
    rch_diag diag;
    if (rch_robot_parse(&r, text, len, name, &diag) == 0) {
        for (unsigned k = 0; k < r.model.n_params; ++k)
            assert_true(isfinite(r.model.x[k]));
    } else {
        assert_true(diag.msg[0] != '\0');
    }
}

static unsigned replay_dir(const char *sub, replay_fn fn)
{
    char dir[1024], path[2048];
    unsigned n = 0;
    snprintf(dir, sizeof dir, "%s/fuzz/corpus/%s", RCAL_SOURCE_DIR, sub);
    DIR *dp = opendir(dir);
    if (!dp)
        return 0;
    struct dirent *e;
    while ((e = readdir(dp)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        size_t len = 0;
        char *text = slurp(path, &len);
        if (!text)
            continue;
        fn(text, len, e->d_name);
        free(text);
        ++n;
    }
    closedir(dp);
    return n;
}

static void test_replay_corpora(void **state)
{
    (void)state;
    unsigned n = replay_dir("fuzz_csv", replay_csv) + replay_dir("fuzz_plan", replay_csv);
    unsigned j = replay_dir("fuzz_json", replay_json) + replay_dir("fuzz_robot", replay_json);
    unsigned r = replay_dir("fuzz_robot", replay_robot) + replay_dir("fuzz_json", replay_robot);
    print_message("replayed %u CSV, %u JSON, %u model inputs\n", n, j, r);
    assert_true(n > 0 && j > 0 && r > 0);
}

/* Truncation at every byte of a valid model file and of a valid CSV file:
 * each prefix is refused with a message or accepted, never a crash. */
static void test_every_truncation(void **state)
{
    size_t len = 0;
    (void)state;
    char *text = slurp(RCAL_SOURCE_DIR "/data/irb120.json", &len);
    assert_non_null(text);
    for (size_t k = 0; k <= len; ++k) {
        char *p = malloc(k ? k : 1);
        assert_non_null(p);
        memcpy(p, text, k);
        replay_robot(p, k, "trunc.json");
        free(p);
    }
    free(text);
    static const char csv[] = "x,y,z,q1,q2,q3,q4,q5,q6,L\n"
                              "106.2,-451.9,498.9,-74.5,33.9,-30.8,-15.1,80.5,-59.7,509.19\n"
                              "164.4,-433.8,499.5,-67.0,33.8,-30.8,-15.1,80.5,-59.7,498.04\n";
    for (size_t k = 0; k < sizeof csv; ++k) {
        char *p = malloc(k ? k : 1);
        assert_non_null(p);
        memcpy(p, csv, k);
        replay_csv(p, k, "trunc.csv");
        free(p);
    }
}

/* Files other programs write (issue 12): what rch_data accepts, and what it
 * names instead of "header has no 'q1'". */
static int parse_text(rch_data *d, rch_diag *dg, const char *text, size_t len, unsigned flags)
{
    int rc = rch_data_parse(d, text, len, "x.csv", flags, dg);
    if (rc != 0) {
        char buf[900];
        print_message("%s\n", rch_diag_str(dg, buf, sizeof buf));
    }
    return rc;
}

static void expect_refused(const char *text, size_t len, const char *needle)
{
    rch_data d;
    rch_diag dg;
    assert_int_equal(parse_text(&d, &dg, text, len, 0), -1);
    if (!strstr(dg.msg, needle))
        fail_msg("message '%s' does not contain '%s'", dg.msg, needle);
}

static void test_csv_conventions(void **state)
{
    static const char bom[] = "\xEF\xBB\xBFq1,q2,q3,q4,q5,q6,L\n1,2,3,4,5,6,500\n";
    static const char cr[] = "q1,q2,q3,q4,q5,q6,L\r1,2,3,4,5,6,500\r7,8,9,10,11,12,600\r";
    static const char quoted[] = "\"q1\",\"q2\",\"q3\",\"q4\",\"q5\",\"q6\",\"L\"\n1,2,3,4,5,6,500\n";
    static const char nul_last[] = "q1,q2,q3,q4,q5,q6,L\n1,2,3,4,5,6,500\n\0\0\0\0\0\0\0\0";
    static const char nul_mid[] = "q1,q2,q3,q4,q5,q6,L\n1,2,3,4,5,6,5\0\n1,2,3,4,5,6,500\n";
    rch_data d;
    rch_diag dg;
    (void)state;
    /* accepted: a byte-order mark, CR-only endings, quoted header names */
    assert_int_equal(parse_text(&d, &dg, bom, sizeof bom - 1, 0), 0);
    assert_int_equal(d.n, 1);
    assert_true(fabs(d.s[0].value - 500.0) < 1e-12);
    rch_data_free(&d);
    assert_int_equal(parse_text(&d, &dg, cr, sizeof cr - 1, 0), 0);
    assert_int_equal(d.n, 2);
    assert_true(fabs(d.s[1].value - 600.0) < 1e-12);
    assert_int_equal(d.line[1], 3);
    rch_data_free(&d);
    assert_int_equal(parse_text(&d, &dg, quoted, sizeof quoted - 1, 0), 0);
    assert_int_equal(d.n, 1);
    rch_data_free(&d);
    /* named: other separators, quoted numbers, hex floats, NULs */
    expect_refused("q1\tq2\tq3\tq4\tq5\tq6\tL\n1\t2\t3\t4\t5\t6\t500\n", 36, "separated by tabs");
    expect_refused("q1;q2;q3;q4;q5;q6;L\n1;2;3;4;5;6;500\n", 36, "separated by semicolons");
    expect_refused("q1,q2,q3,q4,q5,q6,L\n1,2,3,4,5,6,\"500\"\n", 38, "quoted: write numbers without quotes");
    expect_refused("q1,q2,q3,q4,q5,q6,L\n1,2,3,4,5,6,0x1.8p+9\n", 41, "hexadecimal numbers are not accepted");
    expect_refused(nul_last, sizeof nul_last - 1, "power cut");
    expect_refused(nul_last, sizeof nul_last - 1, ".dropped");
    expect_refused(nul_mid, sizeof nul_mid - 1, "NUL byte in text");
    /* the acquisition file's columns: pose read on request, other columns ignored */
    {
        static const char acq[] = "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms\n"
                                  "3,1,2,3,4,5,6,500.25,0.01,5,1700000000000\n";
        assert_int_equal(parse_text(&d, &dg, acq, sizeof acq - 1, RCH_DATA_POSE), 0);
        assert_non_null(d.pose);
        assert_int_equal(d.pose[0], 3);
        rch_data_free(&d);
        assert_int_equal(parse_text(&d, &dg, acq, (size_t)(strchr(acq, '\n') - acq) + 1, RCH_DATA_POSE | RCH_DATA_ALLOW_EMPTY), 0);
        assert_int_equal(d.n, 0);
        rch_data_free(&d);
        assert_int_equal(parse_text(&d, &dg, acq + 5, sizeof acq - 6, RCH_DATA_POSE), -1);
        assert_non_null(strstr(dg.msg, "no 'pose' column"));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_csv_t_overflow),
        cmocka_unit_test(test_replay_corpora),
        cmocka_unit_test(test_every_truncation),
        cmocka_unit_test(test_csv_conventions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
