/* SPDX-License-Identifier: MIT */
/* test_inputs.c - readers that never accept a wrong input in silence
 * (issue 47, item 7, part 1), in-process:
 *  - joint target lists (RCH_DATA_TARGETS, rcal-rt --in): the header
 *    recognised by its names, 0x10, 1e, inf, nan refused with
 *    file:line:col, BOM and CR / LF / CRLF lines counted;
 *  - joint targets that look like radians (rch_data_q_look_rad), in CSV and
 *    RAPID through the compensation (nothing written), and the programs in
 *    degrees the rule must let through;
 *  - model files: an unknown key refused with line:col and the nearest key,
 *    DH angles in radians refused with the key and line:col, CR-only lines
 *    counted;
 *  - RAPID modules with a BOM and CR, LF or CRLF line ends: read, line:col
 *    right, and the output keeping the input's bytes;
 *  - write errors naming the file and the reason (ENOSPC from /dev/full). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rc_comp.h"
#include "rch_acqfile.h"
#include "rch_comp.h"
#include "rch_data.h"
#include "rch_export.h"
#include "rch_rapid.h"
#include "rch_robot.h"
#include "rch_save.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define TRUTH RCAL_SOURCE_DIR "/data/sim_irb120_truth.json"
#define DEG (3.14159265358979323846 / 180.0)
#define TGT (RCH_DATA_TARGETS | RCH_DATA_NO_LEN)

static int targets(rch_data *d, rch_diag *dg, const char *text)
{
    memset(dg, 0, sizeof *dg);
    return rch_data_parse(d, text, strlen(text), "t.csv", TGT, dg);
}

/* 1-based column of the first occurrence of what in the line line (1-based) of text, 0 if absent */
static unsigned col_of(const char *text, unsigned line, const char *what)
{
    const char *p = text;
    for (unsigned l = 1; l < line && p; ++l) {
        p = strpbrk(p, "\r\n");
        if (p && p[0] == '\r' && p[1] == '\n')
            ++p;
        if (p)
            ++p;
    }
    if (!p)
        return 0;
    const size_t len = strcspn(p, "\r\n");
    const char *hit = strstr(p, what);
    return hit && (size_t)(hit - p) < len ? (unsigned)(hit - p) + 1 : 0;
}

static unsigned line_of(const char *text, const char *what)
{
    const char *p = strstr(text, what);
    unsigned line = 1;
    assert_non_null(p);
    for (const char *q = text; q < p; ++q)
        line += *q == '\n';
    return line;
}

/* ---- joint target lists ---- */

static void test_targets_header_by_names(void **state)
{
    (void)state;
    rch_data d;
    rch_diag dg;
    /* no header: the first line is the first target */
    assert_int_equal(targets(&d, &dg, "10,20,-30,40,50,60\n11,21,-31,41,51,61\n"), 0);
    assert_int_equal(d.n, 2);
    assert_int_equal(d.line[0], 1);
    assert_true(fabs(d.s[1].q_rad[5] - 61.0 * DEG) < 1e-12);
    rch_data_free(&d);
    /* a header by its names (any case, other columns read by name) */
    assert_int_equal(targets(&d, &dg, "speed,Q1,q2,q3,q4,q5,q6\n100,10,20,-30,40,50,60\n"), 0);
    assert_int_equal(d.n, 1);
    assert_int_equal(d.line[0], 2);
    assert_true(fabs(d.s[0].q_rad[0] - 10.0 * DEG) < 1e-12);
    rch_data_free(&d);
    /* a first line that names no column is a target: its words are refused, never taken for a header */
    const char *bad = "joint1,joint2,joint3,joint4,joint5,joint6\n10,20,-30,40,50,60\n";
    assert_int_equal(targets(&d, &dg, bad), -1);
    assert_int_equal(dg.line, 1);
    assert_int_equal(dg.col, 1);
    assert_non_null(strstr(dg.msg, "'joint1' is not a number"));
    assert_null(d.s);
    /* a bad first row is refused the same way, not skipped as a header */
    assert_int_equal(targets(&d, &dg, "10,20,-30,4O,50,60\n10,20,-30,40,50,60\n"), -1);
    assert_int_equal(dg.line, 1);
    assert_int_equal(dg.col, col_of("10,20,-30,4O,50,60", 1, "4O"));
    /* a seventh field without a header is refused, not dropped */
    assert_int_equal(targets(&d, &dg, "10,20,-30,40,50,60,70\n"), -1);
    assert_int_equal(dg.line, 1);
    assert_non_null(strstr(dg.msg, "q1..q6"));
}

