/* SPDX-License-Identifier: MIT */
/* test_fanuc_read.c - the Fanuc LS reader (rch_fanuc.h) on its own: the
 * committed every-form program (positions, numbers' bytes, uses), the line
 * ends (LF, CRLF, lone CR: the same positions at the same line:col), a BOM,
 * the frames file, W P R against its definition R = Rz(r) Ry(p) Rx(w) and
 * back (gimbal lock included), and refusals at their line:col. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_fanuc.h"

#define DEG (3.14159265358979323846 / 180.0)
#define PROG RCAL_SOURCE_DIR "/tests/tools/host/comp/data/fanuc/every_form.ls"

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

/* text with every "\n" replaced by eol (and a BOM first when bom) */
static char *with_eol(const char *t, size_t n, const char *eol, int bom, size_t *out_n)
{
    char *o = malloc(3 + 2 * n + 1);
    size_t k = 0;
    if (bom) {
        memcpy(o, "\xEF\xBB\xBF", 3);
        k = 3;
    }
    for (size_t i = 0; i < n; ++i)
        if (t[i] == '\n') {
            memcpy(o + k, eol, strlen(eol));
            k += strlen(eol);
        } else
            o[k++] = t[i];
    o[k] = '\0';
    *out_n = k;
    return o;
}

static void test_every_form(void **state)
{
    (void)state;
    size_t n;
    char *t = slurp(PROG, &n);
    rch_fanuc_prog p;
    rch_diag d;
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_fanuc_scan(&p, t, n, "every_form.ls", &d), 0);
    assert_string_equal(p.name, "EVERY_FORM");
    assert_int_equal((int)p.n, 11);
    assert_int_equal((int)p.n_motion, 10); /* C names two positions in one motion */
    for (size_t i = 0; i < p.n; ++i) {
        const rch_fanuc_pos *q = &p.p[i];
        assert_int_equal((int)q->idx, (int)i + 1);
        assert_int_equal((int)q->n_uses, 1);
        assert_int_equal(q->joint, i == 0 || i == 10);
        for (unsigned k = 0; k < q->n; ++k) { /* each number's bytes read back as its value */
            char buf[64];
            memcpy(buf, t + q->num_off[k], q->num_len[k]);
            buf[q->num_len[k]] = '\0';
            assert_true(fabs(strtod(buf, NULL) - q->val[k]) == 0.0);
        }
    }
    /* P[2:"approach"]: CONFIG 'F U T, 0, 0, 0', X = 547.561 */
    assert_memory_equal(p.p[1].cfg, "FUT", 3);
    assert_true(p.p[1].val[0] == 547.561);
    assert_int_equal(p.p[3].val[8], -1); /* P[4]: J6 turn -1 */
    assert_int_equal(p.p[8].uf, 1);
    /* the same positions, lines and columns with CRLF, a lone CR and a BOM */
    const char *eols[3] = {"\r\n", "\r", "\n"};
    for (int e = 0; e < 3; ++e) {
        size_t n2;
        char *t2 = with_eol(t, n, eols[e], e == 2, &n2);
        rch_fanuc_prog p2;
        assert_int_equal(rch_fanuc_scan(&p2, t2, n2, "x.ls", &d), 0);
        assert_int_equal((int)p2.n, 11);
        for (size_t i = 0; i < p.n; ++i) {
            assert_int_equal((int)p2.p[i].line, (int)p.p[i].line);
            assert_int_equal((int)p2.p[i].col, (int)p.p[i].col);
            for (unsigned k = 0; k < p.p[i].n; ++k) {
                assert_true(p2.p[i].val[k] == p.p[i].val[k]);
                assert_int_equal((int)p2.p[i].num_line[k], (int)p.p[i].num_line[k]);
                assert_int_equal((int)p2.p[i].num_col[k], (int)p.p[i].num_col[k]);
            }
        }
        rch_fanuc_free(&p2);
        free(t2);
    }
    rch_fanuc_free(&p);
    free(t);
}

