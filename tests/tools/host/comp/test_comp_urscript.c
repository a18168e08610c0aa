/* SPDX-License-Identifier: MIT */
/* test_comp_urscript.c - the URScript reader (issue 51): every instruction
 * form of the committed example found with its role, kind, numbers and
 * their bytes; literals in comments and strings left alone; each wrong
 * target of bad_targets.script listed with its error; a text that cannot be
 * read (a bracket not closed or closed by the other kind, a string not
 * closed, a NUL byte) refused at its line and column, with CR, LF and CRLF
 * line ends counted alike; the format detected from a first line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_urscript.h"
#include "rch_urscript_comp.h"

#define EVERY RCAL_SOURCE_DIR "/tests/tools/host/comp/data/urscript/every_form.script"
#define BAD RCAL_SOURCE_DIR "/tests/tools/host/comp/data/urscript/bad_targets.script"

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char *b = malloc(1 << 20);
    assert_non_null(b);
    *len = fread(b, 1, (1 << 20) - 1, f);
    b[*len] = '\0';
    fclose(f);
    return b;
}

static void test_every_form(void **state)
{
    (void)state;
    size_t len;
    char *text = slurp(EVERY, &len);
    rch_urs_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    assert_int_equal(rch_urs_scan(&ts, text, len, "every_form.script", 1, &d), 0);
    unsigned by_role[6] = {0}, poses = 0, joints = 0;
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_urs_target *t = &ts.t[i];
        assert_string_equal(t->error, "");
        assert_int_equal(t->n, 6);
        by_role[t->role]++;
        poses += t->kind == RCH_URS_POSE;
        joints += t->kind == RCH_URS_JOINTS;
        /* each number's bytes are that number */
        for (unsigned k = 0; k < 6; ++k) {
            char b[64];
            assert_true(t->num_len[k] < sizeof b);
            memcpy(b, text + t->num_off[k], t->num_len[k]);
            b[t->num_len[k]] = '\0';
            assert_true(fabs(strtod(b, NULL) - t->val[k]) == 0.0);
            assert_true(t->num_off[k] > t->off && t->num_off[k] < t->end);
        }
        assert_true(t->kind == RCH_URS_POSE ? text[t->off] == 'p' : text[t->off] == '[');
        assert_int_equal(text[t->end - 1], ']');
        if (i > 0)
            assert_true(t->off >= ts.t[i - 1].end);
        /* get_inverse_kin's pose is tied to its qnear */
        if (t->role == RCH_URS_IK) {
            assert_true(t->qnear > (long)i);
            assert_int_equal(ts.t[t->qnear].role, RCH_URS_QNEAR);
        }
    }
    /* the file: 3 assignments, 2 set_tcp, 12 motion arguments, 2 get_inverse_kin with their qnear */
    assert_int_equal(by_role[RCH_URS_ASSIGN], 3);
    assert_int_equal(by_role[RCH_URS_TCP], 2);
    assert_int_equal(by_role[RCH_URS_MOVE], 12);
    assert_int_equal(by_role[RCH_URS_IK], 2);
    assert_int_equal(by_role[RCH_URS_QNEAR], 2);
    assert_int_equal(poses, 1 + 2 + 9 + 2);
    assert_int_equal(joints, 2 + 3 + 2);
    /* the second movec's end point by keyword, on its line and column */
    const rch_urs_target *last = NULL;
    for (size_t i = 0; i < ts.n; ++i)
        if (!strcmp(ts.t[i].instr, "movec"))
            last = &ts.t[i];
    assert_non_null(last);
    assert_int_equal(last->arg, 1);
    const char *ln = text;
    for (unsigned l = 1; l < last->line; ++l)
        ln = strchr(ln, '\n') + 1;
    assert_memory_equal(ln + last->col - 1, "p[", 2);
    assert_true(strstr(ln, "pose_to=p[") == ln + last->col - 1 - 8);
    rch_urs_free(&ts);
    free(text);
}

static void test_bad_targets(void **state)
{
    (void)state;
    size_t len;
    char *text = slurp(BAD, &len);
    rch_urs_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    assert_int_equal(rch_urs_scan(&ts, text, len, "bad_targets.script", 1, &d), 0);
    unsigned n_err = 0;
    for (size_t i = 0; i < ts.n; ++i)
        if (ts.t[i].error[0]) {
            ++n_err;
            assert_int_equal(ts.t[i].n, 0);
        }
    /* pose_trans's pose, d2r, five numbers, qnear=qq, tcp=, my_move's list, p[.., x, ..] (the first pose,
     * the one out of reach and the joint beyond its limit are read: rcal compensate refuses them) */
    assert_int_equal(n_err, 7);
    rch_urs_free(&ts);
    free(text);
}

static void scan_fails(const char *text, unsigned line, unsigned col, const char *what)
{
    rch_urs_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_urs_scan(&ts, text, strlen(text) + (what[0] == 'N'), "t.script", 1, &d), -1);
    assert_int_equal(d.line, line);
    assert_int_equal(d.col, col);
    assert_non_null(strstr(d.msg, what));
    rch_urs_free(&ts);
}

static void test_unreadable(void **state)
{
    (void)state;
    scan_fails("def f():\n  movej([0,0,0,0,0,0]\nend\n", 2, 8, "not closed");
    scan_fails("def f():\r\n  movej([0,0,0,0,0,0]]\r\nend\r\n", 2, 22, "closes the '('");
    scan_fails("def f():\r  textmsg(\"abc)\rend\r", 2, 11, "string not closed");
    scan_fails("movej([0,0,0,0,0,0])\nmovej(1)", 2, 9, "NUL");
    scan_fails("x = 1\n)\n", 2, 1, "no bracket open");
}

static void test_literals_not_targets(void **state)
{
    (void)state;
    const char *text = "# movej(p[1,2,3,4,5,6])\n"
                       "textmsg(\"p[1,2,3,4,5,6]\")\n"
                       "force_mode(p[0,0,0,0,0,0], [0,0,1,0,0,0], [0,0,10,0,0,0], 2, [0.1,0.1,0.1,0.3,0.3,0.3])\n"
                       "if q == [0,0,0,0,0,0]:\n"
                       "  x = [1, 2, 3]\n"
                       "end\n";
    rch_urs_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    assert_int_equal(rch_urs_scan(&ts, text, strlen(text), "t.script", 1, &d), 0);
    /* only the comparison's six numbers are named (they cannot be told a joint target or not) */
    assert_int_equal(ts.n, 1);
    assert_int_equal(ts.t[0].line, 4);
    assert_int_equal(ts.t[0].col, 9);
    assert_non_null(strstr(ts.t[0].error, "cannot be told"));
    rch_urs_free(&ts);
}

static void test_detect(void **state)
{
    (void)state;
    assert_true(rch_cpi_urscript_detect("def prog():", 11));
    assert_true(rch_cpi_urscript_detect("  movej([0,0,0,0,0,0])", 22));
    assert_true(rch_cpi_urscript_detect("global wp = p[0,0,0,0,0,0]", 26));
    assert_false(rch_cpi_urscript_detect("10,20,30,40,50,60", 17));
    assert_false(rch_cpi_urscript_detect("q1,q2,q3,q4,q5,q6,name", 22));
    assert_false(rch_cpi_urscript_detect("my_movej(1)", 11));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_form),
        cmocka_unit_test(test_bad_targets),
        cmocka_unit_test(test_unreadable),
        cmocka_unit_test(test_literals_not_targets),
        cmocka_unit_test(test_detect),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