static void test_targets_numbers(void **state)
{
    (void)state;
    static const struct {
        const char *text, *field, *says;
    } bad[] = {
        {"0x10,20,-30,40,50,60\n", "0x10", "hexadecimal"},
        {"q1,q2,q3,q4,q5,q6\n10,20,1e,40,50,60\n", "1e", "not a number"},
        {"q1,q2,q3,q4,q5,q6\n10,20,-30,inf,50,60\n", "inf", "not finite"},
        {"10,20,-30,40,50,nan\n", "nan", "not finite"},
        {"10,20,-30,40,50,60\n10,20,-30,40,50,0x1p3\n", "0x1p3", "hexadecimal"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        rch_data d;
        rch_diag dg;
        assert_int_equal(targets(&d, &dg, bad[k].text), -1);
        const unsigned line = line_of(bad[k].text, bad[k].field);
        assert_int_equal(dg.line, line);
        assert_int_equal(dg.col, col_of(bad[k].text, line, bad[k].field));
        assert_string_equal(dg.file, "t.csv");
        if (!strstr(dg.msg, bad[k].says))
            fail_msg("%s: '%s' does not say %s", bad[k].field, dg.msg, bad[k].says);
    }
}

static void test_targets_bom_and_line_ends(void **state)
{
    (void)state;
    static const char *const eol[] = {"\n", "\r\n", "\r"};
    for (size_t k = 0; k < 3; ++k) {
        char text[256];
        snprintf(text, sizeof text, "\xEF\xBB\xBFq1,q2,q3,q4,q5,q6%s10,20,-30,40,50,60%s%s11,20,-30,40,50,x%s", eol[k],
                 eol[k], eol[k], eol[k]);
        rch_data d;
        rch_diag dg;
        assert_int_equal(targets(&d, &dg, text), -1);
        assert_int_equal(dg.line, 4); /* the blank line counted too */
        assert_int_equal(dg.col, col_of(text, 4, "x"));
        text[strlen(text) - strlen(eol[k]) - 1] = '0';
        assert_int_equal(targets(&d, &dg, text), 0);
        assert_int_equal(d.n, 2);
        assert_int_equal(d.line[1], 4);
        rch_data_free(&d);
    }
}

/* ---- radians where degrees are read ---- */

static void test_radians_rule(void **state)
{
    (void)state;
    char why[320];
    const double rad[6] = {0.5, 1.2, 0.9, 0.1, 1.5708, 3.1416}; /* a program in radians, largest |q| per joint */
    assert_int_equal(rch_data_q_look_rad(why, sizeof why, rad, 3), 1);
    assert_non_null(strstr(why, "radians"));
    assert_non_null(strstr(why, "3 targets"));
    const double one[6] = {0.0, 0.0, 0.0, 0.0, 1.5708, 0.0}; /* one joint moving: no verdict */
    assert_int_equal(rch_data_q_look_rad(why, sizeof why, one, 5), 0);
    const double zero[6] = {0}; /* a home position */
    assert_int_equal(rch_data_q_look_rad(why, sizeof why, zero, 40), 0);
    const double deg[6] = {0.5, 1.2, 0.9, 0.1, 30.0, 3.0}; /* degrees: one joint beyond pi */
    assert_int_equal(rch_data_q_look_rad(why, sizeof why, deg, 40), 0);
    const double small[6] = {2.0, 3.5, 1.0, 0.0, 0.0, 0.0}; /* small angles in degrees, q2 past pi */
    assert_int_equal(rch_data_q_look_rad(why, sizeof why, small, 40), 0);
}

/* A stream on the simulated truth against the nominal IRB120 (static: one at a time). */
static rc_comp_stream *stream_on_truth(rch_robot *truth, rch_robot *nominal)
{
    static rc_comp_stream s;
    rch_diag d;
    assert_int_equal(rch_robot_load(truth, TRUTH, &d), 0);
    assert_int_equal(rch_robot_load(nominal, ROBOT, &d), 0);
    assert_int_equal(rc_comp_stream_init(&s, &truth->model, &nominal->model, NULL), RC_OK);
    return &s;
}

/* text through rch_comp_lines: its return, the output in out (size outn), d set */
static int comp_text(char *out, size_t outn, const char *text, size_t len, rch_comp_format fmt, rch_diag *d)
{
    static rch_robot truth, nominal;
    rc_comp_stream *s = stream_on_truth(&truth, &nominal);
    FILE *in = fmemopen((void *)(uintptr_t)text, len, "r"), *o = tmpfile();
    assert_non_null(in);
    assert_non_null(o);
    rch_comp_result r;
    memset(&r, 0, sizeof r);
    memset(d, 0, sizeof *d);
    const int rc = rch_comp_lines(o, &r, in, "in", s, &truth.model, fmt, NULL, d);
    fflush(o);
    const long n = ftell(o);
    assert_true(n >= 0 && (size_t)n < outn);
    rewind(o);
    assert_int_equal(fread(out, 1, (size_t)n, o), (size_t)n);
    out[n] = '\0';
    fclose(in);
    fclose(o);
    return rc;
}

static void test_comp_radians(void **state)
{
    (void)state;
    char out[8192];
    rch_diag d;
    /* a CSV program in radians: refused, nothing written */
    const char *rad = "q1,q2,q3,q4,q5,q6\n0.1,0.3,-0.5,0.7,0.9,1.0\n0.2,0.3,-0.5,0.7,0.9,1.0\n0.3,0.35,-0.5,0.7,0.9,1.0\n";
    assert_int_equal(comp_text(out, sizeof out, rad, strlen(rad), RCH_COMP_AUTO, &d), -1);
    assert_string_equal(out, "");
    assert_non_null(strstr(d.msg, "look like radians"));
    assert_non_null(strstr(d.msg, "--assume-degrees"));
    /* --format csv likewise */
    assert_int_equal(comp_text(out, sizeof out, rad + 18, strlen(rad + 18), RCH_COMP_CSV, &d), -1);
    assert_string_equal(out, "");
    assert_non_null(strstr(d.msg, "look like radians"));
    /* a single target likewise */
    const char *one = "0.5,-0.3,0.2,0,1.2,0\n";
    assert_int_equal(comp_text(out, sizeof out, one, strlen(one), RCH_COMP_AUTO, &d), -1);
    assert_string_equal(out, "");
    /* programs in degrees go through: small angles with one joint past pi, one joint moving, a home */
    const char *ok[] = {"q1,q2,q3,q4,q5,q6\n1.5,2.5,-1,0.5,30,0\n1.6,2.4,-1,0.5,31,0\n",
                        "0,0,0,0,1.5,0\n0,0,0,0,2.5,0\n", "0,0,0,0,0,0\n"};
    for (size_t k = 0; k < 3; ++k) {
        const int rc = comp_text(out, sizeof out, ok[k], strlen(ok[k]), RCH_COMP_AUTO, &d);
        if (rc < 0)
            fail_msg("a program in degrees refused: %s", d.msg);
        size_t lines_in = 0, lines_out = 0;
        for (const char *p = ok[k]; *p; ++p)
            lines_in += *p == '\n';
        for (const char *p = out; *p; ++p)
            lines_out += *p == '\n';
        assert_int_equal(lines_out, lines_in); /* every target written */
    }
    /* RAPID jointtargets in radians: refused at the first one, nothing written */
    const char *mod = "MODULE M\n  CONST jointtarget a := [[0.1,0.3,-0.5,0.7,0.9,1],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                      "  CONST jointtarget b := [[0.2,0.3,-0.5,0.7,0.9,1],[9E9,9E9,9E9,9E9,9E9,9E9]];\nENDMODULE\n";
    assert_int_equal(comp_text(out, sizeof out, mod, strlen(mod), RCH_COMP_AUTO, &d), -1);
    assert_string_equal(out, "");
    assert_int_equal(d.line, 2);
    assert_int_equal(d.col, col_of(mod, 2, "[["));
    assert_non_null(strstr(d.msg, "radians"));
}

/* ---- RAPID: BOM and line ends ---- */

static void test_rapid_line_ends(void **state)
{
    (void)state;
    static const char *const eol[] = {"\n", "\r\n", "\r"};
    for (size_t k = 0; k < 3; ++k) {
        const char *e = eol[k];
        char text[1024];
        snprintf(text, sizeof text,
                 "\xEF\xBB\xBFMODULE M%s  ! a comment%s  CONST jointtarget a := [[10,20,-30,40,50,60],"
                 "[9E9,9E9,9E9,9E9,9E9,9E9]];%s  CONST jointtarget b := [[11,21,-31,41,51,61],"
                 "[9E9,9E9,9E9,9E9,9E9,9E9]];%sENDMODULE%s",
                 e, e, e, e, e);
        rch_rapid_targets ts;
        rch_diag d;
        memset(&ts, 0, sizeof ts);
        assert_int_equal(rch_rapid_scan(&ts, text, strlen(text), "m.mod", &d), 0);
        assert_int_equal(ts.n, 2); /* the comment ends at its line's end, whatever it is */
        assert_int_equal(ts.t[0].line, 3);
        assert_int_equal(ts.t[1].line, 4);
        assert_int_equal(ts.t[1].col, col_of(text, 4, "[["));
        assert_int_equal(ts.t[0].num_col[3], col_of(text, 3, "40"));
        rch_rapid_free(&ts);
        /* through the compensation: every byte but the numbers as it was */
        char out[4096];
        assert_true(comp_text(out, sizeof out, text, strlen(text), RCH_COMP_AUTO, &d) >= 0);
        assert_memory_equal(out, "\xEF\xBB\xBFMODULE M", 11);
        size_t n_in = 0, n_out = 0;
        for (const char *p = text; (p = strstr(p, e)) != NULL; p += strlen(e))
            ++n_in;
        for (const char *p = out; (p = strstr(p, e)) != NULL; p += strlen(e))
            ++n_out;
        assert_int_equal(n_out, n_in);
        const size_t tail = strlen("[9E9,9E9,9E9,9E9,9E9,9E9]];") + strlen(e) + strlen("ENDMODULE") + strlen(e);
        assert_true(strlen(out) > tail);
        assert_memory_equal(out + strlen(out) - tail, text + strlen(text) - tail, tail);
        if (k != 0)
            for (const char *p = out; (p = strchr(p, '\n')) != NULL; ++p)
                assert_true(p > out && p[-1] == '\r'); /* no LF alone */
        /* a wrong target is named at its line whatever the line ends */
        char bad[1024];
        snprintf(bad, sizeof bad, "MODULE M%s%s  CONST jointtarget a := [[10,20,-30,40,50,x],[9E9,9E9,9E9,9E9,9E9,9E9]];%s"
                 "ENDMODULE%s", e, e, e, e);
        assert_int_equal(comp_text(out, sizeof out, bad, strlen(bad), RCH_COMP_AUTO, &d), -1);
        assert_int_equal(d.line, 3);
    }
}

/* a CSV program through the compensation keeps its BOM and its line ends */
static void test_comp_csv_line_ends(void **state)
{
    (void)state;
    static const char *const eol[] = {"\r\n", "\r"};
    for (size_t k = 0; k < 2; ++k) {
        char text[256], out[1024];
        rch_diag d;
        snprintf(text, sizeof text, "\xEF\xBB\xBFid,q1,q2,q3,q4,q5,q6%sa,10,20,-30,40,50,60%s# note%sb,11,20,-30,40,50,60%s",
                 eol[k], eol[k], eol[k], eol[k]);
        const int rc = comp_text(out, sizeof out, text, strlen(text), RCH_COMP_AUTO, &d);
        if (rc < 0)
            fail_msg("%s", d.msg);
        const size_t head = strlen("\xEF\xBB\xBFid,q1,q2,q3,q4,q5,q6") + strlen(eol[k]);
        assert_memory_equal(out, text, head);
        size_t n = 0;
        for (const char *p = out; (p = strstr(p, eol[k])) != NULL; p += strlen(eol[k]))
            ++n;
        assert_int_equal(n, 4);
        assert_non_null(strstr(out, "# note"));
        if (k == 1)
            assert_null(strchr(out, '\n'));
    }
}

/* ---- model files ---- */

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char buf[1 << 16];
    const size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return buf;
}

