/* SPDX-License-Identifier: MIT */
/* test_poses_link.c - the link programs of `rcal poses --format rapid-link|urscript-link` (issue 48): the
 * RAPID module read back by the project's RAPID reader (every jointtarget the plan's, to its 4 decimals), its
 * blocks balanced and the socket and standstill instructions present; the URScript's blocks balanced and
 * its calls those of the protocol; each AT reporting the pose's outlet and plate point (-1 without), and every
 * line's parentheses balanced. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_poses_link.h"
#include "rch_rapid.h"

#define N 5

/* outlets 0, 1, 0, 1, 0; plate points 2, 0, 1, 2, 0 */
static void plan(rc_sample rows[N], unsigned char lab[N], unsigned char pts[N])
{
    memset(rows, 0, sizeof(rc_sample) * N);
    for (int i = 0; i < N; ++i) {
        for (int j = 0; j < RC_NJ; ++j)
            rows[i].q_rad[j] = 0.1 * (i + 1) - 0.07 * j + 0.000123 * i;
        lab[i] = (unsigned char)(i % 2);
        pts[i] = (unsigned char)((i + 2) % 3);
    }
}

/* the program text; with_points: the plan's plate points (else none: every AT reports point -1) */
static char *write_to_text(int rapid, int with_points, size_t *len)
{
    rc_sample rows[N];
    unsigned char lab[N], pts[N];
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    assert_non_null(f);
    plan(rows, lab, pts);
    const unsigned char *p = with_points ? pts : NULL;
    assert_int_equal(rapid ? rch_poses_write_rapid_link(f, rows, lab, p, N, "192.168.125.5", 5150, "test")
                           : rch_poses_write_urscript_link(f, rows, lab, p, N, "127.0.0.1", 5150, "test"), 0);
    fclose(f);
    char *copy = malloc(*len + 1); /* a heap copy: GCC's dangling-pointer check does not follow open_memstream */
    assert_non_null(copy);
    memcpy(copy, buf, *len + 1);
    free(buf);
    return copy;
}

/* Every line's parentheses balance (outside strings; comments skipped). */
static void parens_balance(const char *t, char comment)
{
    int line = 1;
    for (const char *p = t; *p; ++line) {
        const char *e = strchr(p, '\n');
        const size_t n = e ? (size_t)(e - p) : strlen(p);
        int depth = 0, in_str = 0;
        for (size_t k = 0; k < n && (in_str || p[k] != comment); ++k) {
            if (p[k] == '"' && (k == 0 || p[k - 1] != '\\'))
                in_str = !in_str;
            else if (!in_str)
                depth += (p[k] == '(') - (p[k] == ')');
            if (depth < 0)
                fail_msg("line %d: a ) before its (: %.*s", line, (int)n, p);
        }
        if (depth != 0 || in_str)
            fail_msg("line %d: unbalanced: %.*s", line, (int)n, p);
        p += n + (e != NULL);
    }
}

/* The body of FUNC num name(num j) up to its ENDFUNC (a pointer into t, its length in *len). */
static const char *rapid_func(const char *t, const char *name, size_t *len)
{
    char head[80];
    snprintf(head, sizeof head, "FUNC num %s(num j)", name);
    const char *b = strstr(t, head), *e = b ? strstr(b, "ENDFUNC") : NULL;
    assert_non_null(b);
    assert_non_null(e);
    *len = (size_t)(e - b);
    return b;
}

/* Occurrences of word at line starts (after indentation). */
static int count_lead(const char *t, const char *word)
{
    int n = 0;
    const size_t wl = strlen(word);
    for (const char *p = t; p && *p; p = strchr(p, '\n'), p = p ? p + 1 : NULL) {
        const char *q = p + strspn(p, " ");
        n += strncmp(q, word, wl) == 0 && (q[wl] == ' ' || q[wl] == '\n' || q[wl] == '(' || q[wl] == ';');
    }
    return n;
}