static void expect_refused(const char *text, unsigned line, unsigned col, const char *words)
{
    rch_fanuc_prog p;
    rch_diag d;
    memset(&d, 0, sizeof d);
    assert_int_equal(rch_fanuc_scan(&p, text, strlen(text), "t.ls", &d), -1);
    if (d.line != line || d.col != col || !strstr(d.msg, words))
        fail_msg("%s: got %u:%u %s, wanted %u:%u %s", text, d.line, d.col, d.msg, line, col, words);
    assert_null(p.p);
}

#define POSJ "P[1]{\n GP1:\n UF : 0, UT : 0,\n J1= 1.0 deg, J2= 2 deg, J3= 3 deg, J4= 4 deg, J5= 5 deg, J6= 6 deg\n};\n"

static void test_refused(void **state)
{
    (void)state;
    expect_refused("/MN\n/END\n", 1, 1, "starts with /PROG");
    expect_refused("/PROG A\n/MN\n   1:  J P[1] 100% FINE ;\n/POS\n" POSJ, 10, 1, "does not end with /END");
    expect_refused("/PROG A\n/MN\n   1:  J PR[1] 100% FINE ;\n/POS\n/END\n", 3, 10, "position register");
    expect_refused("/PROG A\n/MN\n   1:  J P[1] 100% FINE Offset,PR[2] ;\n/POS\n" POSJ "/END\n", 3, 25, "Offset");
    expect_refused("/PROG A\n/MN\n   1:  J P[1] 100% FINE ;\n/POS\n" POSJ "/END\n/MN\n", 11, 1, "after /END");
    expect_refused("/PROG A\n/MN\n   1:  J P[2] 100% FINE ;\n/POS\n" POSJ "/END\n", 3, 10, "not in the /POS");
    expect_refused("/PROG A\n/MN\n   1:  UTOOL_NUM=1 ;\n   2:  J P[1] 100% FINE ;\n/POS\n" POSJ "/END\n", 4, 10,
                   "frame mismatch");
    expect_refused("/PROG A\n/MN\n   1:  J P[1] 100% FINE ;\n/POS\n" POSJ POSJ "/END\n", 10, 1, "twice");
    expect_refused("/PROG A\n/MN\n   1:  J P[1] 100% FINE\n/POS\n" POSJ "/END\n", 3, 24, "';'");
    expect_refused("/PROG A\n/MN\n   J P[1] 100% FINE ;\n/POS\n" POSJ "/END\n", 3, 4, "numbered statement");
    expect_refused("/PROG A\n/MN\n/POS\nP[1]{\n GP1:\n UF : 0, UT : 0,\n J1= 1.0 deg, J2= 0x10 deg", 7, 19,
                   "finite decimal");
    expect_refused("/PROG A\n/MN\n/POS\nP[1]{\n GP1:\n UF : F, UT : 0,\n", 6, 7, "'F'");
    expect_refused("/PROG A\n/MN\n/POS\nP[1]{\n GP2:\n", 5, 2, "GP1");
    expect_refused("/PROG A\n/MN\n/POS\nP[1]{\n GP1:\n UF : 0, UT : 0, CONFIG : 'N U Q, 0, 0, 0',", 6, 32,
                   "CONFIG letter 3");
    expect_refused("/PROG A\n/MN\n   1:  J P[1] 100% FINE ;\n/POS\nP[1]{\n GP1:\n UF : 0, UT : 0,\n J1= 1.0 deg, "
                   "J2= 2 deg, J3= 3 deg, J4= 4 deg, J5= 5 deg, J6= 6 deg, E1= 5 mm\n};\n/END\n",
                   8, 70, "extended axes");
    /* accepted: a comment statement holding P[..], a continuation, P[n:comment] */
    const char *ok = "/PROG A\n/MN\n   1:  ! J P[9] ;\n   2:  C P[1:x]\n    :  P[1] 10mm/sec FINE ;\n/POS\n" POSJ
                     "/END\n";
    rch_fanuc_prog p;
    rch_diag d;
    assert_int_equal(rch_fanuc_scan(&p, ok, strlen(ok), "t.ls", &d), 0);
    assert_int_equal((int)p.p[0].n_uses, 2);
    rch_fanuc_free(&p);
}