/* text with the first `from` replaced by `to` into out */
static void replace1(char *out, size_t n, const char *text, const char *from, const char *to)
{
    const char *p = strstr(text, from);
    assert_non_null(p);
    snprintf(out, n, "%.*s%s%s", (int)(p - text), text, to, p + strlen(from));
}

static void test_model_unknown_keys(void **state)
{
    (void)state;
    const char *irb = read_text(ROBOT);
    static const struct {
        const char *from, *to, *key, *near;
    } typo[] = {
        {"\"joint_limits_deg\"", "\"joint_limit_deg\"", "\"joint_limit_deg\"", "did you mean joint_limits_deg?"},
        {"\"name\"", "\"encoder_xyz_mm\": [0, 0, 0], \"name\"", "\"encoder_xyz_mm\"", "did you mean encoder_mm?"},
        {"\"alpha_deg\"", "\"alpha_dg\"", "\"alpha_dg\"", "did you mean alpha_deg?"},
        {"\"format\"", "\"frobnicate\": 1, \"format\"", "\"frobnicate\"", "its keys: format, name, dh"},
    };
    for (size_t k = 0; k < sizeof typo / sizeof typo[0]; ++k) {
        char text[8192];
        replace1(text, sizeof text, irb, typo[k].from, typo[k].to);
        static rch_robot r;
        rch_diag d;
        memset(&d, 0, sizeof d);
        assert_int_equal(rch_robot_parse(&r, text, strlen(text), "r.json", &d), -1);
        assert_string_equal(d.file, "r.json");
        const char *quoted = typo[k].key;
        assert_int_equal(d.line, line_of(text, quoted));
        assert_int_equal(d.col, col_of(text, d.line, quoted));
        if (!strstr(d.msg, typo[k].near) || !strstr(d.msg, "unknown key"))
            fail_msg("%s: '%s' does not say '%s'", quoted, d.msg, typo[k].near);
    }
    /* the model files the project ships and writes still read */
    const char *const files[] = {ROBOT, TRUTH, RCAL_SOURCE_DIR "/data/kr6.json", RCAL_SOURCE_DIR "/firmware_host/fw_model.json",
                                 RCAL_SOURCE_DIR "/tests/system/golden/cal_out/model.json",
                                 RCAL_SOURCE_DIR "/tests/system/golden/diag_json/model.json",
                                 RCAL_SOURCE_DIR "/tests/system/golden/cal_outlets/model.json",
                                 RCAL_SOURCE_DIR "/tests/system/golden/cal_pos/model.json",
                                 RCAL_SOURCE_DIR "/tests/system/golden/real_cal_jumps_dq/model.json"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; ++k) {
        static rch_robot r;
        rch_diag d;
        if (rch_robot_load(&r, files[k], &d) != 0)
            fail_msg("%s no longer reads: %s", files[k], d.msg);
    }
}