static void test_rapid(void **state)
{
    size_t len;
    char *t = write_to_text(1, 0, &len);
    rch_rapid_targets ts;
    rch_diag d;
    rc_sample rows[N];
    unsigned char lab[N], pts[N];
    (void)state;
    plan(rows, lab, pts);
    memset(&ts, 0, sizeof ts);
    assert_int_equal(rch_rapid_scan(&ts, t, len, "link.mod", &d), 0);
    assert_int_equal(ts.n, N);
    for (size_t i = 0; i < ts.n; ++i) {
        assert_int_equal(ts.t[i].kind, RCH_RAPID_JOINTTARGET);
        assert_int_equal(ts.t[i].error[0], '\0');
        for (int j = 0; j < RC_NJ; ++j)
            assert_true(fabs(ts.t[i].val[j] - rows[i].q_rad[j] * 180.0 / 3.14159265358979323846) < 0.5e-4 + 1e-9);
    }
    rch_rapid_free(&ts);
    assert_int_equal(count_lead(t, "PROC"), count_lead(t, "ENDPROC"));
    assert_int_equal(count_lead(t, "FUNC"), count_lead(t, "ENDFUNC"));
    assert_int_equal(count_lead(t, "TEST"), count_lead(t, "ENDTEST"));
    assert_int_equal(count_lead(t, "WHILE"), count_lead(t, "ENDWHILE"));
    assert_int_equal(count_lead(t, "TRAP"), count_lead(t, "ENDTRAP"));
    int ifs = 0;
    for (const char *p = t; (p = strstr(p, " THEN\n")) != NULL; ++p)
        ++ifs;
    assert_int_equal(ifs, count_lead(t, "ENDIF"));
    static const char *const need[] = {"SocketCreate rcal_sock;", "SocketConnect rcal_sock, \"192.168.125.5\", 5150",
                                       "SocketSend rcal_sock", "SocketReceive rcal_sock", "WaitRob \\ZeroSpeed;",
                                       "CJointT()", "\"HELLO rcal-link/1 abb\\0A\"", "\"STOP\"", "\"NEXT \"",
                                       "\"BACK \"", "\"AGAIN \"", "RETURN 1;", "ITimer 1, rcal_hb;",
                                       "NumToStr(rcal_point(j), 0)"};
    for (size_t k = 0; k < sizeof need / sizeof need[0]; ++k)
        if (!strstr(t, need[k]))
            fail_msg("the RAPID link module lacks %s", need[k]);
    parens_balance(t, '!');
    /* no plate: rcal_point is -1 for every pose */
    size_t fl;
    const char *fn = rapid_func(t, "rcal_point", &fl);
    const char *c = strstr(fn, "CASE");
    assert_true(!c || c > fn + fl);
    free(t);
}

/* A plan with plate points (its target column): each AT reports the pose's point, read back per pose. */
static void test_rapid_points(void **state)
{
    size_t len, fl;
    char *t = write_to_text(1, 1, &len);
    rc_sample rows[N];
    unsigned char lab[N], pts[N];
    rch_rapid_targets ts;
    rch_diag d;
    (void)state;
    plan(rows, lab, pts);
    memset(&ts, 0, sizeof ts);
    assert_int_equal(rch_rapid_scan(&ts, t, len, "link.mod", &d), 0);
    assert_int_equal(ts.n, N);
    rch_rapid_free(&ts);
    parens_balance(t, '!');
    const char *fn = rapid_func(t, "rcal_point", &fl);
    for (int i = 0; i < N; ++i) {
        char want[64];
        snprintf(want, sizeof want, "CASE %d:\n            RETURN %u;", i, (unsigned)pts[i]);
        const char *at = strstr(fn, want);
        if (!at || at > fn + fl)
            fail_msg("rcal_point(%d) does not return %u:\n%.*s", i, (unsigned)pts[i], (int)fl, fn);
    }
    fn = rapid_func(t, "rcal_outlet", &fl);
    for (int i = 0; i < N; ++i) {
        char want[64];
        snprintf(want, sizeof want, "CASE %d:\n            RETURN %u;", i, (unsigned)lab[i]);
        const char *at = strstr(fn, want);
        assert_true(at && at < fn + fl);
    }
    assert_non_null(strstr(t, "NumToStr(rcal_outlet(j), 0) + \" \" + NumToStr(rcal_point(j), 0)"));
    free(t);
}

/* The URScript program: blocks balanced, the protocol's calls, each pose's outlet and plate point (-1 without a
 * plate) reported in AT. */
static void check_urscript(int with_points)
{
    size_t len;
    char *t = write_to_text(0, with_points, &len);
    /* blocks: def/while/if/thread open, end closes (elif/else continue an if) */
    int open = 0;
    for (const char *p = t; p && *p; p = strchr(p, '\n'), p = p ? p + 1 : NULL) {
        const char *q = p + strspn(p, " ");
        if (*q == '#')
            continue;
        if (!strncmp(q, "def ", 4) || !strncmp(q, "while ", 6) || !strncmp(q, "if ", 3) || !strncmp(q, "thread ", 7))
            ++open;
        if (!strncmp(q, "end\n", 4))
            --open;
        assert_true(open >= 0);
    }
    assert_int_equal(open, 0);
    const char *const need[] = {"socket_open(\"127.0.0.1\", 5150, \"rcal\")", "get_actual_joint_positions()",
                                "movej(rcal_plan[j]", "socket_send_line(\"HELLO rcal-link/1 ur\", \"rcal\")",
                                "socket_read_line(\"rcal\"", "rcal_outlet = [0, 1, 0, 1, 0]",
                                "str_cat(to_str(rcal_outlet[j]), str_cat(\" \", to_str(rcal_point[j])))",
                                with_points ? "rcal_point = [2, 0, 1, 2, 0]" : "rcal_point = [-1, -1, -1, -1, -1]"};
    for (size_t k = 0; k < sizeof need / sizeof need[0]; ++k)
        if (!strstr(t, need[k]))
            fail_msg("the URScript link program lacks %s", need[k]);
    parens_balance(t, '#');
    free(t);
}

static void test_urscript(void **state)
{
    (void)state;
    check_urscript(0);
}

static void test_urscript_points(void **state)
{
    (void)state;
    check_urscript(1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rapid),
        cmocka_unit_test(test_rapid_points),
        cmocka_unit_test(test_urscript),
        cmocka_unit_test(test_urscript_points),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