static void test_frames(void **state)
{
    (void)state;
    rch_fanuc_frames f;
    rch_diag d;
    const char *ok = "# c\n\nuframe,1,400,-100,50,0,0,30\r\nutool, 3, 1, 2, 3, 4, 5, 6\n";
    assert_int_equal(rch_fanuc_frames_parse(&f, ok, strlen(ok), "f.csv", &d), 0);
    assert_true(f.has_uf[0] && f.has_ut[0] && f.has_uf[1] && f.has_ut[3] && !f.has_uf[3] && !f.has_ut[1]);
    assert_true(f.uf[1][5] == 30.0 && f.ut[3][0] == 1.0);
    const char *bad[] = {"uframe,0,1,2,3,4,5,6\n", "utool,1,1,2,3,4,5\n", "ufrm,1,1,2,3,4,5,6\n",
                         "uframe,1,1,2,3,4,5,6,7\n", "uframe,1,1,2,3,4,5,6\nuframe,1,1,2,3,4,5,6\n"};
    const unsigned at[][2] = {{1, 8}, {1, 18}, {1, 1}, {1, 21}, {2, 8}};
    for (int k = 0; k < 5; ++k) {
        memset(&d, 0, sizeof d);
        assert_int_equal(rch_fanuc_frames_parse(&f, bad[k], strlen(bad[k]), "f.csv", &d), -1);
        if (d.line != at[k][0] || d.col != at[k][1])
            fail_msg("%s: %u:%u %s", bad[k], d.line, d.col, d.msg);
    }
}

/* R = Rz(r) Ry(p) Rx(w) by matrix products, apart from rch_fanuc_wpr_to_rot's closed form */
static void rot_ref(double R[9], double w, double p, double r)
{
    const double X[9] = {1, 0, 0, 0, cos(w), -sin(w), 0, sin(w), cos(w)};
    const double Y[9] = {cos(p), 0, sin(p), 0, 1, 0, -sin(p), 0, cos(p)};
    const double Z[9] = {cos(r), -sin(r), 0, sin(r), cos(r), 0, 0, 0, 1};
    double T[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            T[3 * i + j] = 0;
            for (int k = 0; k < 3; ++k)
                T[3 * i + j] += Y[3 * i + k] * X[3 * k + j];
        }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            R[3 * i + j] = 0;
            for (int k = 0; k < 3; ++k)
                R[3 * i + j] += Z[3 * i + k] * T[3 * k + j];
        }
}

static void test_wpr(void **state)
{
    (void)state;
    srand(51);
    for (int n = 0; n < 2000; ++n) {
        double v[3] = {360.0 * rand() / RAND_MAX - 180.0, 180.0 * rand() / RAND_MAX - 90.0,
                       360.0 * rand() / RAND_MAX - 180.0};
        if (n < 4)
            v[1] = n % 2 ? 90.0 : -90.0; /* gimbal lock */
        double R[9], Rr[9], back[3], R2[9];
        rch_fanuc_wpr_to_rot(R, v);
        rot_ref(Rr, v[0] * DEG, v[1] * DEG, v[2] * DEG);
        for (int k = 0; k < 9; ++k)
            assert_true(fabs(R[k] - Rr[k]) < 1e-14);
        rch_fanuc_rot_to_wpr(back, R);
        assert_true(back[1] >= -90.0 && back[1] <= 90.0);
        rch_fanuc_wpr_to_rot(R2, back);
        for (int k = 0; k < 9; ++k)
            assert_true(fabs(R2[k] - R[k]) < 1e-12);
        if (n >= 4)
            for (int k = 0; k < 3; ++k)
                assert_true(fabs(back[k] - v[k]) < 1e-9);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_form),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_frames),
        cmocka_unit_test(test_wpr),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