static void test_model_radians(void **state)
{
    (void)state;
    static rch_robot nom;
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, ROBOT, &d), 0);
    for (int col = 2; col < 4; ++col) { /* alpha, then theta, written in radians */
        char text[4096];
        int n = snprintf(text, sizeof text, "{\n  \"format\": \"rcal-model/1\",\n  \"dh\": [\n");
        for (int i = 0; i < RC_NJ; ++i) {
            const double *x = &nom.model.x[4 * i];
            const double al = col == 2 ? x[2] : x[2] / DEG, th = col == 3 ? x[3] : x[3] / DEG;
            n += snprintf(text + n, sizeof text - (size_t)n,
                          "    {\"a_mm\": %.6g, \"d_mm\": %.6g, \"alpha_deg\": %.4f, \"theta_deg\": %.4f}%s\n", x[0],
                          x[1], al, th, i < RC_NJ - 1 ? "," : "");
        }
        snprintf(text + n, sizeof text - (size_t)n, "  ]\n}\n");
        static rch_robot r;
        memset(&d, 0, sizeof d);
        assert_int_equal(rch_robot_parse(&r, text, strlen(text), "rad.json", &d), -1);
        const char *key = col == 2 ? "\"alpha_deg\": -1.5708" : "\"theta_deg\": -1.5708";
        const unsigned line = line_of(text, key);
        assert_int_equal(d.line, line);
        assert_int_equal(d.col, col_of(text, line, key) + (unsigned)strlen(col == 2 ? "\"alpha_deg\": " : "\"theta_deg\": "));
        assert_non_null(strstr(d.msg, col == 2 ? "alpha_deg" : "theta_deg"));
        assert_non_null(strstr(d.msg, "radians"));
    }
    /* a table of zero twists and offsets (a test arm) is no verdict */
    const char *zero = "{\"dh\": [{\"a_mm\": 0, \"d_mm\": 290, \"alpha_deg\": 0, \"theta_deg\": 0},"
                       "{\"a_mm\": 270, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": 0},"
                       "{\"a_mm\": 70, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": 0},"
                       "{\"a_mm\": 0, \"d_mm\": 302, \"alpha_deg\": 0, \"theta_deg\": 0},"
                       "{\"a_mm\": 0, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": 0},"
                       "{\"a_mm\": 0, \"d_mm\": 72, \"alpha_deg\": 0, \"theta_deg\": 0}]}";
    static rch_robot r;
    assert_int_equal(rch_robot_parse(&r, zero, strlen(zero), "zero.json", &d), 0);
}

static void test_model_cr_lines(void **state)
{
    (void)state;
    const char *irb = read_text(ROBOT);
    char text[8192], cr[8192];
    replace1(text, sizeof text, irb, "\"alpha_deg\": 0,", "\"alpha_deg\": x,");
    const unsigned line = line_of(text, "\"alpha_deg\": x");
    size_t k = 0;
    cr[k++] = '\xEF';
    cr[k++] = '\xBB';
    cr[k++] = '\xBF';
    for (const char *p = text; *p && k + 1 < sizeof cr; ++p)
        cr[k++] = *p == '\n' ? '\r' : *p;
    cr[k] = '\0';
    static rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_parse(&r, cr, strlen(cr), "cr.json", &d), -1);
    assert_int_equal(d.line, line);
    assert_int_equal(d.col, col_of(text, line, "x,"));
}

/* ---- write errors name the file and the reason ---- */

static int write_to_full(FILE *f, const void *ctx)
{
    (void)ctx;
    const int fd = open("/dev/full", O_WRONLY);
    if (fd < 0 || dup2(fd, fileno(f)) < 0)
        return -1;
    close(fd);
    for (int i = 0; i < 20000; ++i)
        fprintf(f, "%d,a line of a file that does not fit\n", i);
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}

static void test_write_errors(void **state)
{
    (void)state;
    if (access("/dev/full", W_OK) != 0)
        skip();
    char dir[] = "/tmp/rcal_inputs_XXXXXX", path[256];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/out.csv", dir);
    rch_diag d;
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_save(path, "--out", NULL, 0, write_to_full, NULL, &d), -1);
    assert_string_equal(d.file, path);
    assert_non_null(strstr(d.msg, strerror(ENOSPC)));
    assert_int_equal(access(path, F_OK), -1); /* nothing in its place */
    /* the export's writer */
    FILE *f = fopen("/dev/full", "w");
    assert_non_null(f);
    rch_export_result res;
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_export_file(&res, f, RCH_EXPORT_DH_CSV, TRUTH, NULL, 0, &d), -1);
    fclose(f);
    if (!strstr(d.msg, strerror(ENOSPC)))
        fail_msg("export: '%s' does not give the reason", d.msg);
    /* the acquisition file's appends */
    const double plan[2][RC_NJ] = {{10, 20, 30, 0, 45, 0}, {11, 20, 30, 0, 45, 0}};
    unsigned char done[2];
    rch_acqfile a;
    rch_acqfile_state st;
    snprintf(path, sizeof path, "%s/acq.csv", dir);
    assert_int_equal(rch_acqfile_open(&a, &st, done, path, plan, 2, &d), 0);
    const int fd = open("/dev/full", O_WRONLY);
    assert_true(fd >= 0 && dup2(fd, a.fd) >= 0);
    close(fd);
    rc_stable_result sr;
    memset(&sr, 0, sizeof sr);
    sr.mean_mm = 500.0;
    sr.count = 5;
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_acqfile_append(&a, 0, plan[0], &sr, 0, &d), -1);
    assert_string_equal(d.file, path);
    assert_non_null(strstr(d.msg, strerror(ENOSPC)));
    rch_acqfile_close(&a, NULL);
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_targets_header_by_names),
        cmocka_unit_test(test_targets_numbers),
        cmocka_unit_test(test_targets_bom_and_line_ends),
        cmocka_unit_test(test_radians_rule),
        cmocka_unit_test(test_comp_radians),
        cmocka_unit_test(test_rapid_line_ends),
        cmocka_unit_test(test_comp_csv_line_ends),
        cmocka_unit_test(test_model_unknown_keys),
        cmocka_unit_test(test_model_radians),
        cmocka_unit_test(test_model_cr_lines),
        cmocka_unit_test(test_write_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
